//! End-to-end tests of the `bouncelab` binary: outputs, exit codes and error lines.

use assert_cmd::Command;
use predicates::prelude::*;

fn bouncelab() -> Command {
    Command::cargo_bin("bouncelab").unwrap()
}

/// The README's first command, end to end (render, analyse, diagnose, accept, analyse again). Slow in a debug
/// build, so CI runs it in release: `cargo test --release --test cli -- --ignored demo`.
#[test]
#[ignore]
fn demo_names_the_hidden_effect_and_the_error_falls() {
    let dir = tempfile::tempdir().unwrap();
    let out = bouncelab()
        .args(["demo", "--out"])
        .arg(dir.path().join("demo"))
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let text = String::from_utf8(out).unwrap();
    eprintln!("{text}");
    for surface in ["clay", "tape1"] {
        let row = text
            .lines()
            .find(|l| l.starts_with(surface))
            .unwrap_or_else(|| panic!("no COR row for {surface}:\n{text}"));
        let cor: f64 = row.split_whitespace().nth(2).unwrap().parse().unwrap();
        assert!((0.5..0.9).contains(&cor), "{row}");
    }
    assert!(text.contains("Verdict: hunt_crossley is missing"), "{text}");
    // The verdict once, in short form: its long sentence is for `diagnose` and the report.
    assert!(!text.contains("The model is missing"), "{text}");
    assert!(
        !text.contains("ConvergedCost") && !text.contains("StartsSticking"),
        "{text}"
    );
    let total = text
        .lines()
        .find(|l| l.trim_start().starts_with("all shots"))
        .expect("a before/after total");
    let nums: Vec<f64> = total.split_whitespace().filter_map(|w| w.parse().ok()).collect();
    assert!(nums[0] / nums[1] >= 3.0, "the error must fall at least 3×: {total}");
    // The report shows the verdict and the error before and after, per shot.
    let report = std::fs::read_to_string(dir.path().join("demo/results/report.html")).unwrap();
    assert!(report.contains("Diagnosis: which effect is missing"));
    assert!(report.contains("hunt_crossley"));
    assert!(report.contains("Fit error per shot, before and after"));
    assert!(report.contains("before: built-in paper model (version 1)"));
    // The model change names the effect added and keeps the earlier verdict and residual signature.
    let change = &report[report.find("<section id=\"model-change\">").unwrap()..];
    let change = &change[..change.find("</section>").unwrap()];
    assert!(
        change.contains("<th>Effects added</th><td><code>hunt_crossley</code></td>"),
        "{change}"
    );
    assert!(
        change.contains("The earlier verdict") && change.contains("Missing effect found"),
        "{change}"
    );
    assert!(
        change.contains("Systematic residual per phase and component"),
        "{change}"
    );
    assert!(
        !report.contains("not available: the earlier model"),
        "the earlier verdict was kept"
    );
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

/// Writes a 30-frame clip of a ball falling onto a surface band, in a session folder.
fn write_session_with_one_clip(root: &std::path::Path) -> std::path::PathBuf {
    use bouncelab_track::testutil::{Scene, render};
    std::fs::write(
        root.join("session.toml"),
        "[ball]\ndiameter_m = 0.067\nmass_kg = 0.0567\n[camera]\nfps = 10000\n",
    )
    .unwrap();
    let clip = root.join("shot01");
    std::fs::create_dir_all(&clip).unwrap();
    for i in 0..30 {
        let s = Scene {
            ball: (100.0 + i as f64, 60.0 + 2.0 * i as f64, 40.0),
            surface: Some((220.0, 0.0)),
            band: (150.0, 20.0),
            seed: i,
            ..Scene::default()
        };
        let img = image::GrayImage::from_raw(256, 256, render(&s)).unwrap();
        img.save(clip.join(format!("img_{i:05}.png"))).unwrap();
    }
    clip
}

#[test]
fn track_writes_the_trajectory_columns() {
    let dir = tempfile::tempdir().unwrap();
    let clip = write_session_with_one_clip(dir.path());
    let out = dir.path().join("traj.csv");
    bouncelab()
        .args(["track", clip.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .assert()
        .success()
        .stderr(predicate::str::contains("30 frames, ball measured in 30").and(predicate::str::contains("scale")));
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "frame,t_s,x_px,y_px,r_px,sigma_px,quality,status,x_m,y_m"
    );
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(str::to_string).collect()).collect();
    assert_eq!(rows.len(), 30);
    assert!(rows.iter().all(|r| r[7] == "ok"));
    let x5: f64 = rows[5][2].parse().unwrap();
    assert!((x5 - 105.0).abs() < 0.1, "{x5}");
}

/// A ball that never moves is no ball in flight: exit 1, the clip named once in the error line.
#[test]
fn track_names_a_still_clip_once() {
    use bouncelab_track::testutil::{Scene, render};
    let dir = tempfile::tempdir().unwrap();
    let clip = dir.path().join("still_ball");
    std::fs::create_dir_all(&clip).unwrap();
    for i in 0..20 {
        let s = Scene {
            ball: (128.0, 100.0, 40.0),
            seed: i,
            ..Scene::default()
        };
        let img = image::GrayImage::from_raw(256, 256, render(&s)).unwrap();
        img.save(clip.join(format!("img_{i:05}.png"))).unwrap();
    }
    let out = bouncelab()
        .args(["track", clip.to_str().unwrap(), "--fps", "10000", "--diameter", "0.067"])
        .assert()
        .code(1)
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8(out).unwrap();
    let line = err
        .lines()
        .find(|l| l.contains("no moving ball"))
        .unwrap_or_else(|| panic!("{err}"));
    assert_eq!(line.matches("still_ball").count(), 1, "{line}");
}

#[test]
fn track_bad_inputs_exit_1_naming_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    bouncelab()
        .args(["track", empty.to_str().unwrap()])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("empty"));
    bouncelab()
        .args(["track", "/no/such/clip"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("/no/such/clip"));
    let clip = write_session_with_one_clip(dir.path());
    // A flag's value outside its range is a usage error, refused before anything is read.
    bouncelab()
        .args(["track", clip.to_str().unwrap(), "--fps", "-5"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--fps").and(predicate::str::contains("100–10000000 frames/s")));
}

/// The 30 frames of `write_session_with_one_clip` as an 8-bit Photron recording (`.cih` text header +
/// `.mraw`) named by its conditions, in a folder of its own.
fn write_camera_recording(root: &std::path::Path) -> std::path::PathBuf {
    let frames = write_session_with_one_clip(&root.join("pngs"));
    let mut files: Vec<_> = std::fs::read_dir(&frames).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    let mut raw = Vec::new();
    for f in &files {
        raw.extend(image::open(f).unwrap().into_luma8().into_raw());
    }
    let dir = root.join("recordings");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("clay_15deg_550mm.mraw"), raw).unwrap();
    std::fs::write(
        dir.join("clay_15deg_550mm.cih"),
        "#Camera Information Header\nRecord Rate(fps) : 10000\nShutter Speed(s) : 1/20000\nTotal Frame : 30\n\
         Start Frame : 0\nImage Width : 256\nImage Height : 256\nColor Type : Mono\nColor Bit : 8\n\
         File Format : MRaw\nEffectiveBit Depth : 8\nEffectiveBit Side : Lower\n",
    )
    .unwrap();
    dir
}

#[test]
fn track_reads_a_camera_file_and_init_writes_a_session_for_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("pngs")).unwrap();
    let rec = write_camera_recording(dir.path());
    bouncelab()
        .args(["track", rec.join("clay_15deg_550mm.cih").to_str().unwrap()])
        .assert()
        .success()
        .stderr(
            predicate::str::contains("30 frames, ball measured in 30")
                .and(predicate::str::contains("no ball diameter given"))
                .and(predicate::str::contains("frame rate").not()),
        );
    bouncelab()
        .args(["init", rec.to_str().unwrap(), "--diameter", "0.067", "--mass", "0.0567"])
        .assert()
        .success()
        .stdout(predicate::str::contains("clay_15deg_550mm.cih").and(predicate::str::contains("10000 fps")));
    let csv = std::fs::read_to_string(rec.join("clips.csv")).unwrap();
    assert!(csv.contains("clay_15deg_550mm.cih,clay,15,0.55"), "{csv}");
    let toml = std::fs::read_to_string(rec.join("session.toml")).unwrap();
    assert!(
        toml.contains("fps = 10000.0") && toml.contains("diameter_m = 0.067"),
        "{toml}"
    );
    bouncelab()
        .args(["init", rec.to_str().unwrap()])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("session.toml").and(predicate::str::contains("--force")));
    // Inside the session, the diameter comes from session.toml: no default is taken.
    bouncelab()
        .args(["track", rec.join("clay_15deg_550mm.mraw").to_str().unwrap()])
        .assert()
        .success()
        .stderr(predicate::str::contains("no ball diameter given").not());
    let video = rec.join("shot.mp4");
    std::fs::write(&video, b"x").unwrap();
    #[cfg(not(feature = "opencv"))]
    bouncelab()
        .args(["track", video.to_str().unwrap()])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("--features opencv").and(predicate::str::contains("ffmpeg")));
}
