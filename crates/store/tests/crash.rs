//! Crash safety: a writer killed with SIGKILL mid-run leaves a sound database in which every committed shot is
//! complete, and re-running it resumes without duplicates.
//!
//! The writer is this test binary re-invoked on `crash_child_writer` with `BOUNCELAB_STORE_CRASH_DB` set.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

use bouncelab_store::*;
use common::*;

const ENV: &str = "BOUNCELAB_STORE_CRASH_DB";
const SHOTS: usize = 300;
const FRAMES: u64 = 40;

/// Writes `SHOTS` shots like `analyze` would: upsert, skip if done, else track and estimate, all in one
/// transaction (with a pause inside it, so that a kill often lands mid-transaction). Returns (written,
/// skipped).
fn write_shots(db: &Path, pause: Duration) -> (usize, usize) {
    let mut store = Store::open(db).unwrap();
    let sid = store.upsert_session(&session("/crash")).unwrap();
    let (mut written, mut skipped) = (0, 0);
    for i in 0..SHOTS {
        let did = store
            .transaction(|tx| {
                let up = tx.upsert_shot(sid, &shot(&format!("clip{i:04}"), "h"))?;
                if !up.needs_tracking {
                    return Ok(false);
                }
                tx.put_track(up.id, &track(FRAMES))?;
                sleep(pause);
                tx.put_estimate(up.id, &estimate(i as f64))?;
                Ok(true)
            })
            .unwrap();
        if did {
            written += 1
        } else {
            skipped += 1
        }
        sleep(pause);
    }
    (written, skipped)
}

#[test]
fn crash_child_writer() {
    let Some(db) = std::env::var_os(ENV) else { return };
    write_shots(Path::new(&db), Duration::from_millis(2));
}

fn committed(db: &Path) -> usize {
    let store = Store::open(db).unwrap();
    store.count(Table::Estimates).unwrap() as usize
}

#[test]
fn sigkill_mid_run_loses_nothing_committed_and_resumes_without_duplicates() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("results.sqlite");
    // Create the schema first so that the parent's polling never races the child's migration.
    drop(Store::open(&db).unwrap());
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args(["crash_child_writer", "--exact", "--nocapture", "--test-threads=1"])
        .env(ENV, &db)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while committed(&db) < 20 {
        assert!(start.elapsed() < Duration::from_secs(60), "the writer made no progress");
        assert!(child.try_wait().unwrap().is_none(), "the writer exited early");
        sleep(Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL on Unix
    let status = child.wait().unwrap();
    assert!(!status.success(), "the writer finished before the kill: {status}");

    let store = Store::open(&db).unwrap();
    assert!(store.integrity_check().unwrap());
    let sid = store.session_by_path("/crash").unwrap().unwrap().id;
    let shots = store.shots(sid).unwrap();
    let before = shots.len();
    assert!((20..SHOTS).contains(&before), "{before} shots after the kill");
    for s in &shots {
        assert_eq!(s.status, ShotStatus::Estimated, "half-written shot {}", s.record.clip);
        assert_eq!(
            store.track(s.id).unwrap().unwrap().rows.len() as u64,
            FRAMES,
            "{}",
            s.record.clip
        );
        assert!(store.estimate(s.id).unwrap().is_some(), "{}", s.record.clip);
    }
    assert_eq!(store.count(Table::Estimates).unwrap() as usize, before);
    assert_eq!(store.count(Table::Trajectory).unwrap(), before as u64 * FRAMES);
    drop(store);

    // Re-run: resumes where it stopped.
    let (written, skipped) = write_shots(&db, Duration::ZERO);
    assert_eq!((written, skipped), (SHOTS - before, before));
    let store = Store::open(&db).unwrap();
    assert!(store.integrity_check().unwrap());
    let shots = store.shots(sid).unwrap();
    assert_eq!(shots.len(), SHOTS);
    let mut clips: Vec<_> = shots.iter().map(|s| s.record.clip.clone()).collect();
    clips.dedup();
    assert_eq!(clips.len(), SHOTS);
    assert!(shots.iter().all(|s| s.status == ShotStatus::Estimated));
    assert_eq!(store.count(Table::Estimates).unwrap() as usize, SHOTS);
    assert_eq!(store.count(Table::Sessions).unwrap(), 1);
    // And a third run does nothing.
    drop(store);
    assert_eq!(write_shots(&db, Duration::ZERO), (0, SHOTS));
}
