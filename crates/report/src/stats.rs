//! The statistics sections from `bouncelab-stats` results: ANCOVA tables (the paper's Table 1, Type I and
//! Type II) with the coefficients' tests, comparisons of surfaces and angles on covariate-adjusted means
//! from the same fit with an interval plot (Figure 10), and residual diagnostics whose caption says what the
//! curvature and normality tests found (Figure 11).

use std::fmt::Write;

use bouncelab_stats::{
    Ancova, AncovaInference, AnovaRow, AnovaTable, Diagnostics, FTest, MarginalComparison, MarginalMeans,
    ResidualTests, TestOutcome,
};

use crate::data::Section;

use crate::fmt::{esc, fixed, num, opt, p_value, short};
use crate::html::{Ctx, nc, table, tc, unavailable};
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

/// The ANCOVA section: model summary, Type I and Type II tables, and the coefficients with their tests.
pub(crate) fn ancova_section(ctx: &Ctx) -> String {
    let r = ctx.report;
    let Some(a) = r.ancova.get() else {
        return crate::html::section_or(&r.ancova, |_| String::new());
    };
    let fit = &a.fit;
    let total_ss = a.type1.total.ss;
    let r2 = 1.0 - fit.rss / total_ss;
    let terms: Vec<String> = fit.terms.iter().map(|t| esc(t)).collect();
    let mut s = format!(
        "<p>Main-effects linear model of the COR on {} (factors treatment-coded, first level the reference; no \
         interactions; v_in_n is the incoming normal speed |v<sub>n,in</sub>| in m/s): n = {}, residual df = {}, \
         σ̂ = {}, R² = {}.</p>\n",
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
    match r.inference.get() {
        Some(inf) => {
            let t = &inf.coefficients;
            let level = format!("{}%", short(100.0 * (1.0 - t.alpha), 3));
            let _ = writeln!(
                s,
                "<p>Each coefficient with its standard error, t on the residual df ({}) and two-sided p, and its {level} \
                 confidence interval. A surface or angle coefficient is the COR difference from the reference level at \
                 equal other terms; the v_in_n row is the COR's slope per m/s of impact speed.</p>",
                t.df
            );
            let rows: Vec<Vec<String>> = t
                .rows
                .iter()
                .map(|c| {
                    vec![
                        format!("<code>{}</code>", esc(&c.name)),
                        num(c.estimate, 4),
                        num(c.se, 3),
                        num(c.t, 3),
                        p_value(c.p),
                        format!("{} to {}", num(c.lower, 4), num(c.upper, 4)),
                    ]
                })
                .collect();
            s.push_str(&table(
                &[
                    tc("Coefficient"),
                    nc("Estimate"),
                    nc("SE"),
                    nc("t"),
                    nc("p"),
                    nc(&format!("{level} interval")),
                ],
                &rows,
            ));
        }
        None => {
            let rows: Vec<Vec<String>> = fit
                .coefficient_names
                .iter()
                .zip(&fit.coefficients)
                .map(|(n, c)| vec![format!("<code>{}</code>", esc(n)), num(*c, 4)])
                .collect();
            s.push_str(&table(&[tc("Coefficient"), nc("Estimate")], &rows));
            if let Section::Unavailable(why) = &r.inference {
                s.push_str(&unavailable(&format!("standard errors and tests: {why}")));
            }
        }
    }
    s
}

/// One factor's adjusted means and their comparisons, with the interval figure.
fn factor_comparisons(ctx: &mut Ctx, m: &MarginalMeans) -> String {
    let level = if m.alpha > 0.0 && m.alpha < 1.0 {
        format!("{}% ", short(100.0 * (1.0 - m.alpha), 3))
    } else {
        String::new()
    };
    let mut s = means_intro(m, &level);
    s.push_str(&means_table(ctx, m, &level));
    if m.pairs.is_empty() {
        s.push_str(&unavailable("fewer than two levels to compare"));
        return s;
    }
    s.push_str(&pairs_table(m, &level));
    let (n, id) = ctx.next_figure();
    let chart = pairs_chart(id, m, &level);
    s.push_str(&ctx.figure(
        n,
        &[chart],
        &format!(
            "Tukey–Kramer simultaneous {level}intervals of the differences between adjusted mean COR by {} (the paper's \
             Figure 10, on covariate-adjusted means). An interval that does not cross the dashed zero line marks a \
             difference at the family-wise level α = {}.",
            esc(&m.factor),
            short(m.alpha, 3)
        ),
    ));
    s
}

/// The heading and the sentence saying where the means are taken and how pairs are compared.
fn means_intro(m: &MarginalMeans, level: &str) -> String {
    let at: Vec<String> = m
        .covariates_at
        .iter()
        .map(|g| {
            let unit = if g.name == "v_in_n" { " m/s" } else { "" };
            format!("{} = {}{unit}", esc(&g.name), num(g.value, 4))
        })
        .collect();
    let over = if m.averaged_over.is_empty() {
        String::new()
    } else {
        format!(
            ", averaged with equal weights over the levels of {}",
            m.averaged_over.iter().map(|f| esc(f)).collect::<Vec<_>>().join(", ")
        )
    };
    let is_surface = m.factor == "surface";
    format!(
        "<h3>By {}</h3>\n<p>Estimated marginal means of the COR from the same ANCOVA fit: each {} at {}{over}. Pairs \
         are compared on these adjusted means with the fit's residual mean square ({}) and df ({}); p-values are \
         adjusted for the {} pairs by Tukey–Kramer (simultaneous {level}intervals, critical q = {}) and by \
         Holm.</p>\n",
        esc(&m.factor),
        if is_surface { "surface" } else { "level" },
        if at.is_empty() {
            "the reference grid".to_string()
        } else {
            at.join(", ")
        },
        num(m.mse, 3),
        m.df,
        m.pairs.len(),
        num(m.q_crit, 4),
    )
}

/// The adjusted mean of every level with its interval, beside the raw mean.
fn means_table(ctx: &Ctx, m: &MarginalMeans, level: &str) -> String {
    let is_surface = m.factor == "surface";
    let label = |l: &str| {
        if is_surface {
            ctx.surface_cell(l)
        } else {
            format!("{}°", esc(l))
        }
    };
    let rows: Vec<Vec<String>> = m
        .means
        .iter()
        .map(|g| {
            vec![
                label(&g.level),
                g.n.to_string(),
                fixed(g.raw_mean, 4),
                crate::html::pm_cell(g.estimate, Some(g.se), 4),
                format!("{} to {}", fixed(g.lower, 4), fixed(g.upper, 4)),
            ]
        })
        .collect();
    table(
        &[
            tc(if is_surface { "Surface" } else { "Incline" }),
            nc("Shots"),
            nc("Raw mean COR"),
            nc("Adjusted mean ± SE"),
            nc(&format!("{level}interval")),
        ],
        &rows,
    )
}

/// Every pair's difference with its unadjusted, Tukey and Holm p-values.
fn pairs_table(m: &MarginalMeans, level: &str) -> String {
    let rows: Vec<Vec<String>> = m
        .pairs
        .iter()
        .map(|p| {
            vec![
                esc(&pair_name(p)),
                crate::html::pm_cell(p.estimate, Some(p.se), 3),
                num(p.t, 3),
                p_value(p.p),
                p_value(p.p_tukey),
                p_value(p.p_holm),
                format!("{} to {}", num(p.lower, 3), num(p.upper, 3)),
                if p.reject_tukey {
                    "<b>yes</b>".into()
                } else {
                    "no".into()
                },
            ]
        })
        .collect();
    table(
        &[
            tc("Difference"),
            nc("Estimate ± SE"),
            nc("t"),
            nc("p (unadjusted)"),
            nc("p (Tukey)"),
            nc("p (Holm)"),
            nc(&format!("Tukey {level}interval")),
            tc("Differ?"),
        ],
        &rows,
    )
}

/// "level2 − level1".
fn pair_name(p: &MarginalComparison) -> String {
    format!("{} − {}", p.level2, p.level1)
}

/// The Tukey intervals of the differences, those that exclude zero in their own colour.
fn pairs_chart(id: String, m: &MarginalMeans, level: &str) -> Chart {
    let mut c = Chart::new(id, 760.0, 110.0 + 30.0 * m.pairs.len() as f64);
    c.title = format!("Differences of adjusted mean COR by {}", m.factor);
    c.x_label = format!("difference in adjusted mean COR, with Tukey {level}simultaneous interval");
    c.y_categories = m.pairs.iter().map(pair_name).collect();
    c.x_include.push(0.0);
    c.items.push(Item::VRule {
        x: 0.0,
        color: "#555",
        dash: true,
    });
    for (reject, color, text) in [
        (true, "#D55E00", "interval excludes 0: means differ"),
        (false, "#0072B2", "interval includes 0"),
    ] {
        let idx: Vec<usize> = (0..m.pairs.len())
            .filter(|&i| m.pairs[i].reject_tukey == reject)
            .collect();
        if idx.is_empty() {
            continue;
        }
        c.items.push(Item::ErrorBars {
            bars: idx
                .iter()
                .map(|&i| ErrorBar {
                    x: m.pairs[i].estimate,
                    y: i as f64,
                    x_span: Some((m.pairs[i].lower, m.pairs[i].upper)),
                    y_span: None,
                })
                .collect(),
            color,
        });
        c.items.push(Item::Marks {
            marks: idx
                .iter()
                .map(|&i| {
                    let p = &m.pairs[i];
                    Mark {
                        x: p.estimate,
                        y: i as f64,
                        tip: Some(format!(
                            "{}: {} [{}, {}], p (Tukey) = {}",
                            pair_name(p),
                            num(p.estimate, 3),
                            num(p.lower, 3),
                            num(p.upper, 3),
                            p_value(p.p_tukey)
                        )),
                        href: None,
                    }
                })
                .collect(),
            color,
            shape: Shape::Circle,
            size: 8.0,
        });
        c.legend.push((
            text.into(),
            Key::Mark {
                color,
                shape: Shape::Circle,
            },
        ));
    }
    c
}

/// The comparisons section: every factor of the fit, surfaces first.
pub(crate) fn comparisons(ctx: &mut Ctx, inf: &AncovaInference) -> String {
    let mut s = String::from(
        "<p>Comparisons on the covariate-adjusted means of the same ANCOVA that tests the surfaces above, so they \
         agree with it: a one-way comparison of raw means would leave the impact speed's effect in its error and \
         can miss a difference the ANCOVA finds.</p>\n",
    );
    let mut ordered: Vec<&MarginalMeans> = inf.marginal_means.iter().filter(|m| m.factor == "surface").collect();
    ordered.extend(inf.marginal_means.iter().filter(|m| m.factor != "surface"));
    if ordered.is_empty() {
        s.push_str(&unavailable("the fit has no factor with two or more levels"));
    }
    for m in ordered {
        s.push_str(&factor_comparisons(ctx, m));
    }
    s
}

/// Observation labels: the clips of the COR points when they match the ANCOVA one to one.
fn obs_label(ctx: &Ctx, n: usize, i: usize) -> (String, Option<String>) {
    let pts = &ctx.report.measurements;
    match pts.get(i).filter(|_| pts.len() == n) {
        Some(p) => (format!("{} on {}", p.clip, p.surface), ctx.shot_href(&p.clip)),
        None => (format!("observation {}", i.saturating_add(1)), None),
    }
}

/// The residual diagnostics section.
pub(crate) fn diagnostics(ctx: &mut Ctx, a: &Ancova) -> String {
    let d = &a.diagnostics;
    let (fig, id) = ctx.next_figure();
    let c1 = studentized_chart(ctx, format!("{id}a"), d);
    let c2 = normal_plot_chart(ctx, format!("{id}b"), d);
    let found = match ctx.report.inference.get() {
        Some(i) => esc(&i.residual_tests.caption()),
        None => "Curvature and normality were not tested.".into(),
    };
    let mut s = ctx.figure(
        fig,
        &[c1, c2],
        &format!(
            "Residual diagnostics of the ANCOVA (the paper's Figure 11): externally studentized residuals against the \
             fitted COR, and the normal probability plot of the raw residuals. {found}"
        ),
    );
    if let Some(i) = ctx.report.inference.get() {
        s.push_str(&residual_tests(&i.residual_tests));
    }
    s.push_str(&residual_statistics(ctx, d));
    s
}

/// Studentized residuals against fitted values, with the ±2 band.
fn studentized_chart(ctx: &Ctx, id: String, d: &Diagnostics) -> Chart {
    let n = d.fitted.len();
    let mut c1 = Chart::new(id, 500.0, 360.0);
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
    c1
}

/// The standard normal's upper quartile Φ⁻¹(0.75): the quartiles of normal residuals lie this many σ from the
/// centre.
const NORMAL_Q3: f64 = 0.674_489_750_196_081_7;

/// The normal probability plot of the raw residuals, with the line through their quartiles.
fn normal_plot_chart(ctx: &Ctx, id: String, d: &Diagnostics) -> Chart {
    let n = d.fitted.len();
    let mut c2 = Chart::new(id, 500.0, 360.0);
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
        let z = NORMAL_Q3;
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
    c2
}

/// The curvature and normality tests of the residuals, each at its own α.
fn residual_tests(t: &ResidualTests) -> String {
    let ftest = |what: String, o: &TestOutcome<FTest>| match o {
        TestOutcome::Ran(f) => vec![
            what,
            format!("F({}, {}) = {}", f.df_num, f.df_den, num(f.f, 3)),
            p_value(f.p),
            if f.p < t.alpha {
                "curvature".into()
            } else {
                "none found".into()
            },
        ],
        TestOutcome::NotRun { reason } => vec![what, "—".into(), "—".into(), format!("not run: {}", esc(reason))],
    };
    let mut rows = vec![ftest("RESET (squared fitted values)".into(), &t.reset)];
    for q in &t.quadratic {
        rows.push(ftest(format!("quadratic term in {}", esc(&q.covariate)), &q.test));
    }
    rows.push(match &t.normality {
        TestOutcome::Ran(n) => vec![
            "D'Agostino–Pearson normality".into(),
            format!(
                "K² = {} (skew {}, kurtosis {})",
                num(n.k2, 3),
                num(n.skewness, 3),
                num(n.kurtosis, 3)
            ),
            p_value(n.p),
            if n.p < t.alpha {
                "not normal".into()
            } else {
                "consistent with normal".into()
            },
        ],
        TestOutcome::NotRun { reason } => vec![
            "D'Agostino–Pearson normality".into(),
            "—".into(),
            "—".into(),
            format!("not run: {}", esc(reason)),
        ],
    });
    let mut s = format!(
        "<p>Tests of the residuals, each at α = {} on its own:</p>\n",
        short(t.alpha, 3)
    );
    s.push_str(&table(&[tc("Test"), nc("Statistic"), nc("p"), tc("Finding")], &rows));
    s
}

/// Skewness, kurtosis, the number of observations and the largest studentized residual.
fn residual_statistics(ctx: &Ctx, d: &Diagnostics) -> String {
    let n = d.fitted.len();
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
    table(&[tc("Residual statistic"), nc("Value"), nc("If normal")], &rows)
}
