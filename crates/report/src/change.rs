//! What changed since the previous model fitted to this session: the effects added, the verdict given to
//! the earlier model, where its residual sat against where the current one's sits, and the error per shot.

use crate::data::{ModelChange, Phase, SignatureRow};
use crate::diagnosis::{component_phase, kind_class, row_label};
use crate::fmt::{esc, fixed, num, um};
use crate::html::{Ctx, change_pct, facts, nc, table, tc, unavailable};
use crate::shots::{BarRow, per_shot_bars};
use crate::svg::{Bar, Chart, Item, Key};

fn key(r: &SignatureRow) -> (Phase, bool) {
    (r.phase, r.normal)
}

/// The (phase, component) rows of either signature, in time order, normal before tangential.
fn signature_keys(c: &ModelChange) -> Vec<(Phase, bool)> {
    let mut keys: Vec<(Phase, bool)> = Vec::new();
    for r in c.signature_before.iter().chain(&c.signature_after) {
        if !keys.contains(&key(r)) {
            keys.push(key(r));
        }
    }
    keys.sort();
    keys
}

/// The signature before and after side by side: systematic RMS per phase and component.
fn signature_chart(id: String, c: &ModelChange) -> Chart {
    let keys = signature_keys(c);
    let mut chart = Chart::new(id, 760.0, 90.0 + 34.0 * keys.len().max(1) as f64);
    chart.title = "Systematic residual per phase and component".into();
    chart.x_label = "systematic part of the RMS residual (µm)".into();
    chart.x_include.push(0.0);
    chart.y_categories = keys.iter().map(|&(p, n)| component_phase(n, p)).collect();
    let mut bars = Vec::new();
    for (i, k) in keys.iter().enumerate() {
        for (j, (rows, color, what)) in [
            (&c.signature_before, "#9a9a9a", "before"),
            (&c.signature_after, "#0072B2", "after"),
        ]
        .into_iter()
        .enumerate()
        {
            if let Some(r) = rows.iter().find(|r| key(r) == *k) {
                let a = i as f64 - 0.4 + j as f64 * 0.4;
                bars.push(Bar {
                    x0: 0.0,
                    x1: r.systematic_m * 1e6,
                    y0: a,
                    y1: a + 0.4,
                    color,
                    tip: Some(format!(
                        "{what}: {}: systematic {} µm of RMS {} µm, {} % of χ²",
                        row_label(r),
                        um(r.systematic_m),
                        um(r.rms_m),
                        fixed(100.0 * r.chi2_share, 0)
                    )),
                    href: None,
                });
            }
        }
    }
    chart.items.push(Item::Bars { bars });
    chart
        .legend
        .push((format!("before: {}", c.model_before), Key::Swatch { fill: "#9a9a9a" }));
    chart
        .legend
        .push((format!("after: {}", c.model_after), Key::Swatch { fill: "#0072B2" }));
    chart
}

/// The section.
pub(crate) fn render(ctx: &mut Ctx, c: &ModelChange) -> String {
    let mut s = facts(&change_facts(c));
    s.push_str("<h3>The earlier verdict</h3>\n");
    s.push_str(&earlier_verdict(c));
    s.push_str("<h3>Where the residual sits, before and after</h3>\n");
    if c.signature_before.is_empty() && c.signature_after.is_empty() {
        s.push_str(&unavailable("no residual signature was computed"));
    } else {
        s.push_str(&signatures(ctx, c));
    }
    s.push_str("<h3>Error per shot, before and after</h3>\n");
    if c.shots.is_empty() {
        s.push_str(&unavailable("no shot was fitted by both models"));
        return s;
    }
    s.push_str(&shot_errors(ctx, c));
    s
}

/// The models, the effects added and removed, and the total error before and after.
fn change_facts(c: &ModelChange) -> Vec<(String, String)> {
    let mut rows = vec![
        ("Earlier model".to_string(), esc(&c.model_before)),
        ("Current model".to_string(), esc(&c.model_after)),
    ];
    let list = |v: &[String]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter()
                .map(|e| format!("<code>{}</code>", esc(e)))
                .collect::<Vec<_>>()
                .join(", ")
        }
    };
    rows.push(("Effects added".into(), list(&c.effects_added)));
    if !c.effects_removed.is_empty() {
        rows.push(("Effects removed".into(), list(&c.effects_removed)));
    }
    rows.push((
        "Position RMS".into(),
        format!(
            "<b>{} µm</b> → <b>{} µm</b> ({} %)",
            um(c.total_rms_before_m),
            um(c.total_rms_after_m),
            change_pct(c.total_rms_before_m, c.total_rms_after_m)
        ),
    ));
    rows.push((
        "Reduced χ²".into(),
        format!("{} → {}", num(c.reduced_chi2_before, 3), num(c.reduced_chi2_after, 3)),
    ));
    rows
}

/// The verdict the earlier model was given, when it was kept.
fn earlier_verdict(c: &ModelChange) -> String {
    match &c.verdict_before {
        Some(v) => {
            format!(
                "<div class=\"verdict v-{}\"><p class=\"kind\">{}</p><p class=\"text\">{}</p></div>\n",
                kind_class(v.kind),
                v.kind.label(),
                crate::fmt::esc_code(&v.text)
            )
        }
        None => unavailable("the earlier model's diagnosis was not kept in this output folder"),
    }
}

/// The signatures before and after: the figure and its table.
fn signatures(ctx: &mut Ctx, c: &ModelChange) -> String {
    let (n, id) = ctx.next_figure();
    let chart = signature_chart(id, c);
    let mut s = ctx.figure(
        n,
        &[chart],
        "The part of the RMS position residual above the tracking noise, per phase and component, with the \
         earlier model (grey) and the current one (blue). An effect that was missing shows as a bar that \
         shrinks.",
    );
    let keys = signature_keys(c);
    let cell = |rows: &[SignatureRow], k: (Phase, bool), f: fn(&SignatureRow) -> String| {
        rows.iter().find(|r| key(r) == k).map_or("—".into(), f)
    };
    let trows: Vec<Vec<String>> = keys
        .iter()
        .map(|&k| {
            vec![
                component_phase(k.1, k.0),
                cell(&c.signature_before, k, |r| um(r.rms_m)),
                cell(&c.signature_before, k, |r| um(r.systematic_m)),
                cell(&c.signature_before, k, |r| fixed(100.0 * r.chi2_share, 1)),
                cell(&c.signature_after, k, |r| um(r.rms_m)),
                cell(&c.signature_after, k, |r| um(r.systematic_m)),
                cell(&c.signature_after, k, |r| fixed(100.0 * r.chi2_share, 1)),
            ]
        })
        .collect();
    s.push_str(&table(
        &[
            tc("Component, phase"),
            nc("RMS before (µm)"),
            nc("systematic"),
            nc("χ² share (%)"),
            nc("RMS after (µm)"),
            nc("systematic"),
            nc("χ² share (%)"),
        ],
        &trows,
    ));
    s
}

/// The error of every shot before and after: the figure and its table.
fn shot_errors(ctx: &mut Ctx, c: &ModelChange) -> String {
    let mut rows: Vec<BarRow> = c
        .shots
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
            (format!("before: {}", c.model_before), "#9a9a9a"),
            (format!("after: {}", c.model_after), "#0072B2"),
        ],
        "RMS position residual (µm)",
    );
    chart.title = "Fit error per shot, before and after".into();
    let mut s = ctx.figure(
        n,
        &[chart],
        "RMS position residual per shot with the earlier model (grey) and the current one (blue), shots sorted \
         by their error before. Each bar links to the shot's plots.",
    );
    let mut trows: Vec<Vec<String>> = c
        .shots
        .iter()
        .map(|b| {
            vec![
                ctx.clip_link(&b.clip),
                ctx.surface_cell(&b.surface),
                um(b.rms_before_m),
                um(b.rms_after_m),
                change_pct(b.rms_before_m, b.rms_after_m),
            ]
        })
        .collect();
    trows.push(vec![
        "\u{0}All shots".into(),
        String::new(),
        um(c.total_rms_before_m),
        um(c.total_rms_after_m),
        change_pct(c.total_rms_before_m, c.total_rms_after_m),
    ]);
    s.push_str("<details><summary>Per-shot values</summary>\n");
    s.push_str(&table(
        &[
            tc("Clip"),
            tc("Surface"),
            nc("RMS before (µm)"),
            nc("RMS after (µm)"),
            nc("Change (%)"),
        ],
        &trows,
    ));
    s.push_str("</details>\n");
    s
}
