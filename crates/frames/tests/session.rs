//! Loading session folders: session.toml, clips.csv, clip.toml overrides and their errors (SPEC §2.7, §6).

use bouncelab_frames::testutil::{ClipSpec, SESSION_TOML, write_session};
use bouncelab_frames::{Downslope, FpsSource, FramesError, Session, Warning};

const CSV: &str = "clip,surface,angle_deg,drop_height_m\nshot_01,clay,0,1.2\nshot_02,tape,20,0.8\n";

fn session_with(toml: &str, csv: &str, clips: &[&str]) -> (tempfile::TempDir, Result<Session, FramesError>) {
    let tmp = tempfile::tempdir().unwrap();
    write_session(tmp.path(), toml, csv, clips);
    let s = Session::load(tmp.path());
    (tmp, s)
}

fn assert_names(err: &FramesError, parts: &[&str]) {
    let msg = err.to_string();
    for p in parts {
        assert!(msg.contains(p), "`{msg}` should contain `{p}`");
    }
}

#[test]
fn a_full_session_loads_with_metadata_and_overrides() {
    let toml = "[session]\ndescription = \"clay vs tape\"\n[ball]\ndiameter_m = 0.067\nmass_kg = 0.0567\n\
                [camera]\nfps = 10000\nexposure_us = 20\ndownslope = \"-x\"\n[lighting]\nlamps = 2\n";
    let csv =
        " drop_height_m , notes, clip ,surface, angle_deg\n 1.2 , first ,shot_01, clay , 0\n0.8,,shot_02,tape,20\n";
    let tmp = tempfile::tempdir().unwrap();
    write_session(tmp.path(), toml, csv, &["shot_01", "shot_02"]);
    std::fs::write(
        tmp.path().join("shot_02/clip.toml"),
        "[camera]\nfps = 5000\ndownslope = \"+x\"\n",
    )
    .unwrap();
    let s = Session::load(tmp.path()).unwrap();
    assert_eq!((s.ball.diameter_m, s.ball.mass_kg), (0.067, 0.0567));
    assert_eq!((s.fps, s.downslope), (Some(10_000.0), Downslope::MinusX));
    assert_eq!(s.metadata["session"]["description"].as_str(), Some("clay vs tape"));
    assert_eq!(s.metadata["camera"]["exposure_us"].as_integer(), Some(20));
    assert!(s.warnings.is_empty());
    let [a, b] = &s.clips[..] else { panic!("two clips") };
    assert_eq!(
        (a.name.as_str(), a.surface.as_str(), a.angle_deg, a.drop_height_m),
        ("shot_01", "clay", 0.0, 1.2)
    );
    assert_eq!(a.metadata, vec![("notes".to_string(), "first".to_string())]);
    assert_eq!((a.fps, a.downslope, a.line), (10_000.0, Downslope::MinusX, 2));
    assert!(matches!(a.fps_source, FpsSource::SessionToml(_)));
    assert_eq!((b.fps, b.downslope, b.angle_deg), (5000.0, Downslope::PlusX, 20.0));
    assert!(matches!(b.fps_source, FpsSource::ClipToml(_)));
    let clip = b.open().unwrap();
    assert_eq!((clip.fps(), clip.len()), (5000.0, 2));
    assert!(s.clip("shot_02").is_some() && s.clip("nope").is_none());
}

#[test]
fn no_fps_anywhere_means_default_with_a_warning() {
    let (_t, s) = session_with(
        "[ball]\ndiameter_m = 0.067\nmass_kg = 0.0567\n",
        CSV,
        &["shot_01", "shot_02"],
    );
    let s = s.unwrap();
    assert_eq!(s.clips[0].fps, 10_000.0);
    assert_eq!(s.warnings.len(), 2);
    assert!(matches!(&s.warnings[0], Warning::DefaultFps { clip, .. } if clip.ends_with("shot_01")));
}

#[test]
fn missing_files_are_errors_naming_them() {
    let tmp = tempfile::tempdir().unwrap();
    let err = Session::load(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::MissingFile { .. }));
    assert_names(&err, &["session.toml"]);
    std::fs::write(tmp.path().join("session.toml"), SESSION_TOML).unwrap();
    let err = Session::load(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::MissingFile { .. }));
    assert_names(&err, &["clips.csv"]);
}

#[test]
fn malformed_toml_gives_the_parsers_line() {
    let (_t, s) = session_with(
        "[ball]\ndiameter_m = 0.067\nmass_kg = = 3\n",
        CSV,
        &["shot_01", "shot_02"],
    );
    let err = s.unwrap_err();
    assert!(matches!(err, FramesError::Toml { .. }), "{err:?}");
    assert_names(&err, &["session.toml", "line 3"]);
}

#[test]
fn missing_and_wrong_keys_are_named() {
    let cases = [
        ("[ball]\nmass_kg = 0.0567\n", "[ball] diameter_m missing"),
        ("[ball]\ndiameter_m = 0.067\n", "[ball] mass_kg missing"),
        ("[camera]\nfps = 1000\n", "[ball] diameter_m missing"),
        ("[ball]\ndiameter_m = \"big\"\nmass_kg = 0.0567\n", "[ball] diameter_m"),
        ("[ball]\ndiameter_m = -1\nmass_kg = 0.0567\n", "[ball] diameter_m"),
        ("ball = 3\n", "[ball] diameter_m missing"),
    ];
    for (toml, expect) in cases {
        let (_t, s) = session_with(toml, CSV, &["shot_01", "shot_02"]);
        let err = s.unwrap_err();
        assert!(
            matches!(err, FramesError::MissingKey { .. } | FramesError::BadValue { .. }),
            "{err:?}"
        );
        assert_names(&err, &["session.toml", expect]);
    }
    let (_t, s) = session_with(&SESSION_TOML.replace("10000", "-5"), CSV, &["shot_01", "shot_02"]);
    let err = s.unwrap_err();
    assert!(matches!(err, FramesError::BadFps { .. }));
    assert_names(&err, &["session.toml", "[camera] fps"]);
}

#[test]
fn csv_problems_name_line_and_column() {
    let clips = ["shot_01", "shot_02"];
    let (_t, s) = session_with(SESSION_TOML, "clip,surface,drop_height_m\nshot_01,clay,1\n", &clips);
    let err = s.unwrap_err();
    assert!(matches!(err, FramesError::MissingColumn { .. }));
    assert_names(&err, &["clips.csv", "angle_deg"]);

    let (_t, s) = session_with(
        SESSION_TOML,
        "clip,surface,angle_deg,drop_height_m\nshot_01,clay,0,1\nshot_02,tape,steep,1\n",
        &clips,
    );
    let err = s.unwrap_err();
    assert!(matches!(err, FramesError::BadNumber { line: 3, .. }), "{err:?}");
    assert_names(&err, &["clips.csv", "line 3", "angle_deg", "steep"]);

    let (_t, s) = session_with(
        SESSION_TOML,
        "clip,surface,angle_deg,drop_height_m\nshot_01,clay,0,\n",
        &clips,
    );
    assert_names(&s.unwrap_err(), &["line 2", "drop_height_m"]);

    let (_t, s) = session_with(
        SESSION_TOML,
        "clip,surface,angle_deg,drop_height_m\nshot_01,clay,0,1\nshot_02,tape,0\n",
        &clips,
    );
    let err = s.unwrap_err();
    assert!(matches!(err, FramesError::Csv { line: Some(3), .. }), "{err:?}");
    assert_names(&err, &["clips.csv", "line 3"]);

    let (_t, s) = session_with(
        SESSION_TOML,
        "clip,surface,angle_deg,drop_height_m\nshot_01,clay,0,1\n shot_01 ,tape,0,1\n",
        &clips,
    );
    let err = s.unwrap_err();
    assert!(
        matches!(
            err,
            FramesError::DuplicateClip {
                first_line: 2,
                second_line: 3,
                ..
            }
        ),
        "{err:?}"
    );
    assert_names(&err, &["shot_01"]);

    let (_t, s) = session_with(SESSION_TOML, "", &clips);
    assert!(matches!(s.unwrap_err(), FramesError::MissingColumn { .. }));
}

#[test]
fn a_clip_listed_but_absent_is_named_with_its_expected_path() {
    let (tmp, s) = session_with(SESSION_TOML, CSV, &["shot_01"]);
    let err = s.unwrap_err();
    assert!(matches!(err, FramesError::ClipAbsent { .. }));
    assert_names(&err, &["shot_02", &tmp.path().join("shot_02").display().to_string()]);
}

#[test]
fn a_bad_clip_toml_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    write_session(tmp.path(), SESSION_TOML, CSV, &["shot_01"]);
    ClipSpec::new(1).fps(0.0).write(&tmp.path().join("shot_02"));
    let err = Session::load(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::BadFps { .. }));
    assert_names(&err, &["shot_02", "clip.toml", "[camera] fps"]);
}
