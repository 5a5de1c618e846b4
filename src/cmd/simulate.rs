//! `bouncelab simulate`: one impact, its outputs printed.

use anyhow::{Context, bail};
use bouncelab_model::{Impact, ModelSpec, SimOptions, State, simulate};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Model file (model.toml); the paper's model when omitted.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Surface whose values to use; every surface of the model when omitted.
    #[arg(long)]
    surface: Option<String>,
    /// Impact speed, m/s (the ball falls vertically onto the surface).
    #[arg(long, conflicts_with = "height", allow_negative_numbers = true)]
    speed: Option<f64>,
    /// Drop height instead of a speed, m (√(2gh) without drag).
    #[arg(long, allow_negative_numbers = true)]
    height: Option<f64>,
    /// Incline of the surface, degrees (the paper's impact angle β).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = super::settings::parse_angle)]
    angle: f64,
    /// Spin at touch, rad/s, counter-clockwise as seen by the camera.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_spin)]
    spin: f64,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Spin, rad/s: finite, below 10⁵ rad/s (about 1 million rpm) in magnitude.
fn parse_spin(text: &str) -> Result<f64, String> {
    super::settings::number_in(text, (-1e5, 1e5), " rad/s")
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let spec = super::load_model(a.model.as_deref())?;
    if !(-89.0..=89.0).contains(&a.angle) {
        bail!("--angle {} must be between -89 and 89 degrees", a.angle);
    }
    let speed = match (a.speed, a.height) {
        (Some(v), _) if v > 0.0 && v <= 1000.0 => v,
        (Some(v), _) => bail!("--speed {v} must be a number of m/s in (0, 1000]"),
        (None, Some(h)) if h > 0.0 && h <= 1000.0 => (2.0 * spec.gravity * h).sqrt(),
        (None, Some(h)) => bail!("--height {h} must be a number of metres in (0, 1000]"),
        (None, None) => 2.0,
    };
    let surfaces: Vec<Option<String>> = match &a.surface {
        Some(s) => vec![Some(s.clone())],
        None if spec.surfaces.is_empty() => vec![None],
        None => spec.surface_names().into_iter().map(|s| Some(s.to_string())).collect(),
    };
    let mut rows = Vec::new();
    for surface in &surfaces {
        let imp = impact(&spec, surface.as_deref(), speed, a.angle, a.spin)?;
        rows.push((surface.clone().unwrap_or_else(|| "-".into()), imp));
    }
    if a.json {
        let out: Vec<_> = rows
            .iter()
            .map(|(s, i)| serde_json::json!({ "surface": s, "speed_m_s": speed, "angle_deg": a.angle, "impact": i, "contact_time_s": i.contact_time() }))
            .collect();
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "model: {}   impact speed {speed:.3} m/s, incline {}°, spin {} rad/s",
        spec.origin, a.angle, a.spin
    );
    println!(
        "{:<10} {:>7} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8}",
        "surface", "COR", "μ_eff", "contact", "δ_max", "v_t,in", "v_n,in", "v_t,out", "v_n,out", "ω_out"
    );
    println!(
        "{:<10} {:>7} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8}",
        "", "", "", "ms", "mm", "m/s", "m/s", "m/s", "m/s", "rad/s"
    );
    // A value that rounds to zero is shown without a sign.
    let z = |v: f64, d: usize| super::no_minus_zero(&format!("{v:.d$}"));
    for (s, i) in &rows {
        println!(
            "{:<10} {:>7.4} {:>7} {:>9.4} {:>9.4} {:>9} {:>9.4} {:>9} {:>9.4} {:>8}",
            s,
            i.restitution,
            z(i.effective_friction, 4),
            i.contact_time() * 1e3,
            i.delta_max * 1e3,
            z(i.state_in.vx, 4),
            i.state_in.vy,
            z(i.state_out.vx, 4),
            i.state_out.vy,
            z(i.omega_out(), 2)
        );
    }
    for (s, i) in &rows {
        let events: Vec<String> = i
            .slip_events
            .iter()
            .map(|e| format!("{} at {:.3} ms", slip_words(e.kind), (e.t - i.t_touch) * 1e3))
            .collect();
        println!(
            "{s}: max compression at {:.3} ms, separation at {:.3} ms{}{}",
            (i.t_max_compression - i.t_touch) * 1e3,
            i.contact_time() * 1e3,
            if i.rolling_at_separation {
                ", rolling at separation"
            } else {
                ", sliding at separation"
            },
            if events.is_empty() {
                String::new()
            } else {
                format!("; {}", events.join(", "))
            }
        );
    }
    Ok(())
}

/// A stick/slip switch in words.
fn slip_words(k: bouncelab_model::SlipEventKind) -> &'static str {
    match k {
        bouncelab_model::SlipEventKind::StartsSticking => "starts rolling (the contact point sticks)",
        bouncelab_model::SlipEventKind::StartsSliding => "starts sliding",
        bouncelab_model::SlipEventKind::Reverses => "slip reverses",
    }
}

/// One impact at `speed` m/s falling vertically onto a surface inclined by `angle_deg`.
pub fn impact(
    spec: &ModelSpec,
    surface: Option<&str>,
    speed: f64,
    angle_deg: f64,
    spin: f64,
) -> anyhow::Result<Impact> {
    let model = spec.build(surface)?;
    let beta = angle_deg.to_radians();
    let start = State {
        omega: spin,
        ..State::flying(0.0, model.ball.radius_m, speed * beta.sin(), -speed * beta.cos())
    };
    let sim = simulate(&model, beta, 0.0, start, &[], &SimOptions::default())
        .with_context(|| format!("simulating surface {}", surface.unwrap_or("-")))?;
    Ok(sim.impact)
}
