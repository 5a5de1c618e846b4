//! Measurement effects in a fit: each shot's measured start is what the camera saw, so the simulation
//! starts from the true state whose observation it is, and a rotation such as a camera roll turns about
//! the contact point on the surface line (located in the shot's data), not the tracker's arbitrary x origin.

use crate::MeasuredShot;
use bouncelab_model::{Model, Observation, State};
use nalgebra::DMatrix;

/// The measured x of the centre where it first comes within a radius of the surface line (linear
/// interpolation between the two frames around the crossing), or at its lowest frame without a crossing.
pub(crate) fn touch_x(shot: &MeasuredShot, radius: f64) -> f64 {
    let f = &shot.frames;
    for k in 1..f.len() {
        let (a, b) = (&f[k - 1], &f[k]);
        if a.y_m > radius && b.y_m <= radius {
            let w = (a.y_m - radius) / (a.y_m - b.y_m);
            return a.x_m + w * (b.x_m - a.x_m);
        }
    }
    f.iter()
        .min_by(|a, b| a.y_m.total_cmp(&b.y_m))
        .map(|l| l.x_m)
        .unwrap_or(shot.start.state.x)
}

/// True if a measurement effect of `model` changes what the camera sees.
pub fn observes(model: &Model) -> bool {
    let probe = State {
        x: 0.1,
        y: 0.2,
        theta: 0.3,
        vx: 1.0,
        vy: -2.0,
        omega: 5.0,
    };
    obs_array(&observe(model, &probe)) != obs_array(&Observation::from(probe))
}

/// What the camera would see of `state` through the model's measurement effects.
pub fn observe(model: &Model, state: &State) -> Observation {
    let mut o = Observation::from(*state);
    for e in model.effects() {
        e.observe(&mut o);
    }
    o
}

fn obs_array(o: &Observation) -> [f64; 6] {
    [o.x, o.y, o.theta, o.vx, o.vy, o.omega]
}

fn state_of(a: [f64; 6]) -> State {
    State {
        x: a[0],
        y: a[1],
        theta: a[2],
        vx: a[3],
        vy: a[4],
        omega: a[5],
    }
}

/// The true state whose observation through the model's measurement effects is `measured` (the identity
/// when the model has none). Newton's method on the observation map with a finite-difference Jacobian;
/// the maps of the library (a rotation) are linear, so one step is exact.
pub fn true_start(model: &Model, measured: &State) -> State {
    let target = obs_array(&Observation::from(*measured));
    if !observes(model) {
        return *measured;
    }
    let mut x = target;
    for _ in 0..8 {
        let f0 = obs_array(&observe(model, &state_of(x)));
        let r: Vec<f64> = (0..6).map(|i| target[i] - f0[i]).collect();
        if r.iter().zip(&target).all(|(d, t)| d.abs() <= 1e-14 * (1.0 + t.abs())) {
            break;
        }
        let mut jac = DMatrix::zeros(6, 6);
        for j in 0..6 {
            let h = 1e-6 * (1.0 + x[j].abs());
            let mut xp = x;
            xp[j] += h;
            let fp = obs_array(&observe(model, &state_of(xp)));
            for i in 0..6 {
                jac[(i, j)] = (fp[i] - f0[i]) / h;
            }
        }
        let Some(step) = jac.lu().solve(&nalgebra::DVector::from_vec(r)) else {
            break;
        };
        for j in 0..6 {
            x[j] += step[j];
        }
    }
    state_of(x)
}
