//! The schema: its migrations and the list of tables with their columns in export order.

use std::fmt;
use std::str::FromStr;

use bouncelab_track::TRAJECTORY_COLUMNS;

use crate::error::StoreError;

/// SQL for the current time as ISO 8601 UTC with milliseconds (`2026-04-14T09:30:00.123Z`).
macro_rules! now_sql {
    () => {
        "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')"
    };
}
pub(crate) use now_sql;

/// One schema migration: applied once, inside the transaction that records its version.
#[derive(Debug, Clone, Copy)]
pub struct Migration {
    /// The version this migration brings the schema to (1, 2, …; contiguous).
    pub version: i64,
    /// One line on what it changes.
    pub description: &'static str,
    /// The SQL, run with `execute_batch`.
    pub sql: &'static str,
}

/// Every migration in order. The migration hook: to change the schema, append a migration here (never edit
/// an applied one), add its tables to [`Table`], and describe it in `docs/store.md`.
pub const MIGRATIONS: &[Migration] = &[
    Migration {
        version: 1,
        description: "sessions, shots, tracks, trajectory, estimates, model_versions, fits",
        sql: concat!(
            "
CREATE TABLE sessions (
    id INTEGER PRIMARY KEY,
    path TEXT NOT NULL UNIQUE,
    description TEXT,
    settings_hash TEXT NOT NULL,
    session_toml TEXT NOT NULL,
    loaded_at TEXT NOT NULL DEFAULT (",
            now_sql!(),
            "),
    updated_at TEXT NOT NULL DEFAULT (",
            now_sql!(),
            ")
);
CREATE TABLE shots (
    id INTEGER PRIMARY KEY,
    session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
    clip TEXT NOT NULL,
    surface TEXT NOT NULL,
    angle_deg REAL,
    drop_height_m REAL,
    fps REAL,
    metadata TEXT NOT NULL DEFAULT '{}' CHECK (json_valid(metadata)),
    frames_hash TEXT NOT NULL,
    status TEXT NOT NULL DEFAULT 'pending'
        CHECK (status IN ('pending', 'tracked', 'estimated', 'failed')),
    error TEXT,
    updated_at TEXT NOT NULL DEFAULT (",
            now_sql!(),
            "),
    UNIQUE (session_id, clip)
);
CREATE TABLE tracks (
    shot_id INTEGER PRIMARY KEY REFERENCES shots(id) ON DELETE CASCADE,
    frames INTEGER NOT NULL CHECK (frames >= 0),
    measured INTEGER NOT NULL CHECK (measured >= 0 AND measured <= frames),
    scale_m_per_px REAL,
    scale_se REAL,
    surface_y_px REAL,
    surface_tilt_deg REAL,
    warnings TEXT NOT NULL DEFAULT '[]' CHECK (json_valid(warnings)),
    seconds REAL,
    created_at TEXT NOT NULL DEFAULT (",
            now_sql!(),
            ")
);
CREATE TABLE trajectory (
    shot_id INTEGER NOT NULL REFERENCES tracks(shot_id) ON DELETE CASCADE,
    frame INTEGER NOT NULL CHECK (frame >= 0),
    t_s REAL,
    x_px REAL,
    y_px REAL,
    r_px REAL,
    sigma_px REAL,
    quality REAL,
    status TEXT NOT NULL,
    x_m REAL,
    y_m REAL,
    PRIMARY KEY (shot_id, frame)
) WITHOUT ROWID;
CREATE TABLE estimates (
    shot_id INTEGER PRIMARY KEY REFERENCES shots(id) ON DELETE CASCADE,
    v_in_t REAL, v_in_t_se REAL,
    v_in_n REAL, v_in_n_se REAL,
    v_out_t REAL, v_out_t_se REAL,
    v_out_n REAL, v_out_n_se REAL,
    cor REAL, cor_se REAL,
    mu REAL, mu_se REAL,
    contact_ms REAL, contact_ms_se REAL,
    spin_in REAL, spin_in_se REAL,
    spin_out REAL, spin_out_se REAL,
    delta_max_m REAL, delta_max_m_se REAL,
    notes TEXT NOT NULL DEFAULT '[]' CHECK (json_valid(notes)),
    created_at TEXT NOT NULL DEFAULT (",
            now_sql!(),
            ")
);
CREATE TABLE model_versions (
    id INTEGER PRIMARY KEY,
    name TEXT NOT NULL,
    toml TEXT NOT NULL,
    parent_id INTEGER REFERENCES model_versions(id),
    created_at TEXT NOT NULL DEFAULT (",
            now_sql!(),
            "),
    UNIQUE (name, toml)
);
CREATE TABLE fits (
    id INTEGER PRIMARY KEY,
    session_id INTEGER REFERENCES sessions(id) ON DELETE CASCADE,
    model_version_id INTEGER NOT NULL REFERENCES model_versions(id),
    json TEXT NOT NULL CHECK (json_valid(json)),
    reduced_chi2 REAL,
    rms_m REAL,
    mae_pct REAL,
    created_at TEXT NOT NULL DEFAULT (",
            now_sql!(),
            ")
);
CREATE INDEX fits_by_session ON fits(session_id, id);
CREATE INDEX fits_by_model ON fits(model_version_id, id);
"
        ),
    },
    Migration {
        version: 2,
        description: "estimates.detail: the estimator's full output as JSON (phases, flight arcs)",
        sql: "ALTER TABLE estimates ADD COLUMN detail TEXT CHECK (detail IS NULL OR json_valid(detail));",
    },
    Migration {
        version: 3,
        description: "tracks.camera: the camera file's header (model, rate, exposure, bit depth, trigger) as JSON",
        sql: "ALTER TABLE tracks ADD COLUMN camera TEXT CHECK (camera IS NULL OR json_valid(camera));",
    },
    Migration {
        version: 4,
        description: "estimates: the quantities named as in estimates.csv, units last; delta_max in mm",
        sql: "ALTER TABLE estimates RENAME COLUMN v_in_t TO v_in_t_m_s;
ALTER TABLE estimates RENAME COLUMN v_in_t_se TO v_in_t_se_m_s;
ALTER TABLE estimates RENAME COLUMN v_in_n TO v_in_n_m_s;
ALTER TABLE estimates RENAME COLUMN v_in_n_se TO v_in_n_se_m_s;
ALTER TABLE estimates RENAME COLUMN v_out_t TO v_out_t_m_s;
ALTER TABLE estimates RENAME COLUMN v_out_t_se TO v_out_t_se_m_s;
ALTER TABLE estimates RENAME COLUMN v_out_n TO v_out_n_m_s;
ALTER TABLE estimates RENAME COLUMN v_out_n_se TO v_out_n_se_m_s;
ALTER TABLE estimates RENAME COLUMN mu TO mu_eff;
ALTER TABLE estimates RENAME COLUMN mu_se TO mu_eff_se;
ALTER TABLE estimates RENAME COLUMN contact_ms_se TO contact_se_ms;
ALTER TABLE estimates RENAME COLUMN spin_in TO spin_in_rad_s;
ALTER TABLE estimates RENAME COLUMN spin_in_se TO spin_in_se_rad_s;
ALTER TABLE estimates RENAME COLUMN spin_out TO spin_out_rad_s;
ALTER TABLE estimates RENAME COLUMN spin_out_se TO spin_out_se_rad_s;
ALTER TABLE estimates RENAME COLUMN delta_max_m TO delta_max_mm;
ALTER TABLE estimates RENAME COLUMN delta_max_m_se TO delta_max_se_mm;
UPDATE estimates SET delta_max_mm = delta_max_mm * 1e3, delta_max_se_mm = delta_max_se_mm * 1e3;",
    },
];

/// The measured quantities of an estimate, each as its (value, standard error) columns, units last
/// (`docs/outputs.md`): the columns of the `estimates` table and the same-named columns of `estimates.csv`,
/// in that file's order. [`crate::EstimateRecord::quantities`] gives the values in this order.
pub const ESTIMATE_QUANTITIES: [[&str; 2]; 10] = [
    ["v_in_t_m_s", "v_in_t_se_m_s"],
    ["v_in_n_m_s", "v_in_n_se_m_s"],
    ["v_out_t_m_s", "v_out_t_se_m_s"],
    ["v_out_n_m_s", "v_out_n_se_m_s"],
    ["cor", "cor_se"],
    ["mu_eff", "mu_eff_se"],
    ["contact_ms", "contact_se_ms"],
    ["delta_max_mm", "delta_max_se_mm"],
    ["spin_in_rad_s", "spin_in_se_rad_s"],
    ["spin_out_rad_s", "spin_out_se_rad_s"],
];

/// The `estimates` table's columns in export order: its key, [`ESTIMATE_QUANTITIES`] (value, error), then
/// the notes, the time and the detail.
const ESTIMATES_COLUMNS: [&str; 24] = {
    let mut out = [""; 24];
    out[0] = "shot_id";
    let mut i = 0;
    while i < ESTIMATE_QUANTITIES.len() {
        out[1 + 2 * i] = ESTIMATE_QUANTITIES[i][0];
        out[2 + 2 * i] = ESTIMATE_QUANTITIES[i][1];
        i += 1;
    }
    out[21] = "notes";
    out[22] = "created_at";
    out[23] = "detail";
    out
};

/// The `trajectory` table's columns in export order: its shot, then the trajectory row's
/// ([`bouncelab_track::TRAJECTORY_COLUMNS`]), so the table, `trajectories/<clip>.csv` and `bouncelab track`
/// share one list.
const TRAJECTORY_TABLE_COLUMNS: [&str; 11] = {
    let mut out = ["shot_id"; 11];
    let mut i = 0;
    while i < TRAJECTORY_COLUMNS.len() {
        out[1 + i] = TRAJECTORY_COLUMNS[i];
        i += 1;
    }
    out
};

/// The newest schema version this build knows.
pub fn latest_version() -> i64 {
    MIGRATIONS.last().map_or(0, |m| m.version)
}

/// A table of the store.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Table {
    /// Applied migrations.
    SchemaVersion,
    /// One row per session folder.
    Sessions,
    /// One row per (session, clip).
    Shots,
    /// One row per tracked shot: summary of its track.
    Tracks,
    /// One row per frame of a tracked shot (`docs/outputs.md` trajectory columns).
    Trajectory,
    /// One row per estimated shot (`docs/outputs.md` estimates columns).
    Estimates,
    /// Model files, each version once.
    ModelVersions,
    /// Fits of a model version to a session's shots.
    Fits,
}

impl Table {
    /// Every table, in export order.
    pub const ALL: [Table; 8] = [
        Table::SchemaVersion,
        Table::Sessions,
        Table::Shots,
        Table::Tracks,
        Table::Trajectory,
        Table::Estimates,
        Table::ModelVersions,
        Table::Fits,
    ];

    /// The SQL name (also the CSV file's stem).
    pub fn name(self) -> &'static str {
        match self {
            Table::SchemaVersion => "schema_version",
            Table::Sessions => "sessions",
            Table::Shots => "shots",
            Table::Tracks => "tracks",
            Table::Trajectory => "trajectory",
            Table::Estimates => "estimates",
            Table::ModelVersions => "model_versions",
            Table::Fits => "fits",
        }
    }

    /// Columns in their stable export order (the CSV header).
    pub fn columns(self) -> &'static [&'static str] {
        match self {
            Table::SchemaVersion => &["version", "description", "applied_at"],
            Table::Sessions => &[
                "id",
                "path",
                "description",
                "settings_hash",
                "session_toml",
                "loaded_at",
                "updated_at",
            ],
            Table::Shots => &[
                "id",
                "session_id",
                "clip",
                "surface",
                "angle_deg",
                "drop_height_m",
                "fps",
                "metadata",
                "frames_hash",
                "status",
                "error",
                "updated_at",
            ],
            Table::Tracks => &[
                "shot_id",
                "frames",
                "measured",
                "scale_m_per_px",
                "scale_se",
                "surface_y_px",
                "surface_tilt_deg",
                "warnings",
                "seconds",
                "created_at",
                "camera",
            ],
            Table::Trajectory => &TRAJECTORY_TABLE_COLUMNS,
            Table::Estimates => &ESTIMATES_COLUMNS,
            Table::ModelVersions => &["id", "name", "toml", "parent_id", "created_at"],
            Table::Fits => &[
                "id",
                "session_id",
                "model_version_id",
                "json",
                "reduced_chi2",
                "rms_m",
                "mae_pct",
                "created_at",
            ],
        }
    }

    /// The ORDER BY of the export (primary key order).
    pub(crate) fn order_by(self) -> &'static str {
        match self {
            Table::SchemaVersion => "version",
            Table::Tracks | Table::Estimates => "shot_id",
            Table::Trajectory => "shot_id, frame",
            _ => "id",
        }
    }
}

impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Table {
    type Err = StoreError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Table::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| StoreError::UnknownTable {
                name: s.to_string(),
                known: Table::ALL.map(Table::name).join(", "),
            })
    }
}
