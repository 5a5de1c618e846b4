//! The crate's one error type.

use std::path::PathBuf;

use thiserror::Error;

/// What can go wrong when writing a report; rendering itself cannot fail.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ReportError {
    /// Creating, writing or renaming the report file failed.
    #[error("cannot write the report {}: {source}", path.display())]
    Write {
        /// The report's path.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The path names no file (e.g. `/` or `..`).
    #[error("the report path {} names no file", path.display())]
    NoFileName {
        /// The path given.
        path: PathBuf,
    },
}
