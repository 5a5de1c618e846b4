//! `bouncelab overlay` end to end on clips of the rendered `smoke` session: the pictures written, the key
//! frames against the renderer's truth, determinism, and bad input (exit 1 naming it, never a panic).

use assert_cmd::Command;
use predicates::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn bouncelab() -> Command {
    Command::cargo_bin("bouncelab").unwrap()
}

/// The `smoke` preset (3 shots, one per surface, seed fixed by the preset) rendered once per test process.
fn smoke() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        bouncelab()
            .args(["render", "--preset", "smoke", "--out"])
            .arg(dir.path())
            .assert()
            .success();
        dir
    })
    .path()
}

/// The session's clip folders, sorted.
fn clips() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(smoke().join("session"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    v.sort();
    v
}

/// Runs `overlay` and returns its standard error.
fn overlay(clip: &Path, out: &Path, extra: &[&str]) -> String {
    let assert = bouncelab()
        .arg("overlay")
        .arg(clip)
        .arg("--out")
        .arg(out)
        .args(extra)
        .assert()
        .success();
    String::from_utf8(assert.get_output().stderr.clone()).unwrap()
}

/// The frame of each key role in the `key frames: approach 55, touch 56, …` line.
fn key_frames(stderr: &str) -> Vec<(String, u64)> {
    let line = stderr
        .lines()
        .find_map(|l| l.strip_prefix("key frames: "))
        .unwrap_or_else(|| panic!("no key frames line in:\n{stderr}"));
    let list = line.split(" (").next().unwrap();
    list.split(", ")
        .map(|item| {
            let (role, frame) = item.rsplit_once(' ').unwrap();
            (role.to_string(), frame.parse().unwrap())
        })
        .collect()
}

fn png_files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    v.sort();
    v
}

/// The touch and separation frames in the renderer's truth: first and last frame not in flight.
fn truth_contact(clip: &Path) -> (u64, u64) {
    let name = clip.file_name().unwrap().to_string_lossy();
    let text = std::fs::read_to_string(smoke().join("truth").join(format!("{name}.csv"))).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (fi, pi) = (
        header.iter().position(|h| *h == "frame").unwrap(),
        header.iter().position(|h| *h == "phase").unwrap(),
    );
    let touching: Vec<u64> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|r| r[pi] != "flight")
        .map(|r| r[fi].parse().unwrap())
        .collect();
    (touching[0], *touching.last().unwrap())
}

#[test]
fn overlay_writes_every_frame_and_a_sheet_of_the_key_frames() {
    let clip = &clips()[0];
    let out = tempfile::tempdir().unwrap();
    let err = overlay(clip, out.path(), &[]);
    let frames = std::fs::read_dir(clip)
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|x| x == "png"))
        .count();
    let files = png_files(out.path());
    assert_eq!(files.len(), frames + 1, "{err}");
    assert!(files.contains(&"sheet.png".to_string()) && files.contains(&"frame_000000.png".to_string()));
    assert!(err.contains(&format!("wrote {frames} annotated frame(s)")), "{err}");
    // A frame picture is the frame's size, in colour.
    let first = image::open(out.path().join("frame_000000.png")).unwrap().to_rgb8();
    let source = image::open(clip.read_dir().unwrap().next().unwrap().unwrap().path()).unwrap();
    assert_eq!(first.dimensions(), (source.width(), source.height()));
    assert!(first.pixels().any(|p| p.0[0] != p.0[1]), "no colour drawn");
    // The sheet: five 160 px tiles in a row, each phase's circle colour present.
    let keys = key_frames(&err);
    let roles: Vec<&str> = keys.iter().map(|(r, _)| r.as_str()).collect();
    assert_eq!(roles, ["approach", "touch", "max compression", "separation", "leave"]);
    let sheet = image::open(out.path().join("sheet.png")).unwrap().to_rgb8();
    assert_eq!(sheet.width(), 6 + 5 * (160 + 6));
    for (name, colour) in [
        ("in", [86, 180, 233]),
        ("contact", [213, 94, 0]),
        ("out", [0, 158, 115]),
    ] {
        // The legend's swatch plus the circles: many more pixels than the 7×7 swatch alone.
        let n = sheet.pixels().filter(|p| p.0 == colour).count();
        assert!(n > 49 + 20, "{name}: {n} pixels");
    }
}

#[test]
fn key_frames_fall_within_a_frame_or_two_of_the_rendered_contact() {
    for clip in clips() {
        let out = tempfile::tempdir().unwrap();
        let err = overlay(&clip, out.path(), &["--sheet"]);
        assert_eq!(png_files(out.path()), ["sheet.png"], "--sheet writes the sheet only");
        let keys = key_frames(&err);
        let at = |role: &str| keys.iter().find(|(r, _)| r == role).unwrap().1;
        let (touch, separation) = truth_contact(&clip);
        // At 10,000 fps the ball moves ~0.25 px a frame near the surface: the visible line's position
        // (±0.2 px) and the tracker's σ move the frame the ball reaches it by at most a frame or two.
        assert!(
            at("touch").abs_diff(touch) <= 2,
            "{}: touch {} vs truth {touch}",
            clip.display(),
            at("touch")
        );
        assert!(
            at("separation").abs_diff(separation) <= 2,
            "{}: separation {} vs truth {separation}",
            clip.display(),
            at("separation")
        );
        assert_eq!(at("approach") + 1, at("touch"));
        assert!(at("touch") < at("max compression") && at("max compression") < at("separation"));
    }
}

#[test]
fn every_nth_frame_plus_the_key_frames_and_the_same_bytes_twice() {
    let clip = &clips()[1];
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let err = overlay(clip, a.path(), &["--every", "40", "--levels", "stretch"]);
    overlay(clip, b.path(), &["--every", "40", "--levels", "stretch"]);
    let files = png_files(a.path());
    let keys: Vec<u64> = key_frames(&err).iter().map(|k| k.1).collect();
    for (k, f) in keys.iter().enumerate() {
        assert!(
            files.contains(&format!("frame_{f:06}.png")),
            "key frame {k} ({f}) missing: {files:?}"
        );
    }
    for f in [0, 40, 80, 120] {
        assert!(
            files.contains(&format!("frame_{f:06}.png")),
            "frame {f} missing: {files:?}"
        );
    }
    let extra = files.iter().filter(|n| n.starts_with("frame_")).count();
    assert!(extra <= 5 + 5, "{files:?}");
    for name in &files {
        assert_eq!(
            std::fs::read(a.path().join(name)).unwrap(),
            std::fs::read(b.path().join(name)).unwrap(),
            "{name} differs between two runs"
        );
    }
}

#[test]
fn bad_inputs_exit_1_naming_what_is_wrong() {
    let out = tempfile::tempdir().unwrap();
    bouncelab()
        .args(["overlay", "/no/such/clip", "--out"])
        .arg(out.path())
        .assert()
        .code(1)
        .stderr(predicate::str::contains("/no/such/clip"));
    let clip = &clips()[0];
    for (flag, value, says) in [
        ("--every", "0", "--every 0"),
        ("--zoom", "0", "--zoom 0"),
        ("--zoom", "1e9", "--zoom"),
    ] {
        bouncelab()
            .arg("overlay")
            .arg(clip)
            .args(["--out", out.path().to_str().unwrap(), flag, value])
            .assert()
            .code(1)
            .stderr(predicate::str::contains(says));
    }
    // The output folder's place is taken by a file.
    let file = out.path().join("taken");
    std::fs::write(&file, "x").unwrap();
    bouncelab()
        .arg("overlay")
        .arg(clip)
        .arg("--out")
        .arg(&file)
        .assert()
        .code(1)
        .stderr(predicate::str::contains("taken"));
    // An empty folder is not a clip.
    let empty = out.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    bouncelab()
        .arg("overlay")
        .arg(&empty)
        .assert()
        .code(1)
        .stderr(predicate::str::contains("empty"));
}
