//! The report in a real browser: headless Chromium loads the sample and the hostile report from disk,
//! runs the page's script, and must log nothing to the console (no script error, no blocked or missing
//! resource, no injected markup running); its DOM must hold every section and the plots.
//!
//! Ignored by default (it needs a browser): `cargo test -p bouncelab-report -- --ignored`, with Debian's
//! `chromium` on the PATH or its path in `BOUNCELAB_CHROMIUM`. CI installs it (`.ci/run`).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use bouncelab_report::testutil::{hostile_report, sample_report};
use bouncelab_report::{Report, SECTIONS, write_report};

fn chromium() -> PathBuf {
    if let Some(p) = std::env::var_os("BOUNCELAB_CHROMIUM") {
        return PathBuf::from(p);
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    for name in ["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"] {
        for dir in std::env::split_paths(&path) {
            let p = dir.join(name);
            if p.is_file() {
                return p;
            }
        }
    }
    panic!("no Chromium found: install Debian's `chromium` or set BOUNCELAB_CHROMIUM");
}

/// Runs headless Chromium on `page` with `args`; returns (stdout, stderr). Killed after two minutes.
fn run_chromium(page: &Path, profile: &Path, args: &[&str]) -> (String, String) {
    let out_dir = profile.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    let (stdout_path, stderr_path) = (out_dir.join("stdout"), out_dir.join("stderr"));
    let mut child = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-extensions",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=5000",
        ])
        .arg(format!("--user-data-dir={}", profile.join("profile").display()))
        .args(args)
        .arg(format!("file://{}", page.display()))
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&stdout_path).unwrap())
        .stderr(std::fs::File::create(&stderr_path).unwrap())
        .spawn()
        .expect("start chromium");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "chromium exited with {status}");
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish in two minutes");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    (
        std::fs::read_to_string(stdout_path).unwrap(),
        std::fs::read_to_string(stderr_path).unwrap(),
    )
}

/// Console messages in Chromium's log: lines like `[…:INFO:CONSOLE:12] "message", source: … (12)`.
fn console_messages(stderr: &str) -> Vec<&str> {
    stderr
        .lines()
        .filter(|l| l.contains(":CONSOLE") || l.contains("Uncaught"))
        .collect()
}

fn check_in_browser(report: &Report, name: &str, figures: usize) {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join(format!("{name}.html"));
    write_report(&page, report).unwrap();
    let (dom, log) = run_chromium(&page, dir.path(), &["--dump-dom"]);
    let console = console_messages(&log);
    assert!(console.is_empty(), "{name}: console messages:\n{}", console.join("\n"));
    assert!(dom.contains("</html>"), "{name}: no DOM dumped; log:\n{log}");
    for (id, heading) in SECTIONS {
        assert!(
            dom.contains(&format!("<section id=\"{id}\">")),
            "{name}: section {id} missing from the DOM"
        );
        assert!(dom.contains(heading), "{name}: heading {heading} missing from the DOM");
    }
    let svgs = dom.matches("<svg").count();
    assert!(
        svgs >= figures,
        "{name}: {svgs} plots in the DOM, expected at least {figures}"
    );
    // The script ran: the shot selector is shown when there are shots.
    if !report.shots.is_empty() {
        assert!(
            dom.contains("<p id=\"shot-selector\">"),
            "{name}: the selector script did not run"
        );
    }
    // Injected markup did not become elements.
    assert!(
        !dom.contains("<script>alert") && !dom.contains("<img"),
        "{name}: input text became markup"
    );
}

#[test]
#[ignore = "needs a headless Chromium; run with --ignored"]
fn reports_load_in_headless_chromium_without_console_errors() {
    // The check catches errors: a page with a script error logs to the console.
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.html");
    std::fs::write(&bad, "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>x</title></head><body><script>nosuch();</script></body></html>").unwrap();
    let (_, log) = run_chromium(&bad, dir.path(), &["--dump-dom"]);
    assert!(
        !console_messages(&log).is_empty(),
        "a script error is not seen in the log:\n{log}"
    );

    let sample = sample_report();
    // 24 shots × 4 panels, the bar charts, COR, Tukey, diagnostics, oblique.
    check_in_browser(&sample, "sample", 24 * 4 + 8);
    check_in_browser(&hostile_report(), "hostile", 5);
    check_in_browser(&Report::default(), "empty", 0);

    // A screenshot renders (useful to look at: BOUNCELAB_SCREENSHOT=path.png keeps it).
    let page = dir.path().join("sample.html");
    write_report(&page, &sample).unwrap();
    let png = match std::env::var_os("BOUNCELAB_SCREENSHOT") {
        Some(p) => PathBuf::from(p),
        None => dir.path().join("sample.png"),
    };
    let (_, log) = run_chromium(
        &page,
        dir.path(),
        &[&format!("--screenshot={}", png.display()), "--window-size=1200,4000"],
    );
    let bytes = std::fs::read(&png).unwrap_or_else(|e| panic!("no screenshot ({e}); log:\n{log}"));
    assert!(
        bytes.starts_with(b"\x89PNG") && bytes.len() > 50_000,
        "screenshot of {} bytes",
        bytes.len()
    );
}
