//! The plain input types: one measured shot, its frames, its start state and its measured outputs.

use bouncelab_model::State;
use serde::{Deserialize, Serialize};

/// One tracked frame in the local frame of `docs/outputs.md`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeasuredFrame {
    /// Time, s (t = 0 at the clip's first frame).
    pub t_s: f64,
    /// Centre along the surface, down-slope, m (origin arbitrary: it only has to match the start's).
    pub x_m: f64,
    /// Centre height above the surface line, m.
    pub y_m: f64,
    /// Standard error of each centre coordinate, m (> 0).
    pub sigma_m: f64,
}

/// Where a simulation of the shot starts: the incoming state taken from the measurement (the estimator's
/// incoming ballistic fit evaluated at the first fitted frame).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StartState {
    /// Time of the start, s (no frame may be earlier).
    pub t_s: f64,
    /// State at that time, in the same local frame (and x origin) as the frames.
    pub state: State,
}

/// The shot's measured outputs (from the estimator), used for the paper's errors, not by the fit itself.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeasuredOutputs {
    /// Outgoing velocity of the centre at separation (tangential, normal), m/s.
    pub v_out: [f64; 2],
    /// Coefficient of restitution `|v_n,out / v_n,in|`.
    pub cor: f64,
    /// Effective friction `−Δv_t / Δv_n`.
    pub mu: f64,
}

/// One measured shot: what the fit compares the simulation with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasuredShot {
    /// The shot's name (its clip), used in messages and results.
    pub name: String,
    /// Surface name, as in `[surfaces.NAME]` of the model file.
    pub surface: String,
    /// Incline of the surface, rad.
    pub incline_rad: f64,
    /// The frames to fit, ascending in time (e.g. from the start to ~15 ms after separation).
    pub frames: Vec<MeasuredFrame>,
    /// The incoming state the simulation starts from.
    pub start: StartState,
    /// Measured outputs, if the estimator produced them.
    pub measured: Option<MeasuredOutputs>,
    /// Standard error of the surface line's height in this shot, m, if the tracker gave one. With
    /// per-shot surface offsets ([`crate::Problem::with_surface_offsets`]), the shot's offset is a
    /// deviation from the surface's level with this prior; without it, the offset is free.
    pub surface_sigma_m: Option<f64>,
    /// Standard error of the direction of this shot's frame, rad: the surface line's tilt as measured in
    /// the image. When given, the fit lets the frame turn by a small angle with this prior (see
    /// [`crate::Problem`]); `None`: the frame is taken as exact.
    #[serde(default)]
    pub frame_sigma_rad: Option<f64>,
    /// Standard error of the start's spin, rad/s (the estimator's incoming spin). When given, the fit lets
    /// the incoming spin differ from the measured one with this prior (see [`crate::Problem`]): a spin error
    /// changes how much friction works while the ball goes from sliding to rolling, and so the outgoing
    /// tangential flight; `None`: the spin is taken as exact.
    #[serde(default)]
    pub spin_sigma_rad_s: Option<f64>,
    /// How much the ball's measured radius changed from the incoming flight to the outgoing one, m, with
    /// its standard error (`[value, se]`; the estimator's `rim_change_px` times the scale). The fit does not
    /// use it; the missing-effect search counts it in the tracker's floor: a rim measured differently in
    /// the two flights moves the centre between them too. `None`: not measured.
    #[serde(default)]
    pub rim_change_m: Option<[f64; 2]>,
}
