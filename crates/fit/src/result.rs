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

/// Smallest eigenvalue of the equilibrated `JᵀJ`, relative to its largest, of a determined set of
/// parameters (below it a direction of the parameters moves no residual at the Jacobian's resolution).
const MIN_EIGEN_RATIO: f64 = 1e-12;

/// `(JᵀJ)⁻¹` over the parameters the residuals determine, and for each parameter `None` (determined) or why
/// not. A parameter whose Jacobian column is zero, or that carries most of a direction of the parameters
/// the residuals do not see (the smallest eigenvector of the equilibrated `JᵀJ`, dropped one at a time
/// until the rest is well conditioned), is left out; the returned matrix is full size with its rows and
/// columns NaN. `None` when no parameter is determined.
pub fn identified_inverse(jac: &DMatrix<f64>) -> (Option<DMatrix<f64>>, Vec<Option<String>>) {
    let p = jac.ncols();
    let a = jac.transpose() * jac;
    let mut why: Vec<Option<String>> = (0..p)
        .map(|j| {
            let d = a[(j, j)];
            (!(d.is_finite() && d > 0.0)).then(|| "no residual depends on it".to_string())
        })
        .collect();
    loop {
        let keep: Vec<usize> = (0..p).filter(|&j| why[j].is_none()).collect();
        if keep.is_empty() {
            return (None, why);
        }
        let sub = DMatrix::from_fn(jac.nrows(), keep.len(), |i, k| jac[(i, keep[k])]);
        if let Some(inv) = normal_inverse(&sub) {
            let mut full = DMatrix::from_element(p, p, f64::NAN);
            for (x, &i) in keep.iter().enumerate() {
                for (y, &j) in keep.iter().enumerate() {
                    full[(i, j)] = inv[(x, y)];
                }
            }
            return (Some(full), why);
        }
        // The direction the residuals do not see: drop the parameter that carries most of it.
        let sa = sub.transpose() * &sub;
        let d: Vec<f64> = (0..keep.len()).map(|j| sa[(j, j)].sqrt()).collect();
        let scaled = DMatrix::from_fn(keep.len(), keep.len(), |i, j| sa[(i, j)] / (d[i] * d[j]));
        let eig = scaled.symmetric_eigen();
        let Some(low) = (0..keep.len()).min_by(|&x, &y| eig.eigenvalues[x].total_cmp(&eig.eigenvalues[y])) else {
            return (None, why);
        };
        let v = eig.eigenvectors.column(low);
        let Some(worst) = (0..keep.len()).max_by(|&x, &y| v[x].abs().total_cmp(&v[y].abs())) else {
            return (None, why);
        };
        let partners: Vec<String> = (0..keep.len())
            .filter(|&k| k != worst && v[k].abs() > 0.1)
            .map(|k| format!("#{}", keep[k]))
            .collect();
        why[keep[worst]] = Some(if partners.is_empty() {
            "the residuals hardly depend on it".to_string()
        } else {
            format!("it moves the residuals only as parameters {} do", partners.join(", "))
        });
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
    if min.is_nan() || min <= MIN_EIGEN_RATIO * max {
        return None;
    }
    let inv = scaled.cholesky()?.inverse();
    Some(DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| {
        inv[(i, j)] / (d[i] * d[j])
    }))
}

/// The cluster-robust (sandwich) covariance with each shot a cluster: `(JᵀJ)⁻¹ (Σ_s J_sᵀ r_s r_sᵀ J_s) (JᵀJ)⁻¹`,
/// times `S/(S − p)` for S shots; `None` with fewer than p + 2 shots, where it is not worth having.
/// `why` with the parameter numbers `#j` of [`identified_inverse`] replaced by the parameters' names.
fn name_partners(why: &str, problem: &Problem) -> String {
    let mut s = why.to_string();
    // Highest index first, so `#1` does not rewrite the start of `#12`.
    for (j, fp) in problem.params().iter().enumerate().rev() {
        s = s.replace(&format!("#{j}"), &fp.name);
    }
    s
}

/// The rows and columns of parameters that are not determined (NaN in `inv`) stay NaN.
fn cluster_robust(inv: &DMatrix<f64>, out: &SolverOutcome, problem: &Problem) -> Option<DMatrix<f64>> {
    let jac = out.jacobian.as_ref()?;
    let determined = (0..inv.nrows()).filter(|&j| inv[(j, j)].is_finite()).count();
    let p = inv.nrows();
    let shots = problem.shots();
    if shots.len() < determined + 2 || jac.nrows() != out.residuals.len() {
        return None;
    }
    let nan_rows: Vec<bool> = (0..p).map(|j| !inv[(j, j)].is_finite()).collect();
    let inv = inv.map(|v| if v.is_finite() { v } else { 0.0 });
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
    let robust = &inv * meat * &inv * (s / (s - determined as f64));
    Some(DMatrix::from_fn(p, p, |i, j| {
        if nan_rows[i] || nan_rows[j] {
            f64::NAN
        } else {
            robust[(i, j)]
        }
    }))
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
    let (inverse, mut not_identified) = match out.jacobian.as_ref() {
        Some(jac) => identified_inverse(jac),
        None => (None, vec![None; p]),
    };
    let cov = inverse.map(|c| {
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
                interval: se.map(|s| [value - t_quantile * s, value + t_quantile * s]),
                bounds: [fp.min, fp.max],
                at_bound: value <= fp.min || value >= fp.max,
                not_identified: not_identified[j].take().map(|w| name_partners(&w, problem)),
            }
        })
        .collect();
    let correlation = cov
        .as_ref()
        .map(|c| {
            (0..p)
                .map(|i| {
                    (0..p)
                        .map(|j| {
                            // A parameter that is not determined is uncorrelated by convention (JSON has
                            // no NaN).
                            let r = c[(i, j)] / (c[(i, i)] * c[(j, j)]).sqrt();
                            if r.is_finite() { r } else { f64::from(u8::from(i == j)) }
                        })
                        .collect()
                })
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A Jacobian of `rows` residuals whose columns are smooth, independent functions.
    fn independent(rows: usize, cols: usize) -> DMatrix<f64> {
        DMatrix::from_fn(rows, cols, |i, j| {
            let t = i as f64 / rows as f64;
            t.powi(j as i32) * (1.0 + 0.3 * (7.0 * t + j as f64).sin())
        })
    }

    #[test]
    fn a_zero_column_is_not_identified_and_the_others_keep_their_errors() {
        let jac = independent(40, 3);
        let mut with_zero = DMatrix::zeros(40, 4);
        for j in 0..3 {
            with_zero.set_column(if j < 2 { j } else { 3 }, &jac.column(j));
        }
        let (inv, why) = identified_inverse(&with_zero);
        let inv = inv.unwrap();
        assert_eq!(
            why.iter().map(Option::is_some).collect::<Vec<_>>(),
            [false, false, true, false]
        );
        assert!(why[2].as_deref().unwrap().contains("no residual"));
        let direct = normal_inverse(&jac).unwrap();
        for (a, x) in [(0, 0), (1, 1), (3, 2)] {
            for (b, y) in [(0, 0), (1, 1), (3, 2)] {
                assert!((inv[(a, b)] - direct[(x, y)]).abs() <= 1e-9 * direct[(x, y)].abs().max(1e-12));
            }
        }
        assert!(inv[(2, 2)].is_nan() && inv[(0, 2)].is_nan());
        // With every column determined, nothing is flagged and the inverse is `normal_inverse`'s.
        let (all, why) = identified_inverse(&jac);
        assert!(why.iter().all(Option::is_none));
        assert!((all.unwrap() - direct).abs().max() < 1e-9);
    }

    #[test]
    fn a_column_that_copies_another_is_not_identified_and_names_its_partner() {
        let jac = independent(40, 2);
        let mut dup = DMatrix::zeros(40, 3);
        dup.set_column(0, &jac.column(0));
        dup.set_column(1, &jac.column(1));
        dup.set_column(2, &(jac.column(1) * 3.0));
        let (inv, why) = identified_inverse(&dup);
        assert!(inv.is_some());
        let flagged: Vec<usize> = (0..3).filter(|&j| why[j].is_some()).collect();
        assert_eq!(flagged.len(), 1, "{why:?}");
        let other = if flagged[0] == 1 { "#2" } else { "#1" };
        assert!(why[flagged[0]].as_deref().unwrap().contains(other), "{why:?}");
        assert!(why[0].is_none());
    }

    proptest! {
        /// Zeroing any set of columns flags exactly those, and never all the rest.
        #[test]
        fn zeroed_columns_are_exactly_the_flagged_ones(mask in prop::collection::vec(any::<bool>(), 4)) {
            let mut jac = independent(30, 4);
            for (j, zero) in mask.iter().enumerate() {
                if *zero {
                    jac.set_column(j, &nalgebra::DVector::zeros(30));
                }
            }
            let (inv, why) = identified_inverse(&jac);
            for (j, zero) in mask.iter().enumerate() {
                prop_assert_eq!(why[j].is_some(), *zero);
            }
            prop_assert_eq!(inv.is_some(), mask.iter().any(|z| !z));
        }
    }
}
