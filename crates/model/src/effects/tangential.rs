//! Tangential effects: friction, rolling resistance and the ball's inertia.

use super::{Context, Effect, EffectInfo, Loads, ParamSpec, effect_params, soft_sign};

/// Coulomb friction opposing the slip of the contact point, with sticking (rolling) when slip stops.
///
/// The force itself is computed by the simulator, which owns the stick/slip state: sliding, `F = −μ·P`
/// against the slip; sticking, whatever force keeps the slip at zero while it stays below `μ·P`.
#[derive(Debug, Clone)]
pub struct Coulomb {
    /// Friction coefficient μ (dimensionless), static and kinetic alike.
    pub mu: f64,
}

impl Coulomb {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "coulomb",
            doc: "Coulomb friction |F| ≤ μ·P opposing the contact point's slip; sliding turns into rolling when the slip stops.",
            group: "tangential",
            base: true,
            params: &[ParamSpec {
                name: "mu",
                unit: "1",
                doc: "friction coefficient",
                default: None,
                neutral: 0.0,
                min: 0.0,
                max: 5.0,
            }],
            build: |v| Box::new(Coulomb { mu: v[0] }),
        }
    }
}

impl Effect for Coulomb {
    effect_params!("coulomb", mu);
    fn friction_coefficient(&self) -> f64 {
        self.mu
    }
}

/// Rolling resistance: a torque `c_rr·R·P` opposing the spin while in contact.
#[derive(Debug, Clone)]
pub struct RollingResistance {
    /// Rolling-resistance coefficient (lever arm / R), dimensionless.
    pub c_rr: f64,
}

/// Spin below which the rolling-resistance torque fades linearly to zero, rad/s (avoids chatter at ω = 0).
const ROLLING_SPIN_EPS: f64 = 0.05;

impl RollingResistance {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "rolling_resistance",
            doc: "Rolling resistance: a torque c_rr·R·P opposing the spin while in contact (the contact patch's pressure sits ahead of the centre), so spin decays while rolling.",
            group: "tangential",
            base: false,
            params: &[ParamSpec {
                name: "c_rr",
                unit: "1",
                doc: "rolling-resistance lever arm / radius",
                default: Some(0.0),
                neutral: 0.0,
                min: 0.0,
                max: 1.0,
            }],
            build: |v| Box::new(RollingResistance { c_rr: v[0] }),
        }
    }
}

impl Effect for RollingResistance {
    effect_params!("rolling_resistance", c_rr);
    fn loads(&self, ctx: &Context) -> Loads {
        if !ctx.phase.in_contact() || self.c_rr == 0.0 {
            return Loads::default();
        }
        let arm = self.c_rr * ctx.ball.radius_m;
        Loads {
            torque: -arm * ctx.normal_force.max(0.0) * soft_sign(ctx.state.omega, ROLLING_SPIN_EPS),
            ..Loads::default()
        }
    }
}

/// A different moment of inertia: `I = (c + Δc)·m·R²` (a tennis ball is a thick shell, c ≈ 0.55–0.6).
#[derive(Debug, Clone)]
pub struct InertiaFactor {
    /// Change of the inertia factor from the ball's `c`, dimensionless.
    pub dc: f64,
}

impl InertiaFactor {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "inertia_factor",
            doc: "Moment of inertia I = (c + Δc)·m·R² instead of the thin shell's 2/3: a thick wall changes how much spin friction produces, and so the rolling speed.",
            group: "tangential",
            base: false,
            params: &[ParamSpec {
                name: "dc",
                unit: "1",
                doc: "change of the inertia factor c",
                default: Some(0.0),
                neutral: 0.0,
                min: -0.6,
                max: 0.6,
            }],
            build: |v| Box::new(InertiaFactor { dc: v[0] }),
        }
    }
}

impl Effect for InertiaFactor {
    effect_params!("inertia_factor", dc);
    fn inertia_shift(&self) -> f64 {
        self.dc
    }
}
