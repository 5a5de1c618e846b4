//! Reading the `[camera]` keys shared by `session.toml` and `clip.toml`, and the fps precedence.

use std::path::{Path, PathBuf};

use crate::error::{FramesError, Result};

/// Frame rate used when neither the command line nor `clip.toml` nor `session.toml` gives one, in frames/s.
pub const DEFAULT_FPS: f64 = 10_000.0;

/// The largest frame rate accepted, in frames/s (anything above is taken as a typo).
pub const MAX_FPS: f64 = 1e7;

/// Which image direction is down the slope (SPEC §3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Downslope {
    /// Down-slope is +x_px (to the right in the image); the default. Written `"+x"`.
    #[default]
    PlusX,
    /// Down-slope is −x_px (to the left). Written `"-x"`.
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
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::DefaultFps { clip, fps } => write!(
                f,
                "{}: no frame rate given (command line, clip.toml or session.toml [camera] fps); assuming {fps} frames/s",
                clip.display()
            ),
        }
    }
}

/// The `[camera]` keys of one settings file, each optional.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct CameraKeys {
    pub fps: Option<f64>,
    pub downslope: Option<Downslope>,
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

/// Checks a frame rate: finite, > 0, ≤ [`MAX_FPS`].
pub(crate) fn check_fps(fps: f64, origin: &str, field: &str) -> Result<f64> {
    if fps.is_finite() && fps > 0.0 && fps <= MAX_FPS {
        Ok(fps)
    } else {
        Err(FramesError::BadFps {
            origin: origin.into(),
            field: field.into(),
            value: fps.to_string(),
        })
    }
}

/// The `[camera]` keys of a parsed settings file.
pub(crate) fn camera_keys(path: &Path, doc: &toml::Table) -> Result<CameraKeys> {
    let Some(camera) = doc.get("camera") else {
        return Ok(CameraKeys::default());
    };
    let camera = camera.as_table().ok_or_else(|| FramesError::BadValue {
        path: path.into(),
        field: "[camera]".into(),
        problem: "must be a table".into(),
    })?;
    let origin = path.display().to_string();
    let fps = match camera.get("fps") {
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
    let downslope = match camera.get("downslope") {
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
    Ok(CameraKeys { fps, downslope })
}

/// `[camera]` keys of `dir/name` if that file exists.
pub(crate) fn camera_keys_in(dir: &Path, name: &str) -> Result<Option<(PathBuf, CameraKeys)>> {
    let path = dir.join(name);
    if !path.is_file() {
        return Ok(None);
    }
    let doc = read_toml(&path)?;
    let keys = camera_keys(&path, &doc)?;
    Ok(Some((path, keys)))
}

/// The fps precedence of SPEC §2.1: override > `clip.toml` > `session.toml` in the parent > default.
pub(crate) fn resolve_fps(clip_dir: &Path, fps_override: Option<f64>) -> Result<(f64, FpsSource, Option<Warning>)> {
    if let Some(fps) = fps_override {
        return Ok((check_fps(fps, "command line", "--fps")?, FpsSource::Override, None));
    }
    if let Some((path, CameraKeys { fps: Some(fps), .. })) = camera_keys_in(clip_dir, "clip.toml")? {
        return Ok((fps, FpsSource::ClipToml(path), None));
    }
    if let Some(parent) = clip_dir.parent() {
        if let Some((path, CameraKeys { fps: Some(fps), .. })) = camera_keys_in(parent, "session.toml")? {
            return Ok((fps, FpsSource::SessionToml(path), None));
        }
    }
    let warning = Warning::DefaultFps {
        clip: clip_dir.into(),
        fps: DEFAULT_FPS,
    };
    Ok((DEFAULT_FPS, FpsSource::Default, Some(warning)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(text: &str) -> Result<CameraKeys> {
        camera_keys(Path::new("x/clip.toml"), &text.parse().unwrap())
    }

    #[test]
    fn fps_and_downslope_parse() {
        assert_eq!(
            keys("[camera]\nfps = 5000\ndownslope = \"-x\"").unwrap(),
            CameraKeys {
                fps: Some(5000.0),
                downslope: Some(Downslope::MinusX)
            }
        );
        assert_eq!(keys("[camera]\nfps = 2.5e4").unwrap().fps, Some(25_000.0));
        assert_eq!(keys("[session]\nname = 'a'").unwrap(), CameraKeys::default());
    }

    #[test]
    fn nonsense_fps_is_an_error_naming_file_and_field() {
        for bad in ["0", "-3", "nan", "inf", "\"fast\"", "2e7", "true"] {
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
