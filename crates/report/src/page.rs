//! The page: skeleton, style and script, the header and contents, and the sections in their order (each
//! written by its own module with the building blocks of `html.rs`).

use std::fmt::Write;

use crate::data::Report;
use crate::fmt::esc;
use crate::html::{Ctx, nc, section_or, table, tc, unavailable};
use crate::{SECTIONS, change, cor, diagnosis, fit, shots, stats, summary};

const STYLE: &str = r#"
:root{--fg:#1a1a1a;--muted:#5f6368;--line:#dcdcdc}
body{font:15px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"Helvetica Neue",Arial,sans-serif;color:var(--fg);background:#fff;max-width:1240px;margin:0 auto;padding:0 20px 48px}
p,li{max-width:900px}
h1{font-size:1.75em;margin:.9em 0 .2em}
h2{font-size:1.35em;border-bottom:2px solid var(--line);padding-bottom:.15em;margin:2.2em 0 .6em}
h3{font-size:1.08em;margin:1.5em 0 .4em}
a{color:#0b5fa5}
p.lead{font-size:1.08em;margin:.2em 0 1em;color:#333}
table{border-collapse:collapse;margin:.5em 0 1em;font-size:.9em}
th,td{padding:3px 10px;border-bottom:1px solid var(--line);text-align:left;vertical-align:top}
th{background:#f4f5f6;font-weight:600}
td a,.tag{white-space:nowrap}
td.n,th.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
td.wide{min-width:18em;white-space:normal}
.se{color:var(--muted);font-size:.86em}
td .se{margin-left:.15em}
table.quantities td.n{min-width:7em}
table.stacked td .se{display:block;margin-left:0}
table.stacked th{white-space:normal;vertical-align:bottom}
table.stacked td.wide{min-width:14em}
tr.total td{font-weight:600;border-top:1.5px solid #999}
table.facts th{background:none;font-weight:normal;color:var(--muted);padding-left:0}
.scroll{overflow-x:auto}
figure{margin:1.2em 0}
figcaption{color:var(--muted);font-size:.88em;max-width:780px;margin-top:.3em}
svg{max-width:100%;height:auto;display:block}
.figrow{display:flex;flex-wrap:wrap;gap:8px 16px;align-items:flex-start}
.na{color:var(--muted);font-style:italic}
.sw{display:inline-block;width:.75em;height:.75em;border-radius:2px;margin-right:.35em;vertical-align:-.04em}
.verdict{border-left:6px solid #999;background:#f6f6f6;padding:.7em 1.1em;margin:1em 0 1.2em}
.verdict p{margin:.15em 0}
.verdict .kind{font-weight:700;font-size:1.3em}
.verdict .text{font-size:1.1em}
.v-missing_effect{border-color:#E69F00;background:#fff7e8}
.v-no_missing_effect{border-color:#009E73;background:#eef9f4}
.v-no_candidate_explains{border-color:#D55E00;background:#fdf1ec}
.v-ambiguous{border-color:#D55E00;background:#fdf1ec}
.good{color:#007a5a}.bad{color:#b34700}
ul.warnings li{margin:.15em 0}
details.shot{border:1px solid var(--line);border-radius:5px;margin:.45em 0;padding:.15em .9em}
details.shot[open]{padding-bottom:.8em}
details.shot>summary{cursor:pointer;padding:.35em 0}
details.shot:target{outline:2px solid #0b5fa5}
.tag{font-size:.78em;padding:.05em .45em;border-radius:3px;background:#eee;margin-left:.5em}
.tag.worst{background:#fde2d5}.tag.best{background:#d6f0e2}
.notes{color:var(--muted);font-size:.92em}
.strip{display:flex;flex-wrap:wrap;gap:6px;margin:.4em 0 .6em}
.strip figure{margin:0;max-width:100%}
.strip img{display:block;max-width:100%;height:auto;border:1px solid var(--line)}
.strip figcaption{font-size:.8em}
nav ol{columns:2;max-width:640px;padding-left:1.4em}
footer{margin-top:3em;color:var(--muted);font-size:.85em;border-top:1px solid var(--line);padding-top:.6em}
@media print{nav,#shot-selector{display:none}details.shot,figure{break-inside:avoid}}
"#;

/// Opens the `<details>` a fragment points at (browsers without this still show the summary line), and
/// shows the shot selector, which is useless without script.
const SCRIPT: &str = r#"
(function(){
  function openTarget(){
    var id=decodeURIComponent(location.hash.slice(1));
    var e=id?document.getElementById(id):null;
    if(e&&e.tagName==='DETAILS'){e.open=true;e.scrollIntoView();}
  }
  window.addEventListener('hashchange',openTarget);
  openTarget();
  var box=document.getElementById('shot-selector'), sel=document.getElementById('shot-select');
  if(box&&sel){
    box.hidden=false;
    sel.addEventListener('change',function(){if(sel.value){location.hash=sel.value;}});
  }
})();
"#;

fn heading(id: &str) -> &'static str {
    SECTIONS.iter().find(|s| s.0 == id).map_or("", |s| s.1)
}

fn open_section(out: &mut String, id: &str) {
    let _ = write!(out, "<section id=\"{id}\">\n<h2>{}</h2>\n", heading(id));
}

fn header(ctx: &Ctx) -> String {
    let r = ctx.report;
    let si = &r.session;
    let mut s = format!("<header>\n<h1>{}</h1>\n", esc(title(r)));
    if !si.description.trim().is_empty() {
        let _ = writeln!(s, r#"<p class="lead">{}</p>"#, esc(&si.description));
    }
    let mut facts: Vec<(String, String)> = vec![
        (
            "Session".into(),
            if si.path.is_empty() {
                "—".into()
            } else {
                format!("<code>{}</code>", esc(&si.path))
            },
        ),
        (
            "Shots".into(),
            format!(
                "{} in the session, {} measured, {} fitted",
                si.shots,
                r.measurements.len(),
                r.shots.len()
            ),
        ),
    ];
    if !ctx.surfaces.is_empty() {
        let list: Vec<String> = ctx.surfaces.iter().map(|s| ctx.surface_cell(s)).collect();
        facts.push(("Surfaces".into(), list.join(", ")));
    }
    for (k, v) in &si.metadata {
        facts.push((esc(k), esc(v)));
    }
    if !si.generated_by.is_empty() {
        facts.push(("Generated by".into(), esc(&si.generated_by)));
    }
    if let Some(at) = &si.generated_at {
        facts.push(("Generated".into(), esc(at)));
    }
    s.push_str(r#"<table class="facts"><tbody>"#);
    for (k, v) in facts {
        let _ = write!(s, "<tr><th>{k}</th><td>{v}</td></tr>");
    }
    s.push_str("</tbody></table>\n</header>\n");
    s
}

fn title(r: &Report) -> &str {
    if r.title.trim().is_empty() {
        "bouncelab session report"
    } else {
        &r.title
    }
}

fn nav() -> String {
    let mut s = String::from("<nav aria-label=\"Contents\"><ol>");
    for (id, h) in SECTIONS {
        let _ = write!(s, r##"<li><a href="#{id}">{h}</a></li>"##);
    }
    s.push_str("</ol></nav>\n");
    s
}

fn warnings(r: &Report) -> String {
    let shared = crate::shots::shared_notes(r);
    let mut s = String::new();
    if r.warnings.is_empty() {
        s.push_str("<p>No warnings were raised by this run.</p>\n");
    } else {
        s.push_str("<ul class=\"warnings\">");
        for w in &r.warnings {
            let _ = write!(s, "<li>{}</li>", esc(w));
        }
        s.push_str("</ul>\n");
    }
    if !shared.is_empty() {
        let _ = write!(
            s,
            "<h3>Notes on every shot</h3>\n<p>Each of the {} shots carries these notes; they are said once here \
             and left out of the shots' own notes.</p>\n<ul>",
            r.shots.len()
        );
        for n in &shared {
            let _ = write!(s, "<li>{}</li>", esc(n));
        }
        s.push_str("</ul>\n");
    }
    s
}

fn timings(r: &Report) -> String {
    if r.timings.is_empty() {
        return unavailable("no stage timings were recorded");
    }
    let total: f64 = r.timings.iter().map(|t| t.1).filter(|v| v.is_finite()).sum();
    let mut rows: Vec<Vec<String>> = r
        .timings
        .iter()
        .map(|(name, secs)| {
            let share = if total > 0.0 && secs.is_finite() {
                crate::fmt::fixed(100.0 * secs / total, 1)
            } else {
                "—".into()
            };
            vec![esc(name), crate::fmt::num(*secs, 3), share]
        })
        .collect();
    rows.push(vec!["\u{0}Total".into(), crate::fmt::num(total, 3), "100.0".into()]);
    table(&[tc("Stage"), nc("Time (s)"), nc("Share (%)")], &rows)
}

/// The whole page.
pub(crate) fn render(report: &Report) -> String {
    let mut ctx = Ctx::new(report);
    let mut out = String::with_capacity(64 * 1024 + report.shots.len() * 16 * 1024);
    out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    out.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    if !report.session.generated_by.is_empty() {
        let _ = writeln!(
            out,
            "<meta name=\"generator\" content=\"{}\">",
            esc(&report.session.generated_by)
        );
    }
    let _ = write!(
        out,
        "<title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n",
        esc(title(report))
    );
    out.push_str(&header(&ctx));
    out.push_str(&nav());
    out.push_str("<main>\n");
    for (id, _) in SECTIONS {
        open_section(&mut out, id);
        let body = match *id {
            "summary" => summary::render(&mut ctx),
            "warnings" => warnings(report),
            "diagnosis" => section_or(&report.diagnosis, |d| diagnosis::render(&mut ctx, d)),
            "model-change" => section_or(&report.model_change, |c| change::render(&mut ctx, c)),
            "fit" => section_or(&report.fit, |f| fit::render(&mut ctx, f)),
            "cor" => cor::render(&mut ctx),
            "ancova" => stats::ancova_section(&ctx),
            "comparisons" => section_or(&report.inference, |i| stats::comparisons(&mut ctx, i)),
            "residual-diagnostics" => section_or(&report.ancova, |a| stats::diagnostics(&mut ctx, a)),
            "shots" => shots::render(&mut ctx),
            "timings" => timings(report),
            _ => String::new(),
        };
        out.push_str(&body);
        out.push_str("</section>\n");
    }
    out.push_str("</main>\n<footer>");
    if !report.session.generated_by.is_empty() {
        let _ = write!(out, "Generated by {}. ", esc(&report.session.generated_by));
    }
    out.push_str("This file is self-contained: it loads nothing from the network and reads without script.</footer>\n");
    let _ = write!(out, "<script>{SCRIPT}</script>\n</body>\n</html>\n");
    out
}
