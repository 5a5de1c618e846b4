//! Issues 6 and 16's acceptance, through the whole chain: sessions rendered by our renderer with a hidden
//! effect (or none, or two at once, or one outside the library) are tracked, estimated, fitted with the
//! paper's model (μ per surface) and diagnosed; nothing inside the pipeline sees the truth. Slow (19
//! sessions, one seed each): run in release,
//!
//! ```text
//! cargo test --release -p bouncelab-analyze --test acceptance -- --ignored --nocapture
//! ```
//!
//! (CI runs it). Each test prints the verdict and the figures recorded in `docs/accuracy.md`, and the rows
//! of the verdict table (`| preset | verdict | magnitude recovered | interval covers truth | time |`).

use bouncelab_analyze::{Analysis, AnalyzeOptions, Silent, analyze};
use bouncelab_diagnose::{VerdictKind, add_effect_to_model_toml};
use bouncelab_frames::ClipOptions;
use bouncelab_render::{RenderOptions, Scenario, render_with};
use bouncelab_store::ClipFingerprint;
use std::path::{Path, PathBuf};

/// Renders `scenario` into `root/render` and returns the session folder.
fn render(scenario: &Scenario, root: &Path) -> PathBuf {
    let out = render_with(
        scenario,
        &root.join("render"),
        &RenderOptions::default(),
        &bouncelab_render::Silent,
    )
    .unwrap_or_else(|e| panic!("rendering {}: {e}", scenario.origin));
    out.session_dir
}

fn run(session: &Path, root: &Path, model: Option<PathBuf>) -> Analysis {
    let options = AnalyzeOptions {
        out_dir: root.join("results"),
        store_path: root.join("store.sqlite"),
        model_path: model,
        fingerprint: ClipFingerprint::Metadata,
        diagnose: true,
        clip_options: ClipOptions::default(),
    };
    let a = analyze(session, &options, &Silent).unwrap_or_else(|e| panic!("analysing {}: {e}", session.display()));
    assert!(a.measure.failed.is_empty(), "shots failed: {:?}", a.measure.failed);
    a
}

/// The effect preset `effect-<name>`: named first (alone, or first of an ambiguous few), and once added the
/// error falls ≥ 3× to χ²_red ≤ 1.5. Prints the verdict table's row (magnitude recovered, interval covers
/// the truth, time).
fn hidden(effect: &str) {
    hidden_in(effect, &Scenario::preset(&format!("effect-{effect}")).unwrap());
}

/// [`hidden`] on a given scenario with `effect` hidden; returns the fitted switch parameter's value, its
/// interval and its truth (from the scenario text).
fn hidden_in(effect: &str, scenario: &Scenario) -> (f64, Option<[f64; 2]>, f64) {
    let dir = tempfile::tempdir().unwrap();
    let session = render(scenario, dir.path());
    let first = run(&session, dir.path(), None);
    let d = first.diagnosis.as_ref().expect("the diagnosis ran");
    eprintln!("{effect}: {}", d.verdict.sentence);
    // Named first: alone (`missing_effect`), or first of the effects the data cannot tell apart
    // (`ambiguous`), never behind another.
    assert!(
        matches!(d.verdict.kind, VerdictKind::MissingEffect | VerdictKind::Ambiguous),
        "{}",
        d.verdict.sentence
    );
    assert_eq!(
        d.verdict.effects.first().map(String::as_str),
        Some(effect),
        "{}",
        d.verdict.sentence
    );
    // Accept it: the paper's model with the effect at its fitted values, analysed again.
    let prefix = format!("{effect}.");
    let values: Vec<(String, f64)> = d
        .candidate(effect)
        .and_then(|c| c.evidence.as_ref())
        .map(|e| {
            e.fit
                .parameters
                .iter()
                .filter_map(|p| p.name.strip_prefix(&prefix).map(|n| (n.to_string(), p.value)))
                .collect()
        })
        .unwrap_or_default();
    let c = d.candidate(effect).expect("the hidden effect was tried");
    let e = c.evidence.as_ref().expect("its fit ran");
    let truth = scenario_truth(scenario, effect, &c.param);
    let covers = e.param_interval.map(|[lo, hi]| lo <= truth && truth <= hi);
    eprintln!(
        "{effect}: systematic part removed {:.1} %",
        e.explained_fraction * 100.0
    );
    if effect == "tangential_spring" {
        assert!(e.explained_fraction >= 0.9, "{effect}: {}", e.explained_fraction);
    }
    eprintln!(
        "| effect-{effect} | {} | {} = {:.4e} ({:+.1} % of {truth:e}) | {} | {:.1} s |",
        d.verdict.kind.name(),
        c.param,
        e.param_value,
        (e.param_value - truth) / truth * 100.0,
        match covers {
            Some(true) => "yes",
            Some(false) => "no",
            None => "no interval",
        },
        d.seconds
    );
    let text = add_effect_to_model_toml(bouncelab_model::PAPER_MODEL_TOML, effect, &values).unwrap();
    let model = dir.path().join("model.toml");
    std::fs::write(&model, text).unwrap();
    let second = run(&session, dir.path(), Some(model));
    let b = second.before.as_ref().expect("the earlier fit is in the store");
    let fall = b.total_rms_m.0 / b.total_rms_m.1;
    eprintln!(
        "{effect}: RMS {:.1} → {:.1} µm ({fall:.1}× lower), reduced χ² {:.2} → {:.2}",
        b.total_rms_m.0 * 1e6,
        b.total_rms_m.1 * 1e6,
        b.reduced_chi2.0,
        b.reduced_chi2.1
    );
    assert!(fall >= 3.0, "{effect}: the error fell only {fall:.2}×");
    assert!(
        second.fit.reduced_chi2 <= 1.5,
        "{effect}: reduced χ² {}",
        second.fit.reduced_chi2
    );
    (e.param_value, e.param_interval, truth)
}

/// The hidden value of `effect`'s parameter `param` in the scenario's model (its `[extra_effects]` table).
fn scenario_truth(scenario: &Scenario, effect: &str, param: &str) -> f64 {
    let spec = scenario
        .model_spec(&[effect.to_string()])
        .expect("the scenario's model");
    spec.settings(None)
        .expect("the scenario's model has values")
        .iter()
        .find(|(r, _)| r.effect == effect && r.param == param)
        .map(|(_, s)| s.value)
        .unwrap_or(f64::NAN)
}

#[test]
#[ignore]
fn hidden_hertz_is_named() {
    hidden("hertz");
}

#[test]
#[ignore]
fn hidden_hunt_crossley_is_named() {
    hidden("hunt_crossley");
}

#[test]
#[ignore]
fn hidden_restitution_damping_is_named() {
    hidden("restitution_damping");
}

#[test]
#[ignore]
fn hidden_plastic_dent_is_named() {
    hidden("plastic_dent");
}

#[test]
#[ignore]
fn hidden_rolling_resistance_is_named() {
    hidden("rolling_resistance");
}

#[test]
#[ignore]
fn hidden_inertia_factor_is_named() {
    hidden("inertia_factor");
}

#[test]
#[ignore]
fn hidden_drag_is_named() {
    hidden("drag");
}

/// A rolled camera whose surface line is seen: the estimator measures the line's tilt and takes it out, so
/// (a) the session's measured roll (the mean of the shots' `surface_tilt_deg`; the renderer's truth is
/// `surface_tilt_deg = −roll` for down-slope +x) matches the hidden 3° within its error, and (b) nothing is
/// left for the fit's `camera_roll` to explain: the verdict is `no_missing_effect`. (The fit's
/// `camera_roll` remains for what the line cannot tell; it is named on synthetic tracks without a line,
/// `crates/diagnose/tests/diagnose.rs`.)
#[test]
#[ignore]
fn hidden_camera_roll_is_measured_and_taken_out() {
    let scenario = Scenario::preset("effect-camera_roll").unwrap();
    let roll = scenario_truth(&scenario, "camera_roll", "roll_deg");
    let dir = tempfile::tempdir().unwrap();
    let session = render(&scenario, dir.path());
    let a = run(&session, dir.path(), None);
    let tilts: Vec<(f64, f64)> = a
        .shots
        .iter()
        .filter_map(|s| s.estimate.surface_tilt_deg.map(|m| (m.value, m.se)))
        .collect();
    assert_eq!(tilts.len(), a.shots.len(), "every shot's line seen: {tilts:?}");
    let n = tilts.len() as f64;
    let mean = tilts.iter().map(|t| t.0).sum::<f64>() / n;
    // The mean's error: the larger of the stated errors' and the scatter's.
    let stated = (tilts.iter().map(|t| t.1 * t.1).sum::<f64>()).sqrt() / n;
    let scatter = (tilts.iter().map(|t| (t.0 - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt() / n.sqrt();
    let se = stated.max(scatter);
    let measured_roll = -mean;
    eprintln!(
        "camera_roll: measured roll {measured_roll:.4}° ± {se:.4}° (stated {stated:.4}, scatter {scatter:.4}) over {} shots, hidden {roll}°",
        tilts.len()
    );
    assert!(
        (measured_roll - roll).abs() <= 3.0 * se,
        "measured roll {measured_roll} ± {se} vs hidden {roll}"
    );
    let d = a.diagnosis.as_ref().expect("the diagnosis ran");
    eprintln!("camera_roll: {}", d.verdict.sentence);
    eprintln!(
        "| effect-camera_roll | {} | roll {measured_roll:.3}° ± {se:.3}° measured from the line (hidden {roll}°) | {} | {:.1} s |",
        d.verdict.kind.name(),
        if (measured_roll - roll).abs() <= 1.96 * se {
            "yes"
        } else {
            "no"
        },
        d.seconds
    );
    assert_eq!(d.verdict.kind, VerdictKind::NoMissingEffect, "{}", d.verdict.sentence);
}

/// A compliant contact patch (the slip reverses), at the preset's compliance 1e-5 m/N and a factor 3
/// stiffer: `tangential_spring` is named, removes ≥ 90 % of the systematic misfit, and its compliance is
/// recovered within 10 %.
#[test]
#[ignore]
fn hidden_tangential_spring_is_named_at_two_magnitudes() {
    for compliance in ["1e-5", "3e-6"] {
        let text = bouncelab_render::preset_toml("effect-tangential_spring")
            .unwrap()
            .replace("compliance = 1e-5", &format!("compliance = {compliance}"));
        let scenario = Scenario::parse(&text, &format!("tangential spring λ = {compliance}")).unwrap();
        let (value, _, truth) = hidden_in("tangential_spring", &scenario);
        let err = (value - truth) / truth;
        assert!(
            err.abs() <= 0.1,
            "compliance {value} vs {truth} ({:+.1} %)",
            err * 100.0
        );
    }
}

/// No hidden effect, three seeds: no false alarm; and k, b within 2 % of the truth with 95 % intervals
/// covering it.
#[test]
#[ignore]
fn no_hidden_effect_no_false_alarm_and_k_b_recovered() {
    for seed in [1, 2, 3] {
        let dir = tempfile::tempdir().unwrap();
        let mut scenario = Scenario::preset("none").unwrap();
        scenario.seed = seed;
        let session = render(&scenario, dir.path());
        let a = run(&session, dir.path(), None);
        let d = a.diagnosis.as_ref().expect("the diagnosis ran");
        eprintln!("none, seed {seed}: {}", d.verdict.sentence);
        assert_eq!(
            d.verdict.kind,
            VerdictKind::NoMissingEffect,
            "seed {seed}: {}",
            d.verdict.sentence
        );
        // μ is fitted per surface: determined by the oblique shots, and near the hidden 0.5.
        let mu = a.fit.param("clay:coulomb.mu").expect("μ fitted per surface");
        eprintln!(
            "  clay:coulomb.mu = {:.4} {:?} (truth 0.5){}",
            mu.value,
            mu.interval,
            mu.not_identified
                .as_deref()
                .map(|w| format!(", not identified: {w}"))
                .unwrap_or_default()
        );
        assert!(mu.not_identified.is_none(), "seed {seed}: {:?}", mu.not_identified);
        assert!((mu.value - 0.5).abs() < 0.05 * 0.5, "seed {seed}: μ {}", mu.value);
        for (name, truth) in [("clay:spring.k", 25650.0), ("clay:damping.b", 14.0)] {
            let p = a.fit.param(name).unwrap();
            let [lo, hi] = p.interval.expect("an interval");
            let err = (p.value - truth) / truth;
            eprintln!(
                "  {name} = {:.4} [{lo:.4}, {hi:.4}] (truth {truth}, {:+.3} %)",
                p.value,
                err * 100.0
            );
            assert!(err.abs() < 0.02, "seed {seed}: {name} {} vs {truth}", p.value);
            assert!(
                lo <= truth && truth <= hi,
                "seed {seed}: {name} [{lo}, {hi}] misses {truth}"
            );
        }
    }
}

/// An effect outside the library (an adhesive pull-off near separation, as a custom formula term in the
/// renderer's physics): no library effect is named.
#[test]
#[ignore]
fn an_effect_outside_the_library_is_not_named() {
    let text = bouncelab_render::preset_toml("none")
        .unwrap()
        .replace("effects = []", "effects = [\"pull_off\"]")
        + "\n[extra_effects.pull_off]\nkind = \"custom\"\nphase = \"restitution\"\nnormal = \"-f0 * exp(-delta / d0)\"\nf0 = 10\nd0 = 5e-4\n";
    let scenario = Scenario::parse(&text, "none + pull-off").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let session = render(&scenario, dir.path());
    let a = run(&session, dir.path(), None);
    let d = a.diagnosis.as_ref().expect("the diagnosis ran");
    eprintln!("pull-off: {}", d.verdict.sentence);
    assert_eq!(d.verdict.kind, VerdictKind::NoneExplains, "{}", d.verdict.sentence);
    assert!(d.verdict.effect.is_none());
    // The term search proposes a pull where the pull-off acts, and it removes most of the misfit.
    let p = d.proposal.as_ref().expect("a formula term proposed");
    let t = &p.terms[0];
    assert!(t.target == "normal" && t.phase == "restitution" && t.c < 0.0, "{p:?}");
    assert!(p.systematic_after_m < 0.5 * p.systematic_before_m, "{p:?}");
}

/// The pair preset `pair-A+B`: both effects named (one after the other: the search goes on from the model
/// with the first), each magnitude within 10 % of the truth. Prints the verdict table's rows.
fn pair(a: &str, b: &str) {
    let scenario = Scenario::preset(&format!("pair-{a}+{b}")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let session = render(&scenario, dir.path());
    let run = run(&session, dir.path(), None);
    let d = run.diagnosis.as_ref().expect("the diagnosis ran");
    eprintln!("{a} + {b}: {}", d.verdict.sentence);
    let mut named = d.verdict.effects.clone();
    named.sort();
    let mut want = vec![a.to_string(), b.to_string()];
    want.sort();
    assert_eq!(named, want, "{}", d.verdict.sentence);
    // The last search's named candidate carries every parameter, both effects' refitted together.
    let last = d.then.as_deref().unwrap_or(d);
    let c = last
        .candidate(last.verdict.effect.as_deref().expect("a named effect"))
        .unwrap();
    let fit = &c.evidence.as_ref().expect("its fit").fit;
    for effect in [a, b] {
        let info = bouncelab_model::builtin(effect).unwrap();
        let param = info.params[0].name;
        let truth = scenario_truth(&scenario, effect, param);
        let p = fit
            .parameters
            .iter()
            .find(|p| p.effect == effect && p.param == param)
            .unwrap_or_else(|| panic!("{effect}.{param} not fitted: {:?}", fit.parameters));
        let (mut value, mut truth, mut interval) = (p.value, truth, p.interval);
        let mut label = format!("{effect}.{param}");
        if effect == "hunt_crossley" {
            // λ and n trade along a valley (a larger n with a larger λ fits as well): the magnitude that
            // the shots determine is the damping force λ·δⁿ·δ̇, compared at δ = 2 mm, δ̇ = 1 m/s.
            let n_of = |v: Option<f64>| v.unwrap_or(1.0);
            let n_fit = n_of(
                fit.parameters
                    .iter()
                    .find(|p| p.effect == effect && p.param == "n")
                    .map(|p| p.value),
            );
            let n_true = scenario_truth(&scenario, effect, "n");
            let force = |lambda: f64, n: f64| lambda * 0.002f64.powf(n);
            eprintln!("hunt_crossley: λ = {value:.4e}, n = {n_fit:.3} (truth λ = {truth}, n = {n_true})");
            (value, truth, interval) = (force(value, n_fit), force(truth, n_true), None);
            label = "hunt_crossley λ·δⁿ at δ = 2 mm (N·s/m)".into();
        }
        let err = (value - truth) / truth;
        let covers = interval.map(|[lo, hi]| lo <= truth && truth <= hi);
        eprintln!(
            "| pair-{a}+{b} | {} | {label} = {:.4e} ({:+.1} % of {truth:e}) | {} | {:.1} s |",
            d.verdict.kind.name(),
            value,
            err * 100.0,
            match covers {
                Some(true) => "yes",
                Some(false) => "no",
                None => "no interval",
            },
            d.seconds
        );
        assert!(err.abs() <= 0.1, "{label} = {value} vs {truth}");
    }
}

#[test]
#[ignore]
fn hidden_pair_hertz_and_drag_both_named() {
    pair("hertz", "drag");
}

#[test]
#[ignore]
fn hidden_pair_hunt_crossley_and_rolling_resistance_both_named() {
    pair("hunt_crossley", "rolling_resistance");
}

/// Inertia and a rolled camera whose line is seen: the roll is measured from the line and taken out (see
/// `hidden_camera_roll_is_measured_and_taken_out`), so the search names the inertia change alone.
#[test]
#[ignore]
fn hidden_pair_inertia_and_camera_roll_inertia_named_roll_measured() {
    let scenario = Scenario::preset("pair-inertia_factor+camera_roll").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let session = render(&scenario, dir.path());
    let a = run(&session, dir.path(), None);
    let d = a.diagnosis.as_ref().expect("the diagnosis ran");
    eprintln!("inertia + roll: {}", d.verdict.sentence);
    assert_eq!(d.verdict.effects, ["inertia_factor"], "{}", d.verdict.sentence);
    let c = d.candidate("inertia_factor").unwrap();
    let e = c.evidence.as_ref().unwrap();
    let truth = scenario_truth(&scenario, "inertia_factor", "dc");
    let roll = scenario_truth(&scenario, "camera_roll", "roll_deg");
    let tilts: Vec<f64> = a
        .shots
        .iter()
        .filter_map(|s| s.estimate.surface_tilt_deg.map(|m| m.value))
        .collect();
    let measured_roll = -tilts.iter().sum::<f64>() / tilts.len() as f64;
    eprintln!(
        "| pair-inertia_factor+camera_roll | {} | dc = {:.4} ({:+.1} % of {truth}); roll {measured_roll:.3}° measured from the line (hidden {roll}°) | {} | {:.1} s |",
        d.verdict.kind.name(),
        e.param_value,
        (e.param_value - truth) / truth * 100.0,
        match e.param_interval {
            Some([lo, hi]) if lo <= truth && truth <= hi => "yes",
            Some(_) => "no",
            None => "no interval",
        },
        d.seconds
    );
    assert!(
        ((e.param_value - truth) / truth).abs() <= 0.1,
        "dc {} vs {truth}",
        e.param_value
    );
    assert!(
        (measured_roll - roll).abs() <= 0.1 * roll,
        "roll {measured_roll} vs {roll}"
    );
}
