//! `bouncelab analyze` end to end on the rendered `smoke` session: the output files, incremental re-runs, a
//! run killed with SIGKILL and resumed, and the session faults (clear line, exit 1, nothing lost).

use assert_cmd::Command;
use predicates::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

#[path = "common/files.rs"]
mod files;
use files::copy_dir;

fn bouncelab() -> Command {
    Command::cargo_bin("bouncelab").unwrap()
}

/// The `smoke` preset (3 shots, one per surface) rendered once per test process; tests copy it.
fn smoke() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        bouncelab()
            .args(["render", "--preset", "smoke", "--out"])
            .arg(dir.path())
            .assert()
            .success();
        dir
    })
    .path()
}

/// A fresh copy of the smoke session under `root`; returns the session folder.
fn copy_session(root: &Path) -> PathBuf {
    let to = root.join("session");
    copy_dir(&smoke().join("session"), &to);
    to
}

fn analyze(session: &Path, out: &Path) -> Command {
    let mut c = bouncelab();
    c.arg("analyze")
        .arg(session)
        .arg("--out")
        .arg(out)
        .arg("--store")
        .arg(out.with_extension("sqlite"));
    c
}

fn stdout(c: &mut Command) -> String {
    let out = c.assert().success().get_output().clone();
    String::from_utf8(out.stdout).unwrap()
}

/// A successful run's progress lines (each stage's last word, on stderr).
fn stages(c: &mut Command) -> String {
    let out = c.assert().success().get_output().clone();
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn writes_every_output_and_reuses_unchanged_shots() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let out = dir.path().join("out");
    let first = stdout(&mut analyze(&session, &out));
    assert!(
        first.contains("3 shot(s) listed, 3 measured now, 0 reused, 0 failed"),
        "{first}"
    );
    let header = std::fs::read_to_string(out.join("estimates.csv")).unwrap();
    let columns: Vec<&str> = header.lines().next().unwrap().split(',').collect();
    assert_eq!(
        columns,
        bouncelab_analyze::ESTIMATE_COLUMNS,
        "estimates.csv's header is the documented one"
    );
    assert_eq!(header.lines().count(), 4);
    let traj = std::fs::read_dir(out.join("trajectories")).unwrap().count();
    assert_eq!(traj, 3);
    let fit: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    assert!(fit["parameters"].as_array().unwrap().len() >= 2);
    let comparison = std::fs::read_to_string(out.join("comparison.csv")).unwrap();
    assert!(comparison.starts_with(&bouncelab_analyze::COMPARISON_COLUMNS.join(",")));
    // Spin rows say rad/s, position rows µm, in the unit column.
    for line in comparison.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let unit = if f[4] == "spin" { "rad/s" } else { "um" };
        assert_eq!(f[5], unit, "{line}");
    }
    for file in [
        "model_predictions.csv",
        "model_curves.csv",
        "surfaces.csv",
        "contact_force.csv",
    ] {
        assert!(out.join(file).is_file(), "{file} written");
    }
    report_figures_hold_the_csv_numbers(&out);

    // Nothing changed: nothing tracked, nor fitted.
    const FIT_REUSED: &str = "fit: unchanged since the last run (fit.json)";
    let fitted = std::fs::read(out.join("fit.json")).unwrap();
    let compared = std::fs::read(out.join("comparison.csv")).unwrap();
    let second = stages(&mut analyze(&session, &out));
    assert!(second.contains("0 shot(s) tracked, 3 reused"), "{second}");
    assert!(second.contains(FIT_REUSED), "{second}");
    assert!(
        std::fs::read(out.join("fit.json")).unwrap() == fitted,
        "the fit read back is the fit"
    );
    assert!(
        std::fs::read(out.join("comparison.csv")).unwrap() == compared,
        "the comparison from the fit read back is the same"
    );
    // Another model is fitted again.
    let model = dir.path().join("model.toml");
    std::fs::write(
        &model,
        bouncelab_model::PAPER_MODEL_TOML.replace("[model]", "[model]\n# a copy\n"),
    )
    .unwrap();
    let other = stages(analyze(&session, &out).arg("--model").arg(&model));
    assert!(other.contains("fit: ") && !other.contains(FIT_REUSED), "{other}");

    // One clip's frames touched (a frame rewritten): only that shot is tracked again.
    let clip = std::fs::read_dir(&session)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .min()
        .unwrap();
    let frame = std::fs::read_dir(&clip)
        .unwrap()
        .map(|e| e.unwrap().path())
        .min()
        .unwrap();
    let bytes = std::fs::read(&frame).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(&frame, bytes).unwrap();
    let third = stdout(&mut analyze(&session, &out));
    assert!(third.contains("1 measured now, 2 reused"), "{third}");
}

/// A CSV as rows of named fields.
fn read_csv(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head: Vec<String> = lines.next().unwrap().split(',').map(str::to_string).collect();
    lines
        .map(|l| head.iter().cloned().zip(l.split(',').map(str::to_string)).collect())
        .collect()
}

/// The numbers the report draws are the CSVs': each COR point's tooltip against estimates.csv, the model
/// curves' table against model_curves.csv, the contact force's peak against contact_force.csv.
fn report_figures_hold_the_csv_numbers(out: &Path) {
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    // Every measured shot shows its key frames, drawn from its clip with the track on them.
    let strips = html.matches("<figcaption>key frames: approach ").count();
    assert_eq!(
        strips,
        read_csv(&out.join("estimates.csv")).len(),
        "one key-frame strip per shot"
    );
    let num = |s: &str| s.replace('\u{2212}', "-").parse::<f64>().unwrap();
    for row in read_csv(&out.join("estimates.csv")) {
        let tip = format!("<title>{} ({}, ", row["clip"], row["surface"]);
        let text = html
            .match_indices(&tip)
            .map(|(at, _)| &html[at..at + html[at..].find("</title>").unwrap()])
            .find(|t| t.contains("Coefficient of restitution "))
            .unwrap_or_else(|| panic!("no COR point for {}", row["clip"]));
        // "…: Coefficient of restitution 0.7160 ± 0.0012 at |v_n,in| = 2.345 ± 0.012 m/s"
        let after = &text[text.find("restitution ").unwrap() + "restitution ".len()..];
        let shown_cor = after.split_whitespace().next().unwrap();
        let shown_speed = text.split("= ").nth(1).unwrap().split_whitespace().next().unwrap();
        // Equal to the last digit shown.
        let half_digit = |s: &str| 0.5 * 10f64.powi(-(s.split('.').nth(1).map_or(0, str::len) as i32)) + 1e-12;
        let (c, v) = (num(&row["cor"]), num(&row["v_in_n_m_s"]).abs());
        assert!(
            (num(shown_cor) - c).abs() <= half_digit(shown_cor),
            "COR {shown_cor} vs {c}"
        );
        assert!(
            (num(shown_speed) - v).abs() <= half_digit(shown_speed),
            "speed {shown_speed} vs {v}"
        );
        // The contact level's widening: at least 1, and said in the report when there is one.
        let widened = num(&row["level_se_scale"]);
        assert!(widened >= 1.0, "{}: level_se_scale {widened}", row["clip"]);
        if widened > 1.005 {
            let said = format!("its error widened {widened:.1}-fold");
            assert!(html.contains(&said), "{}: the report does not say {said}", row["clip"]);
        }
    }
    // The curve table lists points of model_curves.csv (four significant digits).
    let curves = read_csv(&out.join("model_curves.csv"));
    assert!(!curves.is_empty());
    let table = &html[html
        .find("Values of the model&#39;s curves")
        .or_else(|| html.find("Values of the model's curves"))
        .unwrap()..];
    let table = &table[..table.find("</table>").unwrap()];
    for row in [&curves[0], curves.last().unwrap()] {
        let v = num(&row["v_in_n_m_s"]);
        let cor = num(&row["cor"]);
        let cell = |x: f64| {
            let mag = x.abs().log10().floor() as i32;
            let d = (3 - mag).max(0) as usize;
            format!("<td class=\"n\">{x:.d$}</td>")
        };
        assert!(
            table.contains(&cell(v)) && table.contains(&cell(cor)),
            "curve point {v} {cor} not in the table"
        );
    }
    let force = read_csv(&out.join("contact_force.csv"));
    let peak = force.iter().map(|r| num(&r["force_n"])).fold(f64::MIN, f64::max);
    let mag = peak.log10().floor() as i32;
    let d = (3 - mag).max(0) as usize;
    assert!(
        html.contains(&format!("peak {peak:.d$} N")),
        "contact force peak {peak} not in the caption"
    );
}

#[test]
fn a_shot_added_to_clips_csv_is_the_only_one_tracked() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let out = dir.path().join("out");
    let csv_path = session.join("clips.csv");
    let full = std::fs::read_to_string(&csv_path).unwrap();
    let lines: Vec<&str> = full.lines().collect();
    std::fs::write(&csv_path, lines[..lines.len() - 1].join("\n") + "\n").unwrap();
    let first = stdout(&mut analyze(&session, &out));
    assert!(first.contains("2 shot(s) listed, 2 measured now"), "{first}");
    std::fs::write(&csv_path, full).unwrap();
    let second = stdout(&mut analyze(&session, &out));
    assert!(
        second.contains("3 shot(s) listed, 1 measured now, 2 reused"),
        "{second}"
    );
}

#[cfg(unix)]
#[test]
fn killed_with_sigkill_it_resumes_without_losing_or_duplicating_a_shot() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let out = dir.path().join("out");
    let store = out.with_extension("sqlite");
    let bin = assert_cmd::cargo::cargo_bin("bouncelab");
    // Kill it as soon as the store holds a first estimated shot (or after 20 s, whichever is first).
    let mut child = std::process::Command::new(&bin)
        .arg("analyze")
        .arg(&session)
        .arg("--out")
        .arg(&out)
        .arg("--store")
        .arg(&store)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    loop {
        let done = bouncelab_store::Store::open(&store)
            .ok()
            .and_then(|s| {
                let id = s.sessions().ok()?.first()?.id;
                Some(s.estimates(id).ok()?.len())
            })
            .unwrap_or(0);
        if done >= 1 || started.elapsed().as_secs() > 20 || child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().ok(); // SIGKILL
    child.wait().unwrap();
    let s = stdout(&mut analyze(&session, &out));
    assert!(s.contains("3 shot(s) listed"), "{s}");
    assert!(s.contains("0 failed"), "{s}");
    let store = bouncelab_store::Store::open(&store).unwrap();
    assert!(store.integrity_check().unwrap());
    let id = store.sessions().unwrap()[0].id;
    assert_eq!(store.shots(id).unwrap().len(), 3);
    assert_eq!(store.estimates(id).unwrap().len(), 3);
    assert_eq!(store.sessions().unwrap().len(), 1);
}

/// One line on stderr naming `needle`, exit 1.
fn fails_naming(c: &mut Command, needle: &str) {
    let out = c
        .assert()
        .code(1)
        .stderr(predicate::str::contains(needle))
        .get_output()
        .clone();
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn session_faults_exit_1_with_a_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");

    let session = copy_session(&dir.path().join("a"));
    std::fs::remove_file(session.join("session.toml")).unwrap();
    fails_naming(&mut analyze(&session, &out), "session.toml");

    let session = copy_session(&dir.path().join("b"));
    std::fs::write(session.join("session.toml"), "[ball\ndiameter_m = 0.067").unwrap();
    fails_naming(&mut analyze(&session, &out), "session.toml");

    let session = copy_session(&dir.path().join("c"));
    std::fs::remove_file(session.join("clips.csv")).unwrap();
    fails_naming(&mut analyze(&session, &out), "clips.csv");

    let session = copy_session(&dir.path().join("d"));
    std::fs::write(session.join("clips.csv"), "clip,surface,angle_deg\nx,clay,0\n").unwrap();
    fails_naming(&mut analyze(&session, &out), "drop_height_m");

    let session = copy_session(&dir.path().join("e"));
    let csv = std::fs::read_to_string(session.join("clips.csv")).unwrap();
    std::fs::write(session.join("clips.csv"), csv + "ghost_clip,clay,0,0.3,1\n").unwrap();
    fails_naming(&mut analyze(&session, &out), "ghost_clip");

    let session = copy_session(&dir.path().join("f"));
    let toml = std::fs::read_to_string(session.join("session.toml")).unwrap();
    std::fs::write(session.join("session.toml"), toml.replace("fps = 10000", "fps = -3")).unwrap();
    fails_naming(&mut analyze(&session, &out), "fps");

    fails_naming(
        &mut analyze(&dir.path().join("no_such_session"), &out),
        "no_such_session",
    );
}

#[test]
fn a_clip_without_a_ball_fails_alone_and_the_rest_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let out = dir.path().join("out");
    // A fourth clip: the first clip's frames, all black.
    let first = std::fs::read_dir(&session)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .min()
        .unwrap();
    let dark = session.join("dark_clip");
    std::fs::create_dir_all(&dark).unwrap();
    for e in std::fs::read_dir(&first).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "png") {
            let img = image::open(&p).unwrap().to_luma8();
            image::GrayImage::new(img.width(), img.height())
                .save(dark.join(p.file_name().unwrap()))
                .unwrap();
        }
    }
    let csv = std::fs::read_to_string(session.join("clips.csv")).unwrap();
    let cols = csv.lines().next().unwrap().split(',').count();
    let extra = ",".repeat(cols - 4);
    std::fs::write(session.join("clips.csv"), format!("{csv}dark_clip,clay,0,0.3{extra}\n")).unwrap();
    fails_naming(&mut analyze(&session, &out), "dark_clip");
    let estimates = std::fs::read_to_string(out.join("estimates.csv")).unwrap();
    assert_eq!(
        estimates.lines().count(),
        4,
        "the three good shots are written:\n{estimates}"
    );
}

/// When no shot can be measured, what was measured is still written: the trajectories, an estimates.csv
/// without rows, and a report giving each shot's reason and how far it got (exit 1).
#[test]
fn when_every_shot_fails_the_trajectories_and_a_report_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let out = dir.path().join("out");
    // Only the first 40 frames of each clip: the ball never reaches the surface.
    let clips: Vec<PathBuf> = std::fs::read_dir(&session)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    for clip in &clips {
        let mut frames: Vec<PathBuf> = std::fs::read_dir(clip).unwrap().map(|e| e.unwrap().path()).collect();
        frames.sort();
        for f in frames.iter().skip(40) {
            std::fs::remove_file(f).unwrap();
        }
    }
    fails_naming(&mut analyze(&session, &out), "none of the 3 shot(s) could be measured");
    let estimates = std::fs::read_to_string(out.join("estimates.csv")).unwrap();
    assert_eq!(estimates.lines().count(), 1, "a header only:\n{estimates}");
    for clip in &clips {
        let name = clip.file_name().unwrap().to_string_lossy().into_owned();
        let t = std::fs::read_to_string(out.join("trajectories").join(format!("{name}.csv"))).unwrap();
        assert_eq!(t.lines().count(), 41, "{name}");
    }
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        html.contains("no impact in the clip") && html.contains("ball measured in 40 of 40 frames"),
        "{html}"
    );
}

#[test]
fn text_from_input_files_is_escaped_in_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let session = copy_session(dir.path());
    let out = dir.path().join("out");
    let csv_path = session.join("clips.csv");
    let csv = std::fs::read_to_string(&csv_path).unwrap();
    // The first clip's surface becomes a script; the session gets a description with markup.
    let mut lines: Vec<String> = csv.lines().map(str::to_string).collect();
    let cells: Vec<&str> = lines[1].split(',').collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let k = header.iter().position(|h| *h == "surface").unwrap();
    let mut changed: Vec<String> = cells.iter().map(|c| c.to_string()).collect();
    changed[k] = "<script>alert(1)</script>".into();
    lines[1] = changed.join(",");
    std::fs::write(&csv_path, lines.join("\n") + "\n").unwrap();
    let toml = std::fs::read_to_string(session.join("session.toml")).unwrap();
    let toml: Vec<String> = toml
        .lines()
        .map(|l| {
            if l.starts_with("description = ") {
                r#"description = "a <b>bold</b> & \"quoted\" session""#.to_string()
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(session.join("session.toml"), toml.join("\n") + "\n").unwrap();
    analyze(&session, &out).assert().success();
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(!html.contains("<script>alert(1)"), "the surface name must be escaped");
    assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(!html.contains("<b>bold</b>"));
    assert!(html.contains("&lt;b&gt;bold&lt;/b&gt; &amp;"));
}
