//! `bouncelab render`: a synthetic session (frames + truth) from a preset or a scenario file.

use anyhow::{Context, bail};
use bouncelab_render::{ProgressBarObserver, RenderOptions, Scenario, preset_names, render_with};
use std::path::PathBuf;

#[derive(clap::Args)]
#[command(group = clap::ArgGroup::new("source").required(true).args(["preset", "scenario"]))]
pub struct Args {
    /// Built-in scenario: smoke, paper, none, looks (64 shots with drawn looks and physics), looks-smoke,
    /// effect-<name> (an unknown name lists them all).
    #[arg(long)]
    preset: Option<String>,
    /// Scenario file (TOML; see docs/renderer.md; a [look] table draws each shot's appearance).
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// Output folder: the session goes to DIR/session, its ground truth to DIR/truth.
    #[arg(long)]
    out: PathBuf,
    /// Session seed (overrides the scenario's).
    #[arg(long)]
    seed: Option<u64>,
    /// Render into a non-empty DIR, replacing DIR/session and DIR/truth.
    #[arg(long)]
    force: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let mut scenario = match (&a.preset, &a.scenario) {
        (Some(p), _) => Scenario::preset(p)?,
        (None, Some(f)) => Scenario::load(f)?,
        (None, None) => bail!("give --preset NAME ({}) or --scenario FILE", preset_names().join(", ")),
    };
    if let Some(seed) = a.seed {
        scenario.seed = seed;
    }
    let non_empty = std::fs::read_dir(&a.out)
        .map(|mut d| d.next().is_some())
        .unwrap_or(false);
    if a.out.exists() && !a.out.is_dir() {
        bail!("{}: exists and is not a folder", a.out.display());
    }
    if non_empty && !a.force {
        bail!(
            "{}: exists and is not empty (refusing to mix sessions; choose another folder or add --force)",
            a.out.display()
        );
    }
    let progress = ProgressBarObserver::new();
    let opts = RenderOptions {
        parallel: true,
        overwrite: a.force,
    };
    let t = std::time::Instant::now();
    let out = render_with(&scenario, &a.out, &opts, &progress)
        .with_context(|| format!("rendering {} into {}", scenario.origin, a.out.display()))?;
    progress.finish();
    println!(
        "rendered {} clips ({} frames) in {:.1} s: session {}, truth {}",
        out.shots.len(),
        out.frames,
        t.elapsed().as_secs_f64(),
        out.session_dir.display(),
        out.truth_dir.display()
    );
    Ok(())
}
