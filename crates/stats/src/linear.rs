//! Least squares by Householder QR of a treatment-coded design matrix.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::{Dataset, StatsError};

/// Relative size below which a column's component orthogonal to the previous columns counts as zero.
const RANK_TOL: f64 = 1e-10;

/// What a model term is made of.
#[derive(Debug, Clone)]
pub(crate) enum TermKind {
    /// A treatment-coded factor: its sorted levels, the first being the reference (no column).
    Factor { levels: Vec<String> },
    /// A numeric covariate and its mean over the observations.
    Covariate { mean: f64 },
    /// A column added for a test (RESET powers, a squared covariate); never part of a reference grid.
    Extra,
}

/// The columns of one model term.
#[derive(Debug, Clone)]
pub(crate) struct TermColumns {
    pub name: String,
    pub kind: TermKind,
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
                kind: TermKind::Factor {
                    levels: f.levels.clone(),
                },
                labels,
                columns,
            });
        } else if let Some(c) = data.covariate(t) {
            let mean = c.values.iter().sum::<f64>() / c.values.len().max(1) as f64;
            out.push(TermColumns {
                name: t.to_string(),
                kind: TermKind::Covariate { mean },
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

/// A least-squares fit with what inference needs: the QR's R gives Var(Lᵀβ̂) = σ̂² ‖R⁻ᵀL‖² for any
/// linear combination L without forming (XᵀX)⁻¹.
pub(crate) struct Ols {
    pub cols: Vec<TermColumns>,
    pub qr: Qr,
    pub beta: DVector<f64>,
    pub fitted: Vec<f64>,
    pub residuals: Vec<f64>,
    pub rss: f64,
    /// Residual degrees of freedom, n − p.
    pub df: usize,
}

impl Ols {
    /// Fits `y` on an intercept plus every column of `cols`, in order.
    pub fn new(y: &[f64], cols: Vec<TermColumns>) -> Result<Self, StatsError> {
        let order: Vec<usize> = (0..cols.len()).collect();
        let qr = qr_fit(y, &cols, &order)?;
        let beta =
            qr.r.solve_upper_triangular(&qr.effects)
                .ok_or_else(|| StatsError::SingularDesign {
                    term: cols.last().map(|c| c.name.clone()).unwrap_or_default(),
                })?;
        let fitted: Vec<f64> = (&qr.q * &qr.effects).iter().copied().collect();
        let residuals: Vec<f64> = y.iter().zip(&fitted).map(|(a, b)| a - b).collect();
        let rss = residuals.iter().map(|e| e * e).sum();
        let df = y.len() - qr.r.ncols();
        Ok(Ols {
            cols,
            qr,
            beta,
            fitted,
            residuals,
            rss,
            df,
        })
    }

    /// Fits the response of `data` on an intercept plus `terms`.
    pub fn of(data: &Dataset, terms: &[&str]) -> Result<Self, StatsError> {
        Ols::new(data.response(), term_columns(data, terms)?)
    }

    /// Number of coefficients, intercept included.
    pub fn p(&self) -> usize {
        self.beta.len()
    }

    /// σ̂², the residual mean square.
    pub fn sigma2(&self) -> f64 {
        self.rss / self.df as f64
    }

    /// Coefficient names, `Intercept` first, then each term's column labels.
    pub fn names(&self) -> Vec<String> {
        let mut names = vec!["Intercept".to_string()];
        for c in &self.cols {
            names.extend(c.labels.iter().cloned());
        }
        names
    }

    /// Standard error of Lᵀβ̂: σ̂ ‖R⁻ᵀL‖.
    pub fn se(&self, l: &DVector<f64>) -> f64 {
        match self.qr.r.tr_solve_upper_triangular(l) {
            Some(z) => (self.sigma2() * z.norm_squared()).sqrt(),
            None => f64::NAN,
        }
    }

    /// The index of the first coefficient of term `t` (the intercept is column 0).
    pub fn first_column(&self, t: usize) -> usize {
        1 + self.cols[..t].iter().map(|c| c.columns.len()).sum::<usize>()
    }
}

/// Fits the response of `data` on an intercept plus `terms` (factor names, treatment coded with the first
/// sorted level as reference, or covariate names), no interactions.
pub fn fit_linear(data: &Dataset, terms: &[&str]) -> Result<LinearFit, StatsError> {
    let ols = Ols::of(data, terms)?;
    let n = data.len();
    let leverage = (0..n).map(|i| ols.qr.q.row(i).norm_squared()).collect();
    Ok(LinearFit {
        terms: terms.iter().map(|s| s.to_string()).collect(),
        coefficient_names: ols.names(),
        coefficients: ols.beta.iter().copied().collect(),
        leverage,
        rss: ols.rss,
        df_resid: ols.df,
        n,
        fitted: ols.fitted,
        residuals: ols.residuals,
    })
}
