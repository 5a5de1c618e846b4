//! `bouncelab estimate`: one clip (a folder of frames or a camera file) → its per-shot measurements with
//! standard errors.

use anyhow::Context;
use bouncelab_estimate::{Conditions, Estimate, estimate_finding_downslope, estimate_with_frames, fall_se_deg};
use bouncelab_frames::{Clip, Downslope, Session};
use bouncelab_track::{ClipTracking, track_clip};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// One clip (a folder of frames, or a camera file: .cihx/.cih/.mraw, .cine, .tif stack), inside a
    /// session folder or on its own.
    clip_dir: PathBuf,
    /// Incline of the surface, degrees (default: the clip's angle_deg in the session's clips.csv).
    #[arg(long, allow_negative_numbers = true, value_parser = super::settings::parse_angle)]
    angle: Option<f64>,
    #[command(flatten)]
    settings: super::settings::Overrides,
    /// Gravitational acceleration, m/s².
    #[arg(long, default_value_t = 9.81, allow_negative_numbers = true, value_parser = super::settings::parse_gravity)]
    gravity: f64,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// The incline of the clip's row in its session's clips.csv, when the clip sits in a session folder that
/// lists it.
fn session_angle(clip_dir: &Path) -> Option<f64> {
    let dir = clip_dir.canonicalize().ok()?;
    let parent = dir.parent()?;
    if !parent.join("session.toml").is_file() {
        return None;
    }
    let s = Session::load(parent).ok()?;
    // The row whose folder or camera file this is (clips.csv may name a file without its extension).
    let clip = s.clips.iter().find(|c| c.dir.canonicalize().is_ok_and(|p| p == dir))?;
    Some(clip.angle_deg)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let options = a.settings.clip_options();
    let clip = Clip::open_with(&a.clip_dir, &options)?;
    for w in clip.warnings() {
        eprintln!("warning: {w}");
    }
    let Some(angle) = a.angle.or_else(|| session_angle(&a.clip_dir)) else {
        anyhow::bail!(
            "{}: no incline known: give --angle, or put the clip in a session folder whose clips.csv lists it",
            a.clip_dir.display()
        );
    };
    let diameter = clip.settings().ball_diameter_m;
    let downslope = clip.settings().downslope;
    let opts = ClipTracking::for_settings(clip.settings(), downslope == Some(Downslope::MinusX));
    let bar = super::progress_bar(clip.len() as u64, "tracking", "frames");
    let track = track_clip(&clip, &opts, |done, _| bar.set_position(done as u64))
        // Every tracking error names its clip or the file it read.
        .context("tracking")?;
    bar.finish_and_clear();
    let c = Conditions {
        incline_deg: angle,
        gravity: a.gravity,
        ball_diameter_m: diameter,
        surface_tilt_deg: clip.settings().surface_tilt_deg,
        fall_se_deg: fall_se_deg(clip.settings().dropped_from_rest, clip.settings().incline_se_deg),
    };
    // Without a down-slope direction given, the flights' fall is checked against the default.
    let e = match downslope {
        Some(_) => estimate_with_frames(&track, &clip, &c),
        None => estimate_finding_downslope(&track, &clip, &c),
    }
    .with_context(|| format!("estimating {}", a.clip_dir.display()))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&e)?);
    } else {
        print_table(&a.clip_dir, angle, &e);
    }
    // Impossible numbers are printed (they help find the cause) but never pass as a measurement.
    if !e.flags.is_empty() {
        anyhow::bail!(
            "{}: impossible numbers, not a measurement (analyze keeps such a shot out of the fit): {}",
            a.clip_dir.display(),
            e.flags.join("; ")
        );
    }
    Ok(())
}

fn print_table(clip: &Path, angle: f64, e: &Estimate) {
    println!("{}  (incline {angle}°)", clip.display());
    let row = |name: &str, unit: &str, v: f64, se: f64| println!("  {name:<14} {:>22} {unit}", super::pm(v, se));
    row("v_in_t", "m/s", e.v_in[0].value, e.v_in[0].se);
    row("v_in_n", "m/s", e.v_in[1].value, e.v_in[1].se);
    row("v_out_t", "m/s", e.v_out[0].value, e.v_out[0].se);
    row("v_out_n", "m/s", e.v_out[1].value, e.v_out[1].se);
    row("COR", "", e.cor.value, e.cor.se);
    row("μ_eff", "", e.mu.value, e.mu.se);
    row("contact", "ms", e.contact_ms.value, e.contact_ms.se);
    row("δ_max", "mm", e.delta_max_m.value * 1e3, e.delta_max_m.se * 1e3);
    for (name, spin) in [("spin_in", e.spin_in), ("spin_out", e.spin_out)] {
        match spin {
            Some(m) => row(name, "rad/s", m.value, m.se),
            None => println!("  {name:<14} not measured (see the notes)"),
        }
    }
    let p = &e.phases;
    println!(
        "  phases: flight in frames {}–{} ({} fitted), contact {}–{}, flight out {}–{} ({} fitted)",
        p.flight_in.0, p.flight_in.1, p.fitted.0, p.contact.0, p.contact.1, p.flight_out.0, p.flight_out.1, p.fitted.1
    );
    for n in &e.notes {
        println!("  note: {n}");
    }
}
