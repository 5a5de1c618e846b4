//! The contact model: what happens to a ball between the last frame before it touches the surface and the
//! first frame after it leaves, as a function of a few physical parameters.
//!
//! The paper's hybrid model (a spring–damper in compression, a spring in restitution, Coulomb friction with
//! rolling) is not hard-wired: it is the default set of [`Effect`]s, and every other physical effect of the
//! library (Hertzian stiffness, Hunt–Crossley damping, a plastic dent, drag, rolling resistance, camera roll,
//! a user formula …) is one more type implementing the same small trait. A [`Model`] is a ball plus a list of
//! effects; [`simulate`] integrates it with an adaptive Dormand–Prince 5(4) scheme that stops exactly at the
//! phase switches (touch, maximum compression, separation, stick/slip), so the outputs the lab measures
//! (restitution, effective friction, contact time, penetration, spin) come out of the same run as the
//! trajectory sampled at the camera's frame times. Models are written by hand in `model.toml`
//! ([`ModelSpec`]), which also says which parameters a fit may move.
//!
//! Conventions (`docs/outputs.md`): local frame with x along the surface pointing down-slope, y along the outward
//! normal, origin on the surface; the ball's centre is at height `y`, so the penetration is `δ = R − y`.
//! Spin ω is positive counter-clockwise as seen by the camera; the contact point slips at `v_t + ω·R`.

mod ball;
pub mod effects;
mod error;
mod file;
mod integrator;
mod model;
mod simulate;

pub use ball::{Ball, State};
pub use effects::{Context, Effect, EffectInfo, Loads, Observation, ParamSpec, Phase, builtin, builtin_effects};
pub use error::{FormulaError, ModelError};
pub use file::{EffectKind, EffectSetting, ModelSpec, PAPER_MODEL_TOML, ParamRef, ParamSetting, SurfaceValues};
pub use model::Model;
pub use simulate::{Impact, Sample, SimOptions, Simulation, SlipEvent, SlipEventKind, simulate, simulate_drop};
