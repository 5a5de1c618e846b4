//! The measurement floor learned from the session: the free flight is exact physics (gravity, and drag at
//! most a slowly changing deceleration), so what is left after fitting each flight arc on its own is the
//! tracker's own error. Its white part is the noise; the rest, structure over a few frames (the rim's
//! edge finding as the ball moves across pixels, the lighting), is a systematic error that no contact
//! effect can be asked to explain.

use crate::diagnosis::Floor;
use bouncelab_fit::{MeasuredShot, arc_residuals};
use bouncelab_model::{Phase, Simulation};

/// Frames next to the contact left out of each arc: the simulated touch and separation may be off by a
/// frame, and a frame that touches is not free flight.
const CONTACT_MARGIN_FRAMES: usize = 3;

/// The floor of a session: each shot's flight frames (by the current model's phases, less
/// [`CONTACT_MARGIN_FRAMES`] next to the contact) split into the arc before and the arc after the contact,
/// each component of each arc fitted by a cubic in time ([`arc_residuals`]); the systematic part of what is left is
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
                if let Some((r, d)) = arc_residuals(&t, &value) {
                    s_sq += r.norm_squared();
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
