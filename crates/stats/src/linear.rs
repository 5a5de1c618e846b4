//! Least squares by Householder QR of a treatment-coded design matrix.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::{Dataset, StatsError};

/// Relative size below which a column's component orthogonal to the previous columns counts as zero.
const RANK_TOL: f64 = 1e-10;

/// The columns of one model term.
#[derive(Debug, Clone)]
pub(crate) struct TermColumns {
    pub name: String,
    /// Column names (`surface[T.tape1]`, `v_in_n`).
    pub labels: Vec<String>,
    /// Column-major values, `labels.len()` columns of `n` rows.
    pub columns: Vec<Vec<f64>>,
}

/// Looks up each term as a factor (treatment coding, first level as reference) or a covariate.
pub(crate) fn term_columns(data: &Dataset, terms: &[&str]) -> Result<Vec<TermColumns>, StatsError> {
    let mut out: Vec<TermColumns> = Vec::with_capacity(terms.len());
    for &t in terms {
        if out.iter().any(|c| c.name == t) {
            return Err(StatsError::UnknownVariable { name: t.to_string() });
        }
        if let Some(f) = data.factor(t) {
            if f.levels.len() < 2 {
                return Err(StatsError::SingleLevel {
                    factor: t.to_string(),
                    level: f.levels.first().cloned().unwrap_or_default(),
                });
            }
            let mut labels = Vec::new();
            let mut columns = Vec::new();
            for (li, level) in f.levels.iter().enumerate().skip(1) {
                labels.push(format!("{t}[T.{level}]"));
                columns.push(f.codes.iter().map(|&c| if c == li { 1.0 } else { 0.0 }).collect());
            }
            out.push(TermColumns {
                name: t.to_string(),
                labels,
                columns,
            });
        } else if let Some(c) = data.covariate(t) {
            out.push(TermColumns {
                name: t.to_string(),
                labels: vec![t.to_string()],
                columns: vec![c.values.clone()],
            });
        } else {
            return Err(StatsError::UnknownVariable { name: t.to_string() });
        }
    }
    Ok(out)
}

/// QR of `[1 | term columns...]` in the given term order.
pub(crate) struct Qr {
    /// Thin Q, n × p.
    pub q: DMatrix<f64>,
    /// R, p × p.
    pub r: DMatrix<f64>,
    /// Qᵀy: the orthogonal effects; the squares of a term's entries are its sequential sum of squares.
    pub effects: DVector<f64>,
    /// For each column, the index of its term (`None` for the intercept).
    pub owner: Vec<Option<usize>>,
}

pub(crate) fn qr_fit(y: &[f64], terms: &[TermColumns], order: &[usize]) -> Result<Qr, StatsError> {
    let n = y.len();
    let mut owner = vec![None];
    let mut cols: Vec<&[f64]> = Vec::new();
    let ones = vec![1.0; n];
    cols.push(&ones);
    for &t in order {
        for c in &terms[t].columns {
            cols.push(c);
            owner.push(Some(t));
        }
    }
    let p = cols.len();
    if n <= p {
        return Err(StatsError::TooFewObservations {
            what: "the linear model (observations must exceed parameters)".into(),
            have: n,
            need: p + 1,
        });
    }
    let x = DMatrix::from_fn(n, p, |i, j| cols[j][i]);
    let qr = x.qr();
    let (q, r) = qr.unpack();
    for j in 0..p {
        let norm = cols[j].iter().map(|v| v * v).sum::<f64>().sqrt();
        if r[(j, j)].abs() <= RANK_TOL * norm || r[(j, j)].is_nan() {
            let term = match owner[j] {
                Some(t) => terms[t].name.clone(),
                None => "intercept".to_string(),
            };
            return Err(StatsError::SingularDesign { term });
        }
    }
    let yv = DVector::from_column_slice(y);
    let effects = q.tr_mul(&yv);
    Ok(Qr { q, r, effects, owner })
}

/// An ordinary least squares fit of the response on an intercept plus the model terms.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearFit {
    /// The model terms, in fitting order.
    pub terms: Vec<String>,
    /// Name of each coefficient (`Intercept`, `surface[T.tape1]`, `v_in_n`, as patsy spells them).
    pub coefficient_names: Vec<String>,
    /// Estimated coefficients, same order.
    pub coefficients: Vec<f64>,
    /// Fitted values, one per observation, in the response's unit.
    pub fitted: Vec<f64>,
    /// Raw residuals, observed − fitted.
    pub residuals: Vec<f64>,
    /// Diagonal of the hat matrix X(XᵀX)⁻¹Xᵀ.
    pub leverage: Vec<f64>,
    /// Residual sum of squares.
    pub rss: f64,
    /// Residual degrees of freedom, n − p.
    pub df_resid: usize,
    /// Number of observations.
    pub n: usize,
}

impl LinearFit {
    /// Residual mean square, rss / df_resid (σ̂²).
    pub fn mse(&self) -> f64 {
        self.rss / self.df_resid as f64
    }
}

/// Fits the response of `data` on an intercept plus `terms` (factor names, treatment coded with the first
/// sorted level as reference, or covariate names), no interactions.
pub fn fit_linear(data: &Dataset, terms: &[&str]) -> Result<LinearFit, StatsError> {
    let cols = term_columns(data, terms)?;
    let order: Vec<usize> = (0..cols.len()).collect();
    let y = data.response();
    let qr = qr_fit(y, &cols, &order)?;
    let p = qr.r.ncols();
    let n = y.len();
    let coef =
        qr.r.solve_upper_triangular(&qr.effects)
            .ok_or_else(|| StatsError::SingularDesign {
                term: terms.last().map(|s| s.to_string()).unwrap_or_default(),
            })?;
    let fitted_v = &qr.q * &qr.effects;
    let fitted: Vec<f64> = fitted_v.iter().copied().collect();
    let residuals: Vec<f64> = y.iter().zip(&fitted).map(|(a, b)| a - b).collect();
    let leverage = (0..n).map(|i| qr.q.row(i).norm_squared()).collect();
    let rss = residuals.iter().map(|e| e * e).sum();
    let mut names = vec!["Intercept".to_string()];
    for c in &cols {
        names.extend(c.labels.iter().cloned());
    }
    Ok(LinearFit {
        terms: terms.iter().map(|s| s.to_string()).collect(),
        coefficient_names: names,
        coefficients: coef.iter().copied().collect(),
        fitted,
        residuals,
        leverage,
        rss,
        df_resid: n - p,
        n,
    })
}
