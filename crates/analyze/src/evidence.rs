//! What each fitted shot carries to the comparison besides its frames ([`ShotExtras`]).

use crate::ShotData;
use bouncelab_compare::{ShotExtras, SpinFrame};
use bouncelab_fit::FitResult;

/// Every fitted shot's extras (in `fitted`'s order, which is `fit.shots`'), the measured contact time
/// re-read from the flight arcs at the surface level the fit found ([`FitResult::shot_level_m`]).
pub(crate) fn fitted_extras(fitted: &[&ShotData], fit: &FitResult, radius_m: f64) -> Vec<ShotExtras> {
    fitted
        .iter()
        .zip(&fit.shots)
        .map(|(s, f)| {
            let mut e = shot_extras(s);
            if let Some(level) = fit.shot_level_m(f) {
                e.contact_time_s = s.estimate.contact_time_at_level(level, radius_m);
            }
            e
        })
        .collect()
}

/// The evidence a shot carries besides its frames: drop height, contact time, the camera's roll from the
/// surface line's tilt, and the spin measured before and after the impact (at the first and last fitted
/// frames, where the flight arcs hold it constant but for rolling resistance and drag, which act slowly).
fn shot_extras(s: &ShotData) -> ShotExtras {
    let frames = &s.measured.frames;
    let mut spin = Vec::new();
    for (m, f) in [
        (s.estimate.spin_in, frames.first()),
        (s.estimate.spin_out, frames.last()),
    ] {
        if let (Some(m), Some(f)) = (m, f)
            && m.se > 0.0
            && m.value.is_finite()
        {
            spin.push(SpinFrame {
                t_s: f.t_s,
                omega_rad_s: m.value,
                sigma_rad_s: m.se,
            });
        }
    }
    ShotExtras {
        drop_height_m: Some(s.drop_height_m),
        contact_time_s: Some(s.estimate.contact_ms.value * 1e-3),
        camera_roll_deg: s.track.surface_tilt_deg,
        camera_roll_se_deg: s.track.surface_tilt_deg.and(s.estimate.surface_tilt_deg).map(|m| m.se),
        spin,
    }
}
