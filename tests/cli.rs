//! End-to-end tests of the `bouncelab` binary: outputs, exit codes and error lines.

use assert_cmd::Command;
use predicates::prelude::*;

fn bouncelab() -> Command {
    Command::cargo_bin("bouncelab").unwrap()
}

#[test]
fn demo_prints_cor_and_contact_time_for_the_three_surfaces() {
    let out = bouncelab().arg("demo").assert().success().get_output().stdout.clone();
    let text = String::from_utf8(out).unwrap();
    for surface in ["clay", "tape1", "tape2"] {
        let rows: Vec<&str> = text.lines().filter(|l| l.starts_with(surface)).collect();
        assert_eq!(rows.len(), 4, "four drop heights for {surface}:\n{text}");
        for row in rows {
            let cols: Vec<f64> = row.split_whitespace().skip(1).map(|c| c.parse().unwrap()).collect();
            let (cor, contact_ms) = (cols[2], cols[3]);
            assert!((0.7..0.8).contains(&cor) && (3.5..5.0).contains(&contact_ms), "{row}");
        }
    }
}

#[test]
fn simulate_prints_the_anchor_for_clay() {
    bouncelab()
        .args([
            "simulate",
            "--surface",
            "clay",
            "--speed",
            "2",
            "--angle",
            "0",
            "--json",
        ])
        .assert()
        .success()
        .stdout(predicate::str::contains("\"restitution\": 0.769"));
}

#[test]
fn simulate_with_the_shipped_model_file() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/paper-model.toml");
    bouncelab()
        .args([
            "simulate",
            "--model",
            path,
            "--surface",
            "tape2",
            "--speed",
            "2.0",
            "--angle",
            "15",
        ])
        .assert()
        .success()
        .stdout(predicate::str::contains("tape2").and(predicate::str::contains("COR")));
}

#[test]
fn effects_lists_every_effect_with_its_parameters() {
    let assert = bouncelab().arg("effects").assert().success();
    let text = String::from_utf8(assert.get_output().stdout.clone()).unwrap();
    for name in [
        "spring",
        "damping",
        "coulomb",
        "hertz",
        "hunt_crossley",
        "restitution_damping",
        "plastic_dent",
        "rolling_resistance",
        "inertia_factor",
        "drag",
        "camera_roll",
        "custom",
    ] {
        assert!(text.contains(name), "{name} missing");
    }
    assert!(text.contains("N/m") && text.contains("delta_dot"));
}

#[test]
fn user_errors_exit_1_with_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("model.toml");
    std::fs::write(&bad, "[effects.sping]\nk = 1\n").unwrap();
    bouncelab()
        .args(["simulate", "--model", bad.to_str().unwrap()])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("unknown effect `sping`").and(predicate::str::contains("model.toml")));
    bouncelab()
        .args(["simulate", "--surface", "grass"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("grass"));
    bouncelab()
        .args(["simulate", "--speed", "-3"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("--speed -3"));
    bouncelab()
        .args(["simulate", "--spin", "-40", "--angle", "-10"])
        .assert()
        .success();
    bouncelab()
        .args(["simulate", "--model", "/nonexistent/model.toml"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("/nonexistent/model.toml"));
}

#[test]
fn usage_errors_exit_2() {
    bouncelab().args(["simulate", "--speed"]).assert().code(2);
    bouncelab().arg("frobnicate").assert().code(2);
}
