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

use bouncelab_analyze::{Analysis, AnalyzeOptions, NoProgress, analyze};
use bouncelab_diagnose::{VerdictKind, add_effect_to_model_toml};
use bouncelab_frames::ClipOptions;
use bouncelab_render::{RenderOptions, Scenario, render_with};
use bouncelab_store::ClipFingerprint;
use std::path::{Path, PathBuf};

#[path = "../../../tests/common/verdicts.rs"]
mod verdicts;
use verdicts::{fit_of, magnitude, measured_roll, print_candidates, scenario_truth};

/// Renders `scenario` into `root/render` and returns the session folder.
fn render(scenario: &Scenario, root: &Path) -> PathBuf {
    let out = render_with(
        scenario,
        &root.join("render"),
        &RenderOptions::default(),
        &bouncelab_render::NoRenderProgress,
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
    let a = analyze(session, &options, &NoProgress).unwrap_or_else(|e| panic!("analysing {}: {e}", session.display()));
    assert!(a.measure.failed.is_empty(), "shots failed: {:?}", a.measure.failed);
    a
}

/// The effect preset `effect-<name>`, judged by issue 16's criteria: named first (alone, or first of an
/// ambiguous few); its magnitude within 10 % of the truth; and, once added at its fitted values, the misfit
/// left within the session's floor (learned from its own flight) with χ²_red ≤ 1.5. Prints the verdict
/// table's row (magnitude recovered, interval covers the truth, time).
///
/// Not "the error falls ≥ 3×": that ratio is the hidden effect's size over the floor, not a measure of the
/// search. The floor bounds what any model can reach (8–9 µm on these renders), and with μ fitted per
/// surface the paper's model absorbs part of a contact or flight effect into μ, so the same effect found
/// as well shows a smaller fall (restitution damping: 32.9 µm before with μ fixed, 26.4 µm with μ free,
/// 9.1 µm after either way). Whether the interval covers the truth is printed, not asserted: issue 16
/// item 6 is open for several effects (docs/accuracy.md).
fn hidden(effect: &str) {
    hidden_in(effect, &Scenario::preset(&format!("effect-{effect}")).unwrap());
}

/// [`hidden`] on a given scenario with `effect` hidden; returns its fitted magnitude (see [`magnitude`]),
/// the interval and the truth (from the scenario text).
fn hidden_in(effect: &str, scenario: &Scenario) -> (f64, Option<[f64; 2]>, f64) {
    let dir = tempfile::tempdir().unwrap();
    let session = render(scenario, dir.path());
    let first = run(&session, dir.path(), None);
    let d = first.diagnosis.as_ref().expect("the diagnosis ran");
    eprintln!("{effect}: {}", d.verdict.sentence);
    print_candidates(d);
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
    let m = magnitude(scenario, effect, &e.fit.parameters).expect("the effect's parameter fitted");
    eprintln!(
        "{effect}: systematic part removed {:.1} %",
        e.explained_fraction * 100.0
    );
    if effect == "tangential_spring" {
        assert!(e.explained_fraction >= 0.9, "{effect}: {}", e.explained_fraction);
    }
    eprintln!(
        "| effect-{effect} | {} | {} = {:.4e} ({:+.1} % of {:e}) | {} | {:.1} s |",
        d.verdict.kind.name(),
        m.label,
        m.value,
        m.error() * 100.0,
        m.truth,
        m.covers_text(),
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
    let after = second
        .diagnosis
        .as_ref()
        .expect("the diagnosis ran with the effect added");
    eprintln!(
        "{effect}: with it added, systematic {:.1} µm against the floor {:.1} µm; {}",
        after.baseline.systematic_m * 1e6,
        after.floor.floor_m * 1e6,
        after.verdict.sentence
    );
    assert!(
        after.baseline.systematic_m <= after.floor.floor_m,
        "{effect}: {:.1} µm left above the {:.1} µm floor",
        after.baseline.systematic_m * 1e6,
        after.floor.floor_m * 1e6
    );
    assert!(
        second.fit.reduced_chi2 <= 1.5,
        "{effect}: reduced χ² {}",
        second.fit.reduced_chi2
    );
    assert!(
        m.error().abs() <= 0.1,
        "{effect}: {} = {} vs {} ({:+.1} %)",
        m.label,
        m.value,
        m.truth,
        m.error() * 100.0
    );
    (m.value, m.interval, m.truth)
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
    let (measured_roll, se, lines) = measured_roll(&a).expect("the lines measured a tilt");
    assert_eq!(lines, a.shots.len(), "every shot's line seen");
    eprintln!("camera_roll: measured roll {measured_roll:.4}° ± {se:.4}° over {lines} shots, hidden {roll}°");
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
        let label = format!("seed {seed}");
        assert_clean_clay(&a, &label);
        // μ is fitted per surface: determined by the oblique shots.
        let mu = a.fit.param("clay:coulomb.mu").expect("μ fitted per surface");
        assert!(mu.not_identified.is_none(), "{label}: {:?}", mu.not_identified);
        for (name, truth) in CLAY_K_B {
            let [lo, hi] = a.fit.param(name).unwrap().interval.expect("an interval");
            assert!(
                lo <= truth && truth <= hi,
                "{label}: {name} [{lo}, {hi}] misses {truth}"
            );
        }
    }
}

/// The `none` preset's clay spring and damping: (parameter, truth).
const CLAY_K_B: [(&str, f64); 2] = [("clay:spring.k", 25650.0), ("clay:damping.b", 14.0)];

/// A session with no hidden effect: `no_missing_effect`, μ within 5 % of the hidden 0.5 and k, b within 2 %
/// of the truth (each printed with its interval).
fn assert_clean_clay(a: &Analysis, label: &str) {
    let d = a.diagnosis.as_ref().expect("the diagnosis ran");
    eprintln!("{label}: {}", d.verdict.sentence);
    print_candidates(d);
    assert_eq!(
        d.verdict.kind,
        VerdictKind::NoMissingEffect,
        "{label}: {}",
        d.verdict.sentence
    );
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
    assert!((mu.value - 0.5).abs() < 0.05 * 0.5, "{label}: μ {}", mu.value);
    for (name, truth) in CLAY_K_B {
        let p = a.fit.param(name).unwrap();
        let err = (p.value - truth) / truth;
        eprintln!(
            "  {name} = {:.4} {:?} (truth {truth}, {:+.3} %)",
            p.value,
            p.interval,
            err * 100.0
        );
        assert!(err.abs() < 0.02, "{label}: {name} {} vs {truth}", p.value);
    }
}

/// No hidden effect, filmed 35 ms either side (drag's flights): each line's tilt error (≈ 0.01°) turns the
/// outgoing tangential flight by tens of µm over so long a flight; with each shot's frame free to turn
/// within its line's σ the session is clean: `no_missing_effect`, μ, k and b near the truth.
#[test]
#[ignore]
fn no_hidden_effect_on_long_flights_no_false_alarm() {
    let text = bouncelab_render::preset_toml("none")
        .unwrap()
        .replace("pre_contact_ms = 10", "pre_contact_ms = 35")
        .replace("post_separation_ms = 10", "post_separation_ms = 35");
    assert!(text.contains("pre_contact_ms = 35"), "the preset's flight is set");
    let scenario = Scenario::parse(&text, "none, 35 ms of flight").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let session = render(&scenario, dir.path());
    let a = run(&session, dir.path(), None);
    assert_clean_clay(&a, "none, 35 ms");
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
    pair_in(a, b, &Scenario::preset(&format!("pair-{a}+{b}")).unwrap());
}

/// [`pair`] on the session of `scenario`.
fn pair_in(a: &str, b: &str, scenario: &Scenario) {
    let dir = tempfile::tempdir().unwrap();
    let session = render(scenario, dir.path());
    let run = run(&session, dir.path(), None);
    let d = run.diagnosis.as_ref().expect("the diagnosis ran");
    eprintln!("{a} + {b}: {}", d.verdict.sentence);
    print_candidates(d);
    let mut named = d.verdict.effects.clone();
    named.sort();
    let mut want = vec![a.to_string(), b.to_string()];
    want.sort();
    assert_eq!(named, want, "{}", d.verdict.sentence);
    // The last search's named candidate carries every parameter, both effects' refitted together.
    for effect in [a, b] {
        let fitted = fit_of(d, effect).unwrap_or_else(|| panic!("{effect} not fitted"));
        let m = magnitude(scenario, effect, fitted).unwrap_or_else(|| panic!("{effect} not fitted: {fitted:?}"));
        eprintln!(
            "| pair-{a}+{b} | {} | {} = {:.4e} ({:+.1} % of {:e}) | {} | {:.1} s |",
            d.verdict.kind.name(),
            m.label,
            m.value,
            m.error() * 100.0,
            m.truth,
            m.covers_text(),
            d.seconds
        );
        assert!(m.error().abs() <= 0.1, "{} = {} vs {}", m.label, m.value, m.truth);
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
    let (measured_roll, ..) = measured_roll(&a).expect("the lines measured a tilt");
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
