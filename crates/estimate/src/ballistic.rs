//! Weighted least-squares fits of a flight arc: with the acceleration known (gravity), or free to check it.

use nalgebra::{DMatrix, DVector};

/// A fitted arc `p(t) = p0 + v0·(t − t_ref) + ½·a·(t − t_ref)²` per coordinate, with covariances.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BallisticFit {
    /// Reference time, s (the mean time of the fitted frames, for a well-conditioned fit).
    pub t_ref: f64,
    /// Position at `t_ref` (x, y), m.
    pub p0: [f64; 2],
    /// Velocity at `t_ref` (x, y), m/s.
    pub v0: [f64; 2],
    /// Known acceleration (x, y), m/s².
    pub a: [f64; 2],
    /// Covariance of (p0, v0) per coordinate: [[var p0, cov], [cov, var v0]].
    pub cov: [[[f64; 2]; 2]; 2],
    /// Reduced χ² of the fit (residuals against the given σ), per coordinate.
    pub chi2_red: [f64; 2],
    /// Frames fitted.
    pub frames: usize,
}

impl BallisticFit {
    /// Position at time `t`, m.
    pub fn position(&self, t: f64) -> [f64; 2] {
        let d = t - self.t_ref;
        [0, 1].map(|k| self.p0[k] + self.v0[k] * d + 0.5 * self.a[k] * d * d)
    }

    /// Velocity at time `t`, m/s.
    pub fn velocity(&self, t: f64) -> [f64; 2] {
        let d = t - self.t_ref;
        [0, 1].map(|k| self.v0[k] + self.a[k] * d)
    }

    /// Standard errors of the position and velocity of coordinate `k` at time `t`, and their correlation.
    pub fn errors_at(&self, k: usize, t: f64) -> (f64, f64, f64) {
        let d = t - self.t_ref;
        let c = &self.cov[k];
        // p(t) = p0 + d·v0 (+ known), v(t) = v0 (+ known).
        let var_p = c[0][0] + 2.0 * d * c[0][1] + d * d * c[1][1];
        let var_v = c[1][1];
        let cov_pv = c[0][1] + d * c[1][1];
        let (sp, sv) = (var_p.max(0.0).sqrt(), var_v.max(0.0).sqrt());
        (sp, sv, if sp > 0.0 && sv > 0.0 { cov_pv / (sp * sv) } else { 0.0 })
    }
}

/// Fits `points` (t s, x m, y m, σ m) with the known acceleration `a` (m/s²). Needs at least 3 points;
/// the standard errors are inflated by √(χ²_red·(1+ρ)/(1−ρ)) when that exceeds 1, ρ the lag-1 correlation
/// of the residuals in the points' order (`ar1_factor`).
pub fn fit_ballistic(points: &[(f64, f64, f64, f64)], a: [f64; 2]) -> Option<BallisticFit> {
    if points.len() < 3 {
        return None;
    }
    let sw: f64 = points.iter().map(|p| 1.0 / (p.3 * p.3)).sum();
    let t_ref = points.iter().map(|p| p.0 / (p.3 * p.3)).sum::<f64>() / sw;
    let mut fit = BallisticFit {
        t_ref,
        p0: [0.0; 2],
        v0: [0.0; 2],
        a,
        cov: [[[0.0; 2]; 2]; 2],
        chi2_red: [0.0; 2],
        frames: points.len(),
    };
    for (k, &ak) in a.iter().enumerate() {
        // Remove the known acceleration, then a weighted straight line in (t − t_ref).
        let (mut s0, mut s1, mut s2, mut b0, mut b1) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for p in points {
            let d = p.0 - t_ref;
            let w = 1.0 / (p.3 * p.3);
            let z = if k == 0 { p.1 } else { p.2 } - 0.5 * ak * d * d;
            s0 += w;
            s1 += w * d;
            s2 += w * d * d;
            b0 += w * z;
            b1 += w * z * d;
        }
        let det = s0 * s2 - s1 * s1;
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let p0 = (s2 * b0 - s1 * b1) / det;
        let v0 = (s0 * b1 - s1 * b0) / det;
        let chi2: f64 = points
            .iter()
            .map(|p| {
                let d = p.0 - t_ref;
                let z = if k == 0 { p.1 } else { p.2 };
                let r = (z - (p0 + v0 * d + 0.5 * ak * d * d)) / p.3;
                r * r
            })
            .sum();
        let dof = (points.len() as f64 - 2.0).max(1.0);
        let chi2_red = chi2 / dof;
        // Neighbouring residuals of a tracker drift together (the rim's look changes slowly from frame to
        // frame): their scatter is counted as √(χ²_red·(1+ρ)/(1−ρ)), as in `fit_free_acceleration`.
        let residuals: Vec<f64> = points
            .iter()
            .map(|p| {
                let d = p.0 - t_ref;
                let z = if k == 0 { p.1 } else { p.2 };
                (z - (p0 + v0 * d + 0.5 * ak * d * d)) / p.3
            })
            .collect();
        let inflate = (chi2_red * ar1_factor(&residuals)).max(1.0);
        fit.p0[k] = p0;
        fit.v0[k] = v0;
        fit.chi2_red[k] = chi2_red;
        fit.cov[k] = [
            [inflate * s2 / det, -inflate * s1 / det],
            [-inflate * s1 / det, inflate * s0 / det],
        ];
    }
    Some(fit)
}

/// A flight fitted with its acceleration free (see [`fit_free_acceleration`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeArc {
    /// The acceleration (x, y), m/s².
    pub a: [f64; 2],
    /// Its standard errors (x, y), m/s².
    pub se: [f64; 2],
    /// The root-mean-square distance of the points from the fitted arc, m: the track's own scatter,
    /// whatever the flight's acceleration.
    pub rms_m: f64,
    /// The reduced χ² of that scatter against the points' σ, both coordinates together.
    pub chi2_red: f64,
}

/// Fits `points` (t s, x m, y m, σ m) with the acceleration free: a weighted quadratic per coordinate.
/// Returns the acceleration with its standard errors: from the given σ, or from the scatter when that is
/// larger, counted as √(χ²_red·(1+ρ)/(1−ρ)) with ρ the lag-1 correlation of the residuals in time order (a
/// tracker's error drifts with the rim's look from frame to frame, so neighbouring residuals are not
/// independent and an acceleration would otherwise look more certain than it is), and the points' scatter
/// about the arc; `None` with fewer than 6 points or degenerate times. Cost: O(n).
pub fn fit_free_acceleration(points: &[(f64, f64, f64, f64)]) -> Option<FreeArc> {
    free_fit(points, None)
}

/// [`fit_free_acceleration`] with the measured radius `radius_m` of each point (m) as one more term per
/// coordinate, its coefficient free: a rigid ball's radius does not change in flight, so a change is the
/// rim read differently as the ball's look changes (a lit side clipping, a shading), and a rim read
/// differently on one side moves the centre by up to as much. The acceleration is then what the centres
/// show beyond that, with its error grown by how much the radius's change resembles a fall. A radius that
/// does not change (to 10⁻⁴ of its scale) adds no term. `None` as there, when the lengths differ, or when
/// the radius changes exactly as a fall would (a quadratic in time), which leaves the fall unmeasurable.
pub fn fit_free_acceleration_beyond_rim(points: &[(f64, f64, f64, f64)], radius_m: &[f64]) -> Option<FreeArc> {
    (radius_m.len() == points.len()).then_some(())?;
    let mean = radius_m.iter().sum::<f64>() / radius_m.len() as f64;
    let spread = radius_m.iter().map(|r| (r - mean).abs()).fold(0.0, f64::max);
    if spread <= 1e-4 * mean.abs() {
        return free_fit(points, None);
    }
    let rim: Vec<f64> = radius_m.iter().map(|r| (r - mean) / spread).collect();
    free_fit(points, Some(&rim))
}

/// The weighted fit of `z = c0 + c1·u + c2·u² (+ c3·rim)` per coordinate, u = (t − t_ref)/span; see
/// [`fit_free_acceleration`].
fn free_fit(points: &[(f64, f64, f64, f64)], rim: Option<&[f64]>) -> Option<FreeArc> {
    if points.len() < 6 {
        return None;
    }
    let sw: f64 = points.iter().map(|p| 1.0 / (p.3 * p.3)).sum();
    let t_ref = points.iter().map(|p| p.0 / (p.3 * p.3)).sum::<f64>() / sw;
    let span = points.iter().map(|p| (p.0 - t_ref).abs()).fold(0.0, f64::max);
    if span.is_nan() || span <= 0.0 {
        return None;
    }
    let terms = if rim.is_some() { 4 } else { 3 };
    // Rows of the design, each weighted by 1/σ.
    let design = DMatrix::from_fn(points.len(), terms, |i, j| {
        let u = (points[i].0 - t_ref) / span;
        let basis = match j {
            0 => 1.0,
            1 => u,
            2 => u * u,
            _ => rim.map_or(0.0, |r| r[i]),
        };
        basis / points[i].3
    });
    let inv = (design.transpose() * &design).try_inverse()?;
    let mut a = [0.0; 2];
    let mut se = [0.0; 2];
    let (mut sum_sq_m, mut chi2_all) = (0.0, 0.0);
    for k in 0..2 {
        let z = DVector::from_iterator(
            points.len(),
            points.iter().map(|p| if k == 0 { p.1 } else { p.2 } / p.3),
        );
        let c = &inv * (design.transpose() * &z);
        // Residuals in units of σ.
        let residuals: Vec<f64> = (&z - &design * &c).iter().copied().collect();
        let chi2: f64 = residuals.iter().map(|r| r * r).sum();
        let inflate = (chi2 / (points.len() - terms) as f64 * ar1_factor(&residuals)).max(1.0);
        a[k] = 2.0 * c[2] / (span * span);
        se[k] = 2.0 * (inv[(2, 2)] * inflate).max(0.0).sqrt() / (span * span);
        sum_sq_m += residuals
            .iter()
            .zip(points)
            .map(|(r, p)| (r * p.3).powi(2))
            .sum::<f64>();
        chi2_all += chi2;
    }
    let n = points.len() as f64;
    // A rim whose change is the fall's own shape leaves nothing to tell them apart.
    a.iter().chain(&se).all(|v| v.is_finite()).then_some(FreeArc {
        a,
        se,
        rms_m: (sum_sq_m / n).sqrt(),
        chi2_red: chi2_all / (2.0 * (n - terms as f64)),
    })
}

/// The variance factor (1+ρ)/(1−ρ) of a mean of AR(1) residuals with lag-1 correlation ρ (measured,
/// held to 0–0.9: a negative ρ is not credited).
pub(crate) fn ar1_factor(residuals: &[f64]) -> f64 {
    let n = residuals.len() as f64;
    let m = residuals.iter().sum::<f64>() / n;
    let var: f64 = residuals.iter().map(|r| (r - m).powi(2)).sum();
    let lag: f64 = residuals.windows(2).map(|w| (w[0] - m) * (w[1] - m)).sum();
    let rho = (lag / var.max(1e-300)).clamp(0.0, 0.9);
    (1.0 + rho) / (1.0 - rho)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_drifting_error_makes_the_acceleration_less_certain_than_the_same_errors_shuffled() {
        // The same 60 errors in two orders: a slow drift (a rim whose look changes from frame to frame) and
        // interleaved (white-like). Only the drift's neighbours agree, so only its standard error grows.
        let errors: Vec<f64> = (0..60).map(|i| 2e-5 * (i as f64 * 0.3).sin()).collect();
        let shuffled: Vec<f64> = (0..60).map(|i| errors[(i * 37) % 60]).collect();
        let fit = |e: &[f64]| {
            let pts: Vec<_> = e
                .iter()
                .enumerate()
                .map(|(i, e)| {
                    let t = i as f64 * 1e-4;
                    (t, 0.1 + 0.5 * t, 0.2 - 2.0 * t - 4.905 * t * t + e, 1e-6)
                })
                .collect();
            fit_free_acceleration(&pts).unwrap().se[1]
        };
        let (drift, white) = (fit(&errors), fit(&shuffled));
        assert!(drift > 2.0 * white, "drift SE {drift}, shuffled SE {white}");
    }

    #[test]
    fn a_free_fit_measures_the_scatter_about_its_arc() {
        // Errors of ±3 µm alternating in y, reported as 1 µm: about 3 µm RMS from the arc, χ²_red ≈ 9/2
        // (both coordinates counted, x exact).
        let pts: Vec<_> = (0..40)
            .map(|i| (i as f64 * 1e-4, if i % 2 == 0 { 3e-6 } else { -3e-6 }))
            .map(|(t, e)| (t, 0.1 + 0.5 * t, 0.2 - 2.0 * t - 4.905 * t * t + e, 1e-6))
            .collect();
        let arc = fit_free_acceleration(&pts).unwrap();
        assert!((arc.rms_m - 3e-6).abs() < 0.1e-6, "{arc:?}");
        assert!((arc.chi2_red - 4.5 * 40.0 / 37.0).abs() < 0.3, "{arc:?}");
    }

    /// A fall whose rim is read differently along the flight (its radius bulging by 0.5 mm mid-flight, one
    /// side's edge moving with it, so the centre by 0.8 of that): the plain fit takes the bulge for a
    /// different fall; beyond the rim, gravity is found within its error. A radius that does not change
    /// gives the plain fit.
    #[test]
    fn a_rim_read_differently_in_flight_is_not_taken_for_the_fall() {
        let n = 150;
        let times: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
        let mid = times[n / 2];
        let bulge = |t: f64| 5e-4 * (1.0 - ((t - mid) / mid).powi(2));
        let noise = |i: usize| 4e-6 * ((i * 7919 % 13) as f64 / 6.0 - 1.0);
        let pts: Vec<_> = times
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                (
                    t,
                    0.1 + 0.5 * t + noise(i),
                    0.2 - 2.0 * t - 4.905 * t * t + 0.8 * bulge(t),
                    1e-5,
                )
            })
            .collect();
        let radius: Vec<f64> = times
            .iter()
            .enumerate()
            .map(|(i, &t)| 0.0335 + bulge(t) + noise(i + 3))
            .collect();
        let plain = fit_free_acceleration(&pts).unwrap();
        assert!((plain.a[1] + 9.81).abs() > 10.0 * plain.se[1], "{plain:?}");
        let beyond = fit_free_acceleration_beyond_rim(&pts, &radius).unwrap();
        assert!((beyond.a[1] + 9.81).abs() < 3.0 * beyond.se[1], "{beyond:?}");
        assert!(beyond.a[0].abs() < 3.0 * beyond.se[0], "{beyond:?}");
        let still = vec![0.0335; n];
        assert_eq!(fit_free_acceleration_beyond_rim(&pts, &still), Some(plain));
        assert_eq!(fit_free_acceleration_beyond_rim(&pts, &still[1..]), None);
    }

    #[test]
    fn a_free_fit_recovers_the_acceleration() {
        let pts: Vec<_> = (0..40)
            .map(|i| i as f64 * 1e-4)
            .map(|t| (t, 0.1 + 0.5 * t + 0.6 * t * t, 0.2 - 2.0 * t - 4.905 * t * t, 1e-6))
            .collect();
        let FreeArc { a, se, rms_m, .. } = fit_free_acceleration(&pts).unwrap();
        assert!((a[0] - 1.2).abs() < 1e-6 && (a[1] + 9.81).abs() < 1e-6, "{a:?}");
        assert!(rms_m < 1e-12, "{rms_m}");
        // 40 frames over 3.9 ms at 1 µm: the acceleration is known to about ±0.27 m/s² (the same for x and y).
        assert!((se[1] - 0.27).abs() < 0.03 && se[0] == se[1], "{se:?}");
    }

    use super::*;

    #[test]
    fn exact_arc_is_recovered() {
        let a = [1.2, -9.0];
        let pts: Vec<_> = (0..30)
            .map(|i| i as f64 * 1e-4)
            .map(|t| (t, 0.1 + 0.5 * t + 0.6 * t * t, 0.2 - 2.0 * t - 4.5 * t * t, 1e-5))
            .collect();
        let f = fit_ballistic(&pts, a).unwrap();
        let v = f.velocity(0.0);
        assert!((v[0] - 0.5).abs() < 1e-9 && (v[1] + 2.0).abs() < 1e-9, "{v:?}");
        let p = f.position(0.001);
        assert!((p[1] - (0.2 - 0.002 - 4.5e-6)).abs() < 1e-12);
        assert!(f.chi2_red[1] < 1e-6);
    }

    #[test]
    fn too_few_points_is_none() {
        assert!(fit_ballistic(&[(0.0, 0.0, 0.0, 1.0), (1.0, 1.0, 1.0, 1.0)], [0.0, 0.0]).is_none());
    }
}
