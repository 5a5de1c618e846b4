//! The settings keys shared by `session.toml` and `clip.toml` (`[camera]`, `[ball]`, `[surface]`), their
//! checks, and how a clip's value is chosen: command line > `clip.toml` > camera header (fps only) >
//! `session.toml` > default (see `docs/session.md`).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{FramesError, Result};

/// Frame rate used when neither the command line nor `clip.toml` nor `session.toml` gives one, in frames/s.
pub const DEFAULT_FPS: f64 = 10_000.0;

/// The largest frame rate accepted, in frames/s (anything above is taken as a typo).
pub const MAX_FPS: f64 = 1e7;

/// The smallest frame rate accepted, in frames/s: below it a contact of a few milliseconds falls between
/// two frames and the flight arcs have a handful of points, so a smaller value is a typo or a wrong unit.
pub const MIN_FPS: f64 = 100.0;

/// Accepted range of `[ball] mass_kg`, in kilograms (a table-tennis ball to a shot put, with margin).
pub const MASS_RANGE_KG: (f64, f64) = (1e-4, 100.0);

/// Accepted range of `clips.csv`'s `drop_height_m`, in metres.
pub const DROP_HEIGHT_RANGE_M: (f64, f64) = (0.0, 100.0);

/// Ball diameter assumed for a clip outside a session when nothing gives one, in metres (a tennis ball).
pub const DEFAULT_BALL_DIAMETER_M: f64 = 0.067;

/// Accepted range of `[camera] scale_m_per_px`, in metres per pixel.
pub const SCALE_RANGE_M_PER_PX: (f64, f64) = (1e-7, 1.0);

/// Accepted range of `[ball] diameter_m`, in metres.
pub const DIAMETER_RANGE_M: (f64, f64) = (1e-4, 1.0);

/// Largest accepted `|[surface] line_tilt_deg|`, in degrees.
pub const MAX_LINE_TILT_DEG: f64 = 45.0;
/// Accepted `[surface] incline_se_deg`, in degrees.
pub const INCLINE_SE_RANGE_DEG: (f64, f64) = (0.001, 10.0);

/// Which image direction is down the slope (`docs/session.md`, conventions).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Downslope {
    /// Down-slope is +x_px (to the right in the image); the default. Written `"+x"`.
    #[default]
    #[serde(rename = "+x")]
    PlusX,
    /// Down-slope is −x_px (to the left). Written `"-x"`.
    #[serde(rename = "-x")]
    MinusX,
}

/// Where a clip's frame rate came from.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum FpsSource {
    /// An explicit override (the command line).
    Override,
    /// `[camera] fps` in this `clip.toml`.
    ClipToml(PathBuf),
    /// `[camera] fps` in this `session.toml`.
    SessionToml(PathBuf),
    /// The frame rate stored in this video file (feature `opencv`).
    Container(PathBuf),
    /// The record rate in this camera file's header (`.cihx`, `.cih`, `.cine`).
    Header(PathBuf),
    /// Nothing gave one: [`DEFAULT_FPS`] (a [`Warning::DefaultFps`] is returned too).
    Default,
}

/// Something worth telling the user that does not stop the run. The library never prints; callers do.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Warning {
    /// No frame rate was given for this clip; [`DEFAULT_FPS`] is assumed.
    DefaultFps {
        /// The clip folder.
        clip: PathBuf,
        /// The frame rate assumed, in frames/s.
        fps: f64,
    },
    /// No ball diameter was given for this clip; [`DEFAULT_BALL_DIAMETER_M`] is assumed.
    DefaultDiameter {
        /// The clip.
        clip: PathBuf,
        /// The diameter assumed, in metres.
        diameter_m: f64,
    },
    /// Clips on an incline whose down-slope direction neither their `clip.toml` nor `session.toml` gives:
    /// `+x` is assumed unless a shot's flights tell otherwise.
    DefaultDownslope {
        /// The session's `session.toml`.
        session: PathBuf,
        /// How many such clips (incline of 1° or more).
        clips: usize,
    },
    /// The camera stored pixel codes that are not linear in the light (Phantom's 10-bit packed P10
    /// format is log-encoded); they are passed on as they are, monotonic but not linear.
    NonLinearPixels {
        /// The camera file.
        path: PathBuf,
        /// What the codes are.
        detail: String,
    },
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::DefaultFps { clip, fps } => write!(
                f,
                "{}: no frame rate given (command line, clip.toml or session.toml [camera] fps); assuming {fps} frames/s",
                clip.display()
            ),
            Self::DefaultDiameter { clip, diameter_m } => write!(
                f,
                "{}: no ball diameter given (command line, clip.toml or session.toml [ball] diameter_m); assuming {diameter_m} m",
                clip.display()
            ),
            Self::DefaultDownslope { session, clips } => write!(
                f,
                "{}: {clips} clip(s) on an incline give no down-slope direction ([camera] downslope, \"+x\" or \"-x\", in clip.toml or session.toml); +x is assumed unless a shot's flights clearly fall the other way, and friction and spin depend on it",
                session.display()
            ),
            Self::NonLinearPixels { path, detail } => write!(f, "{}: {detail}", path.display()),
        }
    }
}

/// A region of interest: the part of every frame the tracker looks at, in pixels (`x`, `y` of the top-left
/// corner; written `roi = [x, y, width, height]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Roi {
    /// Left column, in pixels from the image's left edge.
    pub x: u32,
    /// Top row, in pixels from the image's top edge.
    pub y: u32,
    /// Width, in pixels (≥ 1).
    pub width: u32,
    /// Height, in pixels (≥ 1).
    pub height: u32,
}

impl Roi {
    /// True if the region lies inside a `width`×`height` image.
    pub fn fits(&self, (width, height): (u32, u32)) -> bool {
        u64::from(self.x) + u64::from(self.width) <= u64::from(width)
            && u64::from(self.y) + u64::from(self.height) <= u64::from(height)
    }
}

/// The contact line given by hand: where the surface the ball touches crosses the image.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactLine {
    /// y of the line at the image's centre column, in pixels (y down, pixel centres at integers).
    pub y_px: f64,
    /// The line's tilt, in degrees, counter-clockwise as seen in the image (|tilt| ≤ 45); 0 = level.
    pub tilt_deg: f64,
}

/// Where one setting of a clip came from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum SettingSource {
    /// An explicit override (the command line).
    CommandLine,
    /// This clip's `clip.toml`.
    ClipToml(PathBuf),
    /// The session's `session.toml`.
    SessionToml(PathBuf),
    /// Nothing gave it: the documented default.
    Default,
}

impl std::fmt::Display for SettingSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::CommandLine => f.write_str("command line"),
            Self::ClipToml(p) | Self::SessionToml(p) => write!(f, "{}", p.display()),
            Self::Default => f.write_str("default"),
        }
    }
}

/// Values given on the command line for one clip; each beats `clip.toml` and `session.toml`.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct SettingOverrides {
    /// Image scale, in metres per pixel.
    pub scale_m_per_px: Option<f64>,
    /// Ball diameter, in metres.
    pub ball_diameter_m: Option<f64>,
    /// Region of interest, in pixels.
    pub roi: Option<Roi>,
    /// Contact line, in pixels and degrees.
    pub contact_line: Option<ContactLine>,
    /// The surface's tilt in the image where no line shows it, in degrees.
    pub surface_tilt_deg: Option<f64>,
}

/// A clip's resolved geometry settings, each with where it came from (`docs/session.md`).
///
/// Precedence for every key: command line > `clip.toml` > `session.toml` > default. The region of interest
/// and the contact line are checked against the frames' size when the clip is opened.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct ClipSettings {
    /// Image scale, in metres per pixel (`[camera] scale_m_per_px`); `None`: measured from the ball.
    pub scale_m_per_px: Option<f64>,
    /// Where the scale came from, when given.
    pub scale_source: Option<SettingSource>,
    /// Ball diameter, in metres (`[ball] diameter_m`).
    pub ball_diameter_m: f64,
    /// Where the diameter came from ([`SettingSource::Default`]: [`DEFAULT_BALL_DIAMETER_M`], with a
    /// [`Warning::DefaultDiameter`]).
    pub ball_diameter_source: SettingSource,
    /// Region of interest, in pixels (`[camera] roi`); `None`: the whole frame.
    pub roi: Option<Roi>,
    /// Where the region of interest came from, when given.
    pub roi_source: Option<SettingSource>,
    /// Contact line (`[surface] line_y_px`, `line_tilt_deg`); `None`: found in the image.
    pub contact_line: Option<ContactLine>,
    /// Where the contact line came from, when given.
    pub contact_line_source: Option<SettingSource>,
    /// The surface's tilt in the image, degrees counter-clockwise as seen (`[surface] tilt_deg`), for the
    /// shots whose level no line shows (the trajectory's); `None`: the image's axes, taken as level by eye.
    pub surface_tilt_deg: Option<f64>,
    /// Where that tilt came from, when given.
    pub surface_tilt_source: Option<SettingSource>,
    /// Which image direction is down the slope (`[camera] downslope`); `None`: not given, `+x` is assumed and
    /// the estimator checks it against the way the flights fall.
    #[serde(default)]
    pub downslope: Option<Downslope>,
    /// Where the down-slope direction came from, when given.
    #[serde(default)]
    pub downslope_source: Option<SettingSource>,
    /// How well the ball's fall direction is known, degrees (`[surface] incline_se_deg`: the incline's
    /// standard error and the release's sideways push); `None`: the estimator's default.
    #[serde(default)]
    pub incline_se_deg: Option<f64>,
    /// Whether the ball was released at rest, so that it falls along gravity (`[surface] dropped_from_rest`);
    /// `None`: not said, taken as dropped (`clips.csv`'s drop heights say so).
    #[serde(default)]
    pub dropped_from_rest: Option<bool>,
}

impl Default for ClipSettings {
    fn default() -> Self {
        Self {
            scale_m_per_px: None,
            scale_source: None,
            ball_diameter_m: DEFAULT_BALL_DIAMETER_M,
            ball_diameter_source: SettingSource::Default,
            roi: None,
            roi_source: None,
            contact_line: None,
            contact_line_source: None,
            surface_tilt_deg: None,
            surface_tilt_source: None,
            downslope: None,
            downslope_source: None,
            incline_se_deg: None,
            dropped_from_rest: None,
        }
    }
}

impl ClipSettings {
    /// Checks the region of interest and the contact line against the frames' size.
    pub fn check_against(&self, clip: &Path, size: (u32, u32)) -> Result<()> {
        if let Some(roi) = self.roi
            && !roi.fits(size)
        {
            return Err(FramesError::RoiOutsideImage {
                clip: clip.into(),
                roi,
                origin: origin_of(self.roi_source.as_ref()),
                size,
            });
        }
        if let Some(line) = self.contact_line
            && !(line.y_px >= 0.0 && line.y_px <= f64::from(size.1.saturating_sub(1)))
        {
            return Err(FramesError::LineOutsideImage {
                clip: clip.into(),
                line_y_px: line.y_px,
                origin: origin_of(self.contact_line_source.as_ref()),
                size,
            });
        }
        Ok(())
    }
}

fn origin_of(source: Option<&SettingSource>) -> String {
    source.map_or_else(|| "unknown".to_string(), ToString::to_string)
}

/// The settings keys of one file, each optional.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct CameraKeys {
    pub fps: Option<f64>,
    pub downslope: Option<Downslope>,
    pub scale_m_per_px: Option<f64>,
    pub diameter_m: Option<f64>,
    pub roi: Option<Roi>,
    pub contact_line: Option<ContactLine>,
    pub surface_tilt_deg: Option<f64>,
    pub incline_se_deg: Option<f64>,
    pub dropped_from_rest: Option<bool>,
}

/// Reads and parses a TOML file into a table.
pub(crate) fn read_toml(path: &Path) -> Result<toml::Table> {
    let text = std::fs::read_to_string(path).map_err(|source| FramesError::Io {
        path: path.into(),
        source,
    })?;
    text.parse::<toml::Table>().map_err(|e| FramesError::Toml {
        path: path.into(),
        message: e.to_string().trim_end().replace('\n', " "),
    })
}

/// Checks a frame rate: finite, in [[`MIN_FPS`], [`MAX_FPS`]].
pub(crate) fn check_fps(fps: f64, origin: &str, field: &str) -> Result<f64> {
    if fps.is_finite() && (MIN_FPS..=MAX_FPS).contains(&fps) {
        Ok(fps)
    } else {
        Err(FramesError::BadFps {
            origin: origin.into(),
            field: field.into(),
            value: fps.to_string(),
        })
    }
}

/// A number as a person reads it: plain when moderate, in e-notation when huge or tiny.
pub(crate) fn short_number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Checks a value against a closed range, naming the file, key, unit and range.
pub(crate) fn check_range(x: f64, (lo, hi): (f64, f64), unit: &str, path: &Path, field: &str) -> Result<f64> {
    if x.is_finite() && x >= lo && x <= hi {
        Ok(x)
    } else {
        Err(FramesError::BadValue {
            path: path.into(),
            field: field.into(),
            problem: format!("{} is outside the accepted range {lo:e}–{hi:e} {unit}", short_number(x)),
        })
    }
}

/// The number under `key` in the `[section]` table of the file at `path`, checked against `range`; `None`
/// when the key is absent.
fn ranged(
    path: &Path,
    table: &toml::Table,
    section: &str,
    key: &str,
    range: (f64, f64),
    unit: &str,
) -> Result<Option<f64>> {
    let field = format!("[{section}] {key}");
    table
        .get(key)
        .map(|v| check_range(number(path, &field, v)?, range, unit, path, &field))
        .transpose()
}

fn table<'a>(path: &Path, doc: &'a toml::Table, name: &str) -> Result<Option<&'a toml::Table>> {
    match doc.get(name) {
        None => Ok(None),
        Some(toml::Value::Table(t)) => Ok(Some(t)),
        Some(_) => Err(FramesError::BadValue {
            path: path.into(),
            field: format!("[{name}]"),
            problem: "must be a table".into(),
        }),
    }
}

/// A number (integer or float) or a type error naming the file and key.
pub(crate) fn number(path: &Path, field: &str, value: &toml::Value) -> Result<f64> {
    match value {
        toml::Value::Integer(i) => Ok(*i as f64),
        toml::Value::Float(x) => Ok(*x),
        other => Err(FramesError::BadValue {
            path: path.into(),
            field: field.into(),
            problem: format!("{other} is a {}, not a number", other.type_str()),
        }),
    }
}

fn roi(path: &Path, value: &toml::Value) -> Result<Roi> {
    let field = "[camera] roi";
    let bad = |problem: String| FramesError::BadValue {
        path: path.into(),
        field: field.into(),
        problem,
    };
    let items = value.as_array().filter(|a| a.len() == 4).ok_or_else(|| {
        bad(format!(
            "{value} is not [x, y, width, height] (four whole numbers of pixels)"
        ))
    })?;
    let mut v = [0u32; 4];
    for (slot, item) in v.iter_mut().zip(items) {
        *slot = item
            .as_integer()
            .and_then(|i| u32::try_from(i).ok())
            .ok_or_else(|| bad(format!("{item} is not a whole number of pixels ≥ 0")))?;
    }
    if v[2] == 0 || v[3] == 0 {
        return Err(bad("width and height must be at least 1 pixel".into()));
    }
    Ok(Roi {
        x: v[0],
        y: v[1],
        width: v[2],
        height: v[3],
    })
}

/// The settings keys of a parsed settings file (`[camera]`, `[ball] diameter_m`, `[surface]`).
pub(crate) fn camera_keys(path: &Path, doc: &toml::Table) -> Result<CameraKeys> {
    let mut keys = CameraKeys::default();
    if let Some(camera) = table(path, doc, "camera")? {
        let origin = path.display().to_string();
        keys.fps = match camera.get("fps") {
            None => None,
            Some(toml::Value::Integer(i)) => Some(check_fps(*i as f64, &origin, "[camera] fps")?),
            Some(toml::Value::Float(x)) => Some(check_fps(*x, &origin, "[camera] fps")?),
            Some(other) => {
                return Err(FramesError::BadFps {
                    origin,
                    field: "[camera] fps".into(),
                    value: other.to_string(),
                });
            }
        };
        keys.downslope = match camera.get("downslope") {
            None => None,
            Some(v) => Some(match v.as_str().map(str::trim) {
                Some("+x") => Downslope::PlusX,
                Some("-x") => Downslope::MinusX,
                _ => {
                    return Err(FramesError::BadValue {
                        path: path.into(),
                        field: "[camera] downslope".into(),
                        problem: format!("{v} is not \"+x\" or \"-x\""),
                    });
                }
            }),
        };
        keys.scale_m_per_px = ranged(path, camera, "camera", "scale_m_per_px", SCALE_RANGE_M_PER_PX, "m/px")?;
        if let Some(v) = camera.get("roi") {
            keys.roi = Some(roi(path, v)?);
        }
    }
    if let Some(ball) = table(path, doc, "ball")? {
        keys.diameter_m = ranged(path, ball, "ball", "diameter_m", DIAMETER_RANGE_M, "m")?;
    }
    if let Some(surface) = table(path, doc, "surface")? {
        keys.incline_se_deg = ranged(
            path,
            surface,
            "surface",
            "incline_se_deg",
            INCLINE_SE_RANGE_DEG,
            "degrees",
        )?;
        if let Some(v) = surface.get("dropped_from_rest") {
            keys.dropped_from_rest = Some(v.as_bool().ok_or_else(|| FramesError::BadValue {
                path: path.into(),
                field: "[surface] dropped_from_rest".into(),
                problem: format!("must be true or false, not {v}"),
            })?);
        }
        let tilt_range = (-MAX_LINE_TILT_DEG, MAX_LINE_TILT_DEG);
        keys.surface_tilt_deg = ranged(path, surface, "surface", "tilt_deg", tilt_range, "degrees")?;
        let y = surface
            .get("line_y_px")
            .map(|v| number(path, "[surface] line_y_px", v))
            .transpose()?;
        let tilt = surface
            .get("line_tilt_deg")
            .map(|v| number(path, "[surface] line_tilt_deg", v))
            .transpose()?;
        match (y, tilt) {
            (None, None) => {}
            (None, Some(_)) => {
                return Err(FramesError::BadValue {
                    path: path.into(),
                    field: "[surface] line_tilt_deg".into(),
                    problem: "given without [surface] line_y_px (the line's y at the image's centre column); for a tilt alone, with the level left to the image or the trajectory, use [surface] tilt_deg".into(),
                });
            }
            (Some(y), tilt) => {
                if !(y.is_finite() && y >= 0.0) {
                    return Err(FramesError::BadValue {
                        path: path.into(),
                        field: "[surface] line_y_px".into(),
                        problem: format!("{y} is not a pixel row (a number ≥ 0)"),
                    });
                }
                let tilt = tilt.unwrap_or(0.0);
                check_range(
                    tilt,
                    (-MAX_LINE_TILT_DEG, MAX_LINE_TILT_DEG),
                    "degrees",
                    path,
                    "[surface] line_tilt_deg",
                )?;
                keys.contact_line = Some(ContactLine {
                    y_px: y,
                    tilt_deg: tilt,
                });
            }
        }
    }
    Ok(keys)
}

/// The settings keys of the file at `path`, if it exists.
pub(crate) fn camera_keys_at(path: &Path) -> Result<Option<(PathBuf, CameraKeys)>> {
    if !path.is_file() {
        return Ok(None);
    }
    let doc = read_toml(path)?;
    let keys = camera_keys(path, &doc)?;
    Ok(Some((path.to_path_buf(), keys)))
}

/// A clip's own settings file: `DIR/clip.toml` for a clip folder, `NAME.clip.toml` beside a camera file
/// `NAME.EXT` (the last extension dropped: `shot1.cihx` → `shot1.clip.toml`).
pub fn clip_toml_path(clip: &Path) -> PathBuf {
    if clip.is_dir() {
        return clip.join("clip.toml");
    }
    let stem = clip
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    clip.with_file_name(format!("{stem}.clip.toml"))
}

/// The `session.toml` that applies to a clip: the one in the folder holding the clip.
pub(crate) fn session_toml_path(clip: &Path) -> Option<PathBuf> {
    match clip.parent() {
        // `track .` names the clip by a path with no parent in it: the folder holding it is found on disk.
        Some(p) if !p.as_os_str().is_empty() => Some(p.join("session.toml")),
        _ => clip.canonicalize().ok()?.parent().map(|p| p.join("session.toml")),
    }
}

/// The fps precedence (`docs/session.md`): override > `clip.toml` > the camera file's header >
/// `session.toml` > [`DEFAULT_FPS`] with a warning.
pub(crate) fn choose_fps(
    clip: &Path,
    fps_override: Option<f64>,
    own: Option<&(PathBuf, CameraKeys)>,
    header: Option<(f64, &Path)>,
    session: Option<(f64, &Path)>,
) -> Result<(f64, FpsSource, Option<Warning>)> {
    if let Some(fps) = fps_override {
        return Ok((check_fps(fps, "command line", "--fps")?, FpsSource::Override, None));
    }
    if let Some((path, CameraKeys { fps: Some(fps), .. })) = own {
        return Ok((*fps, FpsSource::ClipToml(path.clone()), None));
    }
    if let Some((fps, path)) = header {
        let fps = check_fps(fps, &path.display().to_string(), "header record rate")?;
        return Ok((fps, FpsSource::Header(path.into()), None));
    }
    if let Some((fps, path)) = session {
        return Ok((fps, FpsSource::SessionToml(path.into()), None));
    }
    let warning = Warning::DefaultFps {
        clip: clip.into(),
        fps: DEFAULT_FPS,
    };
    Ok((DEFAULT_FPS, FpsSource::Default, Some(warning)))
}

/// The geometry settings' precedence: override > `clip.toml` > `session.toml` > default.
pub(crate) fn choose_settings(
    clip: &Path,
    overrides: &SettingOverrides,
    own: Option<&(PathBuf, CameraKeys)>,
    session: Option<&(PathBuf, CameraKeys)>,
    warnings: &mut Vec<Warning>,
) -> ClipSettings {
    fn pick<T: Copy>(
        over: Option<T>,
        own: Option<&(PathBuf, CameraKeys)>,
        session: Option<&(PathBuf, CameraKeys)>,
        get: impl Fn(&CameraKeys) -> Option<T>,
    ) -> Option<(T, SettingSource)> {
        if let Some(v) = over {
            return Some((v, SettingSource::CommandLine));
        }
        if let Some((p, k)) = own
            && let Some(v) = get(k)
        {
            return Some((v, SettingSource::ClipToml(p.clone())));
        }
        session.and_then(|(p, k)| get(k).map(|v| (v, SettingSource::SessionToml(p.clone()))))
    }
    let scale = pick(overrides.scale_m_per_px, own, session, |k| k.scale_m_per_px);
    let diameter = pick(overrides.ball_diameter_m, own, session, |k| k.diameter_m);
    let roi = pick(overrides.roi, own, session, |k| k.roi);
    let line = pick(overrides.contact_line, own, session, |k| k.contact_line);
    let tilt = pick(overrides.surface_tilt_deg, own, session, |k| k.surface_tilt_deg);
    let downslope = pick(None, own, session, |k| k.downslope);
    let incline_se_deg = pick(None, own, session, |k| k.incline_se_deg).map(|(v, _)| v);
    let dropped_from_rest = pick(None, own, session, |k| k.dropped_from_rest).map(|(v, _)| v);
    let (ball_diameter_m, ball_diameter_source) = diameter.unwrap_or_else(|| {
        warnings.push(Warning::DefaultDiameter {
            clip: clip.into(),
            diameter_m: DEFAULT_BALL_DIAMETER_M,
        });
        (DEFAULT_BALL_DIAMETER_M, SettingSource::Default)
    });
    fn split<T>(x: Option<(T, SettingSource)>) -> (Option<T>, Option<SettingSource>) {
        match x {
            Some((v, s)) => (Some(v), Some(s)),
            None => (None, None),
        }
    }
    let (scale_m_per_px, scale_source) = split(scale);
    let (roi, roi_source) = split(roi);
    let (contact_line, contact_line_source) = split(line);
    let (surface_tilt_deg, surface_tilt_source) = split(tilt);
    let (downslope, downslope_source) = split(downslope);
    ClipSettings {
        scale_m_per_px,
        scale_source,
        ball_diameter_m,
        ball_diameter_source,
        roi,
        roi_source,
        contact_line,
        contact_line_source,
        surface_tilt_deg,
        surface_tilt_source,
        downslope,
        downslope_source,
        incline_se_deg,
        dropped_from_rest,
    }
}

/// Checks command-line overrides with the same ranges as the files.
pub(crate) fn check_overrides(o: &SettingOverrides) -> Result<()> {
    let cl = Path::new("command line");
    if let Some(s) = o.scale_m_per_px {
        check_range(s, SCALE_RANGE_M_PER_PX, "m/px", cl, "--scale")?;
    }
    if let Some(d) = o.ball_diameter_m {
        check_range(d, DIAMETER_RANGE_M, "m", cl, "--diameter")?;
    }
    if let Some(l) = o.contact_line {
        check_range(l.y_px, (0.0, f64::MAX), "px", cl, "--line-y")?;
        check_range(
            l.tilt_deg,
            (-MAX_LINE_TILT_DEG, MAX_LINE_TILT_DEG),
            "degrees",
            cl,
            "--line-tilt",
        )?;
    }
    if let Some(t) = o.surface_tilt_deg {
        check_range(t, (-MAX_LINE_TILT_DEG, MAX_LINE_TILT_DEG), "degrees", cl, "--tilt")?;
    }
    if let Some(r) = o.roi
        && (r.width == 0 || r.height == 0)
    {
        return Err(FramesError::BadValue {
            path: cl.into(),
            field: "--roi".into(),
            problem: "width and height must be at least 1 pixel".into(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(text: &str) -> Result<CameraKeys> {
        camera_keys(Path::new("x/clip.toml"), &text.parse().unwrap())
    }

    #[test]
    fn the_fall_s_keys_parse_and_bad_ones_are_named() {
        let k = keys("[surface]\nincline_se_deg = 0.2\ndropped_from_rest = false").unwrap();
        assert_eq!((k.incline_se_deg, k.dropped_from_rest), (Some(0.2), Some(false)));
        for (text, field) in [
            ("[surface]\nincline_se_deg = 0", "[surface] incline_se_deg"),
            ("[surface]\nincline_se_deg = 45", "[surface] incline_se_deg"),
            ("[surface]\ndropped_from_rest = \"yes\"", "[surface] dropped_from_rest"),
        ] {
            match keys(text) {
                Err(FramesError::BadValue { field: f, path, .. }) => {
                    assert_eq!(
                        (f.as_str(), path.as_path()),
                        (field, Path::new("x/clip.toml")),
                        "{text}"
                    )
                }
                other => panic!("{text}: {other:?}"),
            }
        }
    }

    #[test]
    fn fps_and_downslope_parse() {
        assert_eq!(
            keys("[camera]\nfps = 5000\ndownslope = \"-x\"").unwrap(),
            CameraKeys {
                fps: Some(5000.0),
                downslope: Some(Downslope::MinusX),
                ..CameraKeys::default()
            }
        );
        assert_eq!(keys("[camera]\nfps = 2.5e4").unwrap().fps, Some(25_000.0));
        assert_eq!(keys("[session]\nname = 'a'").unwrap(), CameraKeys::default());
    }

    #[test]
    fn nonsense_fps_is_an_error_naming_file_and_field() {
        for bad in [
            "0", "-3", "nan", "inf", "\"fast\"", "2e7", "true", "0.5", "1", "99.9", "1e-300",
        ] {
            let err = keys(&format!("[camera]\nfps = {bad}")).unwrap_err();
            assert!(matches!(err, FramesError::BadFps { .. }), "{bad}: {err}");
            let msg = err.to_string();
            assert!(msg.contains("clip.toml") && msg.contains("[camera] fps"), "{msg}");
        }
        assert!(matches!(
            check_fps(f64::NAN, "command line", "--fps"),
            Err(FramesError::BadFps { .. })
        ));
    }

    #[test]
    fn bad_downslope_names_the_field() {
        let msg = keys("[camera]\ndownslope = \"up\"").unwrap_err().to_string();
        assert!(msg.contains("[camera] downslope"), "{msg}");
    }
}
