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
    /// The clip path does not exist.
    #[error("{}: no such clip folder or camera file", path.display())]
    NotAFolder {
        /// The path given as a clip.
        path: PathBuf,
    },
    /// The clip path is a file that is not a camera file this crate reads.
    #[error(
        "{}: not a clip: a clip is a folder of frames or one camera file (.cihx/.cih/.mraw, .cine, .tif/.tiff stack{})",
        path.display(),
        if cfg!(feature = "opencv") { ", .mp4/.avi/.mov" } else { "" }
    )]
    NotAClip {
        /// The path given as a clip.
        path: PathBuf,
    },
    /// A video file, in a build without the `opencv` feature.
    #[error(
        "{}: video files are read through OpenCV: build bouncelab with `--features opencv` (needs Debian's \
         libopencv-dev clang libclang-dev), or export the frames first, e.g. \
         `ffmpeg -i VIDEO -vsync 0 FOLDER/img_%06d.png` (and give the real frame rate: videos often store a playback rate)",
        path.display()
    )]
    VideoNeedsFeature {
        /// The video file.
        path: PathBuf,
    },
    /// A camera file's header (or the data it describes) is missing a field, or a field has a value this
    /// reader does not accept (unknown bit depth, sizes that disagree with the file, an offset outside it).
    #[error("{}: {field}: {problem}", path.display())]
    CameraHeader {
        /// The header file (`.cihx`, `.cih`, `.cine`, `.tif` …) or the data file the field describes.
        path: PathBuf,
        /// The header field, e.g. `<colorInfo><bit>`, `Color Bit`, `BITMAPINFOHEADER.biBitCount`.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A Photron header without its `.mraw` data file (or a `.mraw` without a header) beside it.
    #[error("{}: {what} not found beside it (expected {})", path.display(), expected.display())]
    MissingCompanion {
        /// The file that was given.
        path: PathBuf,
        /// What is missing, e.g. `the .mraw data file`.
        what: &'static str,
        /// Where it was looked for.
        expected: PathBuf,
    },
    /// A frame larger than the configured limit ([`crate::ClipOptions::max_frame_pixels`]): the header is
    /// probably corrupt, and nothing is allocated for it.
    #[error(
        "{}: frame size {width}×{height} px is over the limit of {limit} pixels (a corrupt header? if it is real, raise the limit with --max-frame-pixels)",
        path.display()
    )]
    FrameTooLarge {
        /// The camera file.
        path: PathBuf,
        /// Width from the header, in pixels.
        width: u64,
        /// Height from the header, in pixels.
        height: u64,
        /// The limit, in pixels.
        limit: u64,
    },
    /// A multi-page TIFF among other frame files of a folder: each page would be lost but the first.
    #[error(
        "{}: a multi-page TIFF stack in a folder of other frames; give the stack itself as the clip (its pages are the frames)",
        path.display()
    )]
    MultiPageInFolder {
        /// The TIFF file.
        path: PathBuf,
    },
    /// The region of interest does not fit in the clip's frames.
    #[error(
        "clip {}: region of interest [{}, {}, {}, {}] (from {}) does not fit in its {}×{} px frames",
        clip.display(), roi.x, roi.y, roi.width, roi.height, origin, size.0, size.1
    )]
    RoiOutsideImage {
        /// The clip.
        clip: PathBuf,
        /// The region, in pixels.
        roi: crate::settings::Roi,
        /// Where it was set (a file path, or `command line`).
        origin: String,
        /// The frames' width and height, in pixels.
        size: (u32, u32),
    },
    /// The contact line lies outside the clip's frames.
    #[error(
        "clip {}: contact line y = {line_y_px} px (from {origin}) is outside its frames (0 ≤ y ≤ {} px)",
        clip.display(), size.1.saturating_sub(1)
    )]
    LineOutsideImage {
        /// The clip.
        clip: PathBuf,
        /// The line's y at the image's centre column, in pixels.
        line_y_px: f64,
        /// Where it was set (a file path, or `command line`).
        origin: String,
        /// The frames' width and height, in pixels.
        size: (u32, u32),
    },
    /// `clips.csv` rows whose required cells are still empty (as `bouncelab init` leaves them).
    #[error(
        "{}: fill these cells before analysing: {}",
        path.display(),
        rows.iter()
            .map(|r| format!("line {} `{}`: {}", r.line, r.clip, r.columns.join(", ")))
            .collect::<Vec<_>>()
            .join("; ")
    )]
    UnfilledColumns {
        /// The `clips.csv` file.
        path: PathBuf,
        /// Every row with empty cells, in file order.
        rows: Vec<UnfilledRow>,
    },
    /// `bouncelab init` would overwrite an existing file.
    #[error("{}: exists already; move it away or give --force to overwrite it", path.display())]
    WouldOverwrite {
        /// The file.
        path: PathBuf,
    },
    /// A `clips.csv` clip name without extension that matches several camera files.
    #[error(
        "clip `{clip}` matches several camera files ({}): write the file name with its extension in clips.csv",
        candidates.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    AmbiguousClip {
        /// The clip name.
        clip: String,
        /// The files it could be.
        candidates: Vec<PathBuf>,
    },
    /// The clip folder holds no frame files.
    #[error(
        "{}: no frames in this folder (looked for .png, .tif, .tiff, .bmp, .pgm, .ppm, .pnm, .jpg, .jpeg, or one camera file: .cihx/.cih/.mraw, .cine)",
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
    /// A frame rate that is not a finite number in [100, 1e7] frames per second.
    #[error("{origin}: {field} = {value} is not a usable frame rate (need a number from 100 to 10,000,000 frames/s)")]
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
    /// A clip listed in `clips.csv` has no folder or camera file.
    #[error("clip `{clip}` is listed in clips.csv but there is no folder or camera file {}", expected.display())]
    ClipAbsent {
        /// The clip name.
        clip: String,
        /// The folder (or file) it should be.
        expected: PathBuf,
    },
    /// A `clips.csv` clip name that leads outside the session folder (an absolute path, or `..`).
    #[error(
        "clip `{clip}`: a clip name must name a folder or camera file inside the session folder {} (no absolute path, no `..`)",
        session.display()
    )]
    ClipOutsideSession {
        /// The clip name.
        clip: String,
        /// The session folder.
        session: PathBuf,
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

/// One `clips.csv` row with required cells left empty.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnfilledRow {
    /// The 1-based line in `clips.csv`.
    pub line: u64,
    /// The clip name.
    pub clip: String,
    /// The empty required columns, in header order.
    pub columns: Vec<String>,
}

/// Shorthand for results of this crate.
pub type Result<T, E = FramesError> = std::result::Result<T, E>;
