//! The building blocks every section writes with: the shared context (surface colours and markers, shot
//! anchors, figure numbers), tables, the facts table and the one line of a missing section. The sections
//! depend on this module and the page on the sections, never the reverse.

use std::collections::BTreeMap;
use std::fmt::Write;

use crate::data::{Report, Section};
use crate::fmt::{esc, fixed, slug};
use crate::svg::{Chart, Shape};

/// Okabe–Ito colours (distinguishable with the common colour-vision deficiencies), yellow last.
const PALETTE: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#C9B800",
];

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

/// The change from `before` to `after` in percent as table-cell HTML: a fall marked good, a rise bad.
pub(crate) fn change_pct(before: f64, after: f64) -> String {
    let c = 100.0 * (after - before) / before;
    if c.is_finite() {
        let class = if c < 0.0 {
            "good"
        } else if c > 0.0 {
            "bad"
        } else {
            ""
        };
        let sign = if c > 0.0 { "+" } else { "" };
        format!(r#"<span class="{class}">{sign}{}</span>"#, fixed(c, 1))
    } else {
        "—".into()
    }
}
