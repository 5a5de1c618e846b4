//! Residual diagnostics of a linear fit: studentized residuals, normal probability plot, moments.

use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, Normal};

use crate::{LinearFit, StatsError};

/// One point of a normal probability plot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NormalPlotPoint {
    /// Index of the observation this residual belongs to.
    pub observation: usize,
    /// The residual (sorted ascending along the plot), in the response's unit.
    pub residual: f64,
    /// Plotting position (i − 0.5)/n for the i-th smallest residual, i = 1..n (MATLAB `normplot`).
    pub probability: f64,
    /// Standard normal quantile Φ⁻¹(probability).
    pub normal_quantile: f64,
}

/// Diagnostics of a [`LinearFit`] (the paper's Figure 11).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diagnostics {
    /// Fitted values.
    pub fitted: Vec<f64>,
    /// Raw residuals.
    pub residuals: Vec<f64>,
    /// Hat-matrix diagonal.
    pub leverage: Vec<f64>,
    /// Internally studentized residuals e_i / (σ̂ √(1 − h_i)).
    pub studentized_internal: Vec<f64>,
    /// Externally studentized residuals e_i / (σ̂₍ᵢ₎ √(1 − h_i)), σ̂₍ᵢ₎ leaving observation i out.
    pub studentized_external: Vec<f64>,
    /// Normal probability plot of the raw residuals.
    pub normal_plot: Vec<NormalPlotPoint>,
    /// Skewness of the residuals, see [`skewness`].
    pub residual_skewness: f64,
    /// Kurtosis of the residuals, see [`kurtosis`] (normal = 3).
    pub residual_kurtosis: f64,
}

pub(crate) fn central_moments(x: &[f64]) -> Result<(f64, f64, f64), StatsError> {
    if x.len() < 2 {
        return Err(StatsError::TooFewObservations {
            what: "sample moments".into(),
            have: x.len(),
            need: 2,
        });
    }
    if let Some(row) = x.iter().position(|v| !v.is_finite()) {
        return Err(StatsError::NonFinite {
            field: "sample".into(),
            row,
        });
    }
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let m = |p: i32| x.iter().map(|v| (v - mean).powi(p)).sum::<f64>() / n;
    Ok((m(2), m(3), m(4)))
}

/// Biased sample skewness g₁ = m₃ / m₂^{3/2} with m_r = (1/n) Σ (x − x̄)^r (MATLAB `skewness(x)`,
/// scipy `skew(x, bias=True)`). NaN when all values are equal.
pub fn skewness(x: &[f64]) -> Result<f64, StatsError> {
    let (m2, m3, _) = central_moments(x)?;
    Ok(m3 / m2.powf(1.5))
}

/// Biased sample kurtosis m₄ / m₂², normal = 3 (MATLAB `kurtosis(x)`, scipy
/// `kurtosis(x, fisher=False, bias=True)`); the paper's 3.866 is of this kind. NaN when all values are
/// equal.
pub fn kurtosis(x: &[f64]) -> Result<f64, StatsError> {
    let (m2, _, m4) = central_moments(x)?;
    Ok(m4 / (m2 * m2))
}

/// Excess kurtosis, [`kurtosis`] − 3 (normal = 0).
pub fn excess_kurtosis(x: &[f64]) -> Result<f64, StatsError> {
    Ok(kurtosis(x)? - 3.0)
}

/// Normal probability plot points of `x`: sorted ascending, plotting position (i − 0.5)/n.
pub fn normal_plot(x: &[f64]) -> Vec<NormalPlotPoint> {
    let n = x.len();
    let mut idx: Vec<usize> = (0..n).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    let Ok(normal) = Normal::new(0.0, 1.0) else {
        return Vec::new();
    };
    idx.into_iter()
        .enumerate()
        .map(|(i, obs)| {
            let probability = (i as f64 + 0.5) / n as f64;
            NormalPlotPoint {
                observation: obs,
                residual: x[obs],
                probability,
                normal_quantile: normal.inverse_cdf(probability),
            }
        })
        .collect()
}

/// Studentized residuals, normal plot and residual moments of a fit.
pub fn diagnostics(fit: &LinearFit) -> Result<Diagnostics, StatsError> {
    let p = fit.n - fit.df_resid;
    if fit.df_resid < 2 {
        return Err(StatsError::TooFewObservations {
            what: "externally studentized residuals (need 2 residual df)".into(),
            have: fit.n,
            need: p + 2,
        });
    }
    let sigma2 = fit.mse();
    let dfr = fit.df_resid as f64;
    let internal: Vec<f64> = fit
        .residuals
        .iter()
        .zip(&fit.leverage)
        .map(|(e, h)| e / (sigma2 * (1.0 - h)).sqrt())
        .collect();
    // σ̂₍ᵢ₎² = (rss − e_i²/(1 − h_i)) / (df − 1)
    let external = fit
        .residuals
        .iter()
        .zip(&fit.leverage)
        .map(|(e, h)| {
            let s2 = (fit.rss - e * e / (1.0 - h)) / (dfr - 1.0);
            e / (s2 * (1.0 - h)).sqrt()
        })
        .collect();
    Ok(Diagnostics {
        fitted: fit.fitted.clone(),
        residuals: fit.residuals.clone(),
        leverage: fit.leverage.clone(),
        studentized_internal: internal,
        studentized_external: external,
        normal_plot: normal_plot(&fit.residuals),
        residual_skewness: skewness(&fit.residuals)?,
        residual_kurtosis: kurtosis(&fit.residuals)?,
    })
}
