//! Shared contact-model parameters fitted to the measured trajectories of many shots at once.
//!
//! Given measured shots ([`MeasuredShot`]: frames in the local frame, the incoming state taken from the
//! measurement) and a [`ModelSpec`] whose parameters say which are free (globally, or per surface when
//! `[surfaces.NAME]` sets them), [`fit`] finds the free parameters that make every simulated trajectory
//! match its measured one in the weighted least-squares sense, with standard errors and confidence
//! intervals. The design follows argmin: a [`Problem`] (implementing [`LeastSquares`]) owns the residuals,
//! a [`LevenbergMarquardt`] solver written here minimises them (finite-difference Jacobian, parameter
//! scaling, bounds by projection) and reports every iteration to an [`IterationObserver`], and the run ends with a
//! [`Termination`] reason the report can show. Shots are simulated in parallel with results collected in
//! shot order, so a fit is deterministic.

mod covariance;
mod error;
mod held_levels;
mod measurement;
mod nuisance;
mod params;
mod predict;
mod problem;
mod result;
mod shot;
mod solver;
mod surface_level;
mod suspect;
/// Synthetic shots for tests (the `testutil` feature, enabled by dependents' dev-dependencies only).
#[cfg(any(test, feature = "testutil"))]
pub mod testutil;

pub use bouncelab_model::{ModelSpec, SimOptions, State};
pub use covariance::{Covariance, covariance, identified_inverse, normal_inverse};
pub use error::FitError;
pub use measurement::{observe, observes, true_start};
pub use params::FreeParam;
pub use predict::{ForceSample, ImpactPrediction, fitted_model, predict_impact};
pub use problem::{Problem, profile_surface_level, surface_prior, weighted_residuals};
pub use result::{FitResult, FittedParam, MAX_RELATIVE_STD_ERROR, ObliqueRow, ShotFit, SurfaceError};
pub use shot::{MeasuredFrame, MeasuredOutputs, MeasuredShot, StartState};
pub use solver::{
    Differences, Iteration, IterationObserver, LeastSquares, LevenbergMarquardt, LogObserver, NoObserver,
    SolverOutcome, Termination,
};
pub use surface_level::{SURFACE_LEVEL_RANGE_M, add_surface_level};
pub use suspect::{
    ARC_DEGREE, MIN_ARC_FRAMES, SUSPECT_FLIGHT_CHI2_MIN, SUSPECT_FLIGHT_FACTOR, arc_residuals, flight_structure_chi2,
    suspect_flights,
};

/// Settings of a fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// The solver and its tolerances.
    pub solver: LevenbergMarquardt,
    /// Integration settings for every simulation.
    pub sim: SimOptions,
    /// Confidence level of the intervals (default 0.95).
    pub confidence: f64,
    /// Simulate the shots on several threads (default true; the result is identical either way).
    pub parallel: bool,
    /// Fit each shot's surface level as a nuisance (default true; see [`Problem::with_surface_offsets`]).
    pub surface_offsets: bool,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            solver: LevenbergMarquardt::default(),
            sim: SimOptions::default(),
            confidence: 0.95,
            parallel: true,
            surface_offsets: true,
        }
    }
}

/// Fits the free parameters of `spec` to `shots`, starting from the model file's values.
///
/// Errors name the shot when an input cannot be used or its simulation fails at the starting values; a
/// failure during the search ends it at the last good point with [`Termination::SimulationFailed`].
pub fn fit(
    spec: &ModelSpec,
    shots: Vec<MeasuredShot>,
    options: &FitOptions,
    observer: &mut dyn IterationObserver,
) -> Result<FitResult, FitError> {
    let problem = Problem::new(spec, shots, options.sim)?
        .with_parallel(options.parallel)
        .with_surface_offsets(options.surface_offsets);
    fit_problem(&problem, &spec.origin, options, observer)
}

/// Fits an already built [`Problem`]; `model` names the model in the result.
pub fn fit_problem(
    problem: &Problem,
    model: &str,
    options: &FitOptions,
    observer: &mut dyn IterationObserver,
) -> Result<FitResult, FitError> {
    let out = options.solver.run(problem, &problem.initial(), observer)?;
    result::build(problem, &out, model, options.confidence)
}
