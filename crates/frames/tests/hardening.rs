//! Issue 19's cases at the front door: each clip's problem fails that clip only; clip names stay inside the
//! session folder; `clips.csv` that would silently lose rows is refused; frame numbers and frame sizes are
//! bounded before anything is allocated.

use bouncelab_frames::testutil::{ClipSpec, SESSION_TOML, bomb_png, write_session};
use bouncelab_frames::{Clip, ClipOptions, FramesError, Session};

const CSV3: &str =
    "clip,surface,angle_deg,drop_height_m\nshot_01,clay,0,0.3\nshot_02,clay,15,0.3\nshot_03,tape,0,0.3\n";

fn session3() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    write_session(tmp.path(), SESSION_TOML, CSV3, &["shot_01", "shot_02", "shot_03"]);
    tmp
}

/// A listed-but-absent clip, a malformed `clip.toml`, and `fps = 0.5` used to stop the whole session: each
/// now fails its own row with the reason, and the other clips load.
#[test]
fn one_clips_problem_fails_that_clip_only() {
    type Spoil = fn(&std::path::Path);
    let cases: [(&str, Spoil, &[&str]); 5] = [
        (
            "absent",
            |d| std::fs::remove_dir_all(d).unwrap(),
            &["shot_02", "no folder or camera file"],
        ),
        (
            "malformed clip.toml",
            |d| std::fs::write(d.join("clip.toml"), "[camera\nfps = 3").unwrap(),
            &["clip.toml", "malformed TOML"],
        ),
        (
            "fps 0.5",
            |d| std::fs::write(d.join("clip.toml"), "[camera]\nfps = 0.5\n").unwrap(),
            &["clip.toml", "[camera] fps = 0.5"],
        ),
        (
            "fps 1",
            |d| std::fs::write(d.join("clip.toml"), "[camera]\nfps = 1\n").unwrap(),
            &["clip.toml", "[camera] fps = 1"],
        ),
        (
            "diameter 16 m",
            |d| std::fs::write(d.join("clip.toml"), "[ball]\ndiameter_m = 16\n").unwrap(),
            &["clip.toml", "[ball] diameter_m", "16"],
        ),
    ];
    for (what, spoil, parts) in cases {
        let tmp = session3();
        spoil(&tmp.path().join("shot_02"));
        let s = Session::load(tmp.path()).unwrap_or_else(|e| panic!("{what}: the session fails: {e}"));
        let names: Vec<_> = s.clips.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["shot_01", "shot_03"], "{what}");
        assert_eq!(s.unusable.len(), 1, "{what}");
        let u = &s.unusable[0];
        assert_eq!(
            (u.name.as_str(), u.line, u.surface.as_str(), u.angle_deg),
            ("shot_02", 3, "clay", 15.0)
        );
        for p in parts {
            assert!(u.reason.contains(p), "{what}: `{}` lacks `{p}`", u.reason);
        }
        assert_eq!(s.listed(), ["shot_01", "shot_02", "shot_03"], "{what}");
    }
}

/// Clip names with `../` or an absolute path used to read folders outside the session.
#[test]
fn clip_names_cannot_leave_the_session_folder() {
    let outside = tempfile::tempdir().unwrap();
    ClipSpec::new(2).write(&outside.path().join("elsewhere"));
    let tmp = tempfile::tempdir().unwrap();
    let abs = outside.path().join("elsewhere");
    let rel = format!("../{}/elsewhere", outside.path().file_name().unwrap().to_str().unwrap());
    let csv = format!(
        "clip,surface,angle_deg,drop_height_m\nshot_01,clay,0,0.3\n{rel},clay,0,0.3\n{},clay,0,0.3\nsub/./../../x,clay,0,0.3\n",
        abs.display()
    );
    write_session(tmp.path(), SESSION_TOML, &csv, &["shot_01"]);
    let s = Session::load(tmp.path()).unwrap();
    assert_eq!(s.clips.len(), 1);
    assert_eq!(s.unusable.len(), 3);
    for u in &s.unusable {
        assert!(u.reason.contains("inside the session folder"), "{}", u.reason);
    }
    // A clip in a subfolder of the session is inside it.
    let csv = "clip,surface,angle_deg,drop_height_m\nday1/shot_01,clay,0,0.3\n";
    let tmp = tempfile::tempdir().unwrap();
    write_session(tmp.path(), SESSION_TOML, csv, &["day1/shot_01"]);
    assert_eq!(Session::load(tmp.path()).unwrap().clips.len(), 1);
}

/// A header with an unterminated quote parsed as 0 rows and the analysis went on with stale data.
#[test]
fn a_clips_csv_that_would_lose_rows_is_refused() {
    let tmp = session3();
    std::fs::write(
        tmp.path().join("clips.csv"),
        CSV3.replacen(",drop_height_m", ",\"drop_height_m", 1),
    )
    .unwrap();
    let err = Session::load(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::Csv { line: Some(1), .. }), "{err:?}");
    assert!(err.to_string().contains("never closes"), "{err}");
    // A quote opened in a later row: that row's line.
    std::fs::write(
        tmp.path().join("clips.csv"),
        CSV3.replacen("shot_02,clay", "shot_02,\"clay", 1),
    )
    .unwrap();
    let err = Session::load(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::Csv { line: Some(3), .. }), "{err:?}");
    // A quoted field with a doubled quote inside and a `#` comment with a lone quote are fine.
    std::fs::write(
        tmp.path().join("clips.csv"),
        CSV3.replacen("shot_01,clay", "# the \"good\" one's\nshot_01,\"cl\"\"ay\"", 1),
    )
    .unwrap();
    assert_eq!(Session::load(tmp.path()).unwrap().clips[0].surface, "cl\"ay");
    // A header alone: no rows to analyse is an error, not an empty analysis.
    std::fs::write(tmp.path().join("clips.csv"), "clip,surface,angle_deg,drop_height_m\n").unwrap();
    let err = Session::load(tmp.path()).unwrap_err();
    assert!(err.to_string().contains("no clip rows"), "{err}");
}

/// Physical ranges with the key and the range named: mass, drop height, angle.
#[test]
fn session_numbers_outside_their_physical_range_are_named() {
    let tmp = session3();
    std::fs::write(tmp.path().join("session.toml"), SESSION_TOML.replace("0.0567", "1e300")).unwrap();
    let msg = Session::load(tmp.path()).unwrap_err().to_string();
    assert!(
        msg.contains("[ball] mass_kg") && msg.contains("1e300") && msg.contains("kg"),
        "{msg}"
    );
    for (cell, column) in [
        ("0,1e300", "drop_height_m"),
        ("0,-1", "drop_height_m"),
        ("1e300,0.3", "angle_deg"),
        ("95,0.3", "angle_deg"),
    ] {
        let tmp = session3();
        std::fs::write(tmp.path().join("clips.csv"), CSV3.replacen("15,0.3", cell, 1)).unwrap();
        let msg = Session::load(tmp.path()).unwrap_err().to_string();
        assert!(msg.contains("line 3") && msg.contains(column), "{cell}: {msg}");
        assert!(msg.len() < 200, "short numbers: {msg}");
    }
}

/// A frame numbered above i64::MAX made the store fail with a message naming neither clip nor file.
#[test]
fn a_frame_number_above_i64_max_names_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("clip");
    ClipSpec::new(2).write(&dir);
    let first = std::fs::read_dir(&dir).unwrap().next().unwrap().unwrap().path();
    let big = dir.join(format!("frame_{}.png", i64::MAX as u64 + 1));
    std::fs::rename(&first, &big).unwrap();
    let err = Clip::open_with(&dir, &ClipOptions::with_fps(1000.0)).unwrap_err();
    assert!(matches!(err, FramesError::NumberTooLarge { .. }), "{err:?}");
    assert!(err.to_string().contains(&big.display().to_string()), "{err}");
    // i64::MAX itself is a frame number like any other.
    std::fs::rename(&big, dir.join(format!("frame_{}.png", i64::MAX))).unwrap();
    assert!(Clip::open_with(&dir, &ClipOptions::with_fps(1000.0)).is_ok());
}

/// Three 20000×20000 PNG frames took 8.2 GB and a minute before an error: the size is checked from the
/// header (first frame) before anything is decoded, and a later frame of another size is refused from its
/// header too.
#[test]
fn bomb_headers_are_refused_before_decoding() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("bomb");
    std::fs::create_dir_all(&dir).unwrap();
    for i in 0..3 {
        std::fs::write(dir.join(format!("f{i}.png")), bomb_png(20_000, 20_000)).unwrap();
    }
    let err = Clip::open_with(&dir, &ClipOptions::with_fps(1000.0)).unwrap_err();
    assert!(
        matches!(
            err,
            FramesError::FrameTooLarge {
                width: 20_000,
                height: 20_000,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("f0.png"), "{err}");
    // The limit is the caller's to set.
    let mut options = ClipOptions::with_fps(1000.0);
    options.max_frame_pixels = 100;
    let small = tmp.path().join("small");
    ClipSpec::new(2).write(&small);
    assert!(matches!(
        Clip::open_with(&small, &options),
        Err(FramesError::FrameTooLarge { limit: 100, .. })
    ));
    // A bomb among ordinary frames: that frame's error names it, from the header.
    let names: Vec<_> = {
        let mut v: Vec<_> = std::fs::read_dir(&small).unwrap().map(|e| e.unwrap().path()).collect();
        v.sort();
        v
    };
    std::fs::write(&names[1], bomb_png(20_000, 20_000)).unwrap();
    let clip = Clip::open_with(&small, &ClipOptions::with_fps(1000.0)).unwrap();
    let frames: Vec<_> = clip.frames().collect();
    assert!(frames[0].is_ok());
    let err = frames[1].as_ref().unwrap_err();
    assert!(
        matches!(
            err,
            FramesError::SizeMismatch {
                found: (20_000, 20_000),
                index: 1,
                ..
            }
        ),
        "{err:?}"
    );
}

/// The frame-size limit given to a session reaches its clips.
#[test]
fn a_sessions_frame_size_limit_reaches_its_clips() {
    let tmp = session3();
    let mut options = ClipOptions::default();
    options.max_frame_pixels = 10;
    let s = Session::load_with(tmp.path(), &options).unwrap();
    let err = s.clips[0].open().unwrap_err();
    assert!(matches!(err, FramesError::FrameTooLarge { limit: 10, .. }), "{err:?}");
    assert!(Session::load(tmp.path()).unwrap().clips[0].open().is_ok());
}
