//! A straight line y = a + b·x by (weighted) least squares, with the slope's standard error and test.

use serde::{Deserialize, Serialize};

use crate::StatsError;
use crate::dist::t_two_sided_p;

/// The least-squares line through (x, y) and its inference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineFit {
    /// Number of points.
    pub n: usize,
    /// Residual degrees of freedom, n − 2.
    pub df: usize,
    /// a, in y's unit: the line's value at x = 0.
    pub intercept: f64,
    /// b, in y's unit per x's unit.
    pub slope: f64,
    /// Standard error of the intercept.
    pub intercept_se: f64,
    /// Standard error of the slope.
    pub slope_se: f64,
    /// Covariance of intercept and slope (for a confidence band: Var(a + b·x) = Var a + 2x·Cov + x²·Var b).
    pub cov_intercept_slope: f64,
    /// slope / slope_se (0 when both are 0).
    pub t: f64,
    /// Two-sided p-value of the slope on n − 2 degrees of freedom (1 when the slope and its SE are both 0).
    pub p: f64,
    /// σ̂² = Σ wᵢ rᵢ² / (n − 2), in y's unit squared (unweighted: the residual mean square).
    pub residual_variance: f64,
    /// The (weighted) mean of x, where the line's uncertainty is smallest.
    pub x_mean: f64,
}

/// Fits y = a + b·x by least squares, weighted by `w` when given.
///
/// Weights are relative precisions (typically 1/σᵢ²): the standard errors are scaled by the residual
/// variance σ̂² = Σ wᵢ rᵢ²/(n − 2), as statsmodels' `WLS(...).fit()` and R's `lm(weights = w)`. If the σᵢ
/// are known absolutely and the scatter should not rescale them, divide each standard error by
/// √`residual_variance`. Unweighted, this is ordinary least squares (`OLS`, `lm`).
///
/// Errors: lengths differ, a value is not finite, a weight is not positive, fewer than 3 points, x does
/// not vary (its weighted spread below 1e-12 of Σ w x², i.e. constant to about six digits), or sums
/// overflow.
pub fn fit_line(x: &[f64], y: &[f64], w: Option<&[f64]>) -> Result<LineFit, StatsError> {
    let n = y.len();
    let check_len = |field: &str, len: usize| {
        if len == n {
            Ok(())
        } else {
            Err(StatsError::LengthMismatch {
                field: field.into(),
                expected: n,
                found: len,
            })
        }
    };
    check_len("x", x.len())?;
    if let Some(w) = w {
        check_len("w", w.len())?;
    }
    for (field, v) in [("x", x), ("y", y)] {
        if let Some(row) = v.iter().position(|v| !v.is_finite()) {
            return Err(StatsError::NonFinite {
                field: field.into(),
                row,
            });
        }
    }
    if let Some(w) = w
        && let Some(row) = w.iter().position(|v| !(v.is_finite() && *v > 0.0))
    {
        return Err(StatsError::InvalidWeight { row, value: w[row] });
    }
    if n < 3 {
        return Err(StatsError::TooFewObservations {
            what: "a straight-line fit (the slope's standard error needs n − 2 ≥ 1)".into(),
            have: n,
            need: 3,
        });
    }
    let wi = |i: usize| w.map_or(1.0, |w| w[i]);
    let sw: f64 = (0..n).map(wi).sum();
    let mx = (0..n).map(|i| wi(i) * x[i]).sum::<f64>() / sw;
    let my = (0..n).map(|i| wi(i) * y[i]).sum::<f64>() / sw;
    let sxx: f64 = (0..n).map(|i| wi(i) * (x[i] - mx).powi(2)).sum();
    let sxy: f64 = (0..n).map(|i| wi(i) * (x[i] - mx) * (y[i] - my)).sum();
    let floor = 1e-12 * (0..n).map(|i| wi(i) * x[i] * x[i]).sum::<f64>().max(1e-300);
    if sxx.is_nan() || sxx <= floor {
        return Err(StatsError::Degenerate {
            what: "a straight-line fit".into(),
            why: "x does not vary".into(),
        });
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let rss: f64 = (0..n).map(|i| wi(i) * (y[i] - my - slope * (x[i] - mx)).powi(2)).sum();
    let df = n - 2;
    let s2 = rss / df as f64;
    let slope_se = (s2 / sxx).sqrt();
    let intercept_se = (s2 * (1.0 / sw + mx * mx / sxx)).sqrt();
    let (t, p) = if slope_se > 0.0 {
        let t = slope / slope_se;
        (t, t_two_sided_p(t, df as f64))
    } else if slope != 0.0 {
        // The points lie exactly on a sloped line.
        (slope.signum() * f64::INFINITY, 0.0)
    } else {
        (0.0, 1.0)
    };
    if ![slope, intercept, slope_se, intercept_se, p]
        .iter()
        .all(|v| v.is_finite())
    {
        return Err(StatsError::Degenerate {
            what: "a straight-line fit".into(),
            why: "sums overflow (values too large)".into(),
        });
    }
    Ok(LineFit {
        n,
        df,
        intercept,
        slope,
        intercept_se,
        slope_se,
        cov_intercept_slope: -s2 * mx / sxx,
        t,
        p,
        residual_variance: s2,
        x_mean: mx,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn hand_computed_line() {
        let x = [0.0, 1.0, 2.0, 3.0];
        let y = [1.1, 2.9, 5.1, 6.9];
        let l = fit_line(&x, &y, None).unwrap();
        // x̄ = 1.5, ȳ = 4, Sxx = 5, Sxy = 9.8 → b = 1.96, a = 4 − 1.96·1.5 = 1.06;
        // residuals 0.04, −0.12, 0.12, −0.04.
        assert!(
            (l.slope - 1.96).abs() < 1e-14 && (l.intercept - 1.06).abs() < 1e-14,
            "{l:?}"
        );
        let s2 = (2.0 * 0.04f64.powi(2) + 2.0 * 0.12f64.powi(2)) / 2.0;
        assert!((l.residual_variance - s2).abs() < 1e-15);
        assert!((l.slope_se - (s2 / 5.0).sqrt()).abs() < 1e-15);
        assert!((l.intercept_se - (s2 * (0.25 + 2.25 / 5.0)).sqrt()).abs() < 1e-15);
        assert_eq!(l.df, 2);
        assert!(l.p < 0.01 && l.p > 0.0);
    }

    #[test]
    fn degenerate_inputs_are_named_errors() {
        assert!(matches!(
            fit_line(&[1.0, 2.0], &[1.0, 2.0], None),
            Err(StatsError::TooFewObservations { have: 2, .. })
        ));
        assert!(matches!(
            fit_line(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0], None),
            Err(StatsError::Degenerate { .. })
        ));
        assert!(matches!(
            fit_line(&[1.0, 2.0, f64::NAN], &[1.0, 2.0, 3.0], None),
            Err(StatsError::NonFinite { row: 2, .. })
        ));
        assert!(matches!(
            fit_line(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0], Some(&[1.0, 0.0, 1.0])),
            Err(StatsError::InvalidWeight { row: 1, .. })
        ));
        assert!(matches!(
            fit_line(&[1.0, 2.0], &[1.0, 2.0, 3.0], None),
            Err(StatsError::LengthMismatch { found: 2, .. })
        ));
        assert!(matches!(
            fit_line(&[-1e308, 1e308, 0.0], &[1.0, 2.0, 3.0], None),
            Err(StatsError::Degenerate { .. })
        ));
        // Exactly on a line: no scatter, the slope is certain.
        let l = fit_line(&[0.0, 1.0, 2.0], &[1.0, 3.0, 5.0], None).unwrap();
        assert_eq!((l.slope_se, l.p), (0.0, 0.0));
        let l = fit_line(&[0.0, 1.0, 2.0], &[4.0, 4.0, 4.0], None).unwrap();
        assert_eq!((l.slope, l.t, l.p), (0.0, 0.0, 1.0));
    }

    proptest! {
        /// Integer weights are repeated points: a weight-2 point counts as two copies of it (the estimates
        /// agree; the standard errors differ only through n).
        #[test]
        fn integer_weights_are_repeated_points(
            pts in prop::collection::vec((-5.0f64..5.0, -5.0f64..5.0, 1usize..4), 3..12),
        ) {
            let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
            let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
            let w: Vec<f64> = pts.iter().map(|p| p.2 as f64).collect();
            let xr: Vec<f64> = pts.iter().flat_map(|p| std::iter::repeat_n(p.0, p.2)).collect();
            let yr: Vec<f64> = pts.iter().flat_map(|p| std::iter::repeat_n(p.1, p.2)).collect();
            match (fit_line(&x, &y, Some(&w)), fit_line(&xr, &yr, None)) {
                (Ok(a), Ok(b)) => {
                    prop_assert!((a.slope - b.slope).abs() <= 1e-9 * (1.0 + b.slope.abs()), "{a:?} {b:?}");
                    prop_assert!((a.intercept - b.intercept).abs() <= 1e-9 * (1.0 + b.intercept.abs()));
                    // Same weighted RSS, different df.
                    let rss_a = a.residual_variance * a.df as f64;
                    let rss_b = b.residual_variance * b.df as f64;
                    prop_assert!((rss_a - rss_b).abs() <= 1e-9 * (1.0 + rss_b));
                }
                (Err(_), Err(_)) => {}
                (a, b) => prop_assert!(false, "{a:?} vs {b:?}"),
            }
        }

        /// Scaling every weight by a constant changes nothing.
        #[test]
        fn weights_are_relative(
            pts in prop::collection::vec((-5.0f64..5.0, -5.0f64..5.0, 0.1f64..10.0), 3..12),
            scale in 0.01f64..100.0,
        ) {
            let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
            let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
            let w: Vec<f64> = pts.iter().map(|p| p.2).collect();
            let ws: Vec<f64> = w.iter().map(|v| v * scale).collect();
            if let (Ok(a), Ok(b)) = (fit_line(&x, &y, Some(&w)), fit_line(&x, &y, Some(&ws))) {
                for (u, v) in [(a.slope, b.slope), (a.slope_se, b.slope_se), (a.intercept_se, b.intercept_se), (a.p, b.p)] {
                    prop_assert!((u - v).abs() <= 1e-9 * (1.0 + v.abs()), "{a:?} {b:?}");
                }
            }
        }
    }
}
