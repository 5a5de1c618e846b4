//! cargo run --release -p bouncelab-render --example render_speed [-- PRESET [SHOT] [OUT.png]]
//!
//! Renders every frame of one shot on one core, PNG-encoded in memory, and prints the time per frame
//! (background preparation counted separately). With OUT.png it also saves the shot's frame at maximum
//! compression.

use bouncelab_render::{Scenario, ShotPlan, encode};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let preset = args.get(1).map(String::as_str).unwrap_or("paper");
    let shot: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100);
    let scenario = Scenario::preset(preset).expect("preset");
    let shot = shot.min(scenario.shots.len() - 1);
    let t = Instant::now();
    let plan = ShotPlan::new(&scenario, shot).expect("plan");
    let t_plan = t.elapsed();
    let t = Instant::now();
    let r = plan.renderer();
    let t_bg = t.elapsed();
    let n = plan.frames.len();
    let (mut t_render, mut t_encode, mut bytes) = (0.0, 0.0, 0usize);
    for i in 0..n {
        let t = Instant::now();
        let f = r.frame(i);
        t_render += t.elapsed().as_secs_f64();
        let t = Instant::now();
        bytes += encode(&f, plan.camera().format).expect("encode").len();
        t_encode += t.elapsed().as_secs_f64();
    }
    println!(
        "{preset} shot {} ({}): {n} frames {}x{}; physics {:.1} ms, background {:.1} ms per clip",
        shot,
        plan.truth.clip,
        plan.camera().width,
        plan.camera().height,
        t_plan.as_secs_f64() * 1e3,
        t_bg.as_secs_f64() * 1e3
    );
    println!(
        "per frame: render {:.2} ms + PNG encode {:.2} ms = {:.2} ms (one core), {:.0} kB per frame",
        t_render / n as f64 * 1e3,
        t_encode / n as f64 * 1e3,
        (t_render + t_encode) / n as f64 * 1e3,
        bytes as f64 / n as f64 / 1e3
    );
    if let Some(out) = args.get(3) {
        let i = plan
            .frames
            .iter()
            .position(|f| f.t_s >= plan.truth.t_max_s)
            .unwrap_or(0);
        std::fs::write(out, encode(&r.frame(i), plan.camera().format).unwrap()).unwrap();
        println!("frame {i} (maximum compression) written to {out}");
    }
}
