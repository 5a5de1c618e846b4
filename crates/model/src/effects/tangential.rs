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

/// Tangential compliance of the contact patch (Maw–Barber–Fawcett; the Cundall–Strack tangential spring):
/// the patch stores the tangential displacement `u` of the ball's contact point and gives it back.
///
/// While the patch holds, the tangential force at the contact point is `F = −u/λ − c_t·u̇` with `u̇` the
/// slip `v_t + ω·R` (λ = 1/k_t the compliance); when `|F|` would exceed the Coulomb limit `μ·P` the patch
/// slides at `F = ∓μ·P` and the stored displacement is limited to `u = λ·(±μ·P − c_t·slip)`, so the force
/// is continuous at every switch. The rigid Coulomb contact is the limit λ → 0, and λ = 0 is that contact
/// exactly. The law and the switches belong to the simulator's stick/slip state machine (`simulate.rs`);
/// this effect only supplies λ and c_t.
#[derive(Debug, Clone)]
pub struct TangentialSpring {
    /// Tangential compliance λ = 1/k_t of the contact patch, m/N (0: a rigid patch, today's Coulomb).
    pub compliance: f64,
    /// Viscous damping of the patch's tangential spring, N·s/m.
    pub c_t: f64,
}

impl TangentialSpring {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "tangential_spring",
            doc: "Elastic contact patch: while friction holds it, the patch stores the contact point's tangential displacement u and pushes back with F = −u/λ − c_t·u̇ (|F| ≤ μ·P, sliding beyond), so the slip reverses and the ball leaves with more spin than rolling (λ = 1/k_t; λ = 0 is the rigid Coulomb contact).",
            group: "tangential",
            base: false,
            params: &[
                ParamSpec {
                    name: "compliance",
                    unit: "m/N",
                    doc: "tangential compliance λ = 1/k_t of the contact patch",
                    default: Some(0.0),
                    neutral: 0.0,
                    min: 0.0,
                    max: 1e-3,
                },
                ParamSpec {
                    name: "c_t",
                    unit: "N·s/m",
                    doc: "damping of the patch's tangential spring",
                    default: Some(0.0),
                    neutral: 0.0,
                    min: 0.0,
                    max: 1e3,
                },
            ],
            build: |v| {
                Box::new(TangentialSpring {
                    compliance: v[0],
                    c_t: v[1],
                })
            },
        }
    }
}

impl Effect for TangentialSpring {
    effect_params!("tangential_spring", compliance, c_t);
    fn tangential_compliance(&self) -> f64 {
        self.compliance
    }
    fn tangential_damping(&self) -> f64 {
        self.c_t
    }
    fn uses_contact_history(&self) -> bool {
        self.compliance != 0.0
    }
}
