//! The shots section: every measured quantity per shot with its standard error, the fitted model's
//! prediction and fit error per shot, a bar chart of the fit error, and each shot's plots in a collapsed
//! block (trajectory with the model over it and the residual below, per component, shaded by phase), the
//! worst and best fits open, with a strip of annotated frames when the run drew one.

use std::fmt::Write;

use crate::data::{Phase, Report, ShotMeasurement, ShotPlot};
use crate::fmt::{esc, num, opt, short, um};
use crate::html::{Ctx, nc, pm_cell, tc, wc};
use crate::svg::{Bar, Chart, Item, Key, Mark, Shape};
use crate::thin::thin_indices;

/// Total marker budget per series over all shots; each shot gets a share, between 60 and 250 points.
const POINT_BUDGET: usize = 12_000;

/// Background of each phase.
pub(crate) fn phase_fill(p: Phase) -> &'static str {
    match p {
        Phase::FlightIn => "#eaf1fb",
        Phase::Compression => "#fde3cf",
        Phase::Restitution => "#d9f1e3",
        Phase::FlightOut => "#efe7f7",
    }
}

/// The shot's RMS position residual, m: as given, else from its residuals (x and y together).
pub(crate) fn rms_of(shot: &ShotPlot) -> Option<f64> {
    if let Some(r) = shot.rms_m {
        return Some(r);
    }
    let ok: Vec<f64> = shot
        .residuals
        .iter()
        .filter(|r| r.dx_m.is_finite() && r.dy_m.is_finite())
        .map(|r| r.dx_m * r.dx_m + r.dy_m * r.dy_m)
        .collect();
    if ok.is_empty() {
        None
    } else {
        Some((ok.iter().sum::<f64>() / (2.0 * ok.len() as f64)).sqrt())
    }
}

/// Notes every shot carries (two shots or more), in the first shot's order: said once for the session.
pub(crate) fn shared_notes(r: &Report) -> Vec<String> {
    if r.shots.len() < 2 {
        return Vec::new();
    }
    let mut out: Vec<String> = Vec::new();
    for n in &r.shots[0].notes {
        if !out.contains(n) && r.shots.iter().all(|s| s.notes.contains(n)) {
            out.push(n.clone());
        }
    }
    out
}

/// A shot's notes without those every shot carries.
fn own_notes(sh: &ShotPlot, shared: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for n in &sh.notes {
        if !shared.contains(n) && !out.contains(n) {
            out.push(n.clone());
        }
    }
    out
}

/// Shot indices with a finite RMS, best first (ties by input order).
fn ranked(ctx: &Ctx) -> Vec<(usize, f64)> {
    let mut v: Vec<(usize, f64)> = ctx
        .report
        .shots
        .iter()
        .enumerate()
        .filter_map(|(i, s)| rms_of(s).filter(|r| r.is_finite()).map(|r| (i, r)))
        .collect();
    v.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    v
}

/// (worst, best) shots to show open: up to three worst, one best.
fn featured(ctx: &Ctx) -> (Vec<usize>, Vec<usize>) {
    let r = ranked(ctx);
    let worst: Vec<usize> = r.iter().rev().take(3.min(r.len())).map(|x| x.0).collect();
    let best: Vec<usize> = r
        .first()
        .filter(|b| r.len() > 3 && !worst.contains(&b.0))
        .map(|b| b.0)
        .into_iter()
        .collect();
    (worst, best)
}

/// One row of a per-shot bar chart.
pub(crate) struct BarRow {
    pub clip: String,
    pub surface: String,
    /// Values in metres, one per series.
    pub values: Vec<f64>,
}

/// Bars per shot (in micrometres): horizontal with clip names for up to 40 shots, vertical and unlabelled
/// (tooltips and links only) beyond. One series is coloured by surface; several by series.
pub(crate) fn per_shot_bars(
    ctx: &Ctx,
    id: String,
    rows: &[BarRow],
    series: &[(String, &'static str)],
    value_label: &str,
) -> Chart {
    let horizontal = rows.len() <= 40;
    let m = series.len().max(1);
    let thick = 0.8 / m as f64;
    let mut bars = Vec::new();
    for (i, row) in rows.iter().enumerate() {
        for (j, v) in row.values.iter().enumerate().take(m) {
            let (color, label) = if m == 1 {
                (ctx.style(&row.surface).0, String::new())
            } else {
                (series[j].1, format!("{}: ", series[j].0))
            };
            let a = i as f64 - 0.4 + j as f64 * thick;
            let val = v * 1e6;
            let (x0, x1, y0, y1) = if horizontal {
                (0.0, val, a, a + thick)
            } else {
                (a, a + thick, 0.0, val)
            };
            bars.push(Bar {
                x0,
                x1,
                y0,
                y1,
                color,
                tip: Some(format!("{} ({}) {label}{} µm", row.clip, row.surface, um(*v))),
                href: ctx.shot_href(&row.clip),
            });
        }
    }
    let legend_rows = if m == 1 { ctx.surfaces.len().div_ceil(5) } else { 1 };
    let mut c = if horizontal {
        let mut c = Chart::new(
            id,
            760.0,
            70.0 + 17.0 * legend_rows as f64 + rows.len().max(1) as f64 * (8.0 + 8.0 * m as f64),
        );
        c.y_categories = rows.iter().map(|r| r.clip.clone()).collect();
        c.x_label = value_label.into();
        c.x_include.push(0.0);
        c
    } else {
        let mut c = Chart::new(id, 1000.0, 300.0);
        c.y_label = value_label.into();
        c.x_label = "shots (hover a bar for its clip, click it for its plots)".into();
        c.x_ticks = false;
        c.y_include.push(0.0);
        c.x_range = Some((-0.6, rows.len() as f64 - 0.4));
        c
    };
    c.items.push(Item::Bars { bars });
    if m == 1 {
        let present: Vec<&String> = ctx
            .surfaces
            .iter()
            .filter(|s| rows.iter().any(|r| &r.surface == *s))
            .collect();
        for s in present {
            c.legend.push((s.clone(), Key::Swatch { fill: ctx.style(s).0 }));
        }
    } else {
        for (label, color) in series {
            c.legend.push((label.clone(), Key::Swatch { fill: color }));
        }
    }
    c
}

/// A link to shot `clip`'s plots with its tags, or its name.
fn clip_cell(ctx: &Ctx, clip: &str, tags: &str) -> String {
    format!("{}{tags}", ctx.clip_link(clip))
}

fn opt_pm(m: Option<crate::data::Measured>, scale: f64, sig: usize) -> String {
    m.map_or("—".into(), |m| pm_cell(m.value * scale, m.se.map(|e| e * scale), sig))
}

/// The measured quantities per shot.
fn measured_table(ctx: &Ctx) -> String {
    let rows: Vec<Vec<String>> = ctx
        .report
        .measurements
        .iter()
        .enumerate()
        .map(|(i, m): (usize, &ShotMeasurement)| {
            let speed = m.impact_speed();
            let angle = m.impact_angle();
            vec![
                (i + 1).to_string(),
                clip_cell(ctx, &m.clip, ""),
                ctx.surface_cell(&m.surface),
                short(m.angle_deg, 3),
                pm_cell(speed.value, speed.se, 4),
                pm_cell(angle.value, angle.se, 3),
                pm_cell(m.cor.value, m.cor.se, 4),
                pm_cell(m.mu_eff.value + 0.0, m.mu_eff.se, 3),
                pm_cell(m.contact_time_s.value * 1e3, m.contact_time_s.se.map(|e| e * 1e3), 4),
                pm_cell(m.delta_max_m.value * 1e3, m.delta_max_m.se.map(|e| e * 1e3), 3),
                opt_pm(m.spin_in_rad_s, 1.0, 3),
                opt_pm(m.spin_out_rad_s, 1.0, 3),
                opt_pm(m.peak_deceleration_track_m_s2, 1.0, 4),
                opt_pm(m.peak_force_track_n, 1.0, 4),
            ]
        })
        .collect();
    crate::html::table_with_class(
        "stacked",
        &[
            nc("#"),
            tc("Clip"),
            tc("Surface"),
            nc("Incline (°)"),
            nc("|v<sub>in</sub>| (m/s)"),
            nc("Impact angle (°)"),
            nc("COR e"),
            nc("μ<sub>eff</sub>"),
            nc("Contact (ms)"),
            nc("δ<sub>max</sub> (mm)"),
            nc("ω<sub>in</sub> (rad/s)"),
            nc("ω<sub>out</sub> (rad/s)"),
            nc("Peak decel. (m/s²)"),
            nc("Peak force (N)"),
        ],
        &rows,
    )
}

/// The model and the fit per shot, with the notes.
fn model_table(ctx: &Ctx, worst: &[usize], best: &[usize], shared: &[String]) -> String {
    let r = ctx.report;
    let mut rows = Vec::new();
    for (i, sh) in r.shots.iter().enumerate() {
        let m = r.measurements.iter().find(|m| m.clip == sh.clip);
        let p = m.and_then(|m| m.model);
        let mut tags = String::new();
        if worst.contains(&i) {
            tags.push_str(r#"<span class="tag worst">worst</span>"#);
        }
        if best.contains(&i) {
            tags.push_str(r#"<span class="tag best">best</span>"#);
        }
        let pred = |f: fn(&crate::data::ShotPrediction) -> f64, scale: f64, sig: usize| {
            p.as_ref().map_or("—".into(), |p| num(f(p) * scale, sig))
        };
        rows.push(vec![
            format!(r##"<a href="#{}">{}</a>{tags}"##, esc(&ctx.shot_ids[i]), esc(&sh.clip)),
            ctx.surface_cell(&sh.surface),
            pred(|p| p.cor, 1.0, 4),
            pred(|p| p.contact_time_s, 1e3, 4),
            pred(|p| p.delta_max_m, 1e3, 3),
            pred(|p| p.peak_force_n, 1.0, 4),
            pred(|p| p.peak_deceleration_m_s2, 1.0, 4),
            sh.measured.len().to_string(),
            rms_of(sh).map_or("—".into(), um),
            opt(sh.chi2_red, 3),
            esc(&own_notes(sh, shared).join("; ")),
        ]);
    }
    crate::html::table_with_class(
        "stacked",
        &[
            tc("Clip"),
            tc("Surface"),
            nc("COR e"),
            nc("Contact (ms)"),
            nc("δ<sub>max</sub> (mm)"),
            nc("Peak force (N)"),
            nc("Peak decel. (m/s²)"),
            nc("Frames"),
            nc("RMS (µm)"),
            nc("χ²<sub>ν</sub>"),
            wc("Notes"),
        ],
        &rows,
    )
}

/// The shots section.
pub(crate) fn render(ctx: &mut Ctx) -> String {
    let r = ctx.report;
    if r.shots.is_empty() && r.measurements.is_empty() {
        return crate::html::unavailable("no shot was tracked");
    }
    let shared = shared_notes(r);
    let (worst, best) = featured(ctx);
    let mut s = String::new();
    if !r.measurements.is_empty() {
        s.push_str(
            "<h3>Measured per shot</h3>\n<p>Each value with its standard error (smaller, after it). Velocities at \
             touch; the impact angle is the incoming velocity's from the surface normal (a vertical drop on an \
             incline arrives at the incline); the peak deceleration is the largest normal acceleration of the \
             ball's centre from the track's second difference, where the track resolves it.</p>\n",
        );
        s.push_str(&measured_table(ctx));
    }
    if r.shots.is_empty() {
        return s;
    }
    s.push_str(
        "<h3>The fitted model per shot</h3>\n<p>The fitted model hit at each shot's measured incoming velocity, and \
         how well it follows the shot's trajectory: RMS of the position residuals (x and y together) and the \
         reduced χ² χ²<sub>ν</sub> (the shot's χ² over its share of the fit's degrees of freedom; see \
         <a href=\"#fit\">Model fit</a>).</p>\n",
    );
    s.push_str(&model_table(ctx, &worst, &best, &shared));
    if !shared.is_empty() {
        s.push_str(r##"<p class="notes">Notes every shot carries are listed once under <a href="#warnings">Warnings and notes</a>.</p>"##);
    }
    s.push_str(&fit_error_figure(ctx));
    s.push_str("<h3>Trajectories and residuals</h3>\n");
    s.push_str(&open_and_selector(ctx, &worst, &best));
    let budget = (POINT_BUDGET / r.shots.len()).clamp(60, 250);
    for i in 0..r.shots.len() {
        let open = worst.contains(&i) || best.contains(&i);
        s.push_str(&shot_block(
            ctx,
            i,
            open,
            budget,
            worst.contains(&i),
            best.contains(&i),
            &shared,
        ));
    }
    s
}

/// The bar chart of every shot's fit error; nothing when no shot has one.
fn fit_error_figure(ctx: &mut Ctx) -> String {
    let r = ctx.report;
    let rows: Vec<BarRow> = r
        .shots
        .iter()
        .filter_map(|sh| {
            rms_of(sh).map(|v| BarRow {
                clip: sh.clip.clone(),
                surface: sh.surface.clone(),
                values: vec![v],
            })
        })
        .collect();
    if rows.is_empty() {
        return String::new();
    }
    let (n, id) = ctx.next_figure();
    let mut chart = per_shot_bars(
        ctx,
        id,
        &rows,
        &[("RMS".into(), "#0072B2")],
        "RMS position residual (µm)",
    );
    chart.title = "Fit error per shot".into();
    ctx.figure(
        n,
        &[chart],
        "RMS of the position residuals (measured − model, x and y together) per shot, coloured by surface. \
         Each bar links to the shot's plots.",
    )
}

/// Which shots' plots are open, and the shot selector (shown by the script only).
fn open_and_selector(ctx: &Ctx, worst: &[usize], best: &[usize]) -> String {
    let r = ctx.report;
    let mut s = String::new();
    let link = |i: usize| {
        format!(
            r##"<a href="#{}">{}</a>"##,
            esc(&ctx.shot_ids[i]),
            esc(&r.shots[i].clip)
        )
    };
    if !worst.is_empty() {
        let w: Vec<String> = worst.iter().map(|&i| link(i)).collect();
        let _ = write!(s, "<p>Worst fits: {}.", w.join(", "));
        if let Some(&b) = best.first() {
            let _ = write!(s, " Best fit: {}.", link(b));
        }
        s.push_str(" Their plots are open below; every other shot's plots open from its name.</p>\n");
    }
    s.push_str(
        r#"<p id="shot-selector" hidden><label>Go to shot: <select id="shot-select"><option value="">choose…</option>"#,
    );
    for (i, sh) in r.shots.iter().enumerate() {
        let _ = write!(
            s,
            r#"<option value="{}">{} ({})</option>"#,
            esc(&ctx.shot_ids[i]),
            esc(&sh.clip),
            esc(&sh.surface)
        );
    }
    s.push_str("</select></label></p>\n");
    s
}

fn base64(bytes: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// The strip of annotated frames of a shot.
fn frame_strip(sh: &ShotPlot) -> String {
    if sh.frames.is_empty() {
        return String::new();
    }
    let mut s = String::from(r#"<div class="strip">"#);
    for f in &sh.frames {
        let _ = write!(
            s,
            r#"<figure><img alt="{alt}" src="data:image/png;base64,{}"><figcaption>{alt}</figcaption></figure>"#,
            base64(&f.png),
            alt = esc(&f.caption)
        );
    }
    s.push_str("</div>\n");
    s
}

fn shot_block(
    ctx: &mut Ctx,
    i: usize,
    open: bool,
    budget: usize,
    worst: bool,
    best: bool,
    shared: &[String],
) -> String {
    let sh = &ctx.report.shots[i];
    let mut s = format!(
        r#"<details class="shot" id="{}"{}><summary><b>{}</b> · {} · {}°"#,
        esc(&ctx.shot_ids[i]),
        if open { " open" } else { "" },
        esc(&sh.clip),
        ctx.surface_cell(&sh.surface),
        short(sh.angle_deg, 3)
    );
    if let Some(rms) = rms_of(sh) {
        let _ = write!(s, " · RMS {} µm", um(rms));
    }
    if let Some(c) = sh.chi2_red {
        let _ = write!(s, " · χ²<sub>ν</sub> {}", num(c, 3));
    }
    if worst {
        s.push_str(r#"<span class="tag worst">worst fit</span>"#);
    }
    if best {
        s.push_str(r#"<span class="tag best">best fit</span>"#);
    }
    s.push_str("</summary>\n");
    let notes = own_notes(sh, shared);
    if !notes.is_empty() {
        let notes: Vec<String> = notes.iter().map(|n| esc(n)).collect();
        let _ = writeln!(s, r#"<p class="notes">{}</p>"#, notes.join("<br>"));
    }
    s.push_str(&frame_strip(sh));
    if sh.measured.is_empty() && sh.model.is_empty() {
        s.push_str(&crate::html::unavailable(
            "no tracked frames and no model for this shot",
        ));
    } else {
        s.push_str(&shot_figure(ctx, i, budget));
    }
    s.push_str("</details>\n");
    s
}

/// Whether `t` (s) lies in a contact phase of the shot, widened by half a millisecond.
fn in_contact(sh: &ShotPlot, t: f64) -> bool {
    sh.phases
        .iter()
        .filter(|p| matches!(p.phase, Phase::Compression | Phase::Restitution))
        .any(|p| t >= p.t0_s - 5e-4 && t <= p.t1_s + 5e-4)
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// Colour of the fitted model's line in a shot's plots.
const MODEL_COLOR: &str = "#D55E00";
/// Colour of the measured centres.
const DATA_COLOR: &str = "#7a7a7a";
/// Width of a shot's plots, px.
const SHOT_PLOT_W: f64 = 540.0;

/// Seconds to milliseconds (the plots' time axis).
fn ms(t: f64) -> f64 {
    t * 1e3
}

/// What a shot's plots share: the time axis, the phase shading and its legend.
struct ShotAxes {
    /// Time range, ms, padded by 1 %; `None` fits the data.
    x_range: Option<(f64, f64)>,
    /// One band per phase span.
    bands: Vec<Item>,
    /// A swatch for each phase the shot has.
    phase_legend: Vec<(String, Key)>,
}

impl ShotAxes {
    fn of(sh: &ShotPlot) -> ShotAxes {
        let times = sh
            .measured
            .iter()
            .map(|p| p.t_s)
            .chain(sh.model.iter().map(|p| p.t_s))
            .chain(sh.residuals.iter().map(|p| p.t_s))
            .filter(|t| t.is_finite() && t.abs() < 1e12);
        let (lo, hi) = times.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| (a.min(t), b.max(t)));
        let x_range = (lo.is_finite() && hi > lo).then(|| {
            let pad = (hi - lo) * 0.01;
            (ms(lo - pad), ms(hi + pad))
        });
        let bands = sh
            .phases
            .iter()
            .map(|p| Item::XBand {
                x0: ms(p.t0_s),
                x1: ms(p.t1_s),
                fill: phase_fill(p.phase),
            })
            .collect();
        let phase_legend = Phase::ALL
            .iter()
            .filter(|p| sh.phases.iter().any(|s| s.phase == **p))
            .map(|p| (p.label().to_string(), Key::Swatch { fill: phase_fill(*p) }))
            .collect();
        ShotAxes {
            x_range,
            bands,
            phase_legend,
        }
    }

    /// An empty chart on the shot's time axis with the phases shaded.
    fn chart(&self, id: String, height: f64) -> Chart {
        let mut c = Chart::new(id, SHOT_PLOT_W, height);
        c.x_label = "t (ms)".into();
        c.x_range = self.x_range;
        c.items.extend(self.bands.iter().cloned());
        c
    }
}

/// One shot's figure (the paper's Figure 9): per component a column, the trajectory with the model
/// drawn over the measured centres on top, the residual measured − model below on the same time axis,
/// both shaded by phase.
fn shot_figure(ctx: &mut Ctx, i: usize, budget: usize) -> String {
    let sh = &ctx.report.shots[i];
    let axes = ShotAxes::of(sh);
    let idx = thin_indices(sh.measured.len(), budget, |k| in_contact(sh, sh.measured[k].t_s));
    let ridx = thin_indices(sh.residuals.len(), budget, |k| in_contact(sh, sh.residuals[k].t_s));
    let (n, id) = ctx.next_figure();
    let mut charts = vec![
        trajectory_chart(&axes, format!("{id}a"), sh, &idx, true),
        trajectory_chart(&axes, format!("{id}b"), sh, &idx, false),
    ];
    if !sh.residuals.is_empty() {
        // Column order in the grid: y trajectory, x trajectory, y residual, x residual.
        let sigma = median(sh.measured.iter().map(|p| p.sigma_m).collect());
        charts.push(residual_chart(&axes, format!("{id}c"), sh, &ridx, sigma, true));
        charts.push(residual_chart(&axes, format!("{id}d"), sh, &ridx, sigma, false));
    }
    let caption = shot_caption(sh, idx.len());
    ctx.figure(n, &charts, &caption)
}

/// A shot's trajectory, one component (`normal`: the height y, else x along the surface): the measured
/// centres at `idx` with the model's line over them.
fn trajectory_chart(axes: &ShotAxes, id: String, sh: &ShotPlot, idx: &[usize], normal: bool) -> Chart {
    let (title, label) = if normal {
        ("Height above the surface", "y")
    } else {
        ("Position along the surface (down-slope)", "x")
    };
    let coord = |p: (f64, f64)| if normal { p.1 } else { p.0 };
    let mut c = axes.chart(id, 250.0);
    c.title = title.into();
    c.y_label = format!("{label} (mm)");
    // Measured centres first, small and hollow; the model's line over them, so both stay visible.
    c.items.push(Item::Marks {
        marks: idx
            .iter()
            .map(|&j| {
                let p = &sh.measured[j];
                Mark::at(ms(p.t_s), coord((p.x_m, p.y_m)) * 1e3)
            })
            .collect(),
        color: DATA_COLOR,
        shape: Shape::Circle,
        size: 4.6,
    });
    // Thinner than the dots, so where they coincide both stay visible.
    if !sh.model.is_empty() {
        c.items.push(Item::Line {
            pts: sh
                .model
                .iter()
                .map(|p| (ms(p.t_s), coord((p.x_m, p.y_m)) * 1e3))
                .collect(),
            color: MODEL_COLOR,
            width: 1.4,
            dash: false,
        });
    }
    c.legend.push((
        "measured".into(),
        Key::Mark {
            color: DATA_COLOR,
            shape: Shape::Circle,
        },
    ));
    if !sh.model.is_empty() {
        c.legend.push((
            "fitted model".into(),
            Key::Line {
                color: MODEL_COLOR,
                dash: false,
            },
        ));
    }
    if normal {
        c.legend.extend(axes.phase_legend.iter().cloned());
    }
    c
}

/// A shot's residual measured − model, one component, at `ridx`, over the ±1σ tracking band.
fn residual_chart(
    axes: &ShotAxes,
    id: String,
    sh: &ShotPlot,
    ridx: &[usize],
    sigma: Option<f64>,
    normal: bool,
) -> Chart {
    let mut c = axes.chart(id, 210.0);
    c.title = format!("Residual, measured − model, {}", if normal { "y" } else { "x" });
    c.y_label = "residual (µm)".into();
    if let Some(sg) = sigma {
        c.items.push(Item::YBand {
            y0: -sg * 1e6,
            y1: sg * 1e6,
            fill: "#cfcfcf",
        });
    }
    c.items.push(Item::HRule {
        y: 0.0,
        color: "#555",
        dash: false,
    });
    c.y_include.push(0.0);
    c.items.push(Item::Marks {
        marks: ridx
            .iter()
            .map(|&j| {
                let r = &sh.residuals[j];
                Mark::at(ms(r.t_s), if normal { r.dy_m } else { r.dx_m } * 1e6)
            })
            .collect(),
        color: if normal { "#0072B2" } else { "#D55E00" },
        shape: Shape::Circle,
        size: 3.2,
    });
    if sigma.is_some() {
        c.legend.push(("±1σ tracking".into(), Key::Swatch { fill: "#cfcfcf" }));
    }
    c
}

/// The caption of a shot's figure, `shown` of its measured frames drawn.
fn shot_caption(sh: &ShotPlot, shown: usize) -> String {
    let mut caption = format!(
        "Shot {} on {} at {}° (the paper's Figure 9): tracked ball centre (dots; {} of {} frames shown, every frame \
         near contact) ",
        esc(&sh.clip),
        esc(&sh.surface),
        short(sh.angle_deg, 3),
        shown,
        sh.measured.len()
    );
    caption.push_str(if sh.model.is_empty() {
        "without a model"
    } else {
        "and the fitted model simulated for this shot (line), normal component left, tangential right"
    });
    if sh.residuals.is_empty() {
        caption.push_str(". No residuals (no model was fitted to this shot).");
    } else {
        caption.push_str(
            "; below each, the residual measured − model in µm with the tracking uncertainty (median σ) shaded grey. \
             The background is shaded by phase: flight in, compression, restitution, flight out.",
        );
    }
    caption
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_every_shot_carries_are_said_once() {
        let shot = |notes: &[&str]| ShotPlot {
            notes: notes.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        };
        let r = Report {
            shots: vec![
                shot(&["level", "gap", "level"]),
                shot(&["gap", "level"]),
                shot(&["level"]),
            ],
            ..Default::default()
        };
        assert_eq!(shared_notes(&r), ["level"]);
        assert_eq!(own_notes(&r.shots[0], &shared_notes(&r)), ["gap"]);
        let one = Report {
            shots: vec![shot(&["level"])],
            ..Default::default()
        };
        assert!(shared_notes(&one).is_empty(), "one shot: its notes are its own");
    }
}
