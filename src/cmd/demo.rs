//! `bouncelab demo [--out DIR]`: the whole product on built-in data, no input and no network.
//!
//! Renders a small session (clay and white tape, three drop heights, two inclines) whose physics has a
//! contact effect the paper's model lacks, analyses it with the paper's model, accepts the diagnosis with
//! `model add`, analyses it again, and prints COR per surface, the verdict and the error before and after,
//! with the report's path.

use anyhow::Context;
use bouncelab_analyze::{Analysis, ShotData};
use bouncelab_render::{ProgressBarObserver, RenderOptions, Scenario, render_with};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Folder for the session, the results and the model files [default: a new folder in the system's
    /// temporary directory].
    #[arg(long)]
    out: Option<PathBuf>,
    /// The hidden effect, a library effect with its `effect-<name>` magnitude (see `bouncelab effects`).
    #[arg(long, default_value = "hunt_crossley")]
    effect: String,
}

/// The demo session: the paper's clay and tape 1 at three drop heights and two inclines, with `effect`
/// switched on in the physics at its `effect-<name>` preset magnitude.
fn scenario(effect: &str) -> anyhow::Result<Scenario> {
    let params = bouncelab_render::EFFECT_MAGNITUDES
        .iter()
        .find(|(n, _)| *n == effect)
        .map(|(_, p)| *p)
        .with_context(|| {
            let known: Vec<&str> = bouncelab_render::EFFECT_MAGNITUDES.iter().map(|(n, _)| *n).collect();
            format!(
                "--effect {effect}: not a hidden-effect preset (known: {})",
                known.join(", ")
            )
        })?;
    let text = format!(
        r#"name = "demo"
description = "bouncelab demo: clay and white tape with a contact effect the paper's model lacks"
seed = 20261122
pre_contact_ms = 8
post_separation_ms = 8

[ball]
diameter_m = 0.067
mass_kg = 0.0567
inertia_factor = 0.6666666666666666

[camera]
width = 512
height = 512
scale_m_per_px = 4.0e-4
fps = 10000
exposure_s = 5e-5

[model]
gravity_m_s2 = 9.81
[model.effects.spring]
k = 25650
[model.effects.damping]
b = 14
[model.effects.coulomb]
mu = 0.5

[surfaces.clay]
texture = "clay"
spring.k = 25650
damping.b = 14

[surfaces.tape1]
texture = "white_tape"
spring.k = 30800
damping.b = 15

[extra_effects.{effect}]
{params}

[grid]
surfaces = ["clay", "tape1"]
drop_heights_m = [0.2, 0.55, 0.9]
angles_deg = [0, 15]
repeats = 1
effects = ["{effect}"]
"#
    );
    Ok(Scenario::parse(&text, "the demo session")?)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let started = std::time::Instant::now();
    let dir = match &a.out {
        Some(d) => d.clone(),
        None => std::env::temp_dir().join(format!("bouncelab-demo-{}", std::process::id())),
    };
    if dir.join("session").exists() {
        anyhow::bail!(
            "{}: holds a session already (choose another --out, or remove it)",
            dir.display()
        );
    }
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let scenario = scenario(&a.effect)?;
    eprintln!("rendering the demo session into {} …", dir.display());
    let progress = ProgressBarObserver::new();
    let out = render_with(&scenario, &dir, &RenderOptions::default(), &progress)
        .with_context(|| format!("rendering into {}", dir.display()))?;
    progress.finish();
    let session = out.session_dir;
    let results = dir.join("results");
    let model_path = dir.join("model.toml");
    let args = |model: Option<PathBuf>| super::analyze::Args {
        session_dir: session.clone(),
        out: Some(results.clone()),
        model,
        store: Some(dir.join("bouncelab.sqlite")),
        content_hash: false,
        no_diagnose: false,
        settings: Default::default(),
    };

    eprintln!("analysing it with the paper's model …");
    let first = super::analyze::run_quiet(&args(None))?;
    super::analyze::fail_on_failed_shots(&first)?;
    println!(
        "\n== bouncelab demo: {} shots rendered with a hidden effect ==",
        first.shots_listed
    );
    print_cor(&first);
    let d = match &first.diagnosis {
        Ok(d) => d,
        Err(why) => anyhow::bail!("the diagnosis did not run: {why}"),
    };
    println!(
        "\nWith the paper's model: position RMS {:.1} µm, reduced χ² {:.2}.",
        first.fit.rms_m * 1e6,
        first.fit.reduced_chi2
    );
    println!("Verdict: {}", bouncelab_analyze::verdict_headline(d).replace('`', ""));
    let Some(effect) = d.verdict.effect.clone() else {
        println!("\nNo effect was named, so the model is left as it is.");
        print_report(&results, started);
        return Ok(());
    };

    let diagnosis_json = results.join("diagnosis.json");
    let (_, values) = super::model::add(&effect, &model_path, Some(&diagnosis_json))?;
    let shown: Vec<String> = values.iter().map(|(n, v)| format!("{n} = {v:.4}")).collect();
    println!(
        "\nAccepting it: bouncelab model add {effect} --model {} ({}), then analysing again …",
        model_path.display(),
        shown.join(", ")
    );
    let second = super::analyze::run_quiet(&args(Some(model_path.clone())))?;
    println!("\nBefore and after adding {effect}:");
    println!("  {:<30} {:>12} {:>12}", "shot", "before µm", "after µm");
    if let Some(b) = &second.before {
        for (clip, before, after) in &b.shots {
            println!("  {clip:<30} {:>12.1} {:>12.1}", before * 1e6, after * 1e6);
        }
        println!(
            "  {:<30} {:>12.1} {:>12.1}   ({:.1}× lower; reduced χ² {:.2} → {:.2})",
            "all shots",
            b.total_rms_m.0 * 1e6,
            b.total_rms_m.1 * 1e6,
            b.total_rms_m.0 / b.total_rms_m.1,
            b.reduced_chi2.0,
            b.reduced_chi2.1
        );
    }
    if let Ok(d2) = &second.diagnosis {
        println!(
            "Verdict with {effect} added: {}",
            bouncelab_analyze::verdict_headline(d2).replace('`', "")
        );
    }
    print_report(&results, started);
    Ok(())
}

fn print_cor(a: &Analysis) {
    let shots: &[ShotData] = &a.shots;
    let mut surfaces: Vec<&str> = shots.iter().map(|s| s.surface.as_str()).collect();
    surfaces.sort();
    surfaces.dedup();
    println!("{:<10} {:>6} {:>10} {:>10}", "surface", "shots", "mean COR", "SD");
    for sf in surfaces {
        let c: Vec<f64> = shots
            .iter()
            .filter(|s| s.surface == sf)
            .map(|s| s.estimate.cor.value)
            .collect();
        let n = c.len() as f64;
        let mean = c.iter().sum::<f64>() / n;
        let sd = if c.len() > 1 {
            (c.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        } else {
            f64::NAN
        };
        println!("{sf:<10} {:>6} {mean:>10.4} {sd:>10.4}", c.len());
    }
}

fn print_report(results: &Path, started: std::time::Instant) {
    let report = results.join("report.html");
    if report.exists() {
        println!("\nReport: {}", report.display());
    }
    println!(
        "Results: {}  ({:.1} s)",
        results.display(),
        started.elapsed().as_secs_f64()
    );
}
