//! A user's force law, written as formulas in `model.toml` and evaluated, never executed as code.
//!
//! Formulas are parsed once by `exmex` into a flat expression; each evaluation fills the variables the
//! formula uses from the context (a few array writes) and evaluates the expression. Names are checked when
//! the model is read, so a typo is reported with its position instead of failing mid-simulation.

use super::{Context, Effect, Loads, Phase};
use crate::ModelError;
use crate::error::FormulaError;
use exmex::prelude::*;
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
pub const FORMULA_VARIABLES: [(&str, &str); 15] = [
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
    ("x", "position along the surface, m"),
    ("y", "height of the centre, m"),
    ("theta", "orientation, rad"),
    ("t", "time, s"),
    ("P", "total normal contact force, N (not in `normal` formulas)"),
    ("m", "ball mass, kg"),
    ("R", "ball radius, m"),
    ("g", "gravitational acceleration, m/s²"),
];

#[derive(Debug, Clone, Copy)]
enum Slot {
    Var(usize),
    Param(usize),
}

/// A formula parsed and bound to its variables.
#[derive(Debug, Clone)]
struct Compiled {
    target: Target,
    expr: FlatEx<f64>,
    slots: Vec<Slot>,
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
}

fn alias(name: &str) -> &str {
    match name {
        "δ" => "delta",
        "ω" => "omega",
        other => other,
    }
}

fn known_function(name: &str) -> bool {
    FlatEx::<f64>::parse(&format!("{name}(1)")).is_ok()
}

impl CustomTerm {
    /// Parses and checks every formula of `spec`; `origin` names the model file in errors.
    pub fn compile(spec: CustomTermSpec, values: Vec<f64>, origin: &str) -> Result<CustomTerm, ModelError> {
        let mut compiled = Vec::new();
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
            precheck(text).map_err(|(pos, msg)| bad(Some(pos), msg))?;
            let expr = FlatEx::<f64>::parse(text).map_err(|e| {
                let msg = e.to_string();
                // exmex appends debug dumps of its operators; keep the sentence.
                let msg = msg.split(", Operator").next().unwrap_or(&msg).to_string();
                bad(None, format!("cannot parse the formula: {msg}"))
            })?;
            let mut slots = Vec::new();
            for var in expr.var_names() {
                let name = alias(var);
                let pos = text.find(var.as_str()).map(|b| text[..b].chars().count());
                if let Some(i) = FORMULA_VARIABLES.iter().position(|(v, _)| *v == name) {
                    if name == "P" && *target == Target::Normal {
                        return Err(bad(
                            pos,
                            "a `normal` formula cannot use P, the total normal force it is part of".into(),
                        ));
                    }
                    slots.push(Slot::Var(i));
                } else if let Some(i) = spec.param_names.iter().position(|p| p == name) {
                    slots.push(Slot::Param(i));
                } else {
                    let vars: Vec<&str> = FORMULA_VARIABLES.iter().map(|(v, _)| *v).collect();
                    let params = if spec.param_names.is_empty() {
                        "none".to_string()
                    } else {
                        spec.param_names.join(", ")
                    };
                    return Err(bad(
                        pos,
                        format!(
                            "`{var}` is neither a state variable ({}) nor a parameter of this effect ({params}); declare it as `{var} = <value>`",
                            vars.join(", ")
                        ),
                    ));
                }
            }
            if *target != Target::Normal || spec.phase != CustomPhase::Flight {
                compiled.push(Compiled {
                    target: *target,
                    expr,
                    slots,
                });
            } else {
                return Err(bad(
                    None,
                    "a `normal` contact force cannot act in phase = \"flight\"".into(),
                ));
            }
        }
        Ok(CustomTerm {
            spec: Arc::new(spec),
            compiled,
            params: values,
        })
    }

    /// The declaration this term was built from.
    pub fn spec(&self) -> &CustomTermSpec {
        &self.spec
    }

    #[inline]
    fn eval(&self, c: &Compiled, ctx: &Context) -> f64 {
        let s = ctx.state;
        let mut vals = [0.0f64; 32];
        for (slot, v) in c.slots.iter().zip(vals.iter_mut()) {
            *v = match *slot {
                Slot::Param(i) => self.params[i],
                Slot::Var(i) => match i {
                    0 => ctx.delta,
                    1 => ctx.delta_dot,
                    2 => ctx.delta_max,
                    3 => s.vx,
                    4 => s.vy,
                    5 => s.omega,
                    6 => ctx.slip,
                    7 => s.x,
                    8 => s.y,
                    9 => s.theta,
                    10 => ctx.t,
                    11 => ctx.normal_force,
                    12 => ctx.ball.mass_kg,
                    13 => ctx.ball.radius_m,
                    _ => ctx.gravity,
                },
            };
        }
        // A formula that cannot be evaluated yields NaN, which the simulator reports with the time and phase.
        c.expr.eval(&vals[..c.slots.len()]).unwrap_or(f64::NAN)
    }
}

/// Checks parentheses and function names, returning the character position of the first problem.
fn precheck(text: &str) -> Result<(), (usize, String)> {
    if text.len() > 2000 {
        return Err((0, "formula longer than 2000 characters".into()));
    }
    let chars: Vec<char> = text.chars().collect();
    let mut open = Vec::new();
    for (i, c) in chars.iter().enumerate() {
        match c {
            '(' => open.push(i),
            ')' if open.pop().is_none() => return Err((i, "this `)` closes nothing".into())),
            _ => {}
        }
    }
    if let Some(i) = open.pop() {
        return Err((i, "this `(` is never closed".into()));
    }
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut i = 0;
    while i < chars.len() {
        if ident(chars[i]) && !chars[i].is_ascii_digit() && (i == 0 || !ident(chars[i - 1])) {
            let start = i;
            while i < chars.len() && ident(chars[i]) {
                i += 1;
            }
            let name: String = chars[start..i].iter().collect();
            let mut j = i;
            while j < chars.len() && chars[j] == ' ' {
                j += 1;
            }
            if j < chars.len() && chars[j] == '(' && !known_function(&name) {
                return Err((
                    start,
                    format!(
                        "unknown function `{name}` (use sin, cos, tan, exp, ln, log10, sqrt, abs, signum, tanh, …)"
                    ),
                ));
            }
        } else {
            i += 1;
        }
    }
    Ok(())
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
    fn clone_box(&self) -> Box<dyn Effect> {
        Box::new(self.clone())
    }
}
