//! A new session from a folder of recordings: find the clips (folders of frames and camera files), read
//! their headers, guess each clip's surface, angle and drop height from its name, and write `session.toml`
//! and `clips.csv` for a person to complete (`bouncelab init`, `docs/session.md`).

use std::path::{Path, PathBuf};

use crate::camera::{CameraFile, DEFAULT_MAX_FRAME_PIXELS, Kind, SourceFormat};
use crate::error::{FramesError, Result};
use crate::session::photron_grouped;
use crate::settings::{DIAMETER_RANGE_M, Downslope, check_range};

/// What a clip's name says about its conditions (see [`guess_from_name`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NameGuess {
    /// Surface name: the name's words other than a few generic ones (`shot`, `clip`, `take` …), joined by `_`.
    pub surface: Option<String>,
    /// Surface inclination, in degrees (a word like `15deg`).
    pub angle_deg: Option<f64>,
    /// Drop height, in metres (a word like `550mm`, `55cm` or `0.55m`).
    pub drop_height_m: Option<f64>,
}

/// Words that name no surface.
const GENERIC: [&str; 16] = [
    "shot", "clip", "take", "run", "trial", "drop", "ball", "test", "cam", "camera", "rec", "video", "stack", "frames",
    "img", "image",
];

/// A word that may name a surface: two or more letters, then optional digits (`clay`, `tape1`), not a
/// generic word; `r1`, `s001` and camera counters such as `c001h001s0001` are not.
fn surface_word(t: &str) -> Option<String> {
    let letters = t.bytes().take_while(u8::is_ascii_alphabetic).count();
    let rest = &t[letters..];
    (letters >= 2 && rest.bytes().all(|b| b.is_ascii_digit()) && !GENERIC.contains(&&t[..letters]))
        .then(|| t.to_string())
}

/// Guesses surface, angle and drop height from a clip name such as `clay_15deg_550mm` or `tape-0deg-1.2m-03`.
///
/// The name (without its extension) is split at `_`, `-` and spaces. A word `<number>deg` (or `°`) is the
/// angle; `<number>mm`, `cm` or `m` the drop height; the remaining words of two or more letters (optionally
/// followed by digits: `tape1`), less generic ones (`shot`, `run` …) and repeats, form the surface — only
/// when an angle or a height was found too, so that `shot_01` guesses nothing.
pub fn guess_from_name(name: &str) -> NameGuess {
    let mut g = NameGuess::default();
    let mut words = Vec::new();
    for token in name.split(['_', '-', ' ']).filter(|t| !t.is_empty()) {
        let t = token.to_ascii_lowercase();
        let num = |suffix: &str| {
            t.strip_suffix(suffix)
                .and_then(|n| n.parse::<f64>().ok())
                .filter(|x| x.is_finite())
        };
        if let Some(a) = num("deg").or_else(|| num("°")).or_else(|| num("degrees")) {
            g.angle_deg.get_or_insert(a);
        } else if let Some(h) = num("mm") {
            g.drop_height_m.get_or_insert(h / 1000.0);
        } else if let Some(h) = num("cm") {
            g.drop_height_m.get_or_insert(h / 100.0);
        } else if let Some(h) = num("m") {
            g.drop_height_m.get_or_insert(h);
        } else if let Some(word) = surface_word(&t)
            && !words.contains(&word)
        {
            words.push(word);
        }
    }
    if (g.angle_deg.is_some() || g.drop_height_m.is_some()) && !words.is_empty() {
        g.surface = Some(words.join("_"));
    }
    g
}

/// One clip found in the folder.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct FoundClip {
    /// The name written in `clips.csv`: the folder's or camera file's name (a Photron clip by its header).
    pub name: String,
    /// The folder or camera file.
    pub path: PathBuf,
    /// What it is stored as.
    pub format: SourceFormat,
    /// Frames in it, when it could be read.
    pub frames: Option<usize>,
    /// Record rate from its header, in frames/s.
    pub fps: Option<f64>,
    /// What its name says.
    pub guess: NameGuess,
    /// Why it could not be read, if it could not (it is listed all the same).
    pub problem: Option<String>,
}

/// What [`scan`] found in a folder.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct Draft {
    /// The folder.
    pub dir: PathBuf,
    /// The clips, in name order.
    pub clips: Vec<FoundClip>,
    /// Entries that look like recordings but are not listed, with why (a folder without frames, a video).
    pub skipped: Vec<(PathBuf, String)>,
}

/// How to write a draft session.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct InitOptions {
    /// Ball diameter, in metres; `None` leaves the key for a person to fill (loading then names it).
    pub diameter_m: Option<f64>,
    /// Ball mass, in kilograms; `None` likewise.
    pub mass_kg: Option<f64>,
    /// Which image direction is down the slope; `None` writes the key commented out, so that each shot's
    /// flights are checked against `+x` and, where they clearly fall the other way, tell it.
    pub downslope: Option<Downslope>,
    /// Overwrite an existing `session.toml` or `clips.csv`.
    pub force: bool,
}

const SETTINGS_FILES: [&str; 2] = ["session.toml", "clips.csv"];

/// Finds the clips in `dir`: every sub-folder holding frame files (or one TIFF stack) and every camera
/// file (`.cihx`/`.cih`/`.mraw`, `.cine`, `.tif`/`.tiff`); reads each header for its frame count and fps.
pub fn scan(dir: impl AsRef<Path>) -> Result<Draft> {
    let dir = dir.as_ref();
    if !dir.is_dir() {
        return Err(FramesError::NotAFolder { path: dir.into() });
    }
    let io = |source| FramesError::Io {
        path: dir.into(),
        source,
    };
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| !n.starts_with('.'))
        })
        .collect();
    entries.sort();
    let mut draft = Draft {
        dir: dir.into(),
        ..Draft::default()
    };
    let (folders, files): (Vec<_>, Vec<_>) = entries.into_iter().partition(|p| p.is_dir());
    for folder in folders {
        match crate::clip::Frames::probe(&folder, DEFAULT_MAX_FRAME_PIXELS) {
            Ok(frames) => {
                let (format, fps) = match &frames.camera {
                    Some(c) => (c.info.format, c.info.fps),
                    None => (SourceFormat::Folder, None),
                };
                draft
                    .clips
                    .push(found(&folder, format, Some(frames.files.len()), fps, None));
            }
            Err(FramesError::NoFrames { .. }) => draft.skipped.push((folder, "no frame files in it".into())),
            Err(e) => draft
                .clips
                .push(found(&folder, SourceFormat::Folder, None, None, Some(e.to_string()))),
        }
    }
    let cameras: Vec<PathBuf> = files.into_iter().filter(|p| Kind::of(p).is_some()).collect();
    for path in photron_grouped(cameras) {
        let kind = Kind::of(&path).expect("filtered above");
        if kind == Kind::Video {
            draft
                .skipped
                .push((path.clone(), crate::camera::video_error(&path).to_string()));
            continue;
        }
        match CameraFile::open(&path, kind, DEFAULT_MAX_FRAME_PIXELS) {
            Ok(cam) => draft
                .clips
                .push(found(&path, cam.info.format, Some(cam.count), cam.info.fps, None)),
            Err(e) => {
                let format = match kind {
                    Kind::Photron => SourceFormat::PhotronMraw,
                    Kind::Cine => SourceFormat::PhantomCine,
                    _ => SourceFormat::TiffStack,
                };
                draft.clips.push(found(&path, format, None, None, Some(e.to_string())));
            }
        }
    }
    draft.clips.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(draft)
}

fn found(
    path: &Path,
    format: SourceFormat,
    frames: Option<usize>,
    fps: Option<f64>,
    problem: Option<String>,
) -> FoundClip {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = if path.is_dir() {
        name.clone()
    } else {
        path.file_stem()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    FoundClip {
        guess: guess_from_name(&stem),
        name,
        path: path.into(),
        format,
        frames,
        fps,
        problem,
    }
}

impl Draft {
    /// The record rate every camera header agrees on, if there are headers and they agree.
    pub fn common_fps(&self) -> Option<f64> {
        let mut rates = self.clips.iter().filter_map(|c| c.fps);
        let first = rates.next()?;
        rates.all(|r| r == first).then_some(first)
    }

    /// The text of `session.toml`.
    pub fn session_toml(&self, o: &InitOptions) -> String {
        let name = self
            .dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let mut t = String::from("# Written by `bouncelab init`; every key is described in docs/session.md.\n\n");
        t += &format!("[session]\ndescription = {}\n\n[ball]\n", toml::Value::from(name));
        match o.diameter_m {
            Some(d) => t += &format!("diameter_m = {d:?}\n"),
            None => t += "# diameter_m = ...   # REQUIRED: the ball's diameter, in metres (e.g. 0.067)\n",
        }
        match o.mass_kg {
            Some(m) => t += &format!("mass_kg = {m:?}\n"),
            None => t += "# mass_kg = ...      # REQUIRED: the ball's mass, in kilograms (e.g. 0.0567)\n",
        }
        t += "\n[camera]\n";
        let headers: Vec<f64> = self.clips.iter().filter_map(|c| c.fps).collect();
        let headerless = self.clips.iter().filter(|c| c.fps.is_none()).count();
        match self.common_fps() {
            Some(f) if headerless == 0 => {
                t +=
                    &format!("fps = {f:?}   # from the camera headers (each header's own rate is used for its clip)\n");
            }
            Some(f) => {
                t += &format!(
                    "fps = {f:?}   # from the camera headers; used for the {headerless} clip(s) without one: check it\n"
                )
            }
            None if headers.is_empty() => {
                t += "# fps = ...   # frames/s: no clip has a header giving it; without it 10000 is assumed (with a warning)\n";
            }
            None => {
                let mut distinct: Vec<f64> = headers.clone();
                distinct.sort_by(f64::total_cmp);
                distinct.dedup();
                t += &format!(
                    "# fps = ...   # camera headers differ ({}): each clip uses its own header's rate\n",
                    distinct.iter().map(|f| format!("{f}")).collect::<Vec<_>>().join(", ")
                );
            }
        }
        t += &match o.downslope {
            Some(d) => format!(
                "downslope = \"{}\"   # which image direction is down the slope: \"+x\" (right) or \"-x\" (left)\n",
                match d {
                    Downslope::PlusX => "+x",
                    Downslope::MinusX => "-x",
                }
            ),
            None => "# downslope = \"+x\"   # which image direction is down the slope: \"+x\" (right) or \"-x\" (left); unset, +x is assumed unless a shot's flights clearly fall the other way (docs/session.md)\n".to_string(),
        };
        t
    }

    /// The text of `clips.csv`: one row per clip, guessed cells filled, the others empty.
    pub fn clips_csv(&self) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        let cell = |x: Option<f64>| x.map(|v| format!("{v}")).unwrap_or_default();
        w.write_record(["clip", "surface", "angle_deg", "drop_height_m"])
            .expect("in memory");
        for c in &self.clips {
            w.write_record([
                c.name.clone(),
                c.guess.surface.clone().unwrap_or_default(),
                cell(c.guess.angle_deg),
                cell(c.guess.drop_height_m),
            ])
            .expect("in memory");
        }
        String::from_utf8(w.into_inner().expect("in memory")).expect("UTF-8 cells")
    }

    /// Writes `session.toml` and `clips.csv` into the folder; refuses to overwrite either unless
    /// `o.force`. Returns the paths written.
    pub fn write(&self, o: &InitOptions) -> Result<Vec<PathBuf>> {
        if let Some(d) = o.diameter_m {
            check_range(d, DIAMETER_RANGE_M, "m", Path::new("command line"), "--diameter")?;
        }
        if let Some(m) = o.mass_kg
            && !(m.is_finite() && m > 0.0)
        {
            return Err(FramesError::BadValue {
                path: "command line".into(),
                field: "--mass".into(),
                problem: format!("{m} must be a positive number of kilograms"),
            });
        }
        let paths: Vec<PathBuf> = SETTINGS_FILES.iter().map(|n| self.dir.join(n)).collect();
        if !o.force
            && let Some(p) = paths.iter().find(|p| p.exists())
        {
            return Err(FramesError::WouldOverwrite { path: p.clone() });
        }
        for (path, text) in paths.iter().zip([self.session_toml(o), self.clips_csv()]) {
            std::fs::write(path, text).map_err(|source| FramesError::Io {
                path: path.clone(),
                source,
            })?;
        }
        Ok(paths)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_give_surface_angle_and_height() {
        let g = guess_from_name("clay_15deg_550mm");
        assert_eq!(g.surface.as_deref(), Some("clay"));
        assert_eq!((g.angle_deg, g.drop_height_m), (Some(15.0), Some(0.55)));
        let g = guess_from_name("White-Tape 0deg 1.2m shot 03");
        assert_eq!(g.surface.as_deref(), Some("white_tape"));
        assert_eq!((g.angle_deg, g.drop_height_m), (Some(0.0), Some(1.2)));
        assert_eq!(guess_from_name("clay_55cm").drop_height_m, Some(0.55));
        assert_eq!(guess_from_name("shot_01"), NameGuess::default());
        assert_eq!(guess_from_name("ball_12bit"), NameGuess::default());
        assert_eq!(guess_from_name("C001H001S0001").surface, None);
        let g = guess_from_name("S002_tape1_15deg_250mm_r1");
        assert_eq!(g.surface.as_deref(), Some("tape1"));
        assert_eq!((g.angle_deg, g.drop_height_m), (Some(15.0), Some(0.25)));
        assert_eq!(guess_from_name("run2_clay_clay_0deg").surface.as_deref(), Some("clay"));
    }
}
