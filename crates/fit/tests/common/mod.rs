//! Shared test helper: synthetic measured shots made by simulating a known model, with seeded noise.
#![allow(dead_code)]

use bouncelab_fit::{MeasuredOutputs, MeasuredShot, StartState};
use bouncelab_model::Model;

pub use bouncelab_fit::testutil::{CLAY, Rng, SIGMA_M, TAPE1, TAPE2};
use bouncelab_fit::testutil::{noisy_frames, simulate_shot};

/// One synthetic shot: `model` dropped from `height_m` onto a surface inclined by `incline_deg`, sampled at
/// 10 kHz from 10 ms before touch to 10 ms after separation, with Gaussian noise σ = [`SIGMA_M`] on x and
/// y, an arbitrary x origin (`x_offset_m`) and the exact state at the first frame as the start.
pub fn synth_shot(
    model: &Model,
    name: &str,
    surface: &str,
    height_m: f64,
    incline_deg: f64,
    x_offset_m: f64,
    rng: &mut Rng,
) -> MeasuredShot {
    let beta = incline_deg.to_radians();
    let sim = simulate_shot(model, height_m, incline_deg, rng);
    let frames = noisy_frames(&sim, x_offset_m, rng);
    let mut start = sim.samples[0].state;
    start.x += x_offset_m;
    let imp = &sim.impact;
    MeasuredShot {
        name: name.to_string(),
        surface: surface.to_string(),
        incline_rad: beta,
        frames,
        start: StartState {
            t_s: sim.samples[0].t,
            state: start,
        },
        measured: Some(MeasuredOutputs {
            v_out: [imp.state_out.vx, imp.state_out.vy],
            cor: imp.restitution,
            mu: imp.effective_friction,
        }),
        surface_sigma_m: None,
        frame_sigma_rad: None,
        spin_sigma_rad_s: None,
        rim_change_m: None,
    }
}

/// Shots of `model` on `surface` at every combination of `heights` (m) and `inclines` (degrees).
pub fn shots_for(model: &Model, surface: &str, heights: &[f64], inclines: &[f64], rng: &mut Rng) -> Vec<MeasuredShot> {
    let mut out = Vec::new();
    for &h in heights {
        for &a in inclines {
            let name = format!("{surface}-h{h:.2}-a{a:.1}");
            let offset = 0.3 * (rng.uniform() - 0.5);
            out.push(synth_shot(model, &name, surface, h, a, offset, rng));
        }
    }
    out
}

/// A model file with k and b free per surface (starting away from the truth) and μ fixed at 0.5.
pub fn spec_toml(surfaces: &[&str], extra: &str) -> String {
    bouncelab_fit::testutil::spec_toml("paper-fit-test", surfaces, extra)
}
