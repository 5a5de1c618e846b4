//! The search on synthetic sessions whose truth is known: each library effect hidden in the data is named
//! first and removes the misfit; no hidden effect gives "no missing effect"; an effect outside the library
//! is not given a library name; a mis-stated σ and a systematic tracking error in contact change no verdict.
//!
//! Every session: 12 clay shots (drop heights 0.2, 0.55, 0.9 m × inclines 0, 7.5, 15, 22.5°) of the
//! clay-like base model (k = 25650 N/m, b = 14 N·s/m, μ = 0.5) with the effect at the renderer's preset
//! magnitude, 10 kHz, 10 ms either side of the contact, noise 12 µm (0.03 px at 4e-4 m/px); the current
//! model is the paper's model file (k and b free per surface). Each search takes 1–4 s in the dev
//! profile; the whole file runs in about a minute on 2 cores. `sweep_over_seeds` (ignored) repeats the
//! effect cases on more seeds and prints the table of `docs/diagnosis.md`:
//!
//! ```text
//! cargo test -p bouncelab-diagnose --test diagnose sweep_over_seeds -- --ignored --nocapture
//! ```

mod common;

use bouncelab_diagnose::{
    DiagnoseError, Diagnosis, FittedBaseline, SearchOptions, VerdictKind, add_effect_to_model_toml,
    find_missing_effect, find_missing_effect_from, find_missing_effect_with,
};
use bouncelab_fit::{FitOptions, NoObserver, fit};
use bouncelab_model::{ModelSpec, PAPER_MODEL_TOML};
use common::*;

/// The effect is named first, its switch parameter is near the truth, and adding it removes the misfit:
/// the residual's systematic part falls at least 3× and the reduced χ² is at most 1.5; the total RMS falls
/// at least 3× too, except for drag, whose whole misfit (17 µm against 12 µm of noise) is too small for
/// that.
fn hidden(effect: &str) -> Diagnosis {
    let shots = session(&truth(Some(effect)), 1, Tracking::default());
    let d = run(effect, &shots, &SearchOptions::default());
    assert!(
        matches!(d.verdict.kind, VerdictKind::MissingEffect | VerdictKind::Ambiguous),
        "{effect}: {}",
        d.verdict.sentence
    );
    assert_eq!(
        d.verdict.effects.first().map(String::as_str),
        Some(effect),
        "{}",
        d.verdict.sentence
    );
    assert_eq!(d.candidates[0].effect, effect);
    let c = &d.candidates[0];
    let e = c.evidence.as_ref().unwrap();
    let truth = MAGNITUDES.iter().find(|(n, _)| *n == effect).unwrap().1[0].1;
    // Within 10 %; drag within 25 %: once each shot's start is measured from its frames (not given), 10 ms
    // of flight constrain C_d only loosely (seeds 1–5 give 1.28–1.80 for 1.5, SD ≈ 0.2; the search's stated
    // interval, ±0.1, is narrower than that scatter: see docs/diagnosis.md, Limits).
    let tolerance = if effect == "drag" { 0.25 } else { 0.1 };
    assert!(
        (e.param_value - truth).abs() < tolerance * truth.abs(),
        "{effect}: {} = {} vs truth {truth}",
        c.param,
        e.param_value
    );
    let systematic_fall = d.baseline.systematic_m / e.systematic_after_m.max(1e-9);
    eprintln!(
        "{effect}: RMS falls {:.1}×, systematic part {:.1}×, χ²_red after {:.3}",
        e.error_fall, systematic_fall, e.chi2_red_after
    );
    assert!(
        systematic_fall >= 3.0,
        "{effect}: systematic part falls only {systematic_fall}×"
    );
    assert!(e.chi2_red_after <= 1.5, "{effect}: χ²_red after {}", e.chi2_red_after);
    if effect != "drag" {
        assert!(e.error_fall >= 3.0, "{effect}: RMS falls only {}×", e.error_fall);
    }
    d
}

#[test]
fn hidden_hertz_is_named() {
    let d = hidden("hertz");
    assert_eq!(d.verdict.kind, VerdictKind::MissingEffect);
}

#[test]
fn hidden_hunt_crossley_is_named() {
    let d = hidden("hunt_crossley");
    assert_eq!(d.verdict.kind, VerdictKind::MissingEffect);
    assert!(
        d.verdict.sentence.contains("bouncelab model add hunt_crossley"),
        "{}",
        d.verdict.sentence
    );
}

/// Restitution damping, a plastic dent and Hunt–Crossley damping (whose exponent can go to 0) all lower
/// the COR in restitution: on these shots each fits the others' data to within the tolerance, so the
/// verdict is "ambiguous", with the true effect first (it fits best, with fewest parameters).
#[test]
fn hidden_restitution_damping_is_named_first() {
    hidden("restitution_damping");
}

#[test]
fn hidden_plastic_dent_is_named_first() {
    hidden("plastic_dent");
}

#[test]
fn hidden_rolling_resistance_is_named() {
    let d = hidden("rolling_resistance");
    assert_eq!(d.verdict.kind, VerdictKind::MissingEffect);
}

#[test]
fn hidden_inertia_factor_is_named() {
    let d = hidden("inertia_factor");
    assert_eq!(d.verdict.kind, VerdictKind::MissingEffect);
}

#[test]
fn hidden_drag_is_named() {
    let d = hidden("drag");
    assert_eq!(d.verdict.kind, VerdictKind::MissingEffect);
}

/// The roll is found although the tracker's x origin is arbitrary and the start is the *observed* state.
#[test]
fn hidden_camera_roll_is_named() {
    let d = hidden("camera_roll");
    assert_eq!(d.verdict.kind, VerdictKind::MissingEffect);
}

/// A compliant contact patch (the slip reverses): the library's `tangential_spring` is named with its
/// compliance within 10 %, at two magnitudes a factor 3 apart, and removes ≥ 90 % of the systematic
/// misfit.
#[test]
fn hidden_tangential_spring_is_named_with_its_compliance_at_two_magnitudes() {
    for compliance in [1e-5, 3e-6] {
        let shots = session(
            &truth_at(Some("tangential_spring"), &[("compliance", compliance)]),
            1,
            Tracking::default(),
        );
        let d = run(
            &format!("tangential_spring λ = {compliance:e}"),
            &shots,
            &SearchOptions::default(),
        );
        assert_eq!(d.verdict.kind, VerdictKind::MissingEffect, "{}", d.verdict.sentence);
        assert_eq!(d.verdict.effect.as_deref(), Some("tangential_spring"));
        let e = d.candidates[0].evidence.as_ref().unwrap();
        let err = (e.param_value - compliance) / compliance;
        eprintln!(
            "λ = {compliance:e}: fitted {:.4e} ({:+.2} %), interval {:?}, explained {:.3}",
            e.param_value,
            err * 100.0,
            e.param_interval,
            e.explained_fraction
        );
        assert!(err.abs() < 0.1, "λ {} vs {compliance}", e.param_value);
        assert!(e.explained_fraction >= 0.9, "{}", e.explained_fraction);
    }
}

/// Two effects at once (Hertz's stiffness and rolling resistance): neither explains all of the misfit alone;
/// the search names the one that explains most, goes on from the model with it and names the other, each
/// with its magnitude within 10 %.
#[test]
fn two_hidden_effects_are_both_named() {
    let shots = session(&truth_pair("hertz", "rolling_resistance"), 1, Tracking::default());
    let d = run("hertz + rolling_resistance", &shots, &SearchOptions::default());
    let mut named = d.verdict.effects.clone();
    named.sort();
    assert_eq!(d.verdict.kind, VerdictKind::MissingEffect, "{}", d.verdict.sentence);
    assert_eq!(named, ["hertz", "rolling_resistance"], "{}", d.verdict.sentence);
    let second = d.then.as_ref().expect("the search went on");
    print("  then", second);
    // Each magnitude, from the search that named it last (the second one refits the first too).
    assert_magnitudes(
        second,
        &[("hertz", "k_h", 400_000.0), ("rolling_resistance", "c_rr", 0.02)],
    );
}

/// Each `(effect, param, truth)` within 10 % in the fit of `last`'s first named effect (the search that named
/// it last refits the others too); each printed with its interval.
fn assert_magnitudes(last: &Diagnosis, expected: &[(&str, &str, f64)]) {
    let fit = &last
        .candidate(&last.verdict.effects[0])
        .unwrap()
        .evidence
        .as_ref()
        .unwrap()
        .fit;
    for &(effect, param, truth) in expected {
        let p = fit
            .parameters
            .iter()
            .find(|p| p.effect == effect && p.param == param)
            .unwrap_or_else(|| panic!("{effect}.{param} in {:?}", fit.parameters));
        let err = (p.value - truth) / truth;
        eprintln!(
            "{effect}.{param} = {:.4e} ({:+.2} %), interval {:?}",
            p.value,
            err * 100.0,
            p.interval
        );
        assert!(err.abs() < 0.1, "{effect}.{param} = {} vs {truth}", p.value);
    }
}

/// Hertz and drag at the renderer's magnitudes on exact tracks filmed as the renderer films drag (35 ms of
/// flight either side): both named, each within 10 % (k_h +0.08 %, C_d +0.3 %; 26 s in release). The
/// rendered pair (`crates/analyze/tests/acceptance.rs`) names neither; this and the next test separate the
/// search from what `analyze` adds. Slow: ignored.
#[test]
#[ignore]
fn hertz_and_drag_on_long_flights_are_both_named() {
    hertz_and_drag_on_long_flights(Tracking::default(), SearchOptions::default());
}

/// [`hertz_and_drag_on_long_flights_are_both_named`] with each shot's surface line off by up to ±40 µm and
/// the levels free per shot, as `analyze` fits them (here without the prior from each line's σ). **Fails
/// today (issue 16)**: neither is named; drag's fit goes to C_d = −0.44 (unphysical) and Hertz explains
/// 16 % — the rendered pair's failure, reproduced in 80 s without rendering or tracking. Ignored until
/// fixed.
#[test]
#[ignore]
fn hertz_and_drag_on_long_flights_with_surface_levels_are_both_named() {
    hertz_and_drag_on_long_flights(
        Tracking {
            surface_level_m: 40e-6,
            ..Tracking::default()
        },
        SearchOptions {
            surface_levels: true,
            ..SearchOptions::default()
        },
    );
}

fn hertz_and_drag_on_long_flights(tracking: Tracking, options: SearchOptions) {
    let mut model = truth_at(Some("hertz"), &[("k_h", 600_000.0)]);
    let drag = truth(Some("drag"));
    model.push(drag.effect("drag").expect("drag").clone_box());
    let shots = session_filmed(&model, 1, tracking, 0.035);
    let d = run("hertz + drag, 35 ms", &shots, &options);
    if let Some(then) = d.then.as_deref() {
        print("  then", then);
    }
    let mut named = d.verdict.effects.clone();
    named.sort();
    assert_eq!(named, ["drag", "hertz"], "{}", d.verdict.sentence);
    let last = d.then.as_deref().unwrap_or(&d);
    assert_magnitudes(last, &[("hertz", "k_h", 600_000.0), ("drag", "cd", 1.5)]);
}

/// A tracker that finds the rim differently after the bounce (the centres of the outgoing flight moved by
/// √2·Δr on each axis, Δr ~ 25 µm) leaves a misfit that each flight's own fit hides. Counted from the
/// radius's change, it is the floor's, not a missing effect; without that count the same session is
/// called a misfit. A real effect on top of it is still named.
#[test]
fn a_rim_found_differently_after_the_bounce_is_the_floor_s_not_a_missing_effect() {
    let tracking = Tracking {
        rim_jump_m: 25e-6,
        ..Tracking::default()
    };
    let shots = session(&truth(None), 5, tracking);
    let d = run("none, rim jumps", &shots, &SearchOptions::default());
    assert_eq!(d.verdict.kind, VerdictKind::NoMissingEffect, "{}", d.verdict.sentence);
    let rim = d.floor.rim_change_m.expect("the rim's change counted");
    assert!(
        rim > 5e-6 && d.verdict.sentence.contains("rim's change"),
        "{rim}: {}",
        d.verdict.sentence
    );
    let blind: Vec<MeasuredShot> = shots
        .iter()
        .cloned()
        .map(|s| MeasuredShot {
            rim_change_m: None,
            ..s
        })
        .collect();
    let d = run("none, rim jumps not counted", &blind, &SearchOptions::default());
    assert!(d.baseline.misfit, "{}", d.verdict.sentence);
    let shots = session(&truth(Some("hertz")), 5, tracking);
    let d = run("hertz, rim jumps", &shots, &SearchOptions::default());
    assert_eq!(d.verdict.effect.as_deref(), Some("hertz"), "{}", d.verdict.sentence);
}

/// Wobbles the centre's height by ±`wobble_m` (alternate frames) in the 1.2 ms from 12 ms after `shot`'s
/// first frame: in its restitution (the touch is 10 ms in, the contact 4.4 ms long), as a track that slid
/// off the ball there and back would.
fn wobble_in_restitution(shot: &mut MeasuredShot, wobble_m: f64) {
    let t0 = shot.frames[0].t_s;
    for (i, f) in shot.frames.iter_mut().enumerate() {
        if (12.0e-3..13.2e-3).contains(&(f.t_s - t0)) {
            f.y_m += if i % 2 == 0 { wobble_m } else { -wobble_m };
        }
    }
}

/// A phase that misfits because of one shot's frames, and not without them, is that shot's, not the
/// model's: the verdict stays `no_missing_effect` and names the shot. The same wobble in three shots is a
/// misfit.
#[test]
fn one_shot_s_misfit_in_a_phase_is_not_the_model_s() {
    let mut shots = session(&truth(None), 1, Tracking::default());
    wobble_in_restitution(&mut shots[4], 160e-6);
    let d = run(
        "none, one shot wobbles in restitution",
        &shots,
        &SearchOptions::default(),
    );
    let phase = d
        .signature
        .phases
        .iter()
        .max_by(|a, b| a.systematic_m.total_cmp(&b.systematic_m))
        .unwrap();
    assert!(
        phase.systematic_m > d.thresholds.phase_tolerance_m,
        "the wobble makes a phase misfit: {phase:?}"
    );
    assert_eq!(d.verdict.kind, VerdictKind::NoMissingEffect, "{}", d.verdict.sentence);
    assert!(
        d.verdict
            .sentence
            .contains(&format!("is one shot's: `{}`", shots[4].name)),
        "{}",
        d.verdict.sentence
    );
    for k in [0, 7] {
        wobble_in_restitution(&mut shots[k], 160e-6);
    }
    let d = run(
        "none, three shots wobble in restitution",
        &shots,
        &SearchOptions::default(),
    );
    assert!(d.baseline.misfit, "{}", d.verdict.sentence);
    assert!(!d.verdict.sentence.contains("one shot's"), "{}", d.verdict.sentence);
}

/// A whole residual above the floor because of one shot's track (a wobble in its restitution large enough to
/// lift the whole), and within it without that shot, is that shot's, not the model's: `no_missing_effect`,
/// naming the shot. The same wobble in three shots is a misfit.
#[test]
fn one_shot_s_misfit_in_the_whole_residual_is_not_the_model_s() {
    let mut shots = session(&truth(None), 1, Tracking::default());
    wobble_in_restitution(&mut shots[4], 700e-6);
    let d = run("none, one shot wobbles hard", &shots, &SearchOptions::default());
    assert!(
        d.baseline.systematic_m > d.thresholds.tolerance_m,
        "the wobble lifts the whole residual above the floor: {} µm against {} µm",
        d.baseline.systematic_m * 1e6,
        d.thresholds.tolerance_m * 1e6
    );
    assert_eq!(d.verdict.kind, VerdictKind::NoMissingEffect, "{}", d.verdict.sentence);
    assert!(
        d.verdict.sentence.contains(&format!(
            "The whole residual's systematic part, {:.1} µm, is one shot's: `{}`",
            d.baseline.systematic_m * 1e6,
            shots[4].name
        )),
        "{}",
        d.verdict.sentence
    );
    for k in [0, 7] {
        wobble_in_restitution(&mut shots[k], 700e-6);
    }
    let d = run("none, three shots wobble hard", &shots, &SearchOptions::default());
    assert!(d.baseline.misfit, "{}", d.verdict.sentence);
    assert!(
        !d.verdict.sentence.contains("whole residual's systematic part"),
        "{}",
        d.verdict.sentence
    );
}

#[test]
fn no_hidden_effect_gives_no_missing_effect_on_three_seeds() {
    for seed in [1, 2, 3] {
        let shots = session(&truth(None), seed, Tracking::default());
        let d = run(&format!("none, seed {seed}"), &shots, &SearchOptions::default());
        assert_eq!(
            d.verdict.kind,
            VerdictKind::NoMissingEffect,
            "seed {seed}: {}",
            d.verdict.sentence
        );
        assert!(d.verdict.effects.is_empty() && !d.baseline.misfit);
        assert!(d.candidates.iter().all(|c| !c.explains));
        // A candidate contains the current model (at its neutral value), so it never ends above it. The
        // tangential spring's response rings as its compliance moves, and its fit stopped at λ ≈ 1e-7 m/N,
        // 3–5 % above the current model, until its neutral value was kept.
        for c in &d.candidates {
            let e = c.evidence.as_ref().unwrap();
            assert!(
                e.error_after <= d.baseline.fit.rms_m * (1.0 + 1e-6),
                "seed {seed}: {} ends at {:.3} µm above the current model's {:.3} µm",
                c.effect,
                e.error_after * 1e6,
                d.baseline.fit.rms_m * 1e6
            );
        }
        let spring = d
            .candidate("tangential_spring")
            .and_then(|c| c.evidence.as_ref())
            .unwrap();
        assert!(spring.kept_at_neutral && spring.param_value == 0.0);
        assert!(
            d.verdict.sentence.starts_with("No missing effect"),
            "{}",
            d.verdict.sentence
        );
        // The floor is learned from the flight (white noise only here: little structure) and stated.
        assert!(d.floor.flight_systematic_m.is_some() && d.floor.floor_m >= d.floor.contact_allowance_m);
        assert!(d.verdict.sentence.contains("floor"), "{}", d.verdict.sentence);
        // Detection limits: every candidate has one, stated in the verdict, and each hidden magnitude that
        // the tests above name lies beyond its limit. Not drag's: its linearised limit (≈ 3.4) overstates
        // what the session shows (drag at 1.5 is named above). Known limit, in `docs/diagnosis.md`.
        assert!(
            d.verdict.sentence.contains("detection limits"),
            "{}",
            d.verdict.sentence
        );
        for (effect, set) in MAGNITUDES.iter().filter(|(e, _)| *e != "drag") {
            let Some(c) = d.candidate(effect) else { continue };
            // Every candidate frees one parameter of its own (Hunt–Crossley's exponent is held), so each
            // has a linear limit.
            let limit = c.evidence.as_ref().and_then(|e| e.detection_limit);
            eprintln!(
                "  detection limit {effect} {}: {limit:?} (named at {:?})",
                c.param, set[0].1
            );
            let limit = limit.unwrap_or_else(|| panic!("{effect}: no detection limit"));
            assert!(limit > 0.0 && limit < (set[0].1 - c.neutral).abs(), "{effect}: {limit}");
        }
    }
}

/// A candidate at its neutral value is the current model, so it fits as the current model does, also
/// when each shot's frame turn is a nuisance (the line's tilt σ): the turns are differenced under the
/// current model for both. Differenced at the candidate's start instead, rolling resistance at c_rr = 0
/// fitted 0.17 % worse in χ² than the current model on a rendered clean session, and its fit on the
/// 144-shot `paper` session ended at ΔBIC +2311 with c_rr ≈ 5·10⁻⁶.
#[test]
fn a_candidate_at_its_neutral_value_fits_as_the_current_model_with_frame_turns() {
    let mut shots = session(&truth(None), 2, Tracking::default());
    for s in &mut shots {
        s.frame_sigma_rad = Some(3e-4);
    }
    let d = run("none, frame turns", &shots, &SearchOptions::default());
    assert_eq!(d.verdict.kind, VerdictKind::NoMissingEffect, "{}", d.verdict.sentence);
    let kept: Vec<_> = d
        .candidates
        .iter()
        .filter_map(|c| Some((c, c.evidence.as_ref()?)))
        .filter(|(_, e)| e.kept_at_neutral)
        .collect();
    assert!(kept.iter().any(|(c, _)| c.effect == "tangential_spring"));
    for (c, e) in kept {
        let (chi2, base) = (e.fit.chi2, d.baseline.fit.chi2);
        assert!(
            (chi2 - base).abs() <= 1e-9 * base,
            "{}: χ² {chi2} against {base}",
            c.effect
        );
    }
}

/// Incoming spins measured 0.3 rad/s off (RMS), as a spin estimator gives them on frames with 14 DN of
/// sensor noise: taken as exact, they leave the clean session's outgoing tangential flight misfitting and
/// the verdict is `none_explains`; with each spin's σ stated, the spin errors are taken out: no missing
/// effect on the clean session, and rolling resistance (a tangential effect the spins could have absorbed)
/// is still named with its magnitude within 10 %.
#[test]
fn incoming_spins_off_by_their_stated_sigma_change_no_verdict() {
    let sigma = 0.3;
    let spun = |effect: Option<&str>, stated: bool| {
        let mut shots = session(&truth(effect), 1, Tracking::default());
        let mut rng = bouncelab_fit::testutil::Rng::new(5);
        for s in &mut shots {
            s.start.state.omega += sigma * rng.normal();
            s.spin_sigma_rad_s = stated.then_some(sigma);
        }
        run(
            &format!("{effect:?}, spins off, σ stated {stated}"),
            &shots,
            &SearchOptions::default(),
        )
    };
    let exact = spun(None, false);
    assert_eq!(
        exact.verdict.kind,
        VerdictKind::NoneExplains,
        "{}",
        exact.verdict.sentence
    );
    let clean = spun(None, true);
    assert_eq!(
        clean.verdict.kind,
        VerdictKind::NoMissingEffect,
        "{}",
        clean.verdict.sentence
    );
    let rolling = spun(Some("rolling_resistance"), true);
    assert_eq!(
        rolling.verdict.effects,
        ["rolling_resistance"],
        "{}",
        rolling.verdict.sentence
    );
    let e = rolling.candidates[0].evidence.as_ref().unwrap();
    assert!((e.param_value - 0.02).abs() < 0.002, "c_rr {}", e.param_value);
}

fn invented(name: &str, body: &str, tracking: Tracking) -> Diagnosis {
    invented_from(&base_spec(), name, body, tracking)
}

fn invented_from(spec: &ModelSpec, name: &str, body: &str, tracking: Tracking) -> Diagnosis {
    let shots = session(&truth_with_custom(name, body), 1, tracking);
    let d = run_with(name, spec, &shots, &SearchOptions::default());
    assert_eq!(
        d.verdict.kind,
        VerdictKind::NoneExplains,
        "{name}: {}",
        d.verdict.sentence
    );
    assert!(d.verdict.effect.is_none() && d.verdict.effects.is_empty());
    assert!(d.baseline.misfit);
    // The signature replaces the name: where χ² sits.
    assert!(!d.signature.phases.is_empty());
    assert!(
        d.verdict.sentence.contains("The residual sits in"),
        "{}",
        d.verdict.sentence
    );
    d
}

/// An adhesive pull-off near separation (a custom term, outside the library): the closest library effect
/// (Hertzian stiffness) removes about 70 % of the misfit on the fitted shots but does not predict the
/// held-out ones better.
#[test]
fn invented_adhesion_is_not_given_a_library_name() {
    let d = invented("pull_off", ADHESION_STRONG, Tracking::default());
    // No library term has the pull-off's exponential shape, but the term library comes close: a constant
    // pull in restitution first.
    let p = d.proposal.as_ref().expect("a term proposed");
    assert_eq!(
        (p.terms[0].phase.as_str(), p.terms[0].formula.as_str()),
        ("restitution", "c"),
        "{p:?}"
    );
    assert!(p.terms[0].c < 0.0, "a pull: {p:?}");
    assert!(p.heldout_after_m < 0.5 * p.heldout_before_m, "{p:?}");
    assert!(p.model_toml.contains("kind = \"custom\""), "{}", p.model_toml);
}

/// A constant pull of 1.5 N while the ball leaves the surface is a term of the library: the search finds
/// it again, with its coefficient.
#[test]
fn a_hidden_library_term_is_proposed_back() {
    let d = invented(
        "pull",
        "phase = \"restitution\"\nnormal = \"-1.5\"",
        Tracking::default(),
    );
    let p = d.proposal.as_ref().expect("a term proposed");
    let t = &p.terms[0];
    assert_eq!(
        (t.phase.as_str(), t.target.as_str(), t.formula.as_str()),
        ("restitution", "normal", "c"),
        "{p:?}"
    );
    let se = t.c_std_error.expect("determined");
    assert!((t.c + 1.5).abs() < 4.0 * se.max(0.01), "c = {} ± {se}", t.c);
    assert!(p.systematic_after_m < 8e-6, "{p:?}");
}

/// Friction growing with the slip speed (a viscous tangential force on top of Coulomb's), against a model
/// that knows μ. (With μ free per surface, as in the shipped model, these shots end rolling and μ takes the
/// whole of it: the verdict is then `no_missing_effect`, systematic 3.7 µm.)
#[test]
fn invented_velocity_dependent_friction_is_not_given_a_library_name() {
    let d = invented_from(
        &known_mu_spec(),
        "viscous_slip",
        VISCOUS_SLIP_STRONG,
        Tracking::default(),
    );
    // It is a term of the library: −η·slip with η = 20 N·s/m.
    let p = d.proposal.as_ref().expect("a term proposed");
    let t = &p.terms[0];
    assert_eq!(
        (t.target.as_str(), t.formula.as_str()),
        ("tangential", "c * slip"),
        "{p:?}"
    );
    let se = t.c_std_error.expect("determined");
    assert!((t.c + 20.0).abs() < 4.0 * se.max(0.1), "c = {} ± {se}", t.c);
}

/// σ stated 1.4× too large or too small, and the flattened ball's centre found 20 µm off in contact:
/// the verdicts do not change. The decisions use the noise estimated from the residuals (reported as
/// `noise.ratio` ≈ 1/1.4 and 1.4 here).
#[test]
fn verdicts_hold_with_sigma_misstated_and_a_contact_tracking_error() {
    let cases: [(Option<&str>, f64, f64); 4] = [
        (None, 1.4, 20e-6),
        (None, 1.0 / 1.4, -20e-6),
        (Some("hunt_crossley"), 1.0 / 1.4, 20e-6),
        (Some("inertia_factor"), 1.4, -20e-6),
    ];
    for (effect, stated, bias) in cases {
        let tracking = Tracking {
            stated_over_true: stated,
            contact_bias_m: bias,
            ..Tracking::default()
        };
        let label = format!("{effect:?}, σ stated ×{stated:.2}, contact bias {:.0} µm", bias * 1e6);
        let d = run(&label, &session(&truth(effect), 2, tracking), &SearchOptions::default());
        assert!(
            (d.noise.ratio * stated - 1.0).abs() < 0.1,
            "{label}: noise ratio {}",
            d.noise.ratio
        );
        match effect {
            None => assert_eq!(
                d.verdict.kind,
                VerdictKind::NoMissingEffect,
                "{label}: {}",
                d.verdict.sentence
            ),
            Some(e) => {
                assert_eq!(
                    d.verdict.kind,
                    VerdictKind::MissingEffect,
                    "{label}: {}",
                    d.verdict.sentence
                );
                assert_eq!(d.verdict.effect.as_deref(), Some(e));
            }
        }
    }
    invented(
        "pull_off",
        ADHESION_STRONG,
        Tracking {
            stated_over_true: 1.4,
            contact_bias_m: 20e-6,
            ..Tracking::default()
        },
    );
}

/// The surface line off by up to ±40 µm (0.1 px) per shot: without the per-shot surface level the current
/// model misfits shot by shot and nothing explains it; with it, nothing is missing. (Slow: ~10 s.)
#[test]
fn surface_line_errors_are_absorbed_by_the_surface_levels() {
    let tracking = Tracking {
        surface_level_m: 40e-6,
        ..Tracking::default()
    };
    let shots = session(&truth(None), 9, tracking);
    let off = run("surface level ±40 µm, levels off", &shots, &SearchOptions::default());
    assert_ne!(off.verdict.kind, VerdictKind::MissingEffect, "{}", off.verdict.sentence);
    assert_ne!(off.verdict.kind, VerdictKind::Ambiguous, "{}", off.verdict.sentence);
    let on = run(
        "surface level ±40 µm, levels on",
        &shots,
        &SearchOptions {
            surface_levels: true,
            ..SearchOptions::default()
        },
    );
    assert_eq!(on.verdict.kind, VerdictKind::NoMissingEffect, "{}", on.verdict.sentence);
}

/// Two candidates only, to keep it quick.
fn quick_options() -> SearchOptions {
    SearchOptions {
        candidates: Some(vec!["hunt_crossley".into(), "drag".into()]),
        ..SearchOptions::default()
    }
}

#[test]
fn diagnosis_json_has_the_spec_fields_and_round_trips() {
    let shots = session(&truth(Some("hunt_crossley")), 4, Tracking::default());
    let d = find_missing_effect(&base_spec(), &shots, &quick_options(), &|_| {}).unwrap();
    let json = d.to_json();
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["verdict"]["kind"], "missing_effect");
    assert_eq!(v["verdict"]["effect"], "hunt_crossley");
    assert!(v["verdict"]["sentence"].as_str().unwrap().len() > 100);
    let c = &v["candidates"][0];
    for field in [
        "effect",
        "error_before",
        "error_after",
        "delta_bic",
        "heldout_error_before",
        "heldout_error_after",
        "chi2_red_after",
        "param_value",
        "param_interval",
    ] {
        assert!(!c[field].is_null(), "candidates[0].{field} missing in\n{json}");
    }
    assert!(
        c["fit"]["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .any(|p| p["name"] == "hunt_crossley.lambda")
    );
    assert!(v["baseline"]["fit"]["chi2_red"].as_f64().unwrap() > 10.0);
    assert!(!v["signature"]["phases"].as_array().unwrap().is_empty());
    // Reads back (numbers to the last digit or so: serde_json's float parsing is not exact).
    let back: Diagnosis = serde_json::from_str(&json).unwrap();
    assert_eq!(back.verdict, d.verdict);
    assert_eq!(back.candidates.len(), d.candidates.len());
    let (a, b) = (
        back.candidates[0].evidence.as_ref().unwrap(),
        d.candidates[0].evidence.as_ref().unwrap(),
    );
    assert!((a.delta_bic / b.delta_bic - 1.0).abs() < 1e-12 && a.shots_improved == b.shots_improved);
}

#[test]
fn the_same_shots_give_the_same_diagnosis() {
    let shots = session(&truth(Some("drag")), 5, Tracking::default());
    let a = find_missing_effect(&base_spec(), &shots, &quick_options(), &|_| {}).unwrap();
    let b = find_missing_effect(&base_spec(), &shots, &quick_options(), &|_| {}).unwrap();
    let strip = |mut d: Diagnosis| {
        d.seconds = 0.0;
        d.baseline.seconds = 0.0;
        for c in &mut d.candidates {
            c.seconds = 0.0;
        }
        d.to_json()
    };
    assert_eq!(strip(a), strip(b));
}

#[test]
fn progress_is_reported_for_every_model() {
    let shots = session(&truth(None), 6, Tracking::default());
    let seen = std::sync::Mutex::new(Vec::new());
    let iterations = std::sync::Mutex::new(Vec::new());
    find_missing_effect(&base_spec(), &shots, &quick_options(), &|p| match p.iteration {
        Some(i) => iterations.lock().unwrap().push((p.done, p.what, i, p.chi2_red)),
        None => seen.lock().unwrap().push((p.done, p.total, p.what)),
    })
    .unwrap();
    let seen = seen.into_inner().unwrap();
    let what: Vec<&str> = seen.iter().map(|s| s.2.as_str()).collect();
    assert_eq!(what, ["current model", "+ hunt_crossley", "+ drag", "done"]);
    assert!(seen.iter().all(|s| s.1 == 3) && seen.last().unwrap().0 == 3);
    // Every model's fit to all shots reports its solver iterations, from 0, with a finite reduced χ².
    let iterations = iterations.into_inner().unwrap();
    for (done, model) in [(0, "current model"), (1, "+ hunt_crossley"), (2, "+ drag")] {
        let its: Vec<_> = iterations.iter().filter(|x| x.1 == model).collect();
        assert!(its.iter().any(|x| x.2 == 0) && its.len() >= 2, "{model}: {its:?}");
        assert!(
            its.iter().all(|x| x.0 == done && x.3.is_some_and(f64::is_finite)),
            "{its:?}"
        );
    }
}

#[test]
fn bad_input_is_an_error_naming_what_is_wrong() {
    let shots = session(&truth(None), 7, Tracking::default());
    let spec = base_spec();
    let o = SearchOptions::default();
    let e = find_missing_effect(&spec, &shots[..4], &o, &|_| {}).unwrap_err();
    assert!(matches!(e, DiagnoseError::TooFewShots { shots: 4, needed: 6 }), "{e}");
    let e = find_missing_effect(&spec, &shots, &SearchOptions { folds: 1, ..o.clone() }, &|_| {}).unwrap_err();
    assert!(e.to_string().contains("`folds`"), "{e}");
    let e = find_missing_effect(
        &spec,
        &shots,
        &SearchOptions {
            tolerance_m: f64::NAN,
            ..o.clone()
        },
        &|_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("tolerance_m"), "{e}");
    let e = find_missing_effect(
        &spec,
        &shots,
        &SearchOptions {
            candidates: Some(vec!["magnus".into()]),
            ..o.clone()
        },
        &|_| {},
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("unknown effect `magnus`") && e.to_string().contains("drag"),
        "{e}"
    );
    let e = find_missing_effect(
        &spec,
        &shots,
        &SearchOptions {
            candidates: Some(vec!["spring".into()]),
            ..o.clone()
        },
        &|_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("base model"), "{e}");
    let mut bad = shots.clone();
    bad[3].frames[10].sigma_m = 0.0;
    let e = find_missing_effect(&spec, &bad, &o, &|_| {}).unwrap_err();
    assert!(
        matches!(e, DiagnoseError::Baseline { .. }) && e.to_string().contains(&shots[3].name),
        "{e}"
    );
    let mut bad = shots.clone();
    bad[0].surface = "grass".into();
    let e = find_missing_effect(&spec, &bad, &o, &|_| {}).unwrap_err();
    assert!(e.to_string().contains("grass"), "{e}");
}

/// The story of `docs/diagnosis.md`: accept the suggestion (the model file gets the effect at its fitted values),
/// refit with the fit crate, and the error falls as the diagnosis said.
#[test]
fn accepting_the_verdict_makes_the_error_fall() {
    let shots = session(&truth(Some("hunt_crossley")), 8, Tracking::default());
    let d = find_missing_effect(&base_spec(), &shots, &quick_options(), &|_| {}).unwrap();
    let name = d.verdict.effect.clone().expect("an effect is named");
    let c = d.candidate(&name).unwrap();
    let e = c.evidence.as_ref().unwrap();
    let values: Vec<(String, f64)> = e
        .fit
        .parameters
        .iter()
        .filter(|p| p.effect == name)
        .map(|p| (p.param.clone(), p.value))
        .collect();
    let text = add_effect_to_model_toml(PAPER_MODEL_TOML, &name, &values).unwrap();
    let spec = ModelSpec::parse(&text, "model.toml").unwrap();
    let before = fit(&base_spec(), shots.clone(), &FitOptions::default(), &mut NoObserver).unwrap();
    let after = fit(&spec, shots, &FitOptions::default(), &mut NoObserver).unwrap();
    eprintln!(
        "accepted {name}: RMS {:.2} → {:.2} µm (diagnosis said {:.2} → {:.2}), χ²_red {:.3}",
        before.rms_m * 1e6,
        after.rms_m * 1e6,
        c.error_before * 1e6,
        e.error_after * 1e6,
        after.reduced_chi2
    );
    assert!((after.rms_m / e.error_after - 1.0).abs() < 0.01);
    assert!(before.rms_m / after.rms_m >= 3.0 && after.reduced_chi2 <= 1.5);
}

/// Every hidden effect on seeds 1–4 and the no-effect and invented cases, as a table (slow: ~2 minutes).
#[test]
#[ignore]
fn sweep_over_seeds() {
    let mut rows = Vec::new();
    for seed in 1..=4u64 {
        for (effect, _) in MAGNITUDES {
            let d = run(
                effect,
                &session(&truth(Some(effect)), seed, Tracking::default()),
                &SearchOptions::default(),
            );
            let e = d.candidates[0].evidence.clone().unwrap();
            rows.push(format!(
                "| {effect} | {seed} | {} {:?} | {:.1} → {:.1} | {:.1}× | {:.1} → {:.1} | {:.2} | {:.1} |",
                d.verdict.kind.name(),
                d.verdict.effects,
                d.baseline.fit.rms_m * 1e6,
                e.error_after * 1e6,
                e.error_fall,
                d.baseline.systematic_m * 1e6,
                e.systematic_after_m * 1e6,
                e.chi2_red_after,
                d.seconds
            ));
        }
        for (label, model) in [
            ("none", truth(None)),
            ("adhesion", truth_with_custom("pull_off", ADHESION_STRONG)),
            ("viscous slip", truth_with_custom("viscous_slip", VISCOUS_SLIP_STRONG)),
        ] {
            let d = run(
                label,
                &session(&model, seed, Tracking::default()),
                &SearchOptions::default(),
            );
            let best = &d.candidates[0];
            rows.push(format!(
                "| {label} | {seed} | {} {:?} | {:.1} → {:.1} (best: {}) | | | | {:.1} |",
                d.verdict.kind.name(),
                d.verdict.effects,
                d.baseline.fit.rms_m * 1e6,
                best.evidence.as_ref().map(|e| e.error_after * 1e6).unwrap_or(f64::NAN),
                best.effect,
                d.seconds
            ));
        }
    }
    eprintln!("| hidden | seed | verdict | RMS, µm | fall | systematic part, µm | χ²_red after | s |");
    for r in rows {
        eprintln!("{r}");
    }
}

/// A session whose shots' surface lines are off by up to ±20 µm (each line's σ stated), with the current
/// model as `analyze` fits it (the surface level free per surface, each shot's level within its σ).
fn leveled_session(effect: Option<&str>, seed: u64) -> (ModelSpec, Vec<bouncelab_fit::MeasuredShot>) {
    let tracking = Tracking {
        surface_level_m: 20e-6,
        ..Tracking::default()
    };
    let mut shots = session(&truth(effect), seed, tracking);
    for s in &mut shots {
        s.surface_sigma_m = Some(20e-6);
    }
    let mut spec = base_spec();
    bouncelab_fit::add_surface_level(&mut spec);
    (spec, shots)
}

/// The fit crate's fit and its comparison, as `analyze` makes them.
fn fit_and_compare(
    spec: &ModelSpec,
    shots: &[bouncelab_fit::MeasuredShot],
) -> (
    bouncelab_fit::FitResult,
    bouncelab_compare::Comparison,
    bouncelab_compare::FailureReport,
) {
    let options = FitOptions::default();
    let problem = bouncelab_fit::Problem::new(spec, shots.to_vec(), options.sim)
        .unwrap()
        .with_surface_offsets(true);
    let fit = bouncelab_fit::fit_problem(&problem, &spec.origin, &options, &mut NoObserver).unwrap();
    let theta: Vec<f64> = fit.parameters.iter().map(|p| p.value).collect();
    let comparison = bouncelab_compare::compare_problem(&problem, &theta, &[]).unwrap();
    let failure = bouncelab_compare::diagnose(&comparison, &bouncelab_compare::DiagnoseOptions::default());
    (fit, comparison, failure)
}

/// Started from the fit `analyze` already made, the search decides as when it fits the current model
/// itself: the same verdict, the baseline's parameters within 1e-4 of each other (the two fits reach the
/// same optimum).
#[test]
fn the_search_from_a_given_fit_decides_as_from_its_own() {
    let (spec, shots) = leveled_session(None, 3);
    let options = SearchOptions {
        surface_levels: true,
        ..SearchOptions::default()
    };
    let own = find_missing_effect_with(&spec, &shots, &[], &options, &|_| {}).unwrap();
    let (fit, comparison, failure) = fit_and_compare(&spec, &shots);
    let given = FittedBaseline::new(&fit, &comparison, &failure);
    let from = find_missing_effect_from(&spec, &shots, &[], given, &options, &|_| {}).unwrap();
    assert_eq!(own.verdict.kind, from.verdict.kind, "{}", from.verdict.sentence);
    assert_eq!(own.verdict.effects, from.verdict.effects);
    for (a, b) in own.baseline.fit.parameters.iter().zip(&from.baseline.fit.parameters) {
        assert_eq!(a.name, b.name);
        assert!(
            (a.value - b.value).abs() <= 1e-4 * a.value.abs().max(1e-6),
            "{}: {} vs {}",
            a.name,
            a.value,
            b.value
        );
    }
}

/// A fit of other shots, or without the surface levels the search fits, is refused naming what differs.
#[test]
fn a_fit_that_is_not_of_these_shots_is_refused() {
    let (spec, shots) = leveled_session(None, 4);
    let (fit, comparison, failure) = fit_and_compare(&spec, &shots);
    let given = FittedBaseline::new(&fit, &comparison, &failure);
    let options = SearchOptions {
        surface_levels: true,
        ..SearchOptions::default()
    };
    let mut reordered = shots.clone();
    reordered.swap(0, 1);
    let err = find_missing_effect_from(&spec, &reordered, &[], given, &options, &|_| {}).unwrap_err();
    assert!(
        matches!(err, DiagnoseError::BaselineMismatch { .. }) && err.to_string().contains(&shots[1].name),
        "{err}"
    );
    let without_levels = SearchOptions::default();
    let err = find_missing_effect_from(&spec, &shots, &[], given, &without_levels, &|_| {}).unwrap_err();
    assert!(err.to_string().contains("surface level"), "{err}");
}
