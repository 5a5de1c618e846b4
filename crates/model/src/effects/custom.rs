//! A user's force law, written as formulas in `model.toml` and evaluated, never executed as code.
//!
//! Formulas are parsed and compiled once (`formula.rs`) into a postfix program whose loads read the
//! context or the term's parameters directly, so an evaluation allocates nothing whatever the number of
//! names. Names are checked when the model is read, so a typo is reported with its position instead of
//! failing mid-simulation.

use super::formula::{self, Program};
use super::{Context, Effect, Loads, Phase};
use crate::ModelError;
use crate::error::FormulaError;
use std::sync::Arc;

/// When a custom term acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CustomPhase {
    /// In compression and restitution (the default).
    Contact,
    /// In compression only.
    Compression,
    /// In restitution only.
    Restitution,
    /// In flight only.
    Flight,
    /// In every phase.
    Always,
}

impl CustomPhase {
    /// Parses the `phase` key of a custom term.
    pub fn parse(s: &str) -> Option<CustomPhase> {
        Some(match s {
            "contact" => CustomPhase::Contact,
            "compression" => CustomPhase::Compression,
            "restitution" => CustomPhase::Restitution,
            "flight" => CustomPhase::Flight,
            "always" => CustomPhase::Always,
            _ => return None,
        })
    }

    fn includes(self, phase: Phase) -> bool {
        match self {
            CustomPhase::Contact => phase.in_contact(),
            CustomPhase::Compression => phase == Phase::Compression,
            CustomPhase::Restitution => phase == Phase::Restitution,
            CustomPhase::Flight => phase == Phase::Flight,
            CustomPhase::Always => true,
        }
    }
}

/// What a formula gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Normal contact force, N (adds to P).
    Normal,
    /// Tangential force at the contact point, N.
    Tangential,
    /// Force on the centre along x, N.
    ForceX,
    /// Force on the centre along y, N.
    ForceY,
    /// Torque about the centre, N·m.
    Torque,
}

impl Target {
    /// The keys of a custom term in `model.toml`, with their targets.
    pub const KEYS: [(&'static str, Target); 5] = [
        ("normal", Target::Normal),
        ("tangential", Target::Tangential),
        ("force_x", Target::ForceX),
        ("force_y", Target::ForceY),
        ("torque", Target::Torque),
    ];
}

/// State variables a formula may use, with their meaning (listed by `bouncelab effects`).
pub const FORMULA_VARIABLES: [(&str, &str); 17] = [
    ("delta", "penetration δ = R − y, m (alias δ)"),
    ("delta_dot", "penetration rate dδ/dt, m/s"),
    (
        "delta_max",
        "maximum penetration so far, m (0 before maximum compression)",
    ),
    ("v_t", "tangential velocity of the centre, m/s"),
    ("v_n", "normal velocity of the centre, m/s"),
    ("omega", "spin, rad/s, counter-clockwise (alias ω)"),
    ("slip", "slip of the contact point v_t + ω·R, m/s"),
    (
        "u_t",
        "tangential displacement of the contact patch ∫ slip dt since touch, m (a spring's stretch)",
    ),
    (
        "delta_int",
        "∫ δ dt since touch, m·s (memory of the load: stress relaxation)",
    ),
    ("x", "position along the surface, m"),
    ("y", "height of the centre, m"),
    ("theta", "orientation, rad"),
    ("t", "time, s"),
    ("P", "total normal contact force, N (not in `normal` formulas)"),
    ("m", "ball mass, kg"),
    ("R", "ball radius, m"),
    ("g", "gravitational acceleration, m/s²"),
];

/// A state variable of [`FORMULA_VARIABLES`], by meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Var {
    Delta,
    DeltaDot,
    DeltaMax,
    Vt,
    Vn,
    Omega,
    Slip,
    Ut,
    DeltaInt,
    X,
    Y,
    Theta,
    T,
    P,
    M,
    R,
    G,
}

impl Var {
    fn from_name(name: &str) -> Option<Var> {
        Some(match name {
            "delta" => Var::Delta,
            "delta_dot" => Var::DeltaDot,
            "delta_max" => Var::DeltaMax,
            "v_t" => Var::Vt,
            "v_n" => Var::Vn,
            "omega" => Var::Omega,
            "slip" => Var::Slip,
            "u_t" => Var::Ut,
            "delta_int" => Var::DeltaInt,
            "x" => Var::X,
            "y" => Var::Y,
            "theta" => Var::Theta,
            "t" => Var::T,
            "P" => Var::P,
            "m" => Var::M,
            "R" => Var::R,
            "g" => Var::G,
            _ => return None,
        })
    }

    #[inline]
    fn value(self, ctx: &Context) -> f64 {
        let s = ctx.state;
        match self {
            Var::Delta => ctx.delta,
            Var::DeltaDot => ctx.delta_dot,
            Var::DeltaMax => ctx.delta_max,
            Var::Vt => s.vx,
            Var::Vn => s.vy,
            Var::Omega => s.omega,
            Var::Slip => ctx.slip,
            Var::Ut => ctx.u_t,
            Var::DeltaInt => ctx.delta_int,
            Var::X => s.x,
            Var::Y => s.y,
            Var::Theta => s.theta,
            Var::T => ctx.t,
            Var::P => ctx.normal_force,
            Var::M => ctx.ball.mass_kg,
            Var::R => ctx.ball.radius_m,
            Var::G => ctx.gravity,
        }
    }

    /// True for the variables the simulator integrates only for the terms that use them.
    fn is_history(self) -> bool {
        matches!(self, Var::Ut | Var::DeltaInt)
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Slot {
    Var(Var),
    Param(usize),
}

/// A formula parsed and bound to its variables.
#[derive(Debug, Clone)]
struct Compiled {
    target: Target,
    program: Program<Slot>,
}

/// A custom term as declared in the model file.
#[derive(Debug, Clone)]
pub struct CustomTermSpec {
    /// Name (the key under `[effects]`).
    pub name: String,
    /// The user's description of the physics.
    pub doc: String,
    /// When it acts.
    pub phase: CustomPhase,
    /// Formulas, by target.
    pub formulas: Vec<(Target, String)>,
    /// Names of its parameters, in order.
    pub param_names: Vec<String>,
}

/// A custom force term: formulas over the state and named parameters.
#[derive(Debug, Clone)]
pub struct CustomTerm {
    spec: Arc<CustomTermSpec>,
    compiled: Vec<Compiled>,
    params: Vec<f64>,
    uses_history: bool,
}

fn alias(name: &str) -> &str {
    match name {
        "δ" => "delta",
        "ω" => "omega",
        other => other,
    }
}

impl CustomTerm {
    /// Parses and checks every formula of `spec`; `origin` names the model file in errors.
    pub fn compile(spec: CustomTermSpec, values: Vec<f64>, origin: &str) -> Result<CustomTerm, ModelError> {
        let mut compiled = Vec::new();
        let mut uses_history = false;
        for (target, text) in &spec.formulas {
            let field = Target::KEYS
                .iter()
                .find(|(_, t)| t == target)
                .map(|(k, _)| *k)
                .unwrap_or("formula");
            let bad = |pos: Option<usize>, message: String| {
                ModelError::BadFormula(Box::new(FormulaError {
                    origin: origin.to_string(),
                    effect: spec.name.clone(),
                    field: field.to_string(),
                    formula: text.clone(),
                    caret: pos.map(|p| format!("{}^", " ".repeat(p))).unwrap_or_default(),
                    message,
                }))
            };
            if *target == Target::Normal && spec.phase == CustomPhase::Flight {
                return Err(bad(
                    None,
                    "a `normal` contact force cannot act in phase = \"flight\"".into(),
                ));
            }
            let ast = formula::parse(text).map_err(|e| bad(Some(e.pos), e.message))?;
            let mut refused_p = false;
            let bound = Program::compile(&ast, &mut |name: &str| {
                let name = alias(name);
                if let Some(v) = Var::from_name(name) {
                    if v == Var::P && *target == Target::Normal {
                        refused_p = true;
                        return None;
                    }
                    uses_history |= v.is_history();
                    return Some(Slot::Var(v));
                }
                spec.param_names.iter().position(|p| p == name).map(Slot::Param)
            });
            let program = match bound {
                Ok(p) => p,
                Err((_, pos)) if refused_p => {
                    return Err(bad(
                        Some(pos),
                        "a `normal` formula cannot use P, the total normal force it is part of".into(),
                    ));
                }
                Err((name, pos)) => {
                    let vars: Vec<&str> = FORMULA_VARIABLES.iter().map(|(v, _)| *v).collect();
                    let params = if spec.param_names.is_empty() {
                        "none".to_string()
                    } else {
                        spec.param_names.join(", ")
                    };
                    return Err(bad(
                        Some(pos),
                        format!(
                            "`{name}` is neither a state variable ({}), a parameter of this effect ({params}) nor a constant ({}); declare it as `{name} = <value>`",
                            vars.join(", "),
                            formula::constant_names()
                        ),
                    ));
                }
            };
            compiled.push(Compiled {
                target: *target,
                program,
            });
        }
        Ok(CustomTerm {
            spec: Arc::new(spec),
            compiled,
            params: values,
            uses_history,
        })
    }

    /// The declaration this term was built from.
    pub fn spec(&self) -> &CustomTermSpec {
        &self.spec
    }

    #[inline]
    fn eval(&self, c: &Compiled, ctx: &Context) -> f64 {
        // A formula that cannot be evaluated yields NaN, which the simulator reports with the time and phase.
        c.program.eval(|slot| match slot {
            Slot::Param(i) => self.params[i],
            Slot::Var(v) => v.value(ctx),
        })
    }
}

impl Effect for CustomTerm {
    fn name(&self) -> &str {
        &self.spec.name
    }
    fn params(&self) -> Vec<f64> {
        self.params.clone()
    }
    fn set_params(&mut self, values: &[f64]) {
        let n = self.params.len();
        self.params.copy_from_slice(&values[..n]);
    }
    fn normal_force(&self, ctx: &Context) -> f64 {
        if !self.spec.phase.includes(ctx.phase) {
            return 0.0;
        }
        self.compiled
            .iter()
            .filter(|c| c.target == Target::Normal)
            .map(|c| self.eval(c, ctx))
            .sum()
    }
    fn loads(&self, ctx: &Context) -> Loads {
        let mut out = Loads::default();
        if !self.spec.phase.includes(ctx.phase) {
            return out;
        }
        for c in &self.compiled {
            match c.target {
                Target::Normal => {}
                Target::Tangential if ctx.phase.in_contact() => out.tangential += self.eval(c, ctx),
                Target::Tangential => {}
                Target::ForceX => out.force_x += self.eval(c, ctx),
                Target::ForceY => out.force_y += self.eval(c, ctx),
                Target::Torque => out.torque += self.eval(c, ctx),
            }
        }
        out
    }
    fn uses_contact_history(&self) -> bool {
        self.uses_history
    }
    fn clone_box(&self) -> Box<dyn Effect> {
        Box::new(self.clone())
    }
}
