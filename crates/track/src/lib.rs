//! Finds the ball in every frame of a high-speed clip and measures its centre to a small fraction of a pixel.
//!
//! A gradient-voting Hough transform finds circle candidates in a whole frame (first frame, or after the
//! ball was lost); from then on each frame costs tens of microseconds: the centre predicted from the
//! previous frames seeds edge searches along rays, and a robust geometric circle fit (Tukey-weighted
//! Gauss–Newton) turns the edge points into a centre, a radius and their uncertainty, ignoring the part of
//! the rim hidden by or pressed into the surface. Once the clip is tracked, every circle is measured again
//! against its neighbouring frames' mean profile across the rim, which an ambiguous edge does not make jump.
//! Frames where the ball is cut by the border, absent or
//! ambiguous are flagged, never invented. The same crate finds the surface line and its tilt, and turns the
//! ball's apparent radius in free flight into the clip's scale.
//!
//! Everything works on [`Plane`], a borrowed 8- or 16-bit grayscale image, so no frame is copied.

mod acquire;
mod ball_search;
mod border;
mod bounce;
mod circle_fit;
mod clip;
mod hough;
mod in_front;
mod level;
mod limb;
mod local;
mod motion;
#[cfg(feature = "opencv")]
pub mod opencv;
mod path;
mod plane;
mod realign;
mod refine;
mod rim_evidence;
mod surface;
mod texture;
mod tracker;
mod trajectory;

pub use circle_fit::{CircleFit, fit_circle};
pub use clip::{ClipTracking, Scale, Track, TrackError, track_clip};
pub use hough::{Circle, CircleDetection, detect_circles, outermost, radius_bands};
pub use level::{LevelShift, RowStatistic, ball_columns, mean_gray_level, remeasured, textured_share_level};
pub use limb::{LimbLearner, LimbOffset};
pub use local::SurfaceFrame;
pub use plane::{Pixel, Plane};
pub use refine::{
    EdgeSearch, Refined, RimShape, RimShapeLearner, refine_candidates, refine_circle, refined_candidates, rim_residuals,
};
pub use rim_evidence::{MIN_SECTORS_STANDING_OUT, RimEvidence, SECTORS, rim_evidence, rim_strength, strongest_rim};
pub use surface::{
    LineCue, SurfaceLine, SurfaceLines, find_faint_surface_lines, find_surface_line, find_surface_lines,
};
pub use texture::{faint_texture_lines, horizontal_gradient_energy, texture_line, texture_lines};
pub use tracker::{BallFix, Status, TrackOptions, Tracker, UnknownStatus};
pub use trajectory::{TRAJECTORY_COLUMNS, TrajectoryCell, TrajectoryRow};

/// Synthetic frames for tests, benches and examples (here and in dependents' dev-dependencies, through the
/// `testutil` feature); not part of the library proper.
#[cfg(any(test, feature = "testutil"))]
#[doc(hidden)]
pub mod testutil;
