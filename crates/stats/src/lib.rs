//! Statistics of restitution experiments: does the coefficient of restitution differ between surfaces
//! and angles once the incoming speed is accounted for? The crate fits a main-effects ANCOVA by least
//! squares (Householder QR of a treatment-coded design, so unbalanced data, Type I/II tables, coefficient
//! standard errors and any linear combination's variance come from the same factorisation), compares
//! surfaces and angles by their covariate-adjusted (estimated marginal) means with Tukey–Kramer and Holm
//! adjustment, using its own studentized range distribution (direct adaptive quadrature, upper tail
//! integrated directly so tiny p-values stay accurate), and tests the residuals for curvature and
//! non-normality with a sentence saying what was found. It is also the workspace's one home for small
//! shared numerics: Holm's correction, a weighted straight-line fit, p-value text. Everything is plain
//! functions over plain data returning serde-serialisable structs; bad input is an error, never a panic.
//! How the numbers are checked against statsmodels and scipy: `docs/stats.md`.

mod anova;
mod coef;
mod data;
mod diagnostics;
mod dist;
mod emm;
mod error;
mod holm;
mod line;
mod linear;
mod quad;
mod residual_tests;
mod session;
mod srange;
mod text;
mod tukey;

use serde::{Deserialize, Serialize};

pub use anova::{AnovaCsvRow, AnovaRow, AnovaTable, AnovaType, anova, write_anova_csv};
pub use coef::{Coefficient, CoefficientTable, coefficient_table};
pub use data::{CorObservation, Covariate, Dataset, Factor, Observation};
pub use diagnostics::{Diagnostics, NormalPlotPoint, diagnostics, excess_kurtosis, kurtosis, normal_plot, skewness};
pub use emm::{GridValue, MarginalComparison, MarginalMean, MarginalMeans, marginal_means};
pub use error::StatsError;
pub use holm::holm;
pub use line::{LineFit, fit_line};
pub use linear::{LinearFit, fit_linear};
pub use residual_tests::{
    CovariateCurvature, FTest, NormalityTest, ResidualTests, TestOutcome, normality_test, quadratic_test, reset_test,
    residual_tests,
};
pub use session::{SESSION_ALPHA, SessionStats, session_stats, session_terms};
pub use srange::StudentizedRange;
pub use text::p_text;
pub use tukey::{
    GroupSummary, TukeyHsd, TukeyPair, UnadjustedTukey, UnadjustedTukeyPair, tukey_hsd, tukey_hsd_factor,
    tukey_hsd_unadjusted, tukey_hsd_unadjusted_factor,
};

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
/// and its diagnostics. Use [`PAPER_TERMS`] for the paper's analysis of a [`Dataset::from_cor`] table;
/// [`ancova_inference`] gives the coefficients' tests, the adjusted comparisons and the residual tests
/// of the same fit.
pub fn ancova(data: &Dataset, terms: &[&str]) -> Result<Ancova, StatsError> {
    let fit = fit_linear(data, terms)?;
    Ok(Ancova {
        type1: anova(data, terms, AnovaType::TypeI)?,
        type2: anova(data, terms, AnovaType::TypeII)?,
        diagnostics: diagnostics(&fit)?,
        fit,
    })
}

/// The inference that goes with an [`Ancova`] of the same data and terms.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AncovaInference {
    /// Every coefficient with SE, t, p and (1 − alpha) interval.
    pub coefficients: CoefficientTable,
    /// Adjusted means and pairwise comparisons of every factor term, in term order.
    pub marginal_means: Vec<MarginalMeans>,
    /// Curvature and normality tests of the residuals, with [`ResidualTests::caption`].
    pub residual_tests: ResidualTests,
}

impl AncovaInference {
    /// The comparisons of `factor`, if it is a factor term of the fit.
    pub fn means_of(&self, factor: &str) -> Option<&MarginalMeans> {
        self.marginal_means.iter().find(|m| m.factor == factor)
    }
}

/// One fit of the response on `terms`, and from it: the coefficient table, the estimated marginal means
/// and pairwise comparisons of every factor term (surfaces and angles compared at the mean impact speed),
/// and the residual tests. `alpha` is the family-wise level of the comparisons, one minus the level of
/// every interval, and the level the residual caption decides at (0.05 for the paper's analysis).
pub fn ancova_inference(data: &Dataset, terms: &[&str], alpha: f64) -> Result<AncovaInference, StatsError> {
    let ols = linear::Ols::of(data, terms)?;
    let marginal_means = ols
        .cols
        .iter()
        .filter(|c| matches!(c.kind, linear::TermKind::Factor { .. }))
        .map(|c| emm::means_of(&ols, data, &c.name, alpha))
        .collect::<Result<_, _>>()?;
    Ok(AncovaInference {
        coefficients: coef::table_of(&ols, alpha)?,
        marginal_means,
        residual_tests: residual_tests::tests_of(&ols, data, alpha)?,
    })
}
