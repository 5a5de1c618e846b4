//! Foreign and corrupt stores, repeated and concurrent runs on one store.

use crate::common::*;

/// A foreign SQLite file as `--store` dumped 5.6 KB of our schema (after creating tables in it); a file
/// that is no database at all: one short line naming the file, which is left as it was.
#[test]
fn foreign_and_corrupt_stores_are_refused_in_one_short_line() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let foreign = dir.path().join("birds.sqlite");
    rusqlite::Connection::open(&foreign)
        .unwrap()
        .execute_batch("CREATE TABLE sessions (x); CREATE TABLE birds (name TEXT); INSERT INTO birds VALUES ('wren');")
        .unwrap();
    let corrupt = dir.path().join("noise.sqlite");
    std::fs::write(
        &corrupt,
        (0..5000u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 11) as u8)
            .collect::<Vec<_>>(),
    )
    .unwrap();
    for (store, part) in [
        (&foreign, "not a bouncelab results store"),
        (&corrupt, "not an SQLite database"),
    ] {
        let before = std::fs::read(store).unwrap();
        let ran = expect(
            &mut analyze(&session, &dir.path().join("out"), store),
            1,
            &[&store.file_name().unwrap().to_string_lossy(), part],
        );
        assert!(ran.stderr.len() < 400, "{} bytes: {}", ran.stderr.len(), ran.stderr);
        assert!(std::fs::read(store).unwrap() == before, "{} untouched", store.display());
    }
}

/// Every run, even a killed one, appended a row to `fits` (32 rows after 31 identical runs).
#[test]
fn identical_runs_store_one_fit_row() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let (out, store) = (dir.path().join("out"), dir.path().join("s.sqlite"));
    for _ in 0..3 {
        expect(&mut analyze(&session, &out, &store), 0, &[]);
    }
    let s = bouncelab_store::Store::open(&store).unwrap();
    assert_eq!(s.fits(None).unwrap().len(), 1);
}

/// Two concurrent runs on one store both re-tracked every shot: the second waits for the first's
/// measuring lock and reuses its shots.
#[test]
fn two_concurrent_runs_track_each_shot_once() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let store = dir.path().join("s.sqlite");
    let bin = assert_cmd::cargo::cargo_bin("bouncelab");
    let spawn = |out: &str| {
        std::process::Command::new(&bin)
            .arg("analyze")
            .arg(&session)
            .arg("--out")
            .arg(dir.path().join(out))
            .arg("--store")
            .arg(&store)
            .arg("--no-diagnose")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (spawn("a"), spawn("b"));
    let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
    let measured = |o: &std::process::Output| {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8_lossy(&o.stdout).into_owned();
        let line = text.lines().find(|l| l.contains("measured now")).unwrap().to_string();
        let n: usize = line
            .split(", ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        (n, line)
    };
    let ((na, la), (nb, lb)) = (measured(&a), measured(&b));
    assert_eq!(na + nb, 3, "each shot tracked once: `{la}` / `{lb}`");
    assert_eq!(
        std::fs::read(dir.path().join("a/estimates.csv")).unwrap(),
        std::fs::read(dir.path().join("b/estimates.csv")).unwrap()
    );
}
