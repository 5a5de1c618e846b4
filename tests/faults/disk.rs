//! A full disk, made with a small tmpfs in a private mount namespace (`unshare`): under the output folder
//! and under the results store. Each run must stop with a message naming the file and the cause, leave no
//! temporary file and a store that a later run with room resumes from to outputs identical to an
//! uninterrupted run's.
//!
//! Where no mount namespace can be made (no `unshare`, no user namespaces and not root) the cases say so on
//! stderr and pass without checking: the issue asks for this case "where available"; CI runs as root.

use crate::common::*;
use std::path::Path;

/// `unshare` arguments that give this process a private mount namespace where it may mount a tmpfs
/// (probed once: a trial mount in a temporary folder, removed again).
fn namespace() -> Option<&'static [&'static str]> {
    static FOUND: std::sync::OnceLock<Option<&'static [&'static str]>> = std::sync::OnceLock::new();
    *FOUND.get_or_init(|| {
        let probe = "d=$(mktemp -d) || exit 1; mount -t tmpfs -o size=64k tmpfs \"$d\"; r=$?; umount \"$d\" 2>/dev/null; rmdir \"$d\"; exit $r";
        [&["-m"][..], &["-r", "-m"][..]].into_iter().find(|args| {
            std::process::Command::new("unshare")
                .args(*args)
                .args(["sh", "-c", probe])
                .output()
                .is_ok_and(|o| o.status.success())
        })
    })
}

/// What the two runs of [`full_then_roomy`] did.
struct TwoRuns {
    full: Ran,
    roomy_code: i32,
}

/// Mounts a tmpfs of `size` at `mount`, runs `analyze` (whose `--out` or `--store` lies on it), copies what
/// that run left to `left`, then remounts the tmpfs at 64 MiB, runs `analyze` again and copies its output
/// folder to `after`. `None` where no mount namespace can be made.
fn full_then_roomy(dir: &Path, size: &str, out: &Path, store: &Path) -> Option<TwoRuns> {
    let Some(ns) = namespace() else {
        eprintln!("full-disk case not checked: no mount namespace can be made here (`unshare -m` failed)");
        return None;
    };
    let session = copy_session(dir);
    let bin = assert_cmd::cargo::cargo_bin("bouncelab");
    let run = |n: u8| {
        format!(
            "\"$BIN\" analyze \"$SESSION\" --out \"$OUT\" --store \"$STORE\" --no-diagnose >/dev/null 2>\"$DIR/err{n}\"; echo $? >\"$DIR/code{n}\""
        )
    };
    let script = format!(
        "set -u; mount -t tmpfs -o size={size} tmpfs \"$MNT\" || exit 90\n{}\n\
         mkdir -p \"$DIR/left\"; cp -a \"$MNT/.\" \"$DIR/left/\"\n\
         mount -o remount,size=64m \"$MNT\" || exit 91\n{}\n\
         cp -a \"$OUT\" \"$DIR/after\"",
        run(1),
        run(2)
    );
    let mnt = dir.join("mnt");
    std::fs::create_dir_all(&mnt).unwrap();
    let mut c = assert_cmd::Command::new("unshare");
    c.args(ns)
        .args(["sh", "-c", &script])
        .env("BIN", bin)
        .env("SESSION", &session)
        .env("OUT", out)
        .env("STORE", store)
        .env("MNT", &mnt)
        .env("DIR", dir)
        .timeout(TIMEOUT * 2);
    let ran = c.output().expect("unshare runs");
    assert!(ran.status.success(), "the namespace script failed: {ran:?}");
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
    let code = |f: &str| read(f).trim().parse::<i32>().unwrap();
    Some(TwoRuns {
        full: Ran {
            code: code("code1"),
            stdout: String::new(),
            stderr: read("err1"),
        },
        roomy_code: code("code2"),
    })
}

/// The reference: an uninterrupted run with room, in `dir/reference`.
fn reference(dir: &Path) -> std::path::PathBuf {
    let session = copy_session(&dir.join("ref"));
    let out = dir.join("reference");
    expect(&mut analyze(&session, &out, &dir.join("ref.sqlite")), 0, &[]);
    out
}

fn assert_same_outputs(after: &Path, reference: &Path) {
    for f in COMPARED {
        assert!(
            std::fs::read(after.join(f)).unwrap() == std::fs::read(reference.join(f)).unwrap(),
            "{f} differs from an uninterrupted run's after the disk had room again"
        );
    }
    assert_eq!(trajectory_files(after), trajectory_files(reference));
}

fn assert_clean_failure(full: &Ran, names: &str, cause: &str) {
    assert!(!full.stderr.contains("panicked"), "panic:\n{}", full.stderr);
    assert_eq!(full.code, 1, "exit code of the run on a full disk:\n{}", full.stderr);
    assert!(full.stderr.contains(names), "stderr lacks `{names}`:\n{}", full.stderr);
    assert_eq!(
        full.stderr.matches(cause).count(),
        1,
        "the cause `{cause}` once:\n{}",
        full.stderr
    );
}

/// The output folder fills up (40 KiB: within the trajectories; 200 KiB: at the report).
#[test]
fn a_full_output_disk_is_a_clean_error_and_a_later_run_completes_it() {
    let dir = tempfile::tempdir().unwrap();
    let reference = reference(dir.path());
    for size in ["40k", "200k"] {
        let case = dir.path().join(size);
        std::fs::create_dir_all(&case).unwrap();
        let out = case.join("mnt").join("out");
        let Some(runs) = full_then_roomy(&case, size, &out, &case.join("s.sqlite")) else {
            return;
        };
        assert_clean_failure(&runs.full, "mnt/out/", "No space left on device");
        let left = partial_files(&case.join("left").join("out"));
        assert!(
            left.is_empty(),
            "{size}: temporary files left on the full disk: {left:?}"
        );
        assert_eq!(runs.roomy_code, 0, "{size}: the run after space was freed");
        assert_same_outputs(&case.join("after"), &reference);
    }
}

/// The results store's disk fills up while the shots are written.
#[test]
fn a_full_store_disk_is_a_clean_error_and_a_later_run_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let reference = reference(dir.path());
    let out = dir.path().join("out");
    let store = dir.path().join("mnt").join("s.sqlite");
    let Some(runs) = full_then_roomy(dir.path(), "100k", &out, &store) else {
        return;
    };
    assert_clean_failure(&runs.full, "mnt/s.sqlite: the disk is full", "disk is full");
    assert!(runs.full.stderr.len() < 400, "{}", runs.full.stderr);
    assert_eq!(runs.roomy_code, 0, "the run after space was freed");
    assert_same_outputs(&dir.path().join("after"), &reference);
}
