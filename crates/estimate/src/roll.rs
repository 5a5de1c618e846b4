//! The camera's roll over a session: the surface line's tilt in the image, pooled over the shots.

use crate::shot::Measured;

/// The surface's tilt in the image over a session from the shots' tilts (`Estimate::surface_tilt_deg` of
/// those whose contact line was seen or given; degrees, counter-clockwise as seen; a camera rolled by φ shows
/// −φ for down-slope +x): their inverse-variance weighted mean. Its standard error is inflated by the shots'
/// scatter when that exceeds their own errors (a camera knocked between shots, a line mis-seen on some), so
/// it never claims more than the shots agree on. Tilts without a finite positive error are skipped; `None`
/// when none is left.
pub fn session_tilt_deg(tilts: &[Measured]) -> Option<Measured> {
    let tilts: Vec<&Measured> = tilts
        .iter()
        .filter(|m| m.value.is_finite() && m.se.is_finite() && m.se > 0.0)
        .collect();
    let n = tilts.len();
    if n == 0 {
        return None;
    }
    let w: f64 = tilts.iter().map(|m| m.se.powi(-2)).sum();
    let mean = tilts.iter().map(|m| m.value * m.se.powi(-2)).sum::<f64>() / w;
    let scatter = if n > 1 {
        let chi2: f64 = tilts.iter().map(|m| ((m.value - mean) / m.se).powi(2)).sum();
        (chi2 / (n - 1) as f64).sqrt().max(1.0)
    } else {
        1.0
    };
    Some(Measured {
        value: mean,
        se: w.powf(-0.5) * scatter,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(value: f64, se: f64) -> Measured {
        Measured { value, se }
    }

    #[test]
    fn agreeing_shots_pool_to_a_smaller_error() {
        let t = session_tilt_deg(&[m(-1.5, 0.02), m(-1.5, 0.02), m(-1.5, 0.02), m(-1.5, 0.02)]).unwrap();
        assert!((t.value + 1.5).abs() < 1e-12 && (t.se - 0.01).abs() < 1e-12, "{t:?}");
    }

    #[test]
    fn scattered_shots_widen_the_error_to_their_scatter() {
        // Errors of 0.01° but values 1° apart: the pooled error follows the scatter, not the claimed errors.
        let t = session_tilt_deg(&[m(-1.0, 0.01), m(-2.0, 0.01), m(-1.0, 0.01), m(-2.0, 0.01)]).unwrap();
        assert!((t.value + 1.5).abs() < 1e-12);
        let sd_of_mean = (4.0 * 0.25 / 3.0f64).sqrt() / 2.0;
        assert!((t.se - sd_of_mean).abs() < 1e-9, "{t:?}");
    }

    #[test]
    fn no_usable_tilt_is_none() {
        assert!(session_tilt_deg(&[]).is_none());
        assert!(session_tilt_deg(&[m(f64::NAN, 0.1), m(1.0, 0.0)]).is_none());
    }
}
