//! Which shots to keep out of a shared fit because their tracks, not the model, are at fault.

use crate::MeasuredShot;
use nalgebra::{DMatrix, DVector};

/// Least reduced χ² of a shot's worst flight fit for its track to be suspect: 9, a scatter of 3σ.
pub const SUSPECT_FLIGHT_CHI2_MIN: f64 = 9.0;

/// How far a shot's worst flight fit may scatter beyond the session's typical shot (× the median of the
/// shots' worst flight reduced χ²) before its track is suspect.
pub const SUSPECT_FLIGHT_FACTOR: f64 = 25.0;

/// Fewest shots with a finite flight χ² for the session's median to stand for its typical shot.
const SUSPECT_MIN_SHOTS: usize = 3;

/// Shots whose flight phases are not ballistic to within the tracking noise, far beyond the session's
/// other shots: `flight_chi2_red[i]` holds the reduced χ² of shot i's flight fits, and a shot is suspect
/// when its worst is not finite, or above [`SUSPECT_FLIGHT_CHI2_MIN`] and above [`SUSPECT_FLIGHT_FACTOR`] ×
/// the session's median. No contact model can fix a flight phase, so such a track (a seam or a shadow
/// followed for some frames) would only bend the shared fit; a missing flight effect (drag) raises every
/// shot's χ² and so the median with it. Returns each suspect shot's index with the reason, in a sentence;
/// none with fewer than three shots with a finite worst flight.
pub fn suspect_flights(flight_chi2_red: &[&[f64]]) -> Vec<(usize, String)> {
    let worst = |c: &[f64]| c.iter().cloned().fold(0.0, f64::max);
    let mut all: Vec<f64> = flight_chi2_red
        .iter()
        .map(|c| worst(c))
        .filter(|v| v.is_finite())
        .collect();
    if all.len() < SUSPECT_MIN_SHOTS {
        return Vec::new();
    }
    all.sort_by(f64::total_cmp);
    let median = all[all.len() / 2];
    flight_chi2_red
        .iter()
        .enumerate()
        .filter(|(_, c)| {
            let w = worst(c);
            !w.is_finite() || (w > SUSPECT_FLIGHT_CHI2_MIN && w > SUSPECT_FLIGHT_FACTOR * median)
        })
        .map(|(i, c)| {
            let w = worst(c);
            (
                i,
                format!(
                    "its flight fits scatter {:.0}× more than the tracker's σ (reduced χ² {:.1}; session median {:.2}): the track is suspect",
                    w.sqrt(),
                    w,
                    median
                ),
            )
        })
        .collect()
}

/// Fewest frames of a flight arc fitted on its own (four coefficients per component, and enough left to
/// measure).
pub const MIN_ARC_FRAMES: usize = 12;

/// Degree of the polynomial in time fitted to a flight arc's component: gravity makes a quadratic; drag's
/// deceleration changes slowly as the speed does, which the cubic term takes (over a 35 ms arc at 4 m/s
/// with C_d = 1.5 what a cubic leaves is below 0.1 µm), so what is left is the tracker's own error.
pub const ARC_DEGREE: usize = 3;

/// The residuals of `values` at times `t` after a least-squares polynomial of degree [`ARC_DEGREE`] in
/// time, and their degrees of freedom; `None` with fewer than [`MIN_ARC_FRAMES`] frames. Cost: one SVD of
/// an n × 4 matrix.
pub fn arc_residuals(t: &[f64], values: &[f64]) -> Option<(DVector<f64>, usize)> {
    let n = t.len();
    if n < MIN_ARC_FRAMES || values.len() != n {
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
    let coef = a.clone().svd(true, true).solve(&b, 1e-12).ok()?;
    Some((b - a * coef, n - cols))
}

/// The reduced χ² of each flight arc of `shot` (frames `margin_s` or more before `touch_s`, and after
/// `separation_s`), both components, after each is fitted on its own by [`arc_residuals`]: the tracker's
/// own scatter against its σ, whatever the flight's physics (gravity, drag). One value per arc measured.
pub fn flight_structure_chi2(shot: &MeasuredShot, touch_s: f64, separation_s: f64, margin_s: f64) -> Vec<f64> {
    let before: Vec<_> = shot.frames.iter().filter(|f| f.t_s <= touch_s - margin_s).collect();
    let after: Vec<_> = shot
        .frames
        .iter()
        .filter(|f| f.t_s >= separation_s + margin_s)
        .collect();
    [before, after]
        .iter()
        .filter_map(|arc| {
            let t: Vec<f64> = arc.iter().map(|f| f.t_s).collect();
            let (mut chi2, mut dof) = (0.0, 0);
            for value in [
                arc.iter().map(|f| f.x_m).collect::<Vec<_>>(),
                arc.iter().map(|f| f.y_m).collect(),
            ] {
                let (r, d) = arc_residuals(&t, &value)?;
                chi2 += r.iter().zip(arc).map(|(r, f)| (r / f.sigma_m).powi(2)).sum::<f64>();
                dof += d;
            }
            (dof > 0).then(|| chi2 / dof as f64)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shot whose incoming and outgoing arcs are cubics in time (gravity and drag) plus σ-sized
    /// alternating errors scores ≈ 1 per arc; the same shot whose track jumps by 60 σ on some incoming
    /// frames (a seam followed) scores far above, and is the suspect one.
    #[test]
    fn flight_structure_ignores_a_bent_flight_and_sees_a_track_that_jumps() {
        let sigma = 1e-5;
        let frame = |i: usize, jump: f64| {
            let t = i as f64 * 1e-4;
            let (tc, sign) = ((t - 0.02).abs(), if i.is_multiple_of(2) { 1.0 } else { -1.0 });
            crate::MeasuredFrame {
                t_s: t,
                x_m: 0.01 + 0.3 * t - 2.0 * t * t * t + sign * sigma + jump,
                y_m: 0.0335 + 3.0 * tc - 4.9 * tc * tc + 8.0 * tc * tc * tc - sign * sigma,
                sigma_m: sigma,
            }
        };
        let shot = |jumps: bool| crate::MeasuredShot {
            name: "s".into(),
            surface: "clay".into(),
            incline_rad: 0.0,
            frames: (0..400)
                .map(|i| frame(i, if jumps && i < 150 && i % 7 < 3 { 6e-4 } else { 0.0 }))
                .collect(),
            start: crate::StartState {
                t_s: 0.0,
                state: bouncelab_model::State::default(),
            },
            measured: None,
            surface_sigma_m: None,
            frame_sigma_rad: None,
            spin_sigma_rad_s: None,
            rim_change_m: None,
        };
        let clean = flight_structure_chi2(&shot(false), 0.0195, 0.0205, 3e-4);
        assert_eq!(clean.len(), 2);
        assert!(clean.iter().all(|c| (0.8..1.3).contains(c)), "{clean:?}");
        let seam = flight_structure_chi2(&shot(true), 0.0195, 0.0205, 3e-4);
        assert!(seam[0] > 100.0 && seam[1] < 1.3, "{seam:?}");
        let shots: Vec<&[f64]> = vec![&clean, &clean, &seam, &clean];
        assert_eq!(suspect_flights(&shots)[0].0, 2);
    }

    #[test]
    fn a_cubic_arc_leaves_nothing_and_structure_is_measured() {
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 1e-4).collect();
        let cubic: Vec<f64> = t
            .iter()
            .map(|t| 0.1 + 2.0 * t - 4.9 * t * t + 3.0 * t * t * t)
            .collect();
        let (r, dof) = arc_residuals(&t, &cubic).unwrap();
        assert!(r.norm_squared() < 1e-20 && dof == 96, "{} {dof}", r.norm_squared());
        // A 5 µm ripple over 2 ms is structure the cubic cannot take.
        let ripple: Vec<f64> = t
            .iter()
            .zip(&cubic)
            .map(|(t, c)| c + 5e-6 * (std::f64::consts::TAU * t / 2e-3).sin())
            .collect();
        let (r, dof) = arc_residuals(&t, &ripple).unwrap();
        let rms = (r.norm_squared() / dof as f64).sqrt();
        assert!((rms - 5e-6 / 2f64.sqrt()).abs() < 0.5e-6, "{rms}");
        assert!(arc_residuals(&t[..MIN_ARC_FRAMES - 1], &ripple[..MIN_ARC_FRAMES - 1]).is_none());
    }

    #[test]
    fn only_a_flight_far_beyond_the_session_and_above_3_sigma_is_suspect() {
        let ok = [1.0, 1.2];
        let seam = [1.1, 40.0];
        let shots: Vec<&[f64]> = vec![&ok, &ok, &seam, &ok];
        let s = suspect_flights(&shots);
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].0, 2);
        assert!(s[0].1.contains("reduced χ² 40.0; session median 1.20"), "{}", s[0].1);
        // Drag raises every shot's χ²: 40 is then not 25× the median.
        let drag = [3.0, 4.0];
        let shots: Vec<&[f64]> = vec![&drag, &drag, &seam, &drag];
        assert!(suspect_flights(&shots).is_empty());
        // Below 9 (3σ) nothing is suspect, however quiet the others.
        let quiet = [0.01];
        let mild = [8.0];
        let shots: Vec<&[f64]> = vec![&quiet, &quiet, &mild, &quiet];
        assert!(suspect_flights(&shots).is_empty());
        // Too few shots to judge; a shot with no finite flight is suspect.
        assert!(suspect_flights(&[&ok, &seam]).is_empty());
        let lost = [f64::INFINITY];
        let shots: Vec<&[f64]> = vec![&ok, &ok, &ok, &lost];
        assert_eq!(suspect_flights(&shots)[0].0, 3);
    }
}
