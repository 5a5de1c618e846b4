//! Errors of the compare crate: each names the shot it is about.

use bouncelab_fit::FitError;
use thiserror::Error;

/// Everything that can stop a comparison.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CompareError {
    /// The lists of shots, simulations (and extras, when given) differ in length.
    #[error("{shots} shots but {other} {what}")]
    CountMismatch {
        /// Number of shots.
        shots: usize,
        /// Number of the other items.
        other: usize,
        /// What the other items are ("simulations", "extras").
        what: &'static str,
    },
    /// A simulation whose samples do not match its shot's frames.
    #[error("shot `{shot}`: {reason}")]
    Mismatch {
        /// The shot's name.
        shot: String,
        /// What does not match.
        reason: String,
    },
    /// Simulating the shots failed (from [`compare_problem`](crate::compare_problem)).
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The CSV could not be written.
    #[error("writing comparison.csv: {0}")]
    Csv(#[from] csv::Error),
}
