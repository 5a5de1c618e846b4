//! The parameter vector: which parameters of a `ModelSpec` are free, their names, bounds and scales, and
//! how a vector of values is set into the per-surface models.

use crate::FitError;
use bouncelab_model::{Model, ModelSpec, ParamRef, ParamSetting};
use serde::{Deserialize, Serialize};

/// One free parameter of the fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FreeParam {
    /// Its name in results: `damping.b` (global) or `clay:spring.k` (one surface's value).
    pub name: String,
    /// The effect's name in the model file.
    pub effect: String,
    /// The parameter's name.
    pub param: String,
    /// Position of the parameter in the effect's parameter list.
    pub index: usize,
    /// The surface this value belongs to, `None` for a global value (used by every surface that does not
    /// set its own).
    pub surface: Option<String>,
    /// Starting value (the model file's), in the parameter's unit.
    pub initial: f64,
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// Typical size, used to scale the parameter for the solver and its finite-difference steps:
    /// `|initial|`, or `max − min` when the initial value is 0 and both bounds are finite, else 1.
    pub scale: f64,
}

impl FreeParam {
    /// Whether `value` lies on a bound (an interval there means little).
    pub fn at_bound(&self, value: f64) -> bool {
        value <= self.min || value >= self.max
    }
}

/// A per-surface model and which entries of the parameter vector go into it.
#[derive(Debug, Clone)]
pub(crate) struct SurfaceModel {
    pub name: String,
    pub base: Model,
    /// (position in the parameter vector, effect name, index in the effect).
    pub assign: Vec<(usize, String, usize)>,
}

impl SurfaceModel {
    pub fn model(&self, theta: &[f64]) -> Result<Model, FitError> {
        let mut m = self.base.clone();
        for (j, effect, index) in &self.assign {
            m.set_param(effect, *index, theta[*j])?;
        }
        Ok(m)
    }
}

fn scale_of(s: &ParamSetting) -> f64 {
    if s.value != 0.0 {
        s.value.abs()
    } else if s.min.is_finite() && s.max.is_finite() && s.max > s.min {
        s.max - s.min
    } else {
        1.0
    }
}

fn free_param(r: &ParamRef, index: usize, surface: Option<&str>, s: &ParamSetting) -> FreeParam {
    FreeParam {
        name: match surface {
            Some(sf) => format!("{sf}:{r}"),
            None => r.to_string(),
        },
        effect: r.effect.clone(),
        param: r.param.clone(),
        index,
        surface: surface.map(str::to_string),
        initial: s.value,
        min: s.min,
        max: s.max,
        scale: scale_of(s),
    }
}

/// Builds the free parameters and the per-surface models for the given shot surfaces (deduplicated, in
/// the model file's surface order, then order of first appearance).
pub(crate) fn build(spec: &ModelSpec, used: &[String]) -> Result<(Vec<FreeParam>, Vec<SurfaceModel>), FitError> {
    // Surfaces in a stable order: the model file's, then any others (a spec without surfaces).
    let mut surfaces: Vec<String> = spec
        .surface_names()
        .into_iter()
        .filter(|s| used.iter().any(|u| u == s))
        .map(str::to_string)
        .collect();
    for u in used {
        if !surfaces.contains(u) {
            surfaces.push(u.clone());
        }
    }
    let overrides = |surface: &str, r: &ParamRef| -> Option<ParamSetting> {
        spec.surfaces
            .iter()
            .find(|(s, _)| s == surface)
            .and_then(|(_, v)| v.iter().find(|(q, _)| q == r).map(|(_, s)| *s))
    };
    let mut models = Vec::new();
    for s in &surfaces {
        models.push(SurfaceModel {
            name: s.clone(),
            base: spec.build(Some(s))?,
            assign: Vec::new(),
        });
    }
    let mut params = Vec::new();
    for e in &spec.effects {
        for (index, (pname, base)) in e.params.iter().enumerate() {
            let r = ParamRef {
                effect: e.name.clone(),
                param: pname.clone(),
            };
            // One unknown per surface that sets this parameter itself.
            let mut global_users = Vec::new();
            for (k, s) in surfaces.iter().enumerate() {
                match overrides(s, &r) {
                    Some(set) => {
                        if set.free {
                            models[k].assign.push((params.len(), e.name.clone(), index));
                            params.push(free_param(&r, index, Some(s), &set));
                        }
                    }
                    None => global_users.push(k),
                }
            }
            // One global unknown shared by the surfaces that do not.
            if let Some(set) = base
                && set.free
                && !global_users.is_empty()
            {
                for k in global_users {
                    models[k].assign.push((params.len(), e.name.clone(), index));
                }
                params.push(free_param(&r, index, None, set));
            }
        }
    }
    Ok((params, models))
}
