//! Estimated marginal (covariate-adjusted) means of a factor from the ANCOVA fit and all their pairwise
//! differences, Tukey–Kramer and Holm adjusted.
//!
//! The convention is emmeans' default reference grid: every covariate at its mean over the observations,
//! every other factor's levels averaged with equal weights (not weighted by their counts). The mean of
//! level j is Lⱼᵀβ̂ with standard error σ̂ ‖R⁻ᵀLⱼ‖; a difference uses Lⱼ − Lᵢ. Tukey's p-value is the upper
//! tail of the studentized range at |t|·√2 with k levels and the fit's residual degrees of freedom (emmeans'
//! `adjust = "tukey"`; exact for a balanced one-way layout, the Tukey–Kramer approximation otherwise).

use nalgebra::DVector;
use serde::{Deserialize, Serialize};

use crate::dist::{check_alpha, t_quantile, t_two_sided_p};
use crate::linear::{Ols, TermKind};
use crate::{Dataset, StatsError, StudentizedRange, holm};

/// One value the reference grid holds fixed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridValue {
    /// The covariate's name.
    pub name: String,
    /// Its value on the grid (its mean over the observations), in its own unit.
    pub value: f64,
}

/// The estimated marginal mean of one level.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MarginalMean {
    /// The level.
    pub level: String,
    /// Observations at this level.
    pub n: usize,
    /// The plain mean of the response at this level (not adjusted), in the response's unit.
    pub raw_mean: f64,
    /// The adjusted mean, in the response's unit.
    pub estimate: f64,
    /// Its standard error.
    pub se: f64,
    /// Lower limit of its (1 − alpha) confidence interval (t on the residual df, not simultaneous).
    pub lower: f64,
    /// Upper limit.
    pub upper: f64,
}

/// The difference of two adjusted means, `level2 − level1`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MarginalComparison {
    /// First level (the earlier in the factor's sorted order).
    pub level1: String,
    /// Second level.
    pub level2: String,
    /// Adjusted mean of `level2` − adjusted mean of `level1`, in the response's unit.
    pub estimate: f64,
    /// Standard error of the difference.
    pub se: f64,
    /// t = estimate / se on the fit's residual degrees of freedom.
    pub t: f64,
    /// Two-sided p-value of t, not adjusted for the number of pairs.
    pub p: f64,
    /// Family-wise p-value, Tukey–Kramer: P(Q > |t|·√2) for Q ~ studentized range(k, df).
    pub p_tukey: f64,
    /// Family-wise p-value, Holm's step-down adjustment of `p` over the factor's pairs.
    pub p_holm: f64,
    /// Lower limit of the Tukey simultaneous (1 − alpha) interval, estimate − q_crit/√2 · se.
    pub lower: f64,
    /// Upper limit of the Tukey simultaneous interval.
    pub upper: f64,
    /// The Tukey interval excludes 0 (|t|·√2 > q_crit).
    pub reject_tukey: bool,
    /// `p_holm ≤ alpha`.
    pub reject_holm: bool,
}

/// Adjusted means of one factor and their pairwise comparisons.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MarginalMeans {
    /// The factor compared.
    pub factor: String,
    /// Family-wise error rate of the comparisons, and one minus the level of every interval.
    pub alpha: f64,
    /// Residual degrees of freedom of the fit (n − p).
    pub df: usize,
    /// Residual mean square of the fit (σ̂²), in the response's unit squared.
    pub mse: f64,
    /// t quantile 1 − alpha/2 on `df`, the half-width of a mean's interval in standard errors.
    pub t_crit: f64,
    /// Studentized range quantile 1 − alpha with k levels and `df`; a difference's simultaneous interval
    /// is ± q_crit/√2 standard errors.
    pub q_crit: f64,
    /// Covariates held at their means on the reference grid.
    pub covariates_at: Vec<GridValue>,
    /// Other factors whose levels are averaged with equal weights.
    pub averaged_over: Vec<String>,
    /// One adjusted mean per level, in the factor's sorted order.
    pub means: Vec<MarginalMean>,
    /// All pairs i < j in level order.
    pub pairs: Vec<MarginalComparison>,
}

/// The reference-grid row of level `j` of factor term `t`.
fn grid_row(ols: &Ols, t: usize, j: usize) -> DVector<f64> {
    let mut l = DVector::zeros(ols.p());
    l[0] = 1.0;
    for (u, c) in ols.cols.iter().enumerate() {
        let first = ols.first_column(u);
        match &c.kind {
            TermKind::Factor { .. } if u == t => {
                if j > 0 {
                    l[first + j - 1] = 1.0;
                }
            }
            TermKind::Factor { levels } => {
                for k in 0..c.columns.len() {
                    l[first + k] = 1.0 / levels.len() as f64;
                }
            }
            TermKind::Covariate { mean } => l[first] = *mean,
            // Test-only columns are never in a fit made from model terms.
            TermKind::Extra => {}
        }
    }
    l
}

/// Everything but the Tukey adjustment (`q_crit`, `p_tukey`, the simultaneous limits are NaN): the cheap
/// part, which the unit tests exercise on many designs.
fn estimates(ols: &Ols, data: &Dataset, factor: &str, alpha: f64) -> Result<MarginalMeans, StatsError> {
    check_alpha(alpha)?;
    let not_term = || {
        if data.factor(factor).is_some() || data.covariate(factor).is_some() {
            StatsError::NotATerm {
                name: factor.to_string(),
                kind: "factor",
            }
        } else {
            StatsError::UnknownVariable {
                name: factor.to_string(),
            }
        }
    };
    let t = ols.cols.iter().position(|c| c.name == factor).ok_or_else(not_term)?;
    let TermKind::Factor { levels } = &ols.cols[t].kind else {
        return Err(not_term());
    };
    let f = data.factor(factor).ok_or_else(not_term)?;
    let k = levels.len();
    let df = ols.df as f64;
    let t_crit = t_quantile(1.0 - alpha / 2.0, df);

    let y = data.response();
    let rows: Vec<DVector<f64>> = (0..k).map(|j| grid_row(ols, t, j)).collect();
    let means = rows
        .iter()
        .enumerate()
        .map(|(j, l)| {
            let (n, sum) = f
                .codes
                .iter()
                .zip(y)
                .filter(|(c, _)| **c == j)
                .fold((0usize, 0.0), |(n, s), (_, v)| (n + 1, s + v));
            let estimate = l.dot(&ols.beta);
            let se = ols.se(l);
            MarginalMean {
                level: levels[j].clone(),
                n,
                raw_mean: sum / n as f64,
                estimate,
                se,
                lower: estimate - t_crit * se,
                upper: estimate + t_crit * se,
            }
        })
        .collect();

    let pairs = pairwise(ols, &rows, levels, df, alpha);
    let (covariates_at, averaged_over) = grid_of(ols, factor);
    Ok(MarginalMeans {
        factor: factor.to_string(),
        alpha,
        df: ols.df,
        mse: ols.sigma2(),
        t_crit,
        q_crit: f64::NAN,
        covariates_at,
        averaged_over,
        means,
        pairs,
    })
}

/// Every pair of levels (i < j, in level order): the difference of their adjusted means (rows `rows` of
/// the grid), its t test on `df` degrees of freedom, and Holm's adjustment over the pairs at `alpha`; the
/// Tukey figures are left NaN.
fn pairwise(ols: &Ols, rows: &[DVector<f64>], levels: &[String], df: f64, alpha: f64) -> Vec<MarginalComparison> {
    let k = levels.len();
    let mut pairs = Vec::with_capacity(k * (k - 1) / 2);
    for i in 0..k {
        for j in i + 1..k {
            let d = &rows[j] - &rows[i];
            let estimate = d.dot(&ols.beta);
            let se = ols.se(&d);
            let tv = estimate / se;
            pairs.push(MarginalComparison {
                level1: levels[i].clone(),
                level2: levels[j].clone(),
                estimate,
                se,
                t: tv,
                p: t_two_sided_p(tv, df),
                p_tukey: f64::NAN,
                p_holm: f64::NAN,
                lower: f64::NAN,
                upper: f64::NAN,
                reject_tukey: false,
                reject_holm: false,
            });
        }
    }
    let raw: Vec<f64> = pairs.iter().map(|p| p.p).collect();
    for (pair, adj) in pairs.iter_mut().zip(holm(&raw)) {
        pair.p_holm = adj;
        pair.reject_holm = adj <= alpha;
    }
    pairs
}

/// Where the adjusted means of `factor` are taken: each covariate at its mean, and the other factors
/// averaged over.
fn grid_of(ols: &Ols, factor: &str) -> (Vec<GridValue>, Vec<String>) {
    let mut covariates_at = Vec::new();
    let mut averaged_over = Vec::new();
    for c in &ols.cols {
        match &c.kind {
            TermKind::Covariate { mean } => covariates_at.push(GridValue {
                name: c.name.clone(),
                value: *mean,
            }),
            TermKind::Factor { .. } if c.name != factor => averaged_over.push(c.name.clone()),
            _ => {}
        }
    }
    (covariates_at, averaged_over)
}

pub(crate) fn means_of(ols: &Ols, data: &Dataset, factor: &str, alpha: f64) -> Result<MarginalMeans, StatsError> {
    let mut m = estimates(ols, data, factor, alpha)?;
    let dist = StudentizedRange::new(m.means.len() as f64, ols.df as f64)?;
    m.q_crit = dist.quantile(1.0 - alpha);
    for pair in &mut m.pairs {
        let q = pair.t.abs() * std::f64::consts::SQRT_2;
        let half = m.q_crit / std::f64::consts::SQRT_2 * pair.se;
        pair.p_tukey = dist.sf(q);
        pair.lower = pair.estimate - half;
        pair.upper = pair.estimate + half;
        pair.reject_tukey = q > m.q_crit;
    }
    Ok(m)
}

/// Estimated marginal means of `factor` from the main-effects fit of the response of `data` on `terms`
/// (which must include `factor`), and every pairwise difference with Tukey–Kramer and Holm adjusted
/// p-values at family-wise level `alpha`. See the module documentation for the reference grid.
///
/// These are the comparisons that agree with the ANCOVA: same fit, same residual variance, same degrees
/// of freedom. Unlike [`tukey_hsd_unadjusted`](crate::tukey_hsd_unadjusted) they compare surfaces at the
/// same impact speed.
pub fn marginal_means(data: &Dataset, terms: &[&str], factor: &str, alpha: f64) -> Result<MarginalMeans, StatsError> {
    means_of(&Ols::of(data, terms)?, data, factor, alpha)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coef::table_of;
    use proptest::prelude::*;

    /// The paper's table from (surface 0..3, angle 0..4, v_in_n, cor) rows.
    fn dataset(rows: &[(usize, usize, f64, f64)]) -> Dataset {
        let obs: Vec<crate::CorObservation> = rows
            .iter()
            .map(|&(s, a, v_in_n, cor)| crate::CorObservation {
                surface: ["clay", "tape1", "tape2"][s].into(),
                angle: [0.0, 7.5, 15.0, 22.5][a],
                v_in_n,
                cor,
            })
            .collect();
        Dataset::from_cor(&obs).unwrap()
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
    }

    const TERMS: [&str; 3] = ["surface", "angle", "v_in_n"];

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Differences from the reference level are the treatment coefficients, with their standard
        /// errors; every difference is the difference of the two means.
        #[test]
        fn differences_are_contrasts_of_the_fit(
            rows in prop::collection::vec((0usize..3, 0usize..4, -3.0f64..-1.0, 0.6f64..0.9), 14..50),
        ) {
            let data = dataset(&rows);
            let Ok(ols) = Ols::of(&data, &TERMS) else { return Ok(()); };
            let m = estimates(&ols, &data, "surface", 0.05).unwrap();
            let coefs = table_of(&ols, 0.05).unwrap();
            for p in m.pairs.iter().filter(|p| p.level1 == "clay") {
                let c = coefs.row(&format!("surface[T.{}]", p.level2)).unwrap();
                prop_assert!(close(p.estimate, c.estimate, 1e-10) && close(p.se, c.se, 1e-9), "{p:?} {c:?}");
                prop_assert!(close(p.p, c.p, 1e-9), "{p:?} {c:?}");
            }
            for p in &m.pairs {
                let mean = |l: &str| m.means.iter().find(|x| x.level == l).unwrap().estimate;
                prop_assert!(close(p.estimate, mean(&p.level2) - mean(&p.level1), 1e-12));
                prop_assert!(p.p_holm >= p.p && p.p_holm <= 1.0);
            }
        }

        /// A balanced layout without the covariate: each surface's adjusted mean is its raw mean (equal
        /// weights over angles are the counts' weights).
        #[test]
        fn balanced_means_are_raw_means(y in prop::collection::vec(0.6f64..0.9, 24)) {
            let rows: Vec<(usize, usize, f64, f64)> = (0..24).map(|i| (i % 3, (i / 3) % 4, -2.0, y[i])).collect();
            let data = dataset(&rows);
            let ols = Ols::of(&data, &["surface", "angle"]).unwrap();
            for factor in ["surface", "angle"] {
                let m = estimates(&ols, &data, factor, 0.05).unwrap();
                for mean in &m.means {
                    prop_assert!(close(mean.estimate, mean.raw_mean, 1e-12), "{factor} {mean:?}");
                }
            }
        }

        /// Shifting the response shifts the means and leaves the differences; scaling scales both.
        #[test]
        fn affine_in_the_response(
            rows in prop::collection::vec((0usize..3, 0usize..4, -3.0f64..-1.0, 0.6f64..0.9), 14..40),
            shift in -1.0f64..1.0,
            scale in 0.1f64..10.0,
        ) {
            let data = dataset(&rows);
            let moved: Vec<(usize, usize, f64, f64)> =
                rows.iter().map(|r| (r.0, r.1, r.2, shift + scale * r.3)).collect();
            let (Ok(a), Ok(b)) = (Ols::of(&data, &TERMS), Ols::of(&dataset(&moved), &TERMS)) else {
                return Ok(());
            };
            let ma = estimates(&a, &data, "angle", 0.05).unwrap();
            let mb = estimates(&b, &dataset(&moved), "angle", 0.05).unwrap();
            for (x, y) in ma.means.iter().zip(&mb.means) {
                prop_assert!(close(shift + scale * x.estimate, y.estimate, 1e-9));
                prop_assert!(close(scale * x.se, y.se, 1e-7));
            }
            for (x, y) in ma.pairs.iter().zip(&mb.pairs) {
                prop_assert!(close(scale * x.estimate, y.estimate, 1e-9));
                prop_assert!(close(x.t, y.t, 1e-6) || x.t.abs() > 1e6, "{x:?} {y:?}");
            }
        }
    }

    #[test]
    fn names_what_is_not_a_factor_term() {
        let rows: Vec<(usize, usize, f64, f64)> = (0..24)
            .map(|i| {
                (
                    i % 3,
                    (i / 3) % 4,
                    -2.0 - 0.01 * i as f64,
                    0.7 + 0.001 * ((i * 7) % 5) as f64,
                )
            })
            .collect();
        let data = dataset(&rows);
        let ols = Ols::of(&data, &["surface", "v_in_n"]).unwrap();
        for (name, kind) in [("angle", "factor"), ("v_in_n", "factor")] {
            match estimates(&ols, &data, name, 0.05) {
                Err(StatsError::NotATerm { name: n, kind: k }) => assert_eq!((n.as_str(), k), (name, kind)),
                other => panic!("{name}: {other:?}"),
            }
        }
        assert!(matches!(
            estimates(&ols, &data, "height", 0.05),
            Err(StatsError::UnknownVariable { .. })
        ));
        assert!(matches!(
            estimates(&ols, &data, "surface", 0.0),
            Err(StatsError::InvalidParameter { name: "alpha", .. })
        ));
        let m = estimates(&ols, &data, "surface", 0.05).unwrap();
        assert_eq!(m.averaged_over, Vec::<String>::new());
        assert_eq!(m.covariates_at.len(), 1);
        let mean_v = rows.iter().map(|r| r.2).sum::<f64>() / 24.0;
        assert!((m.covariates_at[0].value - mean_v).abs() < 1e-15);
    }
}
