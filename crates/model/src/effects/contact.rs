//! Normal contact forces: what pushes the ball back out of the surface.

use super::{Context, Effect, EffectInfo, ParamSpec, Phase, effect_params};

/// Linear spring `P = k·δ` in compression and restitution (the paper's elastic term).
#[derive(Debug, Clone)]
pub struct LinearSpring {
    /// Stiffness k, N/m.
    pub k: f64,
}

impl LinearSpring {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "spring",
            doc: "Linear spring P = k·δ while in contact (the paper's elastic term).",
            group: "normal",
            base: true,
            params: &[ParamSpec {
                name: "k",
                unit: "N/m",
                doc: "contact stiffness",
                default: None,
                neutral: 0.0,
                min: 0.0,
                max: 1e9,
            }],
            build: |v| Box::new(LinearSpring { k: v[0] }),
        }
    }
}

impl Effect for LinearSpring {
    effect_params!("spring", k);
    fn normal_force(&self, ctx: &Context) -> f64 {
        self.k * ctx.delta.max(0.0)
    }
}

/// Viscous damping `P = b·δ̇` during compression only (the paper's hybrid model).
#[derive(Debug, Clone)]
pub struct LinearDamping {
    /// Damping b, N·s/m.
    pub b: f64,
}

impl LinearDamping {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "damping",
            doc: "Viscous damping P = b·dδ/dt during compression only (the paper's hybrid model).",
            group: "normal",
            base: true,
            params: &[ParamSpec {
                name: "b",
                unit: "N·s/m",
                doc: "compression damping",
                default: None,
                neutral: 0.0,
                min: 0.0,
                max: 1e6,
            }],
            build: |v| Box::new(LinearDamping { b: v[0] }),
        }
    }
}

impl Effect for LinearDamping {
    effect_params!("damping", b);
    fn normal_force(&self, ctx: &Context) -> f64 {
        match ctx.phase {
            Phase::Compression => self.b * ctx.delta_dot,
            _ => 0.0,
        }
    }
}

/// Hertzian stiffness `P = k_h·δ^1.5`: a sphere's contact stiffens as the contact patch grows.
#[derive(Debug, Clone)]
pub struct Hertz {
    /// Hertzian stiffness, N/m^1.5.
    pub k_h: f64,
}

impl Hertz {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "hertz",
            doc: "Hertzian stiffness P = k_h·δ^1.5: the contact stiffens as the patch grows, so contact time falls with impact speed.",
            group: "normal",
            base: false,
            params: &[ParamSpec {
                name: "k_h",
                unit: "N/m^1.5",
                doc: "Hertzian stiffness",
                default: Some(0.0),
                neutral: 0.0,
                min: 0.0,
                max: 1e12,
            }],
            build: |v| Box::new(Hertz { k_h: v[0] }),
        }
    }
}

impl Effect for Hertz {
    effect_params!("hertz", k_h);
    fn normal_force(&self, ctx: &Context) -> f64 {
        let d = ctx.delta.max(0.0);
        self.k_h * d * d.sqrt()
    }
}

/// Hunt–Crossley damping `P = λ·δ^n·δ̇` in compression and restitution.
#[derive(Debug, Clone)]
pub struct HuntCrossley {
    /// Damping λ, N·s/m^(1+n).
    pub lambda: f64,
    /// Exponent n of the penetration (dimensionless).
    pub n: f64,
}

impl HuntCrossley {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "hunt_crossley",
            doc: "Hunt–Crossley damping P = λ·δ^n·dδ/dt in both contact phases: dissipation grows with penetration, so COR falls with impact speed.",
            group: "normal",
            base: false,
            params: &[
                ParamSpec {
                    name: "lambda",
                    unit: "N·s/m^(1+n)",
                    doc: "Hunt–Crossley damping",
                    default: Some(0.0),
                    neutral: 0.0,
                    min: 0.0,
                    max: 1e12,
                },
                ParamSpec {
                    name: "n",
                    unit: "1",
                    doc: "exponent of the penetration",
                    default: Some(1.0),
                    neutral: 1.0,
                    min: 0.0,
                    max: 3.0,
                },
            ],
            build: |v| Box::new(HuntCrossley { lambda: v[0], n: v[1] }),
        }
    }
}

impl Effect for HuntCrossley {
    effect_params!("hunt_crossley", lambda, n);
    fn normal_force(&self, ctx: &Context) -> f64 {
        if self.lambda == 0.0 {
            return 0.0;
        }
        let d = ctx.delta.max(0.0);
        self.lambda * d.powf(self.n) * ctx.delta_dot
    }
}

/// Viscous damping `P = b_r·δ̇` during restitution (the paper assumes none).
#[derive(Debug, Clone)]
pub struct RestitutionDamping {
    /// Damping in restitution, N·s/m.
    pub b_r: f64,
}

impl RestitutionDamping {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "restitution_damping",
            doc: "Viscous damping P = b_r·dδ/dt also during restitution (the paper assumes an elastic restitution): lower COR.",
            group: "normal",
            base: false,
            params: &[ParamSpec {
                name: "b_r",
                unit: "N·s/m",
                doc: "restitution damping",
                default: Some(0.0),
                neutral: 0.0,
                min: 0.0,
                max: 1e6,
            }],
            build: |v| Box::new(RestitutionDamping { b_r: v[0] }),
        }
    }
}

impl Effect for RestitutionDamping {
    effect_params!("restitution_damping", b_r);
    fn normal_force(&self, ctx: &Context) -> f64 {
        match ctx.phase {
            Phase::Restitution => self.b_r * ctx.delta_dot,
            _ => 0.0,
        }
    }
}

/// Permanent deformation: the surface unloads to a residual dent `φ·δ_max` instead of springing back.
///
/// In restitution the elastic force is replaced by a steeper unloading line through the maximum-compression
/// point and the dent depth: `P = P_max·(δ − φ·δ_max) / ((1 − φ)·δ_max)`, added as the difference to the
/// loading line so that it composes with any elastic law.
#[derive(Debug, Clone)]
pub struct PlasticDent {
    /// Residual depth as a fraction of the maximum penetration (dimensionless, 0 ≤ φ < 1).
    pub phi: f64,
}

impl PlasticDent {
    /// Catalogue entry.
    pub fn info() -> EffectInfo {
        EffectInfo {
            name: "plastic_dent",
            doc: "Plastic dent: unloading to a residual depth φ·δ_max (the surface keeps a dent), so less energy is returned: lower COR.",
            group: "normal",
            base: false,
            params: &[ParamSpec {
                name: "phi",
                unit: "1",
                doc: "residual depth / maximum penetration",
                default: Some(0.0),
                neutral: 0.0,
                min: 0.0,
                max: 0.95,
            }],
            build: |v| Box::new(PlasticDent { phi: v[0] }),
        }
    }
}

impl Effect for PlasticDent {
    effect_params!("plastic_dent", phi);
    fn normal_force(&self, ctx: &Context) -> f64 {
        if ctx.phase != Phase::Restitution || self.phi == 0.0 || ctx.delta_max <= 0.0 {
            return 0.0;
        }
        let secant = ctx.force_max / ctx.delta_max;
        let shift = secant * self.phi / (1.0 - self.phi) * (ctx.delta_max - ctx.delta.max(0.0));
        -shift
    }
}
