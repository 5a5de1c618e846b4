//! `model.toml`: which effects, their parameters (value, free or fixed in a fit, bounds) and per-surface
//! values.
//!
//! ```toml
//! [ball]                      # optional; the paper's tennis ball by default
//! mass_kg = 0.0567
//! radius_m = 0.0335
//! inertia_factor = 0.6667     # I = c·m·R²
//!
//! gravity_m_s2 = 9.81         # optional
//!
//! [effects.spring]
//! k = { value = 25650, free = true, min = 1000, max = 1e6 }
//! [effects.damping]
//! b = { value = 14, free = true }
//! [effects.coulomb]
//! mu = 0.5                    # a plain number is a fixed value
//!
//! [effects.pull_off]          # a custom term: formulas over the state and its own parameters
//! kind = "custom"
//! doc = "adhesive pull-off near separation"
//! phase = "restitution"       # contact (default) | compression | restitution | flight | always
//! normal = "-f0 * exp(-delta / d0)"
//! f0 = { value = 0.5, free = true, min = 0, max = 5 }
//! d0 = 1e-4
//!
//! [surfaces.clay]             # per-surface values override the effect's
//! spring.k = 25650
//! damping.b = 14
//! ```

use crate::effects::custom::{CustomPhase, FORMULA_VARIABLES, Target};
use crate::effects::{CustomTerm, CustomTermSpec, EffectInfo, builtin, builtin_effects};
use crate::error::num;
use crate::{Ball, Model, ModelError};
use std::path::Path;
use toml::{Table, Value};

/// A parameter's value and how a fit may move it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSetting {
    /// Value, in the parameter's unit.
    pub value: f64,
    /// True if a fit may move it.
    pub free: bool,
    /// Lower bound for a fit.
    pub min: f64,
    /// Upper bound for a fit.
    pub max: f64,
}

/// Names one parameter of one effect.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ParamRef {
    /// The effect's name in the model file.
    pub effect: String,
    /// The parameter's name.
    pub param: String,
}

impl std::fmt::Display for ParamRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}.{}", self.effect, self.param)
    }
}

/// Parameter values set for one surface.
pub type SurfaceValues = Vec<(ParamRef, ParamSetting)>;

/// What kind of effect a setting is.
#[derive(Debug, Clone)]
pub enum EffectKind {
    /// A built-in effect of the library.
    Builtin(&'static EffectInfo),
    /// A custom formula term.
    Custom(CustomTermSpec),
}

/// One effect of the model file with its parameters (values not yet resolved per surface).
#[derive(Debug, Clone)]
pub struct EffectSetting {
    /// The effect's name (its key under `[effects]`).
    pub name: String,
    /// Built-in or custom.
    pub kind: EffectKind,
    /// Parameters in the effect's order; `None` where the file gives no value (a surface must).
    pub params: Vec<(String, Option<ParamSetting>)>,
}

/// A parsed model file.
#[derive(Debug, Clone)]
pub struct ModelSpec {
    /// Where it came from (a path, or "built-in paper model"), for messages.
    pub origin: String,
    /// The ball.
    pub ball: Ball,
    /// Gravitational acceleration, m/s².
    pub gravity: f64,
    /// The effects, in file order.
    pub effects: Vec<EffectSetting>,
    /// Per-surface parameter values, by surface name (file order).
    pub surfaces: Vec<(String, SurfaceValues)>,
}

/// The model file with the paper's three surfaces (also at `fixtures/paper-model.toml`).
pub const PAPER_MODEL_TOML: &str = include_str!("../../../fixtures/paper-model.toml");

fn known_effect_names() -> String {
    let mut names: Vec<&str> = builtin_effects().iter().map(|e| e.name).collect();
    names.push("custom (kind = \"custom\")");
    names.join(", ")
}

impl ModelSpec {
    /// Reads a model file.
    pub fn load(path: &Path) -> Result<ModelSpec, ModelError> {
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ModelError::Syntax {
            origin: origin.clone(),
            message: format!("cannot read: {e}"),
        })?;
        ModelSpec::parse(&text, &origin)
    }

    /// The paper's model with its three surfaces (clay, tape1, tape2).
    pub fn paper() -> ModelSpec {
        ModelSpec::parse(PAPER_MODEL_TOML, "built-in paper model").expect("the shipped paper model parses")
    }

    /// Parses model-file text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<ModelSpec, ModelError> {
        let syntax = |message: String| ModelError::Syntax {
            origin: origin.to_string(),
            message,
        };
        let table: Table = text
            .parse()
            .map_err(|e: toml::de::Error| syntax(e.to_string().trim_end().to_string()))?;
        let mut ball = Ball::TENNIS;
        let mut gravity = crate::model::STANDARD_GRAVITY;
        let mut effects = Vec::new();
        let mut surfaces_raw = None;
        for (key, value) in &table {
            match key.as_str() {
                "ball" => ball = parse_ball(value, origin)?,
                "gravity_m_s2" => {
                    gravity = number(value).ok_or_else(|| syntax("gravity_m_s2 must be a number".into()))?
                }
                "model" => {} // free-form metadata: name, description, version
                "effects" => {
                    let t = value
                        .as_table()
                        .ok_or_else(|| syntax("`effects` must be a table of [effects.NAME]".into()))?;
                    for (name, body) in t {
                        effects.push(parse_effect(name, body, origin)?);
                    }
                }
                "surfaces" => surfaces_raw = Some(value),
                other => {
                    return Err(syntax(format!(
                        "unknown key `{other}` (expected ball, gravity_m_s2, model, effects, surfaces)"
                    )));
                }
            }
        }
        check_range(origin, "gravity_m_s2", gravity, GRAVITY_RANGE, "m/s²")?;
        let mut spec = ModelSpec {
            origin: origin.to_string(),
            ball,
            gravity,
            effects,
            surfaces: Vec::new(),
        };
        if let Some(raw) = surfaces_raw {
            spec.surfaces = spec.parse_surfaces(raw)?;
        }
        Ok(spec)
    }

    fn parse_surfaces(&self, raw: &Value) -> Result<Vec<(String, SurfaceValues)>, ModelError> {
        let origin = &self.origin;
        let syntax = |message: String| ModelError::Syntax {
            origin: origin.clone(),
            message,
        };
        let t = raw
            .as_table()
            .ok_or_else(|| syntax("`surfaces` must be a table of [surfaces.NAME]".into()))?;
        let mut out = Vec::new();
        for (surface, body) in t {
            let body = body
                .as_table()
                .ok_or_else(|| syntax(format!("surfaces.{surface} must be a table")))?;
            let mut values = Vec::new();
            for (effect, params) in body {
                let setting = self.effects.iter().find(|e| &e.name == effect).ok_or_else(|| {
                    syntax(format!(
                        "surfaces.{surface} sets `{effect}`, but the model has no effect `{effect}` (its effects: {})",
                        self.effects
                            .iter()
                            .map(|e| e.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                })?;
                let params = params.as_table().ok_or_else(|| {
                    syntax(format!(
                        "surfaces.{surface}.{effect} must be a table of parameter values"
                    ))
                })?;
                for (param, v) in params {
                    let Some(i) = setting.params.iter().position(|(n, _)| n == param) else {
                        return Err(ModelError::UnknownParam {
                            origin: origin.clone(),
                            effect: effect.clone(),
                            param: param.clone(),
                            known: setting
                                .params
                                .iter()
                                .map(|(n, _)| n.as_str())
                                .collect::<Vec<_>>()
                                .join(", "),
                        });
                    };
                    let inherited = setting.params[i].1;
                    let s = parse_param(
                        v,
                        inherited,
                        &format!("surfaces.{surface}.{effect}"),
                        param,
                        setting.valid_range(param),
                        origin,
                    )?;
                    values.push((
                        ParamRef {
                            effect: effect.clone(),
                            param: param.clone(),
                        },
                        s,
                    ));
                }
            }
            out.push((surface.clone(), values));
        }
        Ok(out)
    }

    /// The surfaces the file has values for.
    pub fn surface_names(&self) -> Vec<&str> {
        self.surfaces.iter().map(|(s, _)| s.as_str()).collect()
    }

    /// Every parameter's setting for `surface` (or the file's own values with `None`), in effect order.
    pub fn settings(&self, surface: Option<&str>) -> Result<Vec<(ParamRef, ParamSetting)>, ModelError> {
        let overrides = match surface {
            None => None,
            Some(name) => match self.surfaces.iter().find(|(s, _)| s == name) {
                Some((_, v)) => Some(v),
                None if self.surfaces.is_empty() => None,
                None => {
                    return Err(ModelError::UnknownSurface {
                        origin: self.origin.clone(),
                        surface: name.to_string(),
                        known: self.surface_names().join(", "),
                    });
                }
            },
        };
        let mut out = Vec::new();
        for e in &self.effects {
            for (p, base) in &e.params {
                let r = ParamRef {
                    effect: e.name.clone(),
                    param: p.clone(),
                };
                let over = overrides.and_then(|o| o.iter().find(|(q, _)| q == &r)).map(|(_, s)| *s);
                let Some(s) = over.or(*base) else {
                    let (unit, doc) = e.describe(p);
                    let where_ = surface
                        .map(|s| format!(" (surface `{s}` does not set it either)"))
                        .unwrap_or_default();
                    return Err(ModelError::MissingParam {
                        origin: self.origin.clone(),
                        effect: e.name.clone(),
                        param: p.clone(),
                        unit,
                        doc: format!("{doc}{where_}"),
                    });
                };
                out.push((r, s));
            }
        }
        Ok(out)
    }

    /// Builds the model for `surface` (per-surface values applied), or with the file's own values.
    pub fn build(&self, surface: Option<&str>) -> Result<Model, ModelError> {
        let settings = self.settings(surface)?;
        let mut model = Model::new(self.ball, self.gravity);
        let mut it = settings.iter();
        for e in &self.effects {
            let values: Vec<f64> = it.by_ref().take(e.params.len()).map(|(_, s)| s.value).collect();
            match &e.kind {
                EffectKind::Builtin(info) => model.push((info.build)(&values)),
                EffectKind::Custom(spec) => {
                    model.push(Box::new(CustomTerm::compile(spec.clone(), values, &self.origin)?))
                }
            }
        }
        let force = probe_normal_force(&model);
        if force <= 0.0 {
            let detail = if self.effects.is_empty() {
                "the file has no effects at all".to_string()
            } else {
                let normal: Vec<String> = settings
                    .iter()
                    .filter(|(r, _)| {
                        self.effects.iter().any(|e| {
                            e.name == r.effect
                                && match &e.kind {
                                    EffectKind::Builtin(info) => info.group == "normal",
                                    EffectKind::Custom(spec) => spec.formulas.iter().any(|(t, _)| *t == Target::Normal),
                                }
                        })
                    })
                    .map(|(r, s)| format!("{r} = {}", s.value))
                    .collect();
                if normal.is_empty() {
                    "no normal-force effect".to_string()
                } else {
                    normal.join(", ")
                }
            };
            return Err(ModelError::NoNormalForce {
                origin: self.origin.clone(),
                surface: surface.map(|s| format!(" (surface `{s}`)")).unwrap_or_default(),
                probe_mm: PROBE_DEPTH_M * 1e3,
                force_n: force,
                detail,
            });
        }
        Ok(model)
    }

    /// True if the model has an effect called `name`.
    pub fn has_effect(&self, name: &str) -> bool {
        self.effects.iter().any(|e| e.name == name)
    }
}

impl EffectSetting {
    fn valid_range(&self, param: &str) -> (f64, f64, &'static str) {
        match &self.kind {
            EffectKind::Builtin(info) => info
                .params
                .iter()
                .find(|p| p.name == param)
                .map(|p| (p.min, p.max, p.unit))
                .unwrap_or((f64::NEG_INFINITY, f64::INFINITY, "")),
            EffectKind::Custom(_) => (f64::NEG_INFINITY, f64::INFINITY, ""),
        }
    }

    fn describe(&self, param: &str) -> (String, String) {
        match &self.kind {
            EffectKind::Builtin(info) => info
                .params
                .iter()
                .find(|p| p.name == param)
                .map(|p| (p.unit.to_string(), p.doc.to_string()))
                .unwrap_or_default(),
            EffectKind::Custom(_) => ("custom".into(), "parameter of a custom term".into()),
        }
    }
}

/// Physical range of gravity, m/s² (0 for a test without weight; the largest planet's is 25).
const GRAVITY_RANGE: (f64, f64) = (0.0, 100.0);
/// Physical range of the ball's mass, kg (a table-tennis ball is 2.7 g, a shot put 7 kg).
const MASS_RANGE: (f64, f64) = (1e-4, 20.0);
/// Physical range of the ball's radius, m.
const RADIUS_RANGE: (f64, f64) = (1e-3, 0.5);
/// Physical range of the inertia factor c = I/(m·R²): a sphere's lies between a point mass at the centre
/// and a thin shell (2/3), with room for a rounded 0.667.
const INERTIA_FACTOR_RANGE: (f64, f64) = (0.05, 0.67);
/// Penetration at which the model's normal force is probed for an elastic term, m.
const PROBE_DEPTH_M: f64 = 1e-3;

fn check_range(
    origin: &str,
    key: &str,
    value: f64,
    (min, max): (f64, f64),
    unit: &'static str,
) -> Result<f64, ModelError> {
    if value.is_finite() && value >= min && value <= max {
        Ok(value)
    } else {
        let range = format!("[{}, {}]{}", num(min), num(max), unit_suffix(unit));
        let reason = if value <= 0.0 && min > 0.0 {
            format!("must be > 0 (its physical range is {range})")
        } else {
            format!("is outside its physical range {range}")
        };
        Err(ModelError::OutOfRange {
            origin: origin.to_string(),
            key: key.to_string(),
            value,
            reason,
        })
    }
}

/// The normal force `model` pushes with at [`PROBE_DEPTH_M`] of penetration, at rest, in compression, N.
fn probe_normal_force(model: &Model) -> f64 {
    use crate::effects::{Context, Phase};
    let state = crate::State {
        y: model.ball.radius_m - PROBE_DEPTH_M,
        ..crate::State::default()
    };
    let ctx = Context::of(0.0, &state, Phase::Compression, &model.ball, model.gravity, 0.0);
    model.effects().iter().map(|e| e.normal_force(&ctx)).sum()
}

fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Float(f) => Some(*f),
        Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

fn parse_ball(v: &Value, origin: &str) -> Result<Ball, ModelError> {
    let syntax = |message: String| ModelError::Syntax {
        origin: origin.to_string(),
        message,
    };
    let t = v.as_table().ok_or_else(|| syntax("`ball` must be a table".into()))?;
    let mut ball = Ball::TENNIS;
    for (k, v) in t {
        let x = number(v).ok_or_else(|| syntax(format!("ball.{k} must be a number")))?;
        let key = format!("ball.{k}");
        match k.as_str() {
            "mass_kg" => ball.mass_kg = check_range(origin, &key, x, MASS_RANGE, "kg")?,
            "radius_m" => ball.radius_m = check_range(origin, &key, x, RADIUS_RANGE, "m")?,
            "diameter_m" => {
                let (lo, hi) = RADIUS_RANGE;
                ball.radius_m = check_range(origin, &key, x, (2.0 * lo, 2.0 * hi), "m")? / 2.0
            }
            "inertia_factor" => ball.inertia_factor = check_range(origin, &key, x, INERTIA_FACTOR_RANGE, "")?,
            "gravity_m_s2" => {
                return Err(syntax(
                    "gravity_m_s2 ended up inside [ball]: TOML files a key under the table above it, so put it before the first [table]".into(),
                ));
            }
            other => {
                return Err(syntax(format!(
                    "unknown key ball.{other} (expected mass_kg, radius_m or diameter_m, inertia_factor)"
                )));
            }
        }
    }
    Ok(ball)
}

fn unit_suffix(unit: &str) -> String {
    if unit.is_empty() || unit == "1" {
        String::new()
    } else {
        format!(" {unit}")
    }
}

fn parse_param(
    v: &Value,
    inherited: Option<ParamSetting>,
    effect: &str,
    param: &str,
    (lo, hi, unit): (f64, f64, &str),
    origin: &str,
) -> Result<ParamSetting, ModelError> {
    let invalid = |value: f64, reason: String| ModelError::InvalidValue {
        origin: origin.to_string(),
        effect: effect.to_string(),
        param: param.to_string(),
        value,
        reason,
    };
    let syntax = |message: String| ModelError::Syntax {
        origin: origin.to_string(),
        message,
    };
    let mut s = inherited.unwrap_or(ParamSetting {
        value: f64::NAN,
        free: false,
        min: lo,
        max: hi,
    });
    match v {
        Value::Table(t) => {
            for (k, x) in t {
                match k.as_str() {
                    "value" => {
                        s.value = number(x).ok_or_else(|| syntax(format!("{effect}.{param}.value must be a number")))?
                    }
                    "free" => {
                        s.free = x
                            .as_bool()
                            .ok_or_else(|| syntax(format!("{effect}.{param}.free must be true or false")))?
                    }
                    "min" => {
                        s.min = number(x).ok_or_else(|| syntax(format!("{effect}.{param}.min must be a number")))?
                    }
                    "max" => {
                        s.max = number(x).ok_or_else(|| syntax(format!("{effect}.{param}.max must be a number")))?
                    }
                    other => {
                        return Err(syntax(format!(
                            "{effect}.{param}: unknown key `{other}` (expected value, free, min, max)"
                        )));
                    }
                }
            }
        }
        other => {
            s.value = number(other).ok_or_else(|| {
                syntax(format!(
                    "{effect}.{param} must be a number or {{ value = …, free = …, min = …, max = … }}"
                ))
            })?;
            if inherited.is_none() {
                s.free = false;
            }
        }
    }
    if s.value.is_nan() {
        return Err(syntax(format!("{effect}.{param} has no `value`")));
    }
    if !s.value.is_finite() {
        return Err(invalid(s.value, "must be finite".into()));
    }
    if s.value < lo || s.value > hi {
        let why = match param {
            "k" | "k_h" if s.value < 0.0 => "; a negative stiffness would pull the ball into the surface",
            _ => "",
        };
        return Err(invalid(
            s.value,
            format!(
                "outside its physical range [{}, {}]{}{why}",
                num(lo),
                num(hi),
                unit_suffix(unit)
            ),
        ));
    }
    s.min = s.min.max(lo);
    s.max = s.max.min(hi);
    if s.min > s.max {
        return Err(invalid(s.value, format!("bounds min = {} > max = {}", s.min, s.max)));
    }
    if s.free && (s.value < s.min || s.value > s.max) {
        return Err(invalid(
            s.value,
            format!("outside its fit bounds [{}, {}]", s.min, s.max),
        ));
    }
    Ok(s)
}

fn parse_effect(name: &str, body: &Value, origin: &str) -> Result<EffectSetting, ModelError> {
    let syntax = |message: String| ModelError::Syntax {
        origin: origin.to_string(),
        message,
    };
    let t = body
        .as_table()
        .ok_or_else(|| syntax(format!("effects.{name} must be a table")))?;
    let kind = t
        .get("kind")
        .map(|k| {
            k.as_str()
                .ok_or_else(|| syntax(format!("effects.{name}.kind must be a string")))
        })
        .transpose()?;
    let builtin_name = kind.unwrap_or(name);
    if builtin_name == "custom" {
        return parse_custom(name, t, origin);
    }
    let info = builtin(builtin_name).ok_or_else(|| ModelError::UnknownEffect {
        origin: origin.to_string(),
        name: builtin_name.to_string(),
        known: known_effect_names(),
    })?;
    if kind.is_some() && builtin_name != name {
        return Err(syntax(format!(
            "effects.{name}: a built-in effect is named by its key (write [effects.{builtin_name}]); `kind` is only for custom terms"
        )));
    }
    let mut params: Vec<(String, Option<ParamSetting>)> = Vec::new();
    for p in info.params {
        let setting = match t.get(p.name) {
            Some(v) => Some(parse_param(
                v,
                None,
                &format!("effects.{name}"),
                p.name,
                (p.min, p.max, p.unit),
                origin,
            )?),
            None => p.default.map(|d| ParamSetting {
                value: d,
                free: false,
                min: p.min,
                max: p.max,
            }),
        };
        params.push((p.name.to_string(), setting));
    }
    for k in t.keys() {
        if k != "kind" && k != "doc" && !info.params.iter().any(|p| p.name == k) {
            return Err(ModelError::UnknownParam {
                origin: origin.to_string(),
                effect: name.to_string(),
                param: k.clone(),
                known: info.params.iter().map(|p| p.name).collect::<Vec<_>>().join(", "),
            });
        }
    }
    Ok(EffectSetting {
        name: name.to_string(),
        kind: EffectKind::Builtin(info),
        params,
    })
}

fn parse_custom(name: &str, t: &Table, origin: &str) -> Result<EffectSetting, ModelError> {
    let syntax = |message: String| ModelError::Syntax {
        origin: origin.to_string(),
        message,
    };
    if builtin(name).is_some() {
        return Err(syntax(format!(
            "effects.{name}: a custom term cannot take the name of a built-in effect"
        )));
    }
    let mut formulas = Vec::new();
    let mut phase = CustomPhase::Contact;
    let mut doc = String::new();
    let mut params = Vec::new();
    for (k, v) in t {
        if let Some((_, target)) = Target::KEYS.iter().find(|(key, _)| key == k) {
            let f = v
                .as_str()
                .ok_or_else(|| syntax(format!("effects.{name}.{k} must be a formula in quotes")))?;
            formulas.push((*target, f.to_string()));
            continue;
        }
        match k.as_str() {
            "kind" => {}
            "doc" => doc = v.as_str().unwrap_or_default().to_string(),
            "phase" => {
                let s = v.as_str().unwrap_or_default();
                phase = CustomPhase::parse(s).ok_or_else(|| {
                    syntax(format!(
                        "effects.{name}.phase = {v}: expected \"contact\", \"compression\", \"restitution\", \"flight\" or \"always\""
                    ))
                })?;
            }
            p => {
                if FORMULA_VARIABLES.iter().any(|(var, _)| *var == p) {
                    return Err(syntax(format!(
                        "effects.{name}: parameter `{p}` would hide the state variable of that name"
                    )));
                }
                let s = parse_param(
                    v,
                    None,
                    &format!("effects.{name}"),
                    p,
                    (f64::NEG_INFINITY, f64::INFINITY, ""),
                    origin,
                )?;
                params.push((p.to_string(), Some(s)));
            }
        }
    }
    if formulas.is_empty() {
        return Err(syntax(format!(
            "effects.{name}: a custom term needs at least one formula (normal, tangential, force_x, force_y or torque)"
        )));
    }
    let spec = CustomTermSpec {
        name: name.to_string(),
        doc,
        phase,
        formulas,
        param_names: params.iter().map(|(n, _)| n.clone()).collect(),
    };
    // Check the formulas now, so a typo is reported when the file is read.
    let values: Vec<f64> = params.iter().map(|(_, s)| s.map(|s| s.value).unwrap_or(0.0)).collect();
    CustomTerm::compile(spec.clone(), values, origin)?;
    Ok(EffectSetting {
        name: name.to_string(),
        kind: EffectKind::Custom(spec),
        params,
    })
}
