//! A session folder: `session.toml`, `clips.csv` and one clip (a folder of frames or a camera file) per row
//! (`docs/session.md`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::camera::{CameraFile, Kind};
use crate::clip::{Clip, ClipOptions};
use crate::error::{FramesError, Result, UnfilledRow};
use crate::settings::{
    ClipSettings, DIAMETER_RANGE_M, DROP_HEIGHT_RANGE_M, Downslope, FpsSource, MASS_RANGE_KG, Warning, camera_keys,
    camera_keys_at, check_overrides, check_range, choose_fps, choose_settings, clip_toml_path, number, read_toml,
};

/// The ball, from `session.toml`'s `[ball]` table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallSpec {
    /// Ball diameter, in metres (`diameter_m`).
    pub diameter_m: f64,
    /// Ball mass, in kilograms (`mass_kg`).
    pub mass_kg: f64,
}

/// One row of `clips.csv`, with its camera settings resolved.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ClipEntry {
    /// Clip name (the `clip` column): the name of its folder or camera file in the session folder (a camera
    /// file may be named without its extension when that is unambiguous).
    pub name: String,
    /// The clip: session folder / name — a folder of frames or a camera file.
    pub dir: PathBuf,
    /// Surface name (the `surface` column).
    pub surface: String,
    /// Surface inclination, in degrees, as in the file (the `angle_deg` column).
    pub angle_deg: f64,
    /// Drop height, in metres (the `drop_height_m` column).
    pub drop_height_m: f64,
    /// Frame rate, in frames/s: `clip.toml` > camera header > `session.toml` > 10,000 (with a warning).
    pub fps: f64,
    /// Where the frame rate came from.
    pub fps_source: FpsSource,
    /// Down-slope image direction: `clip.toml` > `session.toml` > `+x`.
    pub downslope: Downslope,
    /// Whether `clip.toml` or `session.toml` gave the down-slope direction (else `+x` is a default, which
    /// the estimator checks against the way the flights fall).
    pub downslope_given: bool,
    /// The other columns of the row, as (header, value), in header order.
    pub metadata: Vec<(String, String)>,
    /// The row's 1-based line in `clips.csv`.
    pub line: u64,
    /// Scale, ball diameter, region of interest and contact line, each with its source (`clip.toml` >
    /// `session.toml` > default).
    pub settings: ClipSettings,
    /// Largest frame accepted when the clip is opened, in pixels ([`ClipOptions::max_frame_pixels`]).
    pub max_frame_pixels: u64,
}

impl ClipEntry {
    /// The clip: its folder or camera file (same as the `dir` field).
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Opens this clip (folder or camera file) with the entry's resolved frame rate and settings; the
    /// region of interest and the contact line are checked against the frames' size.
    pub fn open(&self) -> Result<Clip> {
        Clip::open_resolved(
            self.dir.clone(),
            self.fps,
            self.fps_source.clone(),
            self.settings.clone(),
            self.max_frame_pixels,
        )
    }
}

/// A `clips.csv` row whose clip cannot be analysed — its folder or camera file absent, its name leading
/// outside the session folder, its `clip.toml` malformed or out of range: the rest of the session loads,
/// and this shot fails with [`UnusableClip::reason`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct UnusableClip {
    /// Clip name (the `clip` column).
    pub name: String,
    /// Surface name (the `surface` column).
    pub surface: String,
    /// Surface inclination, in degrees (the `angle_deg` column).
    pub angle_deg: f64,
    /// Drop height, in metres (the `drop_height_m` column).
    pub drop_height_m: f64,
    /// The other columns of the row, as (header, value), in header order.
    pub metadata: Vec<(String, String)>,
    /// The row's 1-based line in `clips.csv`.
    pub line: u64,
    /// Why it cannot be analysed: the [`FramesError`] message, naming the file or field.
    pub reason: String,
}

/// A loaded session folder. Loading reads only `session.toml`, `clips.csv` and the clips' `clip.toml`s and
/// checks that every clip folder exists; frames are read later, clip by clip.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct Session {
    /// The session folder.
    pub dir: PathBuf,
    /// The ball.
    pub ball: BallSpec,
    /// `[camera] fps` of `session.toml`, in frames/s, if given.
    pub fps: Option<f64>,
    /// `[camera] downslope` of `session.toml` (default `+x`).
    pub downslope: Downslope,
    /// The whole of `session.toml`, every table and key, in file order (metadata).
    pub metadata: toml::Table,
    /// The clips that can be opened, in `clips.csv` order.
    pub clips: Vec<ClipEntry>,
    /// The rows whose clip cannot be analysed, with the reason, in `clips.csv` order.
    pub unusable: Vec<UnusableClip>,
    /// Warnings (e.g. clips with no frame rate given).
    pub warnings: Vec<Warning>,
}

const REQUIRED_COLUMNS: [&str; 4] = ["clip", "surface", "angle_deg", "drop_height_m"];

impl Session {
    /// Loads a session folder (`docs/session.md`).
    ///
    /// `session.toml` needs `[ball] diameter_m` and `mass_kg` (positive numbers); `[camera] fps`,
    /// `downslope`, `scale_m_per_px`, `roi` and `[surface] line_y_px`, `line_tilt_deg`, `tilt_deg` are optional;
    /// anything else is kept in [`Session::metadata`]. `clips.csv` needs the columns
    /// `clip, surface, angle_deg, drop_height_m` in any order; cells are trimmed; other columns are kept per
    /// row. Lines starting with `#` are comments. Rows whose `surface`, `angle_deg` or `drop_height_m` cell
    /// is empty (as `bouncelab init` leaves them) are all listed in one [`FramesError::UnfilledColumns`].
    pub fn load(dir: impl AsRef<Path>) -> Result<Self> {
        Self::load_with(dir, &ClipOptions::default())
    }

    /// [`Session::load`] with command-line overrides applied to every clip: `options.fps` and
    /// `options.overrides` beat each clip's `clip.toml`, its camera header and `session.toml`.
    pub fn load_with(dir: impl AsRef<Path>, options: &ClipOptions) -> Result<Self> {
        if let Some(fps) = options.fps {
            crate::settings::check_fps(fps, "command line", "--fps")?;
        }
        check_overrides(&options.overrides)?;
        let dir = dir.as_ref().to_path_buf();
        let toml_path = dir.join("session.toml");
        if !toml_path.is_file() {
            return Err(FramesError::MissingFile {
                path: toml_path,
                what: "every session folder needs session.toml",
            });
        }
        let metadata = read_toml(&toml_path)?;
        let ball = BallSpec {
            diameter_m: check_range(
                positive(&toml_path, &metadata, "ball", "diameter_m")?,
                DIAMETER_RANGE_M,
                "m",
                &toml_path,
                "[ball] diameter_m",
            )?,
            mass_kg: check_range(
                positive(&toml_path, &metadata, "ball", "mass_kg")?,
                MASS_RANGE_KG,
                "kg",
                &toml_path,
                "[ball] mass_kg",
            )?,
        };
        let session_keys = camera_keys(&toml_path, &metadata)?;
        let (fps, downslope) = (session_keys.fps, session_keys.downslope.unwrap_or_default());
        let session_keys = (toml_path.clone(), session_keys);

        let csv_path = dir.join("clips.csv");
        if !csv_path.is_file() {
            return Err(FramesError::MissingFile {
                path: csv_path,
                what: "every session folder needs clips.csv",
            });
        }
        let rows = read_clips_csv(&csv_path)?;
        let mut clips = Vec::with_capacity(rows.len());
        let mut unusable = Vec::new();
        let mut warnings = Vec::new();
        for row in rows {
            match entry(&dir, row, options, &toml_path, &session_keys, &mut warnings) {
                Ok(e) => clips.push(e),
                Err(u) => unusable.push(u),
            }
        }
        let unset = clips
            .iter()
            .filter(|c| !c.downslope_given && c.angle_deg.abs() >= 1.0)
            .count();
        if unset > 0 {
            warnings.push(Warning::DefaultDownslope {
                session: toml_path.clone(),
                clips: unset,
            });
        }
        Ok(Self {
            dir,
            ball,
            fps,
            downslope,
            metadata,
            clips,
            unusable,
            warnings,
        })
    }

    /// The clip called `name`, if listed and usable.
    pub fn clip(&self, name: &str) -> Option<&ClipEntry> {
        self.clips.iter().find(|c| c.name == name)
    }

    /// Every clip name of `clips.csv`, usable or not, in file order.
    pub fn listed(&self) -> Vec<&str> {
        let mut rows: Vec<(u64, &str)> = self.clips.iter().map(|c| (c.line, c.name.as_str())).collect();
        rows.extend(self.unusable.iter().map(|u| (u.line, u.name.as_str())));
        rows.sort_unstable();
        rows.into_iter().map(|(_, n)| n).collect()
    }
}

/// One row's clip entry, or the row as unusable with why.
fn entry(
    dir: &Path,
    row: Row,
    options: &ClipOptions,
    toml_path: &Path,
    session_keys: &(PathBuf, crate::settings::CameraKeys),
    warnings: &mut Vec<Warning>,
) -> std::result::Result<ClipEntry, UnusableClip> {
    let resolved = (|| {
        let clip_dir = resolve_clip(dir, &row.name)?;
        let own = camera_keys_at(&clip_toml_path(&clip_dir))?;
        // The header's record rate, when the clip is a camera file that opens; a file that does not open
        // fails when the clip is measured, with its own error.
        let header_fps = Kind::of(&clip_dir)
            .filter(|_| clip_dir.is_file())
            .and_then(|kind| CameraFile::open(&clip_dir, kind, options.max_frame_pixels).ok())
            .and_then(|c| c.info.fps.map(|f| (f, c.path)));
        let fps = choose_fps(
            &clip_dir,
            options.fps,
            own.as_ref(),
            header_fps.as_ref().map(|(f, p)| (*f, p.as_path())),
            session_keys.1.fps.map(|f| (f, toml_path)),
        )?;
        Ok::<_, FramesError>((clip_dir, own, fps))
    })();
    let (clip_dir, own, (fps, fps_source, warning)) = match resolved {
        Ok(r) => r,
        Err(e) => {
            return Err(UnusableClip {
                name: row.name,
                surface: row.surface,
                angle_deg: row.angle_deg,
                drop_height_m: row.drop_height_m,
                metadata: row.metadata,
                line: row.line,
                reason: e.to_string(),
            });
        }
    };
    warnings.extend(warning);
    let settings = choose_settings(
        &clip_dir,
        &options.overrides,
        own.as_ref(),
        Some(session_keys),
        warnings,
    );
    let given = settings.downslope;
    let downslope = given.unwrap_or_default();
    Ok(ClipEntry {
        name: row.name,
        dir: clip_dir,
        surface: row.surface,
        angle_deg: row.angle_deg,
        drop_height_m: row.drop_height_m,
        fps,
        fps_source,
        downslope,
        downslope_given: given.is_some(),
        metadata: row.metadata,
        line: row.line,
        settings,
        max_frame_pixels: options.max_frame_pixels,
    })
}

/// The folder or camera file a `clips.csv` name stands for: the exact name in the session folder, or else
/// the one camera file whose name without extension is the clip name (a Photron clip's `.cihx`, `.cih` and
/// `.mraw` count as one, named by its header).
///
/// The name must stay inside the session folder: an absolute path or a `..` component is refused (a clip
/// reached through a symbolic link the user made inside the folder is theirs to make).
pub(crate) fn resolve_clip(session: &Path, name: &str) -> Result<PathBuf> {
    let inside = Path::new(name)
        .components()
        .all(|c| matches!(c, std::path::Component::Normal(_) | std::path::Component::CurDir));
    if !inside {
        return Err(FramesError::ClipOutsideSession {
            clip: name.into(),
            session: session.into(),
        });
    }
    let exact = session.join(name);
    if exact.exists() {
        return Ok(exact);
    }
    let mut candidates: Vec<PathBuf> = Vec::new();
    if let Ok(entries) = std::fs::read_dir(session) {
        for entry in entries.flatten() {
            let path = entry.path();
            if !path.is_file() || path.file_stem().and_then(|s| s.to_str()) != Some(name) || Kind::of(&path).is_none() {
                continue;
            }
            candidates.push(path);
        }
    }
    candidates.sort();
    candidates = photron_grouped(candidates);
    match candidates.len() {
        0 => Err(FramesError::ClipAbsent {
            clip: name.into(),
            expected: exact,
        }),
        1 => Ok(candidates.remove(0)),
        _ => Err(FramesError::AmbiguousClip {
            clip: name.into(),
            candidates,
        }),
    }
}

/// Camera files with a Photron clip's `.cihx`/`.cih`/`.mraw` reduced to one (its header, `.cihx` first).
pub(crate) fn photron_grouped(paths: Vec<PathBuf>) -> Vec<PathBuf> {
    let ext = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .unwrap_or_default()
            .to_ascii_lowercase()
    };
    let rank = |p: &Path| match ext(p).as_str() {
        "cihx" => 0,
        "cih" => 1,
        "mraw" => 2,
        _ => 3,
    };
    let mut out: Vec<PathBuf> = Vec::new();
    for p in paths {
        let r = rank(&p);
        if r < 3 {
            let stem = p.with_extension("");
            if let Some(i) = out.iter().position(|q| rank(q) < 3 && q.with_extension("") == stem) {
                if r < rank(&out[i]) {
                    out[i] = p;
                }
                continue;
            }
        }
        out.push(p);
    }
    out
}

fn positive(path: &Path, doc: &toml::Table, table: &str, key: &str) -> Result<f64> {
    let field = format!("[{table}] {key}");
    let missing = || FramesError::MissingKey {
        path: path.into(),
        field: field.clone(),
    };
    let value = doc
        .get(table)
        .and_then(|t| t.as_table())
        .ok_or_else(missing)?
        .get(key)
        .ok_or_else(missing)?;
    let x = number(path, &field, value)?;
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(FramesError::BadValue {
            path: path.into(),
            field,
            problem: format!("{x} must be a positive number"),
        })
    }
}

struct Row {
    name: String,
    surface: String,
    angle_deg: f64,
    drop_height_m: f64,
    metadata: Vec<(String, String)>,
    line: u64,
}

/// The line where a quoted field opens and never closes, if one does (the CSV reader would take the rest of
/// the file into that field and carry on without a word).
fn unterminated_quote(text: &str) -> Option<u64> {
    let mut open_at = None;
    for (i, line) in text.lines().enumerate() {
        if open_at.is_none() && line.starts_with('#') {
            continue;
        }
        for _ in line.matches('"') {
            open_at = match open_at {
                None => Some(i as u64 + 1),
                Some(_) => None,
            };
        }
    }
    open_at
}

/// A `csv` error as the session's error: the line, and a field-count mismatch said plainly.
fn csv_error(path: &Path, e: csv::Error) -> FramesError {
    FramesError::Csv {
        path: path.into(),
        line: e.position().map(csv::Position::line),
        message: match e.kind() {
            csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
                format!("{len} fields where the header has {expected_len}")
            }
            _ => e.to_string(),
        },
    }
}

/// What one data row of `clips.csv` is.
enum RowRead {
    /// A complete row.
    Clip(Row),
    /// A row with some required cells empty (collected, then reported together).
    Unfilled(UnfilledRow),
}

/// The rows of `clips.csv`: each clip named once, every required cell filled, every number finite and its
/// incline and drop height in range.
fn read_clips_csv(path: &Path) -> Result<Vec<Row>> {
    let text = std::fs::read(path).map_err(|source| FramesError::Io {
        path: path.into(),
        source,
    })?;
    if let Some(line) = unterminated_quote(&String::from_utf8_lossy(&text)) {
        return Err(FramesError::Csv {
            path: path.into(),
            line: Some(line),
            message: "a quoted field opens here and never closes (a missing `\"`)".into(),
        });
    }
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_slice());
    let headers = reader.headers().map_err(|e| csv_error(path, e))?.clone();
    let idx: Vec<usize> = REQUIRED_COLUMNS
        .iter()
        .map(|name| {
            headers
                .iter()
                .position(|h| h == *name)
                .ok_or_else(|| FramesError::MissingColumn {
                    path: path.into(),
                    column: (*name).into(),
                })
        })
        .collect::<Result<_>>()?;
    let mut rows: Vec<Row> = Vec::new();
    let mut seen: HashMap<String, u64> = HashMap::new();
    let mut unfilled = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| csv_error(path, e))?;
        match read_row(path, &headers, &idx, &record, &mut seen)? {
            RowRead::Clip(row) => rows.push(row),
            RowRead::Unfilled(u) => unfilled.push(u),
        }
    }
    if !unfilled.is_empty() {
        return Err(FramesError::UnfilledColumns {
            path: path.into(),
            rows: unfilled,
        });
    }
    if rows.is_empty() {
        return Err(FramesError::Csv {
            path: path.into(),
            line: None,
            message: "no clip rows: a session lists at least one clip under the header".into(),
        });
    }
    Ok(rows)
}

/// One data row: `idx` gives the required columns' positions, `seen` the line of every clip named so far.
fn read_row(
    path: &Path,
    headers: &csv::StringRecord,
    idx: &[usize],
    record: &csv::StringRecord,
    seen: &mut HashMap<String, u64>,
) -> Result<RowRead> {
    let line = record.position().map_or(0, csv::Position::line);
    let cell = |i: usize| record.get(idx[i]).unwrap_or_default();
    let number = |i: usize| -> Result<f64> {
        let text = cell(i);
        text.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| FramesError::BadNumber {
                path: path.into(),
                line,
                column: REQUIRED_COLUMNS[i].into(),
                value: text.into(),
            })
    };
    let name = cell(0).to_string();
    if name.is_empty() {
        return Err(FramesError::Csv {
            path: path.into(),
            line: Some(line),
            message: "empty `clip` cell".into(),
        });
    }
    if let Some(&first_line) = seen.get(&name) {
        return Err(FramesError::DuplicateClip {
            path: path.into(),
            clip: name,
            first_line,
            second_line: line,
        });
    }
    seen.insert(name.clone(), line);
    let empty: Vec<String> = (1..REQUIRED_COLUMNS.len())
        .filter(|&i| cell(i).is_empty())
        .map(|i| REQUIRED_COLUMNS[i].to_string())
        .collect();
    if !empty.is_empty() {
        return Ok(RowRead::Unfilled(UnfilledRow {
            line,
            clip: name,
            columns: empty,
        }));
    }
    let metadata = headers
        .iter()
        .zip(record.iter())
        .enumerate()
        .filter(|(i, _)| !idx.contains(i))
        .map(|(_, (h, v))| (h.to_string(), v.to_string()))
        .collect();
    let (angle_deg, drop_height_m) = (number(2)?, number(3)?);
    check_drop(path, line, angle_deg, drop_height_m)?;
    Ok(RowRead::Clip(Row {
        name,
        surface: cell(1).to_string(),
        angle_deg,
        drop_height_m,
        metadata,
        line,
    }))
}

/// The incline must be one (|β| < 90°) and the drop height within the accepted range.
fn check_drop(path: &Path, line: u64, angle_deg: f64, drop_height_m: f64) -> Result<()> {
    let bad = |column: &str, problem: String| FramesError::BadValue {
        path: path.into(),
        field: format!("line {line}, {column}"),
        problem,
    };
    if angle_deg.abs() >= 90.0 {
        return Err(bad(
            "angle_deg",
            format!(
                "{} is not an incline: it must lie between −90 and 90 degrees",
                crate::settings::short_number(angle_deg)
            ),
        ));
    }
    if !(DROP_HEIGHT_RANGE_M.0..=DROP_HEIGHT_RANGE_M.1).contains(&drop_height_m) {
        return Err(bad(
            "drop_height_m",
            format!(
                "{} is outside the accepted range {}–{} m",
                crate::settings::short_number(drop_height_m),
                DROP_HEIGHT_RANGE_M.0,
                DROP_HEIGHT_RANGE_M.1
            ),
        ));
    }
    Ok(())
}
