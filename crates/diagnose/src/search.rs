//! The search: the current model and every candidate fitted to all shots and cross-validated across
//! shots, then compared.

use crate::VerdictKind;
use crate::candidates::{CandidateSetup, candidate_names, library_effect, set_values, with_candidate};
use crate::diagnosis::{
    Baseline, Candidate, Checks, Diagnosis, Evidence, Floor, Noise, NoiseSource, PhaseResidual, Signature, Thresholds,
};
use crate::evaluate::{Evaluator, ShotSums, summarize};
use crate::options::{Progress, SearchOptions};
use crate::proposal::{self, ProposedTerm, TermProposal};
use crate::verdict::decide;
use crate::{DiagnoseError, FitSummary, stats};
use bouncelab_compare::{Component, DiagnoseOptions, ShotExtras, compare, diagnose};
use bouncelab_fit::{FitError, Iteration, LevenbergMarquardt, MeasuredShot, Observer, SolverOutcome};
use bouncelab_model::{ModelSpec, Simulation};
use rayon::prelude::*;
use std::time::Instant;

/// One model fitted to all shots and cross-validated.
struct ModelRun {
    summary: FitSummary,
    sims: Vec<Simulation>,
    per_shot: Vec<ShotSums>,
    /// Per shot (input order): its residual sums when predicted by the model fitted without its fold.
    heldout: Vec<Option<ShotSums>>,
    /// False when its BIC fall was too small for the folds to decide anything (`heldout` is then empty).
    cross_validated: bool,
    n_params: usize,
    /// Each shot's surface level at the full fit, m (with surface levels).
    levels: Option<Vec<f64>>,
    seconds: f64,
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
struct Scan<'a> {
    name: &'a str,
    noise_m: f64,
    floor_m: f64,
    /// The current model's systematic residual, m.
    base_systematic_m: f64,
}

/// `p0` with the parameter `name` set to each value of `p0[name] × SCAN_FACTORS` (within its bounds), best
/// (lowest χ²) first, at most `n`; just `p0` when it is not free or every simulation fails.
fn scan_starts(ev: &Evaluator, name: &str, p0: &[f64], n: usize) -> Vec<Vec<f64>> {
    let Some(j) = ev.names().iter().position(|x| x == name) else {
        return vec![p0.to_vec()];
    };
    let fp = &ev.problem().params()[j];
    let mut tried: Vec<(f64, Vec<f64>)> = SCAN_FACTORS
        .iter()
        .filter_map(|f| {
            let mut theta = p0.to_vec();
            theta[j] = (p0[j] * f).clamp(fp.min, fp.max);
            let sims = ev.simulate(&theta).ok()?;
            let chi2: f64 = ev.per_shot(&sims).iter().map(|s| s.chi2).sum();
            chi2.is_finite().then_some((chi2, theta))
        })
        .collect();
    if tried.is_empty() {
        return vec![p0.to_vec()];
    }
    tried.sort_by(|a, b| a.0.total_cmp(&b.0));
    tried.dedup_by(|a, b| a.1 == b.1);
    tried.into_iter().take(n).map(|(_, t)| t).collect()
}

/// Where a model's fit starts and what it reports.
struct Start<'a> {
    /// Each shot's surface level to start from (the current model's, for a candidate).
    seed: Option<&'a [f64]>,
    /// A candidate's switch parameter to scan for its start.
    scan: Option<&'a Scan<'a>>,
    /// Called with every solver iteration of the fit to all shots and its reduced χ².
    on_iteration: &'a dyn Fn(usize, f64),
    /// Cross-validate only when the fit to all shots lowers BIC enough to count (a candidate that fails
    /// the BIC check can be neither named nor said to explain part, so its folds would decide nothing).
    gate: Option<BicGate>,
}

/// The current model's χ², parameter count and residual count, and the least BIC fall that counts.
#[derive(Clone, Copy)]
struct BicGate {
    chi2: f64,
    n_params: usize,
    n_res: f64,
    min_delta_bic: f64,
}

impl BicGate {
    /// ΔBIC of a fit with χ² `chi2` and `n_params` parameters against the current model.
    fn delta_bic(&self, chi2: f64, n_params: usize) -> f64 {
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
fn run_model(
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
    let starts = match scan {
        Some(sc) => {
            if let Some(levels) = seed {
                ev.set_levels(levels, false);
            }
            scan_starts(&ev, sc.name, &p0, MAX_STARTS)
        }
        None => vec![p0],
    };
    let zero = ev.levels();
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
        Ok((out, excess(sq / n.max(1) as f64, scan.map_or(0.0, |sc| sc.noise_m))))
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
    // (With profiled levels, this also leaves them at the kept fit's optimum.)
    let sims = ev.simulate(&out.params)?;
    let per_shot = ev.per_shot(&sims);
    let sq: f64 = per_shot.iter().map(|s| s.sq_m2).sum();
    let summary = summarize(&ev, effect_names(spec), &out, sq);
    let fitted: Vec<(String, f64)> = ev.names().into_iter().zip(out.params.iter().copied()).collect();
    let levels = ev.levels();
    let n_params = out.params.len() + ev.nuisance_per_shot() * shots.len();
    let cross_validated = gate.is_none_or(|g| g.delta_bic(out.cost, n_params) <= -g.min_delta_bic);
    // Folds in parallel (each fit also simulates its shots in parallel); collected in fold order.
    let per_fold: Vec<Vec<(usize, Option<ShotSums>)>> = if cross_validated {
        (0..k)
            .into_par_iter()
            .map(|f| heldout_fold(spec, shots, fold_of, f, &fitted, levels.as_deref(), opts))
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
/// at its joint optimum). So a last fit profiles the levels inside every evaluation (the fit crate's joint
/// problem), warm-started where the rounds ended; from a cold start that fit took eight times longer on
/// the benchmark (the profiled levels make the Jacobian noisy and the fit long). Every model starts from
/// the same levels, so all are compared alike. Leaves `ev` profiling from the final levels.
fn fit_with_levels(
    ev: &mut Evaluator,
    start: &[f64],
    p0: &[f64],
    opts: &SearchOptions,
    observer: &mut dyn Observer,
) -> Result<SolverOutcome, FitError> {
    let mut levels = start.to_vec();
    let mut p = p0.to_vec();
    for _ in 0..4 {
        ev.set_levels(&levels, false);
        let out = ev.fit_observed(&opts.solver, &p, observer)?;
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
        ..opts.solver
    };
    let mut joint = ev.fit_observed(&solver, &p, observer)?;
    // The solver's last evaluation may have been a rejected step: profile the levels at the result.
    ev.simulate(&joint.params)?;
    // Its Jacobian went through the profiled levels; the standard errors come from the smooth one.
    let levels = ev.levels().unwrap_or_default();
    joint.jacobian = ev.reduced_jacobian(&solver, &joint.params, &levels).ok();
    Ok(joint)
}

/// The shots of fold `f` predicted by the model fitted to the other folds; `None` for a shot that cannot
/// be predicted (its surface has no shot left to fit, or a fit or simulation failed).
fn heldout_fold(
    spec: &ModelSpec,
    shots: &[MeasuredShot],
    fold_of: &[usize],
    f: usize,
    full: &[(String, f64)],
    levels: Option<&[f64]>,
    opts: &SearchOptions,
) -> Vec<(usize, Option<ShotSums>)> {
    let test: Vec<usize> = (0..shots.len()).filter(|&i| fold_of[i] == f).collect();
    let train_idx: Vec<usize> = (0..shots.len()).filter(|&i| fold_of[i] != f).collect();
    let train: Vec<MeasuredShot> = train_idx.iter().map(|&i| shots[i].clone()).collect();
    let lookup = |table: &[(String, f64)], name: &str| table.iter().find(|(n, _)| n == name).map(|(_, v)| *v);
    let fitted: Option<Vec<(String, f64)>> = (|| {
        let mut ev = Evaluator::new(spec, train, opts.sim, opts.surface_levels).ok()?;
        if let Some(levels) = levels {
            let held: Vec<f64> = train_idx.iter().map(|&i| levels[i]).collect();
            ev.set_levels(&held, false);
        }
        let names = ev.names();
        let p0: Vec<f64> = names.iter().map(|n| lookup(full, n)).collect::<Option<_>>()?;
        let solver = LevenbergMarquardt {
            max_iterations: opts.fold_max_iterations,
            ..opts.solver
        };
        let out = ev.fit(&solver, &p0).ok()?;
        Some(names.into_iter().zip(out.params).collect())
    })();
    test.into_iter()
        .map(|i| {
            let sums = fitted.as_ref().and_then(|fitted| {
                let mut ev = Evaluator::new(spec, vec![shots[i].clone()], opts.sim, opts.surface_levels).ok()?;
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

/// Which physical effect is missing from `spec`, judged on `shots` (see the crate's documentation).
///
/// Fits the current model's free parameters to every shot (the baseline), then each candidate effect of
/// the library added with its own parameters free (see [`CandidateSetup`]), each cross-validated across
/// shots in [`SearchOptions::folds`] folds; `progress` is called before each model and at the end, on the
/// calling thread. Errors when the options are out of range, there are fewer than
/// [`SearchOptions::min_shots`] shots, or the current model cannot be fitted (naming the shot); a
/// candidate whose fit fails is listed with the reason instead.
pub fn find_missing_effect(
    spec: &ModelSpec,
    shots: &[MeasuredShot],
    options: &SearchOptions,
    progress: &dyn Fn(Progress),
) -> Result<Diagnosis, DiagnoseError> {
    find_missing_effect_with(spec, shots, &[], options, progress)
}

/// [`find_missing_effect`] with the evidence each shot carries besides its frames (drop height, measured
/// contact time, camera roll, spin: one [`ShotExtras`] per shot, or none), used by the trend tests of the
/// current model's failure report.
pub fn find_missing_effect_with(
    spec: &ModelSpec,
    shots: &[MeasuredShot],
    extras: &[ShotExtras],
    options: &SearchOptions,
    progress: &dyn Fn(Progress),
) -> Result<Diagnosis, DiagnoseError> {
    let clock = Instant::now();
    options.check()?;
    if shots.len() < options.min_shots {
        return Err(DiagnoseError::TooFewShots {
            shots: shots.len(),
            needed: options.min_shots,
        });
    }
    let setups = setups_for(spec, options)?;
    let k = options.folds.min(shots.len());
    let surfaces: Vec<&str> = shots.iter().map(|s| s.surface.as_str()).collect();
    let fold_of = stats::folds(&surfaces, k);
    let total = 1 + setups.len();
    progress(Progress {
        done: 0,
        total,
        what: "current model".into(),
        iteration: None,
        chi2_red: None,
    });
    let iterations = |done: usize, what: &str| {
        let what = what.to_string();
        move |i: usize, chi2_red: f64| {
            progress(Progress {
                done,
                total,
                what: what.clone(),
                iteration: Some(i),
                chi2_red: Some(chi2_red),
            })
        }
    };
    let base = run_model(
        spec,
        shots,
        &fold_of,
        k,
        options,
        Start {
            seed: None,
            scan: None,
            on_iteration: &iterations(0, "current model"),
            gate: None,
        },
    )
    .map_err(|e| DiagnoseError::Baseline {
        model: spec.origin.clone(),
        source: Box::new(e),
    })?;

    // The noise the decisions are measured against.
    let stated = {
        let (s2, n) = shots
            .iter()
            .flat_map(|s| &s.frames)
            .fold((0.0, 0usize), |(a, n), f| (a + f.sigma_m * f.sigma_m, n + 1));
        (s2 / n.max(1) as f64).sqrt()
    };
    let (noise_m, source) = match options.noise_m {
        Some(s) => (s, NoiseSource::Given),
        None => {
            let series: Vec<(Vec<f64>, Vec<f64>)> = shots
                .iter()
                .zip(&base.sims)
                .flat_map(|(shot, sim)| {
                    let t: Vec<f64> = shot.frames.iter().map(|f| f.t_s).collect();
                    let dx = shot.frames.iter().zip(&sim.samples).map(|(f, s)| f.x_m - s.observed.x);
                    let dy = shot.frames.iter().zip(&sim.samples).map(|(f, s)| f.y_m - s.observed.y);
                    [(t.clone(), dx.collect()), (t, dy.collect())]
                })
                .collect();
            match stats::white_noise(&series) {
                Some(s) if s > 0.0 => (s, NoiseSource::ThirdDifferences),
                _ => (stated, NoiseSource::Stated),
            }
        }
    };
    let noise = Noise {
        noise_m,
        source,
        stated_sigma_m: stated,
        ratio: noise_m / stated,
    };
    let given = options;
    // The floor the decisions are measured against; from here on `options` carries it as the tolerance.
    let floor = if options.learn_floor {
        crate::floor::learn(shots, &base.sims, noise_m, options.tolerance_m)
    } else {
        Floor {
            floor_m: options.tolerance_m,
            contact_allowance_m: options.tolerance_m,
            ..Floor::default()
        }
    };
    let options = &SearchOptions {
        tolerance_m: floor.floor_m,
        ..options.clone()
    };

    // The signature of the current model's residual.
    let cmp = compare(shots, &base.sims, extras, base.n_params)?;
    let report = diagnose(
        &cmp,
        &DiagnoseOptions {
            alpha: options.alpha,
            ..DiagnoseOptions::default()
        },
    );
    let mut phases: Vec<PhaseResidual> = cmp
        .overall
        .iter()
        .filter(|s| s.component != Component::Spin)
        .map(|s| PhaseResidual {
            phase: s.phase,
            component: s.component,
            n: s.n,
            rms_m: s.rms_m,
            systematic_m: excess(s.rms_m * s.rms_m, noise_m),
            chi2_share: if cmp.chi2 > 0.0 { s.chi2 / cmp.chi2 } else { 0.0 },
            chi2_red: s.chi2_red,
        })
        .collect();
    phases.sort_by(|a, b| b.chi2_share.total_cmp(&a.chi2_share));
    let signature = Signature {
        phases,
        // A trend counts only when it is both significant and larger than the measurement resolves
        // (the compare crate's materiality: COR 0.002, contact time 0.05 ms, …).
        trends: report
            .trends
            .iter()
            .filter(|t| t.significant && t.material)
            .cloned()
            .collect(),
        sentences: report.sentences.clone(),
    };

    let base_ms = base.summary.rms_m * base.summary.rms_m;
    let heldout_error_m = rms_of(base.heldout.iter().flatten());
    let baseline = Baseline {
        heldout_error_m,
        systematic_m: excess(base_ms, noise_m),
        misfit: false,
        misfit_reasons: Vec::new(),
        fit: base.summary.clone(),
        seconds: base.seconds,
    };

    let gate = BicGate {
        chi2: base.summary.chi2,
        n_params: base.n_params,
        n_res: base.per_shot.iter().map(|s| s.n).sum::<usize>() as f64,
        min_delta_bic: options.min_delta_bic,
    };
    // Every candidate, started from the current model's fitted values.
    let mut warm = spec.clone();
    set_values(&mut warm, &base.summary.parameters);
    let mut runs: Vec<(CandidateSetup, Result<ModelRun, String>)> = Vec::new();
    for (j, setup) in setups.into_iter().enumerate() {
        progress(Progress {
            done: j + 1,
            total,
            what: format!("+ {}", setup.effect),
            iteration: None,
            chi2_red: None,
        });
        let run = with_candidate(&warm, &setup)
            .map_err(|e| e.to_string())
            .and_then(|cspec| {
                let primary = setup.primary().map(|p| format!("{}.{p}", setup.effect));
                let scan = primary.as_deref().map(|name| Scan {
                    name,
                    noise_m,
                    floor_m: options.tolerance_m,
                    base_systematic_m: excess(base.summary.rms_m.powi(2), noise_m),
                });
                run_model(
                    &cspec,
                    shots,
                    &fold_of,
                    k,
                    options,
                    Start {
                        seed: base.levels.as_deref(),
                        scan: scan.as_ref(),
                        on_iteration: &iterations(j + 1, &format!("+ {}", setup.effect)),
                        gate: Some(gate),
                    },
                )
                .map_err(|e| e.to_string())
            });
        runs.push((setup, run));
    }

    let n_res = base.per_shot.iter().map(|s| s.n).sum::<usize>() as f64;
    let mut candidates: Vec<Candidate> = runs
        .iter()
        .map(|(setup, run)| evidence_of(setup, run, &base, n_res, noise_m, stated, options))
        .collect();
    // Holm over the candidates that have a held-out test.
    let ps: Vec<f64> = candidates
        .iter()
        .map(|c| c.evidence.as_ref().map(|e| e.heldout_p).unwrap_or(1.0))
        .collect();
    for (c, p) in candidates.iter_mut().zip(bouncelab_stats::holm(&ps)) {
        if let Some(e) = c.evidence.as_mut() {
            e.heldout_p_holm = p;
        }
    }
    let heldout_pairs: Vec<Vec<Option<f64>>> = runs
        .iter()
        .map(|(_, run)| match run {
            Ok(r) => r.heldout.iter().map(|h| h.map(|h| h.chi2)).collect(),
            Err(_) => vec![None; shots.len()],
        })
        .collect();
    let verdict_inputs = crate::verdict::Inputs {
        options,
        noise_m,
        floor: &floor,
        baseline,
        signature,
        heldout_chi2: heldout_pairs,
        heldout_ms: runs
            .iter()
            .map(|(_, run)| match run {
                Ok(r) => r.heldout.iter().map(|h| h.map(|h| h.sq_m2 / h.n as f64)).collect(),
                Err(_) => vec![None; shots.len()],
            })
            .collect(),
    };
    let (mut verdict, baseline, signature) = decide(&mut candidates, verdict_inputs);

    // A second effect: when the named one leaves a systematic held-out error above the floor, or none is
    // named but one explains part of the misfit, the search goes on from the model with it at its fitted
    // values.
    let first = match verdict.kind {
        VerdictKind::MissingEffect => candidates.first().filter(|c| {
            c.evidence
                .as_ref()
                .is_some_and(|e| excess(e.heldout_error_after.powi(2), noise_m) > options.tolerance_m)
        }),
        VerdictKind::NoneExplains => candidates.iter().find(|c| c.partly_explains),
        _ => None,
    };
    let then = match first {
        Some(c) if given.max_effects > 1 => {
            let next = then_from(&warm, c, &runs).and_then(|spec| {
                // The second search only names (a term proposal, if any, comes from this one).
                let o = SearchOptions {
                    max_effects: given.max_effects - 1,
                    propose_terms: false,
                    ..given.clone()
                };
                find_missing_effect_with(&spec, shots, extras, &o, progress).map_err(|e| e.to_string())
            });
            Some((
                c.effect.clone(),
                c.evidence.as_ref().map(|e| e.systematic_after_m),
                next,
            ))
        }
        _ => None,
    };
    let mut went_on = false;
    let then = match then {
        Some((a, left, Ok(next))) => {
            let named_next = matches!(next.verdict.kind, VerdictKind::MissingEffect | VerdictKind::Ambiguous);
            // `a` stays only if the second search's current model (with it) still holds its switch
            // parameter clearly away from neutral.
            let keeps = first.is_some_and(|c| {
                next.baseline
                    .fit
                    .parameters
                    .iter()
                    .find(|p| p.effect == c.effect && p.param == c.param)
                    .and_then(|p| p.std_error.map(|se| (p.value - c.neutral).abs() / se))
                    .is_some_and(|z| z >= options.min_param_z)
            });
            if keeps && (named_next || next.verdict.kind == VerdictKind::NoMissingEffect) {
                went_on = true;
                verdict.sentence = format!(
                    "{} With `{a}` added (systematic residual {} left), the search went on: {}",
                    verdict.sentence,
                    left.map(|m| format!("{:.1} µm", m * 1e6)).unwrap_or_else(|| "-".into()),
                    next.verdict.sentence
                );
                // `a` and what the second search named (if anything) together explain the data.
                let mut effects = vec![a.clone()];
                effects.extend(next.verdict.effects.iter().cloned());
                verdict.kind = if next.verdict.kind == VerdictKind::Ambiguous {
                    VerdictKind::Ambiguous
                } else {
                    VerdictKind::MissingEffect
                };
                verdict.effect = Some(a);
                verdict.effects = effects;
            } else {
                let so = if verdict.kind == VerdictKind::MissingEffect {
                    String::new()
                } else {
                    format!(", so `{a}` is not named")
                };
                verdict.sentence = format!(
                    "{} Going on from the model with `{a}` named nothing more ({}){so}.",
                    verdict.sentence,
                    next.verdict.kind.name()
                );
            }
            Some(Box::new(next))
        }
        Some((a, _, Err(why))) => {
            verdict.sentence = format!("{} Going on from the model with `{a}` failed: {why}", verdict.sentence);
            None
        }
        None => None,
    };

    let proposal = if options.propose_terms && verdict.kind == VerdictKind::NoneExplains && !went_on {
        let levels = base.levels.as_deref();
        let search = TermSearch {
            shots,
            fold_of: &fold_of,
            k,
            options,
            levels,
            noise_m,
            progress,
            total,
        };
        search.propose(&warm, heldout_error_m)
    } else {
        None
    };
    if let Some(p) = &proposal {
        verdict.sentence = format!("{} {}", verdict.sentence, proposal::sentence(p));
    }
    progress(Progress {
        done: total,
        total,
        what: "done".into(),
        iteration: None,
        chi2_red: None,
    });
    Ok(Diagnosis {
        verdict,
        candidates,
        baseline,
        signature,
        noise,
        floor,
        shots: shots.len(),
        folds: k,
        thresholds: Thresholds {
            alpha: options.alpha,
            min_delta_bic: options.min_delta_bic,
            min_param_z: options.min_param_z,
            tolerance_m: options.tolerance_m,
            phase_tolerance_m: options.phase_tolerance_m,
            explained_fraction: options.explained_fraction,
        },
        proposal,
        then,
        seconds: clock.elapsed().as_secs_f64(),
    })
}

/// `spec` with candidate `c` added at its fitted values (free, so the next search refits them).
fn then_from(
    spec: &ModelSpec,
    c: &Candidate,
    runs: &[(CandidateSetup, Result<ModelRun, String>)],
) -> Result<ModelSpec, String> {
    let (setup, run) = runs
        .iter()
        .find(|(s, _)| s.effect == c.effect)
        .ok_or_else(|| format!("no run of `{}`", c.effect))?;
    let run = run.as_ref().map_err(Clone::clone)?;
    let mut next = with_candidate(spec, setup).map_err(|e| e.to_string())?;
    set_values(&mut next, &run.summary.parameters);
    Ok(next)
}

/// What the term search needs of the missing-effect search.
struct TermSearch<'a> {
    shots: &'a [MeasuredShot],
    fold_of: &'a [usize],
    k: usize,
    options: &'a SearchOptions,
    levels: Option<&'a [f64]>,
    noise_m: f64,
    progress: &'a dyn Fn(Progress),
    total: usize,
}

impl TermSearch<'_> {
    /// Forward selection over the term library (see [`proposal`]): from `current` (the current model at its
    /// fitted values, held-out error `heldout_m`), each round fits every unused term as one more custom
    /// effect and keeps the one with the lowest held-out error, if its coefficient is at least
    /// `min_param_z` standard errors from zero and it removes at least [`proposal::MIN_TERM_FRACTION`] of
    /// the systematic held-out mean square left; it stops when a round keeps nothing, at
    /// [`proposal::MAX_TERMS`], or when what is left is within the tolerance. `None` when no term is kept.
    fn propose(&self, current: &ModelSpec, heldout_m: f64) -> Option<TermProposal> {
        let systematic = |e: f64| excess(e * e, self.noise_m);
        let mut current = current.clone();
        let mut err = heldout_m;
        let mut chosen: Vec<usize> = Vec::new();
        let mut terms: Vec<ProposedTerm> = Vec::new();
        let mut failed: Vec<String> = Vec::new();
        for round in 0..proposal::MAX_TERMS {
            let name = format!("term_{}", round + 1);
            let tries: Vec<usize> = (0..proposal::library_size()).filter(|i| !chosen.contains(i)).collect();
            let mut best: Option<(usize, ModelRun, f64, ModelSpec)> = None;
            for (j, &i) in tries.iter().enumerate() {
                let (phase, target, formula, start) = proposal::term(i);
                (self.progress)(Progress {
                    done: self.total.saturating_sub(1),
                    total: self.total,
                    what: format!("term {}/{}: {target} {formula} in {phase}", j + 1, tries.len()),
                    iteration: None,
                    chi2_red: None,
                });
                let run = with_term(&current, &name, i, start).and_then(|spec| {
                    let what = format!("term {target} {formula} in {phase}");
                    let on_iteration = |i: usize, chi2_red: f64| {
                        (self.progress)(Progress {
                            done: self.total.saturating_sub(1),
                            total: self.total,
                            what: what.clone(),
                            iteration: Some(i),
                            chi2_red: Some(chi2_red),
                        })
                    };
                    run_model(
                        &spec,
                        self.shots,
                        self.fold_of,
                        self.k,
                        self.options,
                        Start {
                            seed: self.levels,
                            scan: None,
                            on_iteration: &on_iteration,
                            gate: None,
                        },
                    )
                    .map(|run| (spec, run))
                    .map_err(|e| e.to_string())
                });
                let (spec, run) = match run {
                    Ok(r) => r,
                    Err(why) => {
                        failed.push(format!("{target} `{formula}` in {phase}: {why}"));
                        continue;
                    }
                };
                let e = rms_of(run.heldout.iter().flatten());
                if e.is_finite() && best.as_ref().is_none_or(|b| e < b.2) {
                    best = Some((i, run, e, spec));
                }
            }
            let Some((i, run, e, mut spec)) = best else {
                break;
            };
            let Some(c) = run
                .summary
                .parameters
                .iter()
                .find(|p| p.effect == name && p.param == "c")
            else {
                break;
            };
            let z = c.std_error.map_or(0.0, |s| c.value.abs() / s);
            let (before, after) = (systematic(err).powi(2), systematic(e).powi(2));
            if z < self.options.min_param_z || before - after < proposal::MIN_TERM_FRACTION * before {
                break;
            }
            let (phase, target, formula, _) = proposal::term(i);
            terms.push(ProposedTerm {
                name: name.clone(),
                phase: phase.into(),
                target: target.into(),
                formula: formula.into(),
                c: c.value,
                c_std_error: c.std_error,
                heldout_error_m: e,
            });
            set_values(&mut spec, &run.summary.parameters);
            chosen.push(i);
            current = spec;
            err = e;
            if systematic(e) <= self.options.tolerance_m {
                break;
            }
        }
        if terms.is_empty() {
            return None;
        }
        let model_toml = terms
            .iter()
            .zip(&chosen)
            .map(|(t, &i)| proposal::term_toml(&t.name, i, t.c))
            .collect::<Vec<_>>()
            .join("\n");
        Some(TermProposal {
            terms,
            library_size: proposal::library_size(),
            heldout_before_m: heldout_m,
            heldout_after_m: err,
            systematic_before_m: systematic(heldout_m),
            systematic_after_m: systematic(err),
            model_toml,
            failed,
        })
    }
}

/// `spec` with library term `i` added as the custom effect `name`, its coefficient free from `start`.
fn with_term(spec: &ModelSpec, name: &str, i: usize, start: f64) -> Result<ModelSpec, String> {
    // The model crate reads the term as it would from a user's file, so what is proposed is what a file
    // with it would give.
    let parsed = ModelSpec::parse(&proposal::term_toml(name, i, start), "term library").map_err(|e| e.to_string())?;
    let effect = parsed
        .effects
        .into_iter()
        .find(|e| e.name == name)
        .ok_or_else(|| format!("the term library's text has no effect {name}"))?;
    let mut out = spec.clone();
    out.effects.push(effect);
    Ok(out)
}

/// The candidate setups of a search, in library order.
fn setups_for(spec: &ModelSpec, options: &SearchOptions) -> Result<Vec<CandidateSetup>, DiagnoseError> {
    let names: Vec<String> = match &options.candidates {
        Some(list) => {
            for n in list {
                let info = library_effect(n)?;
                if info.base {
                    return Err(DiagnoseError::BaseEffect { effect: n.clone() });
                }
            }
            list.iter().filter(|n| !spec.has_effect(n)).cloned().collect()
        }
        None => candidate_names(spec).into_iter().map(str::to_string).collect(),
    };
    for s in &options.setups {
        library_effect(&s.effect)?;
    }
    names
        .iter()
        .map(|n| match options.setups.iter().find(|s| &s.effect == n) {
            Some(s) => Ok(s.clone()),
            None => CandidateSetup::default_for(n),
        })
        .collect()
}

/// `√max(0, ms − noise²)`: the systematic part of a mean square, m.
pub(crate) fn excess(ms: f64, noise_m: f64) -> f64 {
    (ms - noise_m * noise_m).max(0.0).sqrt()
}

/// RMS over the residuals of the given shots, m (0 when there are none).
fn rms_of<'a>(sums: impl Iterator<Item = &'a ShotSums>) -> f64 {
    let (sq, n) = sums.fold((0.0, 0usize), |(a, n), s| (a + s.sq_m2, n + s.n));
    if n == 0 { 0.0 } else { (sq / n as f64).sqrt() }
}

/// A candidate's evidence against the baseline (Holm's adjustment and the checks come later).
fn evidence_of(
    setup: &CandidateSetup,
    run: &Result<ModelRun, String>,
    base: &ModelRun,
    n_res: f64,
    noise_m: f64,
    stated_sigma_m: f64,
    opts: &SearchOptions,
) -> Candidate {
    let param = setup.primary().unwrap_or("-").to_string();
    let neutral = library_effect(&setup.effect)
        .ok()
        .and_then(|i| i.params.iter().find(|p| p.name == param))
        .map(|p| p.neutral)
        .unwrap_or(0.0);
    let mut cand = Candidate {
        effect: setup.effect.clone(),
        rank: 0,
        explains: false,
        partly_explains: false,
        checks: Checks::default(),
        reasons: Vec::new(),
        error_before: base.summary.rms_m,
        heldout_error_before: rms_of(base.heldout.iter().flatten()),
        param: param.clone(),
        neutral,
        evidence: None,
        failed: None,
        seconds: 0.0,
    };
    let run = match run {
        Ok(r) => {
            cand.seconds = r.seconds;
            r
        }
        Err(e) => {
            cand.failed = Some(e.clone());
            return cand;
        }
    };
    // Paired held-out comparison over the shots both predicted.
    let pairs: Vec<(&ShotSums, &ShotSums)> = base
        .heldout
        .iter()
        .zip(&run.heldout)
        .filter_map(|(a, b)| Some((a.as_ref()?, b.as_ref()?)))
        .collect();
    let tiny = f64::MIN_POSITIVE;
    let d: Vec<f64> = pairs
        .iter()
        .map(|(a, b)| (a.chi2.max(tiny) / b.chi2.max(tiny)).ln())
        .collect();
    let (log_ratio, p) = stats::one_sided_t(&d);
    // Without folds, the fit's own RMS stands in for the held-out error (its lower bound).
    let (before_ho, after_ho) = if run.cross_validated {
        (
            rms_of(pairs.iter().map(|(a, _)| *a)),
            rms_of(pairs.iter().map(|(_, b)| *b)),
        )
    } else {
        (rms_of(base.heldout.iter().flatten()), run.summary.rms_m)
    };
    cand.heldout_error_before = before_ho;
    let ms0 = before_ho * before_ho;
    let ms1 = after_ho * after_ho;
    let denom = (ms0 - noise_m * noise_m).max(opts.tolerance_m * opts.tolerance_m);
    let s = &run.summary;
    let chi0 = base.summary.chi2.max(tiny);
    let delta_bic = n_res * (s.chi2.max(tiny) / chi0).ln() + (run.n_params as f64 - base.n_params as f64) * n_res.ln();
    let primary = s
        .parameters
        .iter()
        .find(|p| p.effect == setup.effect && p.param == param);
    let param_z = primary
        .and_then(|p| p.std_error.map(|se| (p.value - neutral).abs() / se))
        .filter(|z| z.is_finite());
    // With σ-weighted residuals, se = √c / ‖J⊥‖ (J⊥ the parameter's Jacobian column after the others'
    // span is taken out, c the covariance scale), so a change Δ moves the positions by an RMS of about
    // Δ·σ̄·‖J⊥‖/√n = Δ·σ̄·√c / (se·√n) once the other parameters have absorbed what they can.
    // Only for a one-parameter candidate: with a second parameter of its own (Hunt–Crossley's exponent),
    // that one is not determined near neutral and the switch's standard error says nothing there.
    let own_params = setup.free.len();
    let detection_limit = primary
        .and_then(|p| p.std_error)
        .filter(|_| own_params == 1)
        .and_then(|se| {
            let c = s.chi2_red.max(1.0);
            let per_unit = stated_sigma_m * c.sqrt() / (se * n_res.sqrt());
            let limit = (opts.min_param_z * se).max(opts.tolerance_m / per_unit);
            limit.is_finite().then_some(limit)
        });
    cand.evidence = Some(Evidence {
        error_after: s.rms_m,
        error_fall: base.summary.rms_m / s.rms_m,
        delta_bic,
        heldout_error_after: after_ho,
        heldout_log_ratio: log_ratio,
        heldout_p: p,
        heldout_p_holm: p,
        shots_improved: [d.iter().filter(|v| **v > 0.0).count(), d.len()],
        explained_fraction: ((ms0 - ms1) / denom).min(1.0),
        systematic_after_m: excess(s.rms_m * s.rms_m, noise_m),
        chi2_red_after: s.chi2_red,
        chi2_red_noise_after: s.rms_m * s.rms_m / (noise_m * noise_m),
        param_value: primary.map(|p| p.value).unwrap_or(neutral),
        param_interval: primary.and_then(|p| p.interval),
        param_z,
        detection_limit,
        cross_validated: run.cross_validated,
        fit: run.summary.clone(),
    });
    cand
}
