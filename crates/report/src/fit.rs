//! The model fit: parameters with intervals, the paper's mean absolute COR error per surface, and the
//! oblique validation (the paper's Figure 9) as a table and a predicted-vs-measured plot.

use crate::data::FitSummary;
use crate::fmt::{esc, fixed, num, opt, short, um};
use crate::html::{Ctx, facts, nc, section_or, table, tc, unavailable};
use crate::svg::{Chart, Item, Key, Mark, Shape};

/// The fit section.
pub(crate) fn render(ctx: &mut Ctx, f: &FitSummary) -> String {
    let mut s = facts(&fit_facts(f));
    s.push_str(
        "<p>The reduced χ² used throughout this report: χ²<sub>ν</sub> = χ²/ν, where χ² = Σ((model − measured)/σ)² \
         over both coordinates of every fitted frame (σ the tracker's uncertainty of that frame) and ν = the number \
         of those residuals − the fitted parameters (the shared ones and one surface level per shot). A shot's \
         χ²<sub>ν</sub> is its own χ² over its share of ν, in proportion to its frames, so the shots' values \
         average (weighted by frames) to the fit's. About 1 means the model follows the data to the tracking \
         noise.</p>\n",
    );
    s.push_str("<h3>Parameters</h3>\n");
    s.push_str(&parameters(f));
    s.push_str("<h3>COR error per surface</h3>\n");
    s.push_str(&cor_errors(ctx, f));
    s.push_str("<h3>Contact force</h3>\n");
    let report = ctx.report;
    s.push_str(&section_or(&report.contact_force, |c| crate::force::render(ctx, c)));
    s.push_str("<h3>Oblique validation</h3>\n");
    if f.oblique.is_empty() {
        s.push_str(&unavailable("no oblique shot with measured outgoing velocities"));
        return s;
    }
    s.push_str(&oblique_table(ctx, f));
    let (n, id) = ctx.next_figure();
    let chart = oblique_chart(ctx, id, f);
    s.push_str(&ctx.figure(
        n,
        &[chart],
        "Oblique validation (the paper's Figure 9): outgoing velocity components predicted by the fitted model \
         against the measured ones; points on the dashed line are predicted exactly.",
    ));
    s
}

/// The fit's facts: model, solver, reduced χ², RMS residual, mean absolute COR error (those known).
fn fit_facts(f: &FitSummary) -> Vec<(String, String)> {
    let mut facts = vec![("Model".to_string(), esc(&f.model_name))];
    if !f.termination.is_empty() {
        facts.push(("Solver".into(), esc(&f.termination)));
    }
    if let Some(c) = f.reduced_chi2 {
        let nu = f.dof.map_or(String::new(), |d| format!(" (ν = {d})"));
        facts.push(("Reduced χ² χ²<sub>ν</sub>".into(), format!("{}{nu}", num(c, 3))));
    }
    if let Some(r) = f.rms_m {
        facts.push(("RMS position residual".into(), format!("{} µm", um(r))));
    }
    if let Some(e) = f.mean_abs_error_pct {
        facts.push(("Mean absolute COR error".into(), format!("{} %", num(e, 3))));
    }
    facts
}

/// The fitted parameters with standard errors and intervals, or why there are none.
fn parameters(f: &FitSummary) -> String {
    let level = if f.confidence > 0.0 && f.confidence < 1.0 {
        format!("{}%", fixed(100.0 * f.confidence, 0))
    } else {
        "confidence".into()
    };
    let rows: Vec<Vec<String>> = f
        .parameters
        .iter()
        .map(|p| {
            // A length parameter (a surface level) is a fraction of a millimetre: shown in µm.
            let (k, unit) = if p.unit == "m" {
                (1e6, "µm".to_string())
            } else {
                (1.0, p.unit.clone())
            };
            vec![
                format!("<code>{}</code>", esc(&p.name)),
                num(p.value * k, 4),
                opt(p.std_error.map(|e| e * k), 2),
                p.interval
                    .map_or("—".into(), |[a, b]| format!("{} – {}", num(a * k, 4), num(b * k, 4))),
                crate::fmt::esc_code(&unit),
                if p.at_bound {
                    r#"<span class="bad">at a bound of the fit</span>"#.into()
                } else {
                    String::new()
                },
            ]
        })
        .collect();
    if rows.is_empty() {
        return unavailable("the fit has no free parameters");
    }
    table(
        &[
            tc("Parameter"),
            nc("Value"),
            nc("SE"),
            nc(&format!("{level} interval")),
            tc("Unit"),
            tc("Note"),
        ],
        &rows,
    )
}

/// The paper's mean absolute COR error per surface and over all shots.
fn cor_errors(ctx: &Ctx, f: &FitSummary) -> String {
    if f.by_surface.is_empty() {
        return unavailable("no shot with a measured COR");
    }
    let mut rows: Vec<Vec<String>> = f
        .by_surface
        .iter()
        .map(|e| {
            vec![
                ctx.surface_cell(&e.surface),
                e.shots.to_string(),
                num(e.mean_abs_error_pct, 3),
            ]
        })
        .collect();
    if let Some(e) = f.mean_abs_error_pct {
        let n: usize = f.by_surface.iter().map(|e| e.shots).sum();
        rows.push(vec!["\u{0}All".into(), n.to_string(), num(e, 3)]);
    }
    table(
        &[
            tc("Surface"),
            nc("Shots"),
            nc("Mean |e<sub>sim</sub> − e<sub>meas</sub>| / e<sub>meas</sub> (%)"),
        ],
        &rows,
    )
}

/// The oblique shots' outgoing velocity, measured against predicted, per component.
fn oblique_table(ctx: &Ctx, f: &FitSummary) -> String {
    let rows: Vec<Vec<String>> = f
        .oblique
        .iter()
        .map(|o| {
            vec![
                ctx.clip_link(&o.clip),
                ctx.surface_cell(&o.surface),
                short(o.angle_deg, 3),
                fixed(o.v_out_measured[0], 3),
                fixed(o.v_out_predicted[0], 3),
                num(o.error_pct[0], 3),
                fixed(o.v_out_measured[1], 3),
                fixed(o.v_out_predicted[1], 3),
                num(o.error_pct[1], 3),
            ]
        })
        .collect();
    table(
        &[
            tc("Clip"),
            tc("Surface"),
            nc("Angle (°)"),
            nc("v<sub>t,out</sub> meas. (m/s)"),
            nc("pred."),
            nc("error (%)"),
            nc("v<sub>n,out</sub> meas. (m/s)"),
            nc("pred."),
            nc("error (%)"),
        ],
        &rows,
    )
}

/// Predicted against measured outgoing velocity, both components, over the line of equality.
fn oblique_chart(ctx: &Ctx, id: String, f: &FitSummary) -> Chart {
    let mut c = Chart::new(id, 560.0, 460.0);
    c.title = "Outgoing velocity, predicted against measured".into();
    c.x_label = "measured (m/s)".into();
    c.y_label = "predicted (m/s)".into();
    let vals = f
        .oblique
        .iter()
        .flat_map(|o| o.v_out_measured.iter().chain(&o.v_out_predicted))
        .copied();
    let (lo, hi) = vals
        .filter(|v| v.is_finite() && v.abs() < 1e12)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if lo.is_finite() && hi >= lo {
        c.items.push(Item::Line {
            pts: vec![(lo, lo), (hi, hi)],
            color: "#888",
            width: 1.0,
            dash: true,
        });
        c.legend.push((
            "predicted = measured".into(),
            Key::Line {
                color: "#888",
                dash: true,
            },
        ));
    }
    for (k, label, color, shape) in [
        (0, "tangential component", "#D55E00", Shape::Circle),
        (1, "normal component", "#0072B2", Shape::Square),
    ] {
        let marks = f
            .oblique
            .iter()
            .map(|o| Mark {
                x: o.v_out_measured[k],
                y: o.v_out_predicted[k],
                tip: Some(format!(
                    "{} ({}, {}°): measured {}, predicted {} m/s ({} %)",
                    o.clip,
                    o.surface,
                    short(o.angle_deg, 3),
                    fixed(o.v_out_measured[k], 3),
                    fixed(o.v_out_predicted[k], 3),
                    num(o.error_pct[k], 3)
                )),
                href: ctx.shot_href(&o.clip),
            })
            .collect();
        c.items.push(Item::Marks {
            marks,
            color,
            shape,
            size: 7.0,
        });
        c.legend.push((label.into(), Key::Mark { color, shape }));
    }
    c
}
