//! The measurement floor learned from the session: the free flight is exact physics (gravity, and drag at
//! most a slowly changing deceleration), so what is left after fitting each flight arc on its own is the
//! tracker's own error. Its white part is the noise; the rest, structure over a few frames (the rim's
//! edge finding as the ball moves across pixels, the lighting), is a systematic error that no contact
//! effect can be asked to explain. What each arc's own fit absorbs, a tracker error that differs between
//! the two flights, the flights cannot show; the ball's radius can: a rigid ball's does not change, so a
//! radius measured differently in the two flights is the rim found differently, and the centre found from
//! that rim moves with it.

use crate::diagnosis::Floor;
use bouncelab_fit::{MeasuredShot, arc_residuals};
use bouncelab_model::{Phase, Simulation};

/// Standard errors of its learned parts by which the floor exceeds its estimate: a misfit is a misfit when
/// it clears the session's own tracking error beyond doubt (one-sided, about 1 in 700 for a normal error),
/// as a parameter must stand four standard errors from neutral to be named.
pub const FLOOR_MARGIN_SE: f64 = 3.0;

/// Frames next to the contact left out of each arc: the simulated touch and separation may be off by a
/// frame, and a frame that touches is not free flight.
const CONTACT_MARGIN_FRAMES: usize = 3;

/// The floor of a session: each shot's flight frames (by the current model's phases, less
/// [`CONTACT_MARGIN_FRAMES`] next to the contact) split into the arc before and the arc after the contact,
/// each component of each arc fitted by a cubic in time ([`arc_residuals`]); the systematic part of what is left is
/// `√max(0, Σr²/ν − noise²)`, per shot and pooled over every arc. The rim's change between the flights
/// ([`rim_change_part`]) is what the arcs' own fits hide. The floor is those two and `contact_allowance_m`
/// (the tracker's extra error in contact, which the flight cannot show) in quadrature, plus
/// [`FLOOR_MARGIN_SE`] standard errors of the learned parts (from how much the shots differ), so that a
/// misfit counts only when it clears what the session's own tracking could do; without an arc to measure
/// or a radius's change, the allowance alone.
pub(crate) fn learn(shots: &[MeasuredShot], sims: &[Simulation], noise_m: f64, contact_allowance_m: f64) -> Floor {
    let mut per_shot = Vec::with_capacity(shots.len());
    // Per shot: the flights' squared excess over the noise and its degrees of freedom (the weights).
    let mut excess_sq: Vec<(f64, f64)> = Vec::new();
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
        if s_dof > 0 {
            excess_sq.push((s_sq / s_dof as f64 - noise_m * noise_m, s_dof as f64));
        }
        sq += s_sq;
        dof += s_dof;
    }
    // Each component of an arc counted its frames once; a frame has two.
    let frames = frames / 2;
    let flight_systematic_m = (dof > 0).then(|| crate::stats::excess(sq / dof as f64, noise_m));
    let structure = flight_systematic_m.unwrap_or(0.0);
    let rim = rim_change_part(shots);
    let rim_m = rim.map_or(0.0, |r| r.0);
    let estimate = structure.hypot(rim_m).hypot(contact_allowance_m);
    // The floor's square is a sum of means over shots; their standard errors come from how much the shots
    // differ (a few badly tracked shots make a wide margin), then √ by the delta method.
    let var_sq = weighted_mean_se(&excess_sq).powi(2) + rim.map_or(0.0, |r| r.1.powi(2));
    let se = if estimate > 0.0 {
        var_sq.sqrt() / (2.0 * estimate)
    } else {
        0.0
    };
    Floor {
        floor_m: estimate + FLOOR_MARGIN_SE * se,
        flight_systematic_m,
        rim_change_m: rim.map(|r| r.0),
        floor_se_m: se,
        contact_allowance_m,
        per_shot_m: per_shot,
        flight_frames: frames,
    }
}

/// The part of the tracker's error that changes between a shot's two flights, pooled over the shots whose
/// radius change was measured ([`MeasuredShot::rim_change_m`]): `√(max(0, mean((Δr² − se²)/2)))`, m, and the
/// standard error of its square (the mean's, from the shots' spread). A rim found differently moves its
/// fitted centre by √2 times its radius on each axis when its edge points move independently (for a circle
/// fitted to n edge points, var x = var y = 2·var r), and a fit with one offset per shot leaves half of such
/// a jump in each flight: √2·Δr/2 = Δr/√2. That ratio is an assumption, not a law: a rim that only grows
/// moves no centre, one side's edge moving alone moves it by about 1.3·Δr on one axis, and a light across
/// the frame can move the centre with no change of radius. On the independent renderer's clean session it
/// gave the misfit left with the true line (34.2 µm against 26.1 µm of flight structure and 23 µm from the
/// rim, in quadrature 34.8 µm). `None` when no shot has it.
fn rim_change_part(shots: &[MeasuredShot]) -> Option<(f64, f64)> {
    let halves: Vec<(f64, f64)> = shots
        .iter()
        .filter_map(|s| s.rim_change_m)
        .map(|[c, se]| ((c * c - se * se) / 2.0, 1.0))
        .collect();
    if halves.is_empty() {
        return None;
    }
    let mean = halves.iter().map(|h| h.0).sum::<f64>() / halves.len() as f64;
    Some((mean.max(0.0).sqrt(), weighted_mean_se(&halves)))
}

/// The standard error of the weighted mean of `(value, weight)` pairs, from their spread about it
/// (`√(Σw²(x − x̄)²) / Σw`); 0 for fewer than two.
fn weighted_mean_se(values: &[(f64, f64)]) -> f64 {
    let sw: f64 = values.iter().map(|v| v.1).sum();
    if values.len() < 2 || sw <= 0.0 {
        return 0.0;
    }
    let mean = values.iter().map(|v| v.0 * v.1).sum::<f64>() / sw;
    let n = values.len() as f64;
    // n/(n − 1): the spread about a mean fitted to the same values.
    (values.iter().map(|v| (v.1 * (v.0 - mean)).powi(2)).sum::<f64>() * n / (n - 1.0)).sqrt() / sw
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shot_with_rim(change_m: Option<[f64; 2]>) -> MeasuredShot {
        MeasuredShot {
            name: "s".into(),
            surface: "clay".into(),
            incline_rad: 0.0,
            frames: Vec::new(),
            start: bouncelab_fit::StartState {
                t_s: 0.0,
                state: bouncelab_model::State::flying(0.0, 0.1, 0.0, -2.0),
            },
            measured: None,
            surface_sigma_m: None,
            frame_sigma_rad: None,
            spin_sigma_rad_s: None,
            rim_change_m: change_m,
        }
    }

    /// Radii that change by ±a between the flights move the centres by a/√2 in each flight about their
    /// shot's offset; their errors are taken out, shots without a measured change are left out, and the
    /// spread of the shots gives the square's standard error.
    #[test]
    fn the_rim_s_change_between_the_flights_counts_as_its_share_of_the_centre() {
        let a = 40e-6;
        let shots: Vec<MeasuredShot> = [a, -a, a, -a, a, -a]
            .iter()
            .map(|&c| shot_with_rim(Some([c, 0.0])))
            .chain([shot_with_rim(None)])
            .collect();
        let (rim, se_sq) = rim_change_part(&shots).unwrap();
        assert!((rim - a / 2f64.sqrt()).abs() < 1e-12, "{rim}");
        assert!(se_sq.abs() < 1e-20, "equal changes have no spread: {se_sq}");
        // A change within its own error is no change.
        let noisy: Vec<MeasuredShot> = (0..4).map(|_| shot_with_rim(Some([3e-6, 3e-6]))).collect();
        assert_eq!(rim_change_part(&noisy).unwrap().0, 0.0);
        // One badly tracked shot among quiet ones: the same mean square, a wide standard error.
        let mut uneven: Vec<MeasuredShot> = (0..5).map(|_| shot_with_rim(Some([0.0, 0.0]))).collect();
        uneven.push(shot_with_rim(Some([a * 6f64.sqrt(), 0.0])));
        let (rim_u, se_u) = rim_change_part(&uneven).unwrap();
        assert!((rim_u - rim).abs() < 1e-12);
        assert!(se_u > 0.9 * rim_u * rim_u, "{se_u} against {}", rim_u * rim_u);
        assert!(rim_change_part(&[shot_with_rim(None)]).is_none());
    }

    #[test]
    fn the_weighted_mean_s_error_follows_the_spread_and_the_weights() {
        assert_eq!(weighted_mean_se(&[(1.0, 1.0)]), 0.0);
        // Two equal weights: the classic standard error of a mean of two, |x1 − x2| / 2.
        assert!((weighted_mean_se(&[(1.0, 1.0), (3.0, 1.0)]) - 1.0).abs() < 1e-12);
        // Equal values: no spread.
        assert_eq!(weighted_mean_se(&[(2.0, 5.0), (2.0, 1.0), (2.0, 3.0)]), 0.0);
    }
}
