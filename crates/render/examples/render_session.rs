//! cargo run --release -p bouncelab-render --example render_session -- PRESET|SCENARIO.toml OUT_DIR
//!
//! Renders a whole session as `bouncelab render` does (shots and frames in parallel on every core) and
//! prints the wall time, the frames written and the disk used.

use bouncelab_render::{NoRenderProgress, RenderOptions, Scenario, render_with};
use std::time::Instant;

fn du(p: &std::path::Path) -> u64 {
    std::fs::read_dir(p)
        .map(|d| {
            d.flatten()
                .map(|e| {
                    let m = e.metadata().unwrap();
                    if m.is_dir() { du(&e.path()) } else { m.len() }
                })
                .sum()
        })
        .unwrap_or(0)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(name), Some(out)) = (args.first(), args.get(1)) else {
        eprintln!("usage: render_session PRESET|SCENARIO.toml OUT_DIR");
        std::process::exit(2);
    };
    let s = if name.ends_with(".toml") {
        Scenario::load(std::path::Path::new(name)).expect("scenario")
    } else {
        Scenario::preset(name).expect("preset")
    };
    let out = std::path::Path::new(out);
    let opts = RenderOptions {
        parallel: true,
        overwrite: true,
    };
    let t = Instant::now();
    let r = render_with(&s, out, &opts, &NoRenderProgress).expect("render");
    let secs = t.elapsed().as_secs_f64();
    println!(
        "{name}: {} clips, {} frames in {secs:.1} s on {} threads ({:.2} ms per frame), {:.2} GB on disk",
        r.shots.len(),
        r.frames,
        rayon::current_num_threads(),
        secs * 1e3 / r.frames as f64,
        du(&r.session_dir) as f64 / 1e9
    );
}
