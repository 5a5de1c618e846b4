//! Judging a diagnosis of a rendered session against the scenario's truth: the hidden values, a fitted
//! magnitude against them, the roll the lines measured, and every search's candidates printed. Shared by
//! the acceptance tests (`crates/analyze/tests/acceptance.rs`) and the verdict sweep
//! (`examples/verdict_sweep.rs`).

use bouncelab_analyze::Analysis;
use bouncelab_diagnose::{Diagnosis, FittedValue};
use bouncelab_render::Scenario;

/// The hidden value of `effect`'s parameter `param` in the scenario's model (its `[extra_effects]` table).
pub fn scenario_truth(scenario: &Scenario, effect: &str, param: &str) -> f64 {
    let spec = scenario
        .model_spec(&[effect.to_string()])
        .expect("the scenario's model");
    spec.settings(None)
        .expect("the scenario's model has values")
        .iter()
        .find(|(r, _)| r.effect == effect && r.param == param)
        .map(|(_, s)| s.value)
        .unwrap_or(f64::NAN)
}

/// An effect's magnitude as fitted, against the scenario's truth.
pub struct Magnitude {
    pub label: String,
    pub value: f64,
    pub truth: f64,
    pub interval: Option<[f64; 2]>,
}

impl Magnitude {
    /// Relative error, (fitted − truth) / truth.
    pub fn error(&self) -> f64 {
        (self.value - self.truth) / self.truth
    }

    /// Whether the 95 % interval covers the truth: `yes`, `no` or `no interval`.
    pub fn covers_text(&self) -> &'static str {
        match self.interval {
            Some([lo, hi]) if lo <= self.truth && self.truth <= hi => "yes",
            Some(_) => "no",
            None => "no interval",
        }
    }
}

/// `effect`'s magnitude in `fitted` (a search's fit), `None` when the fit has no such parameter: its first
/// parameter, except for Hunt–Crossley, whose magnitude is the damping force per unit speed λ·δⁿ at
/// δ = 2 mm (so a search that frees n is judged by the force, not by a λ that trades with n along a valley).
pub fn magnitude(scenario: &Scenario, effect: &str, fitted: &[FittedValue]) -> Option<Magnitude> {
    let find = |param: &str| fitted.iter().find(|p| p.effect == effect && p.param == param);
    let info = bouncelab_model::builtin(effect)?;
    let param = info.params[0].name;
    let p = find(param)?;
    let truth = scenario_truth(scenario, effect, param);
    if effect != "hunt_crossley" {
        return Some(Magnitude {
            label: format!("{effect}.{param}"),
            value: p.value,
            truth,
            interval: p.interval,
        });
    }
    // n is held at its default (the linear spring's exponent) unless the search freed it; held, λ's
    // interval gives the force's.
    let n_free = find("n");
    let n_fit = n_free
        .map(|p| p.value)
        .unwrap_or_else(|| info.params[1].default.expect("n has a default"));
    let n_true = scenario_truth(scenario, effect, "n");
    let force = |lambda: f64, n: f64| lambda * 0.002f64.powf(n);
    Some(Magnitude {
        label: "hunt_crossley λ·δⁿ at δ = 2 mm (N·s/m)".into(),
        value: force(p.value, n_fit),
        truth: force(truth, n_true),
        interval: if n_free.is_none() {
            p.interval.map(|[lo, hi]| [force(lo, n_fit), force(hi, n_fit)])
        } else {
            None
        },
    })
}

/// The fit in which `effect` was last refitted: the deepest search that named it (a later search refits
/// the earlier effect together with its own), else the first search's candidate for it.
pub fn fit_of<'a>(d: &'a Diagnosis, effect: &str) -> Option<&'a [FittedValue]> {
    let mut searches = vec![d];
    while let Some(next) = searches.last().and_then(|s| s.then.as_deref()) {
        searches.push(next);
    }
    let named = searches.iter().rev().find_map(|s| {
        let c = s.candidate(s.verdict.effect.as_deref()?)?;
        let fit = &c.evidence.as_ref()?.fit;
        fit.parameters
            .iter()
            .any(|p| p.effect == effect)
            .then_some(fit.parameters.as_slice())
    });
    named.or_else(|| {
        d.candidate(effect)
            .and_then(|c| c.evidence.as_ref())
            .map(|e| e.fit.parameters.as_slice())
    })
}

/// The camera roll the shots' surface lines measured, degrees (the renderer's truth is
/// `surface_tilt_deg = −roll` for down-slope +x), with its error (the larger of the stated errors' and the
/// scatter's) and the number of shots whose line gave a tilt; `None` when no line did.
pub fn measured_roll(a: &Analysis) -> Option<(f64, f64, usize)> {
    let tilts: Vec<(f64, f64)> = a
        .shots
        .iter()
        .filter_map(|s| s.estimate.surface_tilt_deg.map(|m| (m.value, m.se)))
        .collect();
    if tilts.is_empty() {
        return None;
    }
    let n = tilts.len() as f64;
    let mean = tilts.iter().map(|t| t.0).sum::<f64>() / n;
    let stated = (tilts.iter().map(|t| t.1 * t.1).sum::<f64>()).sqrt() / n;
    let scatter = if tilts.len() > 1 {
        (tilts.iter().map(|t| (t.0 - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt() / n.sqrt()
    } else {
        0.0
    };
    Some((-mean, stated.max(scatter), tilts.len()))
}

/// Prints every search's candidates (this one's, then the search that went on from it): the evidence a
/// failure is read from.
pub fn print_candidates(d: &Diagnosis) {
    let mut level = Some(d);
    let mut depth = 0;
    while let Some(d) = level {
        eprintln!(
            "  search {}: {} (current model {:?}; systematic {:.1} µm, floor {:.1} µm, noise {:.1} µm, {:.1} s)",
            depth + 1,
            d.verdict.kind.name(),
            d.baseline.fit.effects,
            d.baseline.systematic_m * 1e6,
            d.floor.floor_m * 1e6,
            d.noise.noise_m * 1e6,
            d.seconds
        );
        for ph in d.signature.phases.iter().take(3) {
            eprintln!(
                "    residual: {} {}: systematic {:.1} µm, {:.0} % of χ²",
                ph.component.name(),
                ph.phase.words(),
                ph.systematic_m * 1e6,
                ph.chi2_share * 100.0
            );
        }
        for c in &d.candidates {
            match &c.evidence {
                Some(e) => eprintln!(
                    "    {}. {} = {:.4e} ({:.1} s): held-out {:.1} → {:.1} µm, {:.0} % removed, ΔBIC {:.0}, explains {} (part {}); {}",
                    c.rank,
                    c.effect,
                    e.param_value,
                    c.seconds,
                    c.heldout_error_before * 1e6,
                    e.heldout_error_after * 1e6,
                    e.explained_fraction * 100.0,
                    e.delta_bic,
                    c.explains,
                    c.partly_explains,
                    c.reasons.join("; ")
                ),
                None => eprintln!(
                    "    {}. {} ({:.1} s): {}",
                    c.rank,
                    c.effect,
                    c.seconds,
                    c.reasons.join("; ")
                ),
            }
        }
        level = d.then.as_deref();
        depth += 1;
    }
}
