//! The crate's one error type.

use thiserror::Error;

/// Everything that can go wrong in this crate; each variant names the field, term or group at fault.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum StatsError {
    /// Not enough observations (in total or in one group) for the requested analysis.
    #[error("too few observations for {what}: have {have}, need at least {need}")]
    TooFewObservations {
        /// What was being computed or which group was too small.
        what: String,
        /// Observations available.
        have: usize,
        /// Observations required.
        need: usize,
    },
    /// A categorical factor in the model has only one level, so it has no contrast to estimate.
    #[error("factor `{factor}` has a single level `{level}`")]
    SingleLevel {
        /// The factor's name.
        factor: String,
        /// Its only level.
        level: String,
    },
    /// The design matrix is rank deficient: this term is a linear combination of the terms before it.
    #[error("singular design: term `{term}` is collinear with the terms before it")]
    SingularDesign {
        /// The term whose column was found to be redundant.
        term: String,
    },
    /// A name that the data set holds but the model does not use as a term of the needed kind (marginal
    /// means need a factor term, a quadratic test a covariate term).
    #[error("`{name}` is not a {kind} term of the model")]
    NotATerm {
        /// The name asked for.
        name: String,
        /// `factor` or `covariate`.
        kind: &'static str,
    },
    /// Data the computation cannot use although every value is finite: residuals that are all equal, sums
    /// that overflow.
    #[error("cannot compute {what}: {why}")]
    Degenerate {
        /// What was being computed.
        what: String,
        /// Why it cannot be.
        why: String,
    },
    /// A weight that is not a positive finite number.
    #[error("weight at row {row} is {value}; weights must be positive and finite")]
    InvalidWeight {
        /// Zero-based row index.
        row: usize,
        /// The weight given.
        value: f64,
    },
    /// A NaN or infinite value in the input.
    #[error("non-finite value in `{field}` at row {row}")]
    NonFinite {
        /// The column.
        field: String,
        /// Zero-based row index.
        row: usize,
    },
    /// A column's length differs from the response's.
    #[error("column `{field}` has {found} values, expected {expected}")]
    LengthMismatch {
        /// The column.
        field: String,
        /// Number of observations of the response.
        expected: usize,
        /// Number of values given.
        found: usize,
    },
    /// A term, factor or covariate name that the data set does not hold (or holds twice).
    #[error("unknown or duplicate variable `{name}`")]
    UnknownVariable {
        /// The name asked for.
        name: String,
    },
    /// An observation lacks a value every other observation has.
    #[error("row {row} has no value for `{field}`")]
    MissingValue {
        /// The column.
        field: String,
        /// Zero-based row index.
        row: usize,
    },
    /// A parameter outside its domain (alpha not in (0, 1), k < 2, df < 1, ...).
    #[error("parameter `{name}` = {value} is out of range ({expected})")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range.
        expected: &'static str,
    },
    /// A CSV cell that should hold a number does not.
    #[error("column `{field}` row {row}: cannot parse `{value}` as a number")]
    Parse {
        /// The column.
        field: String,
        /// Zero-based data row index.
        row: usize,
        /// The cell's text.
        value: String,
    },
    /// A session's ANCOVA could not be fitted (the shots are counted in the message).
    #[error("{shots} shot(s): {error}")]
    Session {
        /// Shots in the session.
        shots: usize,
        /// Why the fit failed.
        error: Box<StatsError>,
    },
    /// Reading or writing CSV failed.
    #[error("CSV: {0}")]
    Csv(#[from] csv::Error),
}
