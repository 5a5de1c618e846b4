//! Sequential (Type I) and Type II analysis-of-variance tables of a main-effects linear model.

use serde::{Deserialize, Serialize};

use crate::dist::f_upper_p;
use crate::linear::{qr_fit, term_columns};
use crate::{Dataset, StatsError};

/// Which sums of squares a table holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AnovaType {
    /// Sequential: each term adjusted for the terms before it (order matters).
    TypeI,
    /// Each term adjusted for every other term (no interactions here, so also Type III).
    TypeII,
}

impl AnovaType {
    /// `"I"` or `"II"`, the `type` column of the CSV form.
    pub fn label(self) -> &'static str {
        match self {
            AnovaType::TypeI => "I",
            AnovaType::TypeII => "II",
        }
    }
}

/// One line of an ANOVA table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AnovaRow {
    /// Term name, `Error` or `Total`.
    pub source: String,
    /// Sum of squares, in the response's unit squared.
    pub ss: f64,
    /// Degrees of freedom.
    pub df: usize,
    /// Mean square, ss / df.
    pub ms: f64,
    /// F statistic ms / ms_error; `None` for Error and Total.
    pub f: Option<f64>,
    /// P(F' > F) under the null hypothesis; `None` for Error and Total.
    pub p: Option<f64>,
}

/// A full ANOVA table: the term rows, then Error and Total.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AnovaTable {
    /// Type of the sums of squares.
    pub kind: AnovaType,
    /// One row per model term, in the requested order.
    pub terms: Vec<AnovaRow>,
    /// Residual row.
    pub error: AnovaRow,
    /// Corrected total, Σ(y − ȳ)² on n − 1 df. Only in Type I tables do terms + error add up to it.
    pub total: AnovaRow,
}

/// One CSV line of `anova.csv`: columns `source, ss, df, ms, f, p, type`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AnovaCsvRow {
    /// Term name, `Error` or `Total`.
    pub source: String,
    /// Sum of squares.
    pub ss: f64,
    /// Degrees of freedom.
    pub df: usize,
    /// Mean square.
    pub ms: f64,
    /// F statistic (empty for Error and Total).
    pub f: Option<f64>,
    /// p-value (empty for Error and Total).
    pub p: Option<f64>,
    /// `I` or `II`.
    #[serde(rename = "type")]
    pub kind: String,
}

impl AnovaTable {
    /// All rows, terms then Error then Total.
    pub fn rows(&self) -> impl Iterator<Item = &AnovaRow> {
        self.terms.iter().chain([&self.error, &self.total])
    }

    /// The row of the term (or `Error`/`Total`) called `source`.
    pub fn row(&self, source: &str) -> Option<&AnovaRow> {
        self.rows().find(|r| r.source == source)
    }

    /// The table as flat CSV records.
    pub fn csv_rows(&self) -> Vec<AnovaCsvRow> {
        self.rows()
            .map(|r| AnovaCsvRow {
                source: r.source.clone(),
                ss: r.ss,
                df: r.df,
                ms: r.ms,
                f: r.f,
                p: r.p,
                kind: self.kind.label().to_string(),
            })
            .collect()
    }
}

/// Writes tables as one headed CSV (`source,ss,df,ms,f,p,type`).
pub fn write_anova_csv<W: std::io::Write>(writer: W, tables: &[&AnovaTable]) -> Result<(), StatsError> {
    let mut w = csv::Writer::from_writer(writer);
    for t in tables {
        for r in t.csv_rows() {
            w.serialize(r)?;
        }
    }
    w.flush().map_err(csv::Error::from)?;
    Ok(())
}

fn f_test(ss: f64, df: usize, mse: f64, df_err: usize) -> AnovaRow {
    let ms = ss / df as f64;
    let f = ms / mse;
    let p = f_upper_p(f, df as f64, df_err as f64);
    AnovaRow {
        source: String::new(),
        ss,
        df,
        ms,
        f: Some(f),
        p: Some(p),
    }
}

/// The ANOVA table of the response of `data` on an intercept plus `terms` (main effects, treatment
/// coding; works for unbalanced data). For [`AnovaType::TypeI`], the order of `terms` is the order of
/// adjustment, e.g. `["surface", "angle", "v_in_n"]` for the paper's Table 1.
///
/// Sums of squares are squared orthogonal effects Qᵀy of a Householder QR, never differences of
/// residual sums of squares, so small terms keep their precision.
pub fn anova(data: &Dataset, terms: &[&str], kind: AnovaType) -> Result<AnovaTable, StatsError> {
    let cols = term_columns(data, terms)?;
    let y = data.response();
    let n = y.len();
    let order: Vec<usize> = (0..cols.len()).collect();
    let full = qr_fit(y, &cols, &order)?;
    let p = full.r.ncols();
    let df_err = n - p;
    let fitted = &full.q * &full.effects;
    let rss = y.iter().zip(fitted.iter()).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    let mse = rss / df_err as f64;
    let term_ss = |qr: &crate::linear::Qr, t: usize| -> f64 {
        qr.owner
            .iter()
            .zip(qr.effects.iter())
            .filter(|(o, _)| **o == Some(t))
            .map(|(_, e)| e * e)
            .sum()
    };
    let mut rows = Vec::with_capacity(cols.len());
    for (t, c) in cols.iter().enumerate() {
        let ss = match kind {
            AnovaType::TypeI => term_ss(&full, t),
            AnovaType::TypeII => {
                let mut ord: Vec<usize> = (0..cols.len()).filter(|&u| u != t).collect();
                ord.push(t);
                term_ss(&qr_fit(y, &cols, &ord)?, t)
            }
        };
        let mut row = f_test(ss, c.columns.len(), mse, df_err);
        row.source = c.name.clone();
        rows.push(row);
    }
    let mean = y.iter().sum::<f64>() / n as f64;
    let sst = y.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>();
    Ok(AnovaTable {
        kind,
        terms: rows,
        error: AnovaRow {
            source: "Error".into(),
            ss: rss,
            df: df_err,
            ms: mse,
            f: None,
            p: None,
        },
        total: AnovaRow {
            source: "Total".into(),
            ss: sst,
            df: n - 1,
            ms: sst / (n - 1) as f64,
            f: None,
            p: None,
        },
    })
}
