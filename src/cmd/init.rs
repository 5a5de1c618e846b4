//! `bouncelab init DIR`: a folder of recordings (clip folders and camera files) → `session.toml` and
//! `clips.csv` to complete, then `bouncelab analyze DIR`.

use bouncelab_frames::Downslope;
use bouncelab_frames::init::{InitOptions, scan};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Folder holding the recordings: one sub-folder of frames or one camera file (.cihx/.cih + .mraw,
    /// .cine, .tif stack) per clip.
    dir: PathBuf,
    /// Ball diameter, m (otherwise session.toml leaves it for you to fill).
    #[arg(long)]
    diameter: Option<f64>,
    /// Ball mass, kg (otherwise session.toml leaves it for you to fill).
    #[arg(long)]
    mass: Option<f64>,
    /// Which image direction is down the slope: "+x" (right) or "-x" (left) [default: left unset; +x is
    /// assumed unless a shot's flights clearly fall the other way]
    #[arg(long, allow_hyphen_values = true, value_parser = ["+x", "-x"])]
    downslope: Option<String>,
    /// Overwrite an existing session.toml and clips.csv.
    #[arg(long)]
    force: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let draft = scan(&a.dir)?;
    if draft.clips.is_empty() {
        anyhow::bail!(
            "{}: no clips found (looked for sub-folders of frames and .cihx/.cih/.mraw, .cine, .tif/.tiff files)",
            a.dir.display()
        );
    }
    let mut o = InitOptions::default();
    (o.diameter_m, o.mass_kg, o.force) = (a.diameter, a.mass, a.force);
    o.downslope = a
        .downslope
        .map(|d| if d == "-x" { Downslope::MinusX } else { Downslope::PlusX });
    let written = draft.write(&o)?;
    println!("{} clip(s) in {}:", draft.clips.len(), a.dir.display());
    let cell = |x: Option<f64>| x.map_or_else(|| "?".to_string(), |v| v.to_string());
    for c in &draft.clips {
        let fps = c
            .fps
            .map_or_else(|| "no header fps".to_string(), |f| format!("{f} fps"));
        let frames = c.frames.map_or_else(|| "?".to_string(), |n| n.to_string());
        println!(
            "  {:<32} {:?}, {frames} frames, {fps}; surface {}, angle {}, height {}",
            c.name,
            c.format,
            c.guess.surface.as_deref().unwrap_or("?"),
            cell(c.guess.angle_deg),
            cell(c.guess.drop_height_m),
        );
        if let Some(p) = &c.problem {
            eprintln!("warning: {p}");
        }
    }
    for (path, why) in &draft.skipped {
        eprintln!("skipped {}: {why}", path.display());
    }
    for p in &written {
        println!("wrote {}", p.display());
    }
    let mut todo = Vec::new();
    if a.diameter.is_none() || a.mass.is_none() {
        todo.push("the ball's diameter_m and mass_kg in session.toml");
    }
    let unfilled = draft
        .clips
        .iter()
        .filter(|c| c.guess.surface.is_none() || c.guess.angle_deg.is_none() || c.guess.drop_height_m.is_none())
        .count();
    let cells = format!("the empty surface/angle_deg/drop_height_m cells of {unfilled} clip(s) in clips.csv");
    if unfilled > 0 {
        todo.push(&cells);
    }
    if todo.is_empty() {
        println!(
            "next: check the guesses in clips.csv, then `bouncelab analyze {}`",
            a.dir.display()
        );
    } else {
        println!(
            "next: fill {}, then `bouncelab analyze {}`",
            todo.join(" and "),
            a.dir.display()
        );
    }
    Ok(())
}
