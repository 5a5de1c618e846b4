//! The crate's one error type.

use std::path::PathBuf;

/// Everything that can go wrong while reading a clip or a session.
///
/// Every variant names the file (and, for frames, the frame index; for settings, the field) it is about, so
/// that its `Display` text is a complete one-line message for the user.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FramesError {
    /// A file or folder could not be read (missing, permissions, I/O failure).
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A file the session needs does not exist.
    #[error("{}: not found ({what})", path.display())]
    MissingFile {
        /// The expected file.
        path: PathBuf,
        /// Why it is needed.
        what: &'static str,
    },
    /// The clip path is not a folder (or does not exist).
    #[error("{}: not a clip folder (no such directory)", path.display())]
    NotAFolder {
        /// The path given as a clip.
        path: PathBuf,
    },
    /// The clip folder holds no frame files.
    #[error(
        "{}: no frames in this folder (looked for .png, .tif, .tiff, .bmp, .pgm, .ppm, .pnm, .jpg, .jpeg)",
        dir.display()
    )]
    NoFrames {
        /// The clip folder.
        dir: PathBuf,
    },
    /// A frame file's name has no number to order it by.
    #[error("{}: frame file name has no number to order it by", path.display())]
    NoNumber {
        /// The frame file.
        path: PathBuf,
    },
    /// The last number in a frame file's name does not fit in 64 bits.
    #[error("{}: frame number in the file name is too large", path.display())]
    NumberTooLarge {
        /// The frame file.
        path: PathBuf,
    },
    /// Two frame files carry the same number.
    #[error("{} and {}: both are frame number {number}", first.display(), second.display())]
    DuplicateNumber {
        /// The frame number both names end in.
        number: u64,
        /// The first file.
        first: PathBuf,
        /// The second file.
        second: PathBuf,
    },
    /// A frame could not be decoded (unreadable, truncated, unsupported variant).
    #[error("{} (frame {index}): cannot decode: {message}", path.display())]
    Decode {
        /// The frame file.
        path: PathBuf,
        /// The frame's index in the clip (0-based, dropped frames counted).
        index: u64,
        /// The decoder's message.
        message: String,
    },
    /// A frame's size differs from the clip's first frame.
    #[error(
        "{} (frame {index}): frame is {}×{} px but the clip's first frame {} is {}×{} px",
        path.display(), found.0, found.1, first.display(), expected.0, expected.1
    )]
    SizeMismatch {
        /// The frame file.
        path: PathBuf,
        /// The frame's index in the clip.
        index: u64,
        /// This frame's width and height, in pixels.
        found: (u32, u32),
        /// The first frame's width and height, in pixels.
        expected: (u32, u32),
        /// The clip's first frame file.
        first: PathBuf,
    },
    /// A frame rate that is not a finite number in (0, 1e7] frames per second.
    #[error("{origin}: {field} = {value} is not a usable frame rate (need a number > 0 and ≤ 10,000,000 frames/s)")]
    BadFps {
        /// Where the value came from: a file path, or `command line`.
        origin: String,
        /// The field, e.g. `[camera] fps`.
        field: String,
        /// The offending value as written.
        value: String,
    },
    /// A TOML file is not valid TOML.
    #[error("{}: malformed TOML: {message}", path.display())]
    Toml {
        /// The file.
        path: PathBuf,
        /// The parser's message, with line and column.
        message: String,
    },
    /// A required key is missing from a settings file.
    #[error("{}: {field} missing", path.display())]
    MissingKey {
        /// The file.
        path: PathBuf,
        /// The key, e.g. `[ball] diameter_m`.
        field: String,
    },
    /// A key of a settings file has the wrong type or an impossible value.
    #[error("{}: {field}: {problem}", path.display())]
    BadValue {
        /// The file.
        path: PathBuf,
        /// The key, e.g. `[ball] mass_kg`.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A CSV file is malformed (ragged rows, bad encoding, empty clip name …).
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(" line {l}")).unwrap_or_default())]
    Csv {
        /// The file.
        path: PathBuf,
        /// The 1-based line, when known.
        line: Option<u64>,
        /// What is wrong.
        message: String,
    },
    /// A required CSV column is missing from the header.
    #[error("{}: required column `{column}` missing from the header", path.display())]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column's name.
        column: String,
    },
    /// A CSV cell that must be a number is not one.
    #[error("{} line {line}, column `{column}`: `{value}` is not a number", path.display())]
    BadNumber {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The column's name.
        column: String,
        /// The cell as written.
        value: String,
    },
    /// The same clip is listed twice in `clips.csv`.
    #[error("{} lines {first_line} and {second_line}: clip `{clip}` is listed twice", path.display())]
    DuplicateClip {
        /// The `clips.csv` file.
        path: PathBuf,
        /// The clip name.
        clip: String,
        /// The line of the first listing.
        first_line: u64,
        /// The line of the second listing.
        second_line: u64,
    },
    /// A clip listed in `clips.csv` has no folder.
    #[error("clip `{clip}` is listed in clips.csv but its folder {} does not exist", expected.display())]
    ClipAbsent {
        /// The clip name.
        clip: String,
        /// The folder it should be in.
        expected: PathBuf,
    },
    /// The decoding thread pool could not be built.
    #[error("cannot start {threads} decoding threads: {message}")]
    ThreadPool {
        /// Requested number of threads.
        threads: usize,
        /// Rayon's message.
        message: String,
    },
    /// A video file could not be opened or read (feature `opencv`).
    #[error("{}{}: {message}", path.display(), frame.map(|f| format!(" (frame {f})")).unwrap_or_default())]
    Video {
        /// The video file.
        path: PathBuf,
        /// The frame index, when the problem is about one frame.
        frame: Option<u64>,
        /// What went wrong.
        message: String,
    },
}

/// Shorthand for results of this crate.
pub type Result<T, E = FramesError> = std::result::Result<T, E>;
