//! One model against a set of shots: the weighted residuals a fit minimises, with the measured start taken
//! as what the camera saw, and the fit's summary (values, standard errors, intervals, χ², RMS).
//!
//! This is the fit crate's [`Problem`] (it checks the shots, owns the parameter vector and maps each
//! measured start through the model's measurement effects) with the surface levels held, profiled or
//! neither, and the sums and summaries the search compares.

use bouncelab_fit::{
    Differences, FitError, IterationObserver, LeastSquares, LevenbergMarquardt, MeasuredShot, NoObserver, Problem,
    SolverOutcome, Termination, covariance, profile_surface_level, surface_prior, weighted_residuals,
};
use bouncelab_model::{Model, ModelSpec, SimOptions, Simulation};
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, Ordering};

/// Shared parameters of a model against shots; residuals `(x_sim − x_m)/σ`, `(y_sim − y_m)/σ` per frame.
#[derive(Debug)]
pub(crate) struct Evaluator {
    problem: Problem,
    /// Index of each shot's surface in `surfaces`.
    shot_surface: Vec<usize>,
    surfaces: Vec<String>,
    /// Each shot's surface level, m: none, profiled, or held.
    levels: Levels,
}

/// How each shot's surface level (the true surface's height in the measured frame) enters.
#[derive(Debug)]
enum Levels {
    /// At the measured surface line.
    None,
    /// Profiled in every evaluation, warm-started at the last value (f64 bits).
    Profiled(Vec<AtomicU64>),
    /// Held at given values (a fold's training shots at the full fit's levels).
    Held(Vec<f64>),
}

impl Evaluator {
    /// Checks the shots and builds the parameter vector of `spec` (see [`Problem::new`]); with
    /// `surface_levels`, each shot's surface level is a nuisance profiled in every evaluation (as the fit
    /// crate's `Problem::with_surface_offsets`).
    pub fn new(
        spec: &ModelSpec,
        shots: Vec<MeasuredShot>,
        sim: SimOptions,
        surface_levels: bool,
    ) -> Result<Evaluator, FitError> {
        Ok(Evaluator::of(Problem::new(spec, shots, sim)?, surface_levels))
    }

    /// [`Evaluator::new`] for the shots `which` (indices into `source`'s shots) of `source`, with their
    /// start nuisances as `source` differenced them (a cross-validation fold: nothing simulated to set it
    /// up).
    pub fn part_of(
        spec: &ModelSpec,
        source: &Evaluator,
        which: &[usize],
        sim: SimOptions,
        surface_levels: bool,
    ) -> Result<Evaluator, FitError> {
        let shots = which.iter().map(|&i| source.problem.shots()[i].clone()).collect();
        let problem = Problem::with_nuisances_of(spec, shots, sim, &source.problem, which)?;
        Ok(Evaluator::of(problem, surface_levels))
    }

    fn of(problem: Problem, surface_levels: bool) -> Evaluator {
        let mut surfaces: Vec<String> = Vec::new();
        let mut shot_surface = Vec::with_capacity(problem.shots().len());
        for s in problem.shots() {
            let i = match surfaces.iter().position(|n| n == &s.surface) {
                Some(i) => i,
                None => {
                    surfaces.push(s.surface.clone());
                    surfaces.len() - 1
                }
            };
            shot_surface.push(i);
        }
        let levels = if surface_levels {
            Levels::Profiled(problem.shots().iter().map(|_| AtomicU64::new(0)).collect())
        } else {
            Levels::None
        };
        Evaluator {
            problem,
            shot_surface,
            surfaces,
            levels,
        }
    }

    /// Differences the shots' start nuisances (frame turn, incoming spin) under the model at `theta`, so
    /// that models nested in each other take them out alike: the current model at its fit and each
    /// candidate at its neutral value (see `Problem::difference_nuisances_at`).
    pub fn difference_nuisances_at(&mut self, theta: &[f64]) -> Result<(), FitError> {
        self.problem.difference_nuisances_at(theta)
    }

    /// Surface levels start at `levels` (one per shot, m): profiled from there if they are profiled,
    /// else held there (`profile = false`). Ignored without surface levels.
    pub fn set_levels(&mut self, levels: &[f64], profile: bool) {
        if matches!(self.levels, Levels::None) || levels.len() != self.problem.shots().len() {
            return;
        }
        self.levels = if profile {
            Levels::Profiled(levels.iter().map(|l| AtomicU64::new(l.to_bits())).collect())
        } else {
            Levels::Held(levels.to_vec())
        };
    }

    /// Each shot's current surface level, m (`None` without surface levels).
    pub fn levels(&self) -> Option<Vec<f64>> {
        match &self.levels {
            Levels::None => None,
            Levels::Profiled(l) => Some(l.iter().map(|b| f64::from_bits(b.load(Ordering::Relaxed))).collect()),
            Levels::Held(l) => Some(l.clone()),
        }
    }

    pub fn problem(&self) -> &Problem {
        &self.problem
    }

    /// Parameter names, in vector order (`clay:spring.k`, `hertz.k_h`).
    pub fn names(&self) -> Vec<String> {
        self.problem.params().iter().map(|p| p.name.clone()).collect()
    }

    /// Simulates every shot with `theta` at its frame times, in shot order (parallel over shots); with
    /// surface levels, each shot's level is profiled (warm-started at its last value).
    pub fn simulate(&self, theta: &[f64]) -> Result<Vec<Simulation>, FitError> {
        let all: Vec<usize> = (0..self.problem.shots().len()).collect();
        self.simulate_some(theta, &all)
    }

    /// Simulates the shots `which` with `theta`, in that order (see [`Evaluator::simulate`]).
    fn simulate_some(&self, theta: &[f64], which: &[usize]) -> Result<Vec<Simulation>, FitError> {
        let models = self
            .surfaces
            .iter()
            .map(|s| self.problem.model_for(s, theta))
            .collect::<Result<Vec<_>, _>>()?;
        let one = |&i: &usize| -> Result<Simulation, FitError> {
            let model = &models[self.shot_surface[i]];
            match &self.levels {
                Levels::None => self.simulate_at(i, model, 0.0),
                Levels::Held(levels) => self.simulate_at(i, model, levels[i]),
                Levels::Profiled(levels) => {
                    let start = f64::from_bits(levels[i].load(Ordering::Relaxed));
                    let (sim, level) =
                        profile_surface_level(&self.problem.shots()[i], start, |l| self.simulate_at(i, model, l))?;
                    levels[i].store(level.to_bits(), Ordering::Relaxed);
                    Ok(sim)
                }
            }
        };
        let all: Vec<Result<Simulation, FitError>> = which.par_iter().map(one).collect();
        all.into_iter().collect()
    }

    /// The Jacobian the standard errors come from at `theta`, with every shot's surface level (m,
    /// `levels`) marginalised ([`Problem::reduced_jacobian`], central differences).
    pub fn reduced_jacobian(
        &self,
        solver: &LevenbergMarquardt,
        theta: &[f64],
        levels: &[f64],
    ) -> Result<DMatrix<f64>, FitError> {
        self.problem
            .reduced_jacobian(solver, theta, levels, Differences::Central)
    }

    /// Shot `i` with the true surface at height `level` in the measured frame (m), measurement effects
    /// mapped as the fit crate does ([`Problem::simulate_shot`]).
    fn simulate_at(&self, i: usize, model: &Model, level: f64) -> Result<Simulation, FitError> {
        self.problem.simulate_shot(i, model, level)
    }

    /// Nuisance parameters per shot (1 with surface levels, else 0).
    pub fn nuisance_per_shot(&self) -> usize {
        usize::from(!matches!(self.levels, Levels::None))
    }

    /// Per shot: (Σ ((sim − meas)/σ)², Σ (sim − meas)² in m², residual count).
    pub fn per_shot(&self, sims: &[Simulation]) -> Vec<ShotSums> {
        self.problem
            .shots()
            .iter()
            .zip(sims)
            .map(|(shot, sim)| {
                let mut s = ShotSums::default();
                for (f, p) in shot.frames.iter().zip(&sim.samples) {
                    let (dx, dy) = (p.observed.x - f.x_m, p.observed.y - f.y_m);
                    s.chi2 += (dx * dx + dy * dy) / (f.sigma_m * f.sigma_m);
                    s.sq_m2 += dx * dx + dy * dy;
                    s.n += 2;
                }
                s
            })
            .collect()
    }

    /// Fits from `p0` (clamped into the bounds).
    pub fn fit(&self, solver: &LevenbergMarquardt, p0: &[f64]) -> Result<SolverOutcome, FitError> {
        solver.run(self, p0, &mut NoObserver)
    }

    /// [`Evaluator::fit`], reporting every solver iteration to `observer` (on the calling thread).
    pub fn fit_observed(
        &self,
        solver: &LevenbergMarquardt,
        p0: &[f64],
        observer: &mut dyn IterationObserver,
    ) -> Result<SolverOutcome, FitError> {
        solver.run(self, p0, observer)
    }
}

impl LeastSquares for Evaluator {
    fn n_params(&self) -> usize {
        self.problem.params().len()
    }

    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, FitError> {
        let sims = self.simulate(theta)?;
        let mut r = Vec::with_capacity(self.problem.n_residuals());
        for (shot, sim) in self.problem.shots().iter().zip(&sims) {
            r.extend(weighted_residuals(shot, sim));
        }
        // Each shot's surface-level prior, as the fit crate adds it.
        if let Some(levels) = self.levels() {
            r.extend(
                self.problem
                    .shots()
                    .iter()
                    .zip(levels)
                    .map(|(shot, l)| surface_prior(shot, l).unwrap_or(0.0)),
            );
        }
        Ok(r)
    }

    /// Only the shots of parameter `j`'s surface are simulated again ([`Problem::shots_of_param`]).
    fn residuals_changing(&self, theta: &[f64], j: usize, base: &[f64]) -> Result<Vec<f64>, FitError> {
        let Some(which) = self.problem.shots_of_param(j) else {
            return self.residuals(theta);
        };
        let sims = self.simulate_some(theta, &which)?;
        let mut r = base.to_vec();
        let levels = self.levels();
        let n_frames = self.problem.n_residuals();
        for (&i, sim) in which.iter().zip(&sims) {
            let shot = &self.problem.shots()[i];
            let at = self.problem.first_residual(i);
            r[at..at + 2 * shot.frames.len()].copy_from_slice(&weighted_residuals(shot, sim));
            if let Some(levels) = &levels {
                r[n_frames + i] = surface_prior(shot, levels[i]).unwrap_or(0.0);
            }
        }
        Ok(r)
    }

    fn bounds(&self, j: usize) -> (f64, f64) {
        self.problem.bounds(j)
    }

    fn scale(&self, j: usize) -> f64 {
        self.problem.scale(j)
    }

    /// With the levels profiled in every evaluation, the reduced Jacobian at the levels the last evaluation
    /// profiled (those of `theta`), forward-differenced with them held: the solver then takes variable
    /// projection's steps (Kaufman's), whose gradient is the profiled problem's own, instead of differencing
    /// through the profile (2p profiled evaluations of 3–5 simulations a shot each, and noisy columns).
    fn step_jacobian(&self, solver: &LevenbergMarquardt, theta: &[f64]) -> Option<Result<DMatrix<f64>, FitError>> {
        let Levels::Profiled(_) = &self.levels else {
            return None;
        };
        let levels = self.levels()?;
        Some(
            self.problem
                .reduced_jacobian(solver, theta, &levels, solver.step_differences),
        )
    }
}

/// A shot's sums of squared residuals.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct ShotSums {
    /// Σ ((sim − meas)/σ)² over x and y.
    pub chi2: f64,
    /// Σ (sim − meas)², m².
    pub sq_m2: f64,
    /// Number of residuals (2 per frame).
    pub n: usize,
}

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedValue {
    /// `damping.b` (global) or `clay:spring.k` (one surface's value).
    pub name: String,
    /// The effect.
    pub effect: String,
    /// The parameter.
    pub param: String,
    /// The surface of a per-surface value, `None` for a global one.
    pub surface: Option<String>,
    /// Fitted value, in the parameter's unit (see `bouncelab effects`).
    pub value: f64,
    /// Standard error, same unit (the fit crate's [`covariance`]: `(JᵀJ)⁻¹·max(1, χ²_red)`, each variance
    /// raised to the cluster-robust one with the shots as clusters when that is larger); `None` when the
    /// parameter is not determined by the shots.
    pub std_error: Option<f64>,
    /// 95 % interval `value ± t·se`; `None` with `std_error`.
    pub interval: Option<[f64; 2]>,
    /// True if the value ended on a bound of the fit.
    pub at_bound: bool,
}

/// A model fitted to all shots.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitSummary {
    /// The model's effects, in order.
    pub effects: Vec<String>,
    /// Every free parameter.
    pub parameters: Vec<FittedValue>,
    /// χ² = Σ ((sim − meas)/σ)² with the tracker's σ.
    pub chi2: f64,
    /// Residuals (two per frame) minus free parameters.
    pub dof: usize,
    /// χ² / dof against the tracker's σ.
    pub chi2_red: f64,
    /// RMS of all position residuals (x and y), m.
    pub rms_m: f64,
    /// Solver iterations.
    pub iterations: usize,
    /// Simulations of every shot.
    pub evaluations: usize,
    /// Why the solver stopped.
    pub termination: Termination,
}

impl FitSummary {
    /// The parameter called `name`.
    pub fn param(&self, name: &str) -> Option<&FittedValue> {
        self.parameters.iter().find(|p| p.name == name)
    }
}

/// The summary of a solver outcome on `ev`: standard errors and intervals from the fit crate's
/// [`covariance`] (the one path the fit's own result takes), χ² the minimised objective.
pub(crate) fn summarize(ev: &Evaluator, effects: Vec<String>, out: &SolverOutcome, sq_m2: f64) -> FitSummary {
    let n = out.residuals.len();
    let cov = covariance(&ev.problem, out, INTERVAL_CONFIDENCE);
    let dof = cov.dof;
    let chi2_red = out.cost / dof as f64;
    let parameters = ev
        .problem
        .params()
        .iter()
        .enumerate()
        .map(|(j, fp)| {
            let value = out.params[j];
            // A parameter the shots do not determine (μ of a surface with only normal impacts) has no
            // standard error; the others keep theirs.
            FittedValue {
                name: fp.name.clone(),
                effect: fp.effect.clone(),
                param: fp.param.clone(),
                surface: fp.surface.clone(),
                value,
                std_error: cov.std_error(j),
                interval: cov.interval(j, value),
                at_bound: fp.at_bound(value),
            }
        })
        .collect();
    FitSummary {
        effects,
        parameters,
        chi2: out.cost,
        dof,
        chi2_red,
        rms_m: (sq_m2 / n.max(1) as f64).sqrt(),
        iterations: out.iterations,
        evaluations: out.evaluations,
        termination: out.termination.clone(),
    }
}

/// Confidence level of a [`FittedValue`]'s interval.
const INTERVAL_CONFIDENCE: f64 = 0.95;

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_fit::StartState;
    use bouncelab_fit::testutil::{Rng, noisy_frames, simulate_shot, spec_toml};

    fn shots() -> Vec<MeasuredShot> {
        let model = Model::paper(25_650.0, 14.0, 0.5);
        let mut rng = Rng::new(3);
        [(0.2, 0.0), (0.55, 7.5), (0.9, 15.0), (0.4, 22.5)]
            .iter()
            .enumerate()
            .map(|(k, &(h, a))| {
                let sim = simulate_shot(&model, h, a, &mut rng);
                let frames = noisy_frames(&sim, 0.0, &mut rng);
                MeasuredShot {
                    name: format!("s{k}"),
                    surface: "clay".into(),
                    incline_rad: f64::to_radians(a),
                    frames,
                    start: StartState {
                        t_s: sim.samples[0].t,
                        state: sim.samples[0].observed.into(),
                    },
                    measured: None,
                    surface_sigma_m: Some(20e-6),
                    frame_sigma_rad: None,
                    spin_sigma_rad_s: None,
                    rim_change_m: None,
                }
            })
            .collect()
    }

    #[test]
    fn the_reduced_jacobian_gives_the_shared_block_of_the_joint_covariance() {
        let spec = ModelSpec::parse(&spec_toml("t", &["clay"], ""), "test").unwrap();
        let ev = Evaluator::new(&spec, shots(), SimOptions::default(), true).unwrap();
        let theta = vec![25_000.0, 13.0];
        let levels = [0.0, 5e-6, -5e-6, 1e-5];
        let solver = LevenbergMarquardt::default();
        let reduced = ev.reduced_jacobian(&solver, &theta, &levels).unwrap();
        // The joint Jacobian by brute force: each shared parameter, then each level on its own.
        let r = |t: &[f64], l: &[f64]| ev.problem().residuals_held(t, l).unwrap();
        let (p, n) = (theta.len(), levels.len());
        let mut joint = DMatrix::zeros(reduced.nrows(), p + n);
        for j in 0..p {
            let h = solver.fd_step * ev.problem().params()[j].scale;
            let (mut up, mut dn) = (theta.clone(), theta.clone());
            up[j] += h;
            dn[j] -= h;
            joint.set_column(j, &((r(&up, &levels) - r(&dn, &levels)) / (2.0 * h)));
        }
        const LEVEL_STEP_M: f64 = 1e-6;
        for i in 0..n {
            let (mut up, mut dn) = (levels, levels);
            up[i] += LEVEL_STEP_M;
            dn[i] -= LEVEL_STEP_M;
            joint.set_column(p + i, &((r(&theta, &up) - r(&theta, &dn)) / (2.0 * LEVEL_STEP_M)));
        }
        let cov_joint = joint.tr_mul(&joint).try_inverse().unwrap();
        let cov_reduced = reduced.tr_mul(&reduced).try_inverse().unwrap();
        for a in 0..p {
            for b in 0..p {
                let (x, y) = (cov_joint[(a, b)], cov_reduced[(a, b)]);
                assert!((x - y).abs() <= 1e-6 * x.abs().max(y.abs()), "({a}, {b}): {x} vs {y}");
            }
        }
        // Holding the levels instead would understate the shared parameters' errors (k and b move the
        // contact as a level does).
        let held = joint.columns(0, p).into_owned();
        let cov_held = held.tr_mul(&held).try_inverse().unwrap();
        assert!(cov_held[(0, 0)] < cov_joint[(0, 0)] && cov_held[(1, 1)] < cov_joint[(1, 1)]);
    }

    #[test]
    fn the_step_jacobian_gives_the_profiled_cost_s_gradient() {
        let spec = ModelSpec::parse(&spec_toml("t", &["clay"], ""), "test").unwrap();
        let ev = Evaluator::new(&spec, shots(), SimOptions::default(), true).unwrap();
        // Away from the optimum, so the gradient is large.
        let theta = vec![27_000.0, 12.0];
        let solver = LevenbergMarquardt::default();
        let r = ev.residuals(&theta).unwrap();
        let jac = ev
            .step_jacobian(&solver, &theta)
            .expect("profiled levels give a step Jacobian")
            .unwrap();
        let grad = jac.tr_mul(&DMatrix::from_column_slice(r.len(), 1, &r));
        // The profiled cost ½Σr² differenced, the levels profiled again at each point.
        let cost = |t: &[f64]| ev.residuals(t).unwrap().iter().map(|v| v * v).sum::<f64>() / 2.0;
        for j in 0..theta.len() {
            let h = 1e-4 * theta[j];
            let (mut up, mut dn) = (theta.clone(), theta.clone());
            up[j] += h;
            dn[j] -= h;
            let want = (cost(&up) - cost(&dn)) / (2.0 * h);
            assert!(
                (grad[j] - want).abs() <= 0.01 * want.abs(),
                "parameter {j}: {} vs {want}",
                grad[j]
            );
        }
        // Held levels have no step Jacobian of their own: the solver differences them.
        let mut held = Evaluator::new(&spec, shots(), SimOptions::default(), true).unwrap();
        held.set_levels(&[0.0; 4], false);
        assert!(held.step_jacobian(&solver, &theta).is_none());
    }
}
