//! The candidate effects: which parameters of each library effect a search frees, where they start, and
//! the model files (specs) with a candidate added.

use crate::{DiagnoseError, FittedValue};
use bouncelab_model::{
    EffectInfo, EffectKind, EffectSetting, ModelSpec, ParamSetting, ParamSpec, builtin, builtin_effects,
};
use serde::{Deserialize, Serialize};

/// How a candidate effect is added for the search: which of its parameters are free and where they start.
///
/// The start must differ from the neutral value (at the neutral value some effects have a zero Jacobian
/// column, e.g. Hunt–Crossley's exponent when λ = 0) and be of the right order of magnitude for a tennis
/// ball on a court surface; parameters not listed keep the effect's default and stay fixed (drag's air
/// density).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateSetup {
    /// The effect's name in the library.
    pub effect: String,
    /// Free parameters with their starting values, in the parameter's unit; the first is the one whose
    /// distance from its neutral value says whether the effect is there.
    pub free: Vec<(String, f64)>,
}

/// Starting values of the library's effects: (effect, [(parameter, start)]); the first parameter is the
/// effect's switch. Orders of magnitude below the renderer's preset magnitudes (`EFFECT_MAGNITUDES`).
const STARTS: &[(&str, &[(&str, f64)])] = &[
    ("hertz", &[("k_h", 5.0e4)]),
    // n is held at 1, the exponent of the paper's linear spring: Hunt and Crossley's damping λ·δⁿ·δ̇ takes
    // the elastic law's exponent. Freed, n is not determined by a session's few impact speeds once b is
    // free (b's loss is speed-independent, λ·δⁿ's grows with δ_max): λ and n slide along a valley
    // (n ≈ 2, λ 300× the truth on the rendered sessions) and the damping comes out 47 % off at 2 mm.
    ("hunt_crossley", &[("lambda", 500.0)]),
    ("restitution_damping", &[("b_r", 2.0)]),
    ("plastic_dent", &[("phi", 0.05)]),
    ("rolling_resistance", &[("c_rr", 0.005)]),
    ("inertia_factor", &[("dc", -0.05)]),
    ("drag", &[("cd", 0.3)]),
    ("camera_roll", &[("roll_deg", 0.5)]),
    // k_t ≈ 3e5 N/m: a stiff patch, near the rigid contact but with a Jacobian that is not zero.
    ("tangential_spring", &[("compliance", 3e-6)]),
];

impl CandidateSetup {
    /// The setup the search uses for the library effect `effect`: the table above, or for an effect
    /// added to the library since, its first parameter freed at 5 % of the way from its neutral value to
    /// the end of its physical range (to 1 when the range is unbounded).
    pub fn default_for(effect: &str) -> Result<CandidateSetup, DiagnoseError> {
        let info = library_effect(effect)?;
        if let Some((_, free)) = STARTS.iter().find(|(n, _)| *n == effect) {
            return Ok(CandidateSetup {
                effect: effect.to_string(),
                free: free.iter().map(|(p, v)| (p.to_string(), *v)).collect(),
            });
        }
        let p = info.params.first().ok_or_else(|| DiagnoseError::BadValue {
            effect: effect.to_string(),
            param: "-".into(),
            value: f64::NAN,
            reason: "the effect has no parameter to fit".into(),
        })?;
        let start = if p.max.is_finite() && p.max > p.neutral {
            p.neutral + 0.05 * (p.max - p.neutral)
        } else if p.min.is_finite() && p.min < p.neutral {
            p.neutral - 0.05 * (p.neutral - p.min)
        } else {
            p.neutral + 1.0
        };
        Ok(CandidateSetup {
            effect: effect.to_string(),
            free: vec![(p.name.to_string(), start)],
        })
    }

    /// The switch parameter (the first free one).
    pub fn primary(&self) -> Option<&str> {
        self.free.first().map(|(p, _)| p.as_str())
    }

    /// The switch parameter's neutral value (the effect does nothing there); 0 for an effect or parameter
    /// the library does not know.
    pub(crate) fn neutral(&self) -> f64 {
        library_effect(&self.effect)
            .ok()
            .and_then(|i| i.params.iter().find(|p| Some(p.name) == self.primary()))
            .map_or(0.0, |p| p.neutral)
    }
}

/// The library effect `name`, or an error listing the library.
pub(crate) fn library_effect(name: &str) -> Result<&'static EffectInfo, DiagnoseError> {
    builtin(name).ok_or_else(|| DiagnoseError::UnknownEffect {
        effect: name.to_string(),
        known: builtin_effects().iter().map(|e| e.name).collect::<Vec<_>>().join(", "),
    })
}

/// The library effects a search tries on `spec`: not in the base model and not already in the model.
pub(crate) fn candidate_names(spec: &ModelSpec) -> Vec<&'static str> {
    builtin_effects()
        .iter()
        .filter(|e| !e.base && !spec.has_effect(e.name))
        .map(|e| e.name)
        .collect()
}

/// `spec` with the effect of `setup` appended: the listed parameters free at their starts, the others at
/// their defaults (neutral values when there is none), fixed.
///
/// A free parameter may cross its neutral value: where the physical range ends at the neutral value (a
/// stiffness, a damping ≥ 0) the search range is mirrored about it (`k_h ∈ (−∞, ∞)`, `φ ∈ [−0.95,
/// 0.95]`). A fit that wants the other side then finds it (and the candidate is refused as unphysical)
/// instead of pressing against the bound, where a projected Levenberg–Marquardt creeps for many iterations,
/// and the distance from neutral in standard errors is an honest test in both directions. Not where the
/// other side is no model ([`search_range`]).
pub(crate) fn with_candidate(spec: &ModelSpec, setup: &CandidateSetup) -> Result<ModelSpec, DiagnoseError> {
    let info = library_effect(&setup.effect)?;
    if info.base {
        return Err(DiagnoseError::BaseEffect {
            effect: setup.effect.clone(),
        });
    }
    if spec.has_effect(info.name) {
        return Err(DiagnoseError::AlreadyPresent {
            origin: spec.origin.clone(),
            effect: info.name.to_string(),
        });
    }
    for (p, v) in &setup.free {
        let Some(ps) = info.params.iter().find(|q| q.name == p) else {
            return Err(DiagnoseError::BadValue {
                effect: info.name.into(),
                param: p.clone(),
                value: *v,
                reason: format!(
                    "no such parameter (its parameters: {})",
                    info.params.iter().map(|q| q.name).collect::<Vec<_>>().join(", ")
                ),
            });
        };
        if !(v.is_finite() && *v >= ps.min && *v <= ps.max) {
            return Err(DiagnoseError::BadValue {
                effect: info.name.into(),
                param: p.clone(),
                value: *v,
                reason: format!("a start must be inside the physical range [{}, {}]", ps.min, ps.max),
            });
        }
    }
    let params = info
        .params
        .iter()
        .map(|ps| {
            let free = setup.free.iter().find(|(p, _)| p == ps.name);
            let (min, max) = match free {
                Some(_) => search_range(info.name, ps),
                None => (ps.min, ps.max),
            };
            let setting = ParamSetting {
                value: free.map(|(_, v)| *v).or(ps.default).unwrap_or(ps.neutral),
                free: free.is_some(),
                min,
                max,
            };
            (ps.name.to_string(), Some(setting))
        })
        .collect();
    let mut out = spec.clone();
    out.effects.push(EffectSetting {
        name: info.name.to_string(),
        kind: EffectKind::Builtin(info),
        params,
    });
    Ok(out)
}

/// Parameters whose other side of the neutral value is no model at all rather than the opposite effect: a
/// negative tangential compliance is a patch that pushes the contact point along its slip (the simulated
/// ball leaves at 3.5 m/s where the rigid contact gives 0.4 m/s), so the response jumps at the neutral
/// value and a fit there is meaningless. Their search range is their physical range.
const NOT_MIRRORED: &[(&str, &str)] = &[("tangential_spring", "compliance")];

/// The range a search gives a free parameter of `effect`: its physical range, mirrored about the neutral
/// value where it ends there (except for [`NOT_MIRRORED`]).
pub(crate) fn search_range(effect: &str, p: &ParamSpec) -> (f64, f64) {
    let (mut lo, mut hi) = (p.min, p.max);
    if NOT_MIRRORED.contains(&(effect, p.name)) {
        return (lo, hi);
    }
    if lo == p.neutral && hi > p.neutral {
        lo = p.neutral - (hi - p.neutral);
    } else if hi == p.neutral && lo < p.neutral {
        hi = p.neutral + (p.neutral - lo);
    }
    (lo, hi)
}

/// Sets fitted values (by the fit's parameter names, `damping.b` or `clay:spring.k`) into `spec` as new
/// starting values, clamped into each parameter's bounds.
pub(crate) fn set_values(spec: &mut ModelSpec, values: &[FittedValue]) {
    for fv in values {
        let (surface, effect, param, v) = (&fv.surface, &fv.effect, &fv.param, fv.value);
        let target: Option<&mut ParamSetting> = match surface {
            Some(sf) => spec.surfaces.iter_mut().find(|(s, _)| s == sf).and_then(|(_, vals)| {
                vals.iter_mut()
                    .find(|(r, _)| &r.effect == effect && &r.param == param)
                    .map(|(_, s)| s)
            }),
            None => spec
                .effects
                .iter_mut()
                .find(|e| &e.name == effect)
                .and_then(|e| e.params.iter_mut().find(|(p, _)| p == param))
                .and_then(|(_, s)| s.as_mut()),
        };
        if let Some(s) = target
            && v.is_finite()
        {
            s.value = v.clamp(s.min, s.max);
        }
    }
}
