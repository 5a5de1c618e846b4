//! The store: opening and migrating, transactional writes, queries.

use std::path::{Path, PathBuf};
use std::time::Duration;

use bouncelab_track::{Status, TRAJECTORY_COLUMNS, TrajectoryCell, TrajectoryRow};
use rusqlite::types::Value;
use rusqlite::{Connection, OptionalExtension, Row, TransactionBehavior, params};

use crate::error::{Result, StoreError};
use crate::records::*;
use crate::schema::{ESTIMATE_QUANTITIES, MIGRATIONS, latest_version, now_sql};

/// How long a write waits for another process's write to finish before failing with "database is locked".
const BUSY_TIMEOUT: Duration = Duration::from_secs(30);

/// The results database: one SQLite file (WAL journal, foreign keys on) that accumulates sessions, shots,
/// tracks, estimates, model versions and fits.
///
/// Every write runs in one immediate transaction: either through [`Store::transaction`], which groups
/// several writes (e.g. a shot, its track and its estimate) so that they all land or none does, or through
/// the convenience methods on `Store`, each its own transaction.
#[derive(Debug)]
pub struct Store {
    conn: Connection,
    path: PathBuf,
}

/// The store's measuring lock (see [`Store::lock_measuring`]), released when dropped.
#[derive(Debug)]
pub struct StoreLock {
    _file: std::fs::File,
}

/// An open write transaction (see [`Store::transaction`]). Dropped without commit, it rolls back.
#[derive(Debug)]
pub struct Tx<'a> {
    tx: rusqlite::Transaction<'a>,
    path: &'a Path,
}

fn sql(path: &Path, table: &'static str) -> impl FnOnce(rusqlite::Error) -> StoreError + use<> {
    let path = path.to_path_buf();
    move |source| {
        if source.sqlite_error_code() == Some(rusqlite::ErrorCode::DiskFull) {
            StoreError::DiskFull { path, table }
        } else {
            StoreError::Sql { path, table, source }
        }
    }
}

/// NaN is stored as NULL.
fn nn(x: f64) -> Option<f64> {
    (!x.is_nan()).then_some(x)
}

/// NULL is read as NaN.
fn get_f64(row: &Row<'_>, idx: usize) -> rusqlite::Result<f64> {
    Ok(row.get::<_, Option<f64>>(idx)?.unwrap_or(f64::NAN))
}

fn to_i64(path: &Path, table: &'static str, field: &'static str, x: u64) -> Result<i64> {
    i64::try_from(x).map_err(|_| StoreError::Field {
        path: path.to_path_buf(),
        table,
        field,
        message: format!("{x} is too large"),
    })
}

fn json_field<T: serde::de::DeserializeOwned>(
    path: &Path,
    table: &'static str,
    field: &'static str,
    text: &str,
) -> Result<T> {
    serde_json::from_str(text).map_err(|e| StoreError::Field {
        path: path.to_path_buf(),
        table,
        field,
        message: format!("stored JSON cannot be read: {e}"),
    })
}

fn to_json<T: serde::Serialize>(path: &Path, table: &'static str, field: &'static str, value: &T) -> Result<String> {
    serde_json::to_string(value).map_err(|e| StoreError::Field {
        path: path.to_path_buf(),
        table,
        field,
        message: format!("cannot be written as JSON: {e}"),
    })
}

impl Store {
    /// Opens (creating if needed) the store at `path`: WAL journal, `synchronous = NORMAL` (a commit survives
    /// the process being killed; only a power loss can undo the last commits), foreign keys on, schema
    /// migrated to the latest version.
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref().to_path_buf();
        // Setting up a new store takes its file's lock exclusively (the switch to WAL, the first migration).
        // Two runs opening it at once can deadlock there, and SQLite then answers one of them "busy" at
        // once, without waiting: that one opens again, until the busy timeout.
        let start = std::time::Instant::now();
        let mut attempt = 0u32;
        loop {
            match Self::open_once(&path) {
                Err(e) if e.is_busy() && start.elapsed() < BUSY_TIMEOUT => {
                    attempt += 1;
                    std::thread::sleep(Duration::from_millis(10 * u64::from(attempt.min(20))));
                }
                done => return done,
            }
        }
    }

    fn open_once(path: &Path) -> Result<Self> {
        let path = path.to_path_buf();
        let conn = Connection::open(&path).map_err(|source| StoreError::Open {
            path: path.clone(),
            source,
        })?;
        Self::setup(conn, path.clone(), true).map_err(|e| match e {
            StoreError::Open { source, .. } | StoreError::Sql { source, .. }
                if source.sqlite_error_code() == Some(rusqlite::ErrorCode::NotADatabase) =>
            {
                StoreError::NotADatabase { path }
            }
            e => e,
        })
    }

    /// A store in memory (for tests and dry runs); lost when dropped.
    pub fn open_in_memory() -> Result<Self> {
        let path = PathBuf::from(":memory:");
        let conn = Connection::open_in_memory().map_err(|source| StoreError::Open {
            path: path.clone(),
            source,
        })?;
        Self::setup(conn, path, false)
    }

    fn setup(conn: Connection, path: PathBuf, wal: bool) -> Result<Self> {
        let open = |source| StoreError::Open {
            path: path.clone(),
            source,
        };
        conn.busy_timeout(BUSY_TIMEOUT).map_err(open)?;
        // A database that holds tables but no `schema_version` is someone else's: refused before any
        // pragma or migration writes to it.
        let tables: Vec<String> = conn
            .prepare("SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name")
            .and_then(|mut st| st.query_map([], |r| r.get(0))?.collect())
            .map_err(open)?;
        if !tables.is_empty() && !tables.iter().any(|t| t == "schema_version") {
            return Err(StoreError::Foreign {
                path: path.clone(),
                tables: tables.len(),
                first: tables.into_iter().take(3).collect::<Vec<_>>().join(", "),
            });
        }
        if wal {
            conn.pragma_update_and_check(None, "journal_mode", "WAL", |r| r.get::<_, String>(0))
                .map_err(open)?;
            conn.pragma_update(None, "synchronous", "NORMAL").map_err(open)?;
        }
        conn.pragma_update(None, "foreign_keys", true).map_err(open)?;
        let mut store = Store { conn, path };
        store.migrate()?;
        Ok(store)
    }

    /// Applies the missing [`MIGRATIONS`] in one transaction.
    fn migrate(&mut self) -> Result<()> {
        let latest = latest_version();
        if self.schema_version()? == latest {
            return Ok(());
        }
        let err = |path: &Path| sql(path, "schema_version");
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(err(&self.path))?;
        tx.execute_batch(concat!(
            "CREATE TABLE IF NOT EXISTS schema_version (
                version INTEGER PRIMARY KEY,
                description TEXT NOT NULL,
                applied_at TEXT NOT NULL DEFAULT (",
            now_sql!(),
            "))"
        ))
        .map_err(err(&self.path))?;
        let found: i64 = tx
            .query_row("SELECT COALESCE(MAX(version), 0) FROM schema_version", [], |r| r.get(0))
            .map_err(err(&self.path))?;
        if found > latest {
            return Err(StoreError::SchemaTooNew {
                path: self.path.clone(),
                found,
                supported: latest,
            });
        }
        for m in MIGRATIONS.iter().filter(|m| m.version > found) {
            tx.execute_batch(m.sql).map_err(err(&self.path))?;
            tx.execute(
                "INSERT INTO schema_version (version, description) VALUES (?1, ?2)",
                params![m.version, m.description],
            )
            .map_err(err(&self.path))?;
        }
        tx.commit().map_err(err(&self.path))
    }

    /// Takes the store's measuring lock: an exclusive lock on the file `<store>.lock` beside it, held until
    /// the guard is dropped (or the process dies: the operating system releases it). Runs that measure shots
    /// take it around choosing and tracking them, so that two runs on one store never both track a shot:
    /// the second waits, then finds the first one's results. `waiting` is called once, with the holder's
    /// process id when known, if another run holds the lock. An in-memory store needs no lock (`None`).
    pub fn lock_measuring(&self, waiting: impl FnOnce(Option<u32>)) -> Result<Option<StoreLock>> {
        if self.path == Path::new(":memory:") {
            return Ok(None);
        }
        let mut name = self.path.as_os_str().to_owned();
        name.push(".lock");
        let path = PathBuf::from(name);
        let io = |source| StoreError::Io {
            path: path.clone(),
            source,
        };
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(io)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let holder = std::fs::read_to_string(&path).ok().and_then(|t| t.trim().parse().ok());
                waiting(holder);
                file.lock().map_err(io)?;
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
        }
        use std::io::{Seek, Write};
        // The holder's pid, for the message another run shows while it waits.
        let _ = file.set_len(0);
        let _ = file.seek(std::io::SeekFrom::Start(0));
        let _ = write!(file, "{}", std::process::id());
        Ok(Some(StoreLock { _file: file }))
    }

    /// The database file (`:memory:` for an in-memory store).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The schema version of the file (0 for an empty file before migration).
    pub fn schema_version(&self) -> Result<i64> {
        let err = || sql(&self.path, "schema_version");
        let exists: bool = self
            .conn
            .query_row(
                "SELECT EXISTS (SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'schema_version')",
                [],
                |r| r.get(0),
            )
            .map_err(err())?;
        if !exists {
            return Ok(0);
        }
        let v: i64 = self
            .conn
            .query_row("SELECT COALESCE(MAX(version), 0) FROM schema_version", [], |r| r.get(0))
            .map_err(err())?;
        if v > latest_version() {
            return Err(StoreError::SchemaTooNew {
                path: self.path.clone(),
                found: v,
                supported: latest_version(),
            });
        }
        Ok(v)
    }

    /// Runs `f` in one immediate write transaction: commits if it returns `Ok`, rolls back if it returns an
    /// error (or panics, or the process dies).
    pub fn transaction<T>(&mut self, f: impl FnOnce(&Tx<'_>) -> Result<T>) -> Result<T> {
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(sql(&self.path, "(transaction)"))?;
        let tx = Tx { tx, path: &self.path };
        let out = f(&tx)?;
        tx.tx.commit().map_err(sql(tx.path, "(transaction)"))?;
        Ok(out)
    }

    /// `PRAGMA integrity_check` and `PRAGMA foreign_key_check`: true when both find nothing wrong.
    pub fn integrity_check(&self) -> Result<bool> {
        let err = || sql(&self.path, "(integrity_check)");
        let mut stmt = self.conn.prepare("PRAGMA integrity_check").map_err(err())?;
        let lines: Vec<String> = stmt
            .query_map([], |r| r.get(0))
            .map_err(err())?
            .collect::<rusqlite::Result<_>>()
            .map_err(err())?;
        if lines != ["ok"] {
            return Ok(false);
        }
        let mut stmt = self.conn.prepare("PRAGMA foreign_key_check").map_err(err())?;
        let bad = stmt.query([]).map_err(err())?.next().map_err(err())?.is_some();
        Ok(!bad)
    }

    /// Number of rows in `table`.
    pub fn count(&self, table: crate::Table) -> Result<u64> {
        let n: i64 = self
            .conn
            .query_row(&format!("SELECT COUNT(*) FROM {}", table.name()), [], |r| r.get(0))
            .map_err(sql(&self.path, table.name()))?;
        Ok(n as u64)
    }

    pub(crate) fn conn(&self) -> &Connection {
        &self.conn
    }

    // ----- convenience writes, one transaction each -----

    /// [`Tx::upsert_session`] in its own transaction.
    pub fn upsert_session(&mut self, record: &SessionRecord) -> Result<i64> {
        self.transaction(|tx| tx.upsert_session(record))
    }

    /// [`Tx::upsert_shot`] in its own transaction.
    pub fn upsert_shot(&mut self, session_id: i64, record: &ShotRecord) -> Result<ShotUpsert> {
        self.transaction(|tx| tx.upsert_shot(session_id, record))
    }

    /// [`Tx::put_track`] in its own transaction.
    pub fn put_track(&mut self, shot_id: i64, record: &TrackRecord) -> Result<()> {
        self.transaction(|tx| tx.put_track(shot_id, record))
    }

    /// [`Tx::put_estimate`] in its own transaction.
    pub fn put_estimate(&mut self, shot_id: i64, record: &EstimateRecord) -> Result<()> {
        self.transaction(|tx| tx.put_estimate(shot_id, record))
    }

    /// [`Tx::mark_failed`] in its own transaction.
    pub fn mark_failed(&mut self, shot_id: i64, message: &str) -> Result<()> {
        self.transaction(|tx| tx.mark_failed(shot_id, message))
    }

    /// [`Tx::add_model_version`] in its own transaction.
    pub fn add_model_version(&mut self, record: &ModelVersionRecord) -> Result<i64> {
        self.transaction(|tx| tx.add_model_version(record))
    }

    /// [`Tx::add_fit`] in its own transaction.
    pub fn add_fit(&mut self, record: &FitRecord) -> Result<i64> {
        self.transaction(|tx| tx.add_fit(record))
    }

    // ----- queries -----

    /// All sessions, in the order first stored.
    pub fn sessions(&self) -> Result<Vec<SessionRow>> {
        q_sessions(&self.conn, &self.path, None)
    }

    /// The session stored under `path`.
    pub fn session_by_path(&self, path: &str) -> Result<Option<SessionRow>> {
        Ok(q_sessions(&self.conn, &self.path, Some(path))?.pop())
    }

    /// The shots of a session, in the order first stored.
    pub fn shots(&self, session_id: i64) -> Result<Vec<ShotRow>> {
        q_shots(&self.conn, &self.path, session_id, None)
    }

    /// One shot of a session by clip name.
    pub fn shot(&self, session_id: i64, clip: &str) -> Result<Option<ShotRow>> {
        Ok(q_shots(&self.conn, &self.path, session_id, Some(clip))?.pop())
    }

    /// A shot's track with its trajectory rows (in frame order).
    pub fn track(&self, shot_id: i64) -> Result<Option<TrackRecord>> {
        q_track(&self.conn, &self.path, shot_id)
    }

    /// A shot's estimate.
    pub fn estimate(&self, shot_id: i64) -> Result<Option<EstimateRecord>> {
        Ok(q_estimates(&self.conn, &self.path, "e.shot_id", shot_id)?
            .pop()
            .map(|r| r.estimate))
    }

    /// The estimates of a session's shots joined with their conditions, in shot order (the rows of
    /// `estimates.csv`).
    pub fn estimates(&self, session_id: i64) -> Result<Vec<EstimateRow>> {
        q_estimates(&self.conn, &self.path, "s.session_id", session_id)
    }

    /// All model versions, oldest first.
    pub fn model_versions(&self) -> Result<Vec<ModelVersionRow>> {
        let path = &self.path;
        let mut stmt = self
            .conn
            .prepare("SELECT id, name, toml, parent_id, created_at FROM model_versions ORDER BY id")
            .map_err(sql(path, "model_versions"))?;
        let rows = stmt
            .query_map([], |r| {
                Ok(ModelVersionRow {
                    id: r.get(0)?,
                    record: ModelVersionRecord {
                        name: r.get(1)?,
                        toml: r.get(2)?,
                        parent_id: r.get(3)?,
                    },
                    created_at: r.get(4)?,
                })
            })
            .map_err(sql(path, "model_versions"))?;
        rows.collect::<rusqlite::Result<_>>()
            .map_err(sql(path, "model_versions"))
    }

    /// The fits of a session (`Some(id)`) or of all sessions and none (`None`), oldest first.
    pub fn fits(&self, session_id: Option<i64>) -> Result<Vec<FitRow>> {
        q_fits(&self.conn, &self.path, session_id, false)
    }

    /// The latest fit of a session.
    pub fn latest_fit(&self, session_id: i64) -> Result<Option<FitRow>> {
        Ok(q_fits(&self.conn, &self.path, Some(session_id), false)?.pop())
    }

    /// Every model version, oldest first, with its number of fits and its latest fit's errors (in the
    /// session given, or in all with `None`): shows whether the error fell as effects were added.
    pub fn model_history(&self, session_id: Option<i64>) -> Result<Vec<ModelHistoryRow>> {
        let fits = q_fits(&self.conn, &self.path, session_id, true)?;
        Ok(self
            .model_versions()?
            .into_iter()
            .map(|version| {
                let mine: Vec<&FitRow> = fits
                    .iter()
                    .filter(|f| f.record.model_version_id == version.id)
                    .collect();
                ModelHistoryRow {
                    fits: mine.len() as u64,
                    latest: mine.last().map(|f| (*f).clone()),
                    version,
                }
            })
            .collect())
    }
}

impl Tx<'_> {
    fn ensure(&self, table: &'static str, id: i64) -> Result<()> {
        let found = self
            .tx
            .query_row(&format!("SELECT 1 FROM {table} WHERE id = ?1"), [id], |_| Ok(()))
            .optional()
            .map_err(sql(self.path, table))?;
        found.ok_or_else(|| StoreError::NotFound {
            path: self.path.to_path_buf(),
            table,
            id,
        })
    }

    fn field(&self, table: &'static str, field: &'static str, message: impl Into<String>) -> StoreError {
        StoreError::Field {
            path: self.path.to_path_buf(),
            table,
            field,
            message: message.into(),
        }
    }

    /// Stores a session, or updates the one with the same `path`; returns its id.
    pub fn upsert_session(&self, r: &SessionRecord) -> Result<i64> {
        if r.path.is_empty() {
            return Err(self.field("sessions", "path", "is empty"));
        }
        self.tx
            .query_row(
                concat!(
                    "INSERT INTO sessions (path, description, settings_hash, session_toml)
                     VALUES (?1, ?2, ?3, ?4)
                     ON CONFLICT (path) DO UPDATE SET
                        description = excluded.description,
                        settings_hash = excluded.settings_hash,
                        session_toml = excluded.session_toml,
                        updated_at = ",
                    now_sql!(),
                    " RETURNING id"
                ),
                params![r.path, r.description, r.settings_hash, r.session_toml],
                |row| row.get(0),
            )
            .map_err(sql(self.path, "sessions"))
    }

    /// Stores a shot of a session, or updates the one with the same clip name, and says whether it must be
    /// tracked (see [`ShotUpsert`]). When its fingerprint, fps or angle changed, its track and estimate are
    /// deleted and its status is reset to `pending`; other fields (surface, drop height, metadata) are
    /// updated in place.
    pub fn upsert_shot(&self, session_id: i64, r: &ShotRecord) -> Result<ShotUpsert> {
        self.ensure("sessions", session_id)?;
        if r.clip.is_empty() {
            return Err(self.field("shots", "clip", "is empty"));
        }
        if r.frames_hash.is_empty() {
            return Err(self.field("shots", "frames_hash", format!("is empty for clip `{}`", r.clip)));
        }
        let metadata = to_json(self.path, "shots", "metadata", &r.metadata)?;
        let err = || sql(self.path, "shots");
        type Stored = (i64, String, Option<f64>, Option<f64>, String);
        let old: Option<Stored> = self
            .tx
            .query_row(
                "SELECT id, frames_hash, fps, angle_deg, status FROM shots WHERE session_id = ?1 AND clip = ?2",
                params![session_id, r.clip],
                |row| Ok((row.get(0)?, row.get(1)?, row.get(2)?, row.get(3)?, row.get(4)?)),
            )
            .optional()
            .map_err(err())?;
        let Some((id, hash, fps, angle, status)) = old else {
            let id = self
                .tx
                .query_row(
                    "INSERT INTO shots (session_id, clip, surface, angle_deg, drop_height_m, fps, metadata,
                                        frames_hash, status)
                     VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, 'pending') RETURNING id",
                    params![
                        session_id,
                        r.clip,
                        r.surface,
                        nn(r.angle_deg),
                        nn(r.drop_height_m),
                        nn(r.fps),
                        metadata,
                        r.frames_hash
                    ],
                    |row| row.get(0),
                )
                .map_err(err())?;
            return Ok(ShotUpsert {
                id,
                inserted: true,
                frames_changed: false,
                needs_tracking: true,
            });
        };
        let same =
            |a: Option<f64>, b: f64| a.unwrap_or(f64::NAN).to_bits() == b.to_bits() || (a.is_none() && b.is_nan());
        let changed = hash != r.frames_hash || !same(fps, r.fps) || !same(angle, r.angle_deg);
        if changed {
            self.drop_results(id)?;
        }
        self.tx
            .execute(
                concat!(
                    "UPDATE shots SET surface = ?2, angle_deg = ?3, drop_height_m = ?4, fps = ?5, metadata = ?6,
                        frames_hash = ?7,
                        status = CASE WHEN ?8 THEN 'pending' ELSE status END,
                        error = CASE WHEN ?8 THEN NULL ELSE error END,
                        updated_at = ",
                    now_sql!(),
                    " WHERE id = ?1"
                ),
                params![
                    id,
                    r.surface,
                    nn(r.angle_deg),
                    nn(r.drop_height_m),
                    nn(r.fps),
                    metadata,
                    r.frames_hash,
                    changed
                ],
            )
            .map_err(err())?;
        let done = status == ShotStatus::Estimated.as_str();
        Ok(ShotUpsert {
            id,
            inserted: false,
            frames_changed: changed,
            needs_tracking: changed || !done,
        })
    }

    /// Deletes a shot's estimate, trajectory and track.
    fn drop_results(&self, shot_id: i64) -> Result<()> {
        for table in ["estimates", "trajectory", "tracks"] {
            self.tx
                .execute(&format!("DELETE FROM {table} WHERE shot_id = ?1"), [shot_id])
                .map_err(sql(self.path, table))?;
        }
        Ok(())
    }

    fn set_status(&self, shot_id: i64, status: ShotStatus, error: Option<&str>) -> Result<()> {
        let n = self
            .tx
            .execute(
                concat!(
                    "UPDATE shots SET status = ?2, error = ?3, updated_at = ",
                    now_sql!(),
                    " WHERE id = ?1"
                ),
                params![shot_id, status.as_str(), error],
            )
            .map_err(sql(self.path, "shots"))?;
        if n == 0 {
            return Err(StoreError::NotFound {
                path: self.path.to_path_buf(),
                table: "shots",
                id: shot_id,
            });
        }
        Ok(())
    }

    /// Replaces a shot's track and trajectory (deleting its estimate, which came from the old track) and sets
    /// its status to `tracked`.
    pub fn put_track(&self, shot_id: i64, r: &TrackRecord) -> Result<()> {
        self.ensure("shots", shot_id)?;
        if r.measured > r.frames {
            return Err(self.field(
                "tracks",
                "measured",
                format!("{} measured frames of {} in shot {shot_id}", r.measured, r.frames),
            ));
        }
        let frames = to_i64(self.path, "tracks", "frames", r.frames)?;
        let measured = to_i64(self.path, "tracks", "measured", r.measured)?;
        let warnings = to_json(self.path, "tracks", "warnings", &r.warnings)?;
        let camera = r
            .camera
            .as_ref()
            .map(|c| to_json(self.path, "tracks", "camera", c))
            .transpose()?;
        self.drop_results(shot_id)?;
        self.tx
            .execute(
                "INSERT INTO tracks (shot_id, frames, measured, scale_m_per_px, scale_se, surface_y_px,
                                     surface_tilt_deg, warnings, seconds, camera)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
                params![
                    shot_id,
                    frames,
                    measured,
                    r.scale_m_per_px.and_then(nn),
                    r.scale_se.and_then(nn),
                    r.surface_y_px.and_then(nn),
                    r.surface_tilt_deg.and_then(nn),
                    warnings,
                    nn(r.seconds),
                    camera
                ],
            )
            .map_err(sql(self.path, "tracks"))?;
        self.put_trajectory(shot_id, &r.rows)?;
        self.set_status(shot_id, ShotStatus::Tracked, None)
    }

    /// The rows under their [`TRAJECTORY_COLUMNS`]: the frame an integer, numbers reals (NaN as NULL), the
    /// status by its name.
    fn put_trajectory(&self, shot_id: i64, rows: &[TrajectoryRow]) -> Result<()> {
        let err = || sql(self.path, "trajectory");
        let placeholders: Vec<String> = (2..TRAJECTORY_COLUMNS.len() + 2).map(|i| format!("?{i}")).collect();
        let mut stmt = self
            .tx
            .prepare_cached(&format!(
                "INSERT INTO trajectory (shot_id, {}) VALUES (?1, {})",
                TRAJECTORY_COLUMNS.join(", "),
                placeholders.join(", ")
            ))
            .map_err(err())?;
        let mut values: Vec<Value> = Vec::with_capacity(TRAJECTORY_COLUMNS.len() + 1);
        for row in rows {
            values.clear();
            values.push(Value::Integer(shot_id));
            for cell in row.cells() {
                values.push(match cell {
                    TrajectoryCell::Frame(f) => Value::Integer(to_i64(self.path, "trajectory", "frame", f as u64)?),
                    TrajectoryCell::Number(x) => nn(x).map_or(Value::Null, Value::Real),
                    TrajectoryCell::Status(s) => Value::Text(s.name().to_string()),
                });
            }
            stmt.execute(rusqlite::params_from_iter(&values)).map_err(err())?;
        }
        Ok(())
    }

    /// Replaces a shot's estimate and sets its status to `estimated`.
    pub fn put_estimate(&self, shot_id: i64, r: &EstimateRecord) -> Result<()> {
        self.ensure("shots", shot_id)?;
        let notes = to_json(self.path, "estimates", "notes", &r.notes)?;
        let columns: Vec<&str> = ESTIMATE_QUANTITIES.iter().flatten().copied().collect();
        let placeholders: Vec<String> = (2..columns.len() + 4).map(|i| format!("?{i}")).collect();
        let mut values: Vec<Option<f64>> = Vec::with_capacity(columns.len());
        for q in r.quantities() {
            values.push(q.and_then(|x| nn(x.value)));
            values.push(q.and_then(|x| nn(x.se)));
        }
        let sql_text = format!(
            "INSERT OR REPLACE INTO estimates (shot_id, {}, notes, detail) VALUES (?1, {})",
            columns.join(", "),
            placeholders.join(", ")
        );
        let mut params: Vec<&dyn rusqlite::ToSql> = vec![&shot_id];
        params.extend(values.iter().map(|v| v as &dyn rusqlite::ToSql));
        params.push(&notes);
        params.push(&r.detail);
        self.tx
            .execute(&sql_text, params.as_slice())
            .map_err(sql(self.path, "estimates"))?;
        self.set_status(shot_id, ShotStatus::Estimated, None)
    }

    /// Marks a shot `failed` with a message (its track, if any, is kept); it will be tracked again.
    pub fn mark_failed(&self, shot_id: i64, message: &str) -> Result<()> {
        self.set_status(shot_id, ShotStatus::Failed, Some(message))
    }

    /// Stores a model version and returns its id; an identical (name, text) version already stored is
    /// returned instead (its parent unchanged).
    pub fn add_model_version(&self, r: &ModelVersionRecord) -> Result<i64> {
        if r.name.is_empty() {
            return Err(self.field("model_versions", "name", "is empty"));
        }
        if let Some(parent) = r.parent_id {
            self.ensure("model_versions", parent)?;
        }
        let err = || sql(self.path, "model_versions");
        self.tx
            .execute(
                "INSERT INTO model_versions (name, toml, parent_id) VALUES (?1, ?2, ?3)
                 ON CONFLICT (name, toml) DO NOTHING",
                params![r.name, r.toml, r.parent_id],
            )
            .map_err(err())?;
        self.tx
            .query_row(
                "SELECT id FROM model_versions WHERE name = ?1 AND toml = ?2",
                params![r.name, r.toml],
                |row| row.get(0),
            )
            .map_err(err())
    }

    /// Stores a fit and returns its id; a fit identical to one stored (same session, model version and
    /// result) is not stored twice: its id is returned, so re-running an unchanged analysis adds no row.
    pub fn add_fit(&self, r: &FitRecord) -> Result<i64> {
        self.ensure("model_versions", r.model_version_id)?;
        if let Some(s) = r.session_id {
            self.ensure("sessions", s)?;
        }
        if let Err(e) = serde_json::from_str::<serde::de::IgnoredAny>(&r.json) {
            return Err(self.field("fits", "json", format!("is not valid JSON: {e}")));
        }
        let same: Option<i64> = self
            .tx
            .query_row(
                "SELECT id FROM fits WHERE session_id IS ?1 AND model_version_id = ?2 AND json = ?3
                 ORDER BY id DESC LIMIT 1",
                params![r.session_id, r.model_version_id, r.json],
                |row| row.get(0),
            )
            .optional()
            .map_err(sql(self.path, "fits"))?;
        if let Some(id) = same {
            return Ok(id);
        }
        self.tx
            .query_row(
                "INSERT INTO fits (session_id, model_version_id, json, reduced_chi2, rms_m, mae_pct)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6) RETURNING id",
                params![
                    r.session_id,
                    r.model_version_id,
                    r.json,
                    nn(r.reduced_chi2),
                    nn(r.rms_m),
                    r.mae_pct.and_then(nn)
                ],
                |row| row.get(0),
            )
            .map_err(sql(self.path, "fits"))
    }

    /// The shots of a session (as [`Store::shots`], inside this transaction).
    pub fn shots(&self, session_id: i64) -> Result<Vec<ShotRow>> {
        q_shots(&self.tx, self.path, session_id, None)
    }

    /// One shot by clip name (as [`Store::shot`], inside this transaction).
    pub fn shot(&self, session_id: i64, clip: &str) -> Result<Option<ShotRow>> {
        Ok(q_shots(&self.tx, self.path, session_id, Some(clip))?.pop())
    }
}

// ----- query helpers shared by Store and Tx -----

fn q_sessions(conn: &Connection, path: &Path, by_path: Option<&str>) -> Result<Vec<SessionRow>> {
    let err = || sql(path, "sessions");
    let mut stmt = conn
        .prepare(
            "SELECT id, path, description, settings_hash, session_toml, loaded_at, updated_at FROM sessions
             WHERE ?1 IS NULL OR path = ?1 ORDER BY id",
        )
        .map_err(err())?;
    let rows = stmt
        .query_map([by_path], |r| {
            Ok(SessionRow {
                id: r.get(0)?,
                record: SessionRecord {
                    path: r.get(1)?,
                    description: r.get(2)?,
                    settings_hash: r.get(3)?,
                    session_toml: r.get(4)?,
                },
                loaded_at: r.get(5)?,
                updated_at: r.get(6)?,
            })
        })
        .map_err(err())?;
    rows.collect::<rusqlite::Result<_>>().map_err(err())
}

fn q_shots(conn: &Connection, path: &Path, session_id: i64, clip: Option<&str>) -> Result<Vec<ShotRow>> {
    let err = || sql(path, "shots");
    let mut stmt = conn
        .prepare(
            "SELECT id, session_id, clip, surface, angle_deg, drop_height_m, fps, metadata, frames_hash, status,
                    error, updated_at
             FROM shots WHERE session_id = ?1 AND (?2 IS NULL OR clip = ?2) ORDER BY id",
        )
        .map_err(err())?;
    let raw = stmt
        .query_map(params![session_id, clip], |r| {
            Ok((
                ShotRow {
                    id: r.get(0)?,
                    session_id: r.get(1)?,
                    record: ShotRecord {
                        clip: r.get(2)?,
                        surface: r.get(3)?,
                        angle_deg: get_f64(r, 4)?,
                        drop_height_m: get_f64(r, 5)?,
                        fps: get_f64(r, 6)?,
                        metadata: Default::default(),
                        frames_hash: r.get(8)?,
                    },
                    status: ShotStatus::Pending,
                    error: r.get(10)?,
                    updated_at: r.get(11)?,
                },
                r.get::<_, String>(7)?,
                r.get::<_, String>(9)?,
            ))
        })
        .map_err(err())?
        .collect::<rusqlite::Result<Vec<_>>>()
        .map_err(err())?;
    raw.into_iter()
        .map(|(mut row, metadata, status)| {
            row.record.metadata = json_field(path, "shots", "metadata", &metadata)?;
            row.status = ShotStatus::parse(&status).ok_or_else(|| StoreError::Field {
                path: path.to_path_buf(),
                table: "shots",
                field: "status",
                message: format!("unknown status `{status}`"),
            })?;
            Ok(row)
        })
        .collect()
}

fn q_track(conn: &Connection, path: &Path, shot_id: i64) -> Result<Option<TrackRecord>> {
    let err = || sql(path, "tracks");
    let head = conn
        .query_row(
            "SELECT frames, measured, scale_m_per_px, scale_se, surface_y_px, surface_tilt_deg, warnings, seconds,
                    camera
             FROM tracks WHERE shot_id = ?1",
            [shot_id],
            |r| {
                Ok((
                    TrackRecord {
                        frames: r.get::<_, i64>(0)? as u64,
                        measured: r.get::<_, i64>(1)? as u64,
                        scale_m_per_px: r.get(2)?,
                        scale_se: r.get(3)?,
                        surface_y_px: r.get(4)?,
                        surface_tilt_deg: r.get(5)?,
                        warnings: Vec::new(),
                        seconds: get_f64(r, 7)?,
                        rows: Vec::new(),
                        camera: None,
                    },
                    r.get::<_, String>(6)?,
                    r.get::<_, Option<String>>(8)?,
                ))
            },
        )
        .optional()
        .map_err(err())?;
    let Some((mut track, warnings, camera)) = head else {
        return Ok(None);
    };
    track.warnings = json_field(path, "tracks", "warnings", &warnings)?;
    track.camera = camera.map(|c| json_field(path, "tracks", "camera", &c)).transpose()?;
    track.rows = q_trajectory(conn, path, shot_id)?;
    Ok(Some(track))
}

/// A shot's trajectory in frame order, read under [`TRAJECTORY_COLUMNS`] (the inverse of
/// `Tx::put_trajectory`); a status this build does not know is an error naming the shot and the frame.
fn q_trajectory(conn: &Connection, path: &Path, shot_id: i64) -> Result<Vec<TrajectoryRow>> {
    let err = || sql(path, "trajectory");
    let mut stmt = conn
        .prepare(&format!(
            // The frame first once more, to name the row in an error.
            "SELECT frame, {} FROM trajectory WHERE shot_id = ?1 ORDER BY frame",
            TRAJECTORY_COLUMNS.join(", ")
        ))
        .map_err(err())?;
    let raw: Vec<(i64, Vec<Value>)> = stmt
        .query_map([shot_id], |r| {
            let cells = (1..=TRAJECTORY_COLUMNS.len()).map(|i| r.get(i));
            Ok((r.get(0)?, cells.collect::<rusqlite::Result<_>>()?))
        })
        .map_err(err())?
        .collect::<rusqlite::Result<_>>()
        .map_err(err())?;
    raw.into_iter()
        .map(|(frame, values)| {
            let bad = |message: String| StoreError::Field {
                path: path.to_path_buf(),
                table: "trajectory",
                field: "frame",
                message: format!("shot {shot_id}, frame {frame}: {message}"),
            };
            let mut cells = [TrajectoryCell::Number(f64::NAN); 10];
            for (cell, value) in cells.iter_mut().zip(values) {
                *cell = match value {
                    Value::Null => TrajectoryCell::Number(f64::NAN),
                    Value::Real(x) => TrajectoryCell::Number(x),
                    Value::Integer(i) => {
                        TrajectoryCell::Frame(usize::try_from(i).map_err(|_| bad(format!("{i} is not a frame index")))?)
                    }
                    Value::Text(name) => TrajectoryCell::Status(Status::from_name(&name).map_err(|source| {
                        StoreError::UnknownStatus {
                            path: path.to_path_buf(),
                            clip: shot_clip(conn, shot_id),
                            shot_id,
                            frame,
                            source,
                        }
                    })?),
                    Value::Blob(_) => return Err(bad("a blob where a trajectory value belongs".into())),
                };
            }
            TrajectoryRow::from_cells(cells)
                .ok_or_else(|| bad(format!("{cells:?} are not the trajectory columns' kinds")))
        })
        .collect()
}

/// The clip name of a shot, for an error message (`?` if it cannot be read).
fn shot_clip(conn: &Connection, shot_id: i64) -> String {
    conn.query_row("SELECT clip FROM shots WHERE id = ?1", [shot_id], |r| r.get(0))
        .unwrap_or_else(|_| "?".to_string())
}

/// Estimates joined with shots where `column = id` (`e.shot_id` or `s.session_id`).
fn q_estimates(conn: &Connection, path: &Path, column: &str, id: i64) -> Result<Vec<EstimateRow>> {
    let err = || sql(path, "estimates");
    let quantities: Vec<String> = ESTIMATE_QUANTITIES.iter().flatten().map(|c| format!("e.{c}")).collect();
    // Columns: 0–4 the shot, then each quantity's value and error, then the notes and the detail.
    const FIRST: usize = 5;
    let notes_at = FIRST + 2 * ESTIMATE_QUANTITIES.len();
    let mut stmt = conn
        .prepare(&format!(
            "SELECT e.shot_id, s.clip, s.surface, s.angle_deg, s.drop_height_m, {}, e.notes, e.detail
             FROM estimates e JOIN shots s ON s.id = e.shot_id WHERE {column} = ?1 ORDER BY s.id",
            quantities.join(", ")
        ))
        .map_err(err())?;
    let raw = stmt
        .query_map([id], |r| {
            let mut q = [None; 10];
            for (k, slot) in q.iter_mut().enumerate() {
                let i = FIRST + 2 * k;
                let value: Option<f64> = r.get(i)?;
                let se: Option<f64> = r.get(i + 1)?;
                // Two NULLs: not measured (a spin), which `from_quantities` reads as NaN for the others.
                *slot = (value.is_some() || se.is_some())
                    .then(|| ValueSe::new(value.unwrap_or(f64::NAN), se.unwrap_or(f64::NAN)));
            }
            Ok((
                EstimateRow {
                    shot_id: r.get(0)?,
                    clip: r.get(1)?,
                    surface: r.get(2)?,
                    angle_deg: get_f64(r, 3)?,
                    drop_height_m: get_f64(r, 4)?,
                    estimate: EstimateRecord::from_quantities(q, Vec::new(), r.get(notes_at + 1)?),
                },
                r.get::<_, String>(notes_at)?,
            ))
        })
        .map_err(err())?
        .collect::<rusqlite::Result<Vec<_>>>()
        .map_err(err())?;
    raw.into_iter()
        .map(|(mut row, notes)| {
            row.estimate.notes = json_field(path, "estimates", "notes", &notes)?;
            Ok(row)
        })
        .collect()
}

/// Fits of a session (or all), oldest first; `summary` leaves `json` empty.
fn q_fits(conn: &Connection, path: &Path, session_id: Option<i64>, summary: bool) -> Result<Vec<FitRow>> {
    let err = || sql(path, "fits");
    let json = if summary { "''" } else { "json" };
    let mut stmt = conn
        .prepare(&format!(
            "SELECT id, session_id, model_version_id, {json}, reduced_chi2, rms_m, mae_pct, created_at FROM fits
             WHERE ?1 IS NULL OR session_id = ?1 ORDER BY id"
        ))
        .map_err(err())?;
    let rows = stmt
        .query_map([session_id], |r| {
            Ok(FitRow {
                id: r.get(0)?,
                record: FitRecord {
                    session_id: r.get(1)?,
                    model_version_id: r.get(2)?,
                    json: r.get(3)?,
                    reduced_chi2: get_f64(r, 4)?,
                    rms_m: get_f64(r, 5)?,
                    mae_pct: r.get(6)?,
                },
                created_at: r.get(7)?,
            })
        })
        .map_err(err())?;
    rows.collect::<rusqlite::Result<_>>().map_err(err())
}
