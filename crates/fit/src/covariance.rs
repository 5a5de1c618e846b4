//! The parameters' covariance after a fit: `(JᵀJ)⁻¹` over the parameters the residuals determine, scaled by
//! the reduced objective and widened to the cluster-robust one with each shot a cluster. One path, used by
//! the fit's result and by the missing-effect search's fits alike.

use crate::Problem;
use crate::solver::SolverOutcome;
use nalgebra::{DMatrix, DVector};
use statrs::distribution::{ContinuousCDF, StudentsT};

/// The covariance of a solver outcome's parameters and what goes with it.
#[derive(Debug, Clone, PartialEq)]
pub struct Covariance {
    /// Degrees of freedom ν = n − p (n the frames' residuals, two per frame; p the free parameters and,
    /// when the problem fits them, one surface level per shot).
    pub dof: usize,
    /// Factor applied to `(JᵀJ)⁻¹`: max(1, the minimised objective over `dof`).
    pub scale: f64,
    /// Student t quantile of the intervals at the requested confidence: on S − 1 degrees of freedom for S
    /// shots when the cluster-robust variance is available (the shots are the independent units), else on
    /// ν.
    pub t_quantile: f64,
    /// The covariance, in the parameters' units squared; rows and columns of a parameter that is not
    /// determined are NaN. `None` without a Jacobian or when no parameter is determined.
    pub matrix: Option<DMatrix<f64>>,
    /// Per parameter: `None` when the residuals determine it, else why not (parameters named `#j`, see
    /// [`identified_inverse`]).
    pub not_identified: Vec<Option<String>>,
}

impl Covariance {
    /// Standard error of parameter `j`, in its unit; `None` when it is not determined.
    pub fn std_error(&self, j: usize) -> Option<f64> {
        self.matrix.as_ref().map(|c| c[(j, j)].sqrt()).filter(|s| s.is_finite())
    }

    /// The interval `value ± t·se` of parameter `j` at `value`; `None` when it is not determined.
    pub fn interval(&self, j: usize, value: f64) -> Option<[f64; 2]> {
        self.std_error(j)
            .map(|s| [value - self.t_quantile * s, value + self.t_quantile * s])
    }
}

/// The covariance of `out`'s parameters on `problem` (`out` from minimising `problem`'s residuals, or residuals
/// laid out as its: each shot's frames in order, then any per-shot prior terms): the classical
/// `(JᵀJ)⁻¹·max(1, cost/ν)` over the determined parameters, each variance raised to the cluster-robust one
/// when that is larger (residuals within a shot share systematic errors, the track's bias in contact, the
/// scale, so the shots, not the frames, are the independent units). `confidence` sets [`Covariance::t_quantile`].
pub fn covariance(problem: &Problem, out: &SolverOutcome, confidence: f64) -> Covariance {
    let n = problem.n_residuals();
    let p = problem.params().len();
    let dof = n
        .saturating_sub(p + problem.nuisance_per_shot() * problem.shots().len())
        .max(1);
    // Scaled by the objective the solver minimised (with surface levels, the frames' χ² plus each level's
    // prior term).
    let scale = (out.cost / dof as f64).max(1.0);
    let (inverse, not_identified) = match out.jacobian.as_ref() {
        Some(jac) => identified_inverse(jac),
        None => (None, vec![None; p]),
    };
    let robust = inverse.as_ref().and_then(|c| cluster_robust(c, out, problem));
    // The shots are the independent units: with the cluster-robust variance the interval takes Student's t
    // on S − 1 degrees of freedom (S shots), not on the frames' n − p.
    let t_dof = match robust {
        Some(_) => problem.shots().len().saturating_sub(1).max(1),
        None => dof,
    };
    let t_quantile = StudentsT::new(0.0, 1.0, t_dof as f64)
        .map(|t| t.inverse_cdf(0.5 + confidence / 2.0))
        .unwrap_or(f64::NAN);
    let matrix = inverse.map(|c| {
        let classical = &c * scale;
        match robust {
            // The larger of the two variances is kept.
            Some(robust) => DMatrix::from_fn(c.nrows(), c.ncols(), |i, j| {
                let k = (robust[(i, i)] / classical[(i, i)]).max(1.0).sqrt()
                    * (robust[(j, j)] / classical[(j, j)]).max(1.0).sqrt();
                classical[(i, j)] * if k.is_finite() { k } else { 1.0 }
            }),
            None => classical,
        }
    });
    Covariance {
        dof,
        scale,
        t_quantile,
        matrix,
        not_identified,
    }
}

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

/// The cluster-robust covariance with each shot a cluster, by the cluster jackknife (CR3): `(S − 1)/S ·
/// Σ_s δ_s δ_sᵀ` for S shots, `δ_s = (JᵀJ − J_sᵀJ_s)⁻¹ J_sᵀ r_s` the parameters' move when shot s is left
/// out (one Gauss–Newton step from the fit). With a dozen shots each one's leverage on the parameters is
/// large, and the plain sandwich `(JᵀJ)⁻¹ (Σ_s J_sᵀ r_s r_sᵀ J_s) (JᵀJ)⁻¹` (CR1) sees every shot's residual
/// after the fit has already bent towards that shot, so it understates the variance; the jackknife does
/// not (Bell and McCaffrey 2002; MacKinnon, Nielsen and Webb 2023; figures in `docs/fit.md`).
/// Falls back to CR1 (times `S/(S − p)`) when leaving some shot out leaves a parameter undetermined (that
/// shot alone determines it). `None` with fewer than p + 2 shots, where neither is worth having. The rows
/// and columns of parameters that are not determined (NaN in `inv`) stay NaN.
fn cluster_robust(inv: &DMatrix<f64>, out: &SolverOutcome, problem: &Problem) -> Option<DMatrix<f64>> {
    let jac = out.jacobian.as_ref()?;
    let p = inv.nrows();
    let keep: Vec<usize> = (0..p).filter(|&j| inv[(j, j)].is_finite()).collect();
    let shots = problem.shots();
    if shots.len() < keep.len() + 2 || jac.nrows() != out.residuals.len() {
        return None;
    }
    let q = keep.len();
    let kept = DMatrix::from_fn(jac.nrows(), q, |k, c| jac[(k, keep[c])]);
    let rows: Vec<usize> = shots.iter().map(|shot| 2 * shot.frames.len()).collect();
    let reduced = cluster_jackknife(&kept, &out.residuals, &rows).unwrap_or_else(|| {
        let inv_kept = DMatrix::from_fn(q, q, |i, j| inv[(keep[i], keep[j])]);
        let s = shots.len() as f64;
        let meat = cluster_scores(&kept, &out.residuals, &rows)
            .iter()
            .fold(DMatrix::zeros(q, q), |m, (score, _)| m + score * score.transpose());
        &inv_kept * meat * &inv_kept * (s / (s - q as f64))
    });
    let mut full = DMatrix::from_element(p, p, f64::NAN);
    for (x, &i) in keep.iter().enumerate() {
        for (y, &j) in keep.iter().enumerate() {
            full[(i, j)] = reduced[(x, y)];
        }
    }
    Some(full)
}

/// Per cluster (`rows[s]` consecutive rows of `jac` each; rows after the last cluster, such as prior
/// terms, belong to none): its score `J_sᵀ r_s` and its share `J_sᵀ J_s` of the normal matrix.
fn cluster_scores(jac: &DMatrix<f64>, residuals: &[f64], rows: &[usize]) -> Vec<(DVector<f64>, DMatrix<f64>)> {
    let mut at = 0;
    rows.iter()
        .map(|&n| {
            let js = jac.rows(at, n);
            let rs = DVector::from_column_slice(&residuals[at..at + n]);
            at += n;
            (js.transpose() * rs, js.transpose() * js)
        })
        .collect()
}

/// The cluster jackknife covariance `(S − 1)/S · Σ_s δ_s δ_sᵀ` of a least-squares fit with Jacobian `jac`
/// and residuals `residuals` at its optimum, `δ_s = (JᵀJ − J_sᵀJ_s)⁻¹ J_sᵀ r_s` (for a linear model, exactly
/// the estimate's move when cluster s is left out). Cost: one p×p Cholesky factorisation per cluster.
/// `None` when leaving some cluster out leaves the normal matrix singular.
fn cluster_jackknife(jac: &DMatrix<f64>, residuals: &[f64], rows: &[usize]) -> Option<DMatrix<f64>> {
    let q = jac.ncols();
    let per_cluster = cluster_scores(jac, residuals, rows);
    let normal: DMatrix<f64> = per_cluster.iter().fold(DMatrix::zeros(q, q), |a, (_, n)| a + n);
    let s = rows.len() as f64;
    let sum = per_cluster.iter().try_fold(DMatrix::zeros(q, q), |acc, (score, own)| {
        let left = &normal - own;
        // Equilibrated, so the factorisation's success is about the parameters' correlation, not units.
        let d: Vec<f64> = (0..q).map(|j| left[(j, j)].sqrt()).collect();
        if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return None;
        }
        let scaled = DMatrix::from_fn(q, q, |i, j| left[(i, j)] / (d[i] * d[j]));
        let solved = scaled.cholesky()?.solve(&DVector::from_fn(q, |i, _| score[i] / d[i]));
        let delta = DVector::from_fn(q, |i, _| solved[i] / d[i]);
        Some(acc + &delta * delta.transpose())
    })?;
    Some(sum * ((s - 1.0) / s))
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

    /// For a linear model one Gauss–Newton step is the exact refit, so the jackknife must equal refitting
    /// with each cluster left out: `(S − 1)/S · Σ_s (β̂_(−s) − β̂)(β̂_(−s) − β̂)ᵀ`.
    #[test]
    fn the_cluster_jackknife_is_the_leave_one_cluster_out_refit_of_a_linear_model() {
        let rows = [7, 9, 6, 8, 10, 7, 9];
        let n: usize = rows.iter().sum();
        let x = independent(n, 3);
        let mut rng = bouncelab_testkit::Rng::new(11);
        // Errors shared within a cluster plus independent ones: what the jackknife is for.
        let mut y = DVector::zeros(n);
        let mut at = 0;
        for &m in &rows {
            let shared = rng.normal();
            for k in at..at + m {
                y[k] = 1.0 + 2.0 * x[(k, 1)] + 0.5 * shared + 0.1 * rng.normal();
            }
            at += m;
        }
        let fit =
            |x: &DMatrix<f64>, y: &DVector<f64>| (x.transpose() * x).cholesky().unwrap().solve(&(x.transpose() * y));
        let beta = fit(&x, &y);
        let residuals: Vec<f64> = (&x * &beta - &y).iter().copied().collect();
        let got = cluster_jackknife(&x, &residuals, &rows).unwrap();
        let mut want = DMatrix::zeros(3, 3);
        let mut at = 0;
        for &m in &rows {
            let keep: Vec<usize> = (0..n).filter(|k| !(at..at + m).contains(k)).collect();
            let xs = x.select_rows(&keep);
            let ys = DVector::from_iterator(keep.len(), keep.iter().map(|&k| y[k]));
            let d = fit(&xs, &ys) - &beta;
            want += &d * d.transpose();
            at += m;
        }
        want *= (rows.len() as f64 - 1.0) / rows.len() as f64;
        for i in 0..3 {
            for j in 0..3 {
                let scale = (want[(i, i)] * want[(j, j)]).sqrt();
                assert!(
                    (got[(i, j)] - want[(i, j)]).abs() <= 1e-9 * scale,
                    "({i}, {j}): {} vs {}",
                    got[(i, j)],
                    want[(i, j)]
                );
            }
        }
    }

    /// A cluster that alone determines a parameter leaves the others unable to: no jackknife.
    #[test]
    fn a_cluster_that_alone_determines_a_parameter_gives_no_jackknife() {
        let rows = [5, 5, 5];
        let mut x = independent(15, 2);
        for k in 5..15 {
            x[(k, 1)] = 0.0;
        }
        let residuals = vec![0.1; 15];
        assert!(cluster_jackknife(&x, &residuals, &rows).is_none());
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
