//! `bouncelab track`: one clip (a folder of frames or a camera file) → its trajectory CSV.

use anyhow::Context;
use bouncelab_frames::{Clip, Downslope};
use bouncelab_track::{ClipTracking, Track, track_clip};
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// One clip: a folder of frames, or a camera file (.cihx/.cih/.mraw, .cine, .tif stack).
    clip_dir: PathBuf,
    /// Trajectory CSV to write; standard output when omitted.
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    tracking: Tracking,
}

/// How a clip is tracked: shared by `track` and `overlay`.
#[derive(clap::Args)]
pub struct Tracking {
    /// Detector (builds with the `opencv` feature also offer OpenCV's HoughCircles as `opencv`).
    #[arg(long, value_enum, default_value_t = Detector::Hough)]
    detector: Detector,
    #[command(flatten)]
    settings: super::settings::Overrides,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum Detector {
    /// Our gradient Hough transform with sub-pixel refinement.
    Hough,
    /// OpenCV's HoughCircles on every frame, no refinement: the reference baseline.
    #[cfg(feature = "opencv")]
    Opencv,
}

/// Opens the clip and tracks it as `bouncelab track` does (warnings printed, a progress bar on a terminal).
pub fn track_clip_dir(clip_dir: &Path, a: &Tracking) -> anyhow::Result<(Clip, Track)> {
    let options = a.settings.clip_options();
    let clip = Clip::open_with(clip_dir, &options)?;
    for w in clip.warnings() {
        eprintln!("warning: {w}");
    }
    if !clip.gaps().is_empty() {
        eprintln!("warning: {} dropped frame(s) in {}", clip.dropped(), clip_dir.display());
    }
    let minus_x = clip.settings().downslope == Some(Downslope::MinusX);
    let opts = ClipTracking::for_settings(clip.settings(), minus_x);
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
    // Every tracking error names its clip or the file it read.
    .context("tracking")?;
    bar.finish_and_clear();
    for w in &track.warnings {
        eprintln!("warning: {w}");
    }
    Ok((clip, track))
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let (_, track) = track_clip_dir(&a.clip_dir, &a.tracking)?;
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
    let c = &track.camera;
    if c.format != bouncelab_frames::SourceFormat::Folder {
        let mut line = format!("camera: {}", c.format.label());
        if let Some(m) = &c.camera_model {
            line += &format!(" {m}");
        }
        if let Some(e) = c.exposure_s {
            line += &format!(", exposure {} µs", e * 1e6);
        }
        if let Some(b) = c.effective_bit_depth.or(c.bit_depth) {
            line += &format!(", {b}-bit");
        }
        if let Some(t) = c.trigger_frame {
            line += &format!(", trigger at file frame {t}");
        }
        eprintln!("{line}");
    }
    Ok(())
}
