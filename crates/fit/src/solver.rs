//! A Levenberg–Marquardt solver for bounded least squares, argmin style: a problem trait, a solver that
//! reports every iteration to an [`IterationObserver`], and a [`Termination`] reason.

use crate::FitError;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::io::Write;

/// A least-squares problem: minimise `Σ rᵢ(p)²` over bounded parameters.
pub trait LeastSquares: Sync {
    /// Number of parameters.
    fn n_params(&self) -> usize;
    /// The residual vector at `p` (always the same length).
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, FitError>;
    /// Bounds of parameter `j` (inclusive); unbounded by default.
    fn bounds(&self, _j: usize) -> (f64, f64) {
        (f64::NEG_INFINITY, f64::INFINITY)
    }
    /// Typical size of parameter `j` (> 0): the solver works in `p / scale` and takes finite-difference
    /// steps relative to it.
    fn scale(&self, _j: usize) -> f64 {
        1.0
    }
    /// The residual vector at `p`, which differs from the point whose residuals are `base` only in
    /// parameter `j`: a problem whose parameter touches only some residuals (a per-surface parameter and
    /// that surface's shots) recomputes only those and copies the rest. By default, all of them.
    fn residuals_changing(&self, p: &[f64], _j: usize, _base: &[f64]) -> Result<Vec<f64>, FitError> {
        self.residuals(p)
    }
    /// The Jacobian `∂r/∂p` (in the parameters' own units) the solver's step from `p` uses, when the problem
    /// has a better one than finite differences of [`LeastSquares::residuals`]: a problem that profiles
    /// nuisances inside each evaluation returns the Jacobian with them held and projected out (variable
    /// projection), smooth where differences through the profile are not, and far cheaper. `p` is the
    /// point of the solver's last evaluation. `None` (the default): the solver differences the residuals.
    fn step_jacobian(&self, _solver: &LevenbergMarquardt, _p: &[f64]) -> Option<Result<DMatrix<f64>, FitError>> {
        None
    }
}

/// What the solver reports after each iteration (iteration 0 is the starting point).
#[derive(Debug, Clone, Copy)]
pub struct Iteration<'a> {
    /// Iteration number, 0 for the start.
    pub iteration: usize,
    /// Cost `Σ r²` (χ² for weighted residuals) at `params`.
    pub cost: f64,
    /// Current parameters, in their units.
    pub params: &'a [f64],
    /// Damping λ (dimensionless: it multiplies the diagonal of JᵀJ) to be used for the next step.
    pub lambda: f64,
}

/// Receives every iteration of a solver: a progress bar, a log, a test.
pub trait IterationObserver {
    /// Called once per iteration.
    fn observe(&mut self, it: &Iteration<'_>);
}

/// Ignores every iteration.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoObserver;

impl IterationObserver for NoObserver {
    fn observe(&mut self, _it: &Iteration<'_>) {}
}

/// Any closure taking an [`Iteration`] is an observer.
impl<F: FnMut(&Iteration<'_>)> IterationObserver for F {
    fn observe(&mut self, it: &Iteration<'_>) {
        self(it)
    }
}

/// Writes one line per iteration: `iter 3  cost 1.234e3  λ 1.0e-4  clay:spring.k=25650 …`.
#[derive(Debug)]
pub struct LogObserver<W: Write> {
    out: W,
    names: Vec<String>,
}

impl<W: Write> LogObserver<W> {
    /// A logger writing to `out`, naming the parameters with `names` (e.g. from [`crate::Problem::params`]).
    pub fn new(out: W, names: Vec<String>) -> Self {
        LogObserver { out, names }
    }

    /// The writer back.
    pub fn into_inner(self) -> W {
        self.out
    }
}

impl<W: Write> IterationObserver for LogObserver<W> {
    fn observe(&mut self, it: &Iteration<'_>) {
        let params = it
            .params
            .iter()
            .enumerate()
            .map(|(j, v)| match self.names.get(j) {
                Some(n) => format!("{n}={v:.6e}"),
                None => format!("p{j}={v:.6e}"),
            })
            .collect::<Vec<_>>()
            .join(" ");
        // A log that cannot be written is not a reason to stop a fit.
        let _ = writeln!(
            self.out,
            "iter {:3}  cost {:.6e}  λ {:.1e}  {params}",
            it.iteration, it.cost, it.lambda
        );
    }
}

/// Why the solver stopped.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Termination {
    /// The relative cost change of an accepted step fell below `ftol`.
    ConvergedCost,
    /// The scaled step fell below `xtol` (relative to the scaled parameters).
    ConvergedStep,
    /// `max_iterations` reached.
    MaxIterations,
    /// No step lowering the cost was found even with very strong damping (a minimum to the solver's
    /// resolution, or a parameter pressed against its bound).
    Stalled,
    /// A simulation failed at a trial point and no nearby point worked; the result is the last good point.
    SimulationFailed {
        /// The shot whose simulation failed.
        shot: String,
        /// Why.
        message: String,
    },
}

impl Termination {
    /// True for the two converged reasons.
    pub fn converged(&self) -> bool {
        matches!(self, Termination::ConvergedCost | Termination::ConvergedStep)
    }
}

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Termination::ConvergedCost => write!(f, "converged (relative cost change below tolerance)"),
            Termination::ConvergedStep => write!(f, "converged (step below tolerance)"),
            Termination::MaxIterations => write!(f, "stopped at the maximum number of iterations"),
            Termination::Stalled => write!(f, "stalled (no step lowers the cost)"),
            Termination::SimulationFailed { shot, message } => {
                write!(f, "stopped: the simulation of shot `{shot}` failed: {message}")
            }
        }
    }
}

/// Levenberg–Marquardt with a finite-difference Jacobian, parameter scaling and bounds by projection.
///
/// Works in scaled parameters `u = p / scale`. Each step solves `(A + λ·diag A) δ = −g` with `A = JᵀJ`,
/// `g = Jᵀr` (Marquardt's scaling, so λ is dimensionless), projects `u + δ` onto the bounds, and accepts
/// it if the cost falls; λ follows Nielsen's rule (`λ·max(1/3, 1 − (2ρ − 1)³)` on success with gain ratio
/// ρ, `λ·ν, ν·2` on failure). A trial point whose simulation fails counts as a failed step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevenbergMarquardt {
    /// Most iterations (accepted steps plus the final failed search).
    pub max_iterations: usize,
    /// Converged when an accepted step lowers the cost by less than `ftol · cost`.
    pub ftol: f64,
    /// Converged when the scaled step is below `xtol · (‖u‖ + xtol)`.
    pub xtol: f64,
    /// Finite-difference step relative to each parameter's scale (central differences, one-sided at a bound).
    pub fd_step: f64,
    /// How each iteration's Jacobian is differenced (see [`Differences`]). The Jacobian returned with the
    /// outcome, which the parameters' covariance comes from, is always central.
    pub step_differences: Differences,
    /// Whether the outcome carries the Jacobian at the result (2p + 1 more evaluations): `false` for a fit
    /// whose parameters alone are wanted, such as a cross-validation fold's.
    pub jacobian_at_end: bool,
    /// Starting damping λ.
    pub lambda_init: f64,
    /// Damping at which the search gives up (stalled).
    pub lambda_max: f64,
}

impl Default for LevenbergMarquardt {
    fn default() -> Self {
        LevenbergMarquardt {
            max_iterations: 100,
            ftol: 1e-10,
            xtol: 1e-9,
            fd_step: 1e-5,
            step_differences: Differences::Forward,
            jacobian_at_end: true,
            lambda_init: 1e-3,
            lambda_max: 1e12,
        }
    }
}

/// Finite differences for a Jacobian column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Differences {
    /// `(r(u + h) − r(u − h)) / 2h`: error O(h²), two evaluations per parameter.
    Central,
    /// `(r(u + h) − r(u)) / h` (backward at an upper bound): error O(h), one evaluation per parameter. With
    /// the default relative step of 1e-5 its error is of that order relative to the column, far below what
    /// changes a damped step's direction, for half the cost of [`Differences::Central`].
    Forward,
}

/// What the solver found.
#[derive(Debug, Clone)]
pub struct SolverOutcome {
    /// Best parameters, in their units.
    pub params: Vec<f64>,
    /// Residuals there.
    pub residuals: Vec<f64>,
    /// Cost `Σ r²` there.
    pub cost: f64,
    /// Jacobian `∂r/∂p` (unscaled, central differences) at `params`; `None` if it could not be evaluated or
    /// was not asked for ([`LevenbergMarquardt::jacobian_at_end`]).
    pub jacobian: Option<DMatrix<f64>>,
    /// Iterations done.
    pub iterations: usize,
    /// Residual evaluations (simulations of every shot) done.
    pub evaluations: usize,
    /// Why it stopped.
    pub termination: Termination,
}

struct Eval<'a, P: LeastSquares> {
    problem: &'a P,
    scale: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    count: usize,
}

impl<'a, P: LeastSquares> Eval<'a, P> {
    fn new(problem: &'a P) -> Self {
        let np = problem.n_params();
        let scale: Vec<f64> = (0..np)
            .map(|j| {
                let s = problem.scale(j);
                if s.is_finite() && s > 0.0 { s } else { 1.0 }
            })
            .collect();
        let lo: Vec<f64> = (0..np).map(|j| problem.bounds(j).0 / scale[j]).collect();
        let hi: Vec<f64> = (0..np).map(|j| problem.bounds(j).1 / scale[j]).collect();
        Eval {
            problem,
            scale,
            lo,
            hi,
            count: 0,
        }
    }

    fn params(&self, u: &[f64]) -> Vec<f64> {
        u.iter().zip(&self.scale).map(|(u, s)| u * s).collect()
    }

    fn residuals(&mut self, u: &[f64], n: Option<usize>) -> Result<DVector<f64>, FitError> {
        let r = self.problem.residuals(&self.params(u))?;
        self.check(r, n)
    }

    /// The residuals at `u`, which differs from the point of `base` only in coordinate `j`.
    fn residuals_changing(&mut self, u: &[f64], j: usize, base: &DVector<f64>) -> Result<DVector<f64>, FitError> {
        let r = self.problem.residuals_changing(&self.params(u), j, base.as_slice())?;
        self.check(r, Some(base.len()))
    }

    fn check(&mut self, r: Vec<f64>, n: Option<usize>) -> Result<DVector<f64>, FitError> {
        self.count += 1;
        if let Some(n) = n
            && r.len() != n
        {
            return Err(FitError::BadResiduals(format!("{} residuals, expected {n}", r.len())));
        }
        if let Some(i) = r.iter().position(|v| !v.is_finite()) {
            return Err(FitError::BadResiduals(format!("residual {i} is {}", r[i])));
        }
        Ok(DVector::from_vec(r))
    }

    /// Jacobian with respect to the scaled parameters.
    fn jacobian(
        &mut self,
        u: &[f64],
        r0: &DVector<f64>,
        h: f64,
        differences: Differences,
    ) -> Result<DMatrix<f64>, FitError> {
        let n = r0.len();
        let mut jac = DMatrix::zeros(n, u.len());
        for j in 0..u.len() {
            let (lo, hi) = (self.lo[j], self.hi[j]);
            let mut up = u.to_vec();
            let mut dn = u.to_vec();
            let central = differences == Differences::Central;
            let col = if central && u[j] + h <= hi && u[j] - h >= lo {
                up[j] += h;
                dn[j] -= h;
                (self.residuals_changing(&up, j, r0)? - self.residuals_changing(&dn, j, r0)?) / (2.0 * h)
            } else if u[j] + h <= hi {
                up[j] += h;
                (self.residuals_changing(&up, j, r0)? - r0) / h
            } else {
                dn[j] -= h;
                (r0 - self.residuals_changing(&dn, j, r0)?) / h
            };
            jac.set_column(j, &col);
        }
        Ok(jac)
    }

    /// [`Eval::jacobian`] back in the parameters' own units: ∂r/∂p = ∂r/∂u / scale.
    fn jacobian_unscaled(
        &mut self,
        u: &[f64],
        r0: &DVector<f64>,
        h: f64,
        differences: Differences,
    ) -> Result<DMatrix<f64>, FitError> {
        let mut j = self.jacobian(u, r0, h, differences)?;
        for (k, s) in self.scale.iter().enumerate() {
            j.column_mut(k).scale_mut(1.0 / s);
        }
        Ok(j)
    }

    /// The Jacobian of the step from `u`: the problem's own ([`LeastSquares::step_jacobian`], scaled to `u`)
    /// or finite differences.
    fn step_jacobian(
        &mut self,
        solver: &LevenbergMarquardt,
        u: &[f64],
        r0: &DVector<f64>,
    ) -> Result<DMatrix<f64>, FitError> {
        match self.problem.step_jacobian(solver, &self.params(u)) {
            Some(jac) => {
                let mut jac = jac?;
                if jac.shape() != (r0.len(), u.len()) {
                    return Err(FitError::BadResiduals(format!(
                        "a step Jacobian of {:?}, expected {:?}",
                        jac.shape(),
                        (r0.len(), u.len())
                    )));
                }
                for (k, s) in self.scale.iter().enumerate() {
                    jac.column_mut(k).scale_mut(*s);
                }
                Ok(jac)
            }
            None => self.jacobian(u, r0, solver.fd_step, solver.step_differences),
        }
    }
}

fn failure(e: &FitError) -> Option<Termination> {
    match e {
        FitError::Simulation { shot, source } => Some(Termination::SimulationFailed {
            shot: shot.clone(),
            message: source.to_string(),
        }),
        _ => None,
    }
}

impl LevenbergMarquardt {
    /// The finite-difference Jacobian `∂r/∂p` of `problem` at `p` (in the parameters' own units), as the
    /// solver computes it: central differences of `fd_step` relative to each parameter's scale, one-sided
    /// at a bound.
    pub fn jacobian_at<P: LeastSquares>(&self, problem: &P, p: &[f64]) -> Result<DMatrix<f64>, FitError> {
        self.jacobian_with(problem, p, Differences::Central)
    }

    /// [`LevenbergMarquardt::jacobian_at`] with the given differences (forward: p + 1 evaluations, as the
    /// solver's steps take them by default).
    pub fn jacobian_with<P: LeastSquares>(
        &self,
        problem: &P,
        p: &[f64],
        differences: Differences,
    ) -> Result<DMatrix<f64>, FitError> {
        let mut ev = Eval::new(problem);
        let u: Vec<f64> = p.iter().zip(&ev.scale).map(|(p, s)| p / s).collect();
        let r0 = ev.residuals(&u, None)?;
        ev.jacobian_unscaled(&u, &r0, self.fd_step, differences)
    }

    /// Minimises `problem` from `p0` (clamped into the bounds), reporting each iteration to `observer`.
    ///
    /// Errors only when the starting point itself cannot be evaluated (e.g. a shot's simulation fails
    /// there); a failure later ends the search at the last good point with
    /// [`Termination::SimulationFailed`].
    pub fn run<P: LeastSquares>(
        &self,
        problem: &P,
        p0: &[f64],
        observer: &mut dyn IterationObserver,
    ) -> Result<SolverOutcome, FitError> {
        let np = problem.n_params();
        assert_eq!(p0.len(), np, "starting point has the wrong length");
        let mut ev = Eval::new(problem);
        let mut u: Vec<f64> = p0.iter().zip(&ev.scale).map(|(p, s)| p / s).collect();
        project(&mut u, &ev.lo, &ev.hi);
        let r = ev.residuals(&u, None)?;
        let cost = r.norm_squared();
        let mut st = LmState {
            u,
            r,
            cost,
            lambda: self.lambda_init,
            nu: 2.0,
        };
        observer.observe(&Iteration {
            iteration: 0,
            cost: st.cost,
            params: &ev.params(&st.u),
            lambda: st.lambda,
        });
        let mut iterations = 0;
        let termination = loop {
            if iterations >= self.max_iterations {
                break Termination::MaxIterations;
            }
            iterations += 1;
            let jac = match ev.step_jacobian(self, &st.u, &st.r) {
                Ok(j) => j,
                Err(e) => break failure(&e).ok_or(e)?,
            };
            if let Some(t) = self.damped_step(&mut ev, &mut st, &jac, iterations, observer)? {
                break t;
            }
        };
        let jacobian = if self.jacobian_at_end {
            ev.jacobian_unscaled(&st.u, &st.r, self.fd_step, Differences::Central)
                .ok()
        } else {
            None
        };
        Ok(SolverOutcome {
            params: ev.params(&st.u),
            residuals: st.r.as_slice().to_vec(),
            cost: st.cost,
            jacobian,
            iterations,
            evaluations: ev.count,
            termination,
        })
    }

    /// One iteration's step from `st` with the Jacobian `jac` (of the scaled parameters): the damping is
    /// raised until a step lowers the cost (accepted, the damping lowered by the gain ratio) or the step is
    /// below the tolerance. `None` when a step was taken and the search goes on, else why it stops.
    fn damped_step<P: LeastSquares>(
        &self,
        ev: &mut Eval<'_, P>,
        st: &mut LmState,
        jac: &DMatrix<f64>,
        iteration: usize,
        observer: &mut dyn IterationObserver,
    ) -> Result<Option<Termination>, FitError> {
        let np = st.u.len();
        let n = st.r.len();
        let mut a = jac.transpose() * jac;
        let mut g = jac.transpose() * &st.r;
        // A parameter on a bound that the descent direction pushes outward is held there for this step: a
        // step solved with it free and then projected would go nowhere useful in the others either.
        for j in 0..np {
            let held = (st.u[j] <= ev.lo[j] && g[j] > 0.0) || (st.u[j] >= ev.hi[j] && g[j] < 0.0);
            if held {
                a.row_mut(j).fill(0.0);
                a.column_mut(j).fill(0.0);
                a[(j, j)] = 1.0;
                g[j] = 0.0;
            }
        }
        let diag: Vec<f64> = (0..np).map(|j| a[(j, j)].max(1e-12 * a.diagonal().max())).collect();
        let mut last_failure = None;
        loop {
            if st.lambda > self.lambda_max {
                return Ok(Some(last_failure.unwrap_or(Termination::Stalled)));
            }
            let mut m = a.clone();
            for j in 0..np {
                m[(j, j)] += st.lambda * diag[j];
            }
            let Some(chol) = m.cholesky() else {
                st.lambda *= st.nu;
                st.nu *= 2.0;
                continue;
            };
            let delta = chol.solve(&(-&g));
            let mut trial: Vec<f64> = st.u.iter().zip(delta.iter()).map(|(u, d)| u + d).collect();
            project(&mut trial, &ev.lo, &ev.hi);
            let step = DVector::from_iterator(np, trial.iter().zip(&st.u).map(|(t, u)| t - u));
            let predicted = -(2.0 * g.dot(&step) + (&a * &step).dot(&step));
            let unorm = DVector::from_column_slice(&st.u).norm();
            let tiny_step = step.norm() <= self.xtol * (unorm + self.xtol);
            let r_new = match ev.residuals(&trial, Some(n)) {
                Ok(r) => Some(r),
                Err(e) => {
                    last_failure = Some(failure(&e).ok_or(e)?);
                    None
                }
            };
            let new_cost = r_new.as_ref().map(|r| r.norm_squared()).unwrap_or(f64::INFINITY);
            if new_cost < st.cost && predicted > 0.0 {
                let rho = (st.cost - new_cost) / predicted;
                st.lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                st.nu = 2.0;
                let change = st.cost - new_cost;
                st.u = trial;
                st.r = r_new.expect("a lower cost has residuals");
                st.cost = new_cost;
                observer.observe(&Iteration {
                    iteration,
                    cost: st.cost,
                    params: &ev.params(&st.u),
                    lambda: st.lambda,
                });
                if change <= self.ftol * st.cost {
                    return Ok(Some(Termination::ConvergedCost));
                }
                if tiny_step {
                    return Ok(Some(Termination::ConvergedStep));
                }
                return Ok(None);
            }
            if tiny_step && r_new.is_some() {
                // The step is below the tolerance and does not help: we are at the minimum.
                observer.observe(&Iteration {
                    iteration,
                    cost: st.cost,
                    params: &ev.params(&st.u),
                    lambda: st.lambda,
                });
                return Ok(Some(Termination::ConvergedStep));
            }
            st.lambda *= st.nu;
            st.nu *= 2.0;
        }
    }
}

/// Where the solver stands: the scaled parameters, their residuals and cost, and the damping λ with its
/// growth factor ν.
struct LmState {
    u: Vec<f64>,
    r: DVector<f64>,
    cost: f64,
    lambda: f64,
    nu: f64,
}

/// Clamps each scaled parameter into its bounds.
fn project(u: &mut [f64], lo: &[f64], hi: &[f64]) {
    for j in 0..u.len() {
        u[j] = u[j].clamp(lo[j], hi[j]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_model::ModelError;

    /// y = a·exp(−t/τ) + c sampled without noise.
    struct Decay {
        t: Vec<f64>,
        y: Vec<f64>,
        bounds: [(f64, f64); 3],
    }

    impl Decay {
        fn new(truth: [f64; 3]) -> Decay {
            let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.05).collect();
            let y = t.iter().map(|t| truth[0] * (-t / truth[1]).exp() + truth[2]).collect();
            Decay {
                t,
                y,
                bounds: [(0.0, 100.0), (1e-3, 10.0), (-5.0, 5.0)],
            }
        }
    }

    impl LeastSquares for Decay {
        fn n_params(&self) -> usize {
            3
        }
        fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, FitError> {
            Ok(self
                .t
                .iter()
                .zip(&self.y)
                .map(|(t, y)| p[0] * (-t / p[1]).exp() + p[2] - y)
                .collect())
        }
        fn bounds(&self, j: usize) -> (f64, f64) {
            self.bounds[j]
        }
        fn scale(&self, j: usize) -> f64 {
            [10.0, 0.5, 1.0][j]
        }
    }

    #[test]
    fn finds_the_minimum_of_a_curve_fit() {
        let p = Decay::new([12.0, 0.4, 1.5]);
        let out = LevenbergMarquardt::default()
            .run(&p, &[6.0, 0.8, 0.5], &mut NoObserver)
            .unwrap();
        assert!(out.termination.converged(), "{}", out.termination);
        for (got, want) in out.params.iter().zip([12.0, 0.4, 1.5]) {
            assert!((got - want).abs() < 1e-6 * want, "{:?}", out.params);
        }
        assert!(out.jacobian.is_some());
    }

    /// Two fits' parameters agree within 1e-6 relative.
    fn assert_same_optimum(a: &[f64], b: &[f64]) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-6 * y.abs(), "{a:?} vs {b:?}");
        }
    }

    /// [`Decay`] with its exact Jacobian for the solver's steps, counting how often it is asked.
    struct ExactSteps {
        decay: Decay,
        asked: std::sync::atomic::AtomicUsize,
        shape: Option<(usize, usize)>,
    }

    impl LeastSquares for ExactSteps {
        fn n_params(&self) -> usize {
            3
        }
        fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, FitError> {
            self.decay.residuals(p)
        }
        fn bounds(&self, j: usize) -> (f64, f64) {
            self.decay.bounds(j)
        }
        fn scale(&self, j: usize) -> f64 {
            self.decay.scale(j)
        }
        fn step_jacobian(&self, _solver: &LevenbergMarquardt, p: &[f64]) -> Option<Result<DMatrix<f64>, FitError>> {
            self.asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let (rows, cols) = self.shape.unwrap_or((self.decay.t.len(), 3));
            Some(Ok(DMatrix::from_fn(rows, cols, |i, j| {
                let t = self.decay.t[i];
                let e = (-t / p[1]).exp();
                [e, p[0] * e * t / (p[1] * p[1]), 1.0][j]
            })))
        }
    }

    #[test]
    fn a_problem_s_own_step_jacobian_is_used_and_reaches_the_same_optimum() {
        let exact = ExactSteps {
            decay: Decay::new([12.0, 0.4, 1.5]),
            asked: 0.into(),
            shape: None,
        };
        let solver = LevenbergMarquardt::default();
        let start = [6.0, 0.8, 0.5];
        let own = solver.run(&exact, &start, &mut NoObserver).unwrap();
        let differenced = solver.run(&exact.decay, &start, &mut NoObserver).unwrap();
        assert!(own.termination.converged(), "{}", own.termination);
        assert_same_optimum(&own.params, &differenced.params);
        // One request per iteration, and no residual evaluation spent on differences for the steps (the
        // covariance Jacobian at the end still takes 2p).
        assert_eq!(exact.asked.load(std::sync::atomic::Ordering::Relaxed), own.iterations);
        assert!(
            own.evaluations < differenced.evaluations,
            "{} vs {}",
            own.evaluations,
            differenced.evaluations
        );
        // A Jacobian of the wrong shape is an error, not a panic.
        let wrong = ExactSteps {
            shape: Some((5, 3)),
            ..exact
        };
        assert!(matches!(
            solver.run(&wrong, &start, &mut NoObserver),
            Err(FitError::BadResiduals(_))
        ));
    }

    #[test]
    fn forward_and_central_steps_reach_one_optimum_and_the_same_covariance_jacobian() {
        // Noisy data, so the optimum is not the truth and the residuals there are not zero.
        let mut p = Decay::new([12.0, 0.4, 1.5]);
        let mut rng = bouncelab_testkit::Rng::new(3);
        for y in &mut p.y {
            *y += 0.05 * rng.normal();
        }
        let fit = |d: Differences| {
            let solver = LevenbergMarquardt {
                step_differences: d,
                ..LevenbergMarquardt::default()
            };
            solver.run(&p, &[6.0, 0.8, 0.5], &mut NoObserver).unwrap()
        };
        let (central, forward) = (fit(Differences::Central), fit(Differences::Forward));
        assert!(forward.termination.converged(), "{}", forward.termination);
        assert_same_optimum(&forward.params, &central.params);
        // Each forward Jacobian costs 3 evaluations, a central one 6.
        assert!(
            forward.evaluations < central.evaluations,
            "{} vs {}",
            forward.evaluations,
            central.evaluations
        );
        // The Jacobian returned for the covariance is central either way.
        let (jf, jc) = (forward.jacobian.unwrap(), central.jacobian.unwrap());
        assert!((jf - &jc).norm() < 1e-6 * jc.norm());
        let without = LevenbergMarquardt {
            jacobian_at_end: false,
            ..LevenbergMarquardt::default()
        }
        .run(&p, &[6.0, 0.8, 0.5], &mut NoObserver)
        .unwrap();
        assert!(without.jacobian.is_none() && without.evaluations + 6 == forward.evaluations);
    }

    #[test]
    fn bounds_hold_the_parameters() {
        // The best c is 1.5, but c ≤ 1 is imposed.
        let mut p = Decay::new([12.0, 0.4, 1.5]);
        p.bounds[2] = (-5.0, 1.0);
        let out = LevenbergMarquardt::default()
            .run(&p, &[5.0, 1.0, 0.0], &mut NoObserver)
            .unwrap();
        assert!(out.params[2] <= 1.0 && out.params[2] > 0.999, "{:?}", out.params);
        // The start is clamped into the bounds too.
        let out = LevenbergMarquardt::default()
            .run(&p, &[5.0, 1.0, 3.0], &mut NoObserver)
            .unwrap();
        assert!(out.params[2] <= 1.0);
    }

    /// Two strongly correlated parameters, the first's unconstrained best (≈ 2.5) beyond its bound (1): the search
    /// holds it on the bound and solves for the other alone, reaching the constrained optimum in a few
    /// steps. A step solved with both free and then projected crept along the bound for the whole budget.
    #[test]
    fn a_parameter_pushed_against_its_bound_is_held_there_and_the_others_converge() {
        struct Correlated;
        impl LeastSquares for Correlated {
            fn n_params(&self) -> usize {
                2
            }
            fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, FitError> {
                let (c0, c1, b) = ([1.0, 1.0, 1.0], [1.0, 1.1, 0.9], [4.0, 4.2, 3.9]);
                Ok((0..3).map(|i| c0[i] * p[0] + c1[i] * p[1] - b[i]).collect())
            }
            fn bounds(&self, j: usize) -> (f64, f64) {
                [(-10.0, 1.0), (-10.0, 10.0)][j]
            }
        }
        let out = LevenbergMarquardt::default()
            .run(&Correlated, &[0.0, 0.0], &mut NoObserver)
            .unwrap();
        assert!(
            out.termination.converged(),
            "{} after {}",
            out.termination,
            out.iterations
        );
        assert!(out.iterations <= 10, "{} iterations", out.iterations);
        assert_eq!(out.params[0], 1.0);
        // With p0 on its bound the best p1 is c1·(b − c0)/(c1·c1) = 9.13/3.02.
        assert!((out.params[1] - 9.13 / 3.02).abs() < 1e-6, "{:?}", out.params);
    }

    #[test]
    fn the_log_observer_writes_one_line_per_iteration() {
        let p = Decay::new([12.0, 0.4, 1.5]);
        let mut log = LogObserver::new(Vec::new(), vec!["a".into(), "tau".into(), "c".into()]);
        let out = LevenbergMarquardt::default()
            .run(&p, &[1.0, 2.0, 0.0], &mut log)
            .unwrap();
        let text = String::from_utf8(log.into_inner()).unwrap();
        assert!(text.starts_with("iter   0  cost "), "{text}");
        assert!(text.contains("tau="));
        assert!(text.lines().count() >= out.iterations);
    }

    /// r = p − 10, but the "simulation" fails for p > 5.
    struct FailsBeyond;

    impl LeastSquares for FailsBeyond {
        fn n_params(&self) -> usize {
            1
        }
        fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, FitError> {
            if p[0] > 5.0 {
                return Err(FitError::Simulation {
                    shot: "clip_9".into(),
                    source: Box::new(ModelError::NoImpact { max_time_s: 10.0 }),
                });
            }
            Ok(vec![p[0] - 10.0, 0.5 * (p[0] - 10.0)])
        }
    }

    #[test]
    fn a_failing_simulation_ends_the_search_at_the_last_good_point_naming_the_shot() {
        let out = LevenbergMarquardt::default()
            .run(&FailsBeyond, &[0.0], &mut NoObserver)
            .unwrap();
        match &out.termination {
            Termination::SimulationFailed { shot, message } => {
                assert_eq!(shot, "clip_9");
                assert!(message.contains("did not reach the surface"), "{message}");
            }
            other => panic!("{other:?}"),
        }
        assert!(out.params[0] <= 5.0 && out.params[0] > 4.0, "{:?}", out.params);
        assert!(out.termination.to_string().contains("clip_9"));
        // At the start, the failure is an error.
        assert!(
            LevenbergMarquardt::default()
                .run(&FailsBeyond, &[6.0], &mut NoObserver)
                .is_err()
        );
    }
}
