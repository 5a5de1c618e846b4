//! Errors of the diagnose crate: each names the effect, shot, option or model file it is about.

use bouncelab_compare::CompareError;
use bouncelab_fit::FitError;
use bouncelab_model::ModelError;
use thiserror::Error;

/// Everything that can stop a diagnosis or an edit of `model.toml`.
///
/// A candidate effect whose fit fails does not stop the search: it is listed in the diagnosis with the
/// reason. Only the current model (the baseline) failing is an error.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DiagnoseError {
    /// Too few shots to cross-validate (held-out errors need several shots).
    #[error("{shots} shots: the diagnosis needs at least {needed} (held-out errors are compared across shots)")]
    TooFewShots {
        /// Shots given.
        shots: usize,
        /// Shots needed ([`SearchOptions::min_shots`](crate::SearchOptions::min_shots)).
        needed: usize,
    },
    /// An option outside its meaningful range.
    #[error("option `{option}` = {value}: {reason}")]
    BadOption {
        /// The option's name in [`SearchOptions`](crate::SearchOptions).
        option: &'static str,
        /// Its value, as text.
        value: String,
        /// The range it must be in.
        reason: String,
    },
    /// The fit given as the current model's ([`FittedBaseline`](crate::FittedBaseline)) is not of this model
    /// on these shots.
    #[error("the fit given for the current model `{model}` does not match the search: {why}")]
    BaselineMismatch {
        /// The model file.
        model: String,
        /// What differs (parameters, shots, surface levels).
        why: String,
    },
    /// The current model could not be fitted to the shots (a bad shot, a simulation failing at the
    /// model's own values, no free parameter, …): there is nothing to compare candidates with.
    #[error("fitting the current model `{model}`: {source}")]
    Baseline {
        /// The model file.
        model: String,
        /// The fit's error (names the shot).
        source: Box<FitError>,
    },
    /// The residuals of the current model could not be compared with the shots.
    #[error("comparing the current model with the shots: {0}")]
    Compare(#[from] Box<CompareError>),
    /// An effect that is not in the library.
    #[error("unknown effect `{effect}` (library effects: {known})")]
    UnknownEffect {
        /// The name asked for.
        effect: String,
        /// The library's effects.
        known: String,
    },
    /// A base effect (spring, damping, coulomb) offered as a candidate or added again.
    #[error("effect `{effect}` is part of the base model; it cannot be a candidate")]
    BaseEffect {
        /// The effect.
        effect: String,
    },
    /// The model file already has the effect.
    #[error("{origin}: the model already has effect `{effect}` ([effects.{effect}])")]
    AlreadyPresent {
        /// The model file.
        origin: String,
        /// The effect.
        effect: String,
    },
    /// A value given for a parameter the effect does not have, or outside its physical range.
    #[error("effect `{effect}`, parameter `{param}` = {value}: {reason}")]
    BadValue {
        /// The effect.
        effect: String,
        /// The parameter.
        param: String,
        /// The value given.
        value: f64,
        /// Why it is refused.
        reason: String,
    },
    /// The model file text is not valid TOML or not a valid model (before or after the edit).
    #[error("{origin}: {message}")]
    ModelFile {
        /// The model file.
        origin: String,
        /// What is wrong.
        message: String,
    },
    /// The model's effects cannot be built (a missing parameter, a bad custom formula).
    #[error(transparent)]
    Model(#[from] Box<ModelError>),
}

impl From<ModelError> for DiagnoseError {
    fn from(e: ModelError) -> Self {
        DiagnoseError::Model(Box::new(e))
    }
}

impl From<CompareError> for DiagnoseError {
    fn from(e: CompareError) -> Self {
        DiagnoseError::Compare(Box::new(e))
    }
}
