//! The smoke session rendered once per process, copies of it, and one way to run the binary and judge it.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

pub use crate::files::copy_dir;

/// Longest any one command may take before the case counts as a hang (debug build, 2 shared cores).
pub const TIMEOUT: Duration = Duration::from_secs(180);

/// `bouncelab` with the hang guard.
pub fn bouncelab() -> assert_cmd::Command {
    let mut c = assert_cmd::Command::cargo_bin("bouncelab").unwrap();
    c.timeout(TIMEOUT);
    c
}

/// The `smoke` preset (3 shots), rendered once per test process with seed 1, as in the issue.
pub fn smoke() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        bouncelab()
            .args(["render", "--preset", "smoke", "--seed", "1", "--out"])
            .arg(dir.path())
            .assert()
            .success();
        dir
    })
    .path()
}

/// The smoke session's three clip names, in `clips.csv` order.
pub const CLIPS: [&str; 3] = [
    "S001_clay_0deg_300mm_r1",
    "S002_tape1_15deg_250mm_r1",
    "S003_tape2_22.5deg_350mm_r1",
];

/// A fresh copy of the smoke session at `root/session`.
pub fn copy_session(root: &Path) -> PathBuf {
    let to = root.join("session");
    copy_dir(&smoke().join("session"), &to);
    to
}

/// `bouncelab analyze SESSION --out OUT --store STORE --no-diagnose` (the search is not what is tested here,
/// and it is the slowest stage).
pub fn analyze(session: &Path, out: &Path, store: &Path) -> assert_cmd::Command {
    let mut c = bouncelab();
    c.arg("analyze")
        .arg(session)
        .arg("--out")
        .arg(out)
        .arg("--store")
        .arg(store)
        .arg("--no-diagnose");
    c
}

/// The files whose bytes must match an uninterrupted run (report.html carries the time it was made).
pub const COMPARED: [&str; 5] = [
    "estimates.csv",
    "comparison.csv",
    "model_predictions.csv",
    "surfaces.csv",
    "fit.json",
];

/// The names starting `.partial` (a temporary output file) in `out` and `out/trajectories`.
pub fn partial_files(out: &Path) -> Vec<String> {
    [out.to_path_buf(), out.join("trajectories")]
        .iter()
        .filter_map(|d| std::fs::read_dir(d).ok())
        .flatten()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".partial"))
        .collect()
}

/// What a run did.
pub struct Ran {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `c` and checks what every case checks: it ended (no hang, within [`TIMEOUT`]), with `code`,
/// without a panic, and its stderr names every one of `parts`.
pub fn expect(c: &mut assert_cmd::Command, code: i32, parts: &[&str]) -> Ran {
    let out = c.output().expect("the command runs");
    let ran = Ran {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    };
    assert!(
        !ran.stderr.contains("panicked") && !ran.stderr.contains("RUST_BACKTRACE"),
        "panic:\n{}",
        ran.stderr
    );
    assert_eq!(
        ran.code, code,
        "exit code (-1: killed by the timeout, a hang)\nstdout:\n{}\nstderr:\n{}",
        ran.stdout, ran.stderr
    );
    for p in parts {
        assert!(ran.stderr.contains(p), "stderr lacks `{p}`:\n{}", ran.stderr);
    }
    ran
}

/// `estimates.csv` as (clip, trajectory_file) pairs.
pub fn estimate_rows(out: &Path) -> Vec<(String, String)> {
    let mut r = csv::Reader::from_path(out.join("estimates.csv")).unwrap();
    let h = r.headers().unwrap().clone();
    let clip = h.iter().position(|c| c == "clip").unwrap();
    let file = h.iter().position(|c| c == "trajectory_file").unwrap();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            (rec[clip].to_string(), rec[file].to_string())
        })
        .collect()
}

/// The file names under `out/trajectories`, sorted.
pub fn trajectory_files(out: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(out.join("trajectories"))
        .map(|d| {
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Replaces `from` by `to` at the start of a line of the session's `clips.csv`.
pub fn rename_row(session: &Path, from: &str, to: &str) {
    let path = session.join("clips.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let text: Vec<String> = text
        .lines()
        .map(|l| match l.strip_prefix(from) {
            Some(rest) if rest.starts_with(',') => format!("{to}{rest}"),
            _ => l.to_string(),
        })
        .collect();
    std::fs::write(&path, text.join("\n") + "\n").unwrap();
}

/// The PNG frames of `clip`, in file-name order.
pub fn png_frames(clip: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(clip)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    v.sort();
    v
}

/// Renames the frames of `clip` so that the k-th in time gets number `to(k, n)` (`frame_NNNNNN.png`).
pub fn permute_frames(clip: &Path, to: impl Fn(usize, usize) -> usize) {
    let frames = png_frames(clip);
    let n = frames.len();
    for (k, f) in frames.iter().enumerate() {
        std::fs::rename(f, clip.join(format!("tmp_{:06}.png", to(k, n)))).unwrap();
    }
    for k in 0..n {
        std::fs::rename(
            clip.join(format!("tmp_{k:06}.png")),
            clip.join(format!("frame_{k:06}.png")),
        )
        .unwrap();
    }
}
