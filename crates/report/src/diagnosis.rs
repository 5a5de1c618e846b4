//! The diagnosis: the verdict, shown prominently, its evidence, where the current model's residual sits,
//! the ranked candidates and the model history.

use std::fmt::Write;

use crate::change::{change_pct, row_label};
use crate::data::{DiagnosisSection, VerdictKind};
use crate::fmt::{esc, esc_code, fixed, opt, um};
use crate::page::{Ctx, nc, table, tc};

/// The CSS class of a verdict box.
pub(crate) fn kind_class(k: VerdictKind) -> &'static str {
    match k {
        VerdictKind::MissingEffect => "missing_effect",
        VerdictKind::NoMissingEffect => "no_missing_effect",
        VerdictKind::NoCandidateExplains => "no_candidate_explains",
        VerdictKind::Ambiguous => "ambiguous",
    }
}

/// The diagnosis section.
pub(crate) fn render(_ctx: &mut Ctx, d: &DiagnosisSection) -> String {
    let mut s = format!(
        "<div class=\"verdict v-{}\" role=\"status\"><p class=\"kind\">{}</p><p class=\"text\">{}</p></div>\n",
        kind_class(d.verdict_kind),
        d.verdict_kind.label(),
        esc_code(&d.verdict_text)
    );
    if !d.evidence.is_empty() {
        let head = if d.verdict_kind == VerdictKind::NoCandidateExplains {
            "Signature of the residual"
        } else {
            "Evidence"
        };
        let _ = write!(s, "<h3>{head}</h3>\n<ul>");
        for e in &d.evidence {
            let _ = write!(s, "<li>{}</li>", esc_code(e));
        }
        s.push_str("</ul>\n");
    }
    if !d.signature.is_empty() {
        s.push_str("<h3>Where the current model's residual sits</h3>\n");
        let rows: Vec<Vec<String>> = d
            .signature
            .iter()
            .map(|r| {
                vec![
                    row_label(r),
                    um(r.rms_m),
                    um(r.systematic_m),
                    fixed(100.0 * r.chi2_share, 1),
                ]
            })
            .collect();
        s.push_str(&table(
            &[
                tc("Component, phase"),
                nc("RMS (µm)"),
                nc("Systematic part (µm)"),
                nc("Share of χ² (%)"),
            ],
            &rows,
        ));
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
                    um(c.error_before),
                    um(c.error_after),
                    change_pct(c.error_before, c.error_after),
                    fixed(c.delta_bic, 1),
                    c.heldout_before.map_or("—".into(), um),
                    c.heldout_after.map_or("—".into(), um),
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
                    m.rms_m.map_or("—".into(), um),
                    opt(m.chi2_red, 3),
                ]
            })
            .collect();
        s.push_str(&table(
            &[
                nc("Version"),
                tc("Model"),
                tc("Fitted"),
                nc("RMS (µm)"),
                nc("Reduced χ²"),
            ],
            &rows,
        ));
    }
    s
}
