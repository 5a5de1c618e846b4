//! A clip — a folder of frame files or one camera file: listing, ordering, timing, settings, and streaming
//! its frames.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use rayon::prelude::*;

use crate::camera::{self, CameraFile, CameraInfo, DEFAULT_MAX_FRAME_PIXELS, Kind, SourceFormat};
use crate::decode::{FrameFormat, PngDecoder, decode_path};
use crate::error::{FramesError, Result};
use crate::pixels::GrayPixels;
use crate::settings::{
    ClipSettings, FpsSource, SettingOverrides, Warning, camera_keys_at, check_overrides, choose_fps, choose_settings,
    clip_toml_path, session_toml_path,
};

/// How to open a clip.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ClipOptions {
    /// Frame rate override (from the command line), in frames/s; beats `clip.toml`, the camera header and
    /// `session.toml`.
    pub fps: Option<f64>,
    /// Geometry overrides (from the command line); each beats `clip.toml` and `session.toml`.
    pub overrides: SettingOverrides,
    /// Largest frame accepted from a camera file's header, in pixels (default 2²⁶ = 8192 × 8192): a
    /// corrupt header is refused before anything is allocated for it.
    pub max_frame_pixels: u64,
}

impl Default for ClipOptions {
    fn default() -> Self {
        Self {
            fps: None,
            overrides: SettingOverrides::default(),
            max_frame_pixels: DEFAULT_MAX_FRAME_PIXELS,
        }
    }
}

impl ClipOptions {
    /// Options with this frame-rate override, in frames/s.
    pub fn with_fps(fps: f64) -> Self {
        Self {
            fps: Some(fps),
            ..Self::default()
        }
    }
}

/// How to decode a clip's frames.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct ReadOptions {
    /// Decoding threads: `None` uses rayon's global pool; `Some(1)` decodes on the calling thread;
    /// `Some(n)` builds a dedicated pool of `n` threads for this stream.
    pub threads: Option<usize>,
    /// Frames decoded ahead and held in memory at most; `None` means 4 × the thread count.
    pub window: Option<usize>,
    /// The PNG decoder.
    pub png_decoder: PngDecoder,
}

impl ReadOptions {
    /// Options that decode on `threads` threads (1 = sequential on the caller's thread).
    pub fn with_threads(threads: usize) -> Self {
        Self {
            threads: Some(threads),
            ..Self::default()
        }
    }
}

/// One frame of a clip, before decoding: a frame file of a folder, or one frame of a camera file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameFile {
    /// The file (for a camera file, the camera file itself).
    pub path: PathBuf,
    /// The last number in its name (for a camera file, the frame's position in the file).
    pub number: u64,
    /// Its frame index: `number − first number` (0-based; dropped frames counted). For a camera file, the
    /// position in the file: frame 0 is the first stored frame.
    pub index: u64,
}

/// A run of missing frame numbers (dropped frames).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Gap {
    /// First missing frame number.
    pub first: u64,
    /// Last missing frame number (inclusive).
    pub last: u64,
}

impl Gap {
    /// How many frames are missing.
    pub fn len(&self) -> u64 {
        self.last - self.first + 1
    }

    /// Always false: a gap has at least one missing frame.
    pub fn is_empty(&self) -> bool {
        false
    }
}

/// One decoded frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Frame index in the clip: 0 for the first frame, dropped frames counted (`docs/session.md`).
    pub index: u64,
    /// The number in the file name (for a camera file, the position in the file).
    pub number: u64,
    /// Time since the first frame, in seconds: `index / fps`.
    pub t_s: f64,
    /// The file it came from.
    pub path: PathBuf,
    /// The pixels, gray, at the file's bit depth.
    pub pixels: GrayPixels,
}

/// What holds a clip's frames, before any setting is applied.
pub(crate) struct Frames {
    pub(crate) files: Vec<FrameFile>,
    pub(crate) size: (u32, u32),
    pub(crate) camera: Option<Arc<CameraFile>>,
}

impl Frames {
    /// Lists a folder (or opens the camera file) at `path`.
    pub(crate) fn probe(path: &Path, max_pixels: u64) -> Result<Self> {
        if path.is_dir() {
            let files = match list_frames(path) {
                // A folder holding no frame files but one camera file is that camera file.
                Err(FramesError::NoFrames { dir }) => {
                    return match lone_camera_file(&dir) {
                        Some((file, kind)) => Self::camera(&file, kind, max_pixels),
                        None => Err(FramesError::NoFrames { dir }),
                    };
                }
                other => other?,
            };
            // A folder holding one multi-page TIFF is that stack.
            if let [only] = &files[..]
                && FrameFormat::from_path(&only.path) == Some(FrameFormat::Tiff)
                && tiff_is_stack(&only.path)?
            {
                return Self::camera(&only.path, Kind::Tiff, max_pixels);
            }
            let first = &files[0].path;
            let size = image::ImageReader::open(first)
                .and_then(|r| r.with_guessed_format())
                .map_err(|e| e.to_string())
                .and_then(|r| r.into_dimensions().map_err(|e| e.to_string()))
                .map_err(|message| FramesError::Decode {
                    path: first.clone(),
                    index: 0,
                    message,
                })?;
            return Ok(Self {
                files,
                size,
                camera: None,
            });
        }
        if !path.exists() {
            return Err(FramesError::NotAFolder { path: path.into() });
        }
        match Kind::of(path) {
            Some(kind) => Self::camera(path, kind, max_pixels),
            None => Err(FramesError::NotAClip { path: path.into() }),
        }
    }

    fn camera(path: &Path, kind: Kind, max_pixels: u64) -> Result<Self> {
        let cam = CameraFile::open(path, kind, max_pixels)?;
        let files = (0..cam.count as u64)
            .map(|k| FrameFile {
                path: cam.path.clone(),
                number: k,
                index: k,
            })
            .collect();
        Ok(Self {
            files,
            size: cam.size,
            camera: Some(Arc::new(cam)),
        })
    }
}

/// The one camera file (Photron header and data counted once; no video) in a folder, if there is exactly one.
fn lone_camera_file(dir: &Path) -> Option<(PathBuf, Kind)> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_file()
                && p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| !n.starts_with('.'))
                && Kind::of(p).is_some_and(|k| k != Kind::Video)
        })
        .collect();
    found.sort();
    match &crate::session::photron_grouped(found)[..] {
        [one] => Kind::of(one).map(|k| (one.clone(), k)),
        _ => None,
    }
}

/// True if the TIFF file at `path` has more than one page (through a memory map: only its header and first
/// directory are read).
fn tiff_is_stack(path: &Path) -> Result<bool> {
    Ok(camera::tiff_has_more_pages(&camera::map(path)?))
}

/// An opened clip — a folder of frame files or one camera file: its frames in order, frame rate, dropped
/// frames, size, camera metadata and geometry settings. Nothing is decoded until frames are read.
#[derive(Clone, Debug)]
pub struct Clip {
    dir: PathBuf,
    files: Vec<FrameFile>,
    fps: f64,
    fps_source: FpsSource,
    gaps: Vec<Gap>,
    warnings: Vec<Warning>,
    size: (u32, u32),
    camera: Option<Arc<CameraFile>>,
    info: CameraInfo,
    settings: ClipSettings,
}

impl Clip {
    /// Opens a clip with default options (fps from `clip.toml`, the camera header, `session.toml` or the
    /// default).
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        Self::open_with(path, &ClipOptions::default())
    }

    /// Opens a clip: a folder of frame files, or one camera file (`docs/session.md`).
    ///
    /// A folder: lists every supported image file (`.png .tif .tiff .bmp .pgm .ppm .pnm .jpg .jpeg`, any
    /// case; the formats may be mixed) and ignores everything else, including hidden files. Orders them by
    /// the last number in the file name, finds the dropped frames and reads the first frame's header for the
    /// clip's size. A folder whose only frame file is a multi-page TIFF is that stack; a folder with no frame
    /// files but one camera file is that camera file.
    ///
    /// A camera file (`.cihx`/`.cih`/`.mraw`, `.cine`, `.tif`/`.tiff`): reads its header and checks it
    /// against the data (see [`CameraInfo`]); one frame per stored image, indexed from 0.
    ///
    /// Then resolves the frame rate and the geometry settings (command line > `clip.toml` > header (fps) >
    /// `session.toml` > default) and checks the region of interest and contact line against the size.
    pub fn open_with(path: impl AsRef<Path>, options: &ClipOptions) -> Result<Self> {
        let path = path.as_ref().to_path_buf();
        if let Some(fps) = options.fps {
            crate::settings::check_fps(fps, "command line", "--fps")?;
        }
        check_overrides(&options.overrides)?;
        let frames = Frames::probe(&path, options.max_frame_pixels)?;
        let own = camera_keys_at(&clip_toml_path(&path))?;
        let session = match session_toml_path(&path) {
            Some(p) => camera_keys_at(&p)?,
            None => None,
        };
        let header = frames
            .camera
            .as_ref()
            .and_then(|c| c.info.fps.map(|f| (f, c.path.as_path())));
        let session_fps = session.as_ref().and_then(|(p, k)| k.fps.map(|f| (f, p.as_path())));
        let (fps, fps_source, warning) = choose_fps(&path, options.fps, own.as_ref(), header, session_fps)?;
        let mut warnings: Vec<Warning> = warning.into_iter().collect();
        let settings = choose_settings(&path, &options.overrides, own.as_ref(), session.as_ref(), &mut warnings);
        Self::assemble(path, frames, fps, fps_source, settings, warnings)
    }

    /// Opens a clip whose frame rate and settings were resolved already (a session's entry).
    pub(crate) fn open_resolved(
        path: PathBuf,
        fps: f64,
        fps_source: FpsSource,
        settings: ClipSettings,
        max_frame_pixels: u64,
    ) -> Result<Self> {
        let frames = Frames::probe(&path, max_frame_pixels)?;
        Self::assemble(path, frames, fps, fps_source, settings, Vec::new())
    }

    fn assemble(
        path: PathBuf,
        frames: Frames,
        fps: f64,
        fps_source: FpsSource,
        settings: ClipSettings,
        mut warnings: Vec<Warning>,
    ) -> Result<Self> {
        settings.check_against(&path, frames.size)?;
        let info = match &frames.camera {
            Some(c) => {
                warnings.extend(c.warnings.iter().cloned());
                c.info.clone()
            }
            None => CameraInfo {
                format: SourceFormat::Folder,
                ..CameraInfo::default()
            },
        };
        let gaps = gaps(&frames.files);
        Ok(Self {
            dir: path,
            files: frames.files,
            fps,
            fps_source,
            gaps,
            warnings,
            size: frames.size,
            camera: frames.camera,
            info,
            settings,
        })
    }

    /// The clip as given: its folder, or its camera file. Same as [`Clip::path`].
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The clip as given: its folder, or its camera file (for Photron, the file named: header or `.mraw`).
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// True if the clip is one camera file rather than a folder of frame files.
    pub fn is_camera_file(&self) -> bool {
        self.camera.is_some()
    }

    /// Every file the frames come from: the frame files of a folder, or the camera file (for Photron, the
    /// header and the `.mraw`). Settings files are not included.
    pub fn source_files(&self) -> Vec<PathBuf> {
        match &self.camera {
            Some(c) => c.files(),
            None => self.files.iter().map(|f| f.path.clone()).collect(),
        }
    }

    /// What the camera file's header says (all `None` but the format for a folder of images).
    pub fn camera(&self) -> &CameraInfo {
        &self.info
    }

    /// The clip's geometry settings (scale, ball diameter, region of interest, contact line) with their
    /// sources.
    pub fn settings(&self) -> &ClipSettings {
        &self.settings
    }

    /// The frame files in order.
    pub fn files(&self) -> &[FrameFile] {
        &self.files
    }

    /// Number of frame files (present frames).
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// Always false: opening fails on a clip without frames.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// Frame indices spanned, dropped frames included: last index + 1.
    pub fn span(&self) -> u64 {
        self.files.last().map_or(0, |f| f.index + 1)
    }

    /// Frame rate, in frames/s.
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// Where the frame rate came from.
    pub fn fps_source(&self) -> &FpsSource {
        &self.fps_source
    }

    /// Dropped frames: runs of missing numbers, in order.
    pub fn gaps(&self) -> &[Gap] {
        &self.gaps
    }

    /// Total number of dropped frames.
    pub fn dropped(&self) -> u64 {
        self.gaps.iter().map(Gap::len).sum()
    }

    /// Warnings found while opening (e.g. the default frame rate was assumed).
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// Frame size (width, height) in pixels, from the first frame's header.
    pub fn dimensions(&self) -> (u32, u32) {
        self.size
    }

    /// Time of frame index `index`, in seconds.
    pub fn time_of(&self, index: u64) -> f64 {
        index as f64 / self.fps
    }

    /// Decodes the `k`-th frame file (position in [`Clip::files`], not frame index).
    ///
    /// Returns `None` past the end; an unreadable, truncated or wrongly sized frame is an error naming the
    /// file and frame index.
    pub fn read(&self, k: usize, png_decoder: PngDecoder) -> Option<Result<Frame>> {
        self.files.get(k).map(|f| self.decode(f, png_decoder))
    }

    /// Gives a frame's pixel buffer back, to be reused by the next frames decoded from this clip (MRAW and
    /// CINE files; otherwise the frame is dropped). A consumer done with each frame saves an allocation of
    /// fresh memory a frame, which costs more than unpacking it when frames are decoded on other threads.
    pub fn recycle(&self, frame: Frame) {
        if let Some(cam) = &self.camera {
            cam.recycle(frame.pixels);
        }
    }

    /// Streams the frames in order, decoding a bounded window ahead in parallel on rayon's global pool.
    pub fn frames(&self) -> FrameStream<'_> {
        FrameStream {
            clip: self,
            source: Source::Caller {
                next: 0,
                png: PngDecoder::default(),
            },
            remaining: self.files.len(),
        }
    }

    /// Streams the frames in order with these options (thread count, window, PNG decoder).
    ///
    /// Fails only if a dedicated thread pool cannot be started.
    pub fn frames_with(&self, options: &ReadOptions) -> Result<FrameStream<'_>> {
        let (pool, threads) = match options.threads {
            None => (None, rayon::current_num_threads()),
            Some(n) if n <= 1 => (None, 1),
            Some(n) => {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .thread_name(|i| format!("frames-decode-{i}"))
                    .build()
                    .map_err(|e| FramesError::ThreadPool {
                        threads: n,
                        message: e.to_string(),
                    })?;
                (Some(Pool::Own(pool)), n)
            }
        };
        let pool = match (options.threads, pool) {
            (None, _) => Some(Pool::Global),
            (_, p) => p,
        };
        let window = options.window.unwrap_or(4 * threads).max(1);
        FrameStream::new(self, pool, window, options.png_decoder)
    }

    fn decode(&self, file: &FrameFile, png: PngDecoder) -> Result<Frame> {
        let pixels = match &self.camera {
            Some(cam) => cam.decode(file.index as usize)?,
            None => decode_path(&file.path, png).map_err(|e| match e {
                crate::decode::DecodeError::MultiPage => FramesError::MultiPageInFolder {
                    path: file.path.clone(),
                },
                crate::decode::DecodeError::Other(message) => FramesError::Decode {
                    path: file.path.clone(),
                    index: file.index,
                    message,
                },
            })?,
        };
        if pixels.dimensions() != self.size {
            return Err(FramesError::SizeMismatch {
                path: file.path.clone(),
                index: file.index,
                found: pixels.dimensions(),
                expected: self.size,
                first: self.files[0].path.clone(),
            });
        }
        Ok(Frame {
            index: file.index,
            number: file.number,
            t_s: self.time_of(file.index),
            path: file.path.clone(),
            pixels,
        })
    }
}

enum Pool {
    Global,
    Own(rayon::ThreadPool),
}

/// An ordered stream of a clip's decoded frames, from [`Clip::frames`] or [`Clip::frames_with`].
///
/// With more than one decoding thread, a background reader decodes `window` frames at a time in parallel
/// and hands them over through a channel of `window` frames, so the next window is decoded while the
/// caller works on the current one (tracking hides behind decoding); at most about two windows of decoded
/// frames are held in memory whatever the clip's length. With one thread, frames are decoded on the
/// caller's thread as they are asked for. A frame that fails to decode yields an `Err` in its place; the
/// stream goes on with the next frame. Dropping the stream stops the reader.
pub struct FrameStream<'a> {
    clip: &'a Clip,
    source: Source,
    remaining: usize,
}

enum Source {
    /// Decoded on the caller's thread, one frame at a time.
    Caller { next: usize, png: PngDecoder },
    /// Decoded ahead by a background reader.
    Reader(std::sync::mpsc::Receiver<Result<Frame>>),
}

impl<'a> FrameStream<'a> {
    fn new(clip: &'a Clip, pool: Option<Pool>, window: usize, png: PngDecoder) -> Result<Self> {
        let remaining = clip.files.len();
        let source = match pool {
            None => Source::Caller { next: 0, png },
            Some(pool) => {
                let window = window.max(1);
                let (tx, rx) = std::sync::mpsc::sync_channel(window);
                let owned = std::sync::Arc::new(clip.clone());
                std::thread::Builder::new()
                    .name("frames-reader".into())
                    .spawn(move || {
                        let decode =
                            |chunk: &[FrameFile]| chunk.par_iter().map(|f| owned.decode(f, png)).collect::<Vec<_>>();
                        for chunk in owned.files.chunks(window) {
                            let decoded = match &pool {
                                Pool::Global => decode(chunk),
                                Pool::Own(p) => p.install(|| decode(chunk)),
                            };
                            for frame in decoded {
                                if tx.send(frame).is_err() {
                                    return; // the stream was dropped
                                }
                            }
                        }
                    })
                    .map_err(|e| FramesError::ThreadPool {
                        threads: 1,
                        message: e.to_string(),
                    })?;
                Source::Reader(rx)
            }
        };
        Ok(Self {
            clip,
            source,
            remaining,
        })
    }
}

impl FrameStream<'_> {
    /// Gives a frame's pixel buffer back for the frames still to come: [`Clip::recycle`].
    pub fn recycle(&self, frame: Frame) {
        self.clip.recycle(frame);
    }
}

impl Iterator for FrameStream<'_> {
    type Item = Result<Frame>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.remaining == 0 {
            return None;
        }
        let item = match &mut self.source {
            Source::Caller { next, png } => {
                let file = &self.clip.files[*next];
                *next += 1;
                Some(self.clip.decode(file, *png))
            }
            // The reader sends every frame, in order, unless it died (a panic in a decoder).
            Source::Reader(rx) => Some(rx.recv().unwrap_or_else(|_| {
                Err(FramesError::ThreadPool {
                    threads: 1,
                    message: "the frame reader stopped before the end of the clip".into(),
                })
            })),
        };
        self.remaining -= 1;
        item
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.remaining, Some(self.remaining))
    }
}

impl ExactSizeIterator for FrameStream<'_> {}

/// The last run of ASCII digits in a file stem, as a number: `Ok(None)` if there is none.
pub(crate) fn last_number(stem: &str) -> std::result::Result<Option<u64>, ()> {
    let bytes = stem.as_bytes();
    let Some(end) = bytes.iter().rposition(u8::is_ascii_digit) else {
        return Ok(None);
    };
    let start = bytes[..end]
        .iter()
        .rposition(|b| !b.is_ascii_digit())
        .map_or(0, |i| i + 1);
    stem[start..=end].parse::<u64>().map(Some).map_err(|_| ())
}

fn list_frames(dir: &Path) -> Result<Vec<FrameFile>> {
    let io = |source| FramesError::Io {
        path: dir.into(),
        source,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        if name.starts_with('.') || FrameFormat::from_path(&path).is_none() || !path.is_file() {
            continue;
        }
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
        let number = match last_number(stem) {
            Ok(Some(n)) => n,
            Ok(None) => return Err(FramesError::NoNumber { path }),
            Err(()) => return Err(FramesError::NumberTooLarge { path }),
        };
        files.push(FrameFile { path, number, index: 0 });
    }
    if files.is_empty() {
        return Err(FramesError::NoFrames { dir: dir.into() });
    }
    files.sort_by(|a, b| a.number.cmp(&b.number).then_with(|| a.path.cmp(&b.path)));
    if let Some(w) = files.windows(2).find(|w| w[0].number == w[1].number) {
        return Err(FramesError::DuplicateNumber {
            number: w[0].number,
            first: w[0].path.clone(),
            second: w[1].path.clone(),
        });
    }
    let first = files[0].number;
    for f in &mut files {
        f.index = f.number - first;
    }
    Ok(files)
}

fn gaps(files: &[FrameFile]) -> Vec<Gap> {
    files
        .windows(2)
        .filter(|w| w[1].number > w[0].number + 1)
        .map(|w| Gap {
            first: w[0].number + 1,
            last: w[1].number - 1,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn last_number_of_lab_names() {
        assert_eq!(last_number("C001H001S0001000123"), Ok(Some(1_000_123)));
        assert_eq!(last_number("img_00123"), Ok(Some(123)));
        assert_eq!(last_number("7"), Ok(Some(7)));
        assert_eq!(last_number("shot2_frame_0042_final"), Ok(Some(42)));
        assert_eq!(last_number("thumb"), Ok(None));
        assert_eq!(last_number("x99999999999999999999999"), Err(()));
        assert_eq!(last_number("x000000000000000000000000012"), Ok(Some(12)));
    }

    #[test]
    fn gaps_are_runs_of_missing_numbers() {
        let f = |n| FrameFile {
            path: PathBuf::new(),
            number: n,
            index: 0,
        };
        let files: Vec<_> = [3, 4, 7, 8, 10].into_iter().map(f).collect();
        assert_eq!(gaps(&files), vec![Gap { first: 5, last: 6 }, Gap { first: 9, last: 9 }]);
    }
}
