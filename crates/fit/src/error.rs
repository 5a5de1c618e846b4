//! Errors of the fit crate: each names the shot or parameter it is about.

use bouncelab_model::ModelError;
use thiserror::Error;

/// Everything that can stop a fit before it has a result.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FitError {
    /// The model file cannot be built (missing parameter, bad formula, …).
    #[error(transparent)]
    Model(Box<ModelError>),
    /// No shots were given.
    #[error("nothing to fit: no shots")]
    NoShots,
    /// The model has no free parameter the shots can inform.
    #[error("nothing to fit: no free parameter applies to the shots' surfaces (set `free = true` in the model file)")]
    NoFreeParameters,
    /// A shot whose input cannot be used (no frames, bad σ, a frame before the start, …).
    #[error("shot `{shot}`: {reason}")]
    InvalidShot {
        /// The shot's name.
        shot: String,
        /// What is wrong.
        reason: String,
    },
    /// A shot's surface the model file has no values for.
    #[error("shot `{shot}`: surface `{surface}` is not in the model (its surfaces: {known})")]
    UnknownSurface {
        /// The shot's name.
        shot: String,
        /// Its surface.
        surface: String,
        /// The model's surfaces.
        known: String,
    },
    /// A shot whose start state cannot start a simulation (inside the surface, not finite, …).
    #[error("shot `{shot}`: bad start: {reason}")]
    BadStart {
        /// The shot's name.
        shot: String,
        /// Why.
        reason: String,
    },
    /// Fewer residuals than free parameters.
    #[error("{residuals} residuals cannot determine {params} parameters")]
    TooFewResiduals {
        /// Number of residuals.
        residuals: usize,
        /// Number of free parameters.
        params: usize,
    },
    /// The simulation of a shot failed.
    #[error("shot `{shot}`: simulation failed: {source}")]
    Simulation {
        /// The shot's name.
        shot: String,
        /// The simulator's error.
        source: Box<ModelError>,
    },
    /// A residual function returned a vector of the wrong length or non-finite values (a programming error
    /// in a custom problem).
    #[error("bad residuals: {0}")]
    BadResiduals(String),
    /// A free parameter of the model file that the fit result does not hold (the result comes from
    /// another model file).
    #[error("the fit has no value for the free parameter `{name}` (was it fitted with another model file?)")]
    MissingParameter {
        /// The parameter's name (`clay:spring.k`).
        name: String,
    },
}

impl From<ModelError> for FitError {
    fn from(e: ModelError) -> Self {
        FitError::Model(Box::new(e))
    }
}
