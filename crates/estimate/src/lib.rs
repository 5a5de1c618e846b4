//! What the lab publishes for each shot, measured from the ball's track: the phases of the impact, the
//! velocities in and out, the coefficient of restitution, the effective friction, the contact time and the
//! maximum penetration, each with an honest standard error.
//!
//! The flight phases are fitted as ballistic arcs with gravity's components on the incline known (weighted
//! least squares, the tracker's per-frame σ as weights, inflated by the fit's own scatter when that is
//! larger), and the contact's start and end are where those arcs bring the ball's centre to one radius above
//! the surface line. So every number comes from many frames, not from the one or two frames nearest the
//! impact, and a phase too short to fit is said to be so rather than guessed.

mod ballistic;
mod contact;
mod fall;
mod phase;
mod refit_level;
mod roll;
mod shot;
mod spin;
mod with_frames;

pub use ballistic::{BallisticFit, FreeArc, fit_ballistic, fit_free_acceleration, fit_free_acceleration_beyond_rim};
pub use contact::{HeightPoint, TrajectoryContact, find_impact, trajectory_contact};
pub use phase::{Phase, PhaseFrames};
pub use roll::session_tilt_deg;
pub use shot::{
    Conditions, DOWNSLOPE_SIGMAS, Estimate, EstimateError, FALL_SE_DEG, GravityCheck, LEVEL_BY_EYE_DEG,
    MIN_FLIGHT_FRAMES, MIN_SIGMA_PX, Measured, estimate, fall_se_deg, saturation_flag,
};
pub use spin::{Rotation, Spin, SpinImage, SpinOptions, measure_spin, rotation_between, spin_from_frames};
pub use with_frames::{estimate_finding_downslope, estimate_with_frames};
