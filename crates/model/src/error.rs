//! Errors of the model crate: each names the file, effect, parameter or instant it is about.

use thiserror::Error;

/// Everything that can go wrong while reading a model or simulating it.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The model file is not valid TOML, or a value has the wrong type.
    #[error("{origin}: {message}")]
    Syntax { origin: String, message: String },
    /// An effect name that is neither built in nor declared `kind = "custom"`.
    #[error("{origin}: unknown effect `{name}` (known effects: {known})")]
    UnknownEffect {
        origin: String,
        name: String,
        known: String,
    },
    /// A parameter the effect does not have.
    #[error("{origin}: effect `{effect}` has no parameter `{param}` (its parameters: {known})")]
    UnknownParam {
        origin: String,
        effect: String,
        param: String,
        known: String,
    },
    /// A parameter without a default was not given.
    #[error("{origin}: effect `{effect}` needs parameter `{param}` ({unit}): {doc}")]
    MissingParam {
        origin: String,
        effect: String,
        param: String,
        unit: String,
        doc: String,
    },
    /// A parameter value outside its physical range, or bounds that do not hold it.
    #[error("{origin}: {effect}.{param} = {value}: {reason}")]
    InvalidValue {
        origin: String,
        effect: String,
        param: String,
        value: f64,
        reason: String,
    },
    /// A custom formula that does not parse or names something unknown.
    #[error("{0}")]
    BadFormula(Box<FormulaError>),
    /// A surface the model file has no values for.
    #[error("{origin}: no surface `{surface}` in the model (surfaces: {known})")]
    UnknownSurface {
        origin: String,
        surface: String,
        known: String,
    },
    /// The initial state or options cannot start a simulation.
    #[error("cannot simulate: {0}")]
    BadStart(String),
    /// The ball never reached the surface within the simulated time.
    #[error("the ball did not reach the surface within {max_time_s} s of simulated time")]
    NoImpact { max_time_s: f64 },
    /// The state became NaN or infinite (a custom term returned NaN, or parameters blew the model up).
    #[error("the simulation became non-finite at t = {t_s} s in {phase} (check custom terms and parameters)")]
    NonFinite { t_s: f64, phase: &'static str },
    /// Friction switched between sticking and sliding again and again at one instant.
    #[error(
        "friction switched between sticking and sliding {switches} times at t = {t_s} s in {phase} without the time advancing (the force grazes its Coulomb limit there); change the tangential parameters slightly"
    )]
    Chatter {
        t_s: f64,
        phase: &'static str,
        switches: usize,
    },
    /// The integrator needed more steps than allowed (the step size collapsed).
    #[error(
        "the integrator needed more than {max_steps} steps (at t = {t_s} s in {phase}); the model is too stiff for the tolerance"
    )]
    TooManySteps {
        max_steps: usize,
        t_s: f64,
        phase: &'static str,
    },
}

/// Where and why a custom formula was refused.
#[derive(Debug, Error)]
#[error("{origin}: effects.{effect}.{field}: {message}\n    {formula}\n    {caret}")]
pub struct FormulaError {
    /// The model file.
    pub origin: String,
    /// The custom term's name.
    pub effect: String,
    /// The formula's key (normal, tangential, …).
    pub field: String,
    /// The formula as written.
    pub formula: String,
    /// A `^` under the place the problem was found (blank when no position is known).
    pub caret: String,
    /// What is wrong.
    pub message: String,
}
