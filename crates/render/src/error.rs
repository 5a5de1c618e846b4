//! The render crate's one error type.

use std::path::PathBuf;
use thiserror::Error;

/// Everything that can go wrong while reading a scenario or rendering it; each variant names the file,
/// field, shot or path it is about.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RenderError {
    /// The scenario file cannot be read.
    #[error("{path}: cannot read the scenario: {source}")]
    Read {
        /// The scenario file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The scenario is not valid TOML or a key has the wrong type or is unknown.
    #[error("{origin}: {message}")]
    Syntax {
        /// The scenario file (or preset) it came from.
        origin: String,
        /// What is wrong, with the line when known.
        message: String,
    },
    /// A value outside its valid range.
    #[error("{origin}: {field} = {value}: {reason}")]
    InvalidValue {
        /// The scenario file (or preset).
        origin: String,
        /// The field, as a TOML path (`camera.fps`, `shots[3].drop_height_m`).
        field: String,
        /// The value as written.
        value: String,
        /// Why it is refused.
        reason: String,
    },
    /// A shot names a surface the scenario does not define.
    #[error("{origin}: {field}: unknown surface `{surface}` (surfaces: {known})")]
    UnknownSurface {
        /// The scenario file (or preset).
        origin: String,
        /// Where the name appears (`shots[2].surface`, `grid.surfaces`).
        field: String,
        /// The unknown name.
        surface: String,
        /// The surfaces the scenario defines.
        known: String,
    },
    /// A shot switches on an effect that `[extra_effects]` does not define.
    #[error("{origin}: {field}: effect `{effect}` is not defined in [extra_effects] (defined: {known})")]
    UnknownEffect {
        /// The scenario file (or preset).
        origin: String,
        /// Where the name appears.
        field: String,
        /// The unknown name.
        effect: String,
        /// The effects `[extra_effects]` defines.
        known: String,
    },
    /// The physics part (`[model]`, surface values, `[extra_effects]`) is refused by the model crate, or a
    /// shot cannot be simulated.
    #[error("{origin}: {context}: {source}")]
    Model {
        /// The scenario file (or preset).
        origin: String,
        /// Which shot or table.
        context: String,
        /// The model crate's error.
        source: Box<bouncelab_model::ModelError>,
    },
    /// No preset of that name.
    #[error("unknown preset `{name}` (presets: {known})")]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The presets that exist.
        known: String,
    },
    /// The output folder already holds a session or truth folder.
    #[error("{path}: already exists and is not empty (refusing to mix sessions; remove it or use --force)")]
    OutputExists {
        /// The non-empty folder.
        path: PathBuf,
    },
    /// Writing an output file failed.
    #[error("{path}: cannot write: {message}")]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// What failed.
        message: String,
    },
}

impl RenderError {
    pub(crate) fn write(path: &std::path::Path, e: impl std::fmt::Display) -> RenderError {
        RenderError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }
}
