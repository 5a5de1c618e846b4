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
    #[error("{origin}: {effect}.{param} = {}: {reason}", num(*.value))]
    InvalidValue {
        origin: String,
        effect: String,
        param: String,
        value: f64,
        reason: String,
    },
    /// A number of the model file outside its physical range (gravity, the ball's values).
    #[error("{origin}: {key} = {} {reason}", num(*.value))]
    OutOfRange {
        origin: String,
        key: String,
        value: f64,
        /// Why, with the range and its unit.
        reason: String,
    },
    /// The model has nothing that pushes the ball back out of the surface.
    #[error(
        "{origin}{surface}: the model has no elastic normal force: at {probe_mm} mm of penetration it pushes the ball out with P = {force_n} N ({detail}); add `[effects.spring]` with k > 0 (N/m), `[effects.hertz]` with k_h > 0, or a custom term with a `normal` formula"
    )]
    NoNormalForce {
        origin: String,
        /// ` (surface NAME)` or empty.
        surface: String,
        probe_mm: f64,
        force_n: f64,
        /// What the file sets, e.g. `spring.k = 0` or `no effects at all`.
        detail: String,
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
    /// The ball's centre went below the surface: nothing in the model stops it.
    #[error(
        "the ball sank through the surface (penetration {depth_m} m, more than its radius, at t = {t_s} s): the model's normal force cannot stop it; give it a spring (k > 0) or another elastic normal force"
    )]
    SankThrough { t_s: f64, depth_m: f64 },
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

/// A number as a person writes it: plain when short, with an exponent when very large or small.
pub(crate) fn num(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e6).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
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
