//! Each effect of the library changes what it should, and does nothing at its neutral parameters.

use bouncelab_model::effects::{
    CameraRoll, Hertz, HuntCrossley, InertiaFactor, LinearSpring, PlasticDent, QuadraticDrag, RestitutionDamping,
    RollingResistance,
};
use bouncelab_model::{Ball, Impact, Model, SimOptions, State, builtin_effects, simulate, simulate_drop};
use proptest::prelude::*;

fn at_touch(speed: f64, angle_deg: f64) -> State {
    let a = angle_deg.to_radians();
    State::flying(0.0, Ball::TENNIS.radius_m, speed * a.sin(), -speed * a.cos())
}

fn impact(model: &Model, speed: f64, angle_deg: f64) -> Impact {
    simulate(model, 0.0, 0.0, at_touch(speed, angle_deg), &[], &SimOptions::default())
        .unwrap()
        .impact
}

fn base() -> Model {
    Model::paper(25_650.0, 14.0, 0.5)
}

#[test]
fn hunt_crossley_cor_falls_with_impact_speed() {
    // Spring plus Hunt–Crossley damping only: dissipation ∝ δ·δ̇ grows faster than the elastic energy.
    let model = Model::new(Ball::TENNIS, 9.81)
        .with(LinearSpring { k: 25_650.0 })
        .with(HuntCrossley { lambda: 5e3, n: 1.0 });
    let e: Vec<f64> = [1.0, 2.0, 3.0]
        .iter()
        .map(|&v| impact(&model, v, 0.0).restitution)
        .collect();
    assert!(
        e[0] > e[1] + 0.01 && e[1] > e[2] + 0.01,
        "COR vs speed 1, 2, 3 m/s: {e:?}"
    );
    // The paper's linear damping gives a COR that barely changes with speed (gravity only).
    let lin: Vec<f64> = [1.0, 3.0]
        .iter()
        .map(|&v| impact(&base(), v, 0.0).restitution)
        .collect();
    assert!((lin[0] - lin[1]).abs() < 0.005, "{lin:?}");
}

#[test]
fn hertz_contact_time_falls_with_impact_speed() {
    let model = Model::new(Ball::TENNIS, 9.81).with(Hertz { k_h: 2e6 });
    let tc: Vec<f64> = [1.0, 2.0, 3.0]
        .iter()
        .map(|&v| impact(&model, v, 0.0).contact_time())
        .collect();
    assert!(tc[0] > tc[1] * 1.05 && tc[1] > tc[2] * 1.03, "contact times {tc:?}");
    // Hertz theory: t_c ∝ v^(−1/5).
    let ratio = tc[0] / tc[2];
    assert!((ratio - 3f64.powf(0.2)).abs() < 0.02, "t(1)/t(3) = {ratio}");
}

#[test]
fn restitution_damping_lowers_cor() {
    let e0 = impact(&base(), 2.0, 0.0).restitution;
    let e1 = impact(&base().with(RestitutionDamping { b_r: 8.0 }), 2.0, 0.0).restitution;
    assert!(e1 < e0 - 0.03, "{e1} vs {e0}");
}

#[test]
fn plastic_dent_lowers_cor_and_leaves_a_residual_depth() {
    let phi = 0.2;
    let base_imp = impact(&base(), 2.0, 0.0);
    let dent = impact(&base().with(PlasticDent { phi }), 2.0, 0.0);
    assert!(
        dent.restitution < base_imp.restitution - 0.03,
        "{} vs {}",
        dent.restitution,
        base_imp.restitution
    );
    assert!(
        base_imp.residual_depth < 1e-9,
        "no dent without the effect: {}",
        base_imp.residual_depth
    );
    // With a linear spring the unloading line reaches zero force exactly at φ·δ_max.
    assert!(
        (dent.residual_depth - phi * dent.delta_max).abs() < 1e-8 * dent.delta_max,
        "{} vs {}",
        dent.residual_depth,
        phi * dent.delta_max
    );
}

#[test]
fn drag_makes_the_ball_arrive_slower_than_free_fall() {
    let h = 0.4;
    let free = (2.0f64 * 9.81 * h).sqrt();
    let o = SimOptions::default();
    let no_drag = simulate_drop(&base(), 0.0, h, &[], &o).unwrap().impact.state_in.speed();
    assert!((no_drag - free).abs() < 1e-7, "{no_drag} vs {free}");
    let with = simulate_drop(&base().with(QuadraticDrag { cd: 0.55, rho: 1.204 }), 0.0, h, &[], &o)
        .unwrap()
        .impact;
    let v = with.state_in.speed();
    assert!(v < free - 0.005 && v > free - 0.05, "{v} vs {free}");
}

#[test]
fn camera_roll_rotates_the_observed_frame() {
    let roll = 3.0f64;
    let model = base().with(CameraRoll { roll_deg: roll });
    let times: Vec<f64> = (0..100).map(|i| i as f64 * 1e-4).collect();
    let start = State::flying(0.0, 0.05, 0.0, -2.0);
    let sim = simulate(&model, 0.0, 0.0, start, &times, &SimOptions::default()).unwrap();
    let phi = roll.to_radians();
    for s in &sim.samples {
        let (x, y) = (s.state.x, s.state.y);
        assert!((s.observed.x - (x * phi.cos() + y * phi.sin())).abs() < 1e-15);
        assert!((s.observed.y - (-x * phi.sin() + y * phi.cos())).abs() < 1e-15);
        assert!((s.observed.x.hypot(s.observed.y) - x.hypot(y)).abs() < 1e-15);
    }
    // A normal impact seen by the rolled camera looks oblique.
    assert!(sim.samples[0].state.vx == 0.0 && sim.samples[0].observed.vx.abs() > 0.09);
    // The dynamics are untouched.
    let plain = simulate(&base(), 0.0, 0.0, start, &times, &SimOptions::default()).unwrap();
    assert_eq!(plain.impact, sim.impact);
}

#[test]
fn rolling_resistance_makes_spin_decay_while_rolling() {
    let plain = impact(&base(), 2.0, 30.0);
    let model = base().with(RollingResistance { c_rr: 0.05 });
    let times: Vec<f64> = (0..60).map(|i| i as f64 * 1e-4).collect();
    let sim = simulate(&model, 0.0, 0.0, at_touch(2.0, 30.0), &times, &SimOptions::default()).unwrap();
    let rr = &sim.impact;
    assert!(plain.rolling_at_separation && rr.rolling_at_separation);
    assert!(
        rr.omega_out().abs() < plain.omega_out().abs() - 1.0,
        "{} vs {}",
        rr.omega_out(),
        plain.omega_out()
    );
    // While the contact point sticks, |ω| only falls.
    let rolling: Vec<f64> = sim
        .samples
        .iter()
        .filter(|s| s.sticking)
        .map(|s| s.state.omega.abs())
        .collect();
    assert!(rolling.len() > 5);
    assert!(rolling.windows(2).all(|w| w[1] <= w[0] + 1e-12), "{rolling:?}");
}

#[test]
fn inertia_factor_changes_the_rolling_speed() {
    let dc = -0.1;
    let model = Model::paper(25_650.0, 14.0, 2.0).with(InertiaFactor { dc });
    let start = at_touch(2.0, 30.0);
    let imp = simulate(&model, 0.0, 0.0, start, &[], &SimOptions::default())
        .unwrap()
        .impact;
    let expect = start.vx / (1.0 + 2.0 / 3.0 + dc);
    assert!(
        (imp.state_out.vx - expect).abs() < 1e-6,
        "{} vs {}",
        imp.state_out.vx,
        expect
    );
    let thin = start.vx / (1.0 + 2.0 / 3.0);
    assert!((imp.state_out.vx - thin).abs() > 0.02);
}

/// Every built-in effect at its neutral parameters, added to the base model.
fn with_all_neutral(mut model: Model) -> Model {
    for info in builtin_effects().iter().filter(|i| !i.base) {
        let values: Vec<f64> = info.params.iter().map(|p| p.neutral).collect();
        model.push((info.build)(&values));
    }
    model
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn neutral_effects_leave_the_base_model_unchanged(
        k in 5e3f64..8e4, b in 0.0f64..30.0, mu in 0.0f64..1.5,
        speed in 0.5f64..5.0, angle in 0.0f64..40.0, spin in -100.0f64..100.0, incline in 0.0f64..0.4,
    ) {
        let base = Model::paper(k, b, mu);
        let all = with_all_neutral(base.clone());
        let a = at_touch(speed, angle);
        let start = State { omega: spin, y: a.y + 0.01, ..a };
        let times: Vec<f64> = (0..120).map(|i| i as f64 * 1e-4).collect();
        let o = SimOptions::default();
        let x = simulate(&base, incline, 0.0, start, &times, &o).unwrap();
        let y = simulate(&all, incline, 0.0, start, &times, &o).unwrap();
        let (p, q) = (&x.impact, &y.impact);
        for (u, v) in [
            (p.restitution, q.restitution), (p.effective_friction, q.effective_friction),
            (p.contact_time(), q.contact_time()), (p.delta_max, q.delta_max),
            (p.state_out.vx, q.state_out.vx), (p.state_out.vy, q.state_out.vy), (p.state_out.omega, q.state_out.omega),
        ] {
            prop_assert!((u - v).abs() <= 1e-12 * u.abs().max(1.0), "{} vs {}", u, v);
        }
        for (s, t) in x.samples.iter().zip(&y.samples) {
            prop_assert!((s.observed.x - t.observed.x).abs() <= 1e-12 && (s.observed.y - t.observed.y).abs() <= 1e-12);
        }
    }
}
