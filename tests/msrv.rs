//! The minimum Rust version stated in `Cargo.toml` and `README.md` is the real one: no locked dependency
//! (any feature, this platform) declares a newer `rust-version`, and at least one declares exactly it, so
//! the stated minimum is neither too low nor needlessly high. Our own code is held to it by clippy's
//! `incompatible_msrv` lint, which reads the same `rust-version` (`.ci/run` runs clippy with `-D warnings`).
//!
//! This machine has one toolchain and cannot fetch another, so no build with the minimum itself runs here.

use std::process::Command;

/// A Rust version as (major, minor, patch).
type Version = (u32, u32, u32);

/// `1.89` or `1.89.0` as (1, 89, 0).
fn version(text: &str) -> Version {
    let mut parts = text.trim().split('.').map(|p| p.parse::<u32>().unwrap());
    let mut next = || parts.next().unwrap_or(0);
    (next(), next(), next())
}

/// (package, its declared rust-version) for every package in the locked resolve on this platform, every
/// feature on, and the workspace's own rust-version.
fn locked_rust_versions() -> (Vec<(String, Version)>, Version) {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["metadata", "--locked", "--format-version", "1", "--all-features"])
        .args(["--filter-platform", "x86_64-unknown-linux-gnu"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo metadata runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let members: Vec<&str> = meta["workspace_members"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m.as_str().unwrap())
        .collect();
    let resolved: Vec<&str> = meta["resolve"]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["id"].as_str().unwrap())
        .collect();
    let mut ours = None;
    let mut deps = Vec::new();
    for p in meta["packages"].as_array().unwrap() {
        let id = p["id"].as_str().unwrap();
        let Some(rv) = p["rust_version"].as_str() else {
            continue;
        };
        if members.contains(&id) {
            ours = Some(version(rv));
        } else if resolved.contains(&id) {
            deps.push((format!("{} {}", p["name"].as_str().unwrap(), p["version"]), version(rv)));
        }
    }
    (deps, ours.expect("the workspace states a rust-version"))
}

#[test]
fn the_stated_minimum_rust_version_is_the_locked_dependencies_real_one() {
    let (deps, ours) = locked_rust_versions();
    let newer: Vec<_> = deps.iter().filter(|(_, v)| *v > ours).collect();
    assert!(
        newer.is_empty(),
        "locked dependencies need a newer Rust than {ours:?}: {newer:?}"
    );
    let at: Vec<_> = deps.iter().filter(|(_, v)| *v == ours).map(|(p, _)| p).collect();
    assert!(
        !at.is_empty(),
        "no locked dependency needs {ours:?}; the real minimum is {:?}",
        deps.iter().map(|(_, v)| *v).max()
    );
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let stated = format!("Rust toolchain ({}.{} or newer", ours.0, ours.1);
    assert!(readme.contains(&stated), "README.md should say `{stated}`");
}

#[test]
fn versions_compare_by_number() {
    assert!(version("1.89") > version("1.88.1"));
    assert!(version("1.100") > version("1.99"));
    assert_eq!(version("1.89"), version("1.89.0"));
}
