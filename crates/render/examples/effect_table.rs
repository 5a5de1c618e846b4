//! cargo run --release -p bouncelab-render --example effect_table
//!
//! For every `effect-<name>` preset, the true outputs of its shots next to the `none` preset's (physics
//! only, no images): COR and contact time at 0.2 m and 0.9 m normal drops, and the largest changes of the
//! incoming normal speed, the outgoing tangential speed and the outgoing spin over the session.

use bouncelab_render::{Scenario, ShotPlan, ShotTruth, preset_names};

fn truths(name: &str) -> Vec<ShotTruth> {
    let s = Scenario::preset(name).unwrap();
    (0..s.shots.len())
        .map(|i| ShotPlan::new(&s, i).unwrap().truth)
        .collect()
}

fn main() {
    let none = truths("none");
    let at = |t: &[ShotTruth], h: f64| {
        t.iter()
            .find(|x| x.angle_deg == 0.0 && x.drop_height_m == h)
            .unwrap()
            .clone()
    };
    println!(
        "| preset | COR 0.2 m | COR 0.9 m | contact 0.2 m (ms) | contact 0.9 m (ms) | max Δv_in,n | max Δv_out,t | max Δω_out (rad/s) | tilt (°) |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for name in preset_names()
        .into_iter()
        .filter(|n| n == "none" || n.starts_with("effect-"))
    {
        let t = truths(&name);
        let (lo, hi) = (at(&t, 0.2), at(&t, 0.9));
        let max = |f: &dyn Fn(&ShotTruth) -> f64| {
            t.iter()
                .zip(&none)
                .map(|(a, b)| (f(a) - f(b)).abs())
                .fold(0.0f64, f64::max)
        };
        println!(
            "| {name} | {:.4} | {:.4} | {:.3} | {:.3} | {:.4} m/s | {:.4} m/s | {:.2} | {} |",
            lo.cor,
            hi.cor,
            lo.contact_ms,
            hi.contact_ms,
            max(&|x| x.v_in_n),
            max(&|x| x.v_out_t),
            max(&|x| x.spin_out),
            t[0].surface_tilt_deg
        );
    }
}
