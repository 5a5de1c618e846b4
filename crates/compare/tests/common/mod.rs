//! Shared test helper (adapted from the fit crate's): synthetic measured shots made by simulating a known
//! model, with seeded noise on the positions, the spin and the measured outputs.
#![allow(dead_code)]

use bouncelab_compare::{ShotExtras, SpinFrame};
use bouncelab_fit::{MeasuredOutputs, MeasuredShot, StartState};
use bouncelab_model::{Model, State};

pub use bouncelab_fit::testutil::{CLAY, Rng, TAPE1};
use bouncelab_fit::testutil::{noisy_frames, simulate_shot};

/// Spin noise, rad/s.
pub const SIGMA_OMEGA: f64 = 2.0;
/// Noise of the measured outputs: COR, μ (absolute), v_out (relative).
pub const SIGMA_COR: f64 = 0.003;
pub const SIGMA_MU: f64 = 0.005;
pub const SIGMA_V_REL: f64 = 0.005;
/// Noise of the measured contact time, s.
pub const SIGMA_TC: f64 = 2e-5;

/// One synthetic shot: `model` dropped from `height_m` onto a surface inclined by `incline_deg`, sampled at
/// 10 kHz from 10 ms before touch to 10 ms after separation, with Gaussian noise σ = `SIGMA_M` on what
/// the camera sees (x, y), an arbitrary x origin, and as the start the observed state at the first frame
/// (what the estimator's incoming fit would give). The extras carry the drop height, a noisy contact time
/// and a noisy spin at every frame.
pub fn synth_shot(
    model: &Model,
    name: &str,
    surface: &str,
    height_m: f64,
    incline_deg: f64,
    x_offset_m: f64,
    rng: &mut Rng,
) -> (MeasuredShot, ShotExtras) {
    let beta = incline_deg.to_radians();
    let sim = simulate_shot(model, height_m, incline_deg, rng);
    let frames = noisy_frames(&sim, x_offset_m, rng);
    let spin = sim
        .samples
        .iter()
        .map(|s| SpinFrame {
            t_s: s.t,
            omega_rad_s: s.observed.omega + SIGMA_OMEGA * rng.normal(),
            sigma_rad_s: SIGMA_OMEGA,
        })
        .collect();
    let o = sim.samples[0].observed;
    let start = State {
        x: o.x + x_offset_m,
        ..o.into()
    };
    let imp = &sim.impact;
    let shot = MeasuredShot {
        name: name.to_string(),
        surface: surface.to_string(),
        incline_rad: beta,
        frames,
        start: StartState {
            t_s: sim.samples[0].t,
            state: start,
        },
        measured: Some(MeasuredOutputs {
            v_out: [
                imp.state_out.vx * (1.0 + SIGMA_V_REL * rng.normal()),
                imp.state_out.vy * (1.0 + SIGMA_V_REL * rng.normal()),
            ],
            cor: imp.restitution + SIGMA_COR * rng.normal(),
            mu: imp.effective_friction + SIGMA_MU * rng.normal(),
        }),
        surface_sigma_m: None,
        frame_sigma_rad: None,
        spin_sigma_rad_s: None,
        rim_change_m: None,
    };
    let extras = ShotExtras {
        drop_height_m: Some(height_m),
        contact_time_s: Some(imp.contact_time() + SIGMA_TC * rng.normal()),
        camera_roll_deg: None,
        camera_roll_se_deg: None,
        spin,
    };
    (shot, extras)
}

/// Shots of `model` on `surface` at every combination of `heights` (m) and `inclines` (degrees).
pub fn shots_for(
    model: &Model,
    surface: &str,
    heights: &[f64],
    inclines: &[f64],
    rng: &mut Rng,
) -> (Vec<MeasuredShot>, Vec<ShotExtras>) {
    let (mut shots, mut extras) = (Vec::new(), Vec::new());
    for &h in heights {
        for &a in inclines {
            let name = format!("{surface}-h{h:.2}-a{a:.1}");
            let offset = 0.3 * (rng.uniform() - 0.5);
            let (s, e) = synth_shot(model, &name, surface, h, a, offset, rng);
            shots.push(s);
            extras.push(e);
        }
    }
    (shots, extras)
}

/// A model file with k and b free per surface (starting away from the truth) and μ fixed at 0.5.
pub fn spec_toml(surfaces: &[&str]) -> String {
    bouncelab_fit::testutil::spec_toml("paper-compare-test", surfaces, "")
}
