//! The measurement floor learned from the session: the free flight is exact physics (gravity, and drag at
//! most a slowly changing deceleration), so what is left after fitting each flight arc on its own is the
//! tracker's own error. Its white part is the noise; the rest, structure over a few frames (the rim's
//! edge finding as the ball moves across pixels, the lighting), is a systematic error that no contact
//! effect can be asked to explain.

use crate::diagnosis::Floor;
use bouncelab_fit::MeasuredShot;
use bouncelab_model::{Phase, Simulation};
use nalgebra::{DMatrix, DVector};

/// Frames next to the contact left out of each arc: the simulated touch and separation may be off by a
/// frame, and a frame that touches is not free flight.
const CONTACT_MARGIN_FRAMES: usize = 3;

/// Fewest frames of an arc fitted (four coefficients per component, and enough left to measure).
const MIN_ARC_FRAMES: usize = 12;

/// Degree of the polynomial fitted to each arc and component: gravity makes a quadratic; drag's
/// deceleration changes slowly as the speed does, which the cubic term takes (over a 35 ms arc at 4 m/s
/// with C_d = 1.5 what a cubic leaves is below 0.1 µm).
const ARC_DEGREE: usize = 3;

/// Sums of one arc's residuals after its own polynomial fit: (Σ r², degrees of freedom).
fn arc_sums(t: &[f64], values: &[f64]) -> Option<(f64, usize)> {
    let n = t.len();
    if n < MIN_ARC_FRAMES {
        return None;
    }
    let t0 = t.iter().sum::<f64>() / n as f64;
    let span = t
        .iter()
        .map(|v| (v - t0).abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let cols = ARC_DEGREE + 1;
    let a = DMatrix::from_fn(n, cols, |i, j| ((t[i] - t0) / span).powi(j as i32));
    let b = DVector::from_column_slice(values);
    let svd = a.clone().svd(true, true);
    let coef = svd.solve(&b, 1e-12).ok()?;
    let r = b - a * coef;
    Some((r.norm_squared(), n - cols))
}

/// The floor of a session: each shot's flight frames (by the current model's phases, less
/// [`CONTACT_MARGIN_FRAMES`] next to the contact) split into the arc before and the arc after the contact,
/// each component of each arc fitted by a cubic in time; the systematic part of what is left is
/// `√max(0, Σr²/ν − noise²)`, per shot and pooled over every arc. The floor is that pooled structure and
/// `contact_allowance_m` (the tracker's extra error in contact, which the flight cannot show) in
/// quadrature; without an arc to measure, the allowance alone.
pub(crate) fn learn(shots: &[MeasuredShot], sims: &[Simulation], noise_m: f64, contact_allowance_m: f64) -> Floor {
    let mut per_shot = Vec::with_capacity(shots.len());
    let (mut sq, mut dof, mut frames) = (0.0, 0usize, 0usize);
    for (shot, sim) in shots.iter().zip(sims) {
        let phases: Vec<Phase> = sim.samples.iter().map(|s| s.phase).collect();
        let n = shot.frames.len().min(phases.len());
        let first_contact = phases[..n].iter().position(|p| *p != Phase::Flight);
        let last_contact = phases[..n].iter().rposition(|p| *p != Phase::Flight);
        let arcs: Vec<std::ops::Range<usize>> = match (first_contact, last_contact) {
            (Some(a), Some(b)) => vec![
                0..a.saturating_sub(CONTACT_MARGIN_FRAMES),
                (b + 1 + CONTACT_MARGIN_FRAMES).min(n)..n,
            ],
            _ => std::iter::once(0..n).collect(),
        };
        let (mut s_sq, mut s_dof) = (0.0, 0usize);
        for arc in arcs {
            let f = &shot.frames[arc];
            let t: Vec<f64> = f.iter().map(|f| f.t_s).collect();
            for value in [
                f.iter().map(|f| f.x_m).collect::<Vec<_>>(),
                f.iter().map(|f| f.y_m).collect::<Vec<_>>(),
            ] {
                if let Some((a, d)) = arc_sums(&t, &value) {
                    s_sq += a;
                    s_dof += d;
                    frames += t.len();
                }
            }
        }
        per_shot.push((s_dof > 0).then(|| crate::stats::excess(s_sq / s_dof as f64, noise_m)));
        sq += s_sq;
        dof += s_dof;
    }
    // Each component of an arc counted its frames once; a frame has two.
    let frames = frames / 2;
    let flight_systematic_m = (dof > 0).then(|| crate::stats::excess(sq / dof as f64, noise_m));
    let structure = flight_systematic_m.unwrap_or(0.0);
    Floor {
        floor_m: structure.hypot(contact_allowance_m),
        flight_systematic_m,
        contact_allowance_m,
        per_shot_m: per_shot,
        flight_frames: frames,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cubic_arc_leaves_nothing_and_structure_is_measured() {
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 1e-4).collect();
        let cubic: Vec<f64> = t
            .iter()
            .map(|t| 0.1 + 2.0 * t - 4.9 * t * t + 3.0 * t * t * t)
            .collect();
        let (sq, dof) = arc_sums(&t, &cubic).unwrap();
        assert!(sq < 1e-20 && dof == 96, "{sq} {dof}");
        // A 5 µm ripple over 2 ms is structure the cubic cannot take.
        let ripple: Vec<f64> = t
            .iter()
            .zip(&cubic)
            .map(|(t, c)| c + 5e-6 * (std::f64::consts::TAU * t / 2e-3).sin())
            .collect();
        let (sq, dof) = arc_sums(&t, &ripple).unwrap();
        let rms = (sq / dof as f64).sqrt();
        assert!((rms - 5e-6 / 2f64.sqrt()).abs() < 0.5e-6, "{rms}");
        assert!(arc_sums(&t[..MIN_ARC_FRAMES - 1], &ripple[..MIN_ARC_FRAMES - 1]).is_none());
    }
}
