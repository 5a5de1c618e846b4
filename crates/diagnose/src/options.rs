//! Settings of the search, with the thresholds of the decision rule, and the progress it reports.

use crate::{CandidateSetup, DiagnoseError};
use bouncelab_fit::{LevenbergMarquardt, SimOptions};
use serde::{Deserialize, Serialize};

/// Settings of [`find_missing_effect`](crate::find_missing_effect). Every threshold of the decision rule
/// is here, with its default and why (see `docs/diagnosis.md`).
#[derive(Debug, Clone, PartialEq)]
pub struct SearchOptions {
    /// Library effects to try; `None` (default): every library effect that is not a base effect and not
    /// already in the model.
    pub candidates: Option<Vec<String>>,
    /// Free parameters and starting values overriding [`CandidateSetup::default_for`], per effect.
    pub setups: Vec<CandidateSetup>,
    /// Folds of the cross-validation across shots (default 6; at least 2; as many as shots gives
    /// leave-one-shot-out). Shots are dealt to folds round-robin within each surface.
    pub folds: usize,
    /// Fewest shots a diagnosis accepts (default 6): held-out errors are compared shot by shot.
    pub min_shots: usize,
    /// Significance level of the paired held-out test (Holm-corrected over the candidates), of the paired
    /// test between the two best candidates, and of the trend tests of the current model's failure report
    /// (default 0.01).
    pub alpha: f64,
    /// Least fall of BIC, `n·ln(RSS/n) + p·ln n` with σ-weighted residuals (the noise variance estimated
    /// from the residuals, so a mis-stated σ cancels), for a candidate to count (default 10: "very strong"
    /// on Kass and Raftery's scale).
    pub min_delta_bic: f64,
    /// Least distance of the candidate's switch parameter from its neutral value, in standard errors
    /// (default 4).
    pub min_param_z: f64,
    /// The tracker's extra systematic error in contact, m (default 8e-6, 0.02 px at 4e-4 m/px), which the
    /// free flight cannot show: the ball flattened and partly hidden by the surface (about 5–9 µm per phase
    /// and component on a clean rendered session, against 2–3 µm in the incoming flight). With
    /// [`SearchOptions::learn_floor`] the floor is the flight's measured structure, the rim's change between
    /// the flights and this in quadrature, plus a margin of their standard errors (see `floor.rs`); without,
    /// this is the floor. A model whose systematic residual is within the floor fits; a candidate
    /// must remove at least the floor of held-out error; two candidates whose held-out errors differ by less
    /// cannot be told apart. Raise it when the tracking in contact is worse.
    pub tolerance_m: f64,
    /// Learn the floor from the session's free flight (default true): see `docs/diagnosis.md` and
    /// [`Floor`](crate::Floor).
    pub learn_floor: bool,
    /// Systematic residual allowed in one phase and component, m (default 30e-6, 0.075 px), or three times
    /// the floor's estimate when the session's tracking is that much worse: above it the current model
    /// misfits there even if the total is within [`SearchOptions::tolerance_m`] (a 0.05 px tracking error
    /// in contact stays below it).
    pub phase_tolerance_m: f64,
    /// Least fraction of the current model's systematic held-out mean square (above the noise) that a
    /// candidate leaving more than [`SearchOptions::tolerance_m`] of systematic error must remove to be
    /// named (default 0.9: what is left is at most a third of the systematic RMS). A library effect that
    /// only resembles the missing one removes 50–85 % on the test sessions; the missing one, ≥ 99 %.
    pub explained_fraction: f64,
    /// The white-noise level of the tracked positions, m; `None` (default): estimated from the current
    /// model's residuals (their third differences), which does not depend on the σ the tracker stated.
    pub noise_m: Option<f64>,
    /// Count significant and material trends of the output errors (COR, μ, outgoing velocity, contact time) across
    /// conditions as evidence that the current model misfits (default true).
    pub use_trends: bool,
    /// Fit each shot's surface level as a nuisance, as the fit crate's surface offsets (default false;
    /// `analyze` turns it on). Use it with the `surface_level` effect free per surface in the model and a
    /// stated σ of each shot's surface line ([`MeasuredShot::surface_sigma_m`]): the shot's level is then
    /// a deviation from its surface's within that σ. A free level per shot (no σ stated) also absorbs most
    /// of a missing contact effect (restitution damping's 65 µm misfit falls to 16 µm on a tracked
    /// session, the size of tracking artefacts). Every full fit alternates between the shared parameters
    /// (levels held) and the levels (profiled shot by shot); a fold's fit holds its training shots at the
    /// full fit's levels and profiles each left-out shot's own.
    ///
    /// [`MeasuredShot::surface_sigma_m`]: bouncelab_fit::MeasuredShot::surface_sigma_m
    pub surface_levels: bool,
    /// The solver of every fit to all shots: the fit crate's, with `ftol = xtol = 1e-7` (a relative change
    /// of χ² of 1e-7 decides nothing here, and stopping there makes the search three times faster) and at
    /// most 50 iterations (a candidate that cannot fit the data creeps along its bound otherwise).
    pub solver: LevenbergMarquardt,
    /// Most iterations of each warm-started fit (default 15): the cross-validation fits, which start at the
    /// fit to all shots, a few iterations from their own optimum, and with surface levels the joint fit
    /// that ends each fit to all shots, which starts where the fits by turns ended.
    pub fold_max_iterations: usize,
    /// Integration settings of every simulation.
    pub sim: SimOptions,
    /// When no library effect explains a misfit, look for a formula term that does (default true): forward
    /// selection over a small library of force terms in δ, δ̇, the slip and the contact's history
    /// ([`TermProposal`](crate::TermProposal)),
    /// each fitted and judged by held-out error like a candidate. Costs one candidate's fit per term tried
    /// (14 for the first term, 13 for a second).
    pub propose_terms: bool,
    /// Most effects one diagnosis names one after the other (default 2): when the first leaves a systematic
    /// misfit above the floor, or explains only part of it, the search goes on from the model with it.
    /// 1 stops after the first.
    pub max_effects: usize,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            candidates: None,
            setups: Vec::new(),
            folds: 6,
            min_shots: 6,
            alpha: 0.01,
            min_delta_bic: 10.0,
            min_param_z: 4.0,
            tolerance_m: 8e-6,
            learn_floor: true,
            phase_tolerance_m: 30e-6,
            explained_fraction: 0.9,
            noise_m: None,
            use_trends: true,
            surface_levels: false,
            solver: LevenbergMarquardt {
                ftol: 1e-7,
                xtol: 1e-7,
                max_iterations: 50,
                ..LevenbergMarquardt::default()
            },
            fold_max_iterations: 15,
            sim: SimOptions::default(),
            propose_terms: true,
            max_effects: 2,
        }
    }
}

impl SearchOptions {
    pub(crate) fn check(&self) -> Result<(), DiagnoseError> {
        let bad = |option: &'static str, value: String, reason: &str| {
            Err(DiagnoseError::BadOption {
                option,
                value,
                reason: reason.to_string(),
            })
        };
        if self.folds < 2 {
            return bad("folds", self.folds.to_string(), "at least 2");
        }
        if self.fold_max_iterations == 0 || self.solver.max_iterations == 0 {
            return bad(
                "fold_max_iterations",
                format!("{} (solver: {})", self.fold_max_iterations, self.solver.max_iterations),
                "at least 1 iteration",
            );
        }
        if self.max_effects == 0 {
            return bad("max_effects", self.max_effects.to_string(), "at least 1");
        }
        if self.min_shots < 3 {
            return bad("min_shots", self.min_shots.to_string(), "at least 3");
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return bad("alpha", self.alpha.to_string(), "between 0 and 1");
        }
        if !(self.min_delta_bic.is_finite() && self.min_delta_bic >= 0.0) {
            return bad("min_delta_bic", self.min_delta_bic.to_string(), "finite and ≥ 0");
        }
        if !(self.min_param_z.is_finite() && self.min_param_z >= 0.0) {
            return bad("min_param_z", self.min_param_z.to_string(), "finite and ≥ 0");
        }
        if !(self.tolerance_m.is_finite() && self.tolerance_m > 0.0) {
            return bad("tolerance_m", self.tolerance_m.to_string(), "finite and > 0 (metres)");
        }
        if !(self.phase_tolerance_m.is_finite() && self.phase_tolerance_m > 0.0) {
            return bad(
                "phase_tolerance_m",
                self.phase_tolerance_m.to_string(),
                "finite and > 0 (metres)",
            );
        }
        if !(self.explained_fraction > 0.0 && self.explained_fraction <= 1.0) {
            return bad("explained_fraction", self.explained_fraction.to_string(), "in (0, 1]");
        }
        if let Some(s) = self.noise_m
            && !(s.is_finite() && s > 0.0)
        {
            return bad("noise_m", s.to_string(), "finite and > 0 (metres)");
        }
        Ok(())
    }
}

/// What the search is doing, reported before each fit of a model, after every solver iteration of each fit
/// to all shots (`iteration`, `chi2_red`), and at the end: a progress bar shows `done / total` and `what`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SearchProgress {
    /// Models fitted so far (each with its cross-validation).
    pub done: usize,
    /// Models to fit: the current one plus every candidate.
    pub total: usize,
    /// What comes next: "current model", "+ hertz", or "done".
    pub what: String,
    /// The solver iteration just finished in the fit of `what` to all shots (0 is its start); `None` when
    /// the call announces the model rather than an iteration.
    #[serde(default)]
    pub iteration: Option<usize>,
    /// The reduced χ² (χ²/ν against the tracker's σ) at that iteration.
    #[serde(default)]
    pub chi2_red: Option<f64>,
}
