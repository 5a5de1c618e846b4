//! Tukey–Kramer all-pairs comparison of raw group means (one-way, unadjusted for any covariate), as
//! statsmodels' `pairwise_tukeyhsd`. For surfaces compared at equal impact speed, use the ANCOVA's
//! marginal means ([`marginal_means`](crate::marginal_means)) instead: a one-way test pools the
//! speed-driven spread into its error and can contradict the ANCOVA.

use serde::{Deserialize, Serialize};

use crate::dist::check_alpha;
use crate::{Dataset, StatsError, StudentizedRange};

/// Size and mean of one group.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupSummary {
    /// Group label.
    pub name: String,
    /// Number of observations.
    pub n: usize,
    /// Mean response, in the response's unit.
    pub mean: f64,
}

/// One pairwise comparison of raw means, `group2 − group1` (unadjusted for the covariate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnadjustedTukeyPair {
    /// First group (the earlier in sorted order).
    pub group1: String,
    /// Second group.
    pub group2: String,
    /// mean(group2) − mean(group1).
    pub mean_diff: f64,
    /// √(MSE/2 · (1/n₁ + 1/n₂)), the scale of the studentized range statistic.
    pub std_err: f64,
    /// Studentized range statistic |mean_diff| / std_err.
    pub q: f64,
    /// Family-wise adjusted p-value, P(Q > q) for Q ~ studentized range(k, df).
    pub p_adj: f64,
    /// Lower simultaneous confidence limit, mean_diff − q_crit · std_err.
    pub lower: f64,
    /// Upper simultaneous confidence limit.
    pub upper: f64,
    /// Whether q > q_crit (the interval excludes 0).
    pub reject: bool,
}

/// Result of [`tukey_hsd_unadjusted`]: one-way comparisons of raw means, unadjusted for the covariate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnadjustedTukey {
    /// Family-wise error rate.
    pub alpha: f64,
    /// Error degrees of freedom, n − k.
    pub df: usize,
    /// Pooled within-group variance (one-way MSE: it holds whatever the covariate explains, so it is
    /// larger than the ANCOVA's residual mean square).
    pub mse: f64,
    /// Critical studentized range, the 1 − alpha quantile.
    pub q_crit: f64,
    /// The groups, sorted (numerically when all labels are numbers).
    pub groups: Vec<GroupSummary>,
    /// All pairs i < j in group order.
    pub pairs: Vec<UnadjustedTukeyPair>,
}

/// Old name of [`UnadjustedTukey`], kept so existing callers build; use the new name.
pub type TukeyHsd = UnadjustedTukey;
/// Old name of [`UnadjustedTukeyPair`], kept so existing callers build; use the new name.
pub type TukeyPair = UnadjustedTukeyPair;

/// Tukey–Kramer comparisons of the raw means of `response` grouped by `groups` (one label per observation)
/// with a one-way pooled variance, at family-wise level `alpha`: unadjusted for the covariate (see the
/// module documentation).
pub fn tukey_hsd_unadjusted<S: AsRef<str>>(
    response: &[f64],
    groups: &[S],
    alpha: f64,
) -> Result<UnadjustedTukey, StatsError> {
    let data = Dataset::new("response", response.to_vec())?.with_factor("group", groups)?;
    tukey_hsd_unadjusted_factor(&data, "group", alpha)
}

/// [`tukey_hsd_unadjusted`] on a factor of a data set (ignores every other column).
pub fn tukey_hsd_unadjusted_factor(data: &Dataset, factor: &str, alpha: f64) -> Result<UnadjustedTukey, StatsError> {
    check_alpha(alpha)?;
    let f = data.factor(factor).ok_or_else(|| StatsError::UnknownVariable {
        name: factor.to_string(),
    })?;
    let y = data.response();
    let k = f.levels.len();
    if k < 2 {
        return Err(StatsError::SingleLevel {
            factor: factor.to_string(),
            level: f.levels.first().cloned().unwrap_or_default(),
        });
    }
    let mut n = vec![0usize; k];
    let mut sum = vec![0.0; k];
    for (i, &c) in f.codes.iter().enumerate() {
        n[c] += 1;
        sum[c] += y[i];
    }
    let mean: Vec<f64> = sum.iter().zip(&n).map(|(s, &m)| s / m as f64).collect();
    let total = y.len();
    if total <= k {
        return Err(StatsError::TooFewObservations {
            what: format!("Tukey HSD of `{factor}` (need more observations than groups)"),
            have: total,
            need: k + 1,
        });
    }
    let df = total - k;
    let sse: f64 = f.codes.iter().enumerate().map(|(i, &c)| (y[i] - mean[c]).powi(2)).sum();
    let mse = sse / df as f64;
    let dist = StudentizedRange::new(k as f64, df as f64)?;
    let q_crit = dist.quantile(1.0 - alpha);
    let mut pairs = Vec::new();
    for i in 0..k {
        for j in i + 1..k {
            let mean_diff = mean[j] - mean[i];
            let std_err = (0.5 * mse * (1.0 / n[i] as f64 + 1.0 / n[j] as f64)).sqrt();
            let q = mean_diff.abs() / std_err;
            let half = q_crit * std_err;
            pairs.push(UnadjustedTukeyPair {
                group1: f.levels[i].clone(),
                group2: f.levels[j].clone(),
                mean_diff,
                std_err,
                q,
                p_adj: dist.sf(q),
                lower: mean_diff - half,
                upper: mean_diff + half,
                reject: q > q_crit,
            });
        }
    }
    Ok(UnadjustedTukey {
        alpha,
        df,
        mse,
        q_crit,
        groups: (0..k)
            .map(|i| GroupSummary {
                name: f.levels[i].clone(),
                n: n[i],
                mean: mean[i],
            })
            .collect(),
        pairs,
    })
}

/// Old name of [`tukey_hsd_unadjusted`], kept so existing callers build; use the new name.
pub fn tukey_hsd<S: AsRef<str>>(response: &[f64], groups: &[S], alpha: f64) -> Result<UnadjustedTukey, StatsError> {
    tukey_hsd_unadjusted(response, groups, alpha)
}

/// Old name of [`tukey_hsd_unadjusted_factor`], kept so existing callers build; use the new name.
pub fn tukey_hsd_factor(data: &Dataset, factor: &str, alpha: f64) -> Result<UnadjustedTukey, StatsError> {
    tukey_hsd_unadjusted_factor(data, factor, alpha)
}
