//! Broken session folders and hostile clip names: each bad clip fails its own shot with its reason, the
//! others are analysed and written, and no output overwrites another or outlives its clip.

use crate::common::*;

/// Clips `shot 1` and `shot_1` both wrote `trajectories/shot_1.csv` (exit 0).
#[test]
fn clips_shot_1_and_shot_underscore_1_get_two_files() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    std::fs::rename(session.join(CLIPS[0]), session.join("shot 1")).unwrap();
    copy_dir(&session.join("shot 1"), &session.join("shot_1"));
    rename_row(&session, CLIPS[0], "shot 1");
    let csv = session.join("clips.csv");
    let text = std::fs::read_to_string(&csv).unwrap() + "shot_1,clay,0,0.3,2\n";
    std::fs::write(&csv, text).unwrap();
    let out = dir.path().join("out");
    expect(&mut analyze(&session, &out, &dir.path().join("s.sqlite")), 0, &[]);
    let rows = estimate_rows(&out);
    let mut files: Vec<&str> = rows.iter().map(|(_, f)| f.as_str()).collect();
    files.sort();
    files.dedup();
    assert_eq!(files.len(), 4, "one file per clip: {rows:?}");
    for (clip, file) in &rows {
        assert!(out.join(file).is_file(), "{clip}: {file} missing");
    }
    assert_eq!(trajectory_files(&out).len(), 4);
    let shot1 = rows.iter().find(|(c, _)| c == "shot_1").unwrap();
    assert_eq!(shot1.1, "trajectories/shot_1.csv", "a safe name is kept as it is");
}

/// A legal 250-character clip name aborted output writing after `estimates.csv` (the `.partial` suffix
/// passed the name limit), losing the rest.
#[test]
fn a_250_character_clip_name_loses_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let long = "a".repeat(250);
    std::fs::rename(session.join(CLIPS[0]), session.join(&long)).unwrap();
    rename_row(&session, CLIPS[0], &long);
    let out = dir.path().join("out");
    expect(&mut analyze(&session, &out, &dir.path().join("s.sqlite")), 0, &[]);
    for f in [
        "estimates.csv",
        "fit.json",
        "comparison.csv",
        "surfaces.csv",
        "report.html",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let rows = estimate_rows(&out);
    let (_, file) = rows.iter().find(|(c, _)| *c == long).unwrap();
    assert!(file.len() < 140 && out.join(file).is_file(), "{file}");
    assert!(
        !std::fs::read_dir(&out)
            .unwrap()
            .any(|e| e.unwrap().file_name().to_string_lossy().contains("partial")),
        "no temporary file left"
    );
}

/// A clip removed from `clips.csv` was still fitted and written from the store.
#[test]
fn a_clip_removed_from_clips_csv_is_not_analysed() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let (out, store) = (dir.path().join("out"), dir.path().join("s.sqlite"));
    expect(&mut analyze(&session, &out, &store), 0, &[]);
    assert_eq!(estimate_rows(&out).len(), 3);
    let csv = session.join("clips.csv");
    let text: String = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with(CLIPS[2]))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&csv, text).unwrap();
    let ran = expect(&mut analyze(&session, &out, &store), 0, &[]);
    assert!(ran.stdout.contains("2 shot(s) listed"), "{}", ran.stdout);
    let clips: Vec<String> = estimate_rows(&out).into_iter().map(|(c, _)| c).collect();
    assert_eq!(clips, [CLIPS[0], CLIPS[1]]);
    assert_eq!(trajectory_files(&out).len(), 2, "{:?}", trajectory_files(&out));
    let fit = std::fs::read_to_string(out.join("fit.json")).unwrap();
    assert!(!fit.contains(CLIPS[2]), "the removed clip is not fitted");
}

/// A `clips.csv` whose header has an unterminated quote parsed as 0 rows and exited 0 with outputs built
/// from stale data.
#[test]
fn an_unterminated_quote_in_clips_csv_is_an_error_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let (out, store) = (dir.path().join("out"), dir.path().join("s.sqlite"));
    expect(&mut analyze(&session, &out, &store), 0, &[]);
    let csv = session.join("clips.csv");
    let text = std::fs::read_to_string(&csv)
        .unwrap()
        .replacen(",repeat", ",\"repeat", 1);
    std::fs::write(&csv, text).unwrap();
    expect(
        &mut analyze(&session, &out, &store),
        1,
        &["clips.csv line 1", "never closes"],
    );
}

/// A clip listed but absent, a malformed `clip.toml`, `fps = 0.5`, `fps = 1` (v_in −158 m/s) and
/// `diameter_m = 16` (v_in 570 m/s) stopped the whole session or were accepted: each fails its own shot,
/// named, exit 1, and the two other shots are written.
#[test]
fn one_bad_clip_fails_its_shot_and_the_others_are_written() {
    type Spoil = fn(&std::path::Path);
    let cases: [(&str, Spoil, &[&str]); 5] = [
        (
            "absent",
            |d| std::fs::remove_dir_all(d).unwrap(),
            &["no folder or camera file"],
        ),
        (
            "malformed clip.toml",
            |d| std::fs::write(d.join("clip.toml"), "[camera\n").unwrap(),
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
            "diameter 16",
            |d| std::fs::write(d.join("clip.toml"), "[ball]\ndiameter_m = 16\n").unwrap(),
            &["clip.toml", "[ball] diameter_m"],
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (i, (what, spoil, parts)) in cases.into_iter().enumerate() {
        let root = dir.path().join(i.to_string());
        let session = copy_session(&root);
        spoil(&session.join(CLIPS[1]));
        let out = root.join("out");
        let mut all = vec![CLIPS[1]];
        all.extend_from_slice(parts);
        let ran = expect(&mut analyze(&session, &out, &root.join("s.sqlite")), 1, &all);
        assert!(ran.stdout.contains("3 shot(s) listed"), "{what}: {}", ran.stdout);
        let clips: Vec<String> = estimate_rows(&out).into_iter().map(|(c, _)| c).collect();
        assert_eq!(clips, [CLIPS[0], CLIPS[2]], "{what}");
        assert!(out.join("report.html").is_file(), "{what}");
    }
}

/// Clip names with `../` or an absolute path read folders outside the session.
#[test]
fn clip_names_leading_outside_the_session_fail_their_shot() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let elsewhere = dir.path().join("elsewhere");
    std::fs::rename(session.join(CLIPS[1]), &elsewhere).unwrap();
    for name in ["../elsewhere".to_string(), elsewhere.display().to_string()] {
        let s2 = copy_session(&dir.path().join("copy"));
        rename_row(&s2, CLIPS[1], &name);
        let out = dir.path().join("out");
        expect(
            &mut analyze(&s2, &out, &dir.path().join("s.sqlite")),
            1,
            &[&name, "inside the session folder"],
        );
        assert_eq!(estimate_rows(&out).len(), 2, "{name}");
        std::fs::remove_dir_all(dir.path().join("copy")).unwrap();
    }
}

/// A frame numbered above i64::MAX made the whole analysis fail at the store with a message naming neither
/// clip nor file: that shot fails naming the file, the others are written.
#[test]
fn a_frame_number_above_i64_max_fails_that_shot_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let clip = session.join(CLIPS[0]);
    let frames = png_frames(&clip);
    let last = frames.last().unwrap();
    std::fs::rename(last, clip.join("frame_99999999999999999999.png")).unwrap();
    let out = dir.path().join("out");
    expect(
        &mut analyze(&session, &out, &dir.path().join("s.sqlite")),
        1,
        &["frame_99999999999999999999.png", "too large"],
    );
    assert_eq!(estimate_rows(&out).len(), 2);
}

/// Three 20000×20000 PNG frames (389 KB each) took 8.2 GB and 62 s before a clean error: the header is
/// checked against the frame-size limit before decoding.
#[test]
fn bomb_header_frames_fail_that_shot_from_the_header() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let clip = session.join(CLIPS[2]);
    std::fs::remove_dir_all(&clip).unwrap();
    std::fs::create_dir_all(&clip).unwrap();
    for i in 0..3 {
        std::fs::write(
            clip.join(format!("frame_{i:06}.png")),
            bouncelab_frames::testutil::bomb_png(20_000, 20_000),
        )
        .unwrap();
    }
    let out = dir.path().join("out");
    expect(
        &mut analyze(&session, &out, &dir.path().join("s.sqlite")),
        1,
        &["frame_000000.png", "over the limit"],
    );
    assert_eq!(estimate_rows(&out).len(), 2);
}

/// Truncated, zero-byte and wrong-size frames: the shot fails naming the file and frame, the others are
/// written.
#[test]
fn corrupt_frames_fail_their_shot_naming_file_and_frame() {
    let dir = tempfile::tempdir().unwrap();
    for (i, spoil) in ["truncate", "empty", "size"].into_iter().enumerate() {
        let root = dir.path().join(i.to_string());
        let session = copy_session(&root);
        let clip = session.join(CLIPS[0]);
        let frames = png_frames(&clip);
        let victim = &frames[frames.len() / 2];
        let bytes = std::fs::read(victim).unwrap();
        match spoil {
            "truncate" => std::fs::write(victim, &bytes[..bytes.len() / 2]).unwrap(),
            "empty" => std::fs::write(victim, b"").unwrap(),
            _ => image::GrayImage::new(17, 9).save(victim).unwrap(),
        }
        let name = victim.file_name().unwrap().to_string_lossy().into_owned();
        let out = root.join("out");
        expect(
            &mut analyze(&session, &out, &root.join("s.sqlite")),
            1,
            &[&name, "frame "],
        );
        assert_eq!(estimate_rows(&out).len(), 2, "{spoil}");
    }
}

/// Shuffled frame names (contact −36 ms) and reversed ones (COR 1.30) were accepted: the shot is flagged
/// with the reason in `estimates.csv` and left out of the fit, the others are fitted.
#[test]
fn shuffled_and_reversed_frame_names_are_flagged_and_kept_out_of_the_fit() {
    let dir = tempfile::tempdir().unwrap();
    for (i, order) in ["reversed", "shuffled"].into_iter().enumerate() {
        let root = dir.path().join(i.to_string());
        let session = copy_session(&root);
        let clip = session.join(CLIPS[0]);
        let gcd = |mut a: usize, mut b: usize| {
            while b != 0 {
                (a, b) = (b, a % b);
            }
            a
        };
        // Reversed, or a stride coprime with n: a thorough shuffle, the same every run.
        permute_frames(&clip, |k, n| {
            if order == "reversed" {
                n - 1 - k
            } else {
                k * (n / 3..n).find(|&s| gcd(s, n) == 1).unwrap() % n
            }
        });
        let out = root.join("out");
        let ran = expect(
            &mut analyze(&session, &out, &root.join("s.sqlite")),
            0,
            &["left out of the fit"],
        );
        assert!(ran.stderr.contains(CLIPS[0]), "{order}: {}", ran.stderr);
        let mut r = csv::Reader::from_path(out.join("estimates.csv")).unwrap();
        let flags = r.headers().unwrap().iter().position(|c| c == "flags").unwrap();
        let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
        assert!(!rows[0][flags].is_empty(), "{order}: flagged");
        let fit = std::fs::read_to_string(out.join("fit.json")).unwrap();
        assert!(!fit.contains(CLIPS[0]), "{order}: not fitted");
    }
}

/// The frame-size limit is the user's to set (`--max-frame-pixels`): over it, each shot fails from the
/// header, naming the limit.
#[test]
fn the_frame_size_limit_is_configurable() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let out = dir.path().join("out");
    expect(
        analyze(&session, &out, &dir.path().join("s.sqlite")).args(["--max-frame-pixels", "1000"]),
        1,
        &["over the limit of 1000 pixels"],
    );
}
