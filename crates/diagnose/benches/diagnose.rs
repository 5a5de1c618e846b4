//! Diagnosis of a 48-shot synthetic session: three surfaces (the paper's clay, tape1, tape2) × drop heights
//! 0.2, 0.45, 0.7, 0.9 m × inclines 0, 7.5, 15, 22.5°, Hunt–Crossley damping hidden (λ = 2000, n = 1),
//! noise 12 µm; the current model is the paper's model file (k and b free per surface: 6 parameters),
//! eight candidates, 6 folds. Three timed runs with the defaults, then one with each shot's surface
//! level fitted. Target: ≤ 10 s on 2 cores.
//!
//! ```text
//! cargo bench -p bouncelab-diagnose --bench diagnose
//! ```

use bouncelab_diagnose::{SearchOptions, find_missing_effect};
use bouncelab_fit::testutil::{CLAY, Rng, TAPE1, TAPE2, simulate_shot};
use bouncelab_fit::{MeasuredFrame, MeasuredShot, StartState};
use bouncelab_model::effects::HuntCrossley;
use bouncelab_model::{Model, ModelSpec, State};
use std::time::Instant;

const SIGMA: f64 = 0.03 * 4e-4;

fn session() -> Vec<MeasuredShot> {
    let mut rng = Rng::new(48);
    let mut shots = Vec::new();
    for (surface, (k, b)) in [("clay", CLAY), ("tape1", TAPE1), ("tape2", TAPE2)] {
        let model = Model::paper(k, b, 0.5).with(HuntCrossley { lambda: 2000.0, n: 1.0 });
        for h in [0.2, 0.45, 0.7, 0.9] {
            for a in [0.0, 7.5, 15.0, 22.5] {
                let sim = simulate_shot(&model, h, a, &mut rng);
                let offset = 0.3 * (rng.uniform() - 0.5);
                let frames = sim
                    .samples
                    .iter()
                    .map(|s| MeasuredFrame {
                        t_s: s.t,
                        x_m: s.observed.x + offset + SIGMA * rng.normal(),
                        y_m: s.observed.y + SIGMA * rng.normal(),
                        sigma_m: SIGMA,
                    })
                    .collect();
                let o = sim.samples[0].observed;
                shots.push(MeasuredShot {
                    name: format!("{surface}-h{h}-a{a}"),
                    surface: surface.into(),
                    incline_rad: a.to_radians(),
                    frames,
                    start: StartState {
                        t_s: sim.samples[0].t,
                        state: State {
                            x: o.x + offset,
                            ..o.into()
                        },
                    },
                    measured: None,
                    surface_sigma_m: None,
                    frame_sigma_rad: None,
                    spin_sigma_rad_s: None,
                    rim_change_m: None,
                });
            }
        }
    }
    shots
}

/// One search, timed, with the time of each model.
fn search(shots: &[MeasuredShot], options: &SearchOptions, label: &str) -> f64 {
    let clock = Instant::now();
    let d = find_missing_effect(&ModelSpec::paper(), shots, options, &|_| {}).expect("the diagnosis runs");
    let seconds = clock.elapsed().as_secs_f64();
    eprintln!(
        "{label}: {} shots ({} frames): {} {:?} in {seconds:.2} s",
        shots.len(),
        shots.iter().map(|s| s.frames.len()).sum::<usize>(),
        d.verdict.kind.name(),
        d.verdict.effects,
    );
    eprintln!("  current model: {:.2} s", d.baseline.seconds);
    for c in &d.candidates {
        eprintln!("  + {:<20} {:.2} s", c.effect, c.seconds);
    }
    seconds
}

fn main() {
    // `cargo bench` passes `--bench`; any other argument is a filter we do not need.
    let shots = session();
    let mut times: Vec<f64> = (1..=3)
        .map(|run| search(&shots, &SearchOptions::default(), &format!("run {run} (defaults)")))
        .collect();
    times.sort_by(f64::total_cmp);
    eprintln!("median of 3: {:.2} s (target ≤ 10 s on 2 cores)", times[1]);
    let levels = SearchOptions {
        surface_levels: true,
        ..SearchOptions::default()
    };
    search(&shots, &levels, "surface levels on (free per shot: no σ stated)");
}
