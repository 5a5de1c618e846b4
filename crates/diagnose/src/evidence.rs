//! A candidate's evidence against the current model: its fit to all shots, the paired held-out comparison,
//! its switch parameter and the smallest value of it the session could have shown.

use crate::candidates::CandidateSetup;
use crate::diagnosis::{Candidate, Checks, Evidence};
use crate::evaluate::ShotSums;
use crate::options::SearchOptions;
use crate::run::{BicGate, ModelRun};
use crate::stats::{self, excess, rms_of};
use crate::{FitSummary, FittedValue};

/// A candidate's evidence against the baseline `base` (Holm's adjustment and the checks come later); `gate`
/// holds the baseline's χ², parameter and residual counts for ΔBIC.
pub(crate) fn evidence_of(
    setup: &CandidateSetup,
    run: &Result<ModelRun, String>,
    base: &ModelRun,
    gate: &BicGate,
    noise_m: f64,
    stated_sigma_m: f64,
    opts: &SearchOptions,
) -> Candidate {
    let param = setup.primary().unwrap_or("-").to_string();
    let neutral = setup.neutral();
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
    let held = Heldout::of(base, run);
    cand.heldout_error_before = held.before_m;
    let ms0 = held.before_m * held.before_m;
    let ms1 = held.after_m * held.after_m;
    let denom = (ms0 - noise_m * noise_m).max(opts.tolerance_m * opts.tolerance_m);
    let s = &run.summary;
    let delta_bic = gate.delta_bic(s.chi2, run.n_params);
    let primary = s
        .parameters
        .iter()
        .find(|p| p.effect == setup.effect && p.param == param);
    let param_z = primary
        .and_then(|p| p.std_error.map(|se| (p.value - neutral).abs() / se))
        .filter(|z| z.is_finite());
    let detection_limit = primary
        .and_then(|p| p.std_error)
        .filter(|_| setup.free.len() == 1)
        .and_then(|se| detection_limit(se, s, gate.n_res, stated_sigma_m, opts));
    cand.evidence = Some(Evidence {
        error_after: s.rms_m,
        error_fall: base.summary.rms_m / s.rms_m,
        delta_bic,
        heldout_error_after: held.after_m,
        heldout_log_ratio: held.log_ratio,
        heldout_p: held.p,
        heldout_p_holm: held.p,
        shots_improved: [
            held.log_ratios.iter().filter(|v| **v > 0.0).count(),
            held.log_ratios.len(),
        ],
        explained_fraction: ((ms0 - ms1) / denom).min(1.0),
        systematic_after_m: excess(s.rms_m * s.rms_m, noise_m),
        chi2_red_after: s.chi2_red,
        chi2_red_noise_after: s.rms_m * s.rms_m / (noise_m * noise_m),
        param_value: primary.map(|p: &FittedValue| p.value).unwrap_or(neutral),
        param_interval: primary.and_then(|p| p.interval),
        param_z,
        detection_limit,
        cross_validated: run.cross_validated,
        kept_at_neutral: run.kept_at_neutral,
        fit: run.summary.clone(),
    });
    cand
}

/// The paired held-out comparison of a candidate's run with the baseline's, over the shots both predicted.
struct Heldout {
    /// Per shot: ln(baseline's held-out χ² / the candidate's).
    log_ratios: Vec<f64>,
    /// Mean of `log_ratios`.
    log_ratio: f64,
    /// One-sided p of a positive mean (the candidate predicts better).
    p: f64,
    /// Held-out RMS of the baseline and the candidate over those shots, m; without folds, the candidate's
    /// own fit RMS stands in for its held-out error (its lower bound) and the baseline's is over all shots.
    before_m: f64,
    after_m: f64,
}

impl Heldout {
    fn of(base: &ModelRun, run: &ModelRun) -> Heldout {
        let pairs: Vec<(&ShotSums, &ShotSums)> = base
            .heldout
            .iter()
            .zip(&run.heldout)
            .filter_map(|(a, b)| Some((a.as_ref()?, b.as_ref()?)))
            .collect();
        let tiny = f64::MIN_POSITIVE;
        let log_ratios: Vec<f64> = pairs
            .iter()
            .map(|(a, b)| (a.chi2.max(tiny) / b.chi2.max(tiny)).ln())
            .collect();
        let (log_ratio, p) = stats::one_sided_t(&log_ratios);
        let (before_m, after_m) = if run.cross_validated {
            (
                rms_of(pairs.iter().map(|(a, _)| *a)),
                rms_of(pairs.iter().map(|(_, b)| *b)),
            )
        } else {
            (rms_of(base.heldout.iter().flatten()), run.summary.rms_m)
        };
        Heldout {
            log_ratios,
            log_ratio,
            p,
            before_m,
            after_m,
        }
    }
}

/// The smallest value of a one-parameter candidate's switch (its distance from neutral, in its unit) the
/// session would have shown, from its standard error `se` in the fit `s` over `n_res` residuals.
///
/// With σ-weighted residuals, se = √c / ‖J⊥‖ (J⊥ the parameter's Jacobian column after the others' span is
/// taken out, c the covariance scale), so a change Δ moves the positions by an RMS of about
/// Δ·σ̄·‖J⊥‖/√n = Δ·σ̄·√c / (se·√n) once the other parameters have absorbed what they can. Only for a
/// one-parameter candidate: with a second parameter of its own (Hunt–Crossley's exponent), that one is not
/// determined near neutral and the switch's standard error says nothing there.
fn detection_limit(se: f64, s: &FitSummary, n_res: f64, stated_sigma_m: f64, opts: &SearchOptions) -> Option<f64> {
    let c = s.chi2_red.max(1.0);
    let per_unit = stated_sigma_m * c.sqrt() / (se * n_res.sqrt());
    let limit = (opts.min_param_z * se).max(opts.tolerance_m / per_unit);
    limit.is_finite().then_some(limit)
}
