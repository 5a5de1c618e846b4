//! Round trips of every record, the incremental logic, errors naming their table, CSV export.

mod common;

use bouncelab_store::*;
use common::*;

#[test]
fn open_creates_schema_in_wal_mode() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("results.sqlite");
    let store = Store::open(&path).unwrap();
    assert_eq!(store.schema_version().unwrap(), latest_version());
    assert!(store.integrity_check().unwrap());
    drop(store);
    // Reopening does not migrate again.
    let store = Store::open(&path).unwrap();
    assert_eq!(store.count(Table::SchemaVersion).unwrap(), MIGRATIONS.len() as u64);
    assert!(path.with_extension("sqlite-wal").exists() || path.exists());
}

#[test]
fn schema_too_new_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("results.sqlite");
    let mut store = Store::open(&path).unwrap();
    store.transaction(|_| Ok(())).unwrap();
    drop(store);
    {
        let conn = rusqlite::Connection::open(&path).unwrap();
        conn.execute(
            "INSERT INTO schema_version (version, description) VALUES (999, 'future')",
            [],
        )
        .unwrap();
    }
    let err = Store::open(&path).unwrap_err();
    assert!(matches!(err, StoreError::SchemaTooNew { found: 999, .. }), "{err}");
    assert!(err.to_string().contains("schema_version"), "{err}");
}

#[test]
fn session_round_trip_and_upsert() {
    let mut store = Store::open_in_memory().unwrap();
    let rec = session("/data/s1");
    let id = store.upsert_session(&rec).unwrap();
    let mut changed = rec.clone();
    changed.settings_hash = "s2".into();
    assert_eq!(store.upsert_session(&changed).unwrap(), id);
    let rows = store.sessions().unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].record, changed);
    assert_eq!(store.session_by_path("/data/s1").unwrap().unwrap().id, id);
    assert!(store.session_by_path("/nope").unwrap().is_none());
    let other = store.upsert_session(&session("/data/s2")).unwrap();
    assert_ne!(other, id);
}

#[test]
fn shot_track_estimate_round_trip() {
    let mut store = Store::open_in_memory().unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let rec = shot("c01", "h1");
    let up = store.upsert_shot(sid, &rec).unwrap();
    assert!(up.inserted && up.needs_tracking);
    let t = track(12);
    let e = estimate(0.0);
    store
        .transaction(|tx| {
            tx.put_track(up.id, &t)?;
            tx.put_estimate(up.id, &e)
        })
        .unwrap();
    let row = store.shot(sid, "c01").unwrap().unwrap();
    assert_eq!(row.record, rec);
    assert_eq!(row.status, ShotStatus::Estimated);
    assert_eq!(store.track(up.id).unwrap().unwrap(), t);
    assert_eq!(store.estimate(up.id).unwrap().unwrap(), e);
    let joined = store.estimates(sid).unwrap();
    assert_eq!(joined.len(), 1);
    assert_eq!((joined[0].clip.as_str(), joined[0].surface.as_str()), ("c01", "clay"));
    assert_eq!((joined[0].angle_deg, joined[0].drop_height_m), (20.0, 0.25));
    assert_eq!(joined[0].estimate, e);
    // Replace.
    let e2 = estimate(1.0);
    store.put_estimate(up.id, &e2).unwrap();
    assert_eq!(store.estimate(up.id).unwrap().unwrap(), e2);
    assert_eq!(store.count(Table::Estimates).unwrap(), 1);
    // A new track drops the old estimate.
    store.put_track(up.id, &track(5)).unwrap();
    assert_eq!(store.track(up.id).unwrap().unwrap().rows.len(), 5);
    assert!(store.estimate(up.id).unwrap().is_none());
    assert_eq!(store.shot(sid, "c01").unwrap().unwrap().status, ShotStatus::Tracked);
    assert_eq!(store.count(Table::Trajectory).unwrap(), 5);
}

#[test]
fn nan_is_stored_as_null_and_read_back_as_nan() {
    let mut store = Store::open_in_memory().unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let id = store.upsert_shot(sid, &shot("c", "h")).unwrap().id;
    let mut t = track(3);
    t.rows[1].x_m = f64::NAN;
    t.rows[1].y_m = f64::NAN;
    store.put_track(id, &t).unwrap();
    let back = store.track(id).unwrap().unwrap();
    assert!(back.rows[1].x_m.is_nan() && back.rows[1].y_m.is_nan());
    assert_eq!(back.rows[0], t.rows[0]);
    let mut e = estimate(0.0);
    e.mu = ValueSe::new(f64::NAN, f64::NAN);
    store.put_estimate(id, &e).unwrap();
    let back = store.estimate(id).unwrap().unwrap();
    assert!(back.mu.value.is_nan() && back.mu.se.is_nan());
    assert_eq!(back.cor, e.cor);
}

#[test]
fn incremental_same_fingerprint_needs_nothing_changed_needs_tracking() {
    let mut store = Store::open_in_memory().unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let id = store.upsert_shot(sid, &shot("c", "h1")).unwrap().id;
    // Stored but never finished: still needed (resume).
    let up = store.upsert_shot(sid, &shot("c", "h1")).unwrap();
    assert!(!up.inserted && !up.frames_changed && up.needs_tracking);
    store
        .transaction(|tx| {
            tx.put_track(id, &track(4))?;
            tx.put_estimate(id, &estimate(0.0))
        })
        .unwrap();
    let up = store.upsert_shot(sid, &shot("c", "h1")).unwrap();
    assert_eq!(
        up,
        ShotUpsert {
            id,
            inserted: false,
            frames_changed: false,
            needs_tracking: false
        }
    );
    // Metadata and drop height change in place without re-tracking.
    let mut meta = shot("c", "h1");
    meta.drop_height_m = 0.3;
    meta.metadata.insert("note".into(), "re-measured".into());
    let up = store.upsert_shot(sid, &meta).unwrap();
    assert!(!up.needs_tracking);
    assert_eq!(store.shot(sid, "c").unwrap().unwrap().record, meta);
    assert!(store.estimate(id).unwrap().is_some());
    // Changed frames: needed, and the stale results are gone.
    let up = store.upsert_shot(sid, &shot("c", "h2")).unwrap();
    assert_eq!(
        up,
        ShotUpsert {
            id,
            inserted: false,
            frames_changed: true,
            needs_tracking: true
        }
    );
    assert!(store.track(id).unwrap().is_none());
    assert!(store.estimate(id).unwrap().is_none());
    assert_eq!(store.count(Table::Trajectory).unwrap(), 0);
    assert_eq!(store.shot(sid, "c").unwrap().unwrap().status, ShotStatus::Pending);
    // fps counts as a setting.
    store
        .transaction(|tx| {
            tx.put_track(id, &track(2))
                .and_then(|_| tx.put_estimate(id, &estimate(0.0)))
        })
        .unwrap();
    let mut fps = shot("c", "h2");
    fps.fps = 5_000.0;
    assert!(store.upsert_shot(sid, &fps).unwrap().frames_changed);
    // Failed shots are tried again.
    store.mark_failed(id, "no ball in view").unwrap();
    let row = store.shot(sid, "c").unwrap().unwrap();
    assert_eq!(
        (row.status, row.error.as_deref()),
        (ShotStatus::Failed, Some("no ball in view"))
    );
    assert!(store.upsert_shot(sid, &fps).unwrap().needs_tracking);
    // One shot per (session, clip).
    assert_eq!(store.shots(sid).unwrap().len(), 1);
}

#[test]
fn a_failed_transaction_leaves_nothing() {
    let mut store = Store::open_in_memory().unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let err = store
        .transaction(|tx| {
            let id = tx.upsert_shot(sid, &shot("c", "h"))?.id;
            tx.put_track(id, &track(3))?;
            let mut bad = track(3);
            bad.rows[2].fix.frame = 1; // duplicate frame
            tx.put_track(id, &bad)
        })
        .unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::Sql {
                table: "trajectory",
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("trajectory"), "{err}");
    assert_eq!(store.count(Table::Shots).unwrap(), 0);
    assert_eq!(store.count(Table::Trajectory).unwrap(), 0);
}

#[test]
fn model_versions_and_fits() {
    let mut store = Store::open_in_memory().unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let base = ModelVersionRecord {
        name: "model.toml".into(),
        toml: "[spring]\n".into(),
        parent_id: None,
    };
    let v1 = store.add_model_version(&base).unwrap();
    assert_eq!(
        store.add_model_version(&base).unwrap(),
        v1,
        "identical version stored once"
    );
    let next = ModelVersionRecord {
        name: "model.toml".into(),
        toml: "[spring]\n[hunt_crossley]\n".into(),
        parent_id: Some(v1),
    };
    let v2 = store.add_model_version(&next).unwrap();
    let fit = |v: i64, chi2: f64, mae: Option<f64>| FitRecord {
        session_id: Some(sid),
        model_version_id: v,
        json: format!("{{\"chi2\": {chi2}}}"),
        reduced_chi2: chi2,
        rms_m: chi2 * 1e-5,
        mae_pct: mae,
    };
    let f1 = store.add_fit(&fit(v1, 9.0, Some(6.5))).unwrap();
    let f2 = store.add_fit(&fit(v1, 8.0, Some(6.0))).unwrap();
    let f3 = store.add_fit(&fit(v2, 1.1, None)).unwrap();
    assert!(f1 < f2 && f2 < f3);
    let versions = store.model_versions().unwrap();
    assert_eq!(versions.iter().map(|v| &v.record).collect::<Vec<_>>(), [&base, &next]);
    let latest = store.latest_fit(sid).unwrap().unwrap();
    assert_eq!((latest.id, &latest.record), (f3, &fit(v2, 1.1, None)));
    assert_eq!(store.fits(Some(sid)).unwrap().len(), 3);
    let history = store.model_history(Some(sid)).unwrap();
    assert_eq!(history.len(), 2);
    assert_eq!((history[0].version.id, history[0].fits), (v1, 2));
    let l0 = history[0].latest.as_ref().unwrap();
    assert_eq!((l0.id, l0.record.reduced_chi2, l0.record.mae_pct), (f2, 8.0, Some(6.0)));
    assert_eq!(history[1].latest.as_ref().unwrap().record.reduced_chi2, 1.1);
    // A fit across sessions.
    let mut all = fit(v2, 1.0, None);
    all.session_id = None;
    store.add_fit(&all).unwrap();
    assert_eq!(store.fits(None).unwrap().len(), 4);
    assert_eq!(store.latest_fit(sid).unwrap().unwrap().id, f3);
}

#[test]
fn errors_name_the_table_and_field() {
    let mut store = Store::open_in_memory().unwrap();
    let err = store.upsert_shot(42, &shot("c", "h")).unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::NotFound {
                table: "sessions",
                id: 42,
                ..
            }
        ),
        "{err}"
    );
    assert_eq!(err.to_string(), ":memory:: table `sessions`: no row with id 42");
    let sid = store.upsert_session(&session("/s")).unwrap();
    let err = store.upsert_shot(sid, &shot("c", "")).unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::Field {
                table: "shots",
                field: "frames_hash",
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("`frames_hash`"), "{err}");
    let err = store.put_estimate(7, &estimate(0.0)).unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::NotFound {
                table: "shots",
                id: 7,
                ..
            }
        ),
        "{err}"
    );
    let id = store.upsert_shot(sid, &shot("c", "h")).unwrap().id;
    let mut bad = track(3);
    bad.measured = 4;
    let err = store.put_track(id, &bad).unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::Field {
                table: "tracks",
                field: "measured",
                ..
            }
        ),
        "{err}"
    );
    let v = store
        .add_model_version(&ModelVersionRecord {
            name: "m".into(),
            toml: String::new(),
            parent_id: None,
        })
        .unwrap();
    let err = store
        .add_fit(&FitRecord {
            session_id: Some(sid),
            model_version_id: v,
            json: "{not json".into(),
            reduced_chi2: 1.0,
            rms_m: 0.0,
            mae_pct: None,
        })
        .unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::Field {
                table: "fits",
                field: "json",
                ..
            }
        ),
        "{err}"
    );
    let err = "shotz".parse::<Table>().unwrap_err();
    assert!(
        err.to_string().contains("`shotz`") && err.to_string().contains("estimates"),
        "{err}"
    );
    let err = store.mark_failed(999, "x").unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::NotFound {
                table: "shots",
                id: 999,
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn open_error_names_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no/such/dir/results.sqlite");
    let err = Store::open(&path).unwrap_err();
    assert!(matches!(err, StoreError::Open { .. }), "{err}");
    assert!(err.to_string().contains("no/such/dir/results.sqlite"), "{err}");
}

/// CSV headers of every table, compared with `tests/data/csv_headers.txt` (refresh: `BOUNCELAB_BLESS=1`).
#[test]
fn csv_export_headers_are_stable() {
    let mut store = Store::open_in_memory().unwrap();
    let sid = store.upsert_session(&session("/s")).unwrap();
    let id = store.upsert_shot(sid, &shot("c,1", "h")).unwrap().id;
    store.put_track(id, &track(3)).unwrap();
    store.put_estimate(id, &estimate(0.0)).unwrap();
    let mut actual = String::new();
    for table in Table::ALL {
        let mut buf = Vec::new();
        let n = store.export_csv(table, &mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let header = text.lines().next().unwrap();
        assert_eq!(header, table.columns().join(","));
        let records = csv::Reader::from_reader(text.as_bytes()).records().count() as u64;
        assert_eq!(records, n, "{table}");
        actual.push_str(&format!("{table}: {header}\n"));
    }
    let golden = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/csv_headers.txt");
    if std::env::var_os("BOUNCELAB_BLESS").is_some() {
        std::fs::write(&golden, &actual).unwrap();
    }
    let expected = std::fs::read_to_string(&golden).unwrap_or_default();
    assert_eq!(
        actual, expected,
        "\nexpected:\n{expected}\nactual:\n{actual}\n(refresh with BOUNCELAB_BLESS=1)"
    );

    // Values: quoting, NULL as empty, JSON text.
    let mut buf = Vec::new();
    store.export_csv(Table::Shots, &mut buf).unwrap();
    let mut rdr = csv::Reader::from_reader(buf.as_slice());
    let rec = rdr.records().next().unwrap().unwrap();
    assert_eq!(&rec[2], "c,1");
    assert_eq!(&rec[7], r#"{"operator":"ana"}"#);
    assert_eq!(&rec[10], "");
    let mut buf = Vec::new();
    store.export_csv(Table::Trajectory, &mut buf).unwrap();
    let text = String::from_utf8(buf).unwrap();
    assert_eq!(
        text.lines().nth(2).unwrap(),
        format!("{id},1,0.0001,101,199.5,134,0.05,0.9,ok,0.001,0.03")
    );

    let dir = tempfile::tempdir().unwrap();
    let files = store.export_all_csv(dir.path().join("csv")).unwrap();
    assert_eq!(files.len(), Table::ALL.len());
    for (f, t) in files.iter().zip(Table::ALL) {
        assert_eq!(f.file_name().unwrap().to_str().unwrap(), format!("{t}.csv"));
        assert!(std::fs::read_to_string(f).unwrap().starts_with(t.columns()[0]));
    }
}

#[test]
fn clip_fingerprint_follows_frames_and_settings() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("0001.pgm"), b"P5 1 1 255 a").unwrap();
    std::fs::write(dir.path().join("0002.pgm"), b"P5 1 1 255 b").unwrap();
    for mode in [ClipFingerprint::Metadata, ClipFingerprint::Content] {
        let a = fingerprint_clip_dir(dir.path(), "fps=10000", mode).unwrap();
        assert_eq!(a, fingerprint_clip_dir(dir.path(), "fps=10000", mode).unwrap());
        assert_ne!(a, fingerprint_clip_dir(dir.path(), "fps=5000", mode).unwrap());
    }
    let before = fingerprint_clip_dir(dir.path(), "", ClipFingerprint::Content).unwrap();
    std::fs::write(dir.path().join("0002.pgm"), b"P5 1 1 255 c").unwrap();
    assert_ne!(
        before,
        fingerprint_clip_dir(dir.path(), "", ClipFingerprint::Content).unwrap()
    );
    let meta = fingerprint_clip_dir(dir.path(), "", ClipFingerprint::Metadata).unwrap();
    std::fs::write(dir.path().join("0003.pgm"), b"P5 1 1 255 d").unwrap();
    assert_ne!(
        meta,
        fingerprint_clip_dir(dir.path(), "", ClipFingerprint::Metadata).unwrap()
    );
    let err = fingerprint_clip_dir(&dir.path().join("missing"), "", ClipFingerprint::Metadata).unwrap_err();
    assert!(err.to_string().contains("missing"), "{err}");
}

#[test]
fn a_version_3_store_migrates_its_estimates_to_the_csv_names_and_millimetres() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.sqlite");
    {
        // The store as version 3 left it: migrations 1–3 and one estimate in metres.
        let conn = rusqlite::Connection::open(&path).unwrap();
        conn.execute_batch(
            "CREATE TABLE schema_version (version INTEGER PRIMARY KEY, description TEXT NOT NULL,
             applied_at TEXT NOT NULL DEFAULT 'then')",
        )
        .unwrap();
        for m in &MIGRATIONS[..3] {
            conn.execute_batch(m.sql).unwrap();
            conn.execute(
                "INSERT INTO schema_version (version, description) VALUES (?1, ?2)",
                rusqlite::params![m.version, m.description],
            )
            .unwrap();
        }
        conn.execute_batch(
            "INSERT INTO sessions (path, settings_hash, session_toml) VALUES ('/s', 'h', '');
             INSERT INTO shots (session_id, clip, surface, angle_deg, drop_height_m, fps, metadata, frames_hash, status)
                 VALUES (1, 'c1', 'steel', 0, 0.5, 10000, '{}', 'f', 'estimated');
             INSERT INTO estimates (shot_id, v_in_t, v_in_t_se, v_in_n, v_in_n_se, v_out_t, v_out_t_se, v_out_n,
                 v_out_n_se, cor, cor_se, mu, mu_se, contact_ms, contact_ms_se, spin_in, spin_in_se, spin_out,
                 spin_out_se, delta_max_m, delta_max_m_se, notes)
                 VALUES (1, 0.1, 0.01, -2.0, 0.02, 0.3, 0.03, 1.5, 0.04, 0.75, 0.005, 0.2, 0.01, 4.5, 0.1, NULL,
                 NULL, -12.0, 0.5, 0.00125, 0.00005, '[]');",
        )
        .unwrap();
    }
    let store = Store::open(&path).unwrap();
    assert_eq!(store.schema_version().unwrap(), latest_version());
    let e = store.estimate(1).unwrap().unwrap();
    assert_eq!((e.v_in_n.value, e.mu.se, e.contact_ms.value), (-2.0, 0.01, 4.5));
    assert_eq!(e.delta_max_mm, ValueSe::new(0.00125 * 1e3, 0.00005 * 1e3));
    assert_eq!((e.spin_in, e.spin_out), (None, Some(ValueSe::new(-12.0, 0.5))));
    // The export's header is the one column list, and it names what the table holds.
    let mut csv = Vec::new();
    store.export_csv(Table::Estimates, &mut csv).unwrap();
    let header = String::from_utf8(csv).unwrap().lines().next().unwrap().to_string();
    let quantities: Vec<&str> = ESTIMATE_QUANTITIES.iter().flatten().copied().collect();
    assert_eq!(
        header,
        format!("shot_id,{},notes,created_at,detail", quantities.join(","))
    );
}
