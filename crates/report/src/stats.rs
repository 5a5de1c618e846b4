//! The statistics sections from `bouncelab-stats` results: ANCOVA tables (the paper's Table 1, Type I and
//! Type II), Tukey–Kramer comparisons with an interval plot (Figure 10) and residual diagnostics
//! (Figure 11).

use std::fmt::Write;

use bouncelab_stats::{Ancova, AnovaRow, AnovaTable, TukeyHsd};

use crate::fmt::{esc, fixed, num, opt, p_value, short};
use crate::page::{Ctx, nc, table, tc};
use crate::svg::{Chart, ErrorBar, Item, Key, Mark, Shape};

fn anova_rows(t: &AnovaTable) -> Vec<Vec<String>> {
    let row = |r: &AnovaRow, total: bool| {
        vec![
            format!("{}{}", if total { "\u{0}" } else { "" }, esc(&r.source)),
            num(r.ss, 4),
            r.df.to_string(),
            num(r.ms, 4),
            opt(r.f, 4),
            r.p.map_or("—".into(), p_value),
        ]
    };
    let mut rows: Vec<Vec<String>> = t.terms.iter().map(|r| row(r, false)).collect();
    rows.push(row(&t.error, false));
    rows.push(row(&t.total, true));
    rows
}

fn anova_table(t: &AnovaTable) -> String {
    table(
        &[tc("Source"), nc("SS"), nc("df"), nc("MS"), nc("F"), nc("p")],
        &anova_rows(t),
    )
}

/// The ANCOVA section: model summary, Type I and Type II tables, coefficients.
pub(crate) fn ancova_tables(a: &Ancova) -> String {
    let fit = &a.fit;
    let total_ss = a.type1.total.ss;
    let r2 = 1.0 - fit.rss / total_ss;
    let terms: Vec<String> = fit.terms.iter().map(|t| esc(t)).collect();
    let mut s = format!(
        "<p>Main-effects linear model of the COR on {} (factors treatment-coded, no interactions): n = {}, residual \
         df = {}, σ̂ = {}, R² = {}.</p>\n",
        if terms.is_empty() {
            "an intercept only".into()
        } else {
            terms.join(", ")
        },
        fit.n,
        fit.df_resid,
        num(fit.mse().sqrt(), 3),
        fixed(r2, 3)
    );
    s.push_str("<h3>Type I (sequential) sums of squares</h3>\n");
    s.push_str("<p>Each term adjusted for the terms above it, as in the paper's Table 1.</p>\n");
    s.push_str(&anova_table(&a.type1));
    s.push_str("<h3>Type II sums of squares</h3>\n");
    s.push_str("<p>Each term adjusted for every other term (no interactions, so the same as Type III).</p>\n");
    s.push_str(&anova_table(&a.type2));
    s.push_str("<h3>Coefficients</h3>\n");
    let rows: Vec<Vec<String>> = fit
        .coefficient_names
        .iter()
        .zip(&fit.coefficients)
        .map(|(n, c)| vec![esc(n), num(*c, 4)])
        .collect();
    s.push_str(&table(&[tc("Coefficient"), nc("Estimate")], &rows));
    s
}

/// The Tukey–Kramer section.
pub(crate) fn tukey(ctx: &mut Ctx, t: &TukeyHsd) -> String {
    // "95% " when α is a probability, nothing otherwise.
    let level = if t.alpha > 0.0 && t.alpha < 1.0 {
        format!("{}% ", short(100.0 * (1.0 - t.alpha), 3))
    } else {
        String::new()
    };
    let mut s = format!(
        "<p>Tukey–Kramer comparisons of the mean COR of every pair of surfaces at a family-wise level α = {} \
         (critical studentized range q = {}, error df = {}, pooled MSE = {}).</p>\n",
        short(t.alpha, 3),
        num(t.q_crit, 4),
        t.df,
        num(t.mse, 3)
    );
    let rows: Vec<Vec<String>> = t
        .groups
        .iter()
        .map(|g| vec![ctx.surface_cell(&g.name), g.n.to_string(), fixed(g.mean, 4)])
        .collect();
    s.push_str(&table(&[tc("Surface"), nc("Shots"), nc("Mean COR")], &rows));
    if t.pairs.is_empty() {
        s.push_str(&crate::page::unavailable("fewer than two groups to compare"));
        return s;
    }
    let rows: Vec<Vec<String>> = t
        .pairs
        .iter()
        .map(|p| {
            vec![
                format!("{} − {}", esc(&p.group2), esc(&p.group1)),
                num(p.mean_diff, 3),
                num(p.std_err, 3),
                num(p.q, 3),
                p_value(p.p_adj),
                num(p.lower, 3),
                num(p.upper, 3),
                if p.reject { "<b>yes</b>".into() } else { "no".into() },
            ]
        })
        .collect();
    s.push_str(&table(
        &[
            tc("Difference"),
            nc("Mean diff."),
            nc("SE"),
            nc("q"),
            nc("p (adj.)"),
            nc(&format!("{level}CI low")),
            nc("high"),
            tc("Differ?"),
        ],
        &rows,
    ));
    let (n, id) = ctx.next_figure();
    let mut c = Chart::new(id, 760.0, 110.0 + 30.0 * t.pairs.len() as f64);
    c.title = "Pairwise differences of mean COR".into();
    c.x_label = format!("difference in mean COR, with {level}simultaneous interval");
    c.y_categories = t.pairs.iter().map(|p| format!("{} − {}", p.group2, p.group1)).collect();
    c.x_include.push(0.0);
    c.items.push(Item::VRule {
        x: 0.0,
        color: "#555",
        dash: true,
    });
    for (reject, color, label) in [
        (true, "#D55E00", "interval excludes 0: means differ"),
        (false, "#0072B2", "interval includes 0"),
    ] {
        let idx: Vec<usize> = (0..t.pairs.len()).filter(|&i| t.pairs[i].reject == reject).collect();
        if idx.is_empty() {
            continue;
        }
        let bars = idx
            .iter()
            .map(|&i| {
                let p = &t.pairs[i];
                ErrorBar {
                    x: p.mean_diff,
                    y: i as f64,
                    x_span: Some((p.lower, p.upper)),
                    y_span: None,
                }
            })
            .collect();
        c.items.push(Item::ErrorBars { bars, color });
        let marks = idx
            .iter()
            .map(|&i| {
                let p = &t.pairs[i];
                Mark {
                    x: p.mean_diff,
                    y: i as f64,
                    tip: Some(format!(
                        "{} − {}: {} [{}, {}], p = {}",
                        p.group2,
                        p.group1,
                        num(p.mean_diff, 3),
                        num(p.lower, 3),
                        num(p.upper, 3),
                        p_value(p.p_adj)
                    )),
                    href: None,
                }
            })
            .collect();
        c.items.push(Item::Marks {
            marks,
            color,
            shape: Shape::Circle,
            size: 8.0,
        });
        c.legend.push((
            label.into(),
            Key::Mark {
                color,
                shape: Shape::Circle,
            },
        ));
    }
    s.push_str(&ctx.figure(
        n,
        &[c],
        "Tukey–Kramer simultaneous confidence intervals of the differences between surface mean COR (the paper's \
         Figure 10). An interval that does not cross the dashed zero line marks a significant difference.",
    ));
    s
}

/// Observation labels: the clips of the COR points when they match the ANCOVA one to one.
fn obs_label(ctx: &Ctx, n: usize, i: usize) -> (String, Option<String>) {
    let pts = &ctx.report.cor_points;
    match pts.get(i).filter(|_| pts.len() == n) {
        Some(p) => (format!("{} on {}", p.clip, p.surface), ctx.shot_href(&p.clip)),
        None => (format!("observation {}", i.saturating_add(1)), None),
    }
}

/// The residual diagnostics section.
pub(crate) fn diagnostics(ctx: &mut Ctx, a: &Ancova) -> String {
    let d = &a.diagnostics;
    let n = d.fitted.len();
    let (fig, id) = ctx.next_figure();
    // Studentized residuals against fitted values.
    let mut c1 = Chart::new(format!("{id}a"), 500.0, 360.0);
    c1.title = "Studentized residuals against fitted".into();
    c1.x_label = "fitted COR".into();
    c1.y_label = "externally studentized residual".into();
    c1.y_include.extend([-2.5, 2.5]);
    for y in [-2.0, 2.0] {
        c1.items.push(Item::HRule {
            y,
            color: "#999",
            dash: true,
        });
    }
    c1.items.push(Item::HRule {
        y: 0.0,
        color: "#555",
        dash: false,
    });
    let marks = d
        .fitted
        .iter()
        .zip(&d.studentized_external)
        .enumerate()
        .map(|(i, (f, r))| {
            let (label, href) = obs_label(ctx, n, i);
            Mark {
                x: *f,
                y: *r,
                tip: Some(format!("{label}: fitted {}, residual {}", fixed(*f, 3), num(*r, 3))),
                href,
            }
        })
        .collect();
    c1.items.push(Item::Marks {
        marks,
        color: "#0072B2",
        shape: Shape::Circle,
        size: 6.0,
    });
    c1.legend.push((
        "±2 (about 5% beyond, if normal)".into(),
        Key::Line {
            color: "#999",
            dash: true,
        },
    ));
    // Normal probability plot.
    let mut c2 = Chart::new(format!("{id}b"), 500.0, 360.0);
    c2.title = "Normal probability plot of the residuals".into();
    c2.x_label = "residual (COR)".into();
    c2.y_label = "standard normal quantile".into();
    let marks: Vec<Mark> = d
        .normal_plot
        .iter()
        .map(|p| {
            let (label, href) = obs_label(ctx, n, p.observation);
            Mark {
                x: p.residual,
                y: p.normal_quantile,
                tip: Some(format!(
                    "{label}: residual {}, p = {}",
                    num(p.residual, 3),
                    fixed(p.probability, 3)
                )),
                href,
            }
        })
        .collect();
    // Reference line through the quartiles (as MATLAB's normplot).
    let sorted: Vec<f64> = d
        .normal_plot
        .iter()
        .map(|p| p.residual)
        .filter(|r| r.is_finite())
        .collect();
    if sorted.len() >= 4 {
        let q = |p: f64| {
            let pos = p * (sorted.len() - 1) as f64;
            let (i, f) = (pos.floor() as usize, pos.fract());
            sorted[i] + f * (sorted[(i + 1).min(sorted.len() - 1)] - sorted[i])
        };
        let (q1, q3) = (q(0.25), q(0.75));
        let z = 0.674_489_750_196_081_7;
        if q3 > q1 {
            let slope = (q3 - q1) / (2.0 * z);
            let zs = [-3.0, 3.0];
            c2.items.push(Item::Line {
                pts: zs.iter().map(|&zz| (q1 + (zz + z) * slope, zz)).collect(),
                color: "#D55E00",
                width: 1.3,
                dash: true,
            });
            c2.legend.push((
                "line through the quartiles".into(),
                Key::Line {
                    color: "#D55E00",
                    dash: true,
                },
            ));
            let lo = d.normal_plot.first().map_or(-2.0, |p| p.normal_quantile);
            let hi = d.normal_plot.last().map_or(2.0, |p| p.normal_quantile);
            c2.y_range = Some((lo.min(-1.0) - 0.3, hi.max(1.0) + 0.3));
        }
    }
    c2.items.push(Item::Marks {
        marks,
        color: "#0072B2",
        shape: Shape::Circle,
        size: 6.0,
    });
    let mut s = ctx.figure(
        fig,
        &[c1, c2],
        "Residual diagnostics of the ANCOVA (the paper's Figure 11): externally studentized residuals against the \
         fitted COR (no pattern and few points beyond ±2 expected), and the normal probability plot of the raw \
         residuals (points on a straight line if normal).",
    );
    let (worst_i, worst) = d
        .studentized_external
        .iter()
        .enumerate()
        .filter(|(_, r)| r.is_finite())
        .fold(
            (None, 0.0f64),
            |(wi, w), (i, r)| if r.abs() > w { (Some(i), r.abs()) } else { (wi, w) },
        );
    let mut rows = vec![
        vec!["Skewness".into(), num(d.residual_skewness, 3), "0".into()],
        vec!["Kurtosis".into(), num(d.residual_kurtosis, 3), "3".into()],
        vec!["Observations".into(), n.to_string(), String::new()],
    ];
    if let Some(i) = worst_i {
        let (label, href) = obs_label(ctx, n, i);
        let label = match href {
            Some(h) => format!(r##"<a href="#{}">{}</a>"##, esc(&h), esc(&label)),
            None => esc(&label),
        };
        rows.push(vec![
            "Largest |studentized residual|".into(),
            num(worst, 3),
            String::new(),
        ]);
        let _ = write!(rows.last_mut().expect("just pushed")[0], " ({label})");
    }
    s.push_str(&table(&[tc("Residual statistic"), nc("Value"), nc("If normal")], &rows));
    s
}
