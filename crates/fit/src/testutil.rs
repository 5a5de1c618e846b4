//! Synthetic measured shots for tests, here and in the crates after this one: a known model dropped and
//! sampled like a 10 kHz camera, with seeded noise.

use crate::MeasuredFrame;
use bouncelab_model::{Model, SimOptions, Simulation, simulate_drop};

/// Camera frame rate, frames/s.
pub const FPS: f64 = 10_000.0;
/// Centre noise: 0.05 px at 4e-4 m/px, m.
pub const SIGMA_M: f64 = 0.05 * 4e-4;

/// The paper's k (N/m) and b (N·s/m) for clay and the two tapes.
pub const CLAY: (f64, f64) = (25_650.0, 14.0);
/// Tape 1.
pub const TAPE1: (f64, f64) = (30_800.0, 15.0);
/// Tape 2.
pub const TAPE2: (f64, f64) = (31_825.0, 15.0);

/// The workspace's one seeded generator (SplitMix64 with Box–Muller normals).
pub use bouncelab_testkit::Rng;

/// `model` dropped from `height_m` (m) onto a surface inclined by `incline_deg`, sampled at [`FPS`] from
/// 10 ms before touch to 10 ms after separation, with a random sub-frame phase.
///
/// # Panics
/// If the drop does not simulate (a test's model is wrong).
pub fn simulate_shot(model: &Model, height_m: f64, incline_deg: f64, rng: &mut Rng) -> Simulation {
    let opts = SimOptions::default();
    let beta = incline_deg.to_radians();
    let probe = simulate_drop(model, beta, height_m, &[], &opts).expect("synthetic drop simulates");
    let (t_touch, t_sep) = (probe.impact.t_touch, probe.impact.t_separation);
    let phase = 0.37 / FPS * rng.uniform();
    let first = ((t_touch - 0.010) * FPS).ceil() as i64;
    let last = ((t_sep + 0.010) * FPS).floor() as i64;
    let times: Vec<f64> = (first..=last).map(|k| k as f64 / FPS + phase).collect();
    simulate_drop(model, beta, height_m, &times, &opts).expect("synthetic drop simulates")
}

/// What the camera saw of `sim`, with noise σ = [`SIGMA_M`] on x and y and an arbitrary x origin.
pub fn noisy_frames(sim: &Simulation, x_offset_m: f64, rng: &mut Rng) -> Vec<MeasuredFrame> {
    sim.samples
        .iter()
        .map(|s| MeasuredFrame {
            t_s: s.t,
            x_m: s.observed.x + x_offset_m + SIGMA_M * rng.normal(),
            y_m: s.observed.y + SIGMA_M * rng.normal(),
            sigma_m: SIGMA_M,
        })
        .collect()
}

/// A model file named `name` with k and b free per surface (starting away from the truth, at 20,000 N/m
/// and 10 N·s/m), μ fixed at 0.5, and `extra` appended to the effects.
pub fn spec_toml(name: &str, surfaces: &[&str], extra: &str) -> String {
    let mut s = format!(
        "[model]\nname = \"{name}\"\n\n[effects.spring]\nk = {{ value = 20000, free = true, min = 1000, max = 1000000 }}\n\
         [effects.damping]\nb = {{ value = 10, free = true, min = 0, max = 200 }}\n\
         [effects.coulomb]\nmu = 0.5\n"
    );
    s.push_str(extra);
    for sf in surfaces {
        s.push_str(&format!("\n[surfaces.{sf}]\nspring.k = 20000\ndamping.b = 10\n"));
    }
    s
}
