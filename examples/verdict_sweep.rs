// cargo run --release --example verdict_sweep -- [--seeds 1,2,3] [PRESET | SCENARIO.toml ...]
//
//! The missing-effect diagnosis over seeds: each preset (default: `none`, every `effect-<name>` and every
//! `pair-A+B`; or a scenario file, such as the 16-shot pairs in `fixtures/scenarios/`) rendered at each seed
//! (default 1, 2, 3), analysed as `bouncelab analyze` does (tracked,
//! estimated, fitted with the paper's model, searched), and judged against the scenario's truth. One
//! Markdown row per session, printed as it finishes: the verdict, whether it is right (issue 16's rule: the
//! hidden effect named first, alone or first of an ambiguous few; both of a pair named; nothing named on a
//! clean session; a camera roll whose line is seen measured from the line, not named), each hidden effect's
//! magnitude against the truth, whether its 95 % interval covers the truth, and the times; every search's
//! candidates (with their times) go to stderr. The verdict table of `docs/accuracy.md` ("Verdicts on
//! rendered sessions") and the times in `docs/performance.md` come from this command.

#[path = "../tests/common/verdicts.rs"]
mod verdicts;

use bouncelab_analyze::{Analysis, AnalyzeOptions, NoProgress, analyze};
use bouncelab_diagnose::VerdictKind;
use bouncelab_frames::ClipOptions;
use bouncelab_render::{RenderOptions, Scenario, render_with};
use bouncelab_store::ClipFingerprint;
use std::io::Write;
use std::time::Instant;
use verdicts::{fit_of, magnitude, measured_roll, print_candidates, scenario_truth};

fn main() {
    let mut seeds = vec![1u64, 2, 3];
    let mut presets = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--seeds" {
            let list = args.next().expect("--seeds takes a list such as 1,2,3");
            seeds = list
                .split(',')
                .map(|s| s.trim().parse().expect("a seed is a whole number"))
                .collect();
        } else {
            presets.push(a);
        }
    }
    if presets.is_empty() {
        presets = bouncelab_render::preset_names()
            .into_iter()
            .filter(|p| p == "none" || p.starts_with("effect-") || p.starts_with("pair-"))
            .collect();
    }
    println!("| preset | seed | verdict | right | magnitude recovered | interval covers truth | diagnosis | analyze |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    let (mut right, mut total) = (0, 0);
    for preset in &presets {
        for &seed in &seeds {
            let mut scenario = if preset.ends_with(".toml") {
                Scenario::load(std::path::Path::new(preset))
            } else {
                Scenario::preset(preset)
            }
            .unwrap_or_else(|e| panic!("{preset}: {e}"));
            scenario.seed = seed;
            let row = session_row(&scenario, preset, seed);
            right += row.1 as usize;
            total += 1;
            println!("{}", row.0);
            std::io::stdout().flush().ok();
        }
    }
    println!("\n{right} of {total} verdicts right.");
}

/// Renders, analyses and judges one session: its table row, and whether the verdict is right.
fn session_row(scenario: &Scenario, preset: &str, seed: u64) -> (String, bool) {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let out = render_with(
        scenario,
        &dir.path().join("render"),
        &RenderOptions::default(),
        &bouncelab_render::NoRenderProgress,
    )
    .unwrap_or_else(|e| panic!("rendering {preset}: {e}"));
    let options = AnalyzeOptions {
        out_dir: dir.path().join("results"),
        store_path: dir.path().join("store.sqlite"),
        model_path: None,
        fingerprint: ClipFingerprint::Metadata,
        diagnose: true,
        clip_options: ClipOptions::default(),
    };
    let started = Instant::now();
    let a = match analyze(&out.session_dir, &options, &NoProgress) {
        Ok(a) => a,
        Err(e) => {
            return (
                format!("| {preset} | {seed} | analysis failed: {e} | no | | | | |"),
                false,
            );
        }
    };
    let analyze_s = started.elapsed().as_secs_f64();
    let d = match &a.diagnosis {
        Ok(d) => d,
        Err(why) => {
            return (
                format!("| {preset} | {seed} | search did not run: {why} | no | | | | {analyze_s:.1} s |"),
                false,
            );
        }
    };
    eprintln!("{preset}, seed {seed}: {}", d.verdict.sentence);
    print_candidates(d);
    let hidden = scenario.shots.first().map(|s| s.effects.clone()).unwrap_or_default();
    // A roll whose line is seen is measured from it and taken out by the estimator: nothing to name.
    let to_name: Vec<&str> = hidden
        .iter()
        .map(String::as_str)
        .filter(|e| *e != "camera_roll")
        .collect();
    let ok = is_right(d, &to_name);
    let mut magnitudes = Vec::new();
    let mut covers = Vec::new();
    if hidden.is_empty() {
        for (name, effect, param) in [
            ("clay:coulomb.mu", "coulomb", "mu"),
            ("clay:spring.k", "spring", "k"),
            ("clay:damping.b", "damping", "b"),
        ] {
            let truth = scenario_truth(scenario, effect, param);
            match a.fit.param(name) {
                Some(p) => {
                    magnitudes.push(format!(
                        "{effect}.{param} {:.4} ({:+.2} %)",
                        p.value,
                        (p.value - truth) / truth * 100.0
                    ));
                    covers.push(match p.interval {
                        Some([lo, hi]) if lo <= truth && truth <= hi => format!("{param} yes"),
                        Some(_) => format!("{param} **no**"),
                        None => format!("{param}: no interval"),
                    });
                }
                None => magnitudes.push(format!("{name} not fitted")),
            }
        }
    }
    for effect in &hidden {
        if effect == "camera_roll" {
            let truth = scenario_truth(scenario, effect, "roll_deg");
            match measured_roll(&a) {
                Some((roll, se, lines)) => {
                    magnitudes.push(format!(
                        "roll {roll:.3}° ± {se:.3}° from {lines} lines ({:+.1} %)",
                        (roll - truth) / truth * 100.0
                    ));
                    covers.push(format!(
                        "roll {}",
                        if (roll - truth).abs() <= 1.96 * se {
                            "yes"
                        } else {
                            "**no**"
                        }
                    ));
                }
                None => magnitudes.push("roll: no line measured a tilt".into()),
            }
            continue;
        }
        match fit_of(d, effect).and_then(|f| magnitude(scenario, effect, f)) {
            Some(m) => {
                magnitudes.push(format!("{} {:.4e} ({:+.1} %)", m.label, m.value, m.error() * 100.0));
                covers.push(format!(
                    "{effect} {}",
                    match m.covers_text() {
                        "no" => "**no**",
                        other => other,
                    }
                ));
            }
            None => magnitudes.push(format!("{effect}: not fitted")),
        }
    }
    let named = if d.verdict.effects.is_empty() {
        String::new()
    } else {
        format!(" [{}]", d.verdict.effects.join(", "))
    };
    let row = format!(
        "| {preset} | {seed} | {}{named} | {} | {} | {} | {:.1} s | {analyze_s:.1} s ({}) |",
        d.verdict.kind.name(),
        if ok { "yes" } else { "**no**" },
        magnitudes.join("; "),
        covers.join("; "),
        d.seconds,
        stage_times(&a)
    );
    (row, ok)
}

/// Issue 16's rule: nothing to name → `no_missing_effect`; one → named first (alone, or first of an
/// ambiguous few); two or more → exactly those named.
fn is_right(d: &bouncelab_diagnose::Diagnosis, to_name: &[&str]) -> bool {
    match to_name {
        [] => d.verdict.kind == VerdictKind::NoMissingEffect,
        [one] => {
            matches!(d.verdict.kind, VerdictKind::MissingEffect | VerdictKind::Ambiguous)
                && d.verdict.effects.first().map(String::as_str) == Some(*one)
        }
        many => {
            let mut named: Vec<&str> = d.verdict.effects.iter().map(String::as_str).collect();
            let mut want = many.to_vec();
            named.sort();
            want.sort();
            named == want
        }
    }
}

/// `track 3.8 s, diagnose 10.1 s`: the stages that took a tenth of a second or more.
fn stage_times(a: &Analysis) -> String {
    a.timings
        .iter()
        .filter(|(_, s)| *s >= 0.1)
        .map(|(stage, s)| format!("{} {s:.1} s", stage.name()))
        .collect::<Vec<_>>()
        .join(", ")
}
