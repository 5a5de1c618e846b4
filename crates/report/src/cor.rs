//! The measured quantities against impact speed with the fitted model's prediction over them, per surface
//! (the paper's Figures 6–7 with the model drawn in): COR, contact time, maximum penetration and peak
//! deceleration; then COR against the incline (Figure 8). The model's curves are listed under the figure, as
//! they are in `model_curves.csv`.

use crate::data::{ModelCurve, ShotMeasurement, ShotPrediction};
use crate::fmt::{fixed, num, pm_text, short};
use crate::html::{Ctx, nc, table, tc, unavailable};
use crate::svg::{Chart, ErrorBar, Item, Key, Mark};

/// A shot's value and standard error, in display units, if it has the quantity.
type Reading = Option<(f64, Option<f64>)>;

/// One panel: a measured quantity and the same from the model, in display units.
struct Panel {
    title: &'static str,
    y_label: &'static str,
    unit: &'static str,
    sig: usize,
    measured: fn(&ShotMeasurement) -> Reading,
    model: fn(&ShotPrediction) -> f64,
}

const PANELS: [Panel; 4] = [
    Panel {
        title: "Coefficient of restitution",
        y_label: "COR e",
        unit: "",
        sig: 4,
        measured: |m| Some((m.cor.value, m.cor.se)),
        model: |p| p.cor,
    },
    Panel {
        title: "Contact time",
        y_label: "contact time (ms)",
        unit: "ms",
        sig: 4,
        measured: |m| Some((m.contact_time_s.value * 1e3, m.contact_time_s.se.map(|e| e * 1e3))),
        model: |p| p.contact_time_s * 1e3,
    },
    Panel {
        title: "Maximum penetration",
        y_label: "δ_{max} (mm)",
        unit: "mm",
        sig: 3,
        measured: |m| Some((m.delta_max_m.value * 1e3, m.delta_max_m.se.map(|e| e * 1e3))),
        model: |p| p.delta_max_m * 1e3,
    },
    Panel {
        title: "Peak normal deceleration",
        y_label: "peak deceleration (m/s²)",
        unit: "m/s²",
        sig: 4,
        measured: |m| m.peak_deceleration_track_m_s2.map(|a| (a.value, a.se)),
        model: |p| p.peak_deceleration_m_s2,
    },
];

fn tip(m: &ShotMeasurement, what: &str, v: (f64, Option<f64>), unit: &str, sig: usize) -> String {
    format!(
        "{} ({}, {}°): {what} {}{} at |v_n,in| = {} m/s",
        m.clip,
        m.surface,
        short(m.angle_deg, 3),
        pm_text(v.0, v.1, sig),
        if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        },
        pm_text(m.v_in_m_s[1].value.abs(), m.v_in_m_s[1].se, 4)
    )
}

/// Dash a curve of a surface's second and later angles, so angles stay apart where they differ.
fn curves_of<'a>(ctx: &'a Ctx, surface: &str) -> Vec<(usize, &'a ModelCurve)> {
    ctx.report
        .model_curves
        .iter()
        .filter(|c| c.surface == surface)
        .enumerate()
        .collect()
}

fn panel_chart(ctx: &Ctx, id: String, panel: &Panel, surfaces: &[String]) -> Option<Chart> {
    let ms = &ctx.report.measurements;
    let has_data = ms.iter().any(|m| (panel.measured)(m).is_some());
    let has_model = ctx.report.model_curves.iter().any(|c| !c.points.is_empty());
    if !has_data && !has_model {
        return None;
    }
    let mut c = Chart::new(id, 560.0, 380.0);
    c.title = format!("{} against impact speed", panel.title);
    c.x_label = "impact speed |v_{n,in}| (m/s)".into();
    c.y_label = panel.y_label.into();
    for s in surfaces {
        let (color, shape) = ctx.style(s);
        for (k, curve) in curves_of(ctx, s) {
            c.items.push(Item::Line {
                pts: curve
                    .points
                    .iter()
                    .map(|p| (p.v_in_n_m_s, (panel.model)(&p.prediction)))
                    .collect(),
                color,
                width: 1.8,
                dash: k > 0,
            });
        }
        let pts: Vec<(&ShotMeasurement, (f64, Option<f64>))> = ms
            .iter()
            .filter(|m| &m.surface == s)
            .filter_map(|m| (panel.measured)(m).map(|v| (m, v)))
            .collect();
        if pts.is_empty() {
            continue;
        }
        c.items.push(Item::ErrorBars {
            bars: pts
                .iter()
                .map(|(m, (y, se))| {
                    let x = m.v_in_m_s[1].value.abs();
                    ErrorBar {
                        x,
                        y: *y,
                        x_span: m.v_in_m_s[1].se.map(|e| (x - e, x + e)),
                        y_span: se.map(|e| (y - e, y + e)),
                    }
                })
                .collect(),
            color,
        });
        c.items.push(Item::Marks {
            marks: pts
                .iter()
                .map(|(m, v)| Mark {
                    x: m.v_in_m_s[1].value.abs(),
                    y: v.0,
                    tip: Some(tip(m, panel.title, *v, panel.unit, panel.sig)),
                    href: ctx.shot_href(&m.clip),
                })
                .collect(),
            color,
            shape,
            size: 7.0,
        });
        c.legend.push((s.clone(), Key::Mark { color, shape }));
    }
    if has_model {
        c.legend.push((
            "fitted model".into(),
            Key::Line {
                color: "#555",
                dash: false,
            },
        ));
    }
    Some(c)
}

/// The model's curves as a table (the numbers drawn, as in `model_curves.csv`), a few speeds per curve.
fn curve_table(ctx: &Ctx) -> String {
    let mut rows = Vec::new();
    for curve in &ctx.report.model_curves {
        let n = curve.points.len();
        // Every point would be long: the ends and three between.
        let picks: Vec<usize> = if n <= 5 {
            (0..n).collect()
        } else {
            (0..5).map(|k| k * (n - 1) / 4).collect()
        };
        for &i in &picks {
            let p = &curve.points[i];
            rows.push(vec![
                ctx.surface_cell(&curve.surface),
                short(curve.angle_deg, 3),
                num(p.v_in_n_m_s, 4),
                num(p.prediction.cor, 4),
                num(p.prediction.contact_time_s * 1e3, 4),
                num(p.prediction.delta_max_m * 1e3, 4),
                num(p.prediction.peak_force_n, 4),
                num(p.prediction.peak_deceleration_m_s2, 4),
            ]);
        }
    }
    if rows.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "<details><summary>Values of the model's curves (every point is in <code>model_curves.csv</code>)</summary>\n",
    );
    s.push_str(&table(
        &[
            tc("Surface"),
            nc("Incline (°)"),
            nc("|v<sub>n,in</sub>| (m/s)"),
            nc("COR e"),
            nc("Contact (ms)"),
            nc("δ<sub>max</sub> (mm)"),
            nc("Peak force (N)"),
            nc("Peak decel. (m/s²)"),
        ],
        &rows,
    ));
    s.push_str("</details>\n");
    s
}

/// The section.
pub(crate) fn render(ctx: &mut Ctx) -> String {
    let all = &ctx.report.measurements;
    if all.is_empty() && ctx.report.model_curves.is_empty() {
        return unavailable("no shot was measured");
    }
    let surfaces: Vec<String> = ctx
        .surfaces
        .iter()
        .filter(|s| all.iter().any(|p| &p.surface == *s) || ctx.report.model_curves.iter().any(|c| &c.surface == *s))
        .cloned()
        .collect();
    let mut out = against_speed(ctx, &surfaces);
    out.push_str(&curve_table(ctx));
    if all.is_empty() {
        return out;
    }
    out.push_str(&against_incline(ctx, &surfaces));
    out
}

/// The measured quantities against the incoming normal speed with the model over them: one panel each.
fn against_speed(ctx: &mut Ctx, surfaces: &[String]) -> String {
    let all = &ctx.report.measurements;
    let (n, id) = ctx.next_figure();
    let charts: Vec<Chart> = PANELS
        .iter()
        .enumerate()
        .filter_map(|(k, p)| panel_chart(ctx, format!("{id}{}", (b'a' + k as u8) as char), p, surfaces))
        .collect();
    let track_decel = all.iter().any(|m| m.peak_deceleration_track_m_s2.is_some());
    let angles_note = if ctx.report.model_curves.iter().any(|c| c.angle_deg != 0.0) {
        " One line per surface and incline (the ball arriving vertically, as in a drop; dashed for a surface's \
         second and later inclines): lines of one surface coincide where the incline does not change the normal \
         impact."
    } else {
        ""
    };
    ctx.figure(
        n,
        &charts,
        &format!(
            "Measured COR, contact time and maximum penetration{} against the incoming normal speed per surface (the \
             paper's Figures 6–7), with ±1 standard error bars, and the fitted model's prediction over them \
             (lines).{angles_note} Hover a point for its clip; click it for the shot's plots.",
            if track_decel {
                " and the peak deceleration from the track"
            } else {
                ""
            }
        ),
    )
}

/// COR against the incline, points of different surfaces offset at each incline.
fn against_incline(ctx: &mut Ctx, surfaces: &[String]) -> String {
    let all = &ctx.report.measurements;
    let mut angles: Vec<f64> = all.iter().map(|p| p.angle_deg).filter(|a| a.is_finite()).collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    let gap = angles.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
    let gap = if gap.is_finite() && gap > 0.0 { gap } else { 5.0 };
    let k = surfaces.len().max(1) as f64;
    let step = (gap * 0.5 / k).min(gap * 0.12);
    let (n, id) = ctx.next_figure();
    let mut c = Chart::new(id, 760.0, 400.0);
    c.title = "COR against surface incline".into();
    c.x_label = "surface incline (°)".into();
    c.y_label = "COR e".into();
    for (si, s) in surfaces.iter().enumerate() {
        let (color, shape) = ctx.style(s);
        let off = (si as f64 - (k - 1.0) / 2.0) * step;
        let pts: Vec<&ShotMeasurement> = all.iter().filter(|p| &p.surface == s).collect();
        if pts.is_empty() {
            continue;
        }
        c.items.push(Item::ErrorBars {
            bars: pts
                .iter()
                .map(|p| ErrorBar {
                    x: p.angle_deg + off,
                    y: p.cor.value,
                    x_span: None,
                    y_span: p.cor.se.map(|e| (p.cor.value - e, p.cor.value + e)),
                })
                .collect(),
            color,
        });
        c.items.push(Item::Marks {
            marks: pts
                .iter()
                .map(|p| Mark {
                    x: p.angle_deg + off,
                    y: p.cor.value,
                    tip: Some(tip(p, "COR", (p.cor.value, p.cor.se), "", 4)),
                    href: ctx.shot_href(&p.clip),
                })
                .collect(),
            color,
            shape,
            size: 7.0,
        });
        c.legend.push((s.clone(), Key::Mark { color, shape }));
    }
    ctx.figure(
        n,
        &[c],
        &format!(
            "Coefficient of restitution against the surface incline, per surface (the paper's Figure 8), with ±1 \
             standard error bars. Points of different surfaces at one incline are offset by {}° for legibility.",
            fixed(step, 1)
        ),
    )
}
