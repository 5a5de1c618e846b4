//! A small SVG chart writer: linear axes with nice ticks (or category labels), lines, markers, error
//! bars, bars, shaded bands, reference rules and a legend above the plot area.
//!
//! Written by hand rather than with plotters, after measuring plotters 0.3 (`svg_backend`, no font
//! feature). It does draw labelled axes without system font packages (its naive text layout is enough for
//! SVG), but: each marker is its own `<circle>` with five attributes, about 91 bytes, and a bare set of
//! axes about 6 KB, so 144 shots × three panels of a few hundred points came to several megabytes; an axis
//! range of ±1e308 made its tick search run for over 30 s (killed) where the report must never hang on
//! odd input; and it cannot attach a `<title>` tooltip or a link to a point, which the report uses to go
//! from a COR point or a bar to the shot's plot. Here a series of plain markers is one `<path>` of
//! zero-length round-capped segments (about 12 bytes per point), coordinates have one decimal, every
//! number is checked (non-finite or beyond ±1e300 is left out and counted), and all text is escaped.

use std::fmt::Write;

use crate::fmt::{coord, esc, push_coord};
use crate::thin::simplify;

/// Values beyond this magnitude are treated like NaN: not drawn, counted.
const LIMIT: f64 = 1e300;
/// Tick label font size, px.
const FONT: f64 = 11.0;
/// Average glyph width of a sans-serif font, in font sizes (for layout only).
const GLYPH: f64 = 0.6;

fn usable(v: f64) -> bool {
    v.is_finite() && v.abs() <= LIMIT
}

/// The chart's own label text (never input text) escaped, with `_{…}` set as a subscript.
fn rich(s: &str) -> String {
    let mut out = String::new();
    let mut rest = s;
    while let Some(i) = rest.find("_{") {
        out.push_str(&esc(&rest[..i]));
        let after = &rest[i + 2..];
        match after.find('}') {
            Some(j) => {
                let _ = write!(
                    out,
                    r#"<tspan baseline-shift="sub" font-size="75%">{}</tspan>"#,
                    esc(&after[..j])
                );
                rest = &after[j + 1..];
            }
            None => {
                out.push_str(&esc(&rest[i..]));
                rest = "";
            }
        }
    }
    out.push_str(&esc(rest));
    out
}

/// [`rich`] text as plain text.
fn plain(s: &str) -> String {
    s.replace("_{", "").replace('}', "")
}

fn text_width(s: &str, size: f64) -> f64 {
    s.chars().count() as f64 * size * GLYPH
}

/// Marker shapes (colour is not the only cue: each surface also gets its own shape).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Shape {
    Circle,
    Square,
    Diamond,
    Triangle,
}

impl Shape {
    pub(crate) const ALL: [Shape; 4] = [Shape::Circle, Shape::Square, Shape::Diamond, Shape::Triangle];
}

/// One marker; `tip` is plain text (escaped here), `href` a fragment id already made safe by `slug`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Mark {
    pub x: f64,
    pub y: f64,
    pub tip: Option<String>,
    pub href: Option<String>,
}

impl Mark {
    pub(crate) fn at(x: f64, y: f64) -> Mark {
        Mark {
            x,
            y,
            ..Mark::default()
        }
    }
}

/// An error bar around (x, y); the ends are absolute data values.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ErrorBar {
    pub x: f64,
    pub y: f64,
    pub x_span: Option<(f64, f64)>,
    pub y_span: Option<(f64, f64)>,
}

/// A bar from (x0, y0) to (x1, y1) in data coordinates.
#[derive(Debug, Clone, Default)]
pub(crate) struct Bar {
    pub x0: f64,
    pub x1: f64,
    pub y0: f64,
    pub y1: f64,
    pub color: &'static str,
    pub tip: Option<String>,
    pub href: Option<String>,
}

/// Something drawn inside the plot area.
#[derive(Debug, Clone)]
pub(crate) enum Item {
    Line {
        pts: Vec<(f64, f64)>,
        color: &'static str,
        width: f64,
        dash: bool,
    },
    Marks {
        marks: Vec<Mark>,
        color: &'static str,
        shape: Shape,
        size: f64,
    },
    ErrorBars {
        bars: Vec<ErrorBar>,
        color: &'static str,
    },
    Bars {
        bars: Vec<Bar>,
    },
    /// A band over the full height between two x values (not part of the x range).
    XBand {
        x0: f64,
        x1: f64,
        fill: &'static str,
    },
    /// A band over the full width between two y values (part of the y range).
    YBand {
        y0: f64,
        y1: f64,
        fill: &'static str,
    },
    /// A horizontal line at y (not part of the y range).
    HRule {
        y: f64,
        color: &'static str,
        dash: bool,
    },
    /// A vertical line at x (not part of the x range).
    VRule {
        x: f64,
        color: &'static str,
        dash: bool,
    },
}

/// The glyph of a legend entry.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Key {
    Line { color: &'static str, dash: bool },
    Mark { color: &'static str, shape: Shape },
    Swatch { fill: &'static str },
}

/// A chart; fill the fields, then [`Chart::render`].
#[derive(Debug, Clone)]
pub(crate) struct Chart {
    /// Unique in the page (prefix of the clip path's id).
    pub id: String,
    pub width: f64,
    pub height: f64,
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// Fixed x range (no padding); `None` fits the data.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    /// Values the y range must include (e.g. 0 for bars).
    pub y_include: Vec<f64>,
    pub x_include: Vec<f64>,
    /// If non-empty, the y axis is categorical: label i at y = i, the first at the top.
    pub y_categories: Vec<String>,
    /// Whether to draw x tick labels (off for an axis of shot indices).
    pub x_ticks: bool,
    pub items: Vec<Item>,
    pub legend: Vec<(String, Key)>,
}

impl Chart {
    pub(crate) fn new(id: impl Into<String>, width: f64, height: f64) -> Chart {
        Chart {
            id: id.into(),
            width,
            height,
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_range: None,
            y_range: None,
            y_include: Vec::new(),
            x_include: Vec::new(),
            y_categories: Vec::new(),
            x_ticks: true,
            items: Vec::new(),
            legend: Vec::new(),
        }
    }
}

/// A rendered chart and how many values could not be drawn.
pub(crate) struct Rendered {
    pub svg: String,
    pub dropped: usize,
}

/// A linear axis: its range and labelled ticks.
#[derive(Debug, Clone)]
pub(crate) struct Axis {
    pub lo: f64,
    pub hi: f64,
    pub ticks: Vec<(f64, String)>,
}

/// Makes `(lo, hi)` a usable range: finite, ordered, with a span that ticks can divide.
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let mid = lo / 2.0 + hi / 2.0;
    let min_span = (mid.abs() * 1e-9).max(1e-250);
    if hi - lo >= min_span {
        (lo, hi)
    } else {
        // All values (nearly) equal: a window of ±5% around them, ±1 around zero.
        let half = if mid.abs() < 1e-200 { 1.0 } else { mid.abs() * 0.05 };
        (mid - half, mid + half)
    }
}

/// A 1-2-2.5-5 step near `span / target`.
fn nice_step(span: f64, target: f64) -> f64 {
    let raw = span / target;
    if !(raw > 0.0 && raw.is_finite()) {
        return span;
    }
    let mag = 10f64.powf(raw.log10().floor());
    let n = raw / mag;
    let m = if n <= 1.0 {
        1.0
    } else if n <= 2.0 {
        2.0
    } else if n <= 2.5 {
        2.5
    } else if n <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * mag
}

fn tick_labels(ticks: &[f64], step: f64) -> Vec<String> {
    let max_abs = ticks.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let step_mag = step.log10().floor() as i32;
    let lead = step / 10f64.powi(step_mag);
    let extra = i32::from((lead - 2.5).abs() < 1e-9);
    let sci = max_abs >= 1e6 || (max_abs > 0.0 && max_abs < 1e-3) || step_mag < -6;
    ticks
        .iter()
        .map(|&t| {
            let t = if t.abs() < step * 1e-6 { 0.0 } else { t };
            let s = if t == 0.0 {
                "0".to_string()
            } else if sci {
                let prec = (t.abs().log10().floor() as i32 - step_mag + extra).clamp(0, 8) as usize;
                format!("{t:.prec$e}")
            } else {
                let dec = (extra - step_mag).clamp(0, 12) as usize;
                format!("{t:.dec$}")
            };
            if let Some(rest) = s.strip_prefix('-') {
                format!("\u{2212}{rest}")
            } else {
                s
            }
        })
        .collect()
}

impl Axis {
    /// An axis over `values` (unusable ones ignored), or over `fixed` as given; `nice` extends the range to
    /// whole ticks after a small padding.
    /// `target` is the wanted number of tick intervals.
    pub(crate) fn fit(
        values: impl IntoIterator<Item = f64>,
        fixed: Option<(f64, f64)>,
        nice: bool,
        target: f64,
    ) -> Axis {
        let (lo, hi) = match fixed.filter(|(a, b)| usable(*a) && usable(*b)) {
            Some((a, b)) => widen(a, b),
            None => {
                let mut ext: Option<(f64, f64)> = None;
                for v in values.into_iter().filter(|v| usable(*v)) {
                    ext = Some(ext.map_or((v, v), |(a, b)| (a.min(v), b.max(v))));
                }
                let (a, b) = widen(ext.map_or(0.0, |e| e.0), ext.map_or(1.0, |e| e.1));
                let pad = (b - a) * 0.04;
                // Data that stops at zero (bars, rates) keeps zero as the axis end.
                (if a == 0.0 { a } else { a - pad }, if b == 0.0 { b } else { b + pad })
            }
        };
        let step = nice_step(hi - lo, target.clamp(2.0, 12.0));
        let (lo, hi) = if nice && fixed.is_none() {
            let (a, b) = ((lo / step).floor() * step, (hi / step).ceil() * step);
            if a.is_finite() && b.is_finite() && b > a {
                (a, b)
            } else {
                (lo, hi)
            }
        } else {
            (lo, hi)
        };
        let (k0, k1) = ((lo / step - 1e-9).ceil(), (hi / step + 1e-9).floor());
        let ticks: Vec<f64> = if k0.is_finite() && k1.is_finite() && k1 >= k0 && k1 - k0 <= 50.0 {
            (0..=(k1 - k0) as i64).map(|i| (k0 + i as f64) * step).collect()
        } else {
            vec![lo, hi]
        };
        let step = if ticks.len() == 2 && ticks == [lo, hi] {
            hi - lo
        } else {
            step
        };
        let labels = tick_labels(&ticks, step);
        Axis {
            lo,
            hi,
            ticks: ticks.into_iter().zip(labels).collect(),
        }
    }

    /// Fraction 0–1 of `v` along the axis (may fall outside for values off the range).
    fn frac(&self, v: f64) -> f64 {
        let f = (v - self.lo) / (self.hi - self.lo);
        if f.is_finite() {
            f
        } else {
            v / (self.hi - self.lo) - self.lo / (self.hi - self.lo)
        }
    }
}

/// Pixel mapping of a chart's plot area.
struct Frame {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    xa: Axis,
    ya: Axis,
    /// y grows downward in data (categorical axis).
    y_down: bool,
}

impl Frame {
    fn px(&self, x: f64) -> f64 {
        self.x0 + self.xa.frac(x) * (self.x1 - self.x0)
    }
    fn py(&self, y: f64) -> f64 {
        let f = self.ya.frac(y);
        if self.y_down {
            self.y0 + f * (self.y1 - self.y0)
        } else {
            self.y1 - f * (self.y1 - self.y0)
        }
    }
}

fn marker_path(out: &mut String, shape: Shape, x: f64, y: f64, r: f64) {
    match shape {
        Shape::Circle | Shape::Square => {
            out.push('M');
            push_coord(out, x);
            out.push(' ');
            push_coord(out, y);
            out.push_str("h0");
        }
        Shape::Diamond => {
            let r = r * 1.25;
            let _ = write!(
                out,
                "M{} {}l{r2} {r2} -{r2} {r2} -{r2} -{r2}z",
                coord(x),
                coord(y - r),
                r2 = coord(r)
            );
        }
        Shape::Triangle => {
            let r = r * 1.2;
            let _ = write!(
                out,
                "M{} {}l{} {}h-{}z",
                coord(x),
                coord(y - r),
                coord(r),
                coord(1.73 * r),
                coord(2.0 * r)
            );
        }
    }
}

/// Attributes that draw a marker path of `shape` in `color`, `size` px across.
fn marker_style(shape: Shape, color: &str, size: f64) -> String {
    match shape {
        Shape::Circle => format!(
            r#"fill="none" stroke="{color}" stroke-width="{}" stroke-linecap="round""#,
            coord(size)
        ),
        Shape::Square => {
            format!(
                r#"fill="none" stroke="{color}" stroke-width="{}" stroke-linecap="square""#,
                coord(size * 0.85)
            )
        }
        Shape::Diamond | Shape::Triangle => format!(r#"fill="{color}" stroke="none""#),
    }
}

fn key_glyph(out: &mut String, key: Key, x: f64, y: f64) {
    match key {
        Key::Line { color, dash } => {
            let d = if dash { r#" stroke-dasharray="4 3""# } else { "" };
            let _ = write!(
                out,
                r#"<path d="M{} {}h18" stroke="{color}" stroke-width="2"{d}/>"#,
                coord(x),
                coord(y)
            );
        }
        Key::Mark { color, shape } => {
            let mut d = String::new();
            marker_path(&mut d, shape, x + 9.0, y, 3.5);
            let _ = write!(out, r#"<path d="{d}" {}/>"#, marker_style(shape, color, 7.0));
        }
        Key::Swatch { fill } => {
            let _ = write!(
                out,
                r##"<rect x="{}" y="{}" width="18" height="10" fill="{fill}" stroke="#999" stroke-width="0.5"/>"##,
                coord(x),
                coord(y - 5.0)
            );
        }
    }
}

impl Chart {
    fn x_values(&self) -> Vec<f64> {
        let mut v = self.x_include.clone();
        for item in &self.items {
            match item {
                Item::Line { pts, .. } => v.extend(pts.iter().map(|p| p.0)),
                Item::Marks { marks, .. } => v.extend(marks.iter().map(|m| m.x)),
                Item::ErrorBars { bars, .. } => {
                    for b in bars {
                        v.push(b.x);
                        if let Some((a, c)) = b.x_span.filter(|(a, c)| usable(*a) && usable(*c)) {
                            v.extend([a, c]);
                        }
                    }
                }
                Item::Bars { bars } => v.extend(bars.iter().flat_map(|b| [b.x0, b.x1])),
                Item::XBand { .. } | Item::YBand { .. } | Item::HRule { .. } | Item::VRule { .. } => {}
            }
        }
        v
    }

    fn y_values(&self) -> Vec<f64> {
        let mut v = self.y_include.clone();
        for item in &self.items {
            match item {
                Item::Line { pts, .. } => v.extend(pts.iter().map(|p| p.1)),
                Item::Marks { marks, .. } => v.extend(marks.iter().map(|m| m.y)),
                Item::ErrorBars { bars, .. } => {
                    for b in bars {
                        v.push(b.y);
                        if let Some((a, c)) = b.y_span.filter(|(a, c)| usable(*a) && usable(*c)) {
                            v.extend([a, c]);
                        }
                    }
                }
                Item::Bars { bars } => v.extend(bars.iter().flat_map(|b| [b.y0, b.y1])),
                Item::YBand { y0, y1, .. } => v.extend([*y0, *y1]),
                Item::XBand { .. } | Item::HRule { .. } | Item::VRule { .. } => {}
            }
        }
        v
    }

    /// Lays out the legend entries in rows within `width`; returns (x offset, row) per entry and the
    /// number of rows.
    fn legend_layout(&self, left: f64, width: f64) -> (Vec<(f64, usize)>, usize) {
        let mut pos = Vec::with_capacity(self.legend.len());
        let (mut x, mut row) = (0.0, 0usize);
        for (label, _) in &self.legend {
            let w = 24.0 + text_width(label, FONT) + 14.0;
            if x > 0.0 && left + x + w > width {
                x = 0.0;
                row += 1;
            }
            pos.push((x, row));
            x += w;
        }
        let rows = if self.legend.is_empty() { 0 } else { row + 1 };
        (pos, rows)
    }

    /// The y axis: categories (the first at the top) or linear over the data.
    fn y_axis(&self, h: f64) -> Axis {
        if self.y_categories.is_empty() {
            return Axis::fit(self.y_values(), self.y_range, self.y_range.is_none(), (h - 70.0) / 45.0);
        }
        let n = self.y_categories.len() as f64;
        Axis {
            lo: -0.6,
            hi: n - 0.4,
            ticks: self
                .y_categories
                .iter()
                .enumerate()
                .map(|(i, s)| (i as f64, s.clone()))
                .collect(),
        }
    }

    /// The axes, and the plot area within margins made from the text they hold.
    fn layout(&self) -> Layout {
        let (w, h) = (self.width.max(120.0), self.height.max(80.0));
        let xa = Axis::fit(
            self.x_values(),
            self.x_range,
            self.x_range.is_none(),
            (w - 100.0) / 90.0,
        );
        let ya = self.y_axis(h);
        let y_tick_w = ya
            .ticks
            .iter()
            .map(|(_, s)| text_width(s, FONT))
            .fold(0.0, f64::max)
            .min(w * 0.4);
        let left = 8.0 + y_tick_w + 6.0 + if self.y_label.is_empty() { 0.0 } else { 18.0 };
        let right = 16.0;
        let title_h = if self.title.is_empty() { 8.0 } else { 24.0 };
        let (legend_pos, legend_rows) = self.legend_layout(left, w - right);
        let top = title_h + legend_rows as f64 * 17.0 + 6.0;
        let bottom = 6.0 + if self.x_ticks { 18.0 } else { 4.0 } + if self.x_label.is_empty() { 0.0 } else { 18.0 };
        let f = Frame {
            x0: left,
            x1: (w - right).max(left + 20.0),
            y0: top,
            y1: (h - bottom).max(top + 20.0),
            xa,
            ya,
            y_down: !self.y_categories.is_empty(),
        };
        let h = h.max(f.y1 + bottom);
        Layout {
            w,
            h,
            f,
            title_h,
            legend_pos,
        }
    }

    /// The chart as an `<svg>` element.
    pub(crate) fn render(&self) -> Rendered {
        let Layout {
            w,
            h,
            f,
            title_h,
            legend_pos,
        } = self.layout();
        let mut dropped = 0usize;
        let mut s = String::with_capacity(4096);
        let title_id = format!("{}-t", self.id);
        let _ = write!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {w} {h}" width="{w}" height="{h}" role="img" aria-labelledby="{tid}" font-family="sans-serif" font-size="11">"#,
            w = coord(w),
            h = coord(h),
            tid = esc(&title_id),
        );
        let accessible = if self.title.is_empty() {
            format!("{} against {}", plain(&self.y_label), plain(&self.x_label))
        } else {
            plain(&self.title)
        };
        let _ = write!(s, r#"<title id="{}">{}</title>"#, esc(&title_id), esc(&accessible));
        let clip = format!("{}-c", self.id);
        let _ = write!(
            s,
            r#"<defs><clipPath id="{}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath></defs>"#,
            esc(&clip),
            coord(f.x0),
            coord(f.y0),
            coord(f.x1 - f.x0),
            coord(f.y1 - f.y0)
        );
        let tick_marks = self.grid(&mut s, &f);
        // Data, clipped to the plot area.
        let _ = write!(s, r#"<g clip-path="url(#{})">"#, esc(&clip));
        for item in &self.items {
            dropped += self.render_item(&mut s, &f, item);
        }
        s.push_str("</g>");
        // Axes.
        let _ = write!(
            s,
            r##"<path d="M{x0} {y0}V{y1}H{x1}{tick_marks}" stroke="#333" stroke-width="1" fill="none"/>"##,
            x0 = coord(f.x0),
            y0 = coord(f.y0),
            y1 = coord(f.y1),
            x1 = coord(f.x1),
        );
        self.tick_labels(&mut s, &f, w);
        self.labels(&mut s, &f);
        self.legend_entries(&mut s, &f, title_h, &legend_pos);
        s.push_str("</svg>");
        Rendered { svg: s, dropped }
    }

    /// Writes the grid lines; returns the tick marks' path, drawn with the axes.
    fn grid(&self, s: &mut String, f: &Frame) -> String {
        let mut grid = String::new();
        let mut tick_marks = String::new();
        for (v, _) in &f.ya.ticks {
            let y = f.py(*v);
            let _ = write!(grid, "M{} {}H{}", coord(f.x0), coord(y), coord(f.x1));
            let _ = write!(tick_marks, "M{} {}h4", coord(f.x0 - 4.0), coord(y));
        }
        for (v, _) in f.xa.ticks.iter().filter(|_| self.x_ticks) {
            let x = f.px(*v);
            if !f.y_down {
                let _ = write!(grid, "M{} {}V{}", coord(x), coord(f.y0), coord(f.y1));
            }
            let _ = write!(tick_marks, "M{} {}v4", coord(x), coord(f.y1));
        }
        let _ = write!(
            s,
            r##"<path d="{grid}" stroke="#e6e6e6" stroke-width="1" fill="none"/>"##
        );
        tick_marks
    }

    /// The tick labels; a y label too long for 40 % of the width `w` is cut, in full in its tooltip.
    fn tick_labels(&self, s: &mut String, f: &Frame, w: f64) {
        if self.x_ticks {
            let _ = write!(s, r##"<g fill="#333" text-anchor="middle">"##);
            for (v, label) in &f.xa.ticks {
                let _ = write!(
                    s,
                    r#"<text x="{}" y="{}">{}</text>"#,
                    coord(f.px(*v)),
                    coord(f.y1 + 16.0),
                    esc(label)
                );
            }
            s.push_str("</g>");
        }
        let _ = write!(s, r##"<g fill="#333" text-anchor="end" dominant-baseline="middle">"##);
        for (v, label) in &f.ya.ticks {
            let max_chars = ((w * 0.4) / (FONT * GLYPH)) as usize;
            let shown = if label.chars().count() > max_chars && max_chars > 1 {
                let mut t: String = label.chars().take(max_chars - 1).collect();
                t.push('…');
                t
            } else {
                label.clone()
            };
            let _ = write!(
                s,
                r#"<text x="{}" y="{}">{}"#,
                coord(f.x0 - 7.0),
                coord(f.py(*v)),
                esc(&shown)
            );
            if shown != *label {
                let _ = write!(s, "<title>{}</title>", esc(label));
            }
            s.push_str("</text>");
        }
        s.push_str("</g>");
    }

    /// The axis labels and the title.
    fn labels(&self, s: &mut String, f: &Frame) {
        if !self.x_label.is_empty() {
            let _ = write!(
                s,
                r#"<text x="{}" y="{}" text-anchor="middle" font-size="12">{}</text>"#,
                coord((f.x0 + f.x1) / 2.0),
                coord(f.y1 + if self.x_ticks { 34.0 } else { 18.0 }),
                rich(&self.x_label)
            );
        }
        if !self.y_label.is_empty() {
            let (x, y) = (12.0, (f.y0 + f.y1) / 2.0);
            let _ = write!(
                s,
                r#"<text x="{x}" y="{y}" text-anchor="middle" dominant-baseline="middle" font-size="12" transform="rotate(-90 {x} {y})">{}</text>"#,
                rich(&self.y_label),
                x = coord(x),
                y = coord(y),
            );
        }
        if !self.title.is_empty() {
            let _ = write!(
                s,
                r#"<text x="{}" y="16" font-size="13" font-weight="bold">{}</text>"#,
                coord(f.x0),
                rich(&self.title)
            );
        }
    }

    /// The legend above the plot area, entries placed by [`Chart::legend_layout`].
    fn legend_entries(&self, s: &mut String, f: &Frame, title_h: f64, legend_pos: &[(f64, usize)]) {
        if !self.legend.is_empty() {
            s.push_str(r#"<g dominant-baseline="middle">"#);
            for ((label, key), (dx, row)) in self.legend.iter().zip(legend_pos) {
                let (x, y) = (f.x0 + dx, title_h + 8.0 + *row as f64 * 17.0);
                key_glyph(s, *key, x, y);
                let _ = write!(
                    s,
                    r#"<text x="{}" y="{}">{}</text>"#,
                    coord(x + 24.0),
                    coord(y),
                    esc(label)
                );
            }
            s.push_str("</g>");
        }
    }

    /// Draws one item; returns how many values it could not draw.
    fn render_item(&self, s: &mut String, f: &Frame, item: &Item) -> usize {
        match *item {
            Item::Line {
                ref pts,
                color,
                width,
                dash,
            } => draw_line(s, f, pts, color, width, dash),
            Item::Marks {
                ref marks,
                color,
                shape,
                size,
            } => draw_marks(s, f, marks, color, shape, size),
            Item::ErrorBars { ref bars, color } => draw_error_bars(s, f, bars, color),
            Item::Bars { ref bars } => draw_bars(s, f, bars),
            ref other => {
                draw_guide(s, f, other);
                0
            }
        }
    }
}

/// A chart's computed geometry.
struct Layout {
    /// Width and height of the whole chart, px.
    w: f64,
    h: f64,
    /// The plot area and its axes.
    f: Frame,
    /// Height of the title row, px (the legend rows start below it).
    title_h: f64,
    /// (x offset, row) of every legend entry.
    legend_pos: Vec<(f64, usize)>,
}

/// A polyline in runs of usable points (a break at each unusable one), each run simplified to 0.3 px.
fn draw_line(s: &mut String, f: &Frame, pts: &[(f64, f64)], color: &str, width: f64, dash: bool) -> usize {
    let mut dropped = 0;
    let mut d = String::new();
    let mut run: Vec<(f64, f64)> = Vec::new();
    let flush = |run: &mut Vec<(f64, f64)>, d: &mut String| {
        for (i, (x, y)) in simplify(run, 0.3).into_iter().enumerate() {
            d.push(if i == 0 { 'M' } else { 'L' });
            push_coord(d, x);
            d.push(' ');
            push_coord(d, y);
        }
        run.clear();
    };
    for &(x, y) in pts {
        if usable(x) && usable(y) {
            run.push((f.px(x), f.py(y)));
        } else {
            dropped += 1;
            flush(&mut run, &mut d);
        }
    }
    flush(&mut run, &mut d);
    if !d.is_empty() {
        let dash = if dash { r#" stroke-dasharray="5 3""# } else { "" };
        let _ = write!(
            s,
            r#"<path d="{d}" fill="none" stroke="{color}" stroke-width="{}" stroke-linejoin="round"{dash}/>"#,
            coord(width)
        );
    }
    dropped
}

/// Markers: plain ones as one path, those with a tooltip or link each in its own element.
fn draw_marks(s: &mut String, f: &Frame, marks: &[Mark], color: &str, shape: Shape, size: f64) -> usize {
    let mut dropped = 0;
    let style = marker_style(shape, color, size);
    let r = size / 2.0;
    let mut plain = String::new();
    let mut linked = String::new();
    for m in marks {
        if !(usable(m.x) && usable(m.y)) {
            dropped += 1;
            continue;
        }
        let (x, y) = (f.px(m.x), f.py(m.y));
        if m.tip.is_none() && m.href.is_none() {
            marker_path(&mut plain, shape, x, y, r);
            continue;
        }
        let mut d = String::new();
        marker_path(&mut d, shape, x, y, r);
        if let Some(href) = &m.href {
            let _ = write!(linked, r##"<a href="#{}">"##, esc(href));
        }
        let _ = write!(linked, r#"<path d="{d}">"#);
        if let Some(tip) = &m.tip {
            let _ = write!(linked, "<title>{}</title>", esc(tip));
        }
        linked.push_str("</path>");
        if m.href.is_some() {
            linked.push_str("</a>");
        }
    }
    if !plain.is_empty() {
        let _ = write!(s, r#"<path d="{plain}" {style}/>"#);
    }
    if !linked.is_empty() {
        let _ = write!(s, "<g {style}>{linked}</g>");
    }
    dropped
}

/// Error bars with end caps, vertical and horizontal, as one path.
fn draw_error_bars(s: &mut String, f: &Frame, bars: &[ErrorBar], color: &str) -> usize {
    let mut dropped = 0;
    let mut d = String::new();
    for b in bars {
        if !(usable(b.x) && usable(b.y)) {
            continue;
        }
        if let Some((a, c)) = b.y_span {
            if usable(a) && usable(c) {
                let x = f.px(b.x);
                let (ya, yc) = (f.py(a), f.py(c));
                let _ = write!(
                    d,
                    "M{x} {ya}V{yc}M{xl} {ya}h5M{xl} {yc}h5",
                    x = coord(x),
                    ya = coord(ya),
                    yc = coord(yc),
                    xl = coord(x - 2.5)
                );
            } else {
                dropped += 1;
            }
        }
        if let Some((a, c)) = b.x_span {
            if usable(a) && usable(c) {
                let y = f.py(b.y);
                let (xa, xc) = (f.px(a), f.px(c));
                let _ = write!(
                    d,
                    "M{xa} {y}H{xc}M{xa} {yt}v5M{xc} {yt}v5",
                    xa = coord(xa),
                    xc = coord(xc),
                    y = coord(y),
                    yt = coord(y - 2.5)
                );
            } else {
                dropped += 1;
            }
        }
    }
    if !d.is_empty() {
        let _ = write!(s, r#"<path d="{d}" fill="none" stroke="{color}" stroke-width="1"/>"#);
    }
    dropped
}

/// Bars clipped to a pixel beyond the plot area, each with its tooltip and link.
fn draw_bars(s: &mut String, f: &Frame, bars: &[Bar]) -> usize {
    let mut dropped = 0;
    for b in bars {
        if ![b.x0, b.x1, b.y0, b.y1].iter().all(|v| usable(*v)) {
            dropped += 1;
            continue;
        }
        let (xa, xb) = (f.px(b.x0), f.px(b.x1));
        let (ya, yb) = (f.py(b.y0), f.py(b.y1));
        let (x, y) = (xa.min(xb).max(f.x0 - 1.0), ya.min(yb).max(f.y0 - 1.0));
        let (x_end, y_end) = (xa.max(xb).min(f.x1 + 1.0), ya.max(yb).min(f.y1 + 1.0));
        if let Some(href) = &b.href {
            let _ = write!(s, r##"<a href="#{}">"##, esc(href));
        }
        let _ = write!(
            s,
            r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{}">"#,
            coord(x),
            coord(y),
            coord((x_end - x).max(0.0)),
            coord((y_end - y).max(0.0)),
            b.color
        );
        if let Some(tip) = &b.tip {
            let _ = write!(s, "<title>{}</title>", esc(tip));
        }
        s.push_str("</rect>");
        if b.href.is_some() {
            s.push_str("</a>");
        }
    }
    dropped
}

/// Bands and rules: drawn where usable and inside the plot area, never counted as dropped.
fn draw_guide(s: &mut String, f: &Frame, item: &Item) {
    match item {
        Item::XBand { x0, x1, fill } => {
            if usable(*x0) && usable(*x1) {
                let (a, b) = (f.px(*x0).clamp(f.x0, f.x1), f.px(*x1).clamp(f.x0, f.x1));
                let (a, b) = (a.min(b), a.max(b));
                if b > a {
                    let _ = write!(
                        s,
                        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{fill}"/>"#,
                        coord(a),
                        coord(f.y0),
                        coord(b - a),
                        coord(f.y1 - f.y0)
                    );
                }
            }
        }
        Item::YBand { y0, y1, fill } => {
            if usable(*y0) && usable(*y1) {
                let (a, b) = (f.py(*y0).clamp(f.y0, f.y1), f.py(*y1).clamp(f.y0, f.y1));
                let (a, b) = (a.min(b), a.max(b));
                if b > a {
                    let _ = write!(
                        s,
                        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{fill}"/>"#,
                        coord(f.x0),
                        coord(a),
                        coord(f.x1 - f.x0),
                        coord(b - a)
                    );
                }
            }
        }
        Item::HRule { y, color, dash } => {
            let py = f.py(*y);
            if usable(*y) && py >= f.y0 && py <= f.y1 {
                let dash = if *dash { r#" stroke-dasharray="4 3""# } else { "" };
                let _ = write!(
                    s,
                    r#"<path d="M{} {}H{}" stroke="{color}" stroke-width="1"{dash}/>"#,
                    coord(f.x0),
                    coord(py),
                    coord(f.x1)
                );
            }
        }
        Item::VRule { x, color, dash } => {
            let px = f.px(*x);
            if usable(*x) && px >= f.x0 && px <= f.x1 {
                let dash = if *dash { r#" stroke-dasharray="4 3""# } else { "" };
                let _ = write!(
                    s,
                    r#"<path d="M{} {}V{}" stroke="{color}" stroke-width="1"{dash}/>"#,
                    coord(px),
                    coord(f.y0),
                    coord(f.y1)
                );
            }
        }
        Item::Line { .. } | Item::Marks { .. } | Item::ErrorBars { .. } | Item::Bars { .. } => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(a: &Axis) -> Vec<&str> {
        a.ticks.iter().map(|t| t.1.as_str()).collect()
    }

    #[test]
    fn nice_ticks() {
        let a = Axis::fit([0.12, 0.87], None, true, 6.0);
        assert_eq!(labels(&a), ["0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        let a = Axis::fit([0.0, 59.9], Some((0.0, 59.9)), false, 6.0);
        assert_eq!(labels(&a), ["0", "10", "20", "30", "40", "50"]);
        let a = Axis::fit([-3.0, 2.0], None, true, 5.0);
        assert!(labels(&a).contains(&"\u{2212}2"), "{:?}", labels(&a));
    }

    #[test]
    fn degenerate_ranges_give_a_usable_axis() {
        for vals in [
            vec![],
            vec![f64::NAN],
            vec![5.0],
            vec![5.0, 5.0 + 1e-13],
            vec![0.0, 0.0],
            vec![-1e300, 1e300],
            vec![1e-300, 2e-300],
            vec![f64::MAX, f64::MIN, 1.0],
            vec![5e-324],
        ] {
            let a = Axis::fit(vals.iter().copied(), None, true, 5.0);
            assert!(a.lo.is_finite() && a.hi.is_finite() && a.hi > a.lo, "{vals:?}: {a:?}");
            assert!(!a.ticks.is_empty() && a.ticks.len() <= 52, "{vals:?}: {a:?}");
            assert!(
                a.ticks.iter().all(|(v, s)| v.is_finite() && !s.is_empty()),
                "{vals:?}: {a:?}"
            );
        }
    }

    #[test]
    fn small_and_large_values_use_exponents() {
        let a = Axis::fit([1e-5, 5e-5], None, true, 5.0);
        assert!(labels(&a).iter().any(|s| s.contains('e')), "{:?}", labels(&a));
        let a = Axis::fit([1e7, 5e7], None, true, 5.0);
        assert!(labels(&a).iter().any(|s| s.contains("e7")), "{:?}", labels(&a));
    }

    #[test]
    fn chart_escapes_text_and_counts_dropped_values() {
        let mut c = Chart::new("t", 400.0, 300.0);
        c.title = "<b>".into();
        c.legend.push(("a&b".into(), Key::Swatch { fill: "#fff" }));
        c.items.push(Item::Marks {
            marks: vec![
                Mark {
                    x: 1.0,
                    y: 2.0,
                    tip: Some("<script>".into()),
                    href: Some("x".into()),
                },
                Mark::at(f64::NAN, 1.0),
                Mark::at(2.0, 3.0),
            ],
            color: "#000",
            shape: Shape::Diamond,
            size: 6.0,
        });
        let r = c.render();
        assert_eq!(r.dropped, 1);
        assert!(!r.svg.contains("<script>") && !r.svg.contains("<b>") && r.svg.contains("a&amp;b"));
        assert!(!r.svg.contains("NaN"));
    }

    #[test]
    fn subscripts_in_labels() {
        assert_eq!(
            rich("|v_{n,in}| <"),
            r#"|v<tspan baseline-shift="sub" font-size="75%">n,in</tspan>| &lt;"#
        );
        assert_eq!(rich("a_{b"), "a_{b");
        assert_eq!(plain("v_{n}"), "vn");
    }
}
