//! Weighted least-squares fit of a ballistic arc with known acceleration.

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
/// the standard errors are inflated by √χ²_red when the scatter exceeds the given σ.
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
        let inflate = chi2_red.max(1.0);
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

#[cfg(test)]
mod tests {
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
