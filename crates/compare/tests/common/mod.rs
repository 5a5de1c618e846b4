//! Shared test helper (adapted from the fit crate's): synthetic measured shots made by simulating a known
//! model, with seeded noise on the positions, the spin and the measured outputs.
#![allow(dead_code)]

use bouncelab_compare::{ShotExtras, SpinFrame};
use bouncelab_fit::{MeasuredFrame, MeasuredOutputs, MeasuredShot, StartState};
use bouncelab_model::{Model, SimOptions, State, simulate_drop};

/// Camera: 10 kHz, 4e-4 m/px, centre noise 0.05 px.
pub const FPS: f64 = 10_000.0;
pub const SIGMA_M: f64 = 0.05 * 4e-4;
/// Spin noise, rad/s.
pub const SIGMA_OMEGA: f64 = 2.0;
/// Noise of the measured outputs: COR, μ (absolute), v_out (relative).
pub const SIGMA_COR: f64 = 0.003;
pub const SIGMA_MU: f64 = 0.005;
pub const SIGMA_V_REL: f64 = 0.005;
/// Noise of the measured contact time, s.
pub const SIGMA_TC: f64 = 2e-5;

/// The paper's values.
pub const CLAY: (f64, f64) = (25_650.0, 14.0);
pub const TAPE1: (f64, f64) = (30_800.0, 15.0);

/// A small deterministic generator (SplitMix64) with Box–Muller normals.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// One synthetic shot: `model` dropped from `height_m` onto a surface inclined by `incline_deg`, sampled at
/// 10 kHz from 10 ms before touch to 10 ms after separation, with Gaussian noise σ = [`SIGMA_M`] on what
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
    let opts = SimOptions::default();
    let beta = incline_deg.to_radians();
    let probe = simulate_drop(model, beta, height_m, &[], &opts).expect("synthetic drop simulates");
    let (t_touch, t_sep) = (probe.impact.t_touch, probe.impact.t_separation);
    let phase = 0.37 / FPS * rng.uniform();
    let first = ((t_touch - 0.010) * FPS).ceil() as i64;
    let last = ((t_sep + 0.010) * FPS).floor() as i64;
    let times: Vec<f64> = (first..=last).map(|k| k as f64 / FPS + phase).collect();
    let sim = simulate_drop(model, beta, height_m, &times, &opts).expect("synthetic drop simulates");
    let frames = sim
        .samples
        .iter()
        .map(|s| MeasuredFrame {
            t_s: s.t,
            x_m: s.observed.x + x_offset_m + SIGMA_M * rng.normal(),
            y_m: s.observed.y + SIGMA_M * rng.normal(),
            sigma_m: SIGMA_M,
        })
        .collect();
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
        y: o.y,
        theta: o.theta,
        vx: o.vx,
        vy: o.vy,
        omega: o.omega,
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
    };
    let extras = ShotExtras {
        drop_height_m: Some(height_m),
        contact_time_s: Some(imp.contact_time() + SIGMA_TC * rng.normal()),
        camera_roll_deg: None,
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
    let mut s = String::from(
        "[model]\nname = \"paper-compare-test\"\n\n[effects.spring]\nk = { value = 20000, free = true, min = 1000, max = 1000000 }\n\
         [effects.damping]\nb = { value = 10, free = true, min = 0, max = 200 }\n\
         [effects.coulomb]\nmu = 0.5\n",
    );
    for sf in surfaces {
        s.push_str(&format!("\n[surfaces.{sf}]\nspring.k = 20000\ndamping.b = 10\n"));
    }
    s
}
