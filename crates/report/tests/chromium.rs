//! The report in a real browser: headless Chromium loads the sample and the hostile report from disk,
//! runs the page's script, and must log nothing to the console (no script error, no blocked or missing
//! resource, no injected markup running); its DOM must hold every section and the plots. At 1400 px wide,
//! with every collapsed block opened, no table or figure may run past the viewport or need a scroll bar,
//! and no section may be empty; a screenshot is taken.
//!
//! Ignored by default (it needs a browser): `cargo test -p bouncelab-report -- --ignored`, with Debian's
//! `chromium` on the PATH or its path in `BOUNCELAB_CHROMIUM`. CI installs it (`.ci/run`).
//!
//! `BOUNCELAB_REPORT_HTML=path/report.html` checks that page too (e.g. the demo's), and with
//! `BOUNCELAB_SCREENSHOT_DIR=dir` writes one screenshot per section of it there (`docs/report.md` shows
//! the demo's).

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

/// Width of the window the layout is checked at, px.
const WIDTH: u32 = 1400;

/// Appended to a copy of the page: opens every collapsed block, then lists what runs past the viewport or
/// needs a scroll bar, every section with (almost) no text, and each section's height, in a `<pre>`.
const LAYOUT_CHECK: &str = r#"<script>(function(){
  document.querySelectorAll('details').forEach(function(d){d.open=true;});
  var W=document.documentElement.clientWidth, out=[];
  var where=function(e){var s=e.closest('section');return s?s.id:'page';};
  document.querySelectorAll('table, figure, svg, .figrow, img, pre, p, ul').forEach(function(e){
    var r=e.getBoundingClientRect();
    if(r.width>0 && r.right>W+0.5){out.push('overflow '+e.tagName.toLowerCase()+' in '+where(e)+': right edge '+Math.round(r.right)+' > '+W);}
  });
  document.querySelectorAll('.scroll').forEach(function(e){
    if(e.scrollWidth>e.clientWidth+1){out.push('overflow table in '+where(e)+': '+e.scrollWidth+' px in '+e.clientWidth+' px');}
  });
  document.querySelectorAll('main > section').forEach(function(s){
    var h=s.querySelector('h2'), t=s.innerText.replace(h?h.innerText:'','').trim();
    if(t.length<20){out.push('empty '+s.id);}
    out.push('height '+s.id+' '+Math.ceil(s.getBoundingClientRect().height));
  });
  var p=document.createElement('pre');p.id='layout-check';p.textContent=out.join('\n');document.body.appendChild(p);
})();</script>"#;

/// The page's text with `extra` before `</body>`.
fn with_extra(html: &str, extra: &str) -> String {
    html.replacen("</body>", &format!("{extra}</body>"), 1)
}

/// Runs the layout check on `html` (written into `dir`): (problems, section heights in px).
fn layout(html: &str, dir: &Path, name: &str) -> (Vec<String>, Vec<(String, u32)>) {
    let page = dir.join(format!("{name}-layout.html"));
    std::fs::write(&page, with_extra(html, LAYOUT_CHECK)).unwrap();
    let size = format!("--window-size={WIDTH},3000");
    let (dom, log) = run_chromium(&page, dir, &["--dump-dom", &size]);
    let start = dom
        .find("<pre id=\"layout-check\">")
        .unwrap_or_else(|| panic!("{name}: the layout check did not run; log:\n{log}"));
    let text = &dom[start + "<pre id=\"layout-check\">".len()..];
    let text = &text[..text.find("</pre>").unwrap()];
    let mut problems = Vec::new();
    let mut heights = Vec::new();
    for line in text.lines() {
        match line.strip_prefix("height ") {
            Some(rest) => {
                let (id, h) = rest.rsplit_once(' ').unwrap();
                heights.push((id.to_string(), h.parse().unwrap()));
            }
            None => problems.push(line.replace("&gt;", ">")),
        }
    }
    (problems, heights)
}

/// One screenshot per section of the page at `page` into `out` (`NN-<id>.png`), the others hidden.
fn section_screenshots(html: &str, heights: &[(String, u32)], dir: &Path, out: &Path) {
    std::fs::create_dir_all(out).unwrap();
    for (k, (id, h)) in heights.iter().enumerate() {
        let style = format!(
            "<style>header,nav,footer,main>section:not(#{id}){{display:none}}details{{}}</style>\
             <script>document.querySelectorAll('#{id} details.shot').forEach(function(d,i){{d.open=i<1;}});</script>"
        );
        let page = dir.join(format!("section-{id}.html"));
        std::fs::write(&page, with_extra(html, &style)).unwrap();
        let png = out.join(format!("{:02}-{id}.png", k + 1));
        let size = format!("--window-size={WIDTH},{}", (h + 80).min(16_000));
        let shot = format!("--screenshot={}", png.display());
        let (_, log) = run_chromium(&page, dir, &[&shot, &size, "--hide-scrollbars"]);
        assert!(png.is_file(), "no screenshot of {id}; log:\n{log}");
    }
}

fn check_in_browser(report: &Report, name: &str, figures: usize) {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join(format!("{name}.html"));
    write_report(&page, report).unwrap();
    let html = std::fs::read_to_string(&page).unwrap();
    let (problems, _) = layout(&html, dir.path(), name);
    assert!(problems.is_empty(), "{name} at {WIDTH} px:\n{}", problems.join("\n"));
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

    // The layout check catches a table that runs past the viewport and an empty section.
    let wide = "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>x</title></head><body><main>\
         <section id=\"a\"><h2>A</h2><div class=\"scroll\" style=\"overflow-x:auto\"><table><tr>\
         <td style=\"min-width:3000px\">wide</td></tr></table></div></section>\
         <section id=\"b\"><h2>B</h2></section></main></body></html>";
    let (problems, _) = layout(wide, dir.path(), "wide");
    assert!(
        problems.iter().any(|p| p.starts_with("overflow table in a")),
        "{problems:?}"
    );
    assert!(problems.iter().any(|p| p == "empty b"), "{problems:?}");

    let sample = sample_report();
    // 24 shots × 4 panels, the bar charts, COR (4 panels and the incline), contact force (2), comparisons,
    // diagnostics, oblique.
    check_in_browser(&sample, "sample", 24 * 4 + 14);
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
        &[
            &format!("--screenshot={}", png.display()),
            &format!("--window-size={WIDTH},4000"),
        ],
    );
    let bytes = std::fs::read(&png).unwrap_or_else(|e| panic!("no screenshot ({e}); log:\n{log}"));
    assert!(
        bytes.starts_with(b"\x89PNG") && bytes.len() > 50_000,
        "screenshot of {} bytes",
        bytes.len()
    );
}

/// A report written by the pipeline (the demo's), when given: the same checks, and its sections' screenshots.
#[test]
#[ignore = "needs a headless Chromium and BOUNCELAB_REPORT_HTML; run with --ignored"]
fn a_given_report_lays_out_at_1400_px() {
    let Some(path) = std::env::var_os("BOUNCELAB_REPORT_HTML") else {
        eprintln!("BOUNCELAB_REPORT_HTML not set: nothing to check");
        return;
    };
    let html = std::fs::read_to_string(&path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (problems, heights) = layout(&html, dir.path(), "given");
    assert!(
        problems.is_empty(),
        "{} at {WIDTH} px:\n{}",
        PathBuf::from(&path).display(),
        problems.join("\n")
    );
    for (id, _) in SECTIONS {
        assert!(heights.iter().any(|(h, _)| h == id), "section {id} missing");
    }
    if let Some(out) = std::env::var_os("BOUNCELAB_SCREENSHOT_DIR") {
        section_screenshots(&html, &heights, dir.path(), Path::new(&out));
    }
}
