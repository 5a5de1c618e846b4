//! The surface level: where the plane the ball touches lies relative to the surface line found in the image,
//! fitted as a nuisance (the `surface_level` effect free per surface, and with surface offsets one
//! deviation per shot within its line's σ).

use crate::{FitResult, ShotFit};
use bouncelab_model::{EffectKind, EffectSetting, ModelSpec, ParamRef, ParamSetting};

/// Fit range of the surface level, m (±5 px at the paper's 0.4 mm/px).
pub const SURFACE_LEVEL_RANGE_M: f64 = 2e-3;

/// Adds the `surface_level` nuisance, free per surface within ±[`SURFACE_LEVEL_RANGE_M`], unless the model
/// file sets it itself: the surface line a tracker finds is the band's visible edge, a fraction of a pixel
/// (more with the camera above the surface) off the plane the ball touches, and the contact's timing in
/// every shot depends on it.
pub fn add_surface_level(spec: &mut ModelSpec) {
    let name = "surface_level";
    if spec.has_effect(name) {
        return;
    }
    let Some(info) = bouncelab_model::builtin(name) else {
        return;
    };
    let free = ParamSetting {
        value: 0.0,
        free: true,
        min: -SURFACE_LEVEL_RANGE_M,
        max: SURFACE_LEVEL_RANGE_M,
    };
    spec.effects.push(EffectSetting {
        name: name.into(),
        kind: EffectKind::Builtin(info),
        params: vec![("level_m".into(), Some(free))],
    });
    let r = ParamRef {
        effect: name.into(),
        param: "level_m".into(),
    };
    for (_, values) in &mut spec.surfaces {
        values.push((r.clone(), free));
    }
}

impl FitResult {
    /// The surface level the fit found for `surface`, m (the `surface_level` nuisance: the surface's own
    /// value, else the global one), if it was fitted.
    pub fn surface_level_m(&self, surface: &str) -> Option<f64> {
        let own = format!("{surface}:surface_level.level_m");
        self.param(&own)
            .or_else(|| self.param("surface_level.level_m"))
            .map(|p| p.value)
    }

    /// The fitted level of `shot`'s surface, m: its surface's level plus the shot's own offset, either
    /// counting as 0 when the other was fitted; `None` when neither was.
    pub fn shot_level_m(&self, shot: &ShotFit) -> Option<f64> {
        match (self.surface_level_m(&shot.surface), shot.surface_offset_m) {
            (None, None) => None,
            (a, b) => Some(a.unwrap_or(0.0) + b.unwrap_or(0.0)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_level_is_added_free_per_surface_once() {
        let mut spec = ModelSpec::paper();
        spec.surfaces.push(("tape".into(), Vec::new()));
        add_surface_level(&mut spec);
        add_surface_level(&mut spec);
        assert_eq!(spec.effects.iter().filter(|e| e.name == "surface_level").count(), 1);
        for (surface, values) in &spec.surfaces {
            let levels: Vec<_> = values.iter().filter(|(r, _)| r.effect == "surface_level").collect();
            assert_eq!(levels.len(), 1, "{surface}");
            let (r, setting) = levels[0];
            assert_eq!(r.param, "level_m");
            assert!(setting.free && setting.min == -SURFACE_LEVEL_RANGE_M && setting.max == SURFACE_LEVEL_RANGE_M);
        }
    }
}
