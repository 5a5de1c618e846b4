//! The diagnosis: the verdict, shown prominently, its evidence, where the current model's residual sits,
//! the ranked candidates and the model history.

use std::fmt::Write;

use crate::data::{DiagnosisSection, Phase, SignatureRow, VerdictKind};
use crate::fmt::{esc, esc_code, fixed, opt, um};
use crate::html::{Ctx, change_pct, nc, table, tc, unavailable};

/// The CSS class of a verdict box.
pub(crate) fn kind_class(k: VerdictKind) -> &'static str {
    match k {
        VerdictKind::MissingEffect => "missing_effect",
        VerdictKind::NoMissingEffect => "no_missing_effect",
        VerdictKind::NoCandidateExplains => "no_candidate_explains",
        VerdictKind::Ambiguous => "ambiguous",
    }
}

/// A signature row's component and phase: "normal, flight out".
pub(crate) fn row_label(r: &SignatureRow) -> String {
    component_phase(r.normal, r.phase)
}

/// "normal, flight out" (`normal` false: "tangential, …").
pub(crate) fn component_phase(normal: bool, phase: Phase) -> String {
    format!("{}, {}", if normal { "normal" } else { "tangential" }, phase.label())
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
        s.push_str(&signature_table(&d.signature));
    }
    s.push_str("<h3>Candidate effects</h3>\n");
    s.push_str(&candidates(d));
    s.push_str("<h3>Model history</h3>\n");
    s.push_str(&history(d));
    s
}

/// The residual per phase and component: RMS, its systematic part and its share of χ².
fn signature_table(signature: &[SignatureRow]) -> String {
    let rows: Vec<Vec<String>> = signature
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
    table(
        &[
            tc("Component, phase"),
            nc("RMS (µm)"),
            nc("Systematic part (µm)"),
            nc("Share of χ² (%)"),
        ],
        &rows,
    )
}

/// The candidates tried, best first, with their errors before and after and ΔBIC.
fn candidates(d: &DiagnosisSection) -> String {
    if d.candidates.is_empty() {
        return unavailable("no candidate effect was tried");
    }
    let mut s = String::new();
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
    s
}

/// The store's model versions with their errors.
fn history(d: &DiagnosisSection) -> String {
    if d.model_history.is_empty() {
        return unavailable("no earlier model versions in the store");
    }
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
    table(
        &[
            nc("Version"),
            tc("Model"),
            tc("Fitted"),
            nc("RMS (µm)"),
            nc("Reduced χ²"),
        ],
        &rows,
    )
}
