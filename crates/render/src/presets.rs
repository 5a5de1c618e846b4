//! Built-in scenarios: `smoke` (regression tests), `paper` (the paper's 144-shot session), `none` and one
//! `effect-<name>` session per non-base effect of the model crate (for the missing-effect diagnosis),
//! `pair-A+B` sessions with two effects at once ([`EFFECT_PAIRS`]), `looks` (64 shots, each with its own
//! look and physics) and `looks-smoke` (6 small ones for tests).

use bouncelab_model::{ModelSpec, builtin_effects};

/// The magnitude each `effect-<name>` preset switches its effect on at, as `model.toml` parameter lines,
/// chosen so the measurable outputs change clearly (see `docs/renderer.md`).
pub const EFFECT_MAGNITUDES: &[(&str, &str)] = &[
    ("hertz", "k_h = 600000"),
    ("hunt_crossley", "lambda = 2000\nn = 1"),
    ("restitution_damping", "b_r = 20"),
    ("plastic_dent", "phi = 0.5"),
    ("rolling_resistance", "c_rr = 0.02"),
    ("inertia_factor", "dc = -0.25"),
    ("drag", "cd = 1.5\nrho = 1.204"),
    ("camera_roll", "roll_deg = 3"),
    // k_t = 1e5 N/m: the slip reverses within the contact and the outgoing spin and tangential speed move
    // by tens of µm over the flight filmed (the diagnosis is also checked at 3e-6, a factor 3 stiffer).
    ("tangential_spring", "compliance = 1e-5"),
];

/// The pair presets `pair-A+B`: two effects hidden at once, each at its [`EFFECT_MAGNITUDES`] value (any two
/// non-base effects make a preset; these are the ones listed and tested).
pub const EFFECT_PAIRS: &[(&str, &str)] = &[
    ("hertz", "drag"),
    ("inertia_factor", "camera_roll"),
    ("hunt_crossley", "rolling_resistance"),
];

/// The names of every preset.
pub fn preset_names() -> Vec<String> {
    let mut v: Vec<String> = ["smoke", "paper", "none", "looks", "looks-smoke"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    for e in builtin_effects().iter().filter(|e| !e.base) {
        v.push(format!("effect-{}", e.name));
    }
    for (a, b) in EFFECT_PAIRS {
        v.push(format!("pair-{a}+{b}"));
    }
    v
}

/// The paper's model (`[model]` and per-surface values) written from `ModelSpec::paper()`, with the
/// surfaces' textures: clay → clay, tape1 → white tape, tape2 → green tape.
fn paper_model_tables() -> String {
    let spec = ModelSpec::paper();
    let mut s = format!("[model]\ngravity_m_s2 = {}\n", spec.gravity);
    let base = spec.settings(None).expect("the paper model has values");
    let mut last = String::new();
    for (r, p) in &base {
        if r.effect != last {
            s += &format!("[model.effects.{}]\n", r.effect);
            last = r.effect.clone();
        }
        s += &format!("{} = {}\n", r.param, p.value);
    }
    for name in spec.surface_names() {
        let texture = match name {
            "clay" => "clay",
            "tape1" => "white_tape",
            _ => "green_tape",
        };
        s += &format!("\n[surfaces.{name}]\ntexture = \"{texture}\"\n");
        for (r, p) in spec
            .surfaces
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
            .unwrap_or_default()
        {
            s += &format!("{}.{} = {}\n", r.effect, r.param, p.value);
        }
    }
    s
}

const CAMERA_512: &str =
    "[camera]\nwidth = 512\nheight = 512\nscale_m_per_px = 4.0e-4\nfps = 10000\nexposure_s = 5e-5\n";

/// The scenario text of preset `name`, or `None`.
pub fn preset_toml(name: &str) -> Option<String> {
    let ball = "[ball]\ndiameter_m = 0.067\nmass_kg = 0.0567\ninertia_factor = 0.6666666666666666\n";
    match name {
        "smoke" => Some(format!(
            "name = \"smoke\"\ndescription = \"3 small shots for regression tests\"\nseed = 1\npre_contact_ms = 6\npost_separation_ms = 6\n\n{ball}\n[camera]\nwidth = 256\nheight = 256\nscale_m_per_px = 8.0e-4\nfps = 10000\nexposure_s = 5e-5\n\n{}\n[[shots]]\nsurface = \"clay\"\nangle_deg = 0\ndrop_height_m = 0.3\n\n[[shots]]\nsurface = \"tape1\"\nangle_deg = 15\ndrop_height_m = 0.25\n\n[[shots]]\nsurface = \"tape2\"\nangle_deg = 22.5\ndrop_height_m = 0.35\n",
            paper_model_tables()
        )),
        "paper" => Some(format!(
            "name = \"paper\"\ndescription = \"The paper's session: 3 surfaces x 4 drop heights x 4 angles x 3 repeats\"\nseed = 2024\npre_contact_ms = 15\npost_separation_ms = 20\n\n{ball}\n{CAMERA_512}\n{}\n[grid]\nsurfaces = [\"clay\", \"tape1\", \"tape2\"]\ndrop_heights_m = [0.2, 0.27, 0.33, 0.4]\nangles_deg = [0, 7.5, 15, 22.5]\nrepeats = 3\n",
            paper_model_tables()
        )),
        "none" => Some(effect_session("none", &[])),
        "looks" => Some(looks()),
        "looks-smoke" => Some(looks_smoke()),
        _ => {
            let library = |effect: &str| builtin_effects().iter().find(|e| e.name == effect && !e.base);
            if let Some(pair) = name.strip_prefix("pair-") {
                let (a, b) = pair.split_once('+')?;
                let (a, b) = (library(a)?, library(b)?);
                if a.name == b.name {
                    return None;
                }
                return Some(effect_session(name, &[a.name, b.name]));
            }
            let effect = name.strip_prefix("effect-")?;
            Some(effect_session(name, &[library(effect)?.name]))
        }
    }
}

/// A 12-shot clay session (drop heights 0.2, 0.55, 0.9 m × angles 0, 7.5, 15, 22.5°) with `effects`
/// switched on at their [`EFFECT_MAGNITUDES`] values.
fn effect_session(name: &str, effects: &[&str]) -> String {
    let (extra, list, what) = if effects.is_empty() {
        (
            String::new(),
            "[]".to_string(),
            "no hidden effect (the paper's model)".to_string(),
        )
    } else {
        let mut extra = String::new();
        for e in effects {
            let params = EFFECT_MAGNITUDES
                .iter()
                .find(|(n, _)| n == e)
                .map(|(_, p)| *p)
                .unwrap_or("");
            extra += &format!("[extra_effects.{e}]\n{params}\n");
        }
        let quoted: Vec<String> = effects.iter().map(|e| format!("\"{e}\"")).collect();
        let named: Vec<String> = effects.iter().map(|e| format!("`{e}`")).collect();
        (
            extra,
            format!("[{}]", quoted.join(", ")),
            format!(
                "the hidden effect{} {} switched on",
                if effects.len() > 1 { "s" } else { "" },
                named.join(" and ")
            ),
        )
    };
    let seed = crate::rng::mix(
        name.bytes()
            .fold(7u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64)),
    ) % 1_000_000;
    // Drag acts in flight: its trace grows with the square of the flight filmed, so its session films
    // longer flights (the other effects act in contact, where 10 ms either side suffice).
    let flight_ms = if effects.contains(&"drag") { 35 } else { 10 };
    format!(
        "name = \"{name}\"\ndescription = \"Diagnosis session: clay, {what}\"\nseed = {seed}\npre_contact_ms = {flight_ms}\npost_separation_ms = {flight_ms}\n\n[ball]\ndiameter_m = 0.067\nmass_kg = 0.0567\ninertia_factor = 0.6666666666666666\n\n{CAMERA_512}\n[model]\ngravity_m_s2 = 9.81\n[model.effects.spring]\nk = 25650\n[model.effects.damping]\nb = 14\n[model.effects.coulomb]\nmu = 0.5\n\n[surfaces.clay]\ntexture = \"clay\"\n\n{extra}\n[grid]\nsurfaces = [\"clay\"]\ndrop_heights_m = [0.2, 0.55, 0.9]\nangles_deg = [0, 7.5, 15, 22.5]\nrepeats = 1\neffects = {list}\n"
    )
}

/// A session of `repeats` shots on clay and as many on tape (`white_tape` physics) whose look and physics
/// are drawn per shot from `[random_physics]` (`physics`) and `[look]` (`look`) lines, filmed `flight_ms`
/// before the touch and after separation.
fn looks_session(
    name: &str,
    description: &str,
    seed: u64,
    flight_ms: f64,
    repeats: u32,
    physics: &str,
    look: &str,
) -> String {
    format!(
        r#"name = "{name}"
description = "{description}"
seed = {seed}
pre_contact_ms = {flight_ms}
post_separation_ms = {flight_ms}

[ball]
diameter_m = 0.067
mass_kg = 0.0567
inertia_factor = 0.6666666666666666

[camera]
fps = 10000
exposure_s = 5e-5

[model]
gravity_m_s2 = 9.81
[model.effects.spring]
k = 25650
[model.effects.damping]
b = 14
[model.effects.coulomb]
mu = 0.5

[surfaces.clay]
texture = "clay"
[surfaces.tape]
texture = "white_tape"

[random_physics]
{physics}
[look]
{look}
[grid]
surfaces = ["clay", "tape"]
drop_heights_m = [0.3]
angles_deg = [0]
repeats = {repeats}
"#
    )
}

/// `looks`: 64 shots (32 on clay, 32 on tape), every look family of `docs/renderer.md`, at 320–512 px.
fn looks() -> String {
    looks_session(
        "looks",
        "64 shots, each with its own look (surface, contrast, lighting, clutter, ball, sensor, geometry) and physics",
        15,
        8.0,
        32,
        "drop_height_m = [0.15, 0.6]\nangle_deg = [0, 25]\nk = [20000, 36000]\nb = [8, 20]\nmu = [0.3, 0.7]\n",
        "width_px = [320, 512]\nheight_px = [320, 512]\n",
    )
}

/// `looks-smoke`: 6 small shots (3 on clay, 3 on tape) with drawn looks and physics, 256 × 256, a 4-ms
/// flight either side; renders in a few seconds, for tests of other crates.
fn looks_smoke() -> String {
    looks_session(
        "looks-smoke",
        "6 small shots with drawn looks and physics, for tests",
        3,
        4.0,
        3,
        "drop_height_m = [0.15, 0.35]\nangle_deg = [0, 20]\n",
        "width_px = 256\nheight_px = 256\nball_radius_px = [20, 40]\n",
    )
}
