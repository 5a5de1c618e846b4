//! A formula term proposed for a residual that no library effect explains: forward selection over a small
//! library of force terms in δ, δ̇, the slip and the contact's history (u_t, ∫δ dt), each acting in one contact phase with one free coefficient.
//!
//! This is the sparse regression of SINDy done on trajectories: SINDy regresses a derivative on a library
//! of terms, but the second derivative of a tracked position at 10 kHz is all noise (0.02 px of jitter is
//! 80 m/s² after two differences), so each term is instead added to the model as a custom effect and fitted
//! through the simulator, like the library's candidates, and judged by what it predicts of held-out shots.
//! Sparsity comes from the selection: one term at a time, the best by held-out error, kept only if it
//! removes a material part of the systematic error with a coefficient clearly away from zero; at most
//! [`MAX_TERMS`].

use serde::{Deserialize, Serialize};

/// One term of the library: where it acts, which force it adds (`normal` or `tangential`, the model file's
/// key), the force in the coefficient `c` (N), and a start for `c` giving ≈ 0.1 N at δ = 2 mm,
/// δ̇ = 1 m/s, a slip of 1 m/s (the fit moves it either way).
struct TermShape {
    phase: &'static str,
    target: &'static str,
    formula: &'static str,
    start: f64,
}

/// The term library: normal forces constant, elastic (δ, δ²), viscous (δ̇) and mixed (δ·δ̇), in the whole
/// contact or in one of its phases; tangential forces viscous in the slip of the contact point or in the
/// centre's tangential speed.
const TERMS: &[TermShape] = &[
    TermShape {
        target: "normal",
        phase: "contact",
        formula: "c",
        start: 0.1,
    },
    TermShape {
        target: "normal",
        phase: "contact",
        formula: "c * delta",
        start: 50.0,
    },
    TermShape {
        target: "normal",
        phase: "contact",
        formula: "c * delta * delta",
        start: 2.5e4,
    },
    TermShape {
        target: "normal",
        phase: "contact",
        formula: "c * delta_dot",
        start: 0.1,
    },
    TermShape {
        target: "normal",
        phase: "contact",
        formula: "c * delta * delta_dot",
        start: 50.0,
    },
    TermShape {
        target: "normal",
        phase: "compression",
        formula: "c",
        start: 0.1,
    },
    TermShape {
        target: "normal",
        phase: "compression",
        formula: "c * delta",
        start: 50.0,
    },
    TermShape {
        target: "normal",
        phase: "restitution",
        formula: "c",
        start: 0.1,
    },
    TermShape {
        target: "normal",
        phase: "restitution",
        formula: "c * delta",
        start: 50.0,
    },
    TermShape {
        target: "normal",
        phase: "restitution",
        formula: "c * delta_dot",
        start: 0.1,
    },
    TermShape {
        target: "tangential",
        phase: "contact",
        formula: "c * slip",
        start: -0.1,
    },
    TermShape {
        target: "tangential",
        phase: "contact",
        formula: "c * v_t",
        start: -0.1,
    },
    // State-carrying terms: the contact patch's tangential displacement u_t = ∫ slip dt since touch (a
    // tangential spring −u_t/λ; with `c * slip` chosen beside it, a damped one), and the normal history
    // ∫ δ dt (a force that remembers how long and how deep the ball pressed).
    TermShape {
        target: "tangential",
        phase: "contact",
        formula: "c * u_t",
        start: -1e3,
    },
    TermShape {
        target: "normal",
        phase: "restitution",
        formula: "c * delta_int",
        start: -1e4,
    },
];

/// Most terms a proposal holds.
pub(crate) const MAX_TERMS: usize = 2;

/// Least fraction of the remaining systematic held-out error (above the noise, in mean square) a term must
/// remove to be kept.
pub(crate) const MIN_TERM_FRACTION: f64 = 0.25;

/// One proposed term, as it would go into `model.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProposedTerm {
    /// The custom effect's name (`term_1`, `term_2`).
    pub name: String,
    /// The contact phase it acts in (`contact`, `compression` or `restitution`).
    pub phase: String,
    /// The force it adds: `normal` or `tangential`.
    pub target: String,
    /// The force, N, in the coefficient `c`.
    pub formula: String,
    /// The fitted coefficient, in the unit that makes the formula newtons.
    pub c: f64,
    /// Its standard error; `None` when the shots do not determine it.
    pub c_std_error: Option<f64>,
    /// Held-out error of the model with the terms so far, m.
    pub heldout_error_m: f64,
}

/// The proposal: the terms chosen, what they do to the held-out error, and the `model.toml` text to try.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TermProposal {
    /// The terms kept, in the order chosen.
    pub terms: Vec<ProposedTerm>,
    /// Terms of the library tried.
    pub library_size: usize,
    /// Held-out error of the current model, m.
    pub heldout_before_m: f64,
    /// Held-out error with the proposed terms, m.
    pub heldout_after_m: f64,
    /// Systematic part of the held-out error before and after (above the noise), m.
    pub systematic_before_m: f64,
    /// See `systematic_before_m`.
    pub systematic_after_m: f64,
    /// The terms as `model.toml` sections, coefficients free, to add and fit with `analyze`.
    pub model_toml: String,
    /// Terms whose fit failed, each with why (such a term is not a candidate).
    #[serde(default)]
    pub failed: Vec<String>,
}

/// The library term `i` as the custom effect `name` of a model file, its coefficient free from `c`.
pub(crate) fn term_toml(name: &str, i: usize, c: f64) -> String {
    let t = &TERMS[i];
    format!(
        "[effects.{name}]\nkind = \"custom\"\ndoc = \"proposed by the missing-effect search's term library\"\nphase = \"{}\"\n{} = \"{}\"\nc = {{ value = {c:e}, free = true }}\n",
        t.phase, t.target, t.formula
    )
}

/// Terms in the library.
pub(crate) fn library_size() -> usize {
    TERMS.len()
}

/// The library term `i`: its phase, target (`normal` or `tangential`), formula and start.
pub(crate) fn term(i: usize) -> (&'static str, &'static str, &'static str, f64) {
    let t = &TERMS[i];
    (t.phase, t.target, t.formula, t.start)
}

/// A sentence on a proposal, for the verdict.
pub(crate) fn sentence(p: &TermProposal) -> String {
    let terms: Vec<String> = p
        .terms
        .iter()
        .map(|t| {
            let se = t.c_std_error.map(|s| format!(" ± {s:.3e}")).unwrap_or_default();
            format!("{} `{}` in {} (c = {:.4e}{se})", t.target, t.formula, t.phase, t.c)
        })
        .collect();
    format!(
        "Of {} formula terms in δ, δ̇, the slip and the contact's history tried as an extra force, {} lower{} the held-out error from {:.1} µm to {:.1} µm (systematic part {:.1} → {:.1} µm); to try {}, add the `custom` section{} of `diagnosis.json`'s `proposal.model_toml` to model.toml and analyse again.",
        p.library_size,
        terms.join(" and "),
        if p.terms.len() == 1 { "s" } else { "" },
        p.heldout_before_m * 1e6,
        p.heldout_after_m * 1e6,
        p.systematic_before_m * 1e6,
        p.systematic_after_m * 1e6,
        if p.terms.len() == 1 { "it" } else { "them" },
        if p.terms.len() == 1 { "" } else { "s" },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_model::ModelSpec;

    /// Every library term makes a model file the model crate reads.
    #[test]
    fn every_term_is_a_valid_custom_effect() {
        for i in 0..library_size() {
            let text = format!(
                "[effects.spring]\nk = 25650\n[effects.damping]\nb = 14\n[effects.coulomb]\nmu = 0.5\n{}",
                term_toml("term_1", i, term(i).3)
            );
            let spec = ModelSpec::parse(&text, "term").unwrap_or_else(|e| panic!("{}: {e}", term(i).2));
            spec.build(None).unwrap_or_else(|e| panic!("{}: {e}", term(i).2));
        }
    }
}
