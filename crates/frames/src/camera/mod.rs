//! Camera files: one file (a Photron header with its `.mraw`, a Phantom `.cine`, a multi-page TIFF) that
//! holds a whole clip.
//!
//! A camera file is memory-mapped, never read whole: opening parses the header, checks every size it
//! states against the file's length (and, for CINE, the image offset table against the file), and refuses a
//! frame larger than [`crate::ClipOptions::max_frame_pixels`] before anything is allocated for it. Decoding
//! frame `k` then reads only that frame's bytes from the map, so frames decode independently and in
//! parallel, and memory holds only the frames being decoded.

mod cine;
mod photron;
mod tiffstack;

pub(crate) use tiffstack::has_more_pages as tiff_has_more_pages;
pub(crate) mod unpack;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{FramesError, Result};
use crate::pixels::GrayPixels;
use crate::settings::Warning;

/// Largest frame accepted by default, in pixels (8192 × 8192).
pub const DEFAULT_MAX_FRAME_PIXELS: u64 = 1 << 26;

/// Most frames accepted in one camera file: the frame list is allocated from the header's count (checked
/// against the file's length first), so a tiny frame size must not make it unbounded.
pub(crate) const MAX_FRAMES: usize = 10_000_000;

/// What a clip is stored as.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum SourceFormat {
    /// A folder of image files, one a frame.
    #[default]
    Folder,
    /// A Photron `.cihx`/`.cih` header with its `.mraw` frames.
    PhotronMraw,
    /// A Phantom (Vision Research) `.cine` file.
    PhantomCine,
    /// A multi-page TIFF, one page a frame.
    TiffStack,
    /// A video file (feature `opencv`).
    Video,
}

impl SourceFormat {
    /// The format's name for a person ("Photron MRAW", "folder of images", …).
    pub fn label(self) -> &'static str {
        match self {
            SourceFormat::Folder => "folder of images",
            SourceFormat::PhotronMraw => "Photron MRAW",
            SourceFormat::PhantomCine => "Phantom CINE",
            SourceFormat::TiffStack => "multi-page TIFF",
            SourceFormat::Video => "video",
        }
    }
}

/// Which bits of a 16-bit sample hold a narrower camera's value (Photron `EffectiveBit Side`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BitSide {
    /// The low bits (a 12-bit value 0–4095 in a 16-bit word).
    Lower,
    /// The high bits (already at 16-bit full scale).
    Higher,
}

/// What the camera file's header says about the recording; every field is optional (a folder of images
/// has none of them).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct CameraInfo {
    /// What the clip is stored as.
    pub format: SourceFormat,
    /// Record rate from the header, in frames/s (the clip's fps may be overridden: see `Clip::fps`).
    pub fps: Option<f64>,
    /// Exposure (shutter) time of one frame, in seconds.
    pub exposure_s: Option<f64>,
    /// Bits per pixel as stored in the file (8, 10, 12 or 16).
    pub bit_depth: Option<u8>,
    /// Bits of each sample the sensor really filled (e.g. 12 in a 16-bit word).
    pub effective_bit_depth: Option<u8>,
    /// Which bits of a wider word hold them.
    pub effective_bit_side: Option<BitSide>,
    /// Camera model, as the header names it.
    pub camera_model: Option<String>,
    /// Camera serial number, when the header has one.
    pub camera_serial: Option<String>,
    /// The camera's number of the first stored frame, counted from the trigger (trigger = 0; Photron
    /// `startFrame`, Phantom `FirstImageNo`).
    pub start_frame: Option<i64>,
    /// Position in the file (0-based, as [`crate::Frame::index`]) of the trigger frame: `−start_frame`;
    /// may lie outside the stored frames.
    pub trigger_frame: Option<i64>,
}

/// The kind of camera file a path names, from its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Photron,
    Cine,
    Tiff,
    Video,
}

/// Video extensions (lower case) recognised as clips (read with the `opencv` feature).
pub(crate) const VIDEO_EXTENSIONS: [&str; 6] = ["mov", "mp4", "avi", "mkv", "m4v", "mpg"];

impl Kind {
    pub(crate) fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "cihx" | "cih" | "mraw" => Self::Photron,
            "cine" => Self::Cine,
            "tif" | "tiff" => Self::Tiff,
            e if VIDEO_EXTENSIONS.contains(&e) => Self::Video,
            _ => return None,
        })
    }
}

/// The frame layout of an opened camera file.
#[derive(Debug)]
enum Layout {
    /// Frames of `frame_bytes` back to back from the start of the data file.
    Contiguous {
        packing: unpack::Packing,
        frame_bytes: usize,
    },
    Cine(cine::Frames),
    Tiff(tiffstack::Pages),
}

/// An opened camera file: its memory map, frame layout and header.
#[derive(Debug)]
pub(crate) struct CameraFile {
    /// The file given (for Photron, the header).
    pub path: PathBuf,
    /// The file holding the frames (for Photron, the `.mraw`).
    pub data_path: PathBuf,
    /// Every file the clip is made of (for Photron, header and `.mraw`).
    sources: Vec<PathBuf>,
    map: memmap2::Mmap,
    layout: Layout,
    /// Buffers of frames given back, for the next frames decoded (MRAW and CINE).
    pool: unpack::Pool,
    pub info: CameraInfo,
    pub size: (u32, u32),
    pub count: usize,
    pub warnings: Vec<Warning>,
}

impl CameraFile {
    /// Opens a camera file of a known kind.
    pub(crate) fn open(path: &Path, kind: Kind, max_pixels: u64) -> Result<Self> {
        let cam = match kind {
            Kind::Photron => photron::open(path, max_pixels),
            Kind::Cine => cine::open(path, max_pixels),
            Kind::Tiff => tiffstack::open(path, max_pixels),
            Kind::Video => Err(video_error(path)),
        }?;
        if cam.count > MAX_FRAMES {
            return Err(header_error(
                path,
                "frame count",
                format!("{} frames is over the limit of {MAX_FRAMES} frames a file", cam.count),
            ));
        }
        Ok(cam)
    }

    /// Decodes the frame at position `k` (0-based).
    pub(crate) fn decode(&self, k: usize) -> Result<GrayPixels> {
        let (w, h) = self.size;
        match &self.layout {
            Layout::Contiguous { packing, frame_bytes } => {
                let start = k * frame_bytes;
                let bytes = self
                    .map
                    .get(start..start + frame_bytes)
                    .ok_or_else(|| FramesError::Decode {
                        path: self.data_path.clone(),
                        index: k as u64,
                        message: "frame beyond the end of the file".into(),
                    })?;
                Ok(packing.unpack(bytes, w, h, false, &self.pool))
            }
            Layout::Cine(frames) => frames.decode(&self.map, &self.data_path, k, self.size, &self.pool),
            Layout::Tiff(pages) => pages.decode(&self.map, &self.data_path, k, self.size),
        }
    }

    /// Keeps a decoded frame's buffer for the next frames decoded.
    pub(crate) fn recycle(&self, pixels: GrayPixels) {
        let (w, h) = self.size;
        self.pool.give(pixels, w as usize * h as usize);
    }

    /// Every file the clip is made of (header and data), for fingerprints.
    pub(crate) fn files(&self) -> Vec<PathBuf> {
        self.sources.clone()
    }
}

/// The error for a video file: which feature or tool reads it.
pub(crate) fn video_error(path: &Path) -> FramesError {
    if cfg!(feature = "opencv") {
        FramesError::Video {
            path: path.into(),
            frame: None,
            message: "video files are read with `bouncelab_frames::video::VideoClip` (sequential); the clip \
                      commands take folders and camera files: export the frames, e.g. \
                      `ffmpeg -i VIDEO -vsync 0 FOLDER/img_%06d.png`"
                .into(),
        }
    } else {
        FramesError::VideoNeedsFeature { path: path.into() }
    }
}

/// Memory-maps a file read-only.
pub(crate) fn map(path: &Path) -> Result<memmap2::Mmap> {
    let io = |source| FramesError::Io {
        path: path.into(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    if file.metadata().map_err(io)?.len() == 0 {
        return Err(header_error(path, "file", "the file is empty"));
    }
    // SAFETY: the map is read-only and private to this process. If another program truncates or rewrites
    // the file while it is mapped, reads may see the new bytes or fault; camera files are not written while
    // they are analysed, and every offset read from the map is checked against its length first.
    let map = unsafe { memmap2::Mmap::map(&file) }.map_err(io)?;
    // Frames are mostly read in order: let the kernel read ahead and drop pages behind. Only a hint.
    #[cfg(unix)]
    let _ = map.advise(memmap2::Advice::Sequential);
    Ok(map)
}

fn header_error(path: &Path, field: &str, problem: impl Into<String>) -> FramesError {
    FramesError::CameraHeader {
        path: path.into(),
        field: field.into(),
        problem: problem.into(),
    }
}

/// Checks width × height against the limit before anything is allocated for a frame.
fn check_size(path: &Path, width: u64, height: u64, max_pixels: u64) -> Result<(u32, u32)> {
    if width == 0 || height == 0 {
        return Err(header_error(
            path,
            "image size",
            format!("{width}×{height} px has no pixels"),
        ));
    }
    match width.checked_mul(height) {
        Some(n) if n <= max_pixels && width <= u64::from(u32::MAX) && height <= u64::from(u32::MAX) => {
            Ok((width as u32, height as u32))
        }
        _ => Err(FramesError::FrameTooLarge {
            path: path.into(),
            width,
            height,
            limit: max_pixels,
        }),
    }
}
