//! The effect library: one type per physical effect, all behind the small [`Effect`] trait.
//!
//! An effect is a type with parameters, a doc line on its physics, and the loads it adds per phase. Every
//! method has a default that adds nothing, so an effect implements only what it changes. Adding a built-in
//! effect is one new module here plus one line in [`builtin_effects`] (see `docs/effects.md`).

mod contact;
pub(crate) mod custom;
mod flight;
pub(crate) mod formula;
mod measurement;
mod tangential;

pub use contact::{Hertz, HuntCrossley, LinearDamping, LinearSpring, PlasticDent, RestitutionDamping};
pub use custom::{CustomPhase, CustomTerm, CustomTermSpec, FORMULA_VARIABLES, Target};
pub use flight::QuadraticDrag;
pub use measurement::{CameraRoll, SurfaceLevel};
pub use tangential::{Coulomb, InertiaFactor, RollingResistance, TangentialSpring};

use crate::{Ball, State};
use std::fmt::Debug;

/// The phase of an impact the ball is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Not touching the surface (before or after the impact).
    Flight,
    /// In contact, penetration growing (`δ̇ > 0`), from touch to maximum compression.
    Compression,
    /// In contact, from maximum compression to separation.
    Restitution,
}

impl Phase {
    /// Lower-case name, as in files.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Flight => "flight",
            Phase::Compression => "compression",
            Phase::Restitution => "restitution",
        }
    }

    /// True in compression and restitution.
    pub fn in_contact(self) -> bool {
        self != Phase::Flight
    }
}

/// What an effect sees: the state and everything derived from it that a force law needs.
///
/// Passed by reference to every effect, so adding a field breaks no effect.
#[derive(Debug, Clone, Copy)]
pub struct Context<'a> {
    /// Time since the start of the simulation, s.
    pub t: f64,
    /// The ball's state in the local frame.
    pub state: &'a State,
    /// The phase the ball is in.
    pub phase: Phase,
    /// Penetration `δ = R − y`, m (negative in flight).
    pub delta: f64,
    /// Penetration rate `δ̇ = −v_y`, m/s.
    pub delta_dot: f64,
    /// Slip velocity of the contact point, `v_t + ω·R`, m/s.
    pub slip: f64,
    /// The ball.
    pub ball: &'a Ball,
    /// Gravitational acceleration, m/s².
    pub gravity: f64,
    /// Incline of the surface β, rad.
    pub incline: f64,
    /// Maximum penetration reached so far in this contact, m (0 before maximum compression).
    pub delta_max: f64,
    /// Total normal force at maximum compression, N (0 before maximum compression).
    pub force_max: f64,
    /// Total normal contact force `P`, N: the sum of every effect's [`Effect::normal_force`]. Known in
    /// [`Effect::loads`] only (it is 0 while the normal forces themselves are being summed).
    pub normal_force: f64,
    /// Tangential displacement of the contact patch, m: `u_t = ∫ slip dt` from touch (0 before it; frozen
    /// at its separation value after). Integrated only when an effect of the model says it reads it
    /// ([`Effect::uses_contact_history`]); 0 otherwise.
    pub u_t: f64,
    /// Load history of the contact, m·s: `∫ δ dt` from touch (0 before it; frozen after separation).
    /// Integrated only when an effect of the model says it reads it; 0 otherwise.
    pub delta_int: f64,
}

impl<'a> Context<'a> {
    /// The context of `state` in `phase` at time `t`: penetration, its rate and the slip derived from the
    /// state; nothing known yet of a maximum compression, and no normal force summed.
    pub fn of(t: f64, state: &'a State, phase: Phase, ball: &'a Ball, gravity: f64, incline: f64) -> Self {
        let r = ball.radius_m;
        Context {
            t,
            state,
            phase,
            delta: r - state.y,
            delta_dot: -state.vy,
            slip: state.vx + state.omega * r,
            ball,
            gravity,
            incline,
            delta_max: 0.0,
            force_max: 0.0,
            normal_force: 0.0,
            u_t: 0.0,
            delta_int: 0.0,
        }
    }
}

/// Loads an effect adds besides the normal contact force, in the local frame. All default to zero.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Loads {
    /// Tangential force at the contact point, N, along +x (it also turns the ball). Ignored in flight.
    pub tangential: f64,
    /// Force at the centre, N, along x (e.g. drag).
    pub force_x: f64,
    /// Force at the centre, N, along y.
    pub force_y: f64,
    /// Torque about the centre, N·m, counter-clockwise as seen by the camera.
    pub torque: f64,
}

impl Loads {
    /// Adds `other` into `self`.
    #[inline]
    pub fn add(&mut self, other: &Loads) {
        self.tangential += other.tangential;
        self.force_x += other.force_x;
        self.force_y += other.force_y;
        self.torque += other.torque;
    }
}

/// A position and velocity as the camera measures them, in the camera's axes (m, m/s, rad, rad/s).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Observation {
    /// Along the camera's x axis, m.
    pub x: f64,
    /// Along the camera's y axis (up in the image), m.
    pub y: f64,
    /// Orientation, rad.
    pub theta: f64,
    /// Velocity along the camera's x axis, m/s.
    pub vx: f64,
    /// Velocity along the camera's y axis, m/s.
    pub vy: f64,
    /// Spin, rad/s.
    pub omega: f64,
}

impl From<Observation> for State {
    /// The state the camera saw, read as a local-frame state (what a measured start is).
    fn from(o: Observation) -> Self {
        State {
            x: o.x,
            y: o.y,
            theta: o.theta,
            vx: o.vx,
            vy: o.vy,
            omega: o.omega,
        }
    }
}

impl From<State> for Observation {
    fn from(s: State) -> Self {
        Observation {
            x: s.x,
            y: s.y,
            theta: s.theta,
            vx: s.vx,
            vy: s.vy,
            omega: s.omega,
        }
    }
}

/// A physical effect: a force law, a torque, a property of the ball or a property of the measurement.
///
/// Implementations keep their parameters as fields; [`Effect::params`] and [`Effect::set_params`] expose
/// them in the order of their [`EffectInfo::params`] so a fit can move them.
pub trait Effect: Debug + Send + Sync {
    /// The effect's name as written in `model.toml`.
    fn name(&self) -> &str;
    /// Current parameter values, in declaration order.
    fn params(&self) -> Vec<f64>;
    /// Sets the parameter values, in declaration order.
    ///
    /// # Panics
    /// If `values` is shorter than the effect's parameter list (a programming error).
    fn set_params(&mut self, values: &[f64]);
    /// The normal contact force this effect adds, N, positive pushing the ball out of the surface; called in
    /// compression and restitution only. The sum over effects is the normal load `P` that bounds friction.
    fn normal_force(&self, _ctx: &Context) -> f64 {
        0.0
    }
    /// The other loads this effect adds, in every phase; `ctx.normal_force` holds `P`.
    fn loads(&self, _ctx: &Context) -> Loads {
        Loads::default()
    }
    /// Coulomb friction coefficient this effect contributes (dimensionless).
    fn friction_coefficient(&self) -> f64 {
        0.0
    }
    /// Change of the inertia factor `c` this effect makes (dimensionless).
    fn inertia_shift(&self) -> f64 {
        0.0
    }
    /// Tangential compliance of the contact patch this effect adds, m/N (compliances in series add). With
    /// a total compliance above zero the simulator replaces the rigid stick of Coulomb friction by an
    /// elastic patch (see [`TangentialSpring`] and `docs/model.md`).
    fn tangential_compliance(&self) -> f64 {
        0.0
    }
    /// Viscous damping of the contact patch's tangential spring this effect adds, N·s/m (acts only with a
    /// tangential compliance).
    fn tangential_damping(&self) -> f64 {
        0.0
    }
    /// True if the effect reads [`Context::u_t`] or [`Context::delta_int`]: the simulator then integrates
    /// them with the state (error-controlled like it); models without such an effect integrate the state
    /// alone, exactly as before.
    fn uses_contact_history(&self) -> bool {
        false
    }
    /// How the effect changes what the camera measures (a measurement effect); the default changes nothing.
    fn observe(&self, _obs: &mut Observation) {}
    /// A boxed copy.
    fn clone_box(&self) -> Box<dyn Effect>;
}

impl Clone for Box<dyn Effect> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

/// A parameter of an effect.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// Name as written in `model.toml`.
    pub name: &'static str,
    /// SI unit.
    pub unit: &'static str,
    /// What it is.
    pub doc: &'static str,
    /// Value when the model file does not give one; `None` makes it required.
    pub default: Option<f64>,
    /// The value at which the effect does nothing (used by tests and by the diagnosis as a starting point).
    pub neutral: f64,
    /// Smallest physically meaningful value.
    pub min: f64,
    /// Largest physically meaningful value.
    pub max: f64,
}

/// A built-in effect: its name, physics and parameters, and how to build it.
#[derive(Debug, Clone)]
pub struct EffectInfo {
    /// Name as written in `model.toml`.
    pub name: &'static str,
    /// One line on the physics.
    pub doc: &'static str,
    /// Which group of `docs/effects.md` it belongs to ("normal", "tangential", "flight", "measurement"), or
    /// "nuisance" for a property of the measurement fitted with the base model (the surface level).
    pub group: &'static str,
    /// True for the effects of the paper's base model.
    pub base: bool,
    /// Its parameters, in order.
    pub params: &'static [ParamSpec],
    /// Builds the effect from parameter values in order.
    pub build: fn(&[f64]) -> Box<dyn Effect>,
}

/// The built-in effects, base model first.
pub fn builtin_effects() -> &'static [EffectInfo] {
    static ALL: std::sync::OnceLock<Vec<EffectInfo>> = std::sync::OnceLock::new();
    ALL.get_or_init(|| {
        vec![
            LinearSpring::info(),
            LinearDamping::info(),
            Coulomb::info(),
            Hertz::info(),
            HuntCrossley::info(),
            RestitutionDamping::info(),
            PlasticDent::info(),
            RollingResistance::info(),
            InertiaFactor::info(),
            TangentialSpring::info(),
            QuadraticDrag::info(),
            CameraRoll::info(),
            SurfaceLevel::info(),
        ]
    })
}

/// The built-in effect called `name`.
pub fn builtin(name: &str) -> Option<&'static EffectInfo> {
    builtin_effects().iter().find(|e| e.name == name)
}

/// Defines `name`, `params`, `set_params` and `clone_box` for an effect whose parameters are plain `f64`
/// fields, in declaration order.
macro_rules! effect_params {
    ($name:literal, $($field:ident),+) => {
        fn name(&self) -> &str {
            $name
        }
        fn params(&self) -> Vec<f64> {
            vec![$(self.$field),+]
        }
        fn set_params(&mut self, values: &[f64]) {
            let mut it = values.iter().copied();
            $(self.$field = it.next().expect("too few parameter values");)+
        }
        fn clone_box(&self) -> Box<dyn $crate::effects::Effect> {
            Box::new(self.clone())
        }
    };
}
pub(crate) use effect_params;

/// Sign with a linear zone of half-width `eps` around zero, so that a torque that opposes a velocity does
/// not chatter when the velocity crosses zero.
#[inline]
pub(crate) fn soft_sign(v: f64, eps: f64) -> f64 {
    (v / eps).clamp(-1.0, 1.0)
}
