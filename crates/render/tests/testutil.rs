//! Shared helpers: tiny scenarios and folder comparison.

#![allow(dead_code)]

use bouncelab_render::{NoRenderProgress, RenderOptions, Rendered, RenderedFrame, Scenario, render_with};
use std::path::{Path, PathBuf};

/// A tiny two-shot scenario: 160×160 frames, ball ≈ 42 px across, 2 ms before touch and after separation.
pub fn tiny(seed: u64) -> String {
    format!(
        r#"
seed = {seed}
pre_contact_ms = 2
post_separation_ms = 2
[camera]
width = 160
height = 160
scale_m_per_px = 1.6e-3
[surfaces.clay]
texture = "clay"
spring.k = 25650
damping.b = 14
[surfaces.tape1]
texture = "white_tape"
spring.k = 30800
damping.b = 15
[[shots]]
surface = "clay"
angle_deg = 0
drop_height_m = 0.3
[[shots]]
surface = "tape1"
angle_deg = 15
drop_height_m = 0.25
effects = ["hertz"]
[extra_effects.hertz]
k_h = 300000
"#
    )
}

/// Every file under `dir`, relative, sorted.
pub fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    fn walk(base: &Path, d: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(p.strip_prefix(base).unwrap().to_path_buf());
            }
        }
    }
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Reads a CSV file into (header, rows).
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|x| x.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

/// The value of `col` in `row`.
pub fn col<'a>(header: &[String], row: &'a [String], col: &str) -> &'a str {
    let i = header
        .iter()
        .position(|h| h == col)
        .unwrap_or_else(|| panic!("no column {col}"));
    &row[i]
}

/// Bilinear sample of the frame.
pub fn sample(f: &RenderedFrame, x: f64, y: f64) -> f64 {
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (i, j) = (x0 as u32, y0 as u32);
    let g = |a, b| f.get(a, b);
    (g(i, j) * (1.0 - fx) + g(i + 1, j) * fx) * (1.0 - fy) + (g(i, j + 1) * (1.0 - fx) + g(i + 1, j + 1) * fx) * fy
}

/// Brute-force circle fit: along 360 rays from a start centre, the strongest edge (largest gradient of a
/// lightly smoothed profile) near the start radius, refined by a parabola; then an algebraic least-squares
/// circle fit with one round of outlier rejection.
#[allow(clippy::needless_range_loop)] // a small dense Gauss–Jordan solve
pub fn fit_circle(f: &RenderedFrame, cx: f64, cy: f64, r: f64) -> (f64, f64, f64) {
    let mut pts = Vec::new();
    for a in 0..360 {
        let t = (a as f64).to_radians();
        let (c, s) = (t.cos(), t.sin());
        let prof: Vec<f64> = (0..=64)
            .map(|k| {
                let rr = r - 4.0 + k as f64 * 0.125;
                let mut acc = 0.0;
                for o in [-0.5, 0.0, 0.5] {
                    acc += sample(f, cx + rr * c - o * s, cy + rr * s + o * c);
                }
                acc / 3.0
            })
            .collect();
        let grad: Vec<f64> = (0..prof.len())
            .map(|k| {
                if k < 4 || k + 4 >= prof.len() {
                    0.0
                } else {
                    (prof[k + 4] - prof[k - 4]).abs()
                }
            })
            .collect();
        let (kmax, _) = grad
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (k, &g)| if g > b.1 { (k, g) } else { b });
        if kmax < 5 || kmax + 5 > grad.len() {
            continue;
        }
        let (gm, g0, gp) = (grad[kmax - 1], grad[kmax], grad[kmax + 1]);
        let off = 0.5 * (gm - gp) / (gm - 2.0 * g0 + gp);
        let rr = r - 4.0 + (kmax as f64 + off.clamp(-1.0, 1.0)) * 0.125;
        pts.push((cx + rr * c, cy + rr * s));
    }
    let kasa = |p: &[(f64, f64)]| {
        // Solve for x² + y² + D x + E y + F = 0.
        let mut m = [[0.0f64; 4]; 3];
        for &(x, y) in p {
            let row = [x, y, 1.0, -(x * x + y * y)];
            for i in 0..3 {
                for j in 0..4 {
                    m[i][j] += row[i] * row[j];
                }
            }
        }
        for i in 0..3 {
            let piv = m[i][i];
            for j in 0..4 {
                m[i][j] /= piv;
            }
            for k in 0..3 {
                if k != i {
                    let fct = m[k][i];
                    for j in 0..4 {
                        m[k][j] -= fct * m[i][j];
                    }
                }
            }
        }
        let (d, e, ff) = (m[0][3], m[1][3], m[2][3]);
        let (x0, y0) = (-d / 2.0, -e / 2.0);
        (x0, y0, (x0 * x0 + y0 * y0 - ff).sqrt())
    };
    let first = kasa(&pts);
    let kept: Vec<_> = pts
        .into_iter()
        .filter(|&(x, y)| ((x - first.0).hypot(y - first.1) - first.2).abs() < 1.0)
        .collect();
    kasa(&kept)
}

/// A small scenario with a `[look]`: 3 shots (clay, white tape, green tape) at 176 × 176 with a ball of
/// 14–22 px, 1 ms of flight either side, every clutter item asked for; `extra` holds more `[look]` keys,
/// and replaces these defaults where it sets the same key.
pub fn tiny_look(seed: u64, extra: &str) -> String {
    let defaults = [
        "width_px = 176",
        "height_px = 176",
        "ball_radius_px = [14, 22]",
        "ruler = 1",
        "fixtures = 1",
        "screws = 2",
        "second_circle = 1",
        "hand = 1",
        "hot_spots = 1",
    ];
    let set: Vec<&str> = extra
        .lines()
        .filter_map(|l| l.split('=').next())
        .map(str::trim)
        .collect();
    let look: Vec<&str> = defaults
        .iter()
        .copied()
        .filter(|d| !set.contains(&d.split('=').next().unwrap().trim()))
        .collect();
    format!(
        r#"
seed = {seed}
pre_contact_ms = 1
post_separation_ms = 1
[surfaces.clay]
texture = "clay"
[surfaces.tape1]
texture = "white_tape"
[surfaces.tape2]
texture = "green_tape"
[[shots]]
surface = "clay"
angle_deg = 0
drop_height_m = 0.3
[[shots]]
surface = "tape1"
angle_deg = 15
drop_height_m = 0.25
[[shots]]
surface = "tape2"
angle_deg = 22.5
drop_height_m = 0.2
[look]
{}
{extra}
"#,
        look.join("\n")
    )
}

/// Renders `s` into a fresh folder, in parallel or not, refusing to overwrite.
pub fn render_to(s: &Scenario, dir: &Path, parallel: bool) -> Rendered {
    let opts = RenderOptions {
        parallel,
        overwrite: false,
    };
    render_with(s, dir, &opts, &NoRenderProgress).unwrap()
}

/// Renders `s` twice sequentially and once in parallel and asserts the three folders are byte-identical;
/// returns how many files each holds.
pub fn assert_renders_identically(s: &Scenario) -> usize {
    let dirs = [(); 3].map(|_| tempfile::tempdir().unwrap());
    for (d, parallel) in dirs.iter().zip([false, false, true]) {
        render_to(s, d.path(), parallel);
    }
    let fa = files(dirs[0].path());
    for (d, what) in [(&dirs[1], "between runs"), (&dirs[2], "sequential vs parallel")] {
        assert_eq!(fa, files(d.path()), "the files differ {what}");
        for f in &fa {
            let x = std::fs::read(dirs[0].path().join(f)).unwrap();
            assert!(
                x == std::fs::read(d.path().join(f)).unwrap(),
                "{} differs {what}",
                f.display()
            );
        }
    }
    fa.len()
}
