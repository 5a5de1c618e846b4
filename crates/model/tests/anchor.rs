//! The paper's anchor values and the closed-form checks of the base model (issue 2 acceptance).

use bouncelab_model::{Ball, Impact, Model, SimOptions, State, simulate};

/// A ball just touching the surface, moving at `speed` m/s at `angle_deg` from the normal, down-slope.
fn at_touch(speed: f64, angle_deg: f64) -> State {
    let a = angle_deg.to_radians();
    State::flying(0.0, Ball::TENNIS.radius_m, speed * a.sin(), -speed * a.cos())
}

fn impact(model: &Model, start: State) -> Impact {
    simulate(model, 0.0, 0.0, start, &[], &SimOptions::default())
        .unwrap()
        .impact
}

#[test]
fn paper_clay_anchor_restitution_and_contact_time() {
    let imp = impact(&Model::paper(25_650.0, 14.0, 0.5), at_touch(2.0, 0.0));
    assert!((imp.restitution - 0.770).abs() <= 0.002, "e = {}", imp.restitution);
    assert!(
        (imp.contact_time() * 1e3 - 4.46).abs() <= 0.03,
        "contact time = {} ms",
        imp.contact_time() * 1e3
    );
}

#[test]
fn paper_tape_anchors() {
    let t1 = impact(&Model::paper(30_800.0, 15.0, 0.5), at_touch(2.0, 0.0));
    let t2 = impact(&Model::paper(31_825.0, 15.0, 0.5), at_touch(2.0, 0.0));
    assert!((t1.restitution - 0.774).abs() <= 0.002, "tape 1 e = {}", t1.restitution);
    assert!((t2.restitution - 0.777).abs() <= 0.002, "tape 2 e = {}", t2.restitution);
}

/// Total mechanical energy on a flat surface with a linear spring: kinetic + rotational + gravity + spring.
fn energy(model: &Model, k: f64, s: &State) -> f64 {
    let b = model.ball;
    let delta = (b.radius_m - s.y).max(0.0);
    0.5 * b.mass_kg * (s.vx * s.vx + s.vy * s.vy)
        + 0.5 * model.inertia() * s.omega * s.omega
        + b.mass_kg * model.gravity * s.y
        + 0.5 * k * delta * delta
}

#[test]
fn elastic_frictionless_impact_conserves_energy() {
    let k = 25_650.0;
    let model = Model::paper(k, 0.0, 0.0);
    let start = State {
        omega: 30.0,
        ..at_touch(2.0, 20.0)
    };
    let times: Vec<f64> = (0..200).map(|i| i as f64 * 5e-5).collect();
    let sim = simulate(&model, 0.0, 0.0, start, &times, &SimOptions::default()).unwrap();
    assert!(
        (sim.impact.restitution - 1.0).abs() <= 1e-4,
        "e = {}",
        sim.impact.restitution
    );
    let e0 = energy(&model, k, &start);
    for s in &sim.samples {
        let rel = (energy(&model, k, &s.state) - e0).abs() / e0;
        assert!(rel <= 1e-6, "energy drift {rel:e} at t = {} s ({:?})", s.t, s.phase);
    }
    // No friction: tangential velocity and spin pass through untouched.
    assert!((sim.impact.state_out.vx - start.vx).abs() < 1e-12);
    assert!((sim.impact.state_out.omega - start.omega).abs() < 1e-12);
}

#[test]
fn linear_compression_matches_its_closed_form() {
    // m·δ'' = m·g − k·δ − b·δ', δ(0) = 0, δ'(0) = v0: a damped oscillator about δ_s = m·g/k.
    let (k, b, v0) = (25_650.0, 14.0, 2.0);
    let model = Model::paper(k, b, 0.0);
    let (m, g) = (model.ball.mass_kg, model.gravity);
    let w0 = (k / m).sqrt();
    let zeta = b / (2.0 * (k * m).sqrt());
    let wd = w0 * (1.0 - zeta * zeta).sqrt();
    let ds = m * g / k;
    let (a, bb) = (-ds, (v0 - zeta * w0 * ds) / wd);
    // δ'(t) = e^{−ζω0 t}[(ωd·B − ζω0·A) cos ωd t − (ζω0·B + ωd·A) sin ωd t] = 0.
    let (p, q) = (wd * bb - zeta * w0 * a, zeta * w0 * bb + wd * a);
    let t_m = (p / q).atan().rem_euclid(std::f64::consts::PI) / wd;
    let delta = |t: f64| ds + (-zeta * w0 * t).exp() * (a * (wd * t).cos() + bb * (wd * t).sin());
    let imp = impact(&model, at_touch(v0, 0.0));
    let t_sim = imp.t_max_compression - imp.t_touch;
    assert!((t_sim - t_m).abs() / t_m <= 1e-6, "t_max: {t_sim} vs {t_m}");
    assert!(
        (imp.delta_max - delta(t_m)).abs() / delta(t_m) <= 1e-6,
        "δ_max: {} vs {}",
        imp.delta_max,
        delta(t_m)
    );
}

#[test]
fn oblique_impact_with_large_friction_ends_rolling_at_the_thin_shell_speed() {
    let model = Model::paper(25_650.0, 14.0, 2.0);
    let start = at_touch(2.0, 30.0);
    let imp = impact(&model, start);
    let r = model.ball.radius_m;
    let out = imp.state_out;
    assert!(imp.rolling_at_separation, "events: {:?}", imp.slip_events);
    assert!(
        (out.vx + out.omega * r).abs() <= 1e-6,
        "slip at separation {}",
        out.vx + out.omega * r
    );
    // Angular momentum about the contact point is conserved: v = v_in / (1 + c), c = 2/3.
    let rolling = start.vx / (1.0 + 2.0 / 3.0);
    assert!((out.vx - rolling).abs() <= 1e-6, "v_t,out {} vs {}", out.vx, rolling);
    assert_eq!(
        imp.slip_events.first().map(|e| e.kind),
        Some(bouncelab_model::SlipEventKind::StartsSticking)
    );
}

#[test]
fn oblique_impact_with_small_friction_slides_throughout_and_mu_eff_is_mu() {
    let mu = 0.05;
    // Without gravity the paper's momentum ratio is exactly the friction coefficient while sliding.
    let mut model = Model::paper(25_650.0, 14.0, mu);
    model.gravity = 0.0;
    let imp = impact(&model, at_touch(2.0, 30.0));
    assert!(imp.slip_events.is_empty(), "{:?}", imp.slip_events);
    assert!(!imp.rolling_at_separation);
    assert!(
        (imp.effective_friction - mu).abs() <= 1e-9,
        "μ_eff = {}",
        imp.effective_friction
    );
    // With gravity its impulse during the contact enters the ratio: within 2 %.
    let imp = impact(&Model::paper(25_650.0, 14.0, mu), at_touch(2.0, 30.0));
    assert!(
        (imp.effective_friction - mu).abs() <= 0.02 * mu,
        "μ_eff = {}",
        imp.effective_friction
    );
}

#[test]
fn stick_then_slip_on_an_incline_without_chatter() {
    // On an incline, rolling needs a constant friction force; as P falls to zero near separation the grip
    // is lost once: one StartsSticking then one StartsSliding, never a burst of switches.
    let model = Model::paper(25_650.0, 14.0, 0.8);
    let incline = 22.5f64.to_radians();
    let start = State::flying(
        0.0,
        Ball::TENNIS.radius_m + 1e-3,
        2.0 * incline.sin(),
        -2.0 * incline.cos(),
    );
    let imp = simulate(&model, incline, 0.0, start, &[], &SimOptions::default())
        .unwrap()
        .impact;
    let kinds: Vec<_> = imp.slip_events.iter().map(|e| e.kind).collect();
    use bouncelab_model::SlipEventKind::*;
    assert_eq!(kinds, vec![StartsSticking, StartsSliding], "{:?}", imp.slip_events);
    assert!(imp.slip_events[1].t > imp.t_max_compression && imp.slip_events[1].t < imp.t_separation);
}

#[test]
fn simulation_is_deterministic() {
    let model = Model::paper(25_650.0, 14.0, 0.5);
    let times: Vec<f64> = (0..300).map(|i| i as f64 * 1e-4).collect();
    let start = State::flying(0.0, 0.04, 0.5, -2.0);
    let a = simulate(&model, 0.1, 0.0, start, &times, &SimOptions::default()).unwrap();
    let b = simulate(&model, 0.1, 0.0, start, &times, &SimOptions::default()).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.samples.len(), times.len());
}

#[test]
fn samples_follow_the_phases_in_order() {
    let model = Model::paper(25_650.0, 14.0, 0.5);
    let times: Vec<f64> = (0..400).map(|i| i as f64 * 1e-4).collect();
    let start = State::flying(0.0, Ball::TENNIS.radius_m + 0.02, 0.3, -2.0);
    let sim = simulate(&model, 0.0, 0.0, start, &times, &SimOptions::default()).unwrap();
    use bouncelab_model::Phase::*;
    let mut seen = vec![sim.samples[0].phase];
    for s in &sim.samples {
        if *seen.last().unwrap() != s.phase {
            seen.push(s.phase);
        }
        let expect = if s.t <= sim.impact.t_touch {
            Flight
        } else if s.t <= sim.impact.t_max_compression {
            Compression
        } else if s.t <= sim.impact.t_separation {
            Restitution
        } else {
            Flight
        };
        assert_eq!(s.phase, expect, "t = {}", s.t);
    }
    assert_eq!(seen, vec![Flight, Compression, Restitution, Flight]);
}

#[test]
fn bad_starts_are_errors_not_panics() {
    let model = Model::paper(25_650.0, 14.0, 0.5);
    let o = SimOptions::default();
    let inside = State::flying(0.0, 0.01, 0.0, -1.0);
    assert!(
        simulate(&model, 0.0, 0.0, inside, &[], &o)
            .unwrap_err()
            .to_string()
            .contains("inside the surface")
    );
    let up = State::flying(0.0, 0.1, 0.0, 1.0);
    let mut weightless = model.clone();
    weightless.gravity = 0.0;
    assert!(matches!(
        simulate(&weightless, 0.0, 0.0, up, &[], &o),
        Err(bouncelab_model::ModelError::NoImpact { .. })
    ));
    let ok = State::flying(0.0, 0.05, 0.0, -1.0);
    assert!(simulate(&model, 0.0, 0.0, ok, &[0.2, 0.1], &o).is_err());
    assert!(simulate(&model, 0.0, 1.0, ok, &[0.5], &o).is_err());
    let nan = State::flying(0.0, f64::NAN, 0.0, -1.0);
    assert!(simulate(&model, 0.0, 0.0, nan, &[], &o).is_err());
}
