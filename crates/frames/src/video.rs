//! Video files (.mov, .mp4, .avi …) through OpenCV's videoio (feature `opencv`).
//!
//! OpenCV decodes sequentially, so a [`VideoClip`] is a plain iterator of [`Frame`]s with no parallel
//! window. `VideoCapture` hands out 3-channel BGR frames even for gray video; they are converted to 8-bit
//! gray with OpenCV's `BGR2GRAY` (Rec. 601 weights). Frame rate: the override if given, else the
//! container's, else [`DEFAULT_FPS`] with a warning. Beware that high-speed cameras often store a
//! *playback* rate (e.g. 30 fps) in exported videos: pass the real capture rate as the override.

use std::path::{Path, PathBuf};

use opencv::core::Mat;
use opencv::prelude::*;
use opencv::{imgproc, videoio};

use crate::clip::{ClipOptions, Frame};
use crate::error::{FramesError, Result};
use crate::pixels::GrayPixels;
use crate::settings::{DEFAULT_FPS, FpsSource, MAX_FPS, Warning, check_fps};

/// File extensions treated as video (lower case).
pub const VIDEO_EXTENSIONS: [&str; 6] = ["mov", "mp4", "avi", "mkv", "m4v", "mpg"];

/// True if the path's extension is a video extension.
pub fn is_video(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| VIDEO_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// An opened video file; iterate it for its frames, in order.
pub struct VideoClip {
    path: PathBuf,
    capture: videoio::VideoCapture,
    fps: f64,
    fps_source: FpsSource,
    frame_count: Option<u64>,
    size: (u32, u32),
    warnings: Vec<Warning>,
    next: u64,
    done: bool,
}

impl VideoClip {
    /// Opens a video file. `options.fps` overrides the container's frame rate.
    pub fn open(path: impl AsRef<Path>, options: &ClipOptions) -> Result<Self> {
        let path = path.as_ref().to_path_buf();
        let err = |message: String| FramesError::Video {
            path: path.clone(),
            frame: None,
            message,
        };
        if !path.is_file() {
            return Err(err("no such video file".into()));
        }
        let name = path.to_str().ok_or_else(|| err("path is not valid UTF-8".into()))?;
        let capture = videoio::VideoCapture::from_file(name, videoio::CAP_ANY).map_err(|e| err(e.to_string()))?;
        if !capture.is_opened().map_err(|e| err(e.to_string()))? {
            return Err(err("OpenCV cannot open this video (unknown container or codec)".into()));
        }
        let prop = |p| capture.get(p).unwrap_or(0.0);
        let container_fps = prop(videoio::CAP_PROP_FPS);
        let count = prop(videoio::CAP_PROP_FRAME_COUNT);
        let size = (
            prop(videoio::CAP_PROP_FRAME_WIDTH) as u32,
            prop(videoio::CAP_PROP_FRAME_HEIGHT) as u32,
        );
        let mut warnings = Vec::new();
        let (fps, fps_source) = match options.fps {
            Some(f) => (check_fps(f, "command line", "--fps")?, FpsSource::Override),
            None if container_fps.is_finite() && container_fps > 0.0 && container_fps <= MAX_FPS => {
                (container_fps, FpsSource::Container(path.clone()))
            }
            None => {
                warnings.push(Warning::DefaultFps {
                    clip: path.clone(),
                    fps: DEFAULT_FPS,
                });
                (DEFAULT_FPS, FpsSource::Default)
            }
        };
        let frame_count = (count.is_finite() && count >= 1.0).then_some(count as u64);
        Ok(Self {
            path,
            capture,
            fps,
            fps_source,
            frame_count,
            size,
            warnings,
            next: 0,
            done: false,
        })
    }

    /// The video file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Frame rate, in frames/s.
    pub fn fps(&self) -> f64 {
        self.fps
    }

    /// Where the frame rate came from.
    pub fn fps_source(&self) -> &FpsSource {
        &self.fps_source
    }

    /// Frame count stored in the container, if any (may be approximate for some codecs).
    pub fn frame_count(&self) -> Option<u64> {
        self.frame_count
    }

    /// Frame size (width, height) in pixels, as the container reports it.
    pub fn dimensions(&self) -> (u32, u32) {
        self.size
    }

    /// Warnings found while opening (e.g. no usable frame rate).
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    fn read_next(&mut self) -> Result<Option<Frame>> {
        let index = self.next;
        let err = |message: String| FramesError::Video {
            path: self.path.clone(),
            frame: Some(index),
            message,
        };
        let mut mat = Mat::default();
        if !self.capture.read(&mut mat).map_err(|e| err(e.to_string()))? || mat.empty() {
            return Ok(None);
        }
        let code = match mat.channels() {
            1 => None,
            3 => Some(imgproc::COLOR_BGR2GRAY),
            4 => Some(imgproc::COLOR_BGRA2GRAY),
            n => return Err(err(format!("{n}-channel frame"))),
        };
        let gray = match code {
            Some(code) => {
                let mut gray = Mat::default();
                imgproc::cvt_color_def(&mat, &mut gray, code).map_err(|e| err(e.to_string()))?;
                gray
            }
            None => mat,
        };
        let gray = if gray.is_continuous() {
            gray
        } else {
            gray.try_clone().map_err(|e| err(e.to_string()))?
        };
        if gray.depth() != opencv::core::CV_8U {
            return Err(err("only 8-bit video is supported".into()));
        }
        let (w, h) = (gray.cols() as u32, gray.rows() as u32);
        let bytes = gray.data_bytes().map_err(|e| err(e.to_string()))?.to_vec();
        let image =
            image::GrayImage::from_raw(w, h, bytes).ok_or_else(|| err("frame buffer has the wrong size".into()))?;
        if self.size == (0, 0) {
            self.size = (w, h);
        } else if (w, h) != self.size {
            return Err(err(format!(
                "frame is {w}×{h} px but the video is {}×{} px",
                self.size.0, self.size.1
            )));
        }
        self.next += 1;
        Ok(Some(Frame {
            index,
            number: index,
            t_s: index as f64 / self.fps,
            path: self.path.clone(),
            pixels: GrayPixels::U8(image),
        }))
    }
}

impl Iterator for VideoClip {
    type Item = Result<Frame>;

    /// The next frame; after an error the stream ends.
    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let item = self.read_next().transpose();
        if !matches!(item, Some(Ok(_))) {
            self.done = true;
        }
        item
    }
}
