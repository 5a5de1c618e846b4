//! The pipeline's front door: a clip folder of high-speed camera frames (or, with the `opencv` feature, a
//! video file) in, an ordered stream of timed gray frames out; plus loading a session folder's
//! `session.toml` and `clips.csv` (SPEC §2.1, §2.7).
//!
//! The main design choice is to separate *listing* from *decoding*. [`Clip::open`] only lists and orders the
//! frame files (by the last number in each name, gaps reported as dropped frames), resolves the frame rate
//! and reads one header; [`Clip::frames`] then decodes a bounded window of frames at a time in parallel
//! (rayon) and yields them in order, so memory stays flat however long the clip is. Frames keep the file's
//! bit depth ([`GrayPixels`] is 8- or 16-bit gray; colour becomes luma). PNG, the bottleneck, is decoded by
//! the `image` crate, measured faster here than `zune-png` (kept as a checked alternative, [`PngDecoder`]).
//! The library never prints: warnings are returned, errors are one [`FramesError`] naming the file, frame
//! or field. With the `opencv` feature, `video::VideoClip` reads .mov/.mp4/.avi files through OpenCV.
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

mod clip;
mod decode;
mod error;
mod pixels;
mod session;
mod settings;
#[doc(hidden)]
pub mod testutil;
#[cfg(feature = "opencv")]
pub mod video;

pub use clip::{Clip, ClipOptions, Frame, FrameFile, FrameStream, Gap, ReadOptions};
#[doc(hidden)]
pub use decode::decode_bytes;
pub use decode::{FrameFormat, PngDecoder};
pub use error::{FramesError, Result};
pub use pixels::{Gray16Image, GrayPixels};
pub use session::{BallSpec, ClipEntry, Session};
pub use settings::{DEFAULT_FPS, Downslope, FpsSource, MAX_FPS, Warning};
