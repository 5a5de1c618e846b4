//! What a fitted model predicts: the model of a surface with the fit's values set into it, and one impact of
//! it at a given incoming velocity, with the outputs a lab measures and the contact force over time (the
//! paper's Figure 2). The report draws COR and contact time against impact speed from these, per surface,
//! over the measured points.

use crate::{FitError, FitResult, params};
use bouncelab_model::{Context, Loads, Model, ModelSpec, Phase, SimOptions, State, simulate};
use serde::{Deserialize, Serialize};

/// Height above the surface the ball starts from, m: close enough that gravity changes the incoming speed
/// by less than 1e-5 m/s, far enough that the touch is an event of the run (not its start).
const START_GAP_M: f64 = 1e-6;

/// One instant of the contact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ForceSample {
    /// Time since touch, s.
    pub t_s: f64,
    /// Penetration δ = R − y, m.
    pub delta_m: f64,
    /// Total normal contact force P (the sum of every effect's normal force), N.
    pub force_n: f64,
}

/// One impact as a model predicts it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactPrediction {
    /// Velocity at touch (tangential, normal), m/s; the normal one is negative (toward the surface).
    pub v_in: [f64; 2],
    /// Velocity at separation (tangential, normal), m/s.
    pub v_out: [f64; 2],
    /// Coefficient of restitution |v_n,out / v_n,in|.
    pub cor: f64,
    /// Effective friction −Δv_t / Δv_n.
    pub mu_eff: f64,
    /// Contact time, s.
    pub contact_time_s: f64,
    /// Maximum penetration δ_max, m.
    pub delta_max_m: f64,
    /// Spin at separation, rad/s (counter-clockwise as seen by the camera).
    pub omega_out_rad_s: f64,
    /// Largest total normal contact force over the contact, N.
    pub peak_force_n: f64,
    /// Largest normal acceleration of the ball's centre over the contact, m/s²: every normal load over the
    /// mass, gravity's normal component included (what a second difference of the measured height gives).
    pub peak_deceleration_m_s2: f64,
    /// The contact force at evenly spaced instants from touch to separation (both included).
    pub force: Vec<ForceSample>,
}

/// The model of `surface` with the values `fit` found set into it: `spec` must be the model file the fit
/// was made with (the same free parameters). Measurement effects stay in the model; they change what the
/// camera sees, not the impact.
///
/// Fails when the surface is not in the model or a free parameter of it is missing from `fit`.
pub fn fitted_model(spec: &ModelSpec, fit: &FitResult, surface: &str) -> Result<Model, FitError> {
    if !spec.surfaces.is_empty() && !spec.surfaces.iter().any(|(s, _)| s == surface) {
        return Err(FitError::UnknownSurface {
            shot: "-".into(),
            surface: surface.into(),
            known: spec.surface_names().join(", "),
        });
    }
    let (free, mut models) = params::build(spec, &[surface.to_string()])?;
    let theta = free
        .iter()
        .map(|p| {
            fit.param(&p.name)
                .map(|f| f.value)
                .ok_or_else(|| FitError::MissingParameter { name: p.name.clone() })
        })
        .collect::<Result<Vec<f64>, FitError>>()?;
    models.remove(0).model(&theta)
}

/// One impact of `model` on a surface inclined by `incline_rad`, the ball arriving with velocity `v_in`
/// (tangential, normal; normal < 0, m/s) and spin `omega_rad_s`; the contact force is sampled at `samples`
/// + 1 evenly spaced instants from touch to separation (at least 2).
///
/// Fails when the velocity does not reach the surface or the simulation fails (the error names it).
pub fn predict_impact(
    model: &Model,
    incline_rad: f64,
    v_in: [f64; 2],
    omega_rad_s: f64,
    samples: usize,
    sim: &SimOptions,
) -> Result<ImpactPrediction, FitError> {
    if !(v_in[1] < 0.0 && v_in.iter().all(|v| v.is_finite()) && omega_rad_s.is_finite()) {
        return Err(FitError::BadStart {
            shot: "prediction".into(),
            reason: format!(
                "incoming velocity ({}, {}) m/s must be finite with a negative normal component",
                v_in[0], v_in[1]
            ),
        });
    }
    let start = State {
        omega: omega_rad_s,
        ..State::flying(0.0, model.ball.radius_m + START_GAP_M, v_in[0], v_in[1])
    };
    let run = |times: &[f64]| {
        simulate(model, incline_rad, 0.0, start, times, sim).map_err(|source| FitError::Simulation {
            shot: "prediction".into(),
            source: Box::new(source),
        })
    };
    let first = run(&[])?;
    let imp = first.impact;
    let n = samples.max(2);
    let contact = imp.contact_time();
    let times: Vec<f64> = (0..=n).map(|i| imp.t_touch + contact * i as f64 / n as f64).collect();
    let dense = run(&times)?;
    let (m, r) = (model.ball.mass_kg, model.ball.radius_m);
    let g_n = model.gravity * incline_rad.cos();
    let mut force = Vec::with_capacity(times.len());
    let (mut peak_force, mut peak_accel) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    let mut delta_int = 0.0;
    let mut last: Option<(f64, f64)> = None;
    for (i, s) in dense.samples.iter().enumerate() {
        // The ends are the contact's own instants, whatever phase the recorder gave them.
        let phase = match (i, s.phase) {
            (0, _) => Phase::Compression,
            (k, _) if k == n => Phase::Restitution,
            (_, p) => p,
        };
        let delta = r - s.state.y;
        if let Some((t0, d0)) = last {
            delta_int += 0.5 * (delta + d0) * (s.t - t0);
        }
        last = Some((s.t, delta));
        let after_max = phase == Phase::Restitution;
        let mut ctx = Context {
            delta_max: if after_max { imp.delta_max } else { 0.0 },
            force_max: if after_max { imp.force_max } else { 0.0 },
            u_t: s.u_t,
            delta_int,
            ..Context::of(s.t, &s.state, phase, &model.ball, model.gravity, incline_rad)
        };
        let p: f64 = if phase.in_contact() {
            model.effects().iter().map(|e| e.normal_force(&ctx)).sum()
        } else {
            0.0
        };
        ctx.normal_force = p;
        let mut loads = Loads::default();
        for e in model.effects() {
            loads.add(&e.loads(&ctx));
        }
        peak_force = peak_force.max(p);
        peak_accel = peak_accel.max((p + loads.force_y) / m - g_n);
        force.push(ForceSample {
            t_s: s.t - imp.t_touch,
            delta_m: delta,
            force_n: p,
        });
    }
    // The force at maximum compression is an event of the run, exact where sampling may fall either side.
    peak_force = peak_force.max(imp.force_max);
    Ok(ImpactPrediction {
        v_in: [imp.state_in.vx, imp.state_in.vy],
        v_out: [imp.state_out.vx, imp.state_out.vy],
        cor: imp.restitution,
        mu_eff: imp.effective_friction,
        contact_time_s: contact,
        delta_max_m: imp.delta_max,
        omega_out_rad_s: imp.omega_out(),
        peak_force_n: peak_force,
        peak_deceleration_m_s2: peak_accel.max(imp.force_max / m - g_n),
        force,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_model::effects::{LinearDamping, LinearSpring};
    use bouncelab_model::{Ball, Model};

    fn spring(k: f64) -> Model {
        Model::new(Ball::TENNIS, 0.0).with(LinearSpring { k })
    }

    #[test]
    fn an_undamped_spring_is_a_half_sine() {
        // Without gravity and damping: P = kδ, δ(t) = (v/ω) sin ωt, ω = √(k/m).
        let k = 25_650.0;
        let model = spring(k);
        let v = 2.0;
        let p = predict_impact(&model, 0.0, [0.0, -v], 0.0, 200, &SimOptions::default()).unwrap();
        let m = model.ball.mass_kg;
        let w = (k / m).sqrt();
        assert!(
            (p.contact_time_s - std::f64::consts::PI / w).abs() < 1e-9,
            "{}",
            p.contact_time_s
        );
        assert!((p.cor - 1.0).abs() < 1e-8, "{}", p.cor);
        let peak = k * v / w;
        assert!(
            (p.peak_force_n - peak).abs() < 1e-6 * peak,
            "{} vs {peak}",
            p.peak_force_n
        );
        assert!((p.peak_deceleration_m_s2 - peak / m).abs() < 1e-6 * peak / m);
        for s in &p.force {
            let expected = peak * (w * s.t_s).sin();
            assert!((s.force_n - expected).abs() < 1e-5 * peak, "{s:?} vs {expected}");
        }
        assert_eq!(p.force.len(), 201);
        assert_eq!(p.force[0].t_s, 0.0);
        assert!((p.force[200].t_s - p.contact_time_s).abs() < 1e-15);
    }

    #[test]
    fn the_force_integral_is_the_change_of_momentum() {
        // Impulse–momentum over the contact: ∫P dt = m (v_n,out − v_n,in) + m g cosβ T.
        let model = Model::paper(25_650.0, 14.0, 0.5);
        let beta = 15f64.to_radians();
        let p = predict_impact(&model, beta, [0.5, -2.2], 0.0, 2_000, &SimOptions::default()).unwrap();
        let impulse: f64 = p
            .force
            .windows(2)
            .map(|w| 0.5 * (w[0].force_n + w[1].force_n) * (w[1].t_s - w[0].t_s))
            .sum();
        let m = model.ball.mass_kg;
        let expected = m * (p.v_out[1] - p.v_in[1]) + m * model.gravity * beta.cos() * p.contact_time_s;
        assert!((impulse - expected).abs() < 1e-5 * expected, "{impulse} vs {expected}");
        // Damping in compression: the force jumps to b·v at touch and peaks before maximum compression.
        assert!(
            (p.force[0].force_n - 14.0 * 2.2).abs() < 0.01 * 14.0 * 2.2,
            "{:?}",
            p.force[0]
        );
        assert!(p.peak_force_n > 25_650.0 * p.delta_max_m);
        assert!(p.cor > 0.5 && p.cor < 1.0 && p.mu_eff.is_finite());
    }

    #[test]
    fn damping_lowers_the_restitution_as_speed_rises_only_when_it_should() {
        // Linear spring + linear damping: the COR does not depend on the impact speed (a linear system);
        // the prediction must show that, and a faster impact must push harder.
        let model = Model::new(Ball::TENNIS, 0.0)
            .with(LinearSpring { k: 30_000.0 })
            .with(LinearDamping { b: 15.0 });
        let at = |v: f64| predict_impact(&model, 0.0, [0.0, -v], 0.0, 50, &SimOptions::default()).unwrap();
        let (slow, fast) = (at(1.0), at(3.0));
        assert!((slow.cor - fast.cor).abs() < 1e-8, "{} vs {}", slow.cor, fast.cor);
        assert!((slow.contact_time_s - fast.contact_time_s).abs() < 1e-10);
        assert!((fast.peak_force_n / slow.peak_force_n - 3.0).abs() < 1e-6);
    }

    #[test]
    fn bad_velocities_are_refused() {
        let model = spring(1e4);
        for v in [[0.0, 1.0], [0.0, 0.0], [f64::NAN, -1.0]] {
            let e = predict_impact(&model, 0.0, v, 0.0, 10, &SimOptions::default()).unwrap_err();
            assert!(e.to_string().contains("incoming velocity"), "{e}");
        }
    }
}
