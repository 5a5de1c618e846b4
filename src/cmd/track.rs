//! `bouncelab track`: one clip folder → its trajectory CSV (SPEC §5 columns).

use anyhow::Context;
use bouncelab_frames::{Clip, ClipOptions, Downslope, Session};
use bouncelab_track::{ClipTracking, track_clip};
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Folder of frames (one clip).
    clip_dir: PathBuf,
    /// Trajectory CSV to write; standard output when omitted.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Detector (builds with the `opencv` feature also offer OpenCV's HoughCircles as `opencv`).
    #[arg(long, value_enum, default_value_t = Detector::Hough)]
    detector: Detector,
    /// Frame rate, frames/s (beats clip.toml and session.toml).
    #[arg(long, allow_negative_numbers = true)]
    fps: Option<f64>,
    /// Ball diameter, m (default: session.toml's [ball] diameter_m, else 0.067).
    #[arg(long)]
    diameter: Option<f64>,
    /// Approximate scale, m/px, if known (otherwise the ball is found by its motion).
    #[arg(long)]
    scale: Option<f64>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum Detector {
    /// Our gradient Hough transform with sub-pixel refinement.
    Hough,
    /// OpenCV's HoughCircles on every frame, no refinement: the reference baseline.
    #[cfg(feature = "opencv")]
    Opencv,
}

/// Ball diameter and down-slope direction from the session folder above the clip, if there is one.
fn session_settings(clip_dir: &Path) -> (Option<f64>, bool) {
    let Some(parent) = clip_dir
        .canonicalize()
        .ok()
        .and_then(|p| p.parent().map(Path::to_path_buf))
    else {
        return (None, false);
    };
    if !parent.join("session.toml").is_file() {
        return (None, false);
    }
    match Session::load(&parent) {
        Ok(s) => (Some(s.ball.diameter_m), s.downslope == Downslope::MinusX),
        Err(_) => (None, false),
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let options = match a.fps {
        Some(f) => ClipOptions::with_fps(f),
        None => ClipOptions::default(),
    };
    let clip = Clip::open_with(&a.clip_dir, &options)?;
    for w in clip.warnings() {
        eprintln!("warning: {w}");
    }
    if !clip.gaps().is_empty() {
        eprintln!(
            "warning: {} dropped frame(s) in {}",
            clip.dropped(),
            a.clip_dir.display()
        );
    }
    let (session_diameter, minus_x) = session_settings(&a.clip_dir);
    let diameter = a.diameter.or(session_diameter).unwrap_or(0.067);
    if !(diameter > 0.0 && diameter.is_finite()) {
        anyhow::bail!("--diameter {diameter} must be a positive number of metres");
    }
    let opts = ClipTracking {
        ball_diameter_m: diameter,
        scale_hint_m_per_px: a.scale,
        downslope_negative_x: minus_x,
        ..ClipTracking::default()
    };
    let bar = super::progress_bar(clip.len() as u64, "tracking", "frames");
    let progress = |done: usize, _| bar.set_position(done as u64);
    let track = match a.detector {
        Detector::Hough => track_clip(&clip, &opts, progress),
        // OpenCV's HoughCircles on every frame, no refinement: the reference baseline.
        #[cfg(feature = "opencv")]
        Detector::Opencv => bouncelab_track::opencv::track_clip_opencv(
            &clip,
            &opts,
            bouncelab_track::opencv::OpencvMethod::Gradient,
            progress,
        ),
    }
    .with_context(|| format!("tracking {}", a.clip_dir.display()))?;
    bar.finish_and_clear();
    for w in &track.warnings {
        eprintln!("warning: {w}");
    }
    let mut out: Box<dyn Write> = match &a.out {
        Some(p) => Box::new(std::fs::File::create(p).with_context(|| format!("creating {}", p.display()))?),
        None => Box::new(std::io::stdout().lock()),
    };
    let mut w = csv::Writer::from_writer(&mut out);
    for row in track.rows() {
        w.serialize(row)?;
    }
    w.flush()?;
    drop(w);
    let ok = track.fixes.iter().filter(|f| f.status.measured()).count();
    let mut summary = format!("{} frames, ball measured in {ok}", track.fixes.len());
    if let Some(s) = &track.scale {
        summary += &format!(
            "; scale {:.4e} ± {:.1e} m/px (radius {:.2} px over {} flight frames)",
            s.m_per_px, s.sigma_m_per_px, s.radius_px, s.frames
        );
    }
    if let Some(l) = &track.surface {
        summary += &format!(
            "; surface line y = {:.2} ± {:.2} px at x = {:.0}, tilt {:.3}° ± {:.3}°",
            l.y0,
            l.sigma_y0,
            l.x0,
            l.tilt_deg(),
            l.sigma_tilt_deg
        );
    }
    eprintln!("{summary}");
    Ok(())
}
