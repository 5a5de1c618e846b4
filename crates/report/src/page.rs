//! The page: skeleton, style, shared context (surface colours, shot anchors, figure numbers) and small
//! HTML helpers used by the sections.

use std::collections::BTreeMap;
use std::fmt::Write;

use crate::data::{Report, Section};
use crate::fmt::{esc, slug};
use crate::svg::{Chart, Shape};
use crate::{SECTIONS, change, cor, diagnosis, fit, shots, stats, summary};

/// Okabe–Ito colours (distinguishable with the common colour-vision deficiencies), yellow last.
pub(crate) const PALETTE: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#C9B800",
];

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

/// What the sections share while the page is written.
pub(crate) struct Ctx<'a> {
    pub report: &'a Report,
    /// Surfaces in display order.
    pub surfaces: Vec<String>,
    /// Clip name → anchor id of its shot (first shot of that name).
    anchors: BTreeMap<String, String>,
    /// Anchor id per shot, by index in `report.shots`.
    pub shot_ids: Vec<String>,
    figures: usize,
}

impl<'a> Ctx<'a> {
    pub(crate) fn new(report: &'a Report) -> Ctx<'a> {
        let mut surfaces: Vec<String> = Vec::new();
        for s in &report.session.surfaces {
            if !surfaces.contains(s) {
                surfaces.push(s.clone());
            }
        }
        let mut extra: Vec<&String> = report
            .shots
            .iter()
            .map(|s| &s.surface)
            .chain(report.measurements.iter().map(|c| &c.surface))
            .chain(
                report
                    .fit
                    .get()
                    .into_iter()
                    .flat_map(|f| f.by_surface.iter().map(|s| &s.surface)),
            )
            .filter(|s| !surfaces.contains(s))
            .collect();
        extra.sort();
        extra.dedup();
        surfaces.extend(extra.into_iter().cloned());

        let mut anchors = BTreeMap::new();
        let mut used: BTreeMap<String, usize> = BTreeMap::new();
        let mut shot_ids = Vec::with_capacity(report.shots.len());
        for shot in &report.shots {
            let base = format!("shot-{}", slug(&shot.clip));
            let n = used.entry(base.clone()).or_insert(0);
            *n += 1;
            let id = if *n == 1 { base } else { format!("{base}-{n}") };
            anchors.entry(shot.clip.clone()).or_insert_with(|| id.clone());
            shot_ids.push(id);
        }
        Ctx {
            report,
            surfaces,
            anchors,
            shot_ids,
            figures: 0,
        }
    }

    /// Colour and marker of a surface.
    pub(crate) fn style(&self, surface: &str) -> (&'static str, Shape) {
        let i = self.surfaces.iter().position(|s| s == surface).unwrap_or(0);
        (
            PALETTE[i % PALETTE.len()],
            Shape::ALL[(i + i / PALETTE.len()) % Shape::ALL.len()],
        )
    }

    /// Anchor id of the shot called `clip`, if it is in the report.
    pub(crate) fn shot_href(&self, clip: &str) -> Option<String> {
        self.anchors.get(clip).cloned()
    }

    /// A link to the shot's plot, or the escaped name when there is none.
    pub(crate) fn clip_link(&self, clip: &str) -> String {
        match self.shot_href(clip) {
            Some(id) => format!(r##"<a href="#{}">{}</a>"##, esc(&id), esc(clip)),
            None => esc(clip),
        }
    }

    /// A surface name with its colour swatch.
    pub(crate) fn surface_cell(&self, surface: &str) -> String {
        let (color, _) = self.style(surface);
        format!(r#"<span class="sw" style="background:{color}"></span>{}"#, esc(surface))
    }

    /// The next figure number and a fresh chart id.
    pub(crate) fn next_figure(&mut self) -> (usize, String) {
        self.figures += 1;
        (self.figures, format!("fig{}", self.figures))
    }

    /// A numbered figure holding the charts side by side; `caption` is HTML (escape input text in it).
    pub(crate) fn figure(&mut self, n: usize, charts: &[Chart], caption: &str) -> String {
        let mut s = format!(r#"<figure id="figure-{n}"><div class="figrow">"#);
        let mut dropped = 0;
        for c in charts {
            let r = c.render();
            dropped += r.dropped;
            s.push_str(&r.svg);
        }
        let _ = write!(s, "</div><figcaption><b>Figure {n}.</b> {caption}");
        if dropped > 0 {
            let _ = write!(
                s,
                " ({dropped} non-finite value{} not drawn.)",
                if dropped == 1 { "" } else { "s" }
            );
        }
        s.push_str("</figcaption></figure>\n");
        s
    }
}

/// One table column: heading (HTML) and its cells' class ("n": numbers, right-aligned; "wide": free text
/// that wraps at a readable width; "": plain text).
pub(crate) struct Col {
    pub head: String,
    pub class: &'static str,
}

/// A text column.
pub(crate) fn tc(head: &str) -> Col {
    Col {
        head: head.into(),
        class: "",
    }
}

/// A numeric column.
pub(crate) fn nc(head: &str) -> Col {
    Col {
        head: head.into(),
        class: "n",
    }
}

/// A column of sentences (notes): wraps at a readable width instead of one word per line.
pub(crate) fn wc(head: &str) -> Col {
    Col {
        head: head.into(),
        class: "wide",
    }
}

/// A table; cells are HTML (escape input text in them). A row whose first cell starts with `\u{0}` is a
/// total row (the marker is removed).
pub(crate) fn table(cols: &[Col], rows: &[Vec<String>]) -> String {
    table_with_class("", cols, rows)
}

/// [`table`] with a class on the `<table>` element.
pub(crate) fn table_with_class(class: &str, cols: &[Col], rows: &[Vec<String>]) -> String {
    let mut s = if class.is_empty() {
        String::from(r#"<div class="scroll"><table><thead><tr>"#)
    } else {
        format!(r#"<div class="scroll"><table class="{class}"><thead><tr>"#)
    };
    for c in cols {
        let _ = write!(s, "<th{}>{}</th>", cell_class(c.class), c.head);
    }
    s.push_str("</tr></thead><tbody>");
    for row in rows {
        let total = row.first().is_some_and(|c| c.starts_with('\u{0}'));
        s.push_str(if total { r#"<tr class="total">"# } else { "<tr>" });
        for (i, cell) in row.iter().enumerate() {
            let cell = if i == 0 { cell.trim_start_matches('\u{0}') } else { cell };
            let class = cols.get(i).map_or("", |c| c.class);
            let _ = write!(s, "<td{}>{cell}</td>", cell_class(class));
        }
        s.push_str("</tr>");
    }
    s.push_str("</tbody></table></div>\n");
    s
}

fn cell_class(class: &str) -> String {
    if class.is_empty() {
        String::new()
    } else {
        format!(r#" class="{class}""#)
    }
}

/// A value and its standard error as table-cell HTML: the error smaller, after the value.
pub(crate) fn pm_cell(v: f64, se: Option<f64>, sig: usize) -> String {
    match crate::fmt::pm(v, se, sig) {
        (v, Some(e)) => format!(r#"{v}<span class="se">±{e}</span>"#),
        (v, None) => v,
    }
}

/// The facts table at the top of a section: (heading, value HTML) rows.
pub(crate) fn facts(rows: &[(String, String)]) -> String {
    let mut s = String::from(r#"<table class="facts"><tbody>"#);
    for (k, v) in rows {
        let _ = write!(s, "<tr><th>{k}</th><td>{v}</td></tr>");
    }
    s.push_str("</tbody></table>\n");
    s
}

/// The one line shown for a missing section.
pub(crate) fn unavailable(reason: &str) -> String {
    let reason = if reason.trim().is_empty() {
        "no reason given"
    } else {
        reason
    };
    format!("<p class=\"na\">not available: {}</p>\n", esc(reason))
}

/// The content of a section or its "not available" line.
pub(crate) fn section_or<T>(sec: &Section<T>, body: impl FnOnce(&T) -> String) -> String {
    match sec {
        Section::Available(t) => body(t),
        Section::Unavailable(reason) => unavailable(reason),
    }
}

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
