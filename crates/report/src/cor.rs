//! The coefficient of restitution against impact speed (the paper's Figures 6–7) and against the angle
//! (Figure 8), per surface, with ±1 SE error bars, least-squares trend lines and a table of the trends.

use crate::data::CorPoint;
use crate::fmt::{fixed, num, short};
use crate::page::{Ctx, nc, table, tc, unavailable};
use crate::svg::{Chart, ErrorBar, Item, Key, Mark};

/// Least-squares line y = a + b·x: (a, b, SE of b, n); `None` with fewer than 3 points or no spread in x.
pub(crate) fn ols(pts: &[(f64, f64)]) -> Option<(f64, f64, f64, usize)> {
    let pts: Vec<(f64, f64)> = pts
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    let n = pts.len();
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / nf;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / nf;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if !(sxx > 0.0 && sxx.is_finite() && sxy.is_finite()) {
        return None;
    }
    let b = sxy / sxx;
    let a = my - b * mx;
    let rss: f64 = pts.iter().map(|p| (p.1 - a - b * p.0).powi(2)).sum();
    let se = (rss / (nf - 2.0) / sxx).sqrt();
    (a.is_finite() && b.is_finite()).then_some((a, b, se, n))
}

fn tip(p: &CorPoint) -> String {
    let se = p.cor_se.map_or(String::new(), |s| format!(" ± {}", fixed(s, 3)));
    format!(
        "{} ({}): COR {}{se} at |v_n,in| = {} m/s, {}°",
        p.clip,
        p.surface,
        fixed(p.cor, 3),
        fixed(p.v_in_n.abs(), 3),
        short(p.angle_deg, 3)
    )
}

fn marks(ctx: &Ctx, pts: &[&CorPoint], x: impl Fn(&CorPoint) -> f64) -> Vec<Mark> {
    pts.iter()
        .map(|p| Mark {
            x: x(p),
            y: p.cor,
            tip: Some(tip(p)),
            href: ctx.shot_href(&p.clip),
        })
        .collect()
}

/// The COR section.
pub(crate) fn render(ctx: &mut Ctx) -> String {
    let all = &ctx.report.cor_points;
    if all.is_empty() {
        return unavailable("no shot has a measured COR");
    }
    let surfaces: Vec<String> = ctx
        .surfaces
        .iter()
        .filter(|s| all.iter().any(|p| &p.surface == *s))
        .cloned()
        .collect();
    let mut out = String::new();

    // COR vs impact speed.
    let (n, id) = ctx.next_figure();
    let mut c = Chart::new(id, 760.0, 420.0);
    c.title = "COR against impact speed".into();
    c.x_label = "impact speed |v_{n,in}| (m/s)".into();
    c.y_label = "coefficient of restitution e".into();
    let mut trend_rows = Vec::new();
    for s in &surfaces {
        let (color, shape) = ctx.style(s);
        let pts: Vec<&CorPoint> = all.iter().filter(|p| &p.surface == s).collect();
        let bars = pts
            .iter()
            .map(|p| ErrorBar {
                x: p.v_in_n.abs(),
                y: p.cor,
                x_span: p.v_in_n_se.map(|e| (p.v_in_n.abs() - e, p.v_in_n.abs() + e)),
                y_span: p.cor_se.map(|e| (p.cor - e, p.cor + e)),
            })
            .collect();
        c.items.push(Item::ErrorBars { bars, color });
        let xy: Vec<(f64, f64)> = pts.iter().map(|p| (p.v_in_n.abs(), p.cor)).collect();
        if let Some((a, b, se, k)) = ols(&xy) {
            let xs = xy.iter().map(|p| p.0).filter(|x| x.is_finite());
            let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)));
            c.items.push(Item::Line {
                pts: vec![(lo, a + b * lo), (hi, a + b * hi)],
                color,
                width: 1.3,
                dash: true,
            });
            let t = b / se;
            trend_rows.push(vec![
                ctx.surface_cell(s),
                k.to_string(),
                num(b, 3),
                num(se, 2),
                num(t, 3),
                fixed(a, 3),
            ]);
        } else {
            trend_rows.push(vec![
                ctx.surface_cell(s),
                pts.len().to_string(),
                "—".into(),
                "—".into(),
                "—".into(),
                "—".into(),
            ]);
        }
        c.items.push(Item::Marks {
            marks: marks(ctx, &pts, |p| p.v_in_n.abs()),
            color,
            shape,
            size: 7.0,
        });
        c.legend.push((s.clone(), Key::Mark { color, shape }));
    }
    if c.items.iter().any(|i| matches!(i, Item::Line { .. })) {
        c.legend.push((
            "least-squares trend".into(),
            Key::Line {
                color: "#555",
                dash: true,
            },
        ));
    }
    out.push_str(&ctx.figure(
        n,
        &[c],
        "Coefficient of restitution against the incoming normal speed, per surface (the paper's Figures 6–7), \
         with ±1 standard error bars and each surface's least-squares line (dashed). Hover a point for its \
         clip; click it for the shot's plots.",
    ));
    out.push_str("<h3>COR trend with impact speed</h3>\n");
    out.push_str(&table(
        &[
            tc("Surface"),
            nc("Shots"),
            nc("Slope (1/(m/s))"),
            nc("SE"),
            nc("t"),
            nc("Intercept"),
        ],
        &trend_rows,
    ));
    out.push_str(
        "<p>Ordinary least squares of COR on |v<sub>n,in</sub>| per surface, ignoring the angle; the ANCOVA below \
         separates the two.</p>\n",
    );

    // COR vs angle, points offset by surface.
    let mut angles: Vec<f64> = all.iter().map(|p| p.angle_deg).filter(|a| a.is_finite()).collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    let gap = angles.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
    let gap = if gap.is_finite() && gap > 0.0 { gap } else { 5.0 };
    let k = surfaces.len().max(1) as f64;
    let step = (gap * 0.5 / k).min(gap * 0.12);
    let (n, id) = ctx.next_figure();
    let mut c = Chart::new(id, 760.0, 400.0);
    c.title = "COR against surface angle".into();
    c.x_label = "surface angle (°)".into();
    c.y_label = "coefficient of restitution e".into();
    for (si, s) in surfaces.iter().enumerate() {
        let (color, shape) = ctx.style(s);
        let off = (si as f64 - (k - 1.0) / 2.0) * step;
        let pts: Vec<&CorPoint> = all.iter().filter(|p| &p.surface == s).collect();
        let bars = pts
            .iter()
            .map(|p| ErrorBar {
                x: p.angle_deg + off,
                y: p.cor,
                x_span: None,
                y_span: p.cor_se.map(|e| (p.cor - e, p.cor + e)),
            })
            .collect();
        c.items.push(Item::ErrorBars { bars, color });
        c.items.push(Item::Marks {
            marks: marks(ctx, &pts, |p| p.angle_deg + off),
            color,
            shape,
            size: 7.0,
        });
        c.legend.push((s.clone(), Key::Mark { color, shape }));
    }
    out.push_str(&ctx.figure(
        n,
        &[c],
        &format!(
            "Coefficient of restitution against the surface angle, per surface (the paper's Figure 8), with ±1 \
             standard error bars. Points of different surfaces at one angle are offset by {}° for legibility.",
            short(step, 2)
        ),
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ols_recovers_a_line_and_refuses_degenerate_input() {
        let pts: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, 0.8 - 0.04 * i as f64)).collect();
        let (a, b, se, n) = ols(&pts).unwrap();
        assert!((a - 0.8).abs() < 1e-12 && (b + 0.04).abs() < 1e-12 && se < 1e-9 && n == 10);
        assert!(ols(&[(1.0, 1.0), (1.0, 2.0), (1.0, 3.0)]).is_none());
        assert!(ols(&[(1.0, 1.0), (2.0, f64::NAN)]).is_none());
    }
}
