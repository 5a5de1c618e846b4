//! Effects on the ball in flight.

use super::{Context, Effect, EffectInfo, Loads, ParamSpec, effect_params};

/// Quadratic air drag `F = −½·ρ·C_d·π·R²·|v|·v` on the centre, in every phase.
#[derive(Debug, Clone)]
pub struct QuadraticDrag {
    /// Drag coefficient C_d (dimensionless; ≈ 0.55 for a tennis ball).
    pub cd: f64,
    /// Air density ρ, kg/m³.
    pub rho: f64,
}

impl QuadraticDrag {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "drag",
            doc: "Quadratic air drag F = −½·ρ·C_d·π·R²·|v|·v: the ball arrives slower than √(2gh) and leaves slower.",
            group: "flight",
            base: false,
            params: &[
                ParamSpec {
                    name: "cd",
                    unit: "1",
                    doc: "drag coefficient",
                    default: Some(0.0),
                    neutral: 0.0,
                    min: 0.0,
                    max: 5.0,
                },
                ParamSpec {
                    name: "rho",
                    unit: "kg/m³",
                    doc: "air density",
                    default: Some(1.204),
                    neutral: 1.204,
                    min: 0.0,
                    max: 100.0,
                },
            ],
            build: |v| Box::new(QuadraticDrag { cd: v[0], rho: v[1] }),
        }
    }
}

impl Effect for QuadraticDrag {
    effect_params!("drag", cd, rho);
    fn loads(&self, ctx: &Context) -> Loads {
        let r = ctx.ball.radius_m;
        let c = 0.5 * self.rho * self.cd * std::f64::consts::PI * r * r;
        let (vx, vy) = (ctx.state.vx, ctx.state.vy);
        let speed = vx.hypot(vy);
        Loads {
            force_x: -c * speed * vx,
            force_y: -c * speed * vy,
            ..Loads::default()
        }
    }
}
