// cargo run --release --example estimate_accuracy -- [PRESET|SCENARIO.toml|SESSION_DIR TRUTH_DIR]
//
//! The estimator against the renderer's exact truth, through the whole chain (frames → tracker → estimator,
//! no truth inside the pipeline): per shot the errors of COR, effective friction, incoming and outgoing
//! speed, contact time and maximum penetration, then the RMS errors, the calibration of the standard errors
//! (RMS of error/SE), and the per-surface, per-angle mean COR against the truth's. With a preset name
//! (default `none`) or a scenario file it renders into a temporary folder first.

#[path = "../tests/common/rendered.rs"]
mod rendered;

use bouncelab_estimate::{Conditions, estimate_with_frames, fall_se_deg};
use bouncelab_frames::Session;
use bouncelab_track::{ClipTracking, track_clip};
use std::collections::BTreeMap;

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|e| e * e).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (session_dir, truth_dir, _tmp) = rendered::session_and_truth(&args, "none");
    let session = Session::load(&session_dir).expect("session");
    let mut truth = csv::Reader::from_path(truth_dir.join("shots.csv")).expect("shots.csv");
    let h = truth.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|c| c == n).unwrap_or_else(|| panic!("column {n}"));
    let rows: Vec<csv::StringRecord> = truth.records().map(|r| r.unwrap()).collect();
    println!(
        "| clip | COR est ± SE | COR truth | μ est | μ truth | |v_in| err % | |v_out| err % | contact est / truth ms | δ_max est / truth mm |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let (mut e_cor, mut e_mu, mut e_vin, mut e_vout, mut e_tc, mut e_d) =
        (vec![], vec![], vec![], vec![], vec![], vec![]);
    let (mut z_cor, mut z_vin, mut z_vout, mut z_tc) = (vec![], vec![], vec![], vec![]);
    let mut e_spin: Vec<(f64, f64)> = vec![]; // (error, allowed max(2 rad/s, 3 %))
    let mut groups: BTreeMap<(String, String), (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    let mut failures = Vec::new();
    for r in &rows {
        let name = &r[col("clip")];
        let num = |c: &str| r[col(c)].parse::<f64>().unwrap();
        let entry = session.clip(name).expect("clip in clips.csv");
        let clip = entry.open().expect("clip");
        let opts = ClipTracking {
            ball_diameter_m: session.ball.diameter_m,
            ..ClipTracking::default()
        };
        let track = match track_clip(&clip, &opts, |_, _| {}) {
            Ok(t) => t,
            Err(e) => {
                failures.push(format!("{name}: {e}"));
                continue;
            }
        };
        let c = Conditions {
            incline_deg: entry.angle_deg,
            gravity: 9.81,
            ball_diameter_m: session.ball.diameter_m,
            surface_tilt_deg: None,
            fall_se_deg: fall_se_deg(entry.settings.dropped_from_rest, entry.settings.incline_se_deg),
        };
        let est = match estimate_with_frames(&track, &clip, &c) {
            Ok(e) => e,
            Err(e) => {
                failures.push(format!("{name}: {e}"));
                continue;
            }
        };
        let (vin_t, vin_n, vout_t, vout_n) = (num("v_in_t"), num("v_in_n"), num("v_out_t"), num("v_out_n"));
        let speed = |a: f64, b: f64| a.hypot(b);
        let vin = speed(est.v_in[0].value, est.v_in[1].value);
        let vout = speed(est.v_out[0].value, est.v_out[1].value);
        let (cor_t, mu_t) = (num("cor"), num("mu_eff"));
        e_cor.push(est.cor.value - cor_t);
        e_mu.push(est.mu.value - mu_t);
        e_vin.push((vin / speed(vin_t, vin_n) - 1.0) * 100.0);
        e_vout.push((vout / speed(vout_t, vout_n) - 1.0) * 100.0);
        e_tc.push(est.contact_ms.value - num("contact_ms"));
        e_d.push((est.delta_max_m.value - num("delta_max_m")) * 1e3);
        for (m, t) in [(est.spin_in, num("spin_in")), (est.spin_out, num("spin_out"))] {
            if let Some(m) = m {
                e_spin.push((m.value - t, (0.03 * t.abs()).max(2.0)));
            }
        }
        z_cor.push((est.cor.value - cor_t) / est.cor.se);
        z_vin.push((est.v_in[1].value - vin_n) / est.v_in[1].se);
        z_vout.push((est.v_out[1].value - vout_n) / est.v_out[1].se);
        z_tc.push((est.contact_ms.value - num("contact_ms")) / est.contact_ms.se);
        let g = groups
            .entry((r[col("surface")].to_string(), r[col("angle_deg")].to_string()))
            .or_default();
        g.0.push(est.cor.value);
        g.1.push(cor_t);
        println!(
            "| {name} | {:.4} ± {:.4} | {cor_t:.4} | {:.4} | {mu_t:.4} | {:+.2} | {:+.2} | {:.3} / {:.3} | {:.3} / {:.3} |",
            est.cor.value,
            est.cor.se,
            est.mu.value,
            e_vin.last().unwrap(),
            e_vout.last().unwrap(),
            est.contact_ms.value,
            num("contact_ms"),
            est.delta_max_m.value * 1e3,
            num("delta_max_m") * 1e3
        );
    }
    println!();
    println!("| quantity | RMS error | target |");
    println!("|---|---|---|");
    println!("| COR | {:.4} | ≤ 0.003 |", rms(&e_cor));
    println!("| μ_eff | {:.4} | ≤ 0.01 |", rms(&e_mu));
    println!("| incoming speed | {:.3} % | ≤ 0.3 % |", rms(&e_vin));
    println!("| outgoing speed | {:.3} % | ≤ 0.3 % |", rms(&e_vout));
    println!("| contact time | {:.4} ms | ≤ 0.1 ms |", rms(&e_tc));
    println!("| δ_max | {:.4} mm | ≤ 0.3 mm |", rms(&e_d));
    let spin_err: Vec<f64> = e_spin.iter().map(|e| e.0).collect();
    let worst = e_spin.iter().map(|e| e.0.abs() / e.1).fold(0.0, f64::max);
    println!(
        "| spin (in and out, {} measured) | {:.3} rad/s (worst at {:.0} % of its limit) | ≤ max(2 rad/s, 3 %) |",
        e_spin.len(),
        rms(&spin_err),
        worst * 100.0
    );
    println!(
        "| RMS(error/SE): COR, v_in,n, v_out,n | {:.2}, {:.2}, {:.2} | 0.5–2 |",
        rms(&z_cor),
        rms(&z_vin),
        rms(&z_vout)
    );
    println!("| RMS(error/SE): contact time | {:.2} | not a target |", rms(&z_tc));
    println!();
    println!("| surface | angle ° | mean COR est | mean COR truth | difference |");
    println!("|---|---|---|---|---|");
    for ((s, a), (est, tru)) in &groups {
        let m = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        println!(
            "| {s} | {a} | {:.4} | {:.4} | {:+.4} |",
            m(est),
            m(tru),
            m(est) - m(tru)
        );
    }
    for f in failures {
        println!("failed: {f}");
    }
}
