//! Tests of what the residuals of a fit show, and one sentence that says what was found: curvature
//! (Ramsey's RESET on the fitted values, a quadratic term in each covariate) and normality
//! (D'Agostino–Pearson's K² from the residuals' skewness and kurtosis, as scipy's `normaltest`).
//!
//! Both curvature tests are nested-model F tests: the added columns' sum of squares is read from the
//! orthogonal effects of the QR of [X | added], so it keeps its precision however small. An added power
//! of the fitted values is centred and scaled first; that spans the same space (ŷ is in X's span) and keeps
//! the column far from collinear.

use libm::erfc;
use serde::{Deserialize, Serialize};

use crate::diagnostics::central_moments;
use crate::dist::{check_alpha, f_upper_p};
use crate::linear::{Ols, TermColumns, TermKind, qr_fit};
use crate::text::{p_text, stat_text};
use crate::{Dataset, StatsError};

/// A nested-model F test: does adding columns to the fit explain more than noise?
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FTest {
    /// What was added (`squared fitted values`, `v_in_n²`).
    pub added: String,
    /// F = (ΔRSS / df_num) / (RSS_full / df_den).
    pub f: f64,
    /// Numerator degrees of freedom: the number of added columns.
    pub df_num: usize,
    /// Denominator degrees of freedom: n − p of the enlarged fit.
    pub df_den: usize,
    /// P(F' > F) under the null hypothesis that the added columns have zero coefficients.
    pub p: f64,
}

/// D'Agostino–Pearson omnibus test of normality (scipy's `normaltest`, statsmodels' `omni_normtest`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NormalityTest {
    /// Number of values tested.
    pub n: usize,
    /// Sample skewness g₁ (biased, normal = 0).
    pub skewness: f64,
    /// Sample kurtosis b₂ (biased, normal = 3).
    pub kurtosis: f64,
    /// D'Agostino's normal score of the skewness (scipy's `skewtest`); positive: a long right tail.
    pub z_skewness: f64,
    /// Anscombe–Glynn normal score of the kurtosis (scipy's `kurtosistest`); positive: heavy tails.
    pub z_kurtosis: f64,
    /// K² = z_skewness² + z_kurtosis², χ² with 2 df under normality.
    pub k2: f64,
    /// P(χ²₂ > K²) = exp(−K²/2).
    pub p: f64,
    /// Two-sided p-value of `z_skewness` alone.
    pub p_skewness: f64,
    /// Two-sided p-value of `z_kurtosis` alone.
    pub p_kurtosis: f64,
    /// Fewer than 20 values: the kurtosis score's normal approximation is rough (scipy warns likewise).
    pub small_sample: bool,
}

/// A test that ran, or why it could not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum TestOutcome<T> {
    /// The test's result.
    Ran(T),
    /// The test could not run on these data.
    NotRun {
        /// Why, in words (the error's message).
        reason: String,
    },
}

impl<T> TestOutcome<T> {
    /// The result, if the test ran.
    pub fn ran(&self) -> Option<&T> {
        match self {
            TestOutcome::Ran(t) => Some(t),
            TestOutcome::NotRun { .. } => None,
        }
    }

    fn from_result(r: Result<T, StatsError>) -> Self {
        match r {
            Ok(t) => TestOutcome::Ran(t),
            Err(e) => TestOutcome::NotRun { reason: e.to_string() },
        }
    }
}

/// The quadratic-term test of one covariate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CovariateCurvature {
    /// The covariate.
    pub covariate: String,
    /// The F test of its centred square added to the fit.
    pub test: TestOutcome<FTest>,
}

/// What the residuals of a fit show.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResidualTests {
    /// Significance level the caption decides at.
    pub alpha: f64,
    /// Ramsey's RESET with the squared fitted values.
    pub reset: TestOutcome<FTest>,
    /// A quadratic term in each covariate of the model, in term order.
    pub quadratic: Vec<CovariateCurvature>,
    /// D'Agostino–Pearson on the raw residuals.
    pub normality: TestOutcome<NormalityTest>,
}

/// An error when the fit's residuals are at rounding level (below 1e-9 of the response's root mean
/// square): any test of them would test noise.
fn check_not_exact(ols: &Ols, y: &[f64], what: &str) -> Result<(), StatsError> {
    if (ols.rss / y.len() as f64).sqrt() > 1e-9 * rms(y) {
        Ok(())
    } else {
        Err(StatsError::Degenerate {
            what: what.to_string(),
            why: "the fit is exact (its residuals are rounding noise)".into(),
        })
    }
}

/// Adds `extra` columns to the fit and tests them jointly.
fn added_columns_test(ols: &Ols, y: &[f64], added: &str, extra: Vec<Vec<f64>>) -> Result<FTest, StatsError> {
    check_not_exact(ols, y, &format!("the F test of {added}"))?;
    let q = extra.len();
    let mut cols = ols.cols.clone();
    cols.push(TermColumns {
        name: added.to_string(),
        kind: TermKind::Extra,
        labels: (0..q).map(|i| format!("{added}[{i}]")).collect(),
        columns: extra,
    });
    let order: Vec<usize> = (0..cols.len()).collect();
    let full = qr_fit(y, &cols, &order)?;
    let p = full.r.ncols();
    let ss_added: f64 = full.effects.iter().skip(p - q).map(|e| e * e).sum();
    let fitted = &full.q * &full.effects;
    let rss: f64 = y.iter().zip(fitted.iter()).map(|(a, b)| (a - b) * (a - b)).sum();
    let df_den = y.len() - p;
    let f = (ss_added / q as f64) / (rss / df_den as f64);
    Ok(FTest {
        added: added.to_string(),
        f,
        df_num: q,
        df_den,
        p: f_upper_p(f, q as f64, df_den as f64),
    })
}

/// (v − mean)/sd, or an error naming `what` when v does not vary beyond rounding: a spread below 1e-9
/// of `scale` (the root mean square of what v was computed from) is noise, and standardising it would
/// make a random column.
fn standardised(v: &[f64], scale: f64, what: &str) -> Result<Vec<f64>, StatsError> {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n).sqrt();
    if !(sd > 1e-9 * scale && sd.is_finite()) {
        return Err(StatsError::SingularDesign { term: what.to_string() });
    }
    Ok(v.iter().map(|x| (x - m) / sd).collect())
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

fn reset_of(ols: &Ols, y: &[f64], max_power: u32) -> Result<FTest, StatsError> {
    if max_power < 2 {
        return Err(StatsError::InvalidParameter {
            name: "max_power",
            value: max_power as f64,
            expected: ">= 2",
        });
    }
    let added = if max_power == 2 {
        "squared fitted values".to_string()
    } else {
        format!("fitted values to powers 2..{max_power}")
    };
    let u = standardised(&ols.fitted, rms(y), &added)?;
    let extra = (2..=max_power as i32)
        .map(|k| u.iter().map(|v| v.powi(k)).collect())
        .collect();
    added_columns_test(ols, y, &added, extra)
}

fn quadratic_of(ols: &Ols, y: &[f64], data: &Dataset, covariate: &str) -> Result<FTest, StatsError> {
    let is_term = ols
        .cols
        .iter()
        .any(|c| c.name == covariate && matches!(c.kind, TermKind::Covariate { .. }));
    let Some(c) = data.covariate(covariate).filter(|_| is_term) else {
        return Err(
            if data.covariate(covariate).is_some() || data.factor(covariate).is_some() {
                StatsError::NotATerm {
                    name: covariate.to_string(),
                    kind: "covariate",
                }
            } else {
                StatsError::UnknownVariable {
                    name: covariate.to_string(),
                }
            },
        );
    };
    let added = format!("{covariate}²");
    let u = standardised(&c.values, rms(&c.values), &added)?;
    added_columns_test(ols, y, &added, vec![u.iter().map(|v| v * v).collect()])
}

/// Ramsey's RESET: the fit of `data`'s response on `terms`, enlarged by the fitted values' powers
/// 2..=`max_power`, F-tested against it (statsmodels' `linear_reset(res, power=max_power, use_f=True)`).
/// A small p means the response curves with the fitted value: the linear model misses a trend.
pub fn reset_test(data: &Dataset, terms: &[&str], max_power: u32) -> Result<FTest, StatsError> {
    reset_of(&Ols::of(data, terms)?, data.response(), max_power)
}

/// The F test of a quadratic term in `covariate` (a covariate term of `terms`) added to the fit: does the
/// response curve with that covariate?
pub fn quadratic_test(data: &Dataset, terms: &[&str], covariate: &str) -> Result<FTest, StatsError> {
    quadratic_of(&Ols::of(data, terms)?, data.response(), data, covariate)
}

fn two_sided_normal(z: f64) -> f64 {
    erfc(z.abs() / std::f64::consts::SQRT_2)
}

/// D'Agostino–Pearson's K² test that `x` comes from a normal distribution, with the skewness and kurtosis
/// scores it is made of (formulas as scipy's `skewtest`, `kurtosistest`, `normaltest`). Needs at least 8
/// values and some spread.
pub fn normality_test(x: &[f64]) -> Result<NormalityTest, StatsError> {
    if x.len() < 8 {
        return Err(StatsError::TooFewObservations {
            what: "the D'Agostino–Pearson normality test".into(),
            have: x.len(),
            need: 8,
        });
    }
    let (m2, m3, m4) = central_moments(x)?;
    let mean_abs = x.iter().map(|v| v.abs()).sum::<f64>() / x.len() as f64;
    // Spread at rounding level is no distribution to test.
    let varies = m2 > (1e-14 * mean_abs).powi(2) && m4.is_finite();
    if !varies {
        return Err(StatsError::Degenerate {
            what: "the D'Agostino–Pearson normality test".into(),
            why: "the values are all equal".into(),
        });
    }
    let n = x.len() as f64;
    let g1 = m3 / m2.powf(1.5);
    let b2 = m4 / (m2 * m2);

    // Skewness (D'Agostino 1970).
    let y = g1 * ((n + 1.0) * (n + 3.0) / (6.0 * (n - 2.0))).sqrt();
    let beta2 =
        3.0 * (n * n + 27.0 * n - 70.0) * (n + 1.0) * (n + 3.0) / ((n - 2.0) * (n + 5.0) * (n + 7.0) * (n + 9.0));
    let w2 = -1.0 + (2.0 * (beta2 - 1.0)).sqrt();
    let delta = 1.0 / (0.5 * w2.ln()).sqrt();
    let a = (2.0 / (w2 - 1.0)).sqrt();
    let y = if y == 0.0 { 1.0 } else { y };
    let z_skewness = delta * (y / a).asinh();

    // Kurtosis (Anscombe & Glynn 1983).
    let e = 3.0 * (n - 1.0) / (n + 1.0);
    let var_b2 = 24.0 * n * (n - 2.0) * (n - 3.0) / ((n + 1.0) * (n + 1.0) * (n + 3.0) * (n + 5.0));
    let xk = (b2 - e) / var_b2.sqrt();
    let sqrt_beta1 = 6.0 * (n * n - 5.0 * n + 2.0) / ((n + 7.0) * (n + 9.0))
        * (6.0 * (n + 3.0) * (n + 5.0) / (n * (n - 2.0) * (n - 3.0))).sqrt();
    let aa = 6.0 + 8.0 / sqrt_beta1 * (2.0 / sqrt_beta1 + (1.0 + 4.0 / (sqrt_beta1 * sqrt_beta1)).sqrt());
    let term1 = 1.0 - 2.0 / (9.0 * aa);
    let denom = 1.0 + xk * (2.0 / (aa - 4.0)).sqrt();
    if denom == 0.0 {
        return Err(StatsError::Degenerate {
            what: "the kurtosis score".into(),
            why: "its transformation divides by zero for this kurtosis".into(),
        });
    }
    let term2 = denom.signum() * ((1.0 - 2.0 / aa) / denom.abs()).cbrt();
    let z_kurtosis = (term1 - term2) / (2.0 / (9.0 * aa)).sqrt();

    let k2 = z_skewness * z_skewness + z_kurtosis * z_kurtosis;
    Ok(NormalityTest {
        n: x.len(),
        skewness: g1,
        kurtosis: b2,
        z_skewness,
        z_kurtosis,
        k2,
        p: (-0.5 * k2).exp(),
        p_skewness: two_sided_normal(z_skewness),
        p_kurtosis: two_sided_normal(z_kurtosis),
        small_sample: x.len() < 20,
    })
}

pub(crate) fn tests_of(ols: &Ols, data: &Dataset, alpha: f64) -> Result<ResidualTests, StatsError> {
    check_alpha(alpha)?;
    let y = data.response();
    let quadratic = ols
        .cols
        .iter()
        .filter(|c| matches!(c.kind, TermKind::Covariate { .. }))
        .map(|c| CovariateCurvature {
            covariate: c.name.clone(),
            test: TestOutcome::from_result(quadratic_of(ols, y, data, &c.name)),
        })
        .collect();
    Ok(ResidualTests {
        alpha,
        reset: TestOutcome::from_result(reset_of(ols, y, 2)),
        quadratic,
        normality: TestOutcome::from_result(
            check_not_exact(ols, y, "the normality test of the residuals")
                .and_then(|()| normality_test(&ols.residuals)),
        ),
    })
}

/// RESET (squared fitted values), a quadratic term in every covariate, and D'Agostino–Pearson on the
/// residuals of the fit of `data`'s response on `terms`; a test that cannot run on these data (too few
/// observations, a design with no room for the added column) says why in its [`TestOutcome::NotRun`].
/// `alpha` is the level [`ResidualTests::caption`] decides at.
pub fn residual_tests(data: &Dataset, terms: &[&str], alpha: f64) -> Result<ResidualTests, StatsError> {
    tests_of(&Ols::of(data, terms)?, data, alpha)
}

fn f_text(t: &FTest) -> String {
    format!("F = {}, {}", stat_text(t.f), p_text(t.p))
}

impl ResidualTests {
    /// One plain sentence saying what the tests found, for the caption of a residual plot, e.g.
    /// "Residuals curve with the fitted value (RESET F = 14.2, p < 0.001): the linear model misses a
    /// trend; residuals are consistent with a normal distribution (D'Agostino–Pearson K² = 1.31,
    /// p = 0.519)." Decisions are at `alpha`, each test on its own (no multiplicity correction).
    pub fn caption(&self) -> String {
        let reset = self.reset.ran();
        let quad: Vec<(&str, &FTest)> = self
            .quadratic
            .iter()
            .filter_map(|c| c.test.ran().map(|t| (c.covariate.as_str(), t)))
            .collect();
        let sig = |t: &FTest| t.p < self.alpha;
        let mut curved = Vec::new();
        if let Some(t) = reset.filter(|t| sig(t)) {
            curved.push(format!("the fitted value (RESET {})", f_text(t)));
        }
        for (name, t) in quad.iter().filter(|(_, t)| sig(t)) {
            curved.push(format!("{name} (quadratic term {})", f_text(t)));
        }
        let curvature = if !curved.is_empty() {
            format!(
                "Residuals curve with {}: the linear model misses a trend",
                curved.join(" and with ")
            )
        } else {
            let mut ran = Vec::new();
            if let Some(t) = reset {
                ran.push(format!("RESET {}", f_text(t)));
            }
            for (name, t) in &quad {
                ran.push(format!("quadratic in {name} {}", f_text(t)));
            }
            if ran.is_empty() {
                let why = match &self.reset {
                    TestOutcome::NotRun { reason } => reason.clone(),
                    TestOutcome::Ran(_) => String::new(),
                };
                format!("Curvature not tested ({why})")
            } else {
                format!("No curvature detected ({})", ran.join("; "))
            }
        };
        let normality = match &self.normality {
            TestOutcome::Ran(t) => {
                let stat = format!("D'Agostino–Pearson K² = {}, {}", stat_text(t.k2), p_text(t.p));
                let rough = if t.small_sample {
                    ", approximate with fewer than 20 residuals"
                } else {
                    ""
                };
                if t.p < self.alpha {
                    let mut how = Vec::new();
                    if t.p_skewness < self.alpha {
                        how.push(if t.z_skewness > 0.0 {
                            "skewed right"
                        } else {
                            "skewed left"
                        });
                    }
                    if t.p_kurtosis < self.alpha {
                        how.push(if t.z_kurtosis > 0.0 {
                            "heavy tails"
                        } else {
                            "light tails"
                        });
                    }
                    let how = if how.is_empty() {
                        String::new()
                    } else {
                        format!(": {}", how.join(", "))
                    };
                    format!("residuals are not normal ({stat}{rough}){how}")
                } else {
                    format!("residuals are consistent with a normal distribution ({stat}{rough})")
                }
            }
            TestOutcome::NotRun { reason } => format!("normality not tested ({reason})"),
        };
        format!("{curvature}; {normality}.")
    }
}
