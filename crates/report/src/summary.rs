//! The summary: the verdict in a few words, the model and its fit, what the statistics say about the
//! surfaces, and every measured quantity per surface (mean ± SD, n).

use std::fmt::Write;

use crate::data::{Report, ShotMeasurement, VerdictKind};
use crate::fmt::{esc, num, p_value};
use crate::html::{Ctx, facts, nc, table_with_class, tc};

/// One quantity of the per-surface and per-shot tables: heading (HTML), unit, factor from SI to the unit,
/// significant digits without an error, the value.
pub(crate) struct Quantity {
    pub name: &'static str,
    pub unit: &'static str,
    pub scale: f64,
    pub sig: usize,
    pub get: fn(&ShotMeasurement) -> Option<f64>,
}

/// Every quantity a shot has, measured first, then the model's prediction for it.
pub(crate) const QUANTITIES: &[Quantity] = &[
    Quantity {
        name: "Impact speed |v<sub>in</sub>|",
        unit: "m/s",
        scale: 1.0,
        sig: 4,
        get: |m| Some(m.impact_speed().value),
    },
    Quantity {
        name: "Impact angle from the normal",
        unit: "°",
        scale: 1.0,
        sig: 3,
        get: |m| Some(m.impact_angle().value),
    },
    Quantity {
        name: "Normal speed |v<sub>n,in</sub>|",
        unit: "m/s",
        scale: 1.0,
        sig: 4,
        get: |m| Some(m.v_in_m_s[1].value.abs()),
    },
    Quantity {
        name: "COR e",
        unit: "",
        scale: 1.0,
        sig: 4,
        get: |m| Some(m.cor.value),
    },
    Quantity {
        name: "μ<sub>eff</sub>",
        unit: "",
        scale: 1.0,
        sig: 3,
        get: |m| Some(m.mu_eff.value),
    },
    Quantity {
        name: "Contact time",
        unit: "ms",
        scale: 1e3,
        sig: 4,
        get: |m| Some(m.contact_time_s.value),
    },
    Quantity {
        name: "δ<sub>max</sub>",
        unit: "mm",
        scale: 1e3,
        sig: 3,
        get: |m| Some(m.delta_max_m.value),
    },
    Quantity {
        name: "Spin in ω<sub>in</sub>",
        unit: "rad/s",
        scale: 1.0,
        sig: 3,
        get: |m| m.spin_in_rad_s.map(|s| s.value),
    },
    Quantity {
        name: "Spin out ω<sub>out</sub>",
        unit: "rad/s",
        scale: 1.0,
        sig: 3,
        get: |m| m.spin_out_rad_s.map(|s| s.value),
    },
    Quantity {
        name: "Peak deceleration, track",
        unit: "m/s²",
        scale: 1.0,
        sig: 4,
        get: |m| m.peak_deceleration_track_m_s2.map(|s| s.value),
    },
    Quantity {
        name: "Peak contact force, track",
        unit: "N",
        scale: 1.0,
        sig: 4,
        get: |m| m.peak_force_track_n.map(|s| s.value),
    },
    Quantity {
        name: "COR, model",
        unit: "",
        scale: 1.0,
        sig: 4,
        get: |m| m.model.map(|p| p.cor),
    },
    Quantity {
        name: "Contact time, model",
        unit: "ms",
        scale: 1e3,
        sig: 4,
        get: |m| m.model.map(|p| p.contact_time_s),
    },
    Quantity {
        name: "δ<sub>max</sub>, model",
        unit: "mm",
        scale: 1e3,
        sig: 3,
        get: |m| m.model.map(|p| p.delta_max_m),
    },
    Quantity {
        name: "Peak contact force, model",
        unit: "N",
        scale: 1.0,
        sig: 4,
        get: |m| m.model.map(|p| p.peak_force_n),
    },
    Quantity {
        name: "Peak deceleration, model",
        unit: "m/s²",
        scale: 1.0,
        sig: 4,
        get: |m| m.model.map(|p| p.peak_deceleration_m_s2),
    },
];

/// Mean, sample SD and count of the finite values.
pub(crate) fn mean_sd(v: &[f64]) -> (f64, f64, usize) {
    let v: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    let n = v.len();
    if n == 0 {
        return (f64::NAN, f64::NAN, 0);
    }
    let mean = v.iter().sum::<f64>() / n as f64;
    let sd = if n > 1 {
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
    } else {
        f64::NAN
    };
    (mean, sd, n)
}

/// The per-surface table: one row per quantity that any shot has, one column per surface.
pub(crate) fn by_surface(ctx: &Ctx) -> String {
    let ms = &ctx.report.measurements;
    if ms.is_empty() {
        return crate::html::unavailable("no shot was measured");
    }
    let surfaces: Vec<&String> = ctx
        .surfaces
        .iter()
        .filter(|s| ms.iter().any(|m| &m.surface == *s))
        .collect();
    let mut rows = Vec::new();
    for q in QUANTITIES {
        if !ms.iter().any(|m| (q.get)(m).is_some_and(f64::is_finite)) {
            continue;
        }
        let unit = if q.unit.is_empty() {
            String::new()
        } else {
            format!(" ({})", q.unit)
        };
        let mut row = vec![format!("{}{unit}", q.name)];
        for s in &surfaces {
            let vals: Vec<f64> = ms
                .iter()
                .filter(|m| &m.surface == *s)
                .filter_map(|m| (q.get)(m))
                .map(|v| v * q.scale)
                .collect();
            let (mean, sd, n) = mean_sd(&vals);
            row.push(if n == 0 {
                "—".into()
            } else {
                let sd = sd.is_finite().then_some(sd);
                format!(
                    r#"{} <span class="se">(n = {n})</span>"#,
                    crate::html::pm_cell(mean, sd, q.sig)
                )
            });
        }
        rows.push(row);
    }
    let mut cols = vec![tc("Quantity (unit)")];
    let heads: Vec<String> = surfaces.iter().map(|s| ctx.surface_cell(s)).collect();
    cols.extend(heads.iter().map(|h| nc(h)));
    let mut out = String::from(
        "<h3>Every quantity per surface</h3>\n<p>Mean ± standard deviation over the surface's shots (n shots with \
         the quantity). Measured quantities come from the tracks; \"model\" rows are the fitted model hit at each \
         shot's measured incoming velocity. Per-shot values with their standard errors are in the \
         <a href=\"#shots\">shots section</a>.</p>\n",
    );
    out.push_str(&table_with_class("quantities", &cols, &rows));
    out
}

/// The summary section.
pub(crate) fn render(ctx: &mut Ctx) -> String {
    let r = ctx.report;
    let mut rows: Vec<(String, String)> = vec![verdict_row(r)];
    rows.extend(model_change_row(r));
    rows.extend(model_row(r));
    rows.extend(surface_effect_row(r));
    rows.extend(surface_pairs_row(r));
    rows.push((
        "Warnings".into(),
        if r.warnings.is_empty() {
            "none".into()
        } else {
            format!(r##"<a href="#warnings">{}</a>"##, r.warnings.len())
        },
    ));
    let mut s = facts(&rows);
    s.push_str(&by_surface(ctx));
    s
}

/// The verdict in a few words, linked to the diagnosis.
fn verdict_row(r: &Report) -> (String, String) {
    match r.diagnosis.get() {
        Some(d) => {
            let class = match d.verdict_kind {
                VerdictKind::NoMissingEffect => "good",
                _ => "bad",
            };
            let text = if d.headline.is_empty() {
                &d.verdict_text
            } else {
                &d.headline
            };
            (
                "Verdict".into(),
                format!(
                    r##"<a href="#diagnosis"><b class="{class}">{}</b></a>: {}"##,
                    d.verdict_kind.label(),
                    crate::fmt::esc_code(text)
                ),
            )
        }
        None => ("Verdict".into(), "no diagnosis in this report".into()),
    }
}

/// The effects added and the error before and after, when the model changed.
fn model_change_row(r: &Report) -> Option<(String, String)> {
    let c = r.model_change.get()?;
    let added = if c.effects_added.is_empty() {
        String::new()
    } else {
        let names: Vec<String> = c
            .effects_added
            .iter()
            .map(|e| format!("<code>{}</code>", esc(e)))
            .collect();
        format!("added {} to {}; ", names.join(", "), esc(&c.model_before))
    };
    Some((
        "Model change".into(),
        format!(
            r##"<a href="#model-change">{added}position RMS {} → {} µm</a>"##,
            crate::fmt::um(c.total_rms_before_m),
            crate::fmt::um(c.total_rms_after_m)
        ),
    ))
}

/// The fitted model and how well it fits.
fn model_row(r: &Report) -> Option<(String, String)> {
    let f = r.fit.get()?;
    let mut s = format!(r##"<a href="#fit">{}</a>"##, esc(&f.model_name));
    if let Some(e) = f.rms_m {
        let _ = write!(s, "; position RMS {} µm", crate::fmt::um(e));
    }
    if let Some(c) = f.reduced_chi2 {
        let _ = write!(s, "; reduced χ² {}", num(c, 3));
    }
    if let Some(e) = f.mean_abs_error_pct {
        let _ = write!(s, "; mean absolute COR error {} %", num(e, 3));
    }
    Some(("Model".into(), s))
}

/// The ANCOVA's test of the surface.
fn surface_effect_row(r: &Report) -> Option<(String, String)> {
    let row = r
        .ancova
        .get()
        .and_then(|a| a.type1.terms.iter().find(|t| t.source == "surface"))?;
    Some((
        "Surface effect on COR".into(),
        format!(
            r##"F = {}, p = {} (<a href="#ancova">ANCOVA, Type I, impact speed as covariate</a>)"##,
            crate::fmt::opt(row.f, 3),
            row.p.map_or("—".into(), p_value)
        ),
    ))
}

/// The pairs of surfaces whose adjusted means differ.
fn surface_pairs_row(r: &Report) -> Option<(String, String)> {
    let m = r.inference.get().and_then(|i| i.means_of("surface"))?;
    let differ: Vec<String> = m
        .pairs
        .iter()
        .filter(|p| p.reject_tukey)
        .map(|p| format!("{} − {}", esc(&p.level2), esc(&p.level1)))
        .collect();
    Some((
        "Surfaces at equal impact speed".into(),
        format!(
            r##"pairs that differ: {} of {} (Tukey–Kramer, α = {}){} (<a href="#comparisons">adjusted means</a>)"##,
            differ.len(),
            m.pairs.len(),
            crate::fmt::short(m.alpha, 3),
            if differ.is_empty() {
                String::new()
            } else {
                format!(": {}", differ.join(", "))
            }
        ),
    ))
}
