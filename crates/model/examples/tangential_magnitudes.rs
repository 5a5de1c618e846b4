//! How large a trace the compliant contact patch (`tangential_spring`) leaves on the diagnosis session
//! (clay, drops of 0.2/0.55/0.9 m onto inclines of 0/7.5/15/22.5°, k = 25650 N/m, b = 14 N·s/m, μ = 0.5),
//! next to the renderer's magnitudes of the other effects; and how closely a custom term `−c·u_t` added to
//! the rigid Coulomb contact can imitate it.
//!
//! Run: `cargo run --release -p bouncelab-model --example tangential_magnitudes`

use bouncelab_model::effects::*;
use bouncelab_model::{Model, ModelSpec, SimOptions, simulate_drop};

const HEIGHTS: [f64; 3] = [0.2, 0.55, 0.9];
const INCLINES_DEG: [f64; 4] = [0.0, 7.5, 15.0, 22.5];

fn base() -> Model {
    Model::paper(25_650.0, 14.0, 0.5)
}

/// One shot: observed positions (m), outgoing v_t (m/s) and ω (rad/s).
type Shot = (Vec<(f64, f64)>, f64, f64);

/// Per shot: the observed positions at 10 kHz from 10 ms before touch to 10 ms after separation (of the
/// base model, so every model is sampled at the same times), and the outgoing v_t and ω.
fn shots(model: &Model) -> Vec<Shot> {
    let o = SimOptions::default();
    let mut out = Vec::new();
    for &h in &HEIGHTS {
        for &deg in &INCLINES_DEG {
            let inc = deg.to_radians();
            let timing = simulate_drop(&base(), inc, h, &[], &o).unwrap().impact;
            let (t0, t1) = (timing.t_touch - 0.010, timing.t_separation + 0.010);
            let times: Vec<f64> = (0..).map(|i| t0 + i as f64 * 1e-4).take_while(|&t| t <= t1).collect();
            let sim = simulate_drop(model, inc, h, &times, &o).unwrap();
            let pos = sim.samples.iter().map(|s| (s.observed.x, s.observed.y)).collect();
            out.push((pos, sim.impact.state_out.vx, sim.impact.state_out.omega));
        }
    }
    out
}

/// RMS and largest position difference over every frame of every shot, µm.
fn trace(a: &[Shot], b: &[Shot]) -> (f64, f64) {
    let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0f64);
    for (p, q) in a.iter().zip(b) {
        for (u, v) in p.0.iter().zip(&q.0) {
            let d = (u.0 - v.0).hypot(u.1 - v.1);
            sum += d * d;
            n += 1;
            max = max.max(d);
        }
    }
    ((sum / n as f64).sqrt() * 1e6, max * 1e6)
}

/// Largest |Δv_t,out| (mm/s) and |Δω_out| (rad/s) over the shots.
fn outgoing(a: &[Shot], b: &[Shot]) -> (f64, f64) {
    a.iter().zip(b).fold((0.0f64, 0.0f64), |(dv, dw), (p, q)| {
        (dv.max((p.1 - q.1).abs() * 1e3), dw.max((p.2 - q.2).abs()))
    })
}

fn main() {
    let reference = shots(&base());
    println!("effect (magnitude)                  RMS µm   max µm   max|Δv_t,out| mm/s   max|Δω_out| rad/s");
    let library: Vec<(&str, Model)> = vec![
        ("hertz k_h = 6e5", base().with(Hertz { k_h: 6e5 })),
        (
            "hunt_crossley λ = 2000",
            base().with(HuntCrossley { lambda: 2000.0, n: 1.0 }),
        ),
        (
            "restitution_damping b_r = 20",
            base().with(RestitutionDamping { b_r: 20.0 }),
        ),
        ("plastic_dent φ = 0.5", base().with(PlasticDent { phi: 0.5 })),
        (
            "rolling_resistance c_rr = 0.02",
            base().with(RollingResistance { c_rr: 0.02 }),
        ),
        ("inertia_factor Δc = -0.25", base().with(InertiaFactor { dc: -0.25 })),
    ];
    let row = |name: &str, m: &Model| {
        let s = shots(m);
        let (rms, max) = trace(&s, &reference);
        let (dv, dw) = outgoing(&s, &reference);
        println!("{name:<34} {rms:>8.1} {max:>8.1} {dv:>18.1} {dw:>18.2}");
        s
    };
    for (name, m) in &library {
        row(name, m);
    }
    let compliances = [1e-6, 3e-6, 1e-5, 3e-5, 1e-4];
    let mut springs = Vec::new();
    for &l in &compliances {
        for c_t in [0.0, 1.0] {
            let m = base().with(TangentialSpring { compliance: l, c_t });
            let s = row(&format!("tangential_spring λ = {l:e}, c_t = {c_t}"), &m);
            if c_t == 0.0 {
                springs.push((l, s));
            }
        }
    }
    // A custom tangential term −c·u_t on top of the rigid Coulomb contact, fitted to each spring's
    // trajectories by a golden-section search over log c.
    println!("\ncustom `tangential = \"-c * u_t\"` fitted to tangential_spring (λ, c_t = 0):");
    println!("λ m/N      1/λ N/m    fitted c N/m   misfit RMS µm: rigid → custom   share of mean square removed");
    for (l, truth) in springs {
        let misfit = |c: f64| {
            let text = format!(
                "[effects.spring]\nk = 25650\n[effects.damping]\nb = 14\n[effects.coulomb]\nmu = 0.5\n[effects.patch]\nkind = \"custom\"\ntangential = \"-c * u_t\"\nc = {c}\n"
            );
            let m = ModelSpec::parse(&text, "example").unwrap().build(None).unwrap();
            trace(&shots(&m), &truth).0
        };
        let (mut a, mut b) = ((1e2f64).ln(), (1e7f64).ln());
        let g = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..40 {
            let (x1, x2) = (b - g * (b - a), a + g * (b - a));
            if misfit(x1.exp()) < misfit(x2.exp()) {
                b = x2;
            } else {
                a = x1;
            }
        }
        let c = (0.5 * (a + b)).exp();
        let (before, after) = (trace(&reference, &truth).0, misfit(c));
        println!(
            "{l:<10e} {:<10.3e} {c:<14.3e} {before:>10.1} → {after:<10.1} {:>22.1} %",
            1.0 / l,
            100.0 * (1.0 - (after / before).powi(2))
        );
    }
}
