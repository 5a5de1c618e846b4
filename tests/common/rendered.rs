//! A session and its truth for the accuracy examples: the two folders given on the command line, or a preset
//! (or scenario file) rendered into a temporary folder that lives as long as the returned guard.

use std::path::{Path, PathBuf};

/// `SESSION_DIR TRUTH_DIR`, or `[PRESET|SCENARIO.toml]` (default `default_preset`) rendered now.
pub fn session_and_truth(args: &[String], default_preset: &str) -> (PathBuf, PathBuf, Option<tempfile::TempDir>) {
    if args.len() >= 2 {
        return (args[0].clone().into(), args[1].clone().into(), None);
    }
    let what = args.first().map(String::as_str).unwrap_or(default_preset);
    let scenario = if what.ends_with(".toml") {
        bouncelab_render::Scenario::load(Path::new(what)).expect("scenario")
    } else {
        bouncelab_render::Scenario::preset(what).expect("preset")
    };
    let tmp = tempfile::tempdir().unwrap();
    bouncelab_render::render(&scenario, tmp.path()).expect("render");
    (tmp.path().join("session"), tmp.path().join("truth"), Some(tmp))
}
