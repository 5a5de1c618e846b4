//! SIGKILL at every stage: a run killed at any instant resumes to outputs byte-identical to an
//! uninterrupted run's, with a clean store (one row per shot, one fit row).

use crate::common::*;
use std::time::{Duration, Instant};

#[test]
fn killed_at_every_stage_it_resumes_to_identical_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let reference = dir.path().join("reference");
    let started = Instant::now();
    expect(
        &mut analyze(&session, &reference, &dir.path().join("ref.sqlite")),
        0,
        &[],
    );
    let whole = started.elapsed();
    let bin = assert_cmd::cargo::cargo_bin("bouncelab");
    // Kill points spread over one run's length: opening the store, tracking, the fit, writing.
    for (i, fraction) in [0.02, 0.15, 0.35, 0.6, 0.85].into_iter().enumerate() {
        let out = dir.path().join(format!("out{i}"));
        let store = dir.path().join(format!("s{i}.sqlite"));
        let mut child = std::process::Command::new(&bin)
            .arg("analyze")
            .arg(&session)
            .arg("--out")
            .arg(&out)
            .arg("--store")
            .arg(&store)
            .arg("--no-diagnose")
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_secs_f64(whole.as_secs_f64() * fraction));
        child.kill().ok(); // SIGKILL
        child.wait().unwrap();
        expect(&mut analyze(&session, &out, &store), 0, &[]);
        for f in COMPARED {
            assert!(
                std::fs::read(out.join(f)).unwrap() == std::fs::read(reference.join(f)).unwrap(),
                "{f} differs after a kill at {fraction} of the run"
            );
        }
        assert_eq!(trajectory_files(&out), trajectory_files(&reference));
        let s = bouncelab_store::Store::open(&store).unwrap();
        assert!(s.integrity_check().unwrap());
        let id = s.sessions().unwrap()[0].id;
        assert_eq!(s.shots(id).unwrap().len(), 3);
        assert_eq!(s.estimates(id).unwrap().len(), 3);
        assert_eq!(s.fits(None).unwrap().len(), 1, "kill at {fraction}: one fit row");
        // A temporary file the killed run left is cleared by the next.
        let leftovers = partial_files(&out);
        assert!(leftovers.is_empty(), "{leftovers:?}");
    }
}
