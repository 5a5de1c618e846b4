//! Loading session folders: session.toml, clips.csv, clip.toml overrides and their errors (`docs/session.md`).

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
    // Two clips without an fps, and shot_02 (20°) without a down-slope direction.
    assert_eq!(s.warnings.len(), 3, "{:?}", s.warnings);
    assert!(matches!(&s.warnings[0], Warning::DefaultFps { clip, .. } if clip.ends_with("shot_01")));
    assert!(matches!(&s.warnings[2], Warning::DefaultDownslope { clips: 1, .. }));
}

#[test]
fn an_incline_without_a_down_slope_direction_is_warned_once() {
    let toml = "[ball]\ndiameter_m = 0.067\nmass_kg = 0.0567\n[camera]\nfps = 5000\n";
    let csv = "clip,surface,angle_deg,drop_height_m\nshot_01,clay,0,1.2\nshot_02,tape,20,0.8\nshot_03,clay,15,0.5\n";
    let (_t, s) = session_with(toml, csv, &["shot_01", "shot_02", "shot_03"]);
    let s = s.unwrap();
    assert!(!s.clips[1].downslope_given && s.clips[1].downslope == Downslope::PlusX);
    let w: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("2 clip(s) on an incline give no down-slope direction"),
        "{w:?}"
    );
    // Given in session.toml, nothing to say; the level shot never needs it.
    let (_t, s) = session_with(&format!("{toml}downslope = \"-x\"\n"), CSV, &["shot_01", "shot_02"]);
    let s = s.unwrap();
    assert!(
        s.warnings.is_empty() && s.clips.iter().all(|c| c.downslope_given),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.clips[1].settings.downslope, Some(Downslope::MinusX));
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
    let s = s.unwrap();
    assert_eq!(s.clips.len(), 1, "the other clip loads");
    let [bad] = &s.unusable[..] else {
        panic!("{:?}", s.unusable)
    };
    assert_eq!((bad.name.as_str(), bad.line), ("shot_02", 3));
    for part in ["shot_02", &tmp.path().join("shot_02").display().to_string()] {
        assert!(bad.reason.contains(part), "{}", bad.reason);
    }
}

#[test]
fn a_bad_clip_toml_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    write_session(tmp.path(), SESSION_TOML, CSV, &["shot_01"]);
    ClipSpec::new(1).fps(0.0).write(&tmp.path().join("shot_02"));
    let s = Session::load(tmp.path()).unwrap();
    assert_eq!(s.clips.len(), 1);
    let reason = &s.unusable[0].reason;
    for part in ["shot_02", "clip.toml", "[camera] fps"] {
        assert!(reason.contains(part), "{reason}");
    }
}

/// An incline of 90° or more, or a negative drop height, is no shot: the file, line and column are named.
#[test]
fn an_impossible_angle_or_height_in_clips_csv_is_named() {
    for (row, parts) in [
        ("shot_01,clay,90,1.2", ["line 2, angle_deg", "90 is not an incline"]),
        ("shot_01,clay,-95,1.2", ["line 2, angle_deg", "-95 is not an incline"]),
        (
            "shot_01,clay,10,-0.5",
            ["line 2, drop_height_m", "-0.5 is outside the accepted range 0–100 m"],
        ),
    ] {
        let csv = format!("clip,surface,angle_deg,drop_height_m\n{row}\n");
        let (_tmp, s) = session_with(SESSION_TOML, &csv, &["shot_01"]);
        let err = s.unwrap_err();
        assert_names(&err, &["clips.csv", parts[0], parts[1]]);
    }
}

// ---- camera files, settings keys, unfilled rows, init ------------------------------------------------------

mod common;

use bouncelab_frames::init::{InitOptions, scan};
use bouncelab_frames::{ClipOptions, ContactLine, Roi, SettingSource};
use common::camera::{Cine, CinePacking, Mraw, TiffCompression, moving_disc, write_tiff_stack};

const BALL: &str = "[ball]\ndiameter_m = 0.067\nmass_kg = 0.0567\n";

#[test]
fn camera_files_are_clips_by_exact_name_or_by_name_without_extension() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::write(d.join("session.toml"), BALL).unwrap();
    Mraw::new(16, 8, 12).write(d, "p1", &moving_disc(16, 8, 3, 4095, 1));
    Cine::new(16, 8, CinePacking::U8).write(&d.join("c1.cine"), &moving_disc(16, 8, 4, 255, 1));
    write_tiff_stack(
        &d.join("t1.tif"),
        16,
        8,
        8,
        &moving_disc(16, 8, 5, 255, 1),
        TiffCompression::None,
    );
    ClipSpec::new(2).write(&d.join("folder1"));
    std::fs::write(
        d.join("clips.csv"),
        "clip,surface,angle_deg,drop_height_m\np1,clay,0,1\nc1.cine,clay,10,1\nt1,tape,0,0.5\nfolder1,tape,0,1\n",
    )
    .unwrap();
    let s = Session::load(d).unwrap();
    let by = |n: &str| s.clip(n).unwrap();
    assert_eq!(by("p1").dir, d.join("p1.cihx"));
    assert_eq!((by("p1").fps, by("c1.cine").fps), (30_000.0, 25_000.0));
    assert!(matches!(by("p1").fps_source, FpsSource::Header(_)));
    assert_eq!(by("t1").dir, d.join("t1.tif"));
    // Neither the stack nor the folder has a header; nothing else gives an fps. (And c1.cine, at 10°, has no
    // down-slope direction.)
    let fps_warnings = s.warnings.iter().filter(|w| matches!(w, Warning::DefaultFps { .. }));
    assert_eq!(fps_warnings.count(), 2, "{:?}", s.warnings);
    for (name, frames) in [("p1", 3), ("c1.cine", 4), ("t1", 5), ("folder1", 2)] {
        assert_eq!(by(name).open().unwrap().len(), frames, "{name}");
    }

    Cine::new(16, 8, CinePacking::U8).write(&d.join("t1.cine"), &moving_disc(16, 8, 4, 255, 1));
    // An ambiguous name fails that clip only, naming the candidates.
    let s = Session::load(d).unwrap();
    let [bad] = &s.unusable[..] else {
        panic!("{:?}", s.unusable)
    };
    assert_eq!(bad.name, "t1");
    for part in ["t1", "t1.cine", "t1.tif", "several camera files"] {
        assert!(bad.reason.contains(part), "{}", bad.reason);
    }
}

#[test]
fn settings_keys_resolve_clip_over_session_with_their_sources() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let toml = format!(
        "{BALL}[camera]\nfps = 1000\nscale_m_per_px = 2.5e-4\nroi = [0, 2, 30, 20]\n[surface]\nline_y_px = 20\nline_tilt_deg = -1.5\n"
    );
    write_session(d, &toml, CSV, &["shot_01", "shot_02"]);
    std::fs::write(
        d.join("shot_02/clip.toml"),
        "[ball]\ndiameter_m = 0.04\n[surface]\nline_y_px = 12.5\n",
    )
    .unwrap();
    let s = Session::load(d).unwrap();
    let (a, b) = (&s.clips[0].settings, &s.clips[1].settings);
    let session_src = SettingSource::SessionToml(d.join("session.toml"));
    let clip_src = SettingSource::ClipToml(d.join("shot_02/clip.toml"));
    assert_eq!((a.ball_diameter_m, &a.ball_diameter_source), (0.067, &session_src));
    assert_eq!((b.ball_diameter_m, &b.ball_diameter_source), (0.04, &clip_src));
    assert_eq!((a.scale_m_per_px, b.scale_m_per_px), (Some(2.5e-4), Some(2.5e-4)));
    let roi = Roi {
        x: 0,
        y: 2,
        width: 30,
        height: 20,
    };
    assert_eq!((a.roi, &a.roi_source), (Some(roi), &Some(session_src.clone())));
    assert_eq!(
        a.contact_line,
        Some(ContactLine {
            y_px: 20.0,
            tilt_deg: -1.5
        })
    );
    // The clip's line is a unit: its tilt defaults to 0, not the session's.
    assert_eq!(
        b.contact_line,
        Some(ContactLine {
            y_px: 12.5,
            tilt_deg: 0.0
        })
    );
    assert_eq!(b.contact_line_source, Some(clip_src.clone()));
    assert_eq!((a.surface_tilt_deg, b.surface_tilt_deg), (None, None));
    let clip = s.clips[1].open().unwrap();
    assert_eq!(clip.settings().ball_diameter_m, 0.04);

    // Checked against the frames (32×24) when the clip is opened, naming the clip and the file.
    std::fs::write(d.join("shot_01/clip.toml"), "[camera]\nroi = [10, 0, 30, 10]\n").unwrap();
    std::fs::write(d.join("shot_02/clip.toml"), "[surface]\nline_y_px = 24\n").unwrap();
    let s = Session::load(d).unwrap();
    let err = s.clips[0].open().unwrap_err();
    assert!(matches!(err, FramesError::RoiOutsideImage { .. }), "{err:?}");
    assert_names(&err, &["shot_01", "[10, 0, 30, 10]", "clip.toml", "32×24"]);
    let err = s.clips[1].open().unwrap_err();
    assert!(matches!(err, FramesError::LineOutsideImage { .. }), "{err:?}");
    assert_names(&err, &["shot_02", "y = 24", "0 ≤ y ≤ 23"]);
}

/// The surface's tilt alone (a known camera roll for shots whose level no line shows): clip over session,
/// the command line over both, each with its source.
#[test]
fn the_surface_tilt_resolves_clip_over_session_and_the_command_line_over_both() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write_session(
        d,
        &format!("{BALL}[surface]\ntilt_deg = -1.5\n"),
        CSV,
        &["shot_01", "shot_02"],
    );
    std::fs::write(d.join("shot_02/clip.toml"), "[surface]\ntilt_deg = 0.75\n").unwrap();
    let s = Session::load(d).unwrap();
    let (a, b) = (&s.clips[0].settings, &s.clips[1].settings);
    assert_eq!(
        (a.surface_tilt_deg, &a.surface_tilt_source),
        (Some(-1.5), &Some(SettingSource::SessionToml(d.join("session.toml"))))
    );
    assert_eq!(
        (b.surface_tilt_deg, &b.surface_tilt_source),
        (Some(0.75), &Some(SettingSource::ClipToml(d.join("shot_02/clip.toml"))))
    );
    // The tilt alone leaves the line to the image: no contact line is given.
    assert_eq!((a.contact_line, b.contact_line), (None, None));
    let mut opts = ClipOptions::default();
    opts.overrides.surface_tilt_deg = Some(2.0);
    let s = Session::load_with(d, &opts).unwrap();
    for c in &s.clips {
        assert_eq!(
            (c.settings.surface_tilt_deg, &c.settings.surface_tilt_source),
            (Some(2.0), &Some(SettingSource::CommandLine))
        );
    }
    opts.overrides.surface_tilt_deg = Some(60.0);
    let err = Session::load_with(d, &opts).unwrap_err();
    assert_names(&err, &["--tilt", "4.5e1"]);
}

#[test]
fn settings_values_out_of_range_name_the_file_key_and_range() {
    let cases = [
        ("[camera]\nscale_m_per_px = 0\n", "[camera] scale_m_per_px", "1e-7"),
        ("[camera]\nscale_m_per_px = 3\n", "[camera] scale_m_per_px", "1e0"),
        ("[ball]\ndiameter_m = 5\n", "[ball] diameter_m", "1e-4"),
        ("[camera]\nroi = [1, 2, 3]\n", "[camera] roi", "[x, y, width, height]"),
        ("[camera]\nroi = [1, 2, 0, 4]\n", "[camera] roi", "at least 1 pixel"),
        ("[camera]\nroi = [-1, 2, 3, 4]\n", "[camera] roi", "≥ 0"),
        (
            "[surface]\nline_y_px = 10\nline_tilt_deg = 60\n",
            "[surface] line_tilt_deg",
            "4.5e1",
        ),
        ("[surface]\nline_tilt_deg = 2\n", "[surface] line_tilt_deg", "without"),
        ("[surface]\nline_y_px = -3\n", "[surface] line_y_px", "≥ 0"),
        ("[surface]\ntilt_deg = -50\n", "[surface] tilt_deg", "4.5e1"),
        (
            "[surface]\ntilt_deg = \"level\"\n",
            "[surface] tilt_deg",
            "not a number",
        ),
        (
            "[surface]\nline_y_px = \"top\"\n",
            "[surface] line_y_px",
            "not a number",
        ),
    ];
    for (clip_toml, key, range) in cases {
        let tmp = tempfile::tempdir().unwrap();
        write_session(tmp.path(), SESSION_TOML, CSV, &["shot_01", "shot_02"]);
        std::fs::write(tmp.path().join("shot_02/clip.toml"), clip_toml).unwrap();
        // The clip's own file fails that clip, naming the file, key and range; the session loads.
        let s = Session::load(tmp.path()).unwrap();
        assert_eq!(s.clips.len(), 1, "{clip_toml}");
        let reason = &s.unusable[0].reason;
        for part in ["shot_02", "clip.toml", key, range] {
            assert!(reason.contains(part), "{clip_toml}: `{reason}` lacks `{part}`");
        }
    }
}

#[test]
fn unfilled_cells_are_all_named_at_once() {
    let csv = "clip,surface,angle_deg,drop_height_m\nshot_01,,,1.2\nshot_02,tape,20,\n";
    let (_t, s) = session_with(SESSION_TOML, csv, &["shot_01", "shot_02"]);
    let err = s.unwrap_err();
    let FramesError::UnfilledColumns { rows, .. } = &err else {
        panic!("{err:?}")
    };
    assert_eq!(rows.len(), 2);
    assert_eq!(
        (rows[0].line, rows[0].columns.clone()),
        (2, vec!["surface".to_string(), "angle_deg".into()])
    );
    assert_names(
        &err,
        &[
            "clips.csv",
            "line 2 `shot_01`: surface, angle_deg",
            "line 3 `shot_02`: drop_height_m",
        ],
    );
}

#[test]
fn init_then_load_on_a_folder_of_camera_files() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    Mraw::new(16, 8, 12).write(d, "clay_15deg_550mm", &moving_disc(16, 8, 3, 4095, 1));
    Cine::new(16, 8, CinePacking::P12).write(&d.join("tape_0deg_1.2m.cine"), &moving_disc(16, 8, 4, 4095, 1));
    ClipSpec::new(2).write(&d.join("shot_03"));
    std::fs::create_dir(d.join("notes")).unwrap();
    std::fs::write(d.join("broken.cine"), b"CI but not really").unwrap();
    let draft = scan(d).unwrap();
    let names: Vec<&str> = draft.clips.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(
        names,
        ["broken.cine", "clay_15deg_550mm.cihx", "shot_03", "tape_0deg_1.2m.cine"]
    );
    assert!(draft.clips[0].problem.as_deref().unwrap().contains("broken.cine"));
    assert_eq!(draft.skipped.len(), 1);
    assert_eq!((draft.clips[1].frames, draft.clips[1].fps), (Some(3), Some(30_000.0)));
    // Headers disagree (30,000 and 25,000): no session-wide fps is written.
    assert_eq!(draft.common_fps(), None);
    let mut o = InitOptions::default();
    o.diameter_m = Some(0.067);
    o.mass_kg = Some(0.0567);
    draft.write(&o).unwrap();
    let err = draft.write(&o).unwrap_err();
    assert!(matches!(err, FramesError::WouldOverwrite { .. }), "{err:?}");
    let csv = std::fs::read_to_string(d.join("clips.csv")).unwrap();
    assert!(csv.contains("clay_15deg_550mm.cihx,clay,15,0.55"), "{csv}");
    assert!(csv.contains("tape_0deg_1.2m.cine,tape,0,1.2"), "{csv}");
    let err = Session::load(d).unwrap_err();
    assert_names(
        &err,
        &[
            "line 2 `broken.cine`",
            "line 4 `shot_03`: surface, angle_deg, drop_height_m",
        ],
    );
    let filled = csv
        .replace("broken.cine,,,\n", "")
        .replace("shot_03,,,", "shot_03,clay,0,1");
    std::fs::write(d.join("clips.csv"), &filled).unwrap();
    let s = Session::load(d).unwrap();
    assert_eq!(s.clips.len(), 3);
    assert_eq!(s.clip("tape_0deg_1.2m.cine").unwrap().open().unwrap().len(), 4);
    assert_eq!(s.clip("clay_15deg_550mm.cihx").unwrap().fps, 30_000.0);
    // No down-slope asked for: the key is written commented out, so the inclined clip's flights may tell it.
    assert!(!s.clip("clay_15deg_550mm.cihx").unwrap().downslope_given);
    assert!(
        s.warnings
            .iter()
            .any(|w| matches!(w, Warning::DefaultDownslope { clips: 1, .. }))
    );
    let mut forced = o.clone();
    forced.force = true;
    forced.downslope = Some(Downslope::MinusX);
    draft.write(&forced).unwrap();
    std::fs::write(d.join("clips.csv"), &filled).unwrap();
    let s = Session::load(d).unwrap();
    let c = s.clip("clay_15deg_550mm.cihx").unwrap();
    assert!(c.downslope_given && c.downslope == Downslope::MinusX);
    // Without a ball, the keys are left for a person to fill and loading names them.
    let mut bare = InitOptions::default();
    bare.force = true;
    draft.write(&bare).unwrap();
    assert_names(&Session::load(d).unwrap_err(), &["[ball] diameter_m missing"]);
}
