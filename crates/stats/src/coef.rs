//! The coefficient table of a linear fit: estimate, standard error, t, p and confidence interval of
//! every coefficient, from the QR (as statsmodels' `summary2()`).

use nalgebra::DVector;
use serde::{Deserialize, Serialize};

use crate::dist::{check_alpha, t_quantile, t_two_sided_p};
use crate::linear::Ols;
use crate::{Dataset, StatsError};

/// One coefficient of a linear fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coefficient {
    /// Name as patsy spells it (`Intercept`, `surface[T.tape1]`, `v_in_n`).
    pub name: String,
    /// Estimate, in the response's unit (per unit of the covariate for a covariate's slope).
    pub estimate: f64,
    /// Standard error, same unit as the estimate.
    pub se: f64,
    /// t statistic, estimate / se.
    pub t: f64,
    /// Two-sided p-value of t on the residual degrees of freedom.
    pub p: f64,
    /// Lower limit of the (1 − alpha) confidence interval.
    pub lower: f64,
    /// Upper limit of the (1 − alpha) confidence interval.
    pub upper: f64,
}

/// Every coefficient of a fit with its inference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoefficientTable {
    /// One minus the confidence level of the intervals (0.05 for 95 %).
    pub alpha: f64,
    /// Residual degrees of freedom, n − p.
    pub df: usize,
    /// The t quantile 1 − alpha/2 on `df` that sets the intervals' half-width in standard errors.
    pub t_crit: f64,
    /// Residual standard deviation σ̂, in the response's unit.
    pub sigma: f64,
    /// The coefficients, intercept first, in fitting order.
    pub rows: Vec<Coefficient>,
}

impl CoefficientTable {
    /// The coefficient called `name`, if any.
    pub fn row(&self, name: &str) -> Option<&Coefficient> {
        self.rows.iter().find(|r| r.name == name)
    }
}

pub(crate) fn table_of(ols: &Ols, alpha: f64) -> Result<CoefficientTable, StatsError> {
    check_alpha(alpha)?;
    let df = ols.df as f64;
    let t_crit = t_quantile(1.0 - alpha / 2.0, df);
    let p = ols.p();
    let rows = ols
        .names()
        .into_iter()
        .enumerate()
        .map(|(j, name)| {
            let estimate = ols.beta[j];
            let se = ols.se(&DVector::from_fn(p, |i, _| if i == j { 1.0 } else { 0.0 }));
            let t = estimate / se;
            Coefficient {
                name,
                estimate,
                se,
                t,
                p: t_two_sided_p(t, df),
                lower: estimate - t_crit * se,
                upper: estimate + t_crit * se,
            }
        })
        .collect();
    Ok(CoefficientTable {
        alpha,
        df: ols.df,
        t_crit,
        sigma: ols.sigma2().sqrt(),
        rows,
    })
}

/// The coefficient table of the response of `data` on an intercept plus `terms` (the same fit as
/// [`fit_linear`](crate::fit_linear)), with (1 − `alpha`) confidence intervals.
pub fn coefficient_table(data: &Dataset, terms: &[&str], alpha: f64) -> Result<CoefficientTable, StatsError> {
    table_of(&Ols::of(data, terms)?, alpha)
}
