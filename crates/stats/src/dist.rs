//! Student's t and F tail probabilities, t quantiles, and the significance-level check every test shares.

use statrs::distribution::{Continuous, ContinuousCDF, FisherSnedecor, StudentsT};
use statrs::function::beta::beta_reg;

use crate::StatsError;

/// Rejects a significance level outside (0, 1).
pub(crate) fn check_alpha(alpha: f64) -> Result<(), StatsError> {
    if alpha > 0.0 && alpha < 1.0 {
        Ok(())
    } else {
        Err(StatsError::InvalidParameter {
            name: "alpha",
            value: alpha,
            expected: "0 < alpha < 1",
        })
    }
}

/// P(F' > `f`) for F' ~ F(`df1`, `df2`): 0 for an infinite `f`, NaN for a NaN one.
pub(crate) fn f_upper_p(f: f64, df1: f64, df2: f64) -> f64 {
    if f.is_nan() {
        f64::NAN
    } else if f == f64::INFINITY {
        0.0
    } else {
        FisherSnedecor::new(df1, df2)
            .map(|d| d.sf(f.max(0.0)))
            .unwrap_or(f64::NAN)
    }
}

/// P(|T| > |t|) for T ~ Student t(`df`): the regularised incomplete beta I_{df/(df+t²)}(df/2, 1/2), which
/// keeps its relative accuracy for tiny p (no 1 − cdf). NaN for a NaN `t` or a `df` that is not positive.
pub(crate) fn t_two_sided_p(t: f64, df: f64) -> f64 {
    if t.is_nan() || df.is_nan() || df <= 0.0 {
        return f64::NAN;
    }
    if t.is_infinite() {
        return 0.0;
    }
    beta_reg(0.5 * df, 0.5, df / (df + t * t)).clamp(0.0, 1.0)
}

/// The x with P(T > x) = `upper` for T ~ t(`df`), `upper` in (0, 1): statrs' inverse (via the inverse
/// incomplete beta) polished by Newton steps on the upper tail, so the quantile is good to a few ulps.
pub(crate) fn t_upper_quantile(upper: f64, df: f64) -> f64 {
    let Ok(dist) = StudentsT::new(0.0, 1.0, df) else {
        return f64::NAN;
    };
    if !(upper > 0.0 && upper < 1.0) {
        return f64::NAN;
    }
    let mut x = dist.inverse_cdf(1.0 - upper);
    for _ in 0..4 {
        let tail = if x > 0.0 {
            0.5 * t_two_sided_p(x, df)
        } else {
            1.0 - 0.5 * t_two_sided_p(x, df)
        };
        let step = (tail - upper) / dist.pdf(x);
        if !step.is_finite() {
            break;
        }
        x += step;
        if step.abs() <= 1e-15 * x.abs() {
            break;
        }
    }
    x
}

/// The x with P(T ≤ x) = `p`; a two-sided (1 − alpha) interval uses `t_quantile(1 − alpha/2, df)`.
pub(crate) fn t_quantile(p: f64, df: f64) -> f64 {
    t_upper_quantile(1.0 - p, df)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// scipy 1.17.1 `t.ppf` and `2 * t.sf`.
    #[test]
    fn matches_scipy() {
        for &(p, df, q) in &[
            (0.975, 137.0, 1.977_431_212_308_174_8),
            (0.975, 3.0, 3.182_446_305_283_707_8),
            (0.995, 10.0, 3.169_272_672_616_95),
        ] {
            let got = t_quantile(p, df);
            assert!((got - q).abs() < 1e-12 * q, "t.ppf({p}, {df}) = {got}, scipy {q}");
        }
        for &(t, df, p) in &[
            (2.0, 10.0, 0.073_388_034_770_740_37),
            (9.0, 137.0, 1.673_890_550_590_039e-15),
        ] {
            let got = t_two_sided_p(t, df);
            assert!((got - p).abs() < 1e-9 * p, "2 t.sf({t}, {df}) = {got}, scipy {p}");
        }
        assert_eq!(t_two_sided_p(0.0, 5.0), 1.0);
        assert_eq!(t_two_sided_p(f64::INFINITY, 5.0), 0.0);
        assert!(t_two_sided_p(f64::NAN, 5.0).is_nan());
        assert!(t_quantile(1.5, 5.0).is_nan());
    }
}
