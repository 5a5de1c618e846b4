//! The trajectory table holds the tracker's own row: every column goes in and comes back bit for bit, and a
//! status this build does not know is refused with the shot and the frame named.

mod common;

use bouncelab_store::{Store, StoreError, Table};
use common::*;
use proptest::prelude::*;

/// The numbers a tracker can write: any double (NaN is "not measured"), with the awkward ones drawn often.
fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>(),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(-0.0),
        -1e4..1e4f64
    ]
}

prop_compose! {
    fn any_row()(
        frame in 0..=(i64::MAX as usize),
        v in proptest::collection::vec(any_f64(), 9),
        status in proptest::sample::select(Status::ALL.to_vec()),
    ) -> TrajectoryRow {
        TrajectoryRow {
            fix: BallFix {
                frame, t_s: v[0], x_px: v[1], y_px: v[2], r_px: v[3], sigma_px: v[4], sigma_r_px: v[8],
                quality: v[5], status,
            },
            x_m: v[6],
            y_m: v[7],
        }
    }
}

/// Every column compared by its bits, so NaN (the tracker's "not measured") must survive too; only a zero's
/// sign is not kept (SQLite stores an integral REAL as an integer, so −0 comes back as 0).
fn column_bits(r: &TrajectoryRow) -> (usize, Status, [u64; 8]) {
    let f = &r.fix;
    let numbers = [f.t_s, f.x_px, f.y_px, f.r_px, f.sigma_px, f.quality, r.x_m, r.y_m];
    (
        f.frame,
        f.status,
        numbers.map(|x| if x == 0.0 { 0 } else { x.to_bits() }),
    )
}

/// A store with one session and one shot (clip `S007`), and that shot's id.
fn one_shot() -> (Store, i64) {
    let mut store = Store::open_in_memory().unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let id = store.upsert_shot(sid, &shot("S007", "h")).unwrap().id;
    (store, id)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Stored and read back, every trajectory column of every row survives bit for bit (frames up to the
    /// largest SQLite integer, NaN, infinities; −0 as 0); the radius σ, not a column, comes back NaN.
    #[test]
    fn a_trajectory_survives_the_store(rows in proptest::collection::vec(any_row(), 1..8)) {
        let mut rows = rows;
        rows.sort_by_key(|r| r.fix.frame);
        rows.dedup_by_key(|r| r.fix.frame);
        let (mut store, id) = one_shot();
        let mut t = track(0);
        t.rows = rows.clone();
        store.put_track(id, &t).unwrap();
        let back = store.track(id).unwrap().unwrap().rows;
        prop_assert_eq!(back.len(), rows.len());
        for (a, b) in rows.iter().zip(&back) {
            prop_assert_eq!(column_bits(a), column_bits(b), "{:?} -> {:?}", a, b);
            prop_assert!(b.fix.sigma_r_px.is_nan());
        }
    }
}

/// What the comparison above forgives, shown: a negative zero is read back as a positive one.
#[test]
fn a_negative_zero_comes_back_as_zero() {
    let (mut store, id) = one_shot();
    let mut t = track(1);
    t.rows[0].x_m = -0.0;
    store.put_track(id, &t).unwrap();
    let x = store.track(id).unwrap().unwrap().rows[0].x_m;
    assert_eq!(x.to_bits(), 0.0f64.to_bits());
}

#[test]
fn the_trajectory_table_has_the_trajectory_columns() {
    let columns = Table::Trajectory.columns();
    assert_eq!(columns[0], "shot_id");
    assert_eq!(&columns[1..], &bouncelab_track::TRAJECTORY_COLUMNS[..]);
}

#[test]
fn an_unknown_stored_status_names_the_shot_and_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.sqlite");
    let mut store = Store::open(&path).unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let id = store.upsert_shot(sid, &shot("S007", "h")).unwrap().id;
    let mut t = track(3);
    t.rows[1].fix.frame = 41;
    t.rows[2].fix.frame = 42;
    store.put_track(id, &t).unwrap();
    drop(store);
    // A status only a newer build (or a hand edit) writes: the store must refuse it, not skip the frame.
    let conn = rusqlite::Connection::open(&path).unwrap();
    conn.execute("UPDATE trajectory SET status = 'lost' WHERE frame = 41", [])
        .unwrap();
    drop(conn);
    let store = Store::open(&path).unwrap();
    let e = store.track(id).unwrap_err();
    assert!(
        matches!(e, StoreError::UnknownStatus { shot_id, frame: 41, .. } if shot_id == id),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(
        e.contains("S007") && e.contains("frame 41") && e.contains("`lost`"),
        "{e}"
    );
}
