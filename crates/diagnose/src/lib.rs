//! Which physical effect is missing from the contact model: every effect of the library that the model
//! does not have is added in turn, fitted to all shots with the model's own parameters refitted, and judged
//! against the current model by what it predicts of shots it was not fitted to.
//!
//! The main design choice is that no decision trusts the tracker's σ: real σ can be off by half, and
//! tracked positions carry small systematic errors in contact. So the noise level is measured from the
//! residuals themselves (their third differences), BIC uses the variance estimated from the residuals,
//! the held-out comparison is a paired test across shots of *ratios* of held-out χ² (in which σ cancels),
//! and a candidate must remove a material amount of error (more than a tolerance in metres, and most of
//! the current model's systematic part), with its switch parameter clearly away from its neutral value.
//! Candidates that explain the data about equally well are all named as ambiguous rather than one picked;
//! when the current model misfits and none explains it, the residual's signature (where χ² sits, the
//! trends across conditions) is shown instead of a name. Cross-validation is K-fold across shots
//! (default 6 folds, each fit warm-started at the full fit), which costs a fixed number of refits however
//! many shots a session has: leave-one-shot-out would cost one refit per shot per candidate.
//!
//! When none explains it, a formula term is looked for in a small library of forces in δ, δ̇, the slip and
//! the contact's history (the patch's tangential displacement u_t, ∫δ dt) (forward selection, each term
//! fitted through the simulator: [`TermProposal`]). The thresholds are measured against a floor learned
//! from the session's free flight ([`Floor`]). When the named effect leaves a misfit above the floor, or one
//! explains only part of it, the search goes on from the model with it and may name a second
//! ([`Diagnosis::then`]).
//!
//! [`find_missing_effect`] returns a [`Diagnosis`] (`diagnosis.json`); [`find_missing_effect_from`] starts
//! from the current model as the caller already fitted and compared it ([`FittedBaseline`]); [`add_effect_to_model_toml`] adds the
//! named effect to the user's `model.toml`, comments kept. See `docs/diagnosis.md`.

mod candidates;
mod diagnosis;
mod error;
mod evaluate;
mod evidence;
mod floor;
mod model_file;
mod options;
mod proposal;
mod run;
mod search;
mod stats;
mod terms;
mod verdict;

pub use candidates::CandidateSetup;
pub use diagnosis::{
    Baseline, Candidate, Checks, Diagnosis, Evidence, Floor, Noise, NoiseSource, PhaseResidual, Signature, Thresholds,
    Verdict, VerdictKind, WorstShot,
};
pub use error::DiagnoseError;
pub use evaluate::{FitSummary, FittedValue};
pub use floor::FLOOR_MARGIN_SE;
pub use model_file::add_effect_to_model_toml;
pub use options::{SearchOptions, SearchProgress};
pub use proposal::{ProposedTerm, TermProposal};
pub use search::{FittedBaseline, find_missing_effect, find_missing_effect_from, find_missing_effect_with};
pub use verdict::MIN_SHOTS_FOR_ONE_SHOT;
