//! The fit's result: parameters with intervals, goodness of fit, the paper's errors and the oblique
//! validation table; serialisable as `fit.json`.

use crate::solver::{SolverOutcome, Termination};
use crate::{FitError, Problem};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, StudentsT};

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedParam {
    /// `damping.b` or `clay:spring.k`.
    pub name: String,
    /// Effect name.
    pub effect: String,
    /// Parameter name.
    pub param: String,
    /// Surface of a per-surface value, `None` for a global one.
    pub surface: Option<String>,
    /// Starting value, in the parameter's unit.
    pub initial: f64,
    /// Fitted value, in the parameter's unit.
    pub value: f64,
    /// Standard error, same unit; `None` when the covariance is singular (the parameter is not determined).
    pub std_error: Option<f64>,
    /// Confidence interval `value ± t·se` at [`FitResult::confidence`]; `None` with `std_error`.
    pub interval: Option<[f64; 2]>,
    /// Bounds of the fit.
    pub bounds: [f64; 2],
    /// True if the value ended on a bound (its interval then means little).
    pub at_bound: bool,
}

/// Per-shot goodness of fit and outputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShotFit {
    /// Shot name.
    pub name: String,
    /// Surface.
    pub surface: String,
    /// Incline, degrees.
    pub incline_deg: f64,
    /// Frames fitted.
    pub frames: usize,
    /// RMS of the position residuals (x and y together), m.
    pub rms_m: f64,
    /// The shot's part of χ².
    pub chi2: f64,
    /// Simulated coefficient of restitution.
    pub cor_sim: f64,
    /// Measured coefficient of restitution, if given.
    pub cor_measured: Option<f64>,
    /// `|e_sim − e_meas| / e_meas`, %.
    pub cor_error_pct: Option<f64>,
    /// Simulated contact time, ms.
    pub contact_ms_sim: f64,
    /// The fitted height of the true surface in the measured frame, m (positive: above the surface line the
    /// tracker found), when surface levels are fitted.
    #[serde(default)]
    pub surface_offset_m: Option<f64>,
}

/// The paper's mean absolute error of the COR for one surface.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceError {
    /// Surface.
    pub surface: String,
    /// Shots with a measured COR.
    pub shots: usize,
    /// Mean over them of `|e_sim − e_meas| / e_meas`, %.
    pub mean_abs_error_pct: f64,
}

/// One row of the oblique validation (the paper's Figure 9): outgoing velocity, measured vs predicted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObliqueRow {
    /// Shot name.
    pub shot: String,
    /// Surface.
    pub surface: String,
    /// Incline, degrees.
    pub incline_deg: f64,
    /// Incoming velocity at touch (tangential, normal), m/s: the measured start carried to the surface by
    /// the simulation.
    pub v_in: [f64; 2],
    /// Measured outgoing velocity (tangential, normal), m/s.
    pub v_out_measured: [f64; 2],
    /// Simulated outgoing velocity at separation (tangential, normal), m/s.
    pub v_out_predicted: [f64; 2],
    /// `|predicted − measured| / |measured|` per component, %.
    pub error_pct: [f64; 2],
}

/// Everything a fit found; `fit.json` is its serde serialisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitResult {
    /// The model (its file).
    pub model: String,
    /// The fitted parameters, in the order of the parameter vector.
    pub parameters: Vec<FittedParam>,
    /// Correlation matrix of the parameters (rows in parameter order); empty when the covariance is
    /// singular.
    pub correlation: Vec<Vec<f64>>,
    /// Confidence level of the intervals (0.95).
    pub confidence: f64,
    /// Student t quantile used for the intervals (n − p degrees of freedom).
    pub t_quantile: f64,
    /// χ² = Σ ((pred − meas)/σ)² over both coordinates of every frame (the surface levels' prior terms,
    /// which the solver also minimises, are not part of it).
    pub chi2: f64,
    /// Degrees of freedom ν = n − p (n = 2 × frames; p the free parameters and, when fitted, one surface
    /// level per shot).
    pub dof: usize,
    /// The reduced χ², χ² / ν: the one definition the comparison, the terminal and the report use.
    pub reduced_chi2: f64,
    /// Factor applied to (JᵀJ)⁻¹: max(1, the minimised objective over `dof`), the reduced χ² plus the
    /// surface levels' prior terms when they are fitted.
    pub covariance_scale: f64,
    /// RMS of all position residuals (x and y), m.
    pub rms_m: f64,
    /// Per shot.
    pub shots: Vec<ShotFit>,
    /// The paper's mean absolute error: mean over shots with a measured COR of
    /// `|e_sim − e_meas| / e_meas`, %; `None` when no shot has one.
    pub mean_abs_cor_error_pct: Option<f64>,
    /// The same per surface.
    pub cor_error_by_surface: Vec<SurfaceError>,
    /// Oblique validation: shots with incline > 0 and measured outputs.
    pub oblique: Vec<ObliqueRow>,
    /// Why the solver stopped.
    pub termination: Termination,
    /// Solver iterations.
    pub iterations: usize,
    /// Evaluations of all shots (one simulation of every shot each).
    pub evaluations: usize,
}

impl FitResult {
    /// The parameter called `name` (`clay:spring.k`, `damping.b`).
    pub fn param(&self, name: &str) -> Option<&FittedParam> {
        self.parameters.iter().find(|p| p.name == name)
    }

    /// `fit.json` text (pretty-printed).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a fit result serialises")
    }
}

/// Inverts `JᵀJ` (symmetric positive definite when the parameters are determined), equilibrated so the
/// condition test is about the parameters' correlation; `None` when singular or ill-conditioned.
pub fn normal_inverse(jac: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let a = jac.transpose() * jac;
    // Equilibrate so the condition test is about the parameters' correlation, not their units.
    let d: Vec<f64> = (0..a.ncols()).map(|j| a[(j, j)].sqrt()).collect();
    if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return None;
    }
    let scaled = DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] / (d[i] * d[j]));
    let eig = scaled.clone().symmetric_eigen();
    let (min, max) = eig
        .eigenvalues
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    if min.is_nan() || min <= 1e-12 * max {
        return None;
    }
    let inv = scaled.cholesky()?.inverse();
    Some(DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| {
        inv[(i, j)] / (d[i] * d[j])
    }))
}

/// The cluster-robust (sandwich) covariance with each shot a cluster: `(JᵀJ)⁻¹ (Σ_s J_sᵀ r_s r_sᵀ J_s) (JᵀJ)⁻¹`,
/// times `S/(S − p)` for S shots; `None` with fewer than p + 2 shots, where it is not worth having.
fn cluster_robust(inv: &DMatrix<f64>, out: &SolverOutcome, problem: &Problem) -> Option<DMatrix<f64>> {
    let jac = out.jacobian.as_ref()?;
    let p = inv.nrows();
    let shots = problem.shots();
    if shots.len() < p + 2 || jac.nrows() != out.residuals.len() {
        return None;
    }
    let mut meat = DMatrix::<f64>::zeros(p, p);
    let mut row = 0;
    for shot in shots {
        let n = 2 * shot.frames.len();
        let mut score = nalgebra::DVector::<f64>::zeros(p);
        for k in row..row + n {
            for j in 0..p {
                score[j] += jac[(k, j)] * out.residuals[k];
            }
        }
        meat += &score * score.transpose();
        row += n;
    }
    let s = shots.len() as f64;
    Some(inv * meat * inv * (s / (s - p as f64)))
}

pub(crate) fn build(
    problem: &Problem,
    out: &SolverOutcome,
    model: &str,
    confidence: f64,
) -> Result<FitResult, FitError> {
    let sims = problem.simulate(&out.params)?;
    let n = problem.n_residuals();
    let p = problem.params().len();
    let dof = n
        .saturating_sub(p + problem.nuisance_per_shot() * problem.shots().len())
        .max(1);
    let offsets = problem.offsets();
    // The covariance is scaled by the objective the solver minimised (with surface levels, the frames'
    // χ² plus each level's prior term); the χ² reported below is the frames' alone, the one number the
    // comparison, the terminal and the report show.
    let covariance_scale = (out.cost / dof as f64).max(1.0);
    let t_quantile = StudentsT::new(0.0, 1.0, dof as f64)
        .map(|t| t.inverse_cdf(0.5 + confidence / 2.0))
        .unwrap_or(f64::NAN);
    let cov = out.jacobian.as_ref().and_then(normal_inverse).map(|c| {
        let classical = &c * covariance_scale;
        match cluster_robust(&c, out, problem) {
            // Residuals within a shot share systematic errors (the track's bias in contact, the scale), so
            // the shots, not the frames, are the independent units: the larger of the two variances is kept.
            Some(robust) => DMatrix::from_fn(c.nrows(), c.ncols(), |i, j| {
                let k = (robust[(i, i)] / classical[(i, i)]).max(1.0).sqrt()
                    * (robust[(j, j)] / classical[(j, j)]).max(1.0).sqrt();
                classical[(i, j)] * if k.is_finite() { k } else { 1.0 }
            }),
            None => classical,
        }
    });
    let parameters = problem
        .params()
        .iter()
        .enumerate()
        .map(|(j, fp)| {
            let value = out.params[j];
            let se = cov.as_ref().map(|c| c[(j, j)].sqrt()).filter(|s| s.is_finite());
            FittedParam {
                name: fp.name.clone(),
                effect: fp.effect.clone(),
                param: fp.param.clone(),
                surface: fp.surface.clone(),
                initial: fp.initial,
                value,
                std_error: se,
                interval: se.map(|s| [value - t_quantile * s, value + t_quantile * s]),
                bounds: [fp.min, fp.max],
                at_bound: value <= fp.min || value >= fp.max,
            }
        })
        .collect();
    let correlation = cov
        .as_ref()
        .map(|c| {
            (0..p)
                .map(|i| (0..p).map(|j| c[(i, j)] / (c[(i, i)] * c[(j, j)]).sqrt()).collect())
                .collect()
        })
        .unwrap_or_default();

    let mut shots = Vec::new();
    let mut oblique = Vec::new();
    let (mut sum_sq, mut count) = (0.0, 0usize);
    for ((shot, sim), offset) in problem.shots().iter().zip(&sims).zip(&offsets) {
        let (mut sq, mut c2) = (0.0, 0.0);
        for (f, s) in shot.frames.iter().zip(&sim.samples) {
            let (dx, dy) = (s.observed.x - f.x_m, s.observed.y - f.y_m);
            sq += dx * dx + dy * dy;
            c2 += (dx * dx + dy * dy) / (f.sigma_m * f.sigma_m);
        }
        sum_sq += sq;
        count += 2 * shot.frames.len();
        let imp = &sim.impact;
        let cor_measured = shot.measured.map(|m| m.cor);
        let incline_deg = shot.incline_rad.to_degrees();
        shots.push(ShotFit {
            name: shot.name.clone(),
            surface: shot.surface.clone(),
            incline_deg,
            frames: shot.frames.len(),
            rms_m: (sq / (2 * shot.frames.len()) as f64).sqrt(),
            chi2: c2,
            cor_sim: imp.restitution,
            cor_measured,
            cor_error_pct: cor_measured.map(|e| ((imp.restitution - e) / e).abs() * 100.0),
            contact_ms_sim: imp.contact_time() * 1e3,
            surface_offset_m: problem.surface_offsets().then_some(*offset),
        });
        if let Some(m) = shot.measured
            && shot.incline_rad > 0.0
        {
            let pred = [imp.state_out.vx, imp.state_out.vy];
            oblique.push(ObliqueRow {
                shot: shot.name.clone(),
                surface: shot.surface.clone(),
                incline_deg,
                v_in: [imp.state_in.vx, imp.state_in.vy],
                v_out_measured: m.v_out,
                v_out_predicted: pred,
                error_pct: [0, 1].map(|k| ((pred[k] - m.v_out[k]) / m.v_out[k]).abs() * 100.0),
            });
        }
    }
    let chi2: f64 = shots.iter().map(|s| s.chi2).sum();
    let reduced_chi2 = chi2 / dof as f64;
    let mean = |xs: &[f64]| xs.iter().sum::<f64>() / xs.len() as f64;
    let errs: Vec<f64> = shots.iter().filter_map(|s| s.cor_error_pct).collect();
    let mut surfaces: Vec<&str> = Vec::new();
    for s in &shots {
        if s.cor_error_pct.is_some() && !surfaces.contains(&s.surface.as_str()) {
            surfaces.push(&s.surface);
        }
    }
    let cor_error_by_surface = surfaces
        .iter()
        .map(|sf| {
            let e: Vec<f64> = shots
                .iter()
                .filter(|s| s.surface == *sf)
                .filter_map(|s| s.cor_error_pct)
                .collect();
            SurfaceError {
                surface: sf.to_string(),
                shots: e.len(),
                mean_abs_error_pct: mean(&e),
            }
        })
        .collect();
    Ok(FitResult {
        model: model.to_string(),
        parameters,
        correlation,
        confidence,
        t_quantile,
        chi2,
        dof,
        reduced_chi2,
        covariance_scale,
        rms_m: (sum_sq / count as f64).sqrt(),
        shots,
        mean_abs_cor_error_pct: (!errs.is_empty()).then(|| mean(&errs)),
        cor_error_by_surface,
        oblique,
        termination: out.termination.clone(),
        iterations: out.iterations,
        evaluations: out.evaluations,
    })
}
