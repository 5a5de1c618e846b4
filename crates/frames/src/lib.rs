//! The pipeline's front door: a clip — a folder of high-speed camera frames, or one camera file (Photron
//! `.cihx`/`.cih` + `.mraw`, Phantom `.cine`, a multi-page TIFF) — in, an ordered stream of timed gray
//! frames out; plus a session folder's `session.toml`, `clips.csv` and per-clip settings, and the draft of a
//! new session from a folder of recordings ([`init`]). The formats and keys are described in
//! `docs/session.md`.
//!
//! The main design choice is to separate *listing* from *decoding*. [`Clip::open`] only lists and orders the
//! frame files (by the last number in each name, gaps reported as dropped frames) or reads a camera file's
//! header and checks it against the data, resolves the frame rate and settings; [`Clip::frames`] then
//! decodes a bounded window of frames at a time in parallel (rayon) and yields them in order, so memory
//! stays flat however long the clip is (camera files are memory-mapped, never read whole). Frames keep the
//! file's bit depth ([`GrayPixels`] is 8- or 16-bit gray; 10- and 12-bit camera samples are put at 16-bit
//! full scale; colour becomes luma). The library never prints: warnings are returned, errors are one
//! [`FramesError`] naming the file, frame or field. With the `opencv` feature, `video::VideoClip` reads
//! .mov/.mp4/.avi files through OpenCV.
//!
//! ```no_run
//! use bouncelab_frames::{Clip, ReadOptions};
//! let clip = Clip::open("session/shot_01")?;
//! for frame in clip.frames_with(&ReadOptions::with_threads(2))? {
//!     let frame = frame?;
//!     println!("frame {} at {:.6} s: {:?}", frame.index, frame.t_s, frame.pixels.dimensions());
//! }
//! # Ok::<(), bouncelab_frames::FramesError>(())
//! ```

#![warn(missing_docs)]

mod camera;
mod clip;
mod decode;
mod error;
pub mod init;
mod pixels;
mod session;
mod settings;
#[cfg(any(test, feature = "testutil"))]
#[doc(hidden)]
pub mod testutil;
#[cfg(feature = "opencv")]
pub mod video;

pub use camera::{BitSide, CameraInfo, DEFAULT_MAX_FRAME_PIXELS, SourceFormat};
pub use clip::{Clip, ClipOptions, Frame, FrameFile, FrameStream, Gap, ReadOptions};
#[doc(hidden)]
pub use decode::decode_bytes;
pub use decode::{FrameFormat, PngDecoder};
pub use error::{FramesError, Result, UnfilledRow};
pub use pixels::{Gray16Image, GrayPixels};
pub use session::{BallSpec, ClipEntry, Session, UnusableClip};
pub use settings::{
    ClipSettings, ContactLine, DEFAULT_BALL_DIAMETER_M, DEFAULT_FPS, DIAMETER_RANGE_M, DROP_HEIGHT_RANGE_M, Downslope,
    FpsSource, MASS_RANGE_KG, MAX_FPS, MAX_LINE_TILT_DEG, MIN_FPS, Roi, SCALE_RANGE_M_PER_PX, SettingOverrides,
    SettingSource, Warning, clip_toml_path,
};
