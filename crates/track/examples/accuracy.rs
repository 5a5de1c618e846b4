// cargo run --release -p bouncelab-track --example accuracy -- [PRESET|SCENARIO.toml|SESSION_DIR TRUTH_DIR] [--seed N]
//
//! Tracker accuracy against the renderer's exact truth: per clip, the centre error in flight and in contact,
//! the contact shift (the mean contact error less the mean flight error: what a contact model sees, since a
//! constant offset goes into the start states), the jitter (residual from a local quadratic over 11 frames),
//! the radius bias, the calibration of σ, the scale and the surface tilt. With a preset name (default `none`) it renders the preset into a temporary
//! folder first. Prints a Markdown table.

use bouncelab_frames::Clip;
use bouncelab_track::{ClipTracking, Status, track_clip};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

#[derive(Default)]
struct Truth {
    x: f64,
    y: f64,
    r: f64,
    /// Centre height above the surface, m.
    y_m: f64,
    contact: bool,
    visible: bool,
}

fn read_truth(path: &Path) -> HashMap<usize, Truth> {
    let mut rdr = csv::Reader::from_path(path).expect("truth csv");
    let h = rdr.headers().unwrap().clone();
    let col = |name: &str| {
        h.iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("{name} column"))
    };
    let (f, x, y, r, ym, ph, vis) = (
        col("frame"),
        col("x_px"),
        col("y_px"),
        col("r_px"),
        col("y_m"),
        col("phase"),
        col("visible"),
    );
    rdr.records()
        .map(|rec| {
            let rec = rec.unwrap();
            let n = |i: usize| rec[i].parse::<f64>().unwrap();
            (
                rec[f].parse().unwrap(),
                Truth {
                    x: n(x),
                    y: n(y),
                    r: n(r),
                    y_m: n(ym),
                    contact: &rec[ph] != "flight",
                    visible: &rec[vis] == "full",
                },
            )
        })
        .collect()
}

fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt()
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed_at = args.iter().position(|a| a == "--seed");
    let seed = seed_at.map(|i| args[i + 1].parse::<u64>().expect("--seed N"));
    let positional: Vec<&String> = args
        .iter()
        .enumerate()
        .filter(|(i, a)| !a.starts_with("--") && seed_at.is_none_or(|s| *i != s + 1))
        .map(|(_, a)| a)
        .collect();
    let _tmp;
    let (session, truth_dir): (PathBuf, PathBuf) = if positional.len() >= 2 {
        (positional[0].into(), positional[1].into())
    } else {
        let preset = positional.first().map(|s| s.as_str()).unwrap_or("none");
        let mut scenario = if preset.ends_with(".toml") {
            bouncelab_render::Scenario::load(Path::new(preset)).expect("scenario")
        } else {
            bouncelab_render::Scenario::preset(preset).expect("preset")
        };
        if let Some(s) = seed {
            scenario.seed = s;
        }
        _tmp = tempfile::tempdir().unwrap();
        bouncelab_render::render(&scenario, _tmp.path()).expect("render");
        (_tmp.path().join("session"), _tmp.path().join("truth"))
    };
    let shots = read_shots(&truth_dir.join("shots.csv"));
    println!(
        "| clip | frames ok | flight RMS px | contact RMS px | contact shift px | jitter px | radius bias px | RMS err/σ | scale err % | tilt err ° | line height px |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let (mut all_f, mut all_c, mut all_j, mut all_rb, mut all_z) = (vec![], vec![], vec![], vec![], vec![]);
    let (mut all_shift, mut all_line) = (vec![], vec![]);
    for (clip_name, (scale_truth, tilt_truth)) in &shots {
        let clip = Clip::open(session.join(clip_name)).unwrap();
        let truth = read_truth(&truth_dir.join(format!("{clip_name}.csv")));
        let track = track_clip(&clip, &ClipTracking::default(), |_, _| {}).unwrap();
        let (mut ef, mut ec, mut rb, mut z) = (vec![], vec![], vec![], vec![]);
        let mut series: Vec<(usize, f64, f64)> = vec![];
        let mut ok = 0;
        for f in &track.fixes {
            let Some(t) = truth.get(&f.frame) else { continue };
            if f.status != Status::Ok || !t.visible {
                continue;
            }
            ok += 1;
            let (dx, dy) = (f.x_px - t.x, f.y_px - t.y);
            if t.contact {
                ec.extend([dx, dy]);
            } else {
                ef.extend([dx, dy]);
                rb.push(f.r_px - t.r);
            }
            z.extend([dx / f.sigma_px, dy / f.sigma_px]);
            series.push((f.frame, f.x_px, f.y_px));
        }
        // Jitter: residual from a quadratic over 11 consecutive frames, in flight only.
        let mut jit = vec![];
        for w in series.windows(11) {
            if w[10].0 - w[0].0 != 10 || w.iter().any(|p| truth[&p.0].contact) {
                continue;
            }
            for k in [1, 2] {
                let ys: Vec<f64> = w.iter().map(|p| if k == 1 { p.1 } else { p.2 }).collect();
                jit.push(quad_residual(&ys));
            }
        }
        let scale_err = track
            .scale
            .map(|s| (s.m_per_px / scale_truth - 1.0) * 100.0)
            .unwrap_or(f64::NAN);
        let tilt_err = track.surface.map(|l| l.tilt_deg() - tilt_truth).unwrap_or(f64::NAN);
        // How far above the renderer's contact plane the surface line was found, px, below the first frame's
        // centre (distances taken perpendicular to the line).
        let line_height = match (track.surface, truth.get(&0)) {
            (Some(l), Some(t)) => {
                let found = (l.y_at(t.x) - t.y) * l.slope.atan().cos();
                t.y_m / scale_truth - found
            }
            _ => f64::NAN,
        };
        all_line.push(line_height);
        let mean_rb = rb.iter().sum::<f64>() / rb.len().max(1) as f64;
        // ef and ec hold (dx, dy) pairs.
        let mean_xy = |v: &[f64], k: usize| {
            let n = (v.len() / 2).max(1) as f64;
            v.iter().skip(k).step_by(2).sum::<f64>() / n
        };
        let shift = (mean_xy(&ec, 0) - mean_xy(&ef, 0)).hypot(mean_xy(&ec, 1) - mean_xy(&ef, 1));
        if shift.is_finite() && !ec.is_empty() {
            all_shift.push(shift);
        }
        println!(
            "| {clip_name} | {ok}/{} | {:.3} | {:.3} | {:.3} | {:.4} | {:+.3} | {:.2} | {:+.3} | {:+.3} | {:+.3} |",
            track.fixes.len(),
            rms(&ef),
            rms(&ec),
            shift,
            rms(&jit),
            mean_rb,
            rms(&z),
            scale_err,
            tilt_err,
            line_height
        );
        all_f.extend(ef);
        all_c.extend(ec);
        all_j.extend(jit);
        all_rb.extend(rb);
        all_z.extend(z);
    }
    let mean_rb = all_rb.iter().sum::<f64>() / all_rb.len().max(1) as f64;
    println!(
        "| **all** | | **{:.3}** | **{:.3}** | **{:.3}** (RMS) | **{:.4}** | **{:+.3}** | **{:.2}** | | | **{:+.3}** (mean) |",
        rms(&all_f),
        rms(&all_c),
        rms(&all_shift),
        rms(&all_j),
        mean_rb,
        rms(&all_z),
        all_line.iter().sum::<f64>() / all_line.len().max(1) as f64
    );
}

/// RMS residual of the middle point from a least-squares quadratic through 11 equally spaced values.
fn quad_residual(ys: &[f64]) -> f64 {
    let n = ys.len() as f64;
    let xs: Vec<f64> = (0..ys.len()).map(|i| i as f64 - (n - 1.0) / 2.0).collect();
    let (s2, s4) = (
        xs.iter().map(|x| x * x).sum::<f64>(),
        xs.iter().map(|x| x.powi(4)).sum::<f64>(),
    );
    let sy = ys.iter().sum::<f64>();
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| x * y).sum();
    let sx2y: f64 = xs.iter().zip(ys).map(|(x, y)| x * x * y).sum();
    // Symmetric abscissae: c1 = Σxy/Σx²; c0, c2 from the 2×2 system in (1, x²).
    let c1 = sxy / s2;
    let det = n * s4 - s2 * s2;
    let c0 = (s4 * sy - s2 * sx2y) / det;
    let c2 = (n * sx2y - s2 * sy) / det;
    let res: Vec<f64> = xs.iter().zip(ys).map(|(x, y)| y - (c0 + c1 * x + c2 * x * x)).collect();
    (res.iter().map(|r| r * r).sum::<f64>() / (n - 3.0)).sqrt()
}

fn read_shots(path: &Path) -> Vec<(String, (f64, f64))> {
    let mut rdr = csv::Reader::from_path(path).expect("shots.csv");
    let h = rdr.headers().unwrap().clone();
    let col = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (c, s, t) = (col("clip"), col("scale_m_per_px"), col("surface_tilt_deg"));
    rdr.records()
        .map(|r| {
            let r = r.unwrap();
            (r[c].to_string(), (r[s].parse().unwrap(), r[t].parse().unwrap()))
        })
        .collect()
}
