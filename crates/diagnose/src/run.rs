//! One model fitted to every shot and cross-validated across shots: the unit of work of the search, for
//! the current model, each candidate and each proposed term alike.

use crate::evaluate::{Evaluator, ShotSums, summarize};
use crate::options::SearchOptions;
use crate::{FitSummary, stats};
use bouncelab_fit::{
    Differences, FitError, Iteration, IterationObserver, LeastSquares, LevenbergMarquardt, MeasuredShot, SolverOutcome,
    Termination,
};
use bouncelab_model::{ModelSpec, Simulation};
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::time::Instant;

/// One model fitted to all shots and cross-validated.
pub(crate) struct ModelRun {
    pub summary: FitSummary,
    pub sims: Vec<Simulation>,
    pub per_shot: Vec<ShotSums>,
    /// Per shot (input order): its residual sums when predicted by the model fitted without its fold.
    pub heldout: Vec<Option<ShotSums>>,
    /// False when its BIC fall was too small for the folds to decide anything (`heldout` is then empty).
    pub cross_validated: bool,
    pub n_params: usize,
    /// Each shot's surface level at the full fit, m (with surface levels).
    pub levels: Option<Vec<f64>>,
    /// A candidate reported at its switch's neutral value: no value on its scan, nor its fit, did better.
    pub kept_at_neutral: bool,
    pub seconds: f64,
}

fn effect_names(spec: &ModelSpec) -> Vec<String> {
    spec.effects.iter().map(|e| e.name.clone()).collect()
}

/// Factors of a candidate's start the search tries: its response need not be monotone in its switch
/// parameter, nor separable from the others (a tangential spring's slip reversal moves with the stiffness
/// and with μ: fitted from a start a factor 3 stiffer than the truth, it stops at 58 µm instead of the
/// noise). So the starts are ranked on a log grid spanning 1000× (one simulation of every shot each), and
/// a candidate whose fit removes at least half of the current model's systematic mean square but leaves
/// more than the floor is fitted again from the next best start (at most [`MAX_STARTS`] fits in all).
const SCAN_FACTORS: [f64; 7] = [1.0 / 30.0, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0];

/// Most fits of one candidate from different starts.
const MAX_STARTS: usize = 2;

/// How a candidate's switch parameter is started: scanned on a grid, and fitted again from the next start
/// while the fit leaves a systematic residual above `floor_m` (over the noise `noise_m`).
pub(crate) struct Scan<'a> {
    pub name: &'a str,
    /// The switch's neutral value (the effect does nothing there: the candidate is the current model).
    pub neutral: f64,
    pub noise_m: f64,
    pub floor_m: f64,
    /// The current model's systematic residual, m.
    pub base_systematic_m: f64,
}

/// What the scan of a candidate's switch found.
struct Scanned {
    /// Starts for the fit, best (lowest χ²) first.
    starts: Vec<Vec<f64>>,
    /// The start with the switch at its neutral value, and whether it fitted at least as well as every
    /// start on the grid.
    neutral: Option<(Vec<f64>, bool)>,
}

/// `p0` with the switch `sc.name` set to each value of `p0[name] × SCAN_FACTORS` (within its bounds), best
/// (lowest χ²) first, at most `n`, and set to its neutral value; just `p0` when it is not free or every
/// simulation fails.
fn scan_starts(ev: &Evaluator, sc: &Scan<'_>, p0: &[f64], n: usize) -> Scanned {
    let Some(j) = ev.names().iter().position(|x| x == sc.name) else {
        return Scanned {
            starts: vec![p0.to_vec()],
            neutral: None,
        };
    };
    let fp = &ev.problem().params()[j];
    let at = |v: f64| -> Option<(f64, Vec<f64>)> {
        let mut theta = p0.to_vec();
        theta[j] = v.clamp(fp.min, fp.max);
        let sims = ev.simulate(&theta).ok()?;
        let chi2: f64 = ev.per_shot(&sims).iter().map(|s| s.chi2).sum();
        chi2.is_finite().then_some((chi2, theta))
    };
    let mut tried: Vec<(f64, Vec<f64>)> = SCAN_FACTORS.iter().filter_map(|f| at(p0[j] * f)).collect();
    tried.sort_by(|a, b| a.0.total_cmp(&b.0));
    tried.dedup_by(|a, b| a.1 == b.1);
    let neutral = at(sc.neutral).map(|(chi2, theta)| (theta, tried.first().is_none_or(|best| chi2 <= best.0)));
    let starts = if tried.is_empty() {
        vec![p0.to_vec()]
    } else {
        tried.into_iter().take(n).map(|(_, t)| t).collect()
    };
    Scanned { starts, neutral }
}

/// True when the switch `name`'s neutral value is an end of its search range (a range not mirrored about it).
fn neutral_on_bound(ev: &Evaluator, sc: &Scan<'_>) -> bool {
    ev.names().iter().position(|x| x == sc.name).is_some_and(|j| {
        let fp = &ev.problem().params()[j];
        sc.neutral <= fp.min || sc.neutral >= fp.max
    })
}

/// Where a model's fit starts and what it reports.
pub(crate) struct Start<'a> {
    /// Each shot's surface level to start from (the current model's, for a candidate).
    pub seed: Option<&'a [f64]>,
    /// A candidate's switch parameter to scan for its start.
    pub scan: Option<&'a Scan<'a>>,
    /// Called with every solver iteration of the fit to all shots and its reduced χ².
    pub on_iteration: &'a dyn Fn(usize, f64),
    /// Cross-validate only when the fit to all shots lowers BIC enough to count (a candidate that fails
    /// the BIC check can be neither named nor said to explain part, so its folds would decide nothing).
    pub gate: Option<BicGate>,
}

/// The current model's χ², parameter count and residual count, and the least BIC fall that counts.
#[derive(Clone, Copy)]
pub(crate) struct BicGate {
    pub chi2: f64,
    pub n_params: usize,
    pub n_res: f64,
    pub min_delta_bic: f64,
}

impl BicGate {
    /// The gate of the current model's run `base`: a candidate counts when its BIC falls by at least
    /// `min_delta_bic`.
    pub fn of(base: &ModelRun, min_delta_bic: f64) -> BicGate {
        BicGate {
            chi2: base.summary.chi2,
            n_params: base.n_params,
            n_res: base.per_shot.iter().map(|s| s.n).sum::<usize>() as f64,
            min_delta_bic,
        }
    }

    /// ΔBIC of a fit with χ² `chi2` and `n_params` parameters against the current model.
    pub fn delta_bic(&self, chi2: f64, n_params: usize) -> f64 {
        let tiny = f64::MIN_POSITIVE;
        self.n_res * (chi2.max(tiny) / self.chi2.max(tiny)).ln()
            + (n_params as f64 - self.n_params as f64) * self.n_res.ln()
    }
}

/// Fits `spec` to every shot from the file's values, then once per fold without that fold's shots
/// (warm-started at the full fit), predicting each left-out shot. With surface levels, the full fit
/// profiles them from `seed` (the current model's, for a candidate); a fold's fit holds its training
/// shots' levels at the full fit's values (profiling them again in every fold would multiply the
/// search's time by ten and move them by a few µm), while each left-out shot's level is profiled on its
/// own data, as its incoming state is.
pub(crate) fn run_model(
    spec: &ModelSpec,
    shots: &[MeasuredShot],
    fold_of: &[usize],
    k: usize,
    opts: &SearchOptions,
    how: Start<'_>,
) -> Result<ModelRun, FitError> {
    let Start {
        seed,
        scan,
        on_iteration,
        gate,
    } = how;
    let clock = Instant::now();
    let mut ev = Evaluator::new(spec, shots.to_vec(), opts.sim, opts.surface_levels)?;
    let dof = ev
        .problem()
        .n_residuals()
        .saturating_sub(ev.problem().params().len() + ev.nuisance_per_shot() * shots.len())
        .max(1) as f64;
    let mut observer = |it: &Iteration<'_>| on_iteration(it.iteration, it.cost / dof);
    let p0 = ev.problem().initial();
    let scanned = match scan {
        Some(sc) => {
            // The start nuisances under the candidate at its neutral value: the current model's.
            if let Some(j) = ev.names().iter().position(|x| x == sc.name) {
                let fp = &ev.problem().params()[j];
                let mut theta = p0.clone();
                theta[j] = sc.neutral.clamp(fp.min, fp.max);
                ev.difference_nuisances_at(&theta)?;
            }
            if let Some(levels) = seed {
                ev.set_levels(levels, false);
            }
            scan_starts(&ev, sc, &p0, MAX_STARTS)
        }
        None => Scanned {
            starts: vec![p0],
            neutral: None,
        },
    };
    let zero = ev.levels();
    // The candidate at its neutral value is the current model, from its levels (no fit, no Jacobian yet).
    let at_neutral = |ev: &mut Evaluator, theta: &[f64]| -> Result<SolverOutcome, FitError> {
        if let Some(levels) = seed.or(zero.as_deref()) {
            ev.set_levels(levels, true);
        }
        outcome_at(ev, theta, (0, 0, Termination::Stalled))
    };
    // Nothing on the scan fits better than the neutral value, and the fit cannot cross it: a fit from the
    // grid could only end on the far side of a ringing response (the tangential spring's), above it.
    if let (Some(sc), Some((theta, true))) = (scan, &scanned.neutral)
        && neutral_on_bound(&ev, sc)
    {
        let mut out = at_neutral(&mut ev, theta)?;
        out.jacobian = covariance_jacobian(&ev, opts, theta);
        return finish_run(spec, shots, fold_of, k, opts, &ev, &out, gate, clock, true);
    }
    let starts = scanned.starts;
    let mut fit_from = |ev: &mut Evaluator, start: &[f64]| -> Result<(SolverOutcome, f64), FitError> {
        let out = match &zero {
            None => ev.fit_observed(&opts.solver, start, &mut observer)?,
            Some(zero) => fit_with_levels(ev, seed.unwrap_or(zero), start, opts, &mut observer)?,
        };
        let sims = ev.simulate(&out.params)?;
        let (sq, n) = ev
            .per_shot(&sims)
            .iter()
            .fold((0.0, 0usize), |(a, n), s| (a + s.sq_m2, n + s.n));
        Ok((
            out,
            stats::excess(sq / n.max(1) as f64, scan.map_or(0.0, |sc| sc.noise_m)),
        ))
    };
    let (mut out, mut systematic) = fit_from(&mut ev, &starts[0])?;
    for start in &starts[1..] {
        let promising = |sc: &Scan<'_>| systematic > sc.floor_m && systematic < sc.base_systematic_m / 2f64.sqrt();
        if !scan.is_some_and(promising) {
            break;
        }
        let (next, s) = fit_from(&mut ev, start)?;
        if next.cost < out.cost {
            (out, systematic) = (next, s);
        }
    }
    // A fit that ended above the candidate's neutral value (a local minimum of a response that is not
    // monotone) reports the neutral value: the candidate is never worse than the current model it contains.
    if let Some((theta, _)) = &scanned.neutral {
        let fitted_levels = ev.levels();
        let mut neutral = at_neutral(&mut ev, theta)?;
        if neutral.cost < out.cost {
            neutral.jacobian = covariance_jacobian(&ev, opts, theta);
            return finish_run(spec, shots, fold_of, k, opts, &ev, &neutral, gate, clock, true);
        }
        if let Some(levels) = fitted_levels {
            ev.set_levels(&levels, true);
        }
    }
    // The current model (no scan) is reported with its start nuisances differenced under its fit, as its
    // candidates take them at their neutral values and as a given fit's are (`run_fitted`).
    let nuisances = |s: &MeasuredShot| s.frame_sigma_rad.is_some() || s.spin_sigma_rad_s.is_some();
    if scan.is_none() && ev.problem().shots().iter().any(nuisances) {
        ev.difference_nuisances_at(&out.params)?;
        let mut again = outcome_at(
            &ev,
            &out.params,
            (out.iterations, out.evaluations, out.termination.clone()),
        )?;
        again.jacobian = covariance_jacobian(&ev, opts, &out.params);
        out = again;
    }
    finish_run(spec, shots, fold_of, k, opts, &ev, &out, gate, clock, false)
}

/// The current model at values the caller already fitted (`theta`, in the parameter order of `spec` on
/// `shots`; `levels` each shot's surface level, m, with surface levels): its residual sums and the
/// covariance at that point (the Jacobian with the levels marginalised, as a search fit's), then
/// cross-validated as [`run_model`] does. `fitted` carries the fit's iterations, evaluations and
/// termination into the summary.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_fitted(
    spec: &ModelSpec,
    shots: &[MeasuredShot],
    fold_of: &[usize],
    k: usize,
    opts: &SearchOptions,
    theta: &[f64],
    levels: Option<&[f64]>,
    fitted: (usize, usize, Termination),
) -> Result<ModelRun, FitError> {
    let clock = Instant::now();
    let mut ev = Evaluator::new(spec, shots.to_vec(), opts.sim, opts.surface_levels)?;
    ev.difference_nuisances_at(theta)?;
    if let Some(levels) = levels {
        ev.set_levels(levels, true);
    }
    let mut out = outcome_at(&ev, theta, fitted)?;
    out.jacobian = covariance_jacobian(&ev, opts, theta);
    finish_run(spec, shots, fold_of, k, opts, &ev, &out, None, clock, false)
}

/// `ev`'s residuals and cost at `theta` as a solver's outcome without a Jacobian, reporting `fitted`'s
/// iterations, evaluations and termination. With surface levels, each shot's level is profiled from its
/// current value at `theta`.
fn outcome_at(
    ev: &Evaluator,
    theta: &[f64],
    (iterations, evaluations, termination): (usize, usize, Termination),
) -> Result<SolverOutcome, FitError> {
    let residuals = ev.residuals(theta)?;
    Ok(SolverOutcome {
        params: theta.to_vec(),
        cost: residuals.iter().map(|r| r * r).sum(),
        residuals,
        jacobian: None,
        iterations,
        evaluations,
        termination,
    })
}

/// The Jacobian the standard errors come from at `theta` (with surface levels, marginalised over them as a
/// search fit's is); `None` when a simulation fails.
fn covariance_jacobian(ev: &Evaluator, opts: &SearchOptions, theta: &[f64]) -> Option<DMatrix<f64>> {
    match ev.levels() {
        Some(levels) => ev.reduced_jacobian(&opts.solver, theta, &levels).ok(),
        None => opts.solver.jacobian_at(ev, theta).ok(),
    }
}

/// A model's run from its fit `out` on `ev`: the residual sums at the fit, the summary, and (unless its
/// BIC fall fails `gate`) the held-out predictions of every fold.
#[allow(clippy::too_many_arguments)]
fn finish_run(
    spec: &ModelSpec,
    shots: &[MeasuredShot],
    fold_of: &[usize],
    k: usize,
    opts: &SearchOptions,
    ev: &Evaluator,
    out: &SolverOutcome,
    gate: Option<BicGate>,
    clock: Instant,
    kept_at_neutral: bool,
) -> Result<ModelRun, FitError> {
    // (With profiled levels, this also leaves them at the kept fit's optimum.)
    let sims = ev.simulate(&out.params)?;
    let per_shot = ev.per_shot(&sims);
    let sq: f64 = per_shot.iter().map(|s| s.sq_m2).sum();
    let summary = summarize(ev, effect_names(spec), out, sq);
    let fitted: Vec<(String, f64)> = ev.names().into_iter().zip(out.params.iter().copied()).collect();
    let levels = ev.levels();
    let n_params = out.params.len() + ev.nuisance_per_shot() * shots.len();
    let cross_validated = gate.is_none_or(|g| g.delta_bic(out.cost, n_params) <= -g.min_delta_bic);
    // Folds in parallel (each fit also simulates its shots in parallel); collected in fold order.
    let per_fold: Vec<Vec<(usize, Option<ShotSums>)>> = if cross_validated {
        (0..k)
            .into_par_iter()
            .map(|f| {
                let at = Fold {
                    values: &fitted,
                    levels: levels.as_deref(),
                    full: ev,
                };
                heldout_fold(spec, shots, fold_of, f, &at, opts)
            })
            .collect()
    } else {
        Vec::new()
    };
    let mut heldout = vec![None; shots.len()];
    for (i, sums) in per_fold.into_iter().flatten() {
        heldout[i] = sums;
    }
    Ok(ModelRun {
        summary,
        sims,
        per_shot,
        heldout,
        cross_validated,
        n_params,
        levels,
        kept_at_neutral,
        seconds: clock.elapsed().as_secs_f64(),
    })
}

/// Fits the shared parameters and each shot's surface level, from the levels `start`. First by turns: the
/// parameters with the levels held (a smooth problem for the finite-difference Jacobian), then each level
/// profiled at those parameters, until no level moves by more than 0.5 µm (at most four rounds). Block-wise
/// descent stops where neither block alone can move, which is not the joint optimum when the blocks are
/// correlated (a free surface level per surface against each shot's level, and a restitution-phase effect
/// against both): on a tracked restitution-damping session it left the current model at 32.9 µm against
/// the joint optimum's 16.4 µm, and ranked the plastic dent (9.1 µm) above the true effect (9.5 µm; 8.3 µm
/// at its joint optimum). So a last fit profiles the levels inside every evaluation, warm-started where the
/// rounds ended, stepping with the levels projected out (variable projection); when its steps were
/// differenced through the profile, a cold start took eight times longer on the benchmark. Every model
/// starts from the same levels, so all are compared alike. Leaves `ev` profiling from the final levels.
fn fit_with_levels(
    ev: &mut Evaluator,
    start: &[f64],
    p0: &[f64],
    opts: &SearchOptions,
    observer: &mut dyn IterationObserver,
) -> Result<SolverOutcome, FitError> {
    let mut levels = start.to_vec();
    let mut p = p0.to_vec();
    // The rounds' covariance is not wanted, and the joint fit's comes from the smooth reduced Jacobian.
    // They only bring the joint fit a start, so they stop at the joint fit's tolerance: at 1e-7 a
    // misfitting candidate's rounds crept through all 50 iterations, four times over.
    let rounds = LevenbergMarquardt {
        jacobian_at_end: false,
        ftol: opts.solver.ftol.max(1e-5),
        ..opts.solver
    };
    for _ in 0..4 {
        ev.set_levels(&levels, false);
        let out = ev.fit_observed(&rounds, &p, observer)?;
        p.clone_from(&out.params);
        ev.set_levels(&levels, true);
        ev.simulate(&p)?;
        let next = ev.levels().unwrap_or_default();
        let moved = next.iter().zip(&levels).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        levels = next;
        if moved <= 0.5e-6 {
            break;
        }
    }
    ev.set_levels(&levels, true);
    // Warm-started, it converges in a few iterations, except along Hunt–Crossley's λ–n valley, where it
    // would creep for the whole budget. A relative χ² change of 1e-5 moves a BIC over 10⁴ residuals by
    // 0.1, nothing the search decides on, and stopping there nearly halves the joint fit's time on the
    // 144-shot `paper` session, whose levels were already nearly right (search 28.0 → 22.8 s).
    let solver = LevenbergMarquardt {
        max_iterations: opts.fold_max_iterations,
        ftol: opts.solver.ftol.max(1e-5),
        // Its steps take the reduced Jacobian (variable projection, `Evaluator`'s step Jacobian), here
        // centrally differenced with the levels held. Differenced through the profiled levels instead,
        // forward differences were too noisy to converge in this budget (restitution damping's fit stopped
        // 1 % higher on a drag session) and central ones cost 2p profiles a step: 21.7 → 16.2 s of
        // search on `paper`.
        step_differences: Differences::Central,
        ..rounds
    };
    let mut joint = ev.fit_observed(&solver, &p, observer)?;
    // The solver's last evaluation may have been a rejected step: profile the levels at the result.
    ev.simulate(&joint.params)?;
    // The standard errors come from the reduced Jacobian at the result.
    let levels = ev.levels().unwrap_or_default();
    joint.jacobian = ev.reduced_jacobian(&solver, &joint.params, &levels).ok();
    Ok(joint)
}

/// Where a fold starts: the full fit's values (by name), its surface levels and the full fit's evaluator
/// (each shot's start nuisances as differenced there).
struct Fold<'a> {
    values: &'a [(String, f64)],
    levels: Option<&'a [f64]>,
    full: &'a Evaluator,
}

/// The shots of fold `f` predicted by the model fitted to the other folds; `None` for a shot that cannot
/// be predicted (its surface has no shot left to fit, or a fit or simulation failed).
fn heldout_fold(
    spec: &ModelSpec,
    shots: &[MeasuredShot],
    fold_of: &[usize],
    f: usize,
    at: &Fold<'_>,
    opts: &SearchOptions,
) -> Vec<(usize, Option<ShotSums>)> {
    let Fold { values, levels, full } = *at;
    let new_evaluator = |which: &[usize]| Evaluator::part_of(spec, full, which, opts.sim, opts.surface_levels).ok();
    let test: Vec<usize> = (0..shots.len()).filter(|&i| fold_of[i] == f).collect();
    let train_idx: Vec<usize> = (0..shots.len()).filter(|&i| fold_of[i] != f).collect();
    let lookup = |table: &[(String, f64)], name: &str| table.iter().find(|(n, _)| n == name).map(|(_, v)| *v);
    let fitted: Option<Vec<(String, f64)>> = (|| {
        let mut ev = new_evaluator(&train_idx)?;
        if let Some(levels) = levels {
            let held: Vec<f64> = train_idx.iter().map(|&i| levels[i]).collect();
            ev.set_levels(&held, false);
        }
        let names = ev.names();
        let p0: Vec<f64> = names.iter().map(|n| lookup(values, n)).collect::<Option<_>>()?;
        // Only the fold's parameters are wanted, not their covariance.
        let solver = LevenbergMarquardt {
            max_iterations: opts.fold_max_iterations,
            jacobian_at_end: false,
            ..opts.solver
        };
        let out = ev.fit(&solver, &p0).ok()?;
        Some(names.into_iter().zip(out.params).collect())
    })();
    test.into_iter()
        .map(|i| {
            let sums = fitted.as_ref().and_then(|fitted| {
                let mut ev = new_evaluator(&[i])?;
                if let Some(levels) = levels {
                    ev.set_levels(&[levels[i]], true);
                }
                let theta: Vec<f64> = ev.names().iter().map(|n| lookup(fitted, n)).collect::<Option<_>>()?;
                let sims = ev.simulate(&theta).ok()?;
                ev.per_shot(&sims).first().copied()
            });
            (i, sums)
        })
        .collect()
}
