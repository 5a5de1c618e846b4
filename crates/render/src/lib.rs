//! Synthetic high-speed drop clips with exact ground truth: the project's test bench.
//!
//! A [`Scenario`] (a TOML file or a built-in preset) describes a session — camera, ball, surfaces with their
//! physics in `model.toml` syntax, shots — and [`render`] writes it in the layout of `docs/session.md` with the
//! truth in a `truth/` folder beside the session, never inside it. The physics is not re-implemented: every
//! shot is simulated by `bouncelab-model` at the frames' mid-exposure times (the truth) and at sub-exposure
//! times (motion blur), so the truth is the model's own output. The main design choice is that the
//! expensive image work is split into a static background made once per shot and a per-frame pass that
//! only shades the ball's bounding box, with every random stream derived from (seed, shot, frame): frames
//! can be rendered in any order, in parallel, and come out byte-identical. A scenario's `[look]` draws each
//! shot's appearance and camera from wide ranges (`docs/renderer.md`, "Looks"), so the pipeline is tested
//! on many looks, not on this renderer's one.

mod appearance;
mod error;
mod look;
pub mod presets;
mod progress;
mod rng;
mod scenario;
mod scene;
mod session;
mod shot;

pub use error::RenderError;
pub use look::{BallLook, HotSpot, Item, ItemKind, LOOK_COLUMNS, LOOK_FAMILIES, Look, LookSpec, Range, SurfaceLook};
pub use presets::{EFFECT_MAGNITUDES, EFFECT_PAIRS, preset_names, preset_toml};
pub use progress::ProgressBarObserver;
pub use scenario::{BallSpec, Camera, Downslope, Format, RandomPhysics, Scenario, Shot, Surface, Texture};
pub use scene::{Pixels, RenderedFrame, ShotRenderer};
pub use session::{
    FRAME_COLUMNS, NoRenderProgress, RenderObserver, RenderOptions, Rendered, SHOTS_COLUMNS, encode, render,
    render_with,
};
pub use shot::{FrameTruth, ShotPlan, ShotTruth, Visibility};
