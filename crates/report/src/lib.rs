//! The session report: one self-contained HTML file, with every plot drawn as inline SVG, that a lab
//! keeps with its data and opens offline. The crate's design choice is that it knows nothing of the
//! pipeline: [`render_html`] takes a [`Report`] of plain data structs (trajectories, every measured quantity,
//! the fitted model's curves, the fit, the diagnosis; the ANCOVA and its inference as `bouncelab-stats` gives
//! them) and returns a `String`,
//! deterministically (same input, same bytes), escaping every text that came from input files and
//! drawing what it can of odd numbers (NaN, infinities, empty or constant series) without panicking.
//! Plots come from a small hand-written SVG module (see `svg.rs` for why not plotters), so the page
//! needs no fonts, scripts or network; a few lines of inline script only open a shot's plots from a link.
//!
//! ```
//! use bouncelab_report::{Report, SessionInfo, render_html};
//! let report = Report {
//!     title: "Drop tests, clay".into(),
//!     session: SessionInfo { path: "sessions/2024-05-03".into(), ..Default::default() },
//!     ..Default::default()
//! };
//! let html = render_html(&report);
//! assert!(html.starts_with("<!DOCTYPE html>"));
//! assert!(html.contains("not available: not computed"));
//! ```

mod change;
mod cor;
mod data;
mod diagnosis;
mod error;
mod fit;
mod fmt;
mod force;
mod html;
mod page;
mod shots;
mod stats;
mod summary;
mod svg;
/// Synthetic reports for tests, examples and the browser check; not part of the library (enable the
/// `testutil` feature in `[dev-dependencies]` to use it from another crate's tests).
#[cfg(any(test, feature = "testutil"))]
pub mod testutil;
mod thin;

use std::io::Write;
use std::path::Path;

pub use data::{
    Candidate, ContactForce, CurvePoint, DiagnosisSection, EarlierVerdict, FitParameter, FitSummary, ForceSample,
    FrameImage, Measured, MeasuredPoint, ModelChange, ModelCurve, ModelPoint, ModelVersion, ObliqueRow, Phase,
    PhaseSpan, Report, Residual, Section, SessionInfo, ShotBeforeAfter, ShotMeasurement, ShotPlot, ShotPrediction,
    SignatureRow, SurfaceError, VerdictKind,
};
pub use error::ReportError;

/// The report's sections in page order: (element id, heading). Every section is always present; one
/// without data says why in one line.
pub const SECTIONS: &[(&str, &str)] = &[
    ("summary", "Summary"),
    ("warnings", "Warnings and notes"),
    ("diagnosis", "Diagnosis: which effect is missing"),
    ("model-change", "Model change: before and after"),
    ("fit", "Model fit"),
    ("cor", "Measured quantities and the model against impact speed"),
    ("ancova", "ANCOVA"),
    ("comparisons", "Comparisons of surfaces at equal impact speed"),
    ("residual-diagnostics", "ANCOVA residual diagnostics"),
    ("shots", "Shots"),
    ("timings", "Timings"),
];

/// The report as one HTML5 document (UTF-8), with inline CSS and SVG and no external resources.
///
/// Deterministic: the same report gives the same bytes (the renderer never reads the clock; see
/// [`SessionInfo::generated_at`]). Never panics on any numbers in the input.
pub fn render_html(report: &Report) -> String {
    page::render(report)
}

/// Renders `report` and writes it to `path` atomically: into a temporary file in the same folder, flushed
/// to disk, then renamed over `path`, so a reader never sees half a report and an interrupted run leaves
/// the previous one in place.
pub fn write_report(path: impl AsRef<Path>, report: &Report) -> Result<(), ReportError> {
    let path = path.as_ref();
    let html = render_html(report);
    let name = path.file_name().ok_or_else(|| ReportError::NoFileName {
        path: path.to_path_buf(),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    // Unique per process and call, so concurrent writers never share a temporary file.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".{}-{call}.tmp", std::process::id()));
    let tmp = dir.join(tmp_name);
    let io = |source| ReportError::Write {
        path: path.to_path_buf(),
        source,
    };
    let result = (|| {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(html.as_bytes())?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(e));
    }
    Ok(())
}
