//! `bouncelab overlay`: one clip folder → its frames with the tracking drawn on them (PNG) and a contact
//! sheet of the impact's key frames (`docs/overlay.md`).

use anyhow::Context;
use bouncelab_overlay::{
    BallMark, ContactRule, Crop, Levels, Phase, PngSpeed, SheetLayout, StripFrame, Style, SurfaceLine, annotate_frame,
    choose_key_frames, encode_png, encode_png_with, key_frame_strip,
};
use bouncelab_track::Track;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Clips up to this many frames are drawn whole by default; longer ones every N-th frame to about this many.
const DEFAULT_MAX_PICTURES: u64 = 500;

#[derive(clap::Args)]
pub struct Args {
    /// Folder of frames (one clip).
    clip_dir: PathBuf,
    /// Folder to write `frame_NNNNNN.png` and `sheet.png` into (default: bouncelab-results/overlay/<clip>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Draw every N-th frame (default: every frame of a clip up to 500 frames, else about 500 frames);
    /// the key frames are always drawn.
    #[arg(long)]
    every: Option<u64>,
    /// Write only the contact sheet of the key frames, no per-frame pictures.
    #[arg(long)]
    sheet: bool,
    /// Magnification of the per-frame pictures (2 doubles their width and height).
    #[arg(long, default_value_t = 1.0)]
    zoom: f64,
    /// Gray levels: the file's full scale, or stretched to the clip's range (0.5–99.5 % of the first frame;
    /// for 12-bit cameras writing 16-bit files, or dark footage).
    #[arg(long, value_enum, default_value_t = LevelsArg::Full)]
    levels: LevelsArg,
    #[command(flatten)]
    tracking: super::track::Tracking,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum LevelsArg {
    /// 0 is black, the bit depth's maximum white.
    Full,
    /// The first frame's 0.5 and 99.5 percentiles are black and white.
    Stretch,
}

/// The ball of every tracked frame, by frame index, and the surface line, as the overlay's plain data.
fn marks_of(track: &Track) -> (Vec<BallMark>, Option<SurfaceLine>) {
    let marks = track
        .fixes
        .iter()
        .map(|f| BallMark {
            frame: f.frame as u64,
            x_px: f.x_px,
            y_px: f.y_px,
            r_px: f.r_px,
            status: f.status,
            phase: Phase::Unknown,
        })
        .collect();
    let line = track.surface.map(|l| SurfaceLine {
        x0: l.x0,
        y0: l.y0,
        slope: l.slope,
    });
    (marks, line)
}

/// The default step: every frame up to `DEFAULT_MAX_PICTURES`, else the smallest step giving at most that many.
fn default_every(frames: u64) -> u64 {
    frames.div_ceil(DEFAULT_MAX_PICTURES).max(1)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if a.every == Some(0) {
        anyhow::bail!("--every 0: give a step of at least 1 frame");
    }
    if !(a.zoom.is_finite() && a.zoom > 0.0 && a.zoom <= 16.0) {
        anyhow::bail!("--zoom {}: give a magnification above 0 and at most 16", a.zoom);
    }
    let name = a
        .clip_dir
        .canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "clip".to_string());
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| Path::new("bouncelab-results").join("overlay").join(&name));
    std::fs::create_dir_all(&out).with_context(|| format!("creating the output folder {}", out.display()))?;
    let (clip, track) = super::track::track_clip_dir(&a.clip_dir, &a.tracking)?;
    let (mut marks, line) = marks_of(&track);
    let rule = ContactRule {
        radius_px: track.scale.map(|s| s.radius_px),
        ..ContactRule::default()
    };
    let (phases, keys, how) = choose_key_frames(&marks, line.as_ref(), &rule)
        .with_context(|| format!("choosing the key frames of {}", a.clip_dir.display()))?;
    if let Some(p) = &phases {
        for m in &mut marks {
            m.phase = p.phase_of(m.frame);
        }
    }
    let by_frame: HashMap<u64, BallMark> = marks.iter().map(|m| (m.frame, *m)).collect();
    let placed = keys.placed();
    let every = a.every.unwrap_or_else(|| default_every(clip.len() as u64));

    let mut style = Style::default();
    let mut key_pixels = HashMap::new();
    let mut written = 0usize;
    let bar = super::progress_bar(clip.len() as u64, "drawing", "frames");
    for (k, frame) in clip.frames().enumerate() {
        let frame = frame.with_context(|| format!("reading {} again to draw it", a.clip_dir.display()))?;
        bar.set_position(k as u64 + 1);
        if k == 0 && matches!(a.levels, LevelsArg::Stretch) {
            style.levels = Levels::stretch(&frame.pixels, 0.5, 99.5);
        }
        let is_key = placed.iter().any(|(_, f)| *f == frame.index);
        let Some(mark) = by_frame.get(&frame.index) else {
            continue;
        };
        if !a.sheet && ((k as u64).is_multiple_of(every) || is_key) {
            let picture = annotate_frame(&frame.pixels, mark, line.as_ref(), a.zoom, &style)
                .with_context(|| format!("drawing {}", frame.path.display()))?;
            let png = encode_png_with(&picture, PngSpeed::Fast)?;
            let path = out.join(format!("frame_{:06}.png", frame.index));
            std::fs::write(&path, png).with_context(|| format!("writing {}", path.display()))?;
            written += 1;
        }
        if is_key {
            key_pixels.insert(frame.index, frame.pixels);
        }
    }
    bar.finish_and_clear();

    let mut strip = Vec::with_capacity(placed.len());
    for (role, f) in &placed {
        let pixels = key_pixels
            .get(f)
            .with_context(|| format!("{}: key frame {f} was not read back", a.clip_dir.display()))?;
        strip.push(StripFrame {
            pixels,
            mark: by_frame[f],
            caption: role.label(),
        });
    }
    let sheet = key_frame_strip(&strip, line.as_ref(), &Crop::default(), &style, &SheetLayout::default())
        .with_context(|| format!("drawing the key frames of {}", a.clip_dir.display()))?;
    let sheet_path = out.join("sheet.png");
    std::fs::write(&sheet_path, encode_png(&sheet)?).with_context(|| format!("writing {}", sheet_path.display()))?;

    let list: Vec<String> = placed
        .iter()
        .map(|(role, f)| format!("{} {f}", role.label().to_lowercase()))
        .collect();
    eprintln!("key frames: {} ({how})", list.join(", "));
    if a.sheet {
        eprintln!("wrote {}", sheet_path.display());
    } else {
        eprintln!(
            "wrote {written} annotated frame(s) (every {every}{}) and sheet.png to {}",
            if every > 1 { " + key frames" } else { "" },
            out.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_step_keeps_about_five_hundred_pictures() {
        assert_eq!(default_every(0), 1);
        assert_eq!(default_every(500), 1);
        assert_eq!(default_every(501), 2);
        assert_eq!(default_every(10_000), 20);
    }
}
