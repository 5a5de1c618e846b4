//! The fit's result: parameters with intervals, goodness of fit, the paper's errors and the oblique
//! validation table; serialisable as `fit.json`.

use crate::covariance::{Covariance, covariance};
use crate::solver::{SolverOutcome, Termination};
use crate::{FitError, MeasuredShot, Problem};
use bouncelab_model::{Impact, Simulation};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

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
    /// Why the shots do not determine this parameter, `None` when they do. Set when no residual depends on
    /// it (Coulomb's μ with only normal impacts), when it moves the residuals only as other parameters do
    /// (then it has no standard error, and the others' are computed with it held), or when it is a
    /// magnitude (a range starting at ≥ 0) whose standard error exceeds half its value. Its `value` is
    /// then where the solver left it, not a measurement.
    #[serde(default)]
    pub not_identified: Option<String>,
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

/// Largest relative standard error of a magnitude (a parameter whose range starts at ≥ 0) that still counts
/// as determined: beyond it the 95 % interval spans from about zero to twice the value.
pub const MAX_RELATIVE_STD_ERROR: f64 = 0.5;

/// `why` with the parameter numbers `#j` of [`identified_inverse`] replaced by the parameters' names.
fn name_partners(why: &str, problem: &Problem) -> String {
    let mut s = why.to_string();
    // Highest index first, so `#1` does not rewrite the start of `#12`.
    for (j, fp) in problem.params().iter().enumerate().rev() {
        s = s.replace(&format!("#{j}"), &fp.name);
    }
    s
}

/// The result of `out` on `problem`: parameters with intervals, goodness of fit, per-shot outputs, the
/// paper's errors and the oblique table.
pub(crate) fn build(
    problem: &Problem,
    out: &SolverOutcome,
    model: &str,
    confidence: f64,
) -> Result<FitResult, FitError> {
    let sims = problem.simulate(&out.params)?;
    // The covariance is scaled by the objective the solver minimised (see [`covariance`]); the χ² reported
    // below is the frames' alone, the one number the comparison, the terminal and the report show.
    let cov = covariance(problem, out, confidence);
    let parameters = fitted_params(problem, out, &cov);
    let correlation = correlation(cov.matrix.as_ref(), problem.params().len());
    let fits = ShotFits::of(problem, &sims);
    let chi2: f64 = fits.shots.iter().map(|s| s.chi2).sum();
    let reduced_chi2 = chi2 / cov.dof as f64;
    let (mean_abs_cor_error_pct, cor_error_by_surface) = cor_errors(&fits.shots);
    Ok(FitResult {
        model: model.to_string(),
        parameters,
        correlation,
        confidence,
        t_quantile: cov.t_quantile,
        chi2,
        dof: cov.dof,
        reduced_chi2,
        covariance_scale: cov.scale,
        rms_m: fits.rms_m,
        shots: fits.shots,
        mean_abs_cor_error_pct,
        cor_error_by_surface,
        oblique: fits.oblique,
        termination: out.termination.clone(),
        iterations: out.iterations,
        evaluations: out.evaluations,
    })
}

/// Every free parameter with its value, standard error and interval from `cov`; a magnitude (a range
/// starting at ≥ 0) whose standard error exceeds [`MAX_RELATIVE_STD_ERROR`] of its value is marked not
/// identified.
fn fitted_params(problem: &Problem, out: &SolverOutcome, cov: &Covariance) -> Vec<FittedParam> {
    let mut not_identified = cov.not_identified.clone();
    problem
        .params()
        .iter()
        .enumerate()
        .map(|(j, fp)| {
            let value = out.params[j];
            let se = cov.std_error(j);
            if let Some(s) = se
                && fp.min >= 0.0
                && s > MAX_RELATIVE_STD_ERROR * value.abs()
            {
                not_identified[j] = Some(format!(
                    "its standard error {s:.3e} is more than {:.0} % of its value",
                    MAX_RELATIVE_STD_ERROR * 100.0
                ));
            }
            FittedParam {
                name: fp.name.clone(),
                effect: fp.effect.clone(),
                param: fp.param.clone(),
                surface: fp.surface.clone(),
                initial: fp.initial,
                value,
                std_error: se,
                interval: cov.interval(j, value),
                bounds: [fp.min, fp.max],
                at_bound: fp.at_bound(value),
                not_identified: not_identified[j].take().map(|w| name_partners(&w, problem)),
            }
        })
        .collect()
}

/// The correlation matrix of the `p` parameters (rows in parameter order); empty without a covariance.
fn correlation(cov: Option<&DMatrix<f64>>, p: usize) -> Vec<Vec<f64>> {
    cov.map(|c| {
        (0..p)
            .map(|i| {
                (0..p)
                    .map(|j| {
                        // A parameter that is not determined is uncorrelated by convention (JSON has no NaN).
                        let r = c[(i, j)] / (c[(i, i)] * c[(j, j)]).sqrt();
                        if r.is_finite() { r } else { f64::from(u8::from(i == j)) }
                    })
                    .collect()
            })
            .collect()
    })
    .unwrap_or_default()
}

/// Per-shot goodness of fit and outputs, the oblique rows, and the RMS of all position residuals.
struct ShotFits {
    shots: Vec<ShotFit>,
    oblique: Vec<ObliqueRow>,
    /// RMS of all position residuals (x and y), m.
    rms_m: f64,
}

impl ShotFits {
    /// Every shot of `problem` against its simulation in `sims` (shot order).
    fn of(problem: &Problem, sims: &[Simulation]) -> ShotFits {
        let offsets = problem.offsets();
        let mut shots = Vec::new();
        let mut oblique = Vec::new();
        let (mut sum_sq, mut count) = (0.0, 0usize);
        for ((shot, sim), offset) in problem.shots().iter().zip(sims).zip(&offsets) {
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
                oblique.push(oblique_row(shot, imp, m.v_out, incline_deg));
            }
        }
        ShotFits {
            shots,
            oblique,
            rms_m: (sum_sq / count as f64).sqrt(),
        }
    }
}

/// The oblique validation row of `shot`: its measured outgoing velocity `v_out` (tangential, normal; m/s)
/// against the simulated impact's.
fn oblique_row(shot: &MeasuredShot, imp: &Impact, v_out: [f64; 2], incline_deg: f64) -> ObliqueRow {
    let pred = [imp.state_out.vx, imp.state_out.vy];
    ObliqueRow {
        shot: shot.name.clone(),
        surface: shot.surface.clone(),
        incline_deg,
        v_in: [imp.state_in.vx, imp.state_in.vy],
        v_out_measured: v_out,
        v_out_predicted: pred,
        error_pct: [0, 1].map(|k| ((pred[k] - v_out[k]) / v_out[k]).abs() * 100.0),
    }
}

/// The paper's mean absolute COR error over the shots that have a measured COR (%, `None` when none has),
/// and the same per surface in order of first appearance.
fn cor_errors(shots: &[ShotFit]) -> (Option<f64>, Vec<SurfaceError>) {
    let mean = |xs: &[f64]| xs.iter().sum::<f64>() / xs.len() as f64;
    let errs: Vec<f64> = shots.iter().filter_map(|s| s.cor_error_pct).collect();
    let mut surfaces: Vec<&str> = Vec::new();
    for s in shots {
        if s.cor_error_pct.is_some() && !surfaces.contains(&s.surface.as_str()) {
            surfaces.push(&s.surface);
        }
    }
    let by_surface = surfaces
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
    ((!errs.is_empty()).then(|| mean(&errs)), by_surface)
}
