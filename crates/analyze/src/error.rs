//! Why an analysis could not run.

use std::path::PathBuf;

/// An error of [`crate::analyze`]: each names the file, shot or field it is about.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AnalyzeError {
    /// The session folder could not be loaded (missing or malformed `session.toml`/`clips.csv`, a clip listed
    /// but absent …).
    #[error(transparent)]
    Session(#[from] bouncelab_frames::FramesError),
    /// The results store failed.
    #[error(transparent)]
    Store(#[from] bouncelab_store::StoreError),
    /// The model file is unusable.
    #[error(transparent)]
    Model(#[from] bouncelab_model::ModelError),
    /// The fit could not run.
    #[error("fitting the model")]
    Fit(#[from] bouncelab_fit::FitError),
    /// The comparison could not run.
    #[error("comparing the model with the measurements")]
    Compare(#[from] bouncelab_compare::CompareError),
    /// The missing-effect search could not run.
    #[error("searching for the missing effect")]
    Diagnose(#[from] bouncelab_diagnose::DiagnoseError),
    /// The report could not be written.
    #[error(transparent)]
    Report(#[from] bouncelab_report::ReportError),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A CSV file could not be written.
    #[error("{}: {source}", path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// Why.
        source: csv::Error,
    },
    /// No shot of the session could be measured, so nothing can be fitted.
    #[error(
        "{session}: none of the {total} shot(s) could be measured; first failure: {first} (the failures, and the trajectories that were measured, are in the files written)"
    )]
    NothingMeasured {
        /// The session folder.
        session: PathBuf,
        /// Shots listed.
        total: usize,
        /// The first shot's failure, "clip: reason".
        first: String,
        /// What was written all the same: `estimates.csv` (no rows), the measured trajectories,
        /// `report.html` with every shot's failure.
        written: Vec<PathBuf>,
    },
    /// A stored estimate lacks the detail later stages need (written by an older program).
    #[error(
        "shot {clip}: its stored estimate predates this program; delete the store or touch the clip's folder to measure it again"
    )]
    StaleStore {
        /// The clip.
        clip: String,
    },
}
