//! Issue 19's store cases: idempotent fit rows, foreign and corrupt files refused untouched with a short
//! message, the measuring lock between two runs.

mod common;

use bouncelab_store::*;
use common::*;

fn fit(session_id: i64, version: i64, chi2: f64) -> FitRecord {
    FitRecord {
        session_id: Some(session_id),
        model_version_id: version,
        json: format!("{{\"chi2\": {chi2}}}"),
        reduced_chi2: chi2,
        rms_m: chi2 * 1e-5,
        mae_pct: None,
    }
}

/// 31 identical runs used to leave 32 rows in `fits`: the same fit of the same input is stored once.
#[test]
fn identical_fits_are_stored_once() {
    let mut store = Store::open_in_memory().unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let v = store
        .add_model_version(&ModelVersionRecord {
            name: "paper".into(),
            toml: "[spring]\n".into(),
            parent_id: None,
        })
        .unwrap();
    let first = store.add_fit(&fit(sid, v, 2.0)).unwrap();
    for _ in 0..30 {
        assert_eq!(store.add_fit(&fit(sid, v, 2.0)).unwrap(), first);
    }
    assert_eq!(store.fits(Some(sid)).unwrap().len(), 1);
    // A different result (another input) is a new row.
    let other = store.add_fit(&fit(sid, v, 3.0)).unwrap();
    assert_ne!(other, first);
    assert_eq!(store.fits(Some(sid)).unwrap().len(), 2);
    // A fit across sessions is not the same as the session's.
    let mut all = fit(sid, v, 2.0);
    all.session_id = None;
    assert_ne!(store.add_fit(&all).unwrap(), first);
}

/// A foreign SQLite file given as the store used to get our tables half-created in it and a 5.6 KB message
/// quoting our schema: it is refused, untouched, in one short line.
#[test]
fn a_foreign_sqlite_file_is_refused_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("birds.sqlite");
    {
        let c = rusqlite::Connection::open(&path).unwrap();
        c.execute_batch(
            "CREATE TABLE sessions (x); CREATE TABLE birds (name TEXT); INSERT INTO birds VALUES ('wren');",
        )
        .unwrap();
    }
    let before = std::fs::read(&path).unwrap();
    let err = Store::open(&path).unwrap_err();
    assert!(matches!(err, StoreError::Foreign { tables: 2, .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.len() < 300, "{} bytes: {msg}", msg.len());
    assert!(
        msg.contains("birds.sqlite") && msg.contains("not a bouncelab results store"),
        "{msg}"
    );
    let c = rusqlite::Connection::open(&path).unwrap();
    let tables: i64 = c
        .query_row("SELECT COUNT(*) FROM sqlite_master WHERE type = 'table'", [], |r| {
            r.get(0)
        })
        .unwrap();
    assert_eq!(tables, 2, "no table added");
    drop(c);
    assert!(std::fs::read(&path).unwrap() == before, "file unchanged");
}

/// A file that is not a database at all: one short line naming it, the file left as it was.
#[test]
fn a_file_that_is_not_a_database_is_named_in_one_short_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("notes.sqlite");
    let bytes: Vec<u8> = (0..5000u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    std::fs::write(&path, &bytes).unwrap();
    let err = Store::open(&path).unwrap_err();
    assert!(matches!(err, StoreError::NotADatabase { .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("notes.sqlite") && msg.len() < 300, "{msg}");
    assert!(std::fs::read(&path).unwrap() == bytes, "file unchanged");
}

/// Two runs on one store: the second waits for the first's measuring lock (and is told who holds it), and
/// gets it once the first lets go.
#[test]
fn the_measuring_lock_makes_a_second_run_wait() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("results.sqlite");
    let first = Store::open(&path).unwrap();
    let held = first.lock_measuring(|_| panic!("nobody holds it yet")).unwrap();
    assert!(held.is_some());
    let (tx, rx) = std::sync::mpsc::channel();
    let second = {
        let path = path.clone();
        std::thread::spawn(move || {
            let store = Store::open(&path).unwrap();
            let waited = std::cell::Cell::new(None);
            let lock = store.lock_measuring(|holder| {
                waited.set(Some(holder));
                tx.send(holder).unwrap();
            });
            (lock.map(|l| l.is_some()), waited.get())
        })
    };
    // flock is per open file: the second run's thread sees the first's lock like another process would.
    let holder = rx
        .recv_timeout(std::time::Duration::from_secs(30))
        .expect("second run waits");
    assert_eq!(holder, Some(std::process::id()), "the holder's pid is read back");
    drop(held);
    let (got, waited) = second.join().unwrap();
    assert!(got.unwrap());
    assert!(waited.is_some());
    // In memory there is nothing to share, so no lock.
    assert!(
        Store::open_in_memory()
            .unwrap()
            .lock_measuring(|_| {})
            .unwrap()
            .is_none()
    );
}

/// Runs started together on a new store all open it: setting it up (the switch to WAL, the first migration)
/// takes the file's lock exclusively, and where two connections deadlock on it SQLite answers one "database
/// is locked" at once, without waiting (seen failing `two_concurrent_runs_track_each_shot_once`).
#[test]
fn runs_opening_a_new_store_at_once_all_open_it() {
    for round in 0..100 {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.sqlite");
        let barrier = std::sync::Barrier::new(6);
        std::thread::scope(|s| {
            let opened: Vec<_> = (0..6)
                .map(|_| {
                    s.spawn(|| {
                        barrier.wait();
                        Store::open(&path).map(|_| ())
                    })
                })
                .collect();
            for o in opened {
                if let Err(e) = o.join().unwrap() {
                    panic!("round {round}: {e}");
                }
            }
        });
    }
}
