// cargo run --release --example looks_accuracy -- [PRESET|SCENARIO.toml|SESSION_DIR TRUTH_DIR]
//
//! The tracker and estimator on many looks (default: the `looks` preset, 64 shots, rendered into a temporary
//! folder): a Markdown table per clip and one per look family (frames found, centre RMS in flight and
//! contact, contact level error, COR and μ errors). The figures in `docs/accuracy.md` ("Many looks") come
//! from this command.

#[path = "../tests/common/looks.rs"]
mod looks;

use std::path::{Path, PathBuf};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let _tmp;
    let (session, truth): (PathBuf, PathBuf) = if args.len() >= 2 {
        (args[0].clone().into(), args[1].clone().into())
    } else {
        let what = args.first().map(String::as_str).unwrap_or("looks");
        let scenario = if what.ends_with(".toml") {
            bouncelab_render::Scenario::load(Path::new(what)).expect("scenario")
        } else {
            bouncelab_render::Scenario::preset(what).expect("preset")
        };
        _tmp = tempfile::tempdir().unwrap();
        bouncelab_render::render(&scenario, _tmp.path()).expect("render");
        (_tmp.path().join("session"), _tmp.path().join("truth"))
    };
    let results = looks::evaluate(&session, &truth);
    println!("{}", looks::clip_table(&results));
    println!("{}", looks::family_table(&results));
}
