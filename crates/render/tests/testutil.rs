//! Shared helpers: tiny scenarios and folder comparison.

#![allow(dead_code)]

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
