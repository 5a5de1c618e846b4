//! The summary and the shots section: a table of every shot linking to its plots (trajectory with the
//! model over it, residuals shaded by phase), a bar chart of the fit error per shot, and the plots
//! themselves in collapsed blocks, the worst and best fits open.

use std::fmt::Write;

use crate::data::{Phase, ShotPlot, VerdictKind};
use crate::fmt::{esc, fixed, mm, num, opt, p_value, short};
use crate::page::{Ctx, nc, table, tc};
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

/// Bars per shot (in millimetres): horizontal with clip names for up to 40 shots, vertical and unlabelled
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
            let val = v * 1e3;
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
                tip: Some(format!("{} ({}) {label}{} mm", row.clip, row.surface, num(val, 3))),
                href: ctx.shot_href(&row.clip),
            });
        }
    }
    let legend_rows = if m == 1 { ctx.surfaces.len().div_ceil(5) } else { 1 };
    let mut c = if horizontal {
        let mut c = Chart::new(
            id,
            720.0,
            70.0 + 17.0 * legend_rows as f64 + rows.len().max(1) as f64 * (8.0 + 8.0 * m as f64),
        );
        c.y_categories = rows.iter().map(|r| r.clip.clone()).collect();
        c.x_label = value_label.into();
        c.x_include.push(0.0);
        c
    } else {
        let mut c = Chart::new(id, 960.0, 300.0);
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

/// The summary section.
pub(crate) fn summary(ctx: &mut Ctx) -> String {
    let r = ctx.report;
    let mut facts: Vec<(String, String)> = Vec::new();
    match r.diagnosis.get() {
        Some(d) => {
            let class = match d.verdict_kind {
                VerdictKind::MissingEffect => "bad",
                VerdictKind::NoMissingEffect => "good",
                VerdictKind::NoCandidateExplains | VerdictKind::Ambiguous => "bad",
            };
            facts.push((
                "Verdict".into(),
                format!(
                    r##"<a href="#diagnosis"><b class="{class}">{}</b></a>: {}"##,
                    d.verdict_kind.label(),
                    esc(&d.verdict_text)
                ),
            ));
        }
        None => facts.push(("Verdict".into(), "no diagnosis in this report".into())),
    }
    if let Some(f) = r.fit.get() {
        let mut s = format!(r##"<a href="#fit">{}</a>"##, esc(&f.model_name));
        if let Some(e) = f.mean_abs_error_pct {
            let _ = write!(s, "; mean absolute COR error {} %", num(e, 3));
        }
        if let Some(c) = f.reduced_chi2 {
            let _ = write!(s, "; reduced χ² {}", num(c, 3));
        }
        facts.push(("Model".into(), s));
    }
    if let Some(row) = r
        .ancova
        .get()
        .and_then(|a| a.type1.terms.iter().find(|t| t.source == "surface"))
    {
        facts.push((
            "Surface effect on COR".into(),
            format!(
                r##"F = {}, p = {} (<a href="#ancova">ANCOVA, Type I</a>)"##,
                opt(row.f, 3),
                row.p.map_or("—".into(), p_value)
            ),
        ));
    }
    let ranked = ranked(ctx);
    if let (Some(best), Some(worst)) = (ranked.first(), ranked.last()) {
        let clip = |i: usize| {
            let s = &r.shots[i];
            format!(r##"<a href="#{}">{}</a>"##, esc(&ctx.shot_ids[i]), esc(&s.clip))
        };
        facts.push((
            "Fit error per shot".into(),
            format!(
                "RMS {} mm ({}) to {} mm ({})",
                mm(best.1, 3),
                clip(best.0),
                mm(worst.1, 3),
                clip(worst.0)
            ),
        ));
    }
    facts.push((
        "Warnings".into(),
        if r.warnings.is_empty() {
            "none".into()
        } else {
            format!(r##"<a href="#warnings">{}</a>"##, r.warnings.len())
        },
    ));
    let mut s = String::from(r#"<table class="facts"><tbody>"#);
    for (k, v) in facts {
        let _ = write!(s, "<tr><th>{k}</th><td>{v}</td></tr>");
    }
    s.push_str("</tbody></table>\n");
    s.push_str(&cor_by_surface(ctx));
    s
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = if v.len() > 1 {
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        f64::NAN
    };
    (mean, sd)
}

/// COR per surface: count, mean, SD, speeds and angles.
fn cor_by_surface(ctx: &Ctx) -> String {
    let pts = &ctx.report.cor_points;
    if pts.is_empty() {
        return String::new();
    }
    let mut rows = Vec::new();
    for surface in &ctx.surfaces {
        let of: Vec<_> = pts.iter().filter(|p| &p.surface == surface).collect();
        if of.is_empty() {
            continue;
        }
        let cors: Vec<f64> = of.iter().map(|p| p.cor).filter(|v| v.is_finite()).collect();
        let speeds: Vec<f64> = of.iter().map(|p| p.v_in_n.abs()).filter(|v| v.is_finite()).collect();
        let mut angles: Vec<f64> = of.iter().map(|p| p.angle_deg).filter(|v| v.is_finite()).collect();
        angles.sort_by(f64::total_cmp);
        angles.dedup();
        let (mean, sd) = if cors.is_empty() {
            (f64::NAN, f64::NAN)
        } else {
            mean_sd(&cors)
        };
        let range = if speeds.is_empty() {
            "—".into()
        } else {
            let lo = speeds.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = speeds.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            format!("{}–{}", fixed(lo, 2), fixed(hi, 2))
        };
        let angles: Vec<String> = angles.iter().map(|a| short(*a, 3)).collect();
        rows.push(vec![
            ctx.surface_cell(surface),
            of.len().to_string(),
            fixed(mean, 3),
            fixed(sd, 3),
            range,
            angles.join(", "),
        ]);
    }
    let mut s = String::from("<h3>COR by surface</h3>\n");
    s.push_str(&table(
        &[
            tc("Surface"),
            nc("Shots"),
            nc("Mean COR"),
            nc("SD"),
            nc("|v<sub>n,in</sub>| (m/s)"),
            tc("Angles (°)"),
        ],
        &rows,
    ));
    s
}

/// The shots section.
pub(crate) fn render(ctx: &mut Ctx) -> String {
    let r = ctx.report;
    if r.shots.is_empty() {
        return crate::page::unavailable("no shot was tracked");
    }
    let (worst, best) = featured(ctx);
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
        s.push_str(" Their plots are open below; every other shot's plots open from its name in the table.</p>\n");
    }
    // Fit error per shot.
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
    if !rows.is_empty() {
        let (n, id) = ctx.next_figure();
        let mut chart = per_shot_bars(
            ctx,
            id,
            &rows,
            &[("RMS".into(), "#0072B2")],
            "RMS position residual (mm)",
        );
        chart.title = "Fit error per shot".into();
        s.push_str(&ctx.figure(
            n,
            &[chart],
            "RMS of the position residuals (measured − model, x and y together) per shot, coloured by surface. \
             Each bar links to the shot's plots.",
        ));
    }
    // Selector (shown by the script only).
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
    // Table.
    let mut rows = Vec::new();
    for (i, sh) in r.shots.iter().enumerate() {
        let cp = r.cor_points.iter().find(|c| c.clip == sh.clip);
        let cor = cp.map_or("—".into(), |c| match c.cor_se {
            Some(se) => format!("{} ± {}", fixed(c.cor, 3), fixed(se, 3)),
            None => fixed(c.cor, 3),
        });
        let mut tags = String::new();
        if worst.contains(&i) {
            tags.push_str(r#"<span class="tag worst">worst</span>"#);
        }
        if best.contains(&i) {
            tags.push_str(r#"<span class="tag best">best</span>"#);
        }
        rows.push(vec![
            (i + 1).to_string(),
            format!(r##"<a href="#{}">{}</a>{tags}"##, esc(&ctx.shot_ids[i]), esc(&sh.clip)),
            ctx.surface_cell(&sh.surface),
            short(sh.angle_deg, 3),
            sh.drop_height_m.map_or("—".into(), |h| fixed(h, 3)),
            cp.map_or("—".into(), |c| fixed(c.v_in_n.abs(), 3)),
            cor,
            sh.measured.len().to_string(),
            rms_of(sh).map_or("—".into(), |v| mm(v, 3)),
            opt(sh.chi2_red, 3),
            esc(&sh.notes.join("; ")),
        ]);
    }
    s.push_str(&table(
        &[
            nc("#"),
            tc("Clip"),
            tc("Surface"),
            nc("Angle (°)"),
            nc("Drop (m)"),
            nc("|v<sub>n,in</sub>| (m/s)"),
            nc("COR"),
            nc("Frames"),
            nc("RMS (mm)"),
            nc("χ²<sub>red</sub>"),
            tc("Notes"),
        ],
        &rows,
    ));
    // Plots.
    s.push_str("<h3>Trajectories and residuals</h3>\n");
    let budget = (POINT_BUDGET / r.shots.len()).clamp(60, 250);
    for i in 0..r.shots.len() {
        let open = worst.contains(&i) || best.contains(&i);
        s.push_str(&shot_block(ctx, i, open, budget, worst.contains(&i), best.contains(&i)));
    }
    s
}

fn shot_block(ctx: &mut Ctx, i: usize, open: bool, budget: usize, worst: bool, best: bool) -> String {
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
        let _ = write!(s, " · RMS {} mm", mm(rms, 3));
    }
    if let Some(c) = sh.chi2_red {
        let _ = write!(s, " · χ²<sub>red</sub> {}", num(c, 3));
    }
    if worst {
        s.push_str(r#"<span class="tag worst">worst fit</span>"#);
    }
    if best {
        s.push_str(r#"<span class="tag best">best fit</span>"#);
    }
    s.push_str("</summary>\n");
    if !sh.notes.is_empty() {
        let notes: Vec<String> = sh.notes.iter().map(|n| esc(n)).collect();
        let _ = writeln!(s, r#"<p class="notes">{}</p>"#, notes.join("<br>"));
    }
    if sh.measured.is_empty() && sh.model.is_empty() {
        s.push_str(&crate::page::unavailable(
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

/// The contact window of a shot, s: from the first contact phase's start to the last one's end, widened
/// by 2 ms on each side.
fn contact_window(sh: &ShotPlot) -> Option<(f64, f64)> {
    let spans = sh
        .phases
        .iter()
        .filter(|p| matches!(p.phase, Phase::Compression | Phase::Restitution));
    let (lo, hi) = spans
        .flat_map(|p| [p.t0_s, p.t1_s])
        .filter(|t| t.is_finite() && t.abs() < 1e12)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| (a.min(t), b.max(t)));
    (lo.is_finite() && hi >= lo).then_some((lo - 2e-3, hi + 2e-3))
}

fn shot_figure(ctx: &mut Ctx, i: usize, budget: usize) -> String {
    const W: f64 = 490.0;
    let sh = &ctx.report.shots[i];
    let ms = |t: f64| t * 1e3;
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
    let bands: Vec<Item> = sh
        .phases
        .iter()
        .map(|p| Item::XBand {
            x0: ms(p.t0_s),
            x1: ms(p.t1_s),
            fill: phase_fill(p.phase),
        })
        .collect();
    let phase_legend: Vec<(String, Key)> = Phase::ALL
        .iter()
        .filter(|p| sh.phases.iter().any(|s| s.phase == **p))
        .map(|p| (p.label().to_string(), Key::Swatch { fill: phase_fill(*p) }))
        .collect();
    let idx = thin_indices(sh.measured.len(), budget, |k| in_contact(sh, sh.measured[k].t_s));
    let model_color = "#D55E00";
    let panel = |id: String,
                 title: &str,
                 y_label: &str,
                 get: &dyn Fn(usize) -> (f64, f64),
                 model: &dyn Fn(usize) -> (f64, f64)| {
        let mut c = Chart::new(id, W, 260.0);
        c.title = title.into();
        c.y_label = y_label.into();
        c.x_label = "t (ms)".into();
        c.x_range = x_range;
        c.items.extend(bands.iter().cloned());
        if !sh.model.is_empty() {
            c.items.push(Item::Line {
                pts: (0..sh.model.len()).map(model).collect(),
                color: model_color,
                width: 1.6,
                dash: false,
            });
        }
        c.items.push(Item::Marks {
            marks: idx.iter().map(|&k| get(k)).map(|(x, y)| Mark::at(x, y)).collect(),
            color: "#222",
            shape: Shape::Circle,
            size: 3.2,
        });
        c.legend.push((
            "measured".into(),
            Key::Mark {
                color: "#222",
                shape: Shape::Circle,
            },
        ));
        if !sh.model.is_empty() {
            c.legend.push((
                "model".into(),
                Key::Line {
                    color: model_color,
                    dash: false,
                },
            ));
        }
        c
    };
    let (n, id) = ctx.next_figure();
    let mut charts = vec![
        panel(
            format!("{id}a"),
            "Height above the surface",
            "y (mm)",
            &|k| (ms(sh.measured[k].t_s), sh.measured[k].y_m * 1e3),
            &|k| (ms(sh.model[k].t_s), sh.model[k].y_m * 1e3),
        ),
        panel(
            format!("{id}b"),
            "Position along the surface (down-slope)",
            "x (mm)",
            &|k| (ms(sh.measured[k].t_s), sh.measured[k].x_m * 1e3),
            &|k| (ms(sh.model[k].t_s), sh.model[k].x_m * 1e3),
        ),
    ];
    let mut caption = format!(
        "Shot {} on {} at {}°: tracked ball centre (dots; {} of {} frames shown, every frame near contact) ",
        esc(&sh.clip),
        esc(&sh.surface),
        short(sh.angle_deg, 3),
        idx.len(),
        sh.measured.len()
    );
    caption.push_str(if sh.model.is_empty() {
        "without a model"
    } else {
        "and the fitted model simulated for this shot (line)"
    });
    if sh.residuals.is_empty() {
        caption.push_str(". No residuals (no model was fitted to this shot).");
        return ctx.figure(n, &charts, &caption);
    }
    let sigma = median(sh.measured.iter().map(|p| p.sigma_m).collect());
    let zoom = contact_window(sh);
    let residual_chart =
        |id: String, title: &str, range: Option<(f64, f64)>, ridx: &[usize], legend: Vec<(String, Key)>| {
            let mut c = Chart::new(id, W, 280.0);
            c.title = title.into();
            c.y_label = "residual (mm)".into();
            c.x_label = "t (ms)".into();
            c.x_range = range;
            c.items.extend(bands.iter().cloned());
            if let Some(sg) = sigma {
                c.items.push(Item::YBand {
                    y0: -sg * 1e3,
                    y1: sg * 1e3,
                    fill: "#cfcfcf",
                });
            }
            c.items.push(Item::HRule {
                y: 0.0,
                color: "#555",
                dash: false,
            });
            c.y_include.push(0.0);
            let pick = |f: &dyn Fn(usize) -> f64| -> Vec<Mark> {
                ridx.iter()
                    .map(|&k| Mark::at(ms(sh.residuals[k].t_s), f(k) * 1e3))
                    .collect()
            };
            c.items.push(Item::Marks {
                marks: pick(&|k| sh.residuals[k].dx_m),
                color: "#D55E00",
                shape: Shape::Circle,
                size: 3.4,
            });
            c.items.push(Item::Marks {
                marks: pick(&|k| sh.residuals[k].dy_m),
                color: "#0072B2",
                shape: Shape::Square,
                size: 3.4,
            });
            c.legend = legend;
            c
        };
    let mut main_legend = vec![
        (
            "x (along surface)".to_string(),
            Key::Mark {
                color: "#D55E00",
                shape: Shape::Circle,
            },
        ),
        (
            "y (normal)".to_string(),
            Key::Mark {
                color: "#0072B2",
                shape: Shape::Square,
            },
        ),
    ];
    if sigma.is_some() {
        main_legend.push(("±1σ tracking".into(), Key::Swatch { fill: "#cfcfcf" }));
    }
    if zoom.is_none() {
        main_legend.extend(phase_legend.iter().cloned());
    }
    let ridx = thin_indices(sh.residuals.len(), budget, |k| in_contact(sh, sh.residuals[k].t_s));
    charts.push(residual_chart(
        format!("{id}c"),
        "Residuals, measured − model",
        x_range,
        &ridx,
        main_legend,
    ));
    if let Some((z0, z1)) = zoom {
        let inside: Vec<usize> = (0..sh.residuals.len())
            .filter(|&k| (z0..=z1).contains(&sh.residuals[k].t_s))
            .collect();
        let keep = thin_indices(inside.len(), budget, |_| false);
        let zidx: Vec<usize> = keep.into_iter().map(|k| inside[k]).collect();
        charts.push(residual_chart(
            format!("{id}d"),
            "Residuals around the contact",
            Some((ms(z0), ms(z1))),
            &zidx,
            phase_legend,
        ));
    }
    caption.push_str(
        "; residuals over the whole clip and around the contact (±2 ms), with the tracking uncertainty (median σ) \
         shaded grey. The background is shaded by phase: flight in, compression, restitution, flight out.",
    );
    ctx.figure(n, &charts, &caption)
}
