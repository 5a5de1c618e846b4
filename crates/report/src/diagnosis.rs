//! The diagnosis: the verdict, shown prominently, its evidence, the per-shot error before and after
//! adding the suggested effect, the ranked candidates and the model history.

use std::fmt::Write;

use crate::data::{DiagnosisSection, VerdictKind};
use crate::fmt::{esc, fixed, mm, num, opt};
use crate::page::{Ctx, nc, table, tc};
use crate::shots::{BarRow, per_shot_bars};

fn change_pct(before: f64, after: f64) -> String {
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

fn quadratic_mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = v.filter(|x| x.is_finite()).collect();
    (!v.is_empty()).then(|| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt())
}

/// The diagnosis section.
pub(crate) fn render(ctx: &mut Ctx, d: &DiagnosisSection) -> String {
    let kind = match d.verdict_kind {
        VerdictKind::MissingEffect => "missing_effect",
        VerdictKind::NoMissingEffect => "no_missing_effect",
        VerdictKind::NoCandidateExplains => "no_candidate_explains",
        VerdictKind::Ambiguous => "ambiguous",
    };
    let mut s = format!(
        "<div class=\"verdict v-{kind}\" role=\"status\"><p class=\"kind\">{}</p><p class=\"text\">{}</p></div>\n",
        d.verdict_kind.label(),
        esc(&d.verdict_text)
    );
    if !d.evidence.is_empty() {
        let head = if d.verdict_kind == VerdictKind::NoCandidateExplains {
            "Signature of the residual"
        } else {
            "Evidence"
        };
        let _ = write!(s, "<h3>{head}</h3>\n<ul>");
        for e in &d.evidence {
            let _ = write!(s, "<li>{}</li>", esc(e));
        }
        s.push_str("</ul>\n");
    }

    s.push_str("<h3>Error before and after</h3>\n");
    if d.before_after.is_empty() {
        s.push_str(&crate::page::unavailable(
            "the suggested effect has not been added and re-fitted yet",
        ));
    } else {
        let (tb, given_b) = match d.total_rms_before_m {
            Some(v) => (Some(v), true),
            None => (quadratic_mean(d.before_after.iter().map(|b| b.rms_before_m)), false),
        };
        let (ta, given_a) = match d.total_rms_after_m {
            Some(v) => (Some(v), true),
            None => (quadratic_mean(d.before_after.iter().map(|b| b.rms_after_m)), false),
        };
        let before = if d.model_before.is_empty() {
            "before".to_string()
        } else {
            d.model_before.clone()
        };
        let after = if d.model_after.is_empty() {
            "after".to_string()
        } else {
            d.model_after.clone()
        };
        if let (Some(tb), Some(ta)) = (tb, ta) {
            let _ = writeln!(
                s,
                "<p class=\"verdict-total\">Total RMS position residual: <b>{} mm</b> with {} → <b>{} mm</b> with {} \
                 ({} %){}.</p>",
                mm(tb, 3),
                esc(&before),
                mm(ta, 3),
                esc(&after),
                change_pct(tb, ta),
                if given_b && given_a {
                    ""
                } else {
                    "; quadratic mean of the per-shot values"
                }
            );
        }
        let mut rows: Vec<BarRow> = d
            .before_after
            .iter()
            .map(|b| BarRow {
                clip: b.clip.clone(),
                surface: b.surface.clone(),
                values: vec![b.rms_before_m, b.rms_after_m],
            })
            .collect();
        rows.sort_by(|a, b| b.values[0].total_cmp(&a.values[0]));
        let (n, id) = ctx.next_figure();
        let mut chart = per_shot_bars(
            ctx,
            id,
            &rows,
            &[
                (format!("before: {before}"), "#9a9a9a"),
                (format!("after: {after}"), "#0072B2"),
            ],
            "RMS position residual (mm)",
        );
        chart.title = "Fit error per shot, before and after".into();
        s.push_str(&ctx.figure(
            n,
            &[chart],
            "RMS position residual per shot with the earlier model (grey) and after adding the suggested effect \
             (blue), shots sorted by their error before. Each bar links to the shot's plots.",
        ));
        let mut trows: Vec<Vec<String>> = d
            .before_after
            .iter()
            .map(|b| {
                vec![
                    ctx.clip_link(&b.clip),
                    ctx.surface_cell(&b.surface),
                    mm(b.rms_before_m, 3),
                    mm(b.rms_after_m, 3),
                    change_pct(b.rms_before_m, b.rms_after_m),
                ]
            })
            .collect();
        if let (Some(tb), Some(ta)) = (tb, ta) {
            trows.push(vec![
                "\u{0}Total".into(),
                String::new(),
                mm(tb, 3),
                mm(ta, 3),
                change_pct(tb, ta),
            ]);
        }
        s.push_str("<details><summary>Per-shot values</summary>\n");
        s.push_str(&table(
            &[
                tc("Clip"),
                tc("Surface"),
                nc("RMS before (mm)"),
                nc("RMS after (mm)"),
                nc("Change (%)"),
            ],
            &trows,
        ));
        s.push_str("</details>\n");
    }

    s.push_str("<h3>Candidate effects</h3>\n");
    if d.candidates.is_empty() {
        s.push_str(&crate::page::unavailable("no candidate effect was tried"));
    } else {
        let metric = if d.error_metric.is_empty() {
            "error".to_string()
        } else {
            d.error_metric.clone()
        };
        let _ = writeln!(
            s,
            "<p>Each candidate effect was added to the current model and fitted; best first. Errors are {}; \
             ΔBIC &lt; 0 favours the effect.</p>",
            esc(&metric)
        );
        let rows: Vec<Vec<String>> = d
            .candidates
            .iter()
            .enumerate()
            .map(|(i, c)| {
                vec![
                    (i + 1).to_string(),
                    format!("<code>{}</code>", esc(&c.effect)),
                    num(c.error_before * 1e6, 3),
                    num(c.error_after * 1e6, 3),
                    change_pct(c.error_before, c.error_after),
                    fixed(c.delta_bic, 1),
                    opt(c.heldout_before.map(|v| v * 1e6), 3),
                    opt(c.heldout_after.map(|v| v * 1e6), 3),
                ]
            })
            .collect();
        s.push_str(&table(
            &[
                nc("Rank"),
                tc("Effect"),
                nc("Error before (µm)"),
                nc("Error after (µm)"),
                nc("Change (%)"),
                nc("ΔBIC"),
                nc("Held-out before (µm)"),
                nc("Held-out after (µm)"),
            ],
            &rows,
        ));
    }

    s.push_str("<h3>Model history</h3>\n");
    if d.model_history.is_empty() {
        s.push_str(&crate::page::unavailable("no earlier model versions in the store"));
    } else {
        let rows: Vec<Vec<String>> = d
            .model_history
            .iter()
            .map(|m| {
                vec![
                    m.version.to_string(),
                    esc(&m.model),
                    esc(&m.created),
                    m.rms_m.map_or("—".into(), |r| mm(r, 3)),
                    opt(m.chi2_red, 3),
                ]
            })
            .collect();
        s.push_str(&table(
            &[
                nc("Version"),
                tc("Model"),
                tc("Created"),
                nc("RMS (mm)"),
                nc("χ²<sub>red</sub>"),
            ],
            &rows,
        ));
    }
    s
}
