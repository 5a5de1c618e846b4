//! Statistics of restitution experiments: does the coefficient of restitution differ between surfaces
//! and angles once the incoming speed is accounted for? The crate fits a main-effects ANCOVA by least
//! squares (Householder QR of a treatment-coded design, so unbalanced data and Type I/II tables come
//! from the same orthogonal effects), compares surfaces pairwise by Tukey–Kramer with its own
//! studentized range distribution (direct adaptive quadrature, upper tail integrated directly so tiny
//! p-values stay accurate), and reports residual diagnostics. Everything is plain functions over a small
//! validated [`Dataset`], returning serde-serialisable structs; bad input is an error, never a panic.

mod anova;
mod data;
mod diagnostics;
mod error;
mod linear;
mod quad;
mod srange;
mod tukey;

use serde::{Deserialize, Serialize};

pub use anova::{AnovaCsvRow, AnovaRow, AnovaTable, AnovaType, anova, write_anova_csv};
pub use data::{CorObservation, Covariate, Dataset, Factor, Observation};
pub use diagnostics::{Diagnostics, NormalPlotPoint, diagnostics, excess_kurtosis, kurtosis, normal_plot, skewness};
pub use error::StatsError;
pub use linear::{LinearFit, fit_linear};
pub use srange::StudentizedRange;
pub use tukey::{GroupSummary, TukeyHsd, TukeyPair, tukey_hsd, tukey_hsd_factor};

/// The paper's Table 1 term order: surface, angle, then the incoming normal speed covariate.
pub const PAPER_TERMS: [&str; 3] = ["surface", "angle", "v_in_n"];

/// Everything the report shows about one ANCOVA.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ancova {
    /// Sequential table in the given term order.
    pub type1: AnovaTable,
    /// Type II table.
    pub type2: AnovaTable,
    /// The least-squares fit.
    pub fit: LinearFit,
    /// Residual diagnostics of the fit.
    pub diagnostics: Diagnostics,
}

/// Fits the response on `terms` (main effects, no interactions) and returns both ANOVA tables, the fit
/// and its diagnostics. Use [`PAPER_TERMS`] for the paper's analysis of a [`Dataset::from_cor`] table.
pub fn ancova(data: &Dataset, terms: &[&str]) -> Result<Ancova, StatsError> {
    let fit = fit_linear(data, terms)?;
    Ok(Ancova {
        type1: anova(data, terms, AnovaType::TypeI)?,
        type2: anova(data, terms, AnovaType::TypeII)?,
        diagnostics: diagnostics(&fit)?,
        fit,
    })
}
