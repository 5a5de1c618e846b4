//! The scenario file: the session to render (camera, ball, surfaces with their physics, shots) and how it
//! is read and checked.

use crate::RenderError;
use crate::look::{LookSpec, Range};
use crate::rng::{Rng, derive};
use bouncelab_model::ModelSpec;
use serde::Deserialize;
use std::path::Path;
use toml::{Table, Value};

/// What a surface band looks like.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Texture {
    /// Granular green clay: fine, grainy, mid-dark, with brighter grains.
    Clay,
    /// White court-line tape: bright, woven herringbone.
    WhiteTape,
    /// Green court-line tape: mid-gray, woven.
    GreenTape,
}

impl Texture {
    /// Name as written in scenario files.
    pub fn name(self) -> &'static str {
        match self {
            Texture::Clay => "clay",
            Texture::WhiteTape => "white_tape",
            Texture::GreenTape => "green_tape",
        }
    }
}

/// Image file format of the frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// PNG with fast compression (default).
    Png,
    /// Uncompressed TIFF.
    Tiff,
}

impl Format {
    /// The extension of its frame files, with the dot (`.png`, `.tif`).
    pub(crate) fn extension(self) -> &'static str {
        match self {
            Format::Png => ".png",
            Format::Tiff => ".tif",
        }
    }
}

/// Which image direction is down the slope (`docs/session.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum Downslope {
    /// Down-slope is +x_px (to the right); the default.
    #[serde(rename = "+x")]
    PlusX,
    /// Down-slope is −x_px: the image is the mirror image of the `+x` camera's.
    #[serde(rename = "-x")]
    MinusX,
}

impl Downslope {
    /// As written in `session.toml`.
    pub fn as_str(self) -> &'static str {
        match self {
            Downslope::PlusX => "+x",
            Downslope::MinusX => "-x",
        }
    }
    /// +1 or −1: the sign of x_px along the down-slope direction.
    pub fn sign(self) -> f64 {
        match self {
            Downslope::PlusX => 1.0,
            Downslope::MinusX => -1.0,
        }
    }
}

/// The high-speed camera and its lighting (`[camera]`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Camera {
    /// Frame width, pixels (default 512).
    pub width: u32,
    /// Frame height, pixels (default 512).
    pub height: u32,
    /// Scale, metres per pixel (default 4.0e-4: the ball is about 168 px across).
    pub scale_m_per_px: f64,
    /// Frame rate, frames per second (default 10,000).
    pub fps: f64,
    /// Exposure time, s (default 5e-5); a frame integrates the window centred on its time.
    pub exposure_s: f64,
    /// Read noise, standard deviation in DN of the 8-bit scale (default 1.8).
    pub read_noise: f64,
    /// Shot-noise gain, DN per photo-electron: the noise variance is `read_noise² + gain·signal` with the
    /// signal in DN (default 0.06).
    pub shot_noise_gain: f64,
    /// Light flicker, relative amplitude of the global brightness modulation (default 0.03).
    pub flicker_amplitude: f64,
    /// Light flicker frequency, Hz (default 120: mains-powered lights).
    pub flicker_hz: f64,
    /// Camera roll, degrees counter-clockwise with respect to the surface: the whole scene turns in the
    /// image and the surface line is tilted (default 0). Adds to a shot's `camera_roll` effect.
    pub roll_deg: f64,
    /// Bits of the frame data: 8 (8-bit files), 12 (12-bit data in 16-bit files, shifted left by 4: values
    /// × 16, as 12-bit cameras write them) or 16 (default 8).
    pub bit_depth: u8,
    /// Frame file format (default png).
    pub format: Format,
    /// Image direction that is down the slope (default "+x").
    pub downslope: Downslope,
    /// Frame file name pattern with one `{}` or `{:0N}` placeholder for the frame number, which must be
    /// the last number of the name (default `C001H001S0001{:06}.png`, `.tif` for TIFF).
    pub naming: Option<String>,
    /// Sub-exposure samples averaged for motion blur at the ball's edge (default 6).
    pub blur_samples: u32,
    /// Lens vignetting: relative brightness lost at the image corners (default 0.22).
    pub vignetting: f64,
    /// Fixed-pattern noise of the sensor: standard deviation of the per-column offsets, DN (rows get half
    /// of it); the same in every clip of a session (default 0.5).
    pub fixed_pattern_noise: f64,
    /// Fraction of hot pixels (a fixed offset of +20 to +80 DN, the same in every clip; default 3e-5).
    pub hot_pixel_fraction: f64,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            width: 512,
            height: 512,
            scale_m_per_px: 4.0e-4,
            fps: 10_000.0,
            exposure_s: 5e-5,
            read_noise: 1.8,
            shot_noise_gain: 0.06,
            flicker_amplitude: 0.03,
            flicker_hz: 120.0,
            roll_deg: 0.0,
            bit_depth: 8,
            format: Format::Png,
            downslope: Downslope::PlusX,
            naming: None,
            blur_samples: 6,
            vignetting: 0.22,
            fixed_pattern_noise: 0.5,
            hot_pixel_fraction: 3e-5,
        }
    }
}

impl Camera {
    /// The naming pattern in use (the default one for the format when none is given).
    pub fn naming_pattern(&self) -> String {
        self.naming.clone().unwrap_or_else(|| match self.format {
            Format::Png => "C001H001S0001{:06}.png".into(),
            Format::Tiff => "C001H001S0001{:06}.tif".into(),
        })
    }

    /// The file name of frame `frame` (0-based).
    pub fn frame_name(&self, frame: usize) -> String {
        let p = parse_naming(&self.naming_pattern()).expect("naming checked when the scenario was read");
        format!("{}{:0width$}{}", p.0, frame, p.2, width = p.1)
    }
}

/// (prefix, zero-padding width, suffix) of a naming pattern.
pub(crate) fn parse_naming(pattern: &str) -> Result<(String, usize, String), String> {
    let open = pattern
        .find('{')
        .ok_or("needs a `{}` or `{:06}` placeholder for the frame number")?;
    let close = pattern[open..].find('}').map(|c| open + c).ok_or("unclosed `{`")?;
    let inner = &pattern[open + 1..close];
    let width = if inner.is_empty() {
        0
    } else if let Some(w) = inner.strip_prefix(":0") {
        w.parse::<usize>()
            .map_err(|_| format!("placeholder `{{{inner}}}`: expected `{{}}` or `{{:0N}}`"))?
    } else {
        return Err(format!("placeholder `{{{inner}}}`: expected `{{}}` or `{{:0N}}`"));
    };
    let (prefix, suffix) = (&pattern[..open], &pattern[close + 1..]);
    if suffix.contains(['{', '}']) || prefix.contains(['{', '}']) {
        return Err("only one placeholder is allowed".into());
    }
    if suffix.chars().any(|c| c.is_ascii_digit()) {
        return Err("no digit may follow the placeholder: the frame number must be the last number".into());
    }
    if prefix.contains(['/', '\\']) || suffix.contains(['/', '\\']) {
        return Err("a file name, not a path".into());
    }
    Ok((prefix.to_string(), width.min(20), suffix.to_string()))
}

/// The ball (`[ball]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BallSpec {
    /// Diameter, m (default 0.067).
    pub diameter_m: f64,
    /// Mass, kg (default 0.0567).
    pub mass_kg: f64,
    /// Inertia factor c in I = c·m·R² (default 2/3, a thin shell).
    pub inertia_factor: f64,
}

impl Default for BallSpec {
    fn default() -> Self {
        BallSpec {
            diameter_m: 0.067,
            mass_kg: 0.0567,
            inertia_factor: 2.0 / 3.0,
        }
    }
}

/// A surface of the session (`[surfaces.NAME]`).
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// Its name (as in `clips.csv`).
    pub name: String,
    /// How its band looks.
    pub texture: Texture,
    /// Its per-surface model values, in `model.toml`'s `[surfaces.NAME]` syntax (`spring.k = 25650`).
    pub model_values: Table,
}

/// The `[random_physics]` table: physics drawn per shot from the shot's seed, replacing the shot's drop
/// height and incline and its surface's k, b and μ. Draws are rounded to 1 mm, 0.1°, 10 N/m, 0.1 N·s/m and
/// 0.01 (so clip names and `clips.csv` show them exactly).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomPhysics {
    /// Drop height, m.
    pub drop_height_m: Option<Range>,
    /// Incline β, degrees.
    pub angle_deg: Option<Range>,
    /// Spring stiffness k (`spring.k`), N/m.
    pub k: Option<Range>,
    /// Compression damping b (`damping.b`), N·s/m.
    pub b: Option<Range>,
    /// Coulomb friction μ (`coulomb.mu`).
    pub mu: Option<Range>,
}

/// Stream of a shot's random physics, derived from the shot's seed.
const PHYSICS_STREAM: u64 = 0x5048_5953_5354_524D;

/// A model value replaced for one shot: (effect, parameter, value).
pub(crate) type Override = (&'static str, &'static str, f64);

impl RandomPhysics {
    /// The model parameters it draws: (key, effect, parameter, range, rounding step).
    fn model_keys(&self) -> [(&'static str, &'static str, &'static str, Option<Range>, f64); 3] {
        [
            ("k", "spring", "k", self.k, 10.0),
            ("b", "damping", "b", self.b, 0.1),
            ("mu", "coulomb", "mu", self.mu, 0.01),
        ]
    }
}

/// The value at `u` ∈ [0, 1) of range `r`, rounded to a multiple of `step` (dividing by a whole number for
/// decimal steps, so 0.287 is printed as 0.287) and kept within `r`.
fn rounded(r: Range, u: f64, step: f64) -> f64 {
    let x = r.lo + (r.hi - r.lo) * u;
    let q = if step >= 1.0 {
        (x / step).round() * step
    } else {
        let per_unit = (1.0 / step).round();
        (x * per_unit).round() / per_unit
    };
    q.clamp(r.lo, r.hi)
}

/// One drop shot.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shot {
    /// Surface name.
    pub surface: String,
    /// Incline of the surface β, degrees.
    pub angle_deg: f64,
    /// Drop height, m (vertical, from the ball's bottom to the point it hits).
    pub drop_height_m: f64,
    /// Repeat number, from 1.
    #[serde(default = "one")]
    pub repeat: u32,
    /// Extra (hidden) effects switched on for this shot, by name in `[extra_effects]`.
    #[serde(default)]
    pub effects: Vec<String>,
}

fn one() -> u32 {
    1
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Grid {
    surfaces: Vec<String>,
    drop_heights_m: Vec<f64>,
    angles_deg: Vec<f64>,
    #[serde(default = "one")]
    repeats: u32,
    #[serde(default)]
    effects: Vec<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default = "default_pre")]
    pre_contact_ms: f64,
    #[serde(default = "default_post")]
    post_separation_ms: f64,
    #[serde(default)]
    ball: BallSpec,
    #[serde(default)]
    camera: Camera,
    #[serde(default)]
    model: Option<Table>,
    #[serde(default)]
    surfaces: Table,
    #[serde(default)]
    shots: Vec<Shot>,
    #[serde(default)]
    grid: Option<Grid>,
    #[serde(default)]
    extra_effects: Table,
    #[serde(default)]
    look: Option<LookSpec>,
    #[serde(default)]
    random_physics: Option<RandomPhysics>,
}

fn default_pre() -> f64 {
    15.0
}
fn default_post() -> f64 {
    20.0
}

/// A session to render: read from a scenario file ([`Scenario::load`], [`Scenario::parse`]) or a built-in
/// preset ([`Scenario::preset`]).
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Where it came from (a path or `preset NAME`), for messages.
    pub origin: String,
    /// The scenario's text as read (written to `truth/scenario.toml`).
    pub source: String,
    /// Name (metadata).
    pub name: String,
    /// Description (metadata, copied into `session.toml`).
    pub description: String,
    /// Session seed; per-shot seeds are derived from it and the shot index.
    pub seed: u64,
    /// Time from the first frame to the touch, s (a random 0–2 frames are added per shot).
    pub pre_contact_s: f64,
    /// Time from separation to the last frame, s.
    pub post_separation_s: f64,
    /// The ball.
    pub ball: BallSpec,
    /// The camera.
    pub camera: Camera,
    /// The surfaces, in file order.
    pub surfaces: Vec<Surface>,
    /// The shots, in order (`[[shots]]` first, then the `[grid]` expanded surface × angle × height ×
    /// repeat), as written: with `[random_physics]`, [`Scenario::shot`] gives the values each shot is
    /// rendered with.
    pub shots: Vec<Shot>,
    /// The `[look]` table: when present each shot's appearance and camera are drawn from its ranges.
    pub look: Option<LookSpec>,
    /// The `[random_physics]` table: when present each shot's physics is drawn from its ranges.
    pub random_physics: Option<RandomPhysics>,
    model: Table,
    extra_effects: Table,
}

impl Scenario {
    /// Reads a scenario file.
    pub fn load(path: &Path) -> Result<Scenario, RenderError> {
        let text = std::fs::read_to_string(path).map_err(|source| RenderError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Scenario::parse(&text, &path.display().to_string())
    }

    /// A built-in preset (see [`crate::presets`]).
    pub fn preset(name: &str) -> Result<Scenario, RenderError> {
        let text = crate::presets::preset_toml(name).ok_or_else(|| RenderError::UnknownPreset {
            name: name.to_string(),
            known: crate::presets::preset_names().join(", "),
        })?;
        Scenario::parse(&text, &format!("preset {name}"))
    }

    /// Parses scenario text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Scenario, RenderError> {
        let at = Origin(origin);
        let raw: Raw = toml::from_str(text).map_err(|e| at.syntax(e.to_string().trim_end().replace('\n', " ")))?;
        check_camera(&raw.camera, &at)?;
        check_ball_and_timing(&raw, &at)?;
        let surfaces = read_surfaces(&raw.surfaces, &at)?;
        let mut shots = raw.shots;
        if let Some(g) = &raw.grid {
            expand_grid(g, &surfaces, &mut shots, &at)?;
        }
        check_shots(&shots, &surfaces, &raw.extra_effects, &at)?;
        let model = model_table(raw.model, &at)?;
        let scenario = Scenario {
            origin: origin.to_string(),
            source: text.to_string(),
            name: raw.name.unwrap_or_else(|| "scenario".into()),
            description: raw.description.unwrap_or_default(),
            seed: raw.seed,
            pre_contact_s: raw.pre_contact_ms * 1e-3,
            post_separation_s: raw.post_separation_ms * 1e-3,
            ball: raw.ball,
            camera: raw.camera,
            surfaces,
            shots,
            look: raw.look,
            random_physics: raw.random_physics,
            model,
            extra_effects: raw.extra_effects,
        };
        if let Some(l) = &scenario.look {
            l.check(origin)?;
        }
        scenario.check_surface_values()?;
        scenario.check_effect_sets()?;
        if let Some(rp) = scenario.random_physics {
            scenario.check_random_physics(&rp)?;
        }
        Ok(scenario)
    }

    /// Surface values may only name effects of the model or of `[extra_effects]`.
    fn check_surface_values(&self) -> Result<(), RenderError> {
        let model_effects = self.model.get("effects").and_then(Value::as_table);
        for s in &self.surfaces {
            for key in s.model_values.keys() {
                let known = model_effects.is_some_and(|m| m.contains_key(key)) || self.extra_effects.contains_key(key);
                if !known {
                    return Err(Origin(&self.origin).syntax(format!(
                        "surfaces.{}.{key}: no effect `{key}` in [model.effects] or [extra_effects] (write e.g. spring.k = 25650)",
                        s.name
                    )));
                }
            }
        }
        Ok(())
    }

    /// Builds the model of every effect set the shots use, for every surface they use it on.
    fn check_effect_sets(&self) -> Result<(), RenderError> {
        let mut seen: Vec<(Vec<String>, String)> = Vec::new();
        for s in &self.shots {
            let key = (s.effects.clone(), s.surface.clone());
            if seen.contains(&key) {
                continue;
            }
            let spec = self.model_spec(&s.effects)?;
            spec.build(Some(&s.surface)).map_err(|source| RenderError::Model {
                origin: self.origin.clone(),
                context: format!("surface `{}` with effects [{}]", s.surface, s.effects.join(", ")),
                source: Box::new(source),
            })?;
            seen.push(key);
        }
        Ok(())
    }

    /// Checks `[random_physics]`: finite ranges, inclines and heights in range, and every drawn model value
    /// accepted by the model crate at both ends of its range, for every surface and effect set shots use.
    fn check_random_physics(&self, rp: &RandomPhysics) -> Result<(), RenderError> {
        let invalid = |field: &str, r: Range, reason: &str| RenderError::InvalidValue {
            origin: self.origin.clone(),
            field: format!("random_physics.{field}"),
            value: r.to_string(),
            reason: reason.to_string(),
        };
        let finite = |r: Range| r.lo.is_finite() && r.hi.is_finite() && r.lo <= r.hi;
        if let Some(r) = rp.drop_height_m
            && !(finite(r) && r.lo > 0.0 && r.hi <= 10.0)
        {
            return Err(invalid("drop_height_m", r, "must lie within (0, 10] m, low ≤ high"));
        }
        if let Some(r) = rp.angle_deg
            && !(finite(r) && r.lo >= -60.0 && r.hi <= 60.0)
        {
            return Err(invalid("angle_deg", r, "must lie within ±60°, low ≤ high"));
        }
        let base = self.model_spec(&[])?;
        for (key, effect, _, range, _) in rp.model_keys() {
            let Some(r) = range else { continue };
            if !finite(r) {
                return Err(invalid(key, r, "must be finite with low ≤ high"));
            }
            if !base.has_effect(effect) {
                return Err(invalid(
                    key,
                    r,
                    &format!("the scenario's [model] has no `{effect}` effect to set it on"),
                ));
            }
        }
        let mut seen: Vec<(Vec<String>, String)> = Vec::new();
        for s in &self.shots {
            let key = (s.effects.clone(), s.surface.clone());
            if seen.contains(&key) {
                continue;
            }
            for end in [0.0, 1.0] {
                let over: Vec<Override> = rp
                    .model_keys()
                    .iter()
                    .filter_map(|&(_, e, p, r, _)| r.map(|r| (e, p, r.lo + (r.hi - r.lo) * end)))
                    .collect();
                let context = || {
                    format!(
                        "random_physics at the {} end of its ranges, surface `{}`",
                        if end == 0.0 { "low" } else { "high" },
                        s.surface
                    )
                };
                let spec = self
                    .model_spec_with(&s.effects, &s.surface, &over)
                    .map_err(|e| match e {
                        RenderError::Model { origin, source, .. } => RenderError::Model {
                            origin,
                            context: context(),
                            source,
                        },
                        other => other,
                    })?;
                spec.build(Some(&s.surface)).map_err(|source| RenderError::Model {
                    origin: self.origin.clone(),
                    context: context(),
                    source: Box::new(source),
                })?;
            }
            seen.push(key);
        }
        Ok(())
    }

    /// Shot `index` as rendered: with `[random_physics]`, its drop height and incline drawn from the shot's
    /// seed.
    ///
    /// # Panics
    /// If `index` is not a shot of the scenario.
    pub fn shot(&self, index: usize) -> Shot {
        self.shot_physics(index).0
    }

    /// Shot `index` as rendered and the model values its random physics replaces.
    pub(crate) fn shot_physics(&self, index: usize) -> (Shot, Vec<Override>) {
        let mut shot = self.shots[index].clone();
        let Some(rp) = &self.random_physics else {
            return (shot, Vec::new());
        };
        let mut rng = Rng::new(derive(derive(self.seed, index as u64), PHYSICS_STREAM));
        // One draw per key whether or not it is given, so adding a key does not change the others.
        let (uh, ua) = (rng.uniform(), rng.uniform());
        if let Some(r) = rp.drop_height_m {
            shot.drop_height_m = rounded(r, uh, 0.001);
        }
        if let Some(r) = rp.angle_deg {
            shot.angle_deg = rounded(r, ua, 0.1);
        }
        let mut over = Vec::new();
        for (_, effect, param, range, step) in rp.model_keys() {
            let u = rng.uniform();
            if let Some(r) = range {
                over.push((effect, param, rounded(r, u, step)));
            }
        }
        (shot, over)
    }

    /// The parsed model for a shot on `surface` with the extra effects `effects` switched on and the
    /// model values `overrides` set for that surface.
    pub(crate) fn model_spec_with(
        &self,
        effects: &[String],
        surface: &str,
        overrides: &[Override],
    ) -> Result<ModelSpec, RenderError> {
        if overrides.is_empty() {
            return self.model_spec(effects);
        }
        let text = self.model_toml_with(effects, Some((surface, overrides)));
        ModelSpec::parse(&text, &format!("{} [model]", self.origin)).map_err(|source| RenderError::Model {
            origin: self.origin.clone(),
            context: format!(
                "the model with effects [{}] and random physics on surface `{surface}`",
                effects.join(", ")
            ),
            source: Box::new(source),
        })
    }

    /// The model file (model.toml text) for shots with the extra effects `effects` switched on: `[model]`,
    /// the ball, the chosen `[extra_effects]` and every surface's values for the effects present.
    pub fn model_toml(&self, effects: &[String]) -> String {
        self.model_toml_with(effects, None)
    }

    fn model_toml_with(&self, effects: &[String], overrides: Option<(&str, &[Override])>) -> String {
        let mut t = Table::new();
        if let Some(g) = self.model.get("gravity_m_s2") {
            t.insert("gravity_m_s2".into(), g.clone());
        }
        let mut ball = Table::new();
        ball.insert("mass_kg".into(), Value::Float(self.ball.mass_kg));
        ball.insert("radius_m".into(), Value::Float(self.ball.diameter_m / 2.0));
        ball.insert("inertia_factor".into(), Value::Float(self.ball.inertia_factor));
        t.insert("ball".into(), Value::Table(ball));
        for (k, v) in &self.model {
            if k != "gravity_m_s2" && k != "effects" {
                t.insert(k.clone(), v.clone());
            }
        }
        let mut fx = self
            .model
            .get("effects")
            .and_then(Value::as_table)
            .cloned()
            .unwrap_or_default();
        for e in effects {
            if !fx.contains_key(e)
                && let Some(v) = self.extra_effects.get(e)
            {
                fx.insert(e.clone(), v.clone());
            }
        }
        let mut surfaces = Table::new();
        for s in &self.surfaces {
            let mut vals = Table::new();
            for (k, v) in &s.model_values {
                if fx.contains_key(k) {
                    vals.insert(k.clone(), v.clone());
                }
            }
            if let Some((surface, over)) = overrides
                && surface == s.name
            {
                for &(effect, param, value) in over {
                    let e = vals
                        .entry(effect.to_string())
                        .or_insert_with(|| Value::Table(Table::new()));
                    if let Value::Table(e) = e {
                        e.insert(param.to_string(), Value::Float(value));
                    }
                }
            }
            surfaces.insert(s.name.clone(), Value::Table(vals));
        }
        t.insert("effects".into(), Value::Table(fx));
        t.insert("surfaces".into(), Value::Table(surfaces));
        toml::to_string(&t).expect("a TOML table serializes")
    }

    /// The parsed model for shots with the extra effects `effects` switched on.
    pub fn model_spec(&self, effects: &[String]) -> Result<ModelSpec, RenderError> {
        let text = self.model_toml(effects);
        ModelSpec::parse(&text, &format!("{} [model]", self.origin)).map_err(|source| RenderError::Model {
            origin: self.origin.clone(),
            context: format!("the model with effects [{}]", effects.join(", ")),
            source: Box::new(source),
        })
    }

    /// The surface called `name`.
    pub fn surface(&self, name: &str) -> Option<&Surface> {
        self.surfaces.iter().find(|s| s.name == name)
    }

    /// The extra effects defined in `[extra_effects]`, in file order.
    pub fn extra_effect_names(&self) -> Vec<&str> {
        self.extra_effects.keys().map(String::as_str).collect()
    }

    /// The clip (folder) name of shot `index` (0-based), e.g. `S001_clay_7.5deg_300mm_r1`.
    pub fn clip_name(&self, index: usize) -> String {
        let s = &self.shot(index);
        format!(
            "S{:03}_{}_{}deg_{}mm_r{}",
            index + 1,
            s.surface,
            s.angle_deg,
            (s.drop_height_m * 1000.0).round() as i64,
            s.repeat
        )
    }
}

/// The paper's base model without per-surface values, for scenarios without `[model]`.
fn default_model() -> Table {
    let text =
        "gravity_m_s2 = 9.81\n[effects.spring]\nk = 25650\n[effects.damping]\nb = 14\n[effects.coulomb]\nmu = 0.5\n";
    text.parse().expect("built-in model parses")
}

/// The scenario a check is about: builds its errors, each naming it.
struct Origin<'a>(&'a str);

impl Origin<'_> {
    /// The file does not say what a scenario needs (`message` says what).
    fn syntax(&self, message: String) -> RenderError {
        RenderError::Syntax {
            origin: self.0.to_string(),
            message,
        }
    }

    /// `field` holds `value`, which breaks `reason`.
    fn invalid(&self, field: &str, value: String, reason: &str) -> RenderError {
        RenderError::InvalidValue {
            origin: self.0.to_string(),
            field: field.to_string(),
            value,
            reason: reason.to_string(),
        }
    }

    /// Each (field, value, within its range, reason) in turn: the first value out of its range (or not
    /// finite) is the error.
    fn check_all<'f>(
        &self,
        checks: impl IntoIterator<Item = (&'f str, f64, bool, &'f str)>,
    ) -> Result<(), RenderError> {
        for (field, v, ok, reason) in checks {
            if !(ok && v.is_finite()) {
                return Err(self.invalid(field, v.to_string(), reason));
            }
        }
        Ok(())
    }
}

/// Checks `[camera]`: frame size, optics, noise, bits, blur samples and the naming pattern.
fn check_camera(c: &Camera, at: &Origin) -> Result<(), RenderError> {
    for (field, px) in [("camera.width", c.width), ("camera.height", c.height)] {
        if !(16..=8192).contains(&px) {
            return Err(at.invalid(field, px.to_string(), "must be 16 to 8192 pixels"));
        }
    }
    at.check_all([
        (
            "camera.scale_m_per_px",
            c.scale_m_per_px,
            c.scale_m_per_px > 0.0,
            "must be > 0",
        ),
        (
            "camera.fps",
            c.fps,
            c.fps > 0.0 && c.fps <= 1e7,
            "must be > 0 (and ≤ 1e7)",
        ),
        (
            "camera.exposure_s",
            c.exposure_s,
            c.exposure_s > 0.0 && c.exposure_s <= 1.0 / c.fps,
            "must be > 0 and at most one frame period (1/fps)",
        ),
        ("camera.read_noise", c.read_noise, c.read_noise >= 0.0, "must be ≥ 0 DN"),
        (
            "camera.shot_noise_gain",
            c.shot_noise_gain,
            c.shot_noise_gain >= 0.0,
            "must be ≥ 0 DN per electron",
        ),
        (
            "camera.flicker_amplitude",
            c.flicker_amplitude,
            (0.0..0.5).contains(&c.flicker_amplitude),
            "must be in [0, 0.5)",
        ),
        ("camera.flicker_hz", c.flicker_hz, c.flicker_hz >= 0.0, "must be ≥ 0 Hz"),
        (
            "camera.roll_deg",
            c.roll_deg,
            c.roll_deg.abs() <= 45.0,
            "must be within ±45°",
        ),
        (
            "camera.vignetting",
            c.vignetting,
            (0.0..=0.9).contains(&c.vignetting),
            "must be in [0, 0.9]",
        ),
        (
            "camera.fixed_pattern_noise",
            c.fixed_pattern_noise,
            (0.0..=20.0).contains(&c.fixed_pattern_noise),
            "must be 0 to 20 DN",
        ),
        (
            "camera.hot_pixel_fraction",
            c.hot_pixel_fraction,
            (0.0..=0.01).contains(&c.hot_pixel_fraction),
            "must be 0 to 0.01",
        ),
    ])?;
    if ![8, 12, 16].contains(&c.bit_depth) {
        return Err(at.invalid(
            "camera.bit_depth",
            c.bit_depth.to_string(),
            "must be 8, 12 (12-bit data in 16-bit files) or 16",
        ));
    }
    if !(1..=64).contains(&c.blur_samples) {
        return Err(at.invalid("camera.blur_samples", c.blur_samples.to_string(), "must be 1 to 64"));
    }
    check_naming(c, at)
}

/// Checks the frame file naming pattern and that its extension matches the format.
fn check_naming(c: &Camera, at: &Origin) -> Result<(), RenderError> {
    let pattern = c.naming_pattern();
    let (_, _, suffix) = parse_naming(&pattern).map_err(|r| at.invalid("camera.naming", format!("{pattern:?}"), &r))?;
    let lower = suffix.to_ascii_lowercase();
    let ext_ok = match c.format {
        Format::Png => lower.ends_with(".png"),
        Format::Tiff => lower.ends_with(".tif") || lower.ends_with(".tiff"),
    };
    if !ext_ok {
        return Err(at.invalid(
            "camera.naming",
            format!("{pattern:?}"),
            "its extension must match camera.format (.png, or .tif/.tiff)",
        ));
    }
    Ok(())
}

/// Checks `[ball]` and the flight filmed either side of the contact.
fn check_ball_and_timing(raw: &Raw, at: &Origin) -> Result<(), RenderError> {
    let b = &raw.ball;
    at.check_all([
        (
            "ball.diameter_m",
            b.diameter_m,
            b.diameter_m > 0.0 && b.diameter_m < 10.0,
            "must be > 0 m",
        ),
        ("ball.mass_kg", b.mass_kg, b.mass_kg > 0.0, "must be > 0 kg"),
        (
            "ball.inertia_factor",
            b.inertia_factor,
            b.inertia_factor > 0.0,
            "must be > 0",
        ),
        (
            "pre_contact_ms",
            raw.pre_contact_ms,
            (0.0..=2000.0).contains(&raw.pre_contact_ms),
            "must be 0 to 2000 ms",
        ),
        (
            "post_separation_ms",
            raw.post_separation_ms,
            (0.0..=2000.0).contains(&raw.post_separation_ms),
            "must be 0 to 2000 ms",
        ),
    ])
}

/// The `[surfaces.NAME]` tables, in file order: each a texture plus per-surface model values.
fn read_surfaces(tables: &Table, at: &Origin) -> Result<Vec<Surface>, RenderError> {
    let mut surfaces = Vec::new();
    for (name, body) in tables {
        let field = format!("surfaces.{name}");
        let t = body
            .as_table()
            .ok_or_else(|| at.syntax(format!("{field} must be a table")))?;
        let tex = t
            .get("texture")
            .ok_or_else(|| at.syntax(format!("{field}: missing `texture` (clay, white_tape or green_tape)")))?;
        let texture: Texture = tex.clone().try_into().map_err(|_| {
            at.invalid(
                &format!("{field}.texture"),
                tex.to_string(),
                "expected \"clay\", \"white_tape\" or \"green_tape\"",
            )
        })?;
        let mut model_values = t.clone();
        model_values.remove("texture");
        if name.is_empty() || name.contains([',', '"', '/', '\\', '\n']) {
            return Err(at.invalid(
                &field,
                format!("{name:?}"),
                "a surface name must be non-empty, without , \" / \\",
            ));
        }
        surfaces.push(Surface {
            name: name.clone(),
            texture,
            model_values,
        });
    }
    if surfaces.is_empty() {
        return Err(at.syntax("no surfaces: add at least one [surfaces.NAME] with a texture".into()));
    }
    Ok(surfaces)
}

/// The surfaces' names, for messages.
fn surface_list(surfaces: &[Surface]) -> String {
    surfaces.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
}

/// Appends the `[grid]`'s shots (surface × angle × height × repeat) once its surfaces and repeats are checked.
fn expand_grid(g: &Grid, surfaces: &[Surface], shots: &mut Vec<Shot>, at: &Origin) -> Result<(), RenderError> {
    for s in &g.surfaces {
        if !surfaces.iter().any(|x| &x.name == s) {
            return Err(RenderError::UnknownSurface {
                origin: at.0.to_string(),
                field: "grid.surfaces".into(),
                surface: s.clone(),
                known: surface_list(surfaces),
            });
        }
    }
    if g.repeats == 0 {
        return Err(at.invalid("grid.repeats", "0".into(), "must be ≥ 1"));
    }
    for s in &g.surfaces {
        for &a in &g.angles_deg {
            for &h in &g.drop_heights_m {
                for r in 1..=g.repeats {
                    shots.push(Shot {
                        surface: s.clone(),
                        angle_deg: a,
                        drop_height_m: h,
                        repeat: r,
                        effects: g.effects.clone(),
                    });
                }
            }
        }
    }
    Ok(())
}

/// Checks every shot: a known surface, incline and height in range, a repeat from 1, known extra effects.
fn check_shots(shots: &[Shot], surfaces: &[Surface], extra_effects: &Table, at: &Origin) -> Result<(), RenderError> {
    if shots.is_empty() {
        return Err(at.syntax("no shots: add [[shots]] or a [grid]".into()));
    }
    for (i, s) in shots.iter().enumerate() {
        let f = |k: &str| format!("shots[{i}].{k}");
        if !surfaces.iter().any(|x| x.name == s.surface) {
            return Err(RenderError::UnknownSurface {
                origin: at.0.to_string(),
                field: f("surface"),
                surface: s.surface.clone(),
                known: surface_list(surfaces),
            });
        }
        at.check_all([
            (
                f("angle_deg").as_str(),
                s.angle_deg,
                s.angle_deg.abs() <= 60.0,
                "must be within ±60°",
            ),
            (
                f("drop_height_m").as_str(),
                s.drop_height_m,
                s.drop_height_m > 0.0 && s.drop_height_m <= 10.0,
                "must be > 0 and ≤ 10 m",
            ),
        ])?;
        if s.repeat == 0 {
            return Err(at.invalid(&f("repeat"), "0".into(), "must be ≥ 1"));
        }
        if let Some(e) = s.effects.iter().find(|e| !extra_effects.contains_key(*e)) {
            return Err(RenderError::UnknownEffect {
                origin: at.0.to_string(),
                field: f("effects"),
                effect: e.clone(),
                known: if extra_effects.is_empty() {
                    "none".into()
                } else {
                    extra_effects.keys().cloned().collect::<Vec<_>>().join(", ")
                },
            });
        }
    }
    Ok(())
}

/// `[model]` (the paper's base model when absent), which must hold neither the ball nor per-surface values.
fn model_table(model: Option<Table>, at: &Origin) -> Result<Table, RenderError> {
    let model = model.unwrap_or_else(default_model);
    for key in ["ball", "surfaces"] {
        if model.contains_key(key) {
            return Err(at.syntax(format!(
                "model.{key}: the ball comes from [ball] and per-surface values go under [surfaces.NAME]"
            )));
        }
    }
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn naming_patterns() {
        assert_eq!(
            parse_naming("C001H001S0001{:06}.png").unwrap(),
            ("C001H001S0001".into(), 6, ".png".into())
        );
        assert_eq!(parse_naming("{}.tif").unwrap().1, 0);
        assert!(parse_naming("img.png").is_err());
        assert!(parse_naming("img{:06}_2.png").is_err());
        let c = Camera::default();
        assert_eq!(c.frame_name(123), "C001H001S0001000123.png");
    }
}
