//! The term search: when no library effect explains the misfit, a formula term from a small library
//! ([`proposal`]) added by forward selection, each fitted through the simulator and cross-validated.

use crate::SearchProgress;
use crate::options::SearchOptions;
use crate::proposal::{self, ProposedTerm, TermProposal};
use crate::run::{ModelRun, Start, run_model};
use crate::stats::{self, rms_of};
use bouncelab_fit::MeasuredShot;
use bouncelab_model::ModelSpec;

/// What the term search needs of the missing-effect search.
pub(crate) struct TermSearch<'a> {
    pub shots: &'a [MeasuredShot],
    pub fold_of: &'a [usize],
    pub k: usize,
    pub options: &'a SearchOptions,
    pub levels: Option<&'a [f64]>,
    pub noise_m: f64,
    pub progress: &'a dyn Fn(SearchProgress),
    pub total: usize,
}

/// The best term of one round: its library index, its run, held-out error (m) and the model with it.
struct RoundBest {
    term: usize,
    run: ModelRun,
    heldout_m: f64,
    spec: ModelSpec,
}

impl TermSearch<'_> {
    /// Forward selection over the term library (see [`proposal`]): from `current` (the current model at its
    /// fitted values, held-out error `heldout_m`), each round fits every unused term as one more custom
    /// effect and keeps the one with the lowest held-out error, if its coefficient is at least
    /// `min_param_z` standard errors from zero and it removes at least [`proposal::MIN_TERM_FRACTION`] of
    /// the systematic held-out mean square left; it stops when a round keeps nothing, at
    /// [`proposal::MAX_TERMS`], or when what is left is within the tolerance. `None` when no term is kept.
    pub fn propose(&self, current: &ModelSpec, heldout_m: f64) -> Option<TermProposal> {
        let systematic = |e: f64| stats::excess(e * e, self.noise_m);
        let mut current = current.clone();
        let mut err = heldout_m;
        let mut chosen: Vec<usize> = Vec::new();
        let mut terms: Vec<ProposedTerm> = Vec::new();
        let mut failed: Vec<String> = Vec::new();
        for round in 0..proposal::MAX_TERMS {
            let name = format!("term_{}", round + 1);
            let Some(RoundBest {
                term: i,
                run,
                heldout_m: e,
                mut spec,
            }) = self.best_term(&current, &name, &chosen, &mut failed)
            else {
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
            crate::candidates::set_values(&mut spec, &run.summary.parameters);
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

    /// One round: every term not yet `chosen` added to `current` as the custom effect `name` and fitted;
    /// the one with the lowest held-out error, if any fitted (those that failed are added to `failed`).
    fn best_term(
        &self,
        current: &ModelSpec,
        name: &str,
        chosen: &[usize],
        failed: &mut Vec<String>,
    ) -> Option<RoundBest> {
        let tries: Vec<usize> = (0..proposal::library_size()).filter(|i| !chosen.contains(i)).collect();
        let mut best: Option<RoundBest> = None;
        for (j, &i) in tries.iter().enumerate() {
            let (phase, target, formula, start) = proposal::term(i);
            (self.progress)(SearchProgress {
                done: self.total.saturating_sub(1),
                total: self.total,
                what: format!("term {}/{}: {target} {formula} in {phase}", j + 1, tries.len()),
                iteration: None,
                chi2_red: None,
            });
            let run = with_term(current, name, i, start).and_then(|spec| {
                let what = format!("term {target} {formula} in {phase}");
                let on_iteration = |i: usize, chi2_red: f64| {
                    (self.progress)(SearchProgress {
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
            if e.is_finite() && best.as_ref().is_none_or(|b| e < b.heldout_m) {
                best = Some(RoundBest {
                    term: i,
                    run,
                    heldout_m: e,
                    spec,
                });
            }
        }
        best
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
