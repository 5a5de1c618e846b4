//! A session folder: `session.toml`, `clips.csv` and one clip folder per row (SPEC §2.7).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::clip::Clip;
use crate::error::{FramesError, Result};
use crate::settings::{CameraKeys, DEFAULT_FPS, Downslope, FpsSource, Warning, camera_keys, camera_keys_in, read_toml};

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
    /// Clip name (the `clip` column); also the name of its folder.
    pub name: String,
    /// The clip folder: session folder / name.
    pub dir: PathBuf,
    /// Surface name (the `surface` column).
    pub surface: String,
    /// Surface inclination, in degrees, as in the file (the `angle_deg` column).
    pub angle_deg: f64,
    /// Drop height, in metres (the `drop_height_m` column).
    pub drop_height_m: f64,
    /// Frame rate, in frames/s: `clip.toml` > `session.toml` > 10,000 (with a warning).
    pub fps: f64,
    /// Where the frame rate came from.
    pub fps_source: FpsSource,
    /// Down-slope image direction: `clip.toml` > `session.toml` > `+x`.
    pub downslope: Downslope,
    /// The other columns of the row, as (header, value), in header order.
    pub metadata: Vec<(String, String)>,
    /// The row's 1-based line in `clips.csv`.
    pub line: u64,
}

impl ClipEntry {
    /// Opens this clip's folder with the entry's resolved frame rate.
    pub fn open(&self) -> Result<Clip> {
        Clip::open_resolved(self.dir.clone(), self.fps, self.fps_source.clone(), Vec::new())
    }
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
    /// The clips, in `clips.csv` order.
    pub clips: Vec<ClipEntry>,
    /// Warnings (e.g. clips with no frame rate given).
    pub warnings: Vec<Warning>,
}

const REQUIRED_COLUMNS: [&str; 4] = ["clip", "surface", "angle_deg", "drop_height_m"];

impl Session {
    /// Loads a session folder.
    ///
    /// `session.toml` needs `[ball] diameter_m` and `mass_kg` (positive numbers); `[camera] fps` and
    /// `downslope` are optional; anything else is kept in [`Session::metadata`]. `clips.csv` needs the
    /// columns `clip, surface, angle_deg, drop_height_m` in any order; cells are trimmed; other columns are
    /// kept per row. Lines starting with `#` are comments.
    pub fn load(dir: impl AsRef<Path>) -> Result<Self> {
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
            diameter_m: positive(&toml_path, &metadata, "ball", "diameter_m")?,
            mass_kg: positive(&toml_path, &metadata, "ball", "mass_kg")?,
        };
        let CameraKeys { fps, downslope } = camera_keys(&toml_path, &metadata)?;
        let downslope = downslope.unwrap_or_default();

        let csv_path = dir.join("clips.csv");
        if !csv_path.is_file() {
            return Err(FramesError::MissingFile {
                path: csv_path,
                what: "every session folder needs clips.csv",
            });
        }
        let rows = read_clips_csv(&csv_path)?;
        let mut clips = Vec::with_capacity(rows.len());
        let mut warnings = Vec::new();
        for row in rows {
            let clip_dir = dir.join(&row.name);
            if !clip_dir.is_dir() {
                return Err(FramesError::ClipAbsent {
                    clip: row.name,
                    expected: clip_dir,
                });
            }
            let own = camera_keys_in(&clip_dir, "clip.toml")?;
            let (fps, fps_source) = match (&own, fps) {
                (Some((path, CameraKeys { fps: Some(f), .. })), _) => (*f, FpsSource::ClipToml(path.clone())),
                (_, Some(f)) => (f, FpsSource::SessionToml(toml_path.clone())),
                _ => {
                    warnings.push(Warning::DefaultFps {
                        clip: clip_dir.clone(),
                        fps: DEFAULT_FPS,
                    });
                    (DEFAULT_FPS, FpsSource::Default)
                }
            };
            let downslope = own.and_then(|(_, k)| k.downslope).unwrap_or(downslope);
            clips.push(ClipEntry {
                name: row.name,
                dir: clip_dir,
                surface: row.surface,
                angle_deg: row.angle_deg,
                drop_height_m: row.drop_height_m,
                fps,
                fps_source,
                downslope,
                metadata: row.metadata,
                line: row.line,
            });
        }
        Ok(Self {
            dir,
            ball,
            fps,
            downslope,
            metadata,
            clips,
            warnings,
        })
    }

    /// The clip called `name`, if listed.
    pub fn clip(&self, name: &str) -> Option<&ClipEntry> {
        self.clips.iter().find(|c| c.name == name)
    }
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
    let x = match value {
        toml::Value::Integer(i) => *i as f64,
        toml::Value::Float(x) => *x,
        other => {
            return Err(FramesError::BadValue {
                path: path.into(),
                field,
                problem: format!("{other} is a {}, not a number", other.type_str()),
            });
        }
    };
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

fn read_clips_csv(path: &Path) -> Result<Vec<Row>> {
    let csv_err = |e: csv::Error| FramesError::Csv {
        path: path.into(),
        line: e.position().map(csv::Position::line),
        message: match e.kind() {
            csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
                format!("{len} fields where the header has {expected_len}")
            }
            _ => e.to_string(),
        },
    };
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(csv_err)?;
    let headers = reader.headers().map_err(csv_err)?.clone();
    let column = |name: &str| -> Result<usize> {
        headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| FramesError::MissingColumn {
                path: path.into(),
                column: name.into(),
            })
    };
    let idx: Vec<usize> = REQUIRED_COLUMNS.iter().map(|c| column(c)).collect::<Result<_>>()?;
    let mut rows: Vec<Row> = Vec::new();
    let mut seen: HashMap<String, u64> = HashMap::new();
    for record in reader.records() {
        let record = record.map_err(csv_err)?;
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
        let metadata = headers
            .iter()
            .zip(record.iter())
            .enumerate()
            .filter(|(i, _)| !idx.contains(i))
            .map(|(_, (h, v))| (h.to_string(), v.to_string()))
            .collect();
        rows.push(Row {
            name,
            surface: cell(1).to_string(),
            angle_deg: number(2)?,
            drop_height_m: number(3)?,
            metadata,
            line,
        });
    }
    Ok(rows)
}
