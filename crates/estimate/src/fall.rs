//! The surface's tilt told by the ball's fall: a ball released at rest falls along gravity, so it meets a
//! surface inclined by β at β from the surface's normal, towards down-slope. Measured in a frame turned by
//! δ, the incoming velocity's angle from the normal is β − δ; so the fall measures the frame's turn to the
//! precision of the incline's angle, where a ragged band's edge may leave it uncertain by a degree.

use crate::shot::Measured;

/// The incoming velocity's angle from the inward normal, towards down-slope, rad, with its standard error,
/// from its components (along the surface down-slope, along the normal; m/s) and their standard errors.
/// `None` for a velocity that does not move towards the surface.
pub(crate) fn incidence_rad(v: [f64; 2], se: [f64; 2]) -> Option<Measured> {
    let [vt, vn] = v;
    let speed2 = vt * vt + vn * vn;
    if !(vn < 0.0 && speed2.is_finite()) {
        return None;
    }
    let se_rad = ((vn * se[0]).powi(2) + (vt * se[1]).powi(2)).sqrt() / speed2;
    Some(Measured {
        value: vt.atan2(-vn),
        se: se_rad,
    })
}

/// The surface's tilt in the image (degrees counter-clockwise as seen) that a fall at `incidence` (rad,
/// [`incidence_rad`] in a frame tilted by `frame_tilt_deg`) onto an incline of `incline_deg` implies, with
/// its standard error: the incidence's, and `fall_se_deg` for how well the fall's direction was known
/// beforehand (the incline's angle, the release). `downslope_sign` is +1 for down-slope +x in the image,
/// −1 for −x (a mirrored view turns the other way).
pub(crate) fn tilt_from_fall(
    frame_tilt_deg: f64,
    incidence: Measured,
    incline_deg: f64,
    fall_se_deg: f64,
    downslope_sign: f64,
) -> Measured {
    Measured {
        value: frame_tilt_deg + downslope_sign * (incidence.value.to_degrees() - incline_deg),
        se: incidence.se.to_degrees().hypot(fall_se_deg),
    }
}

/// How many standard errors of their difference a line's tilt and the fall's may differ by and still be
/// one tilt: beyond it the ball was not dropped from rest, the incline is not the one given, or the line is
/// not the surface, and the two are not combined.
pub(crate) const AGREE_SIGMAS: f64 = 3.0;

/// Whether a frame's tilt (a line's, or the image's axes with how level they are taken to be) and the
/// fall's agree within [`AGREE_SIGMAS`]; `Err` with their difference in standard errors if not.
pub(crate) fn agree(frame: Measured, fall: Measured) -> Result<(), f64> {
    let z = (frame.value - fall.value) / frame.se.hypot(fall.se);
    if !z.is_finite() || z.abs() > AGREE_SIGMAS {
        return Err(z);
    }
    Ok(())
}

/// The tilt a line and the fall give, inverse-variance weighted, when they [`agree`].
pub(crate) fn combine(line: Measured, fall: Measured) -> Result<Measured, f64> {
    agree(line, fall)?;
    let (wl, wf) = (line.se.powi(-2), fall.se.powi(-2));
    Ok(Measured {
        value: (line.value * wl + fall.value * wf) / (wl + wf),
        se: (wl + wf).powf(-0.5),
    })
}

/// Whether a fall taken with the down-slope the other way (`reversed_tilt_deg`: a fall at −β) agrees with the
/// `line`'s tilt as well as the `fall`'s does: the fall's direction along the surface then does not confirm
/// the down-slope it was measured with, and a wrong one (a mirrored camera) would turn the frame by 2β.
pub(crate) fn other_way_fits_as_well(line: Measured, fall: Measured, reversed_tilt_deg: f64) -> bool {
    (line.value - reversed_tilt_deg).abs() <= (line.value - fall.value).abs() && reversed_tilt_deg != fall.value
}

/// What a ball dropped from rest says of the down-slope direction its frame was built with: it meets the
/// surface at β (`incline_deg`) from the normal, moving down-slope. `Some(true)` when its `incidence` (rad,
/// with an error that counts the frame's tilt) lies near −β (a mirrored camera, a wrong default),
/// `Some(false)` near +β, `None` when the two are less than [`crate::DOWNSLOPE_SIGMAS`] standard errors
/// apart (with `fall_se_deg`) or the incidence is near neither (within [`AGREE_SIGMAS`]).
pub(crate) fn downslope_reversed(incidence: Measured, incline_deg: f64, fall_se_deg: f64) -> Option<bool> {
    let phi = incidence.value.to_degrees();
    let se = incidence.se.to_degrees().hypot(fall_se_deg);
    let resolved = 2.0 * incline_deg.abs() >= crate::DOWNSLOPE_SIGMAS * se;
    if !resolved {
        return None;
    }
    let (as_given, other_way) = ((phi - incline_deg).abs(), (phi + incline_deg).abs());
    if as_given <= AGREE_SIGMAS * se && as_given < other_way {
        Some(false)
    } else if other_way <= AGREE_SIGMAS * se && other_way < as_given {
        Some(true)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(value: f64, se: f64) -> Measured {
        Measured { value, se }
    }

    /// The velocity of a fall at β from the true normal, seen in a frame turned by δ (degrees, CCW as seen,
    /// down-slope +x): its angle from the frame's normal is β − δ.
    fn seen(beta_deg: f64, delta_deg: f64, speed: f64) -> [f64; 2] {
        let a = (beta_deg - delta_deg).to_radians();
        [speed * a.sin(), -speed * a.cos()]
    }

    #[test]
    fn a_frame_turned_by_a_degree_is_told_by_the_fall() {
        for (beta, delta) in [(20.0, 1.0), (20.0, -0.7), (0.0, 0.5), (-12.0, 2.0)] {
            let i = incidence_rad(seen(beta, delta, 2.5), [0.0, 0.0]).unwrap();
            // The frame's tilt is the truth (0.3°) plus δ; the fall takes δ out.
            let t = tilt_from_fall(0.3 + delta, i, beta, 0.5, 1.0);
            assert!((t.value - 0.3).abs() < 1e-9, "β {beta} δ {delta}: {t:?}");
            assert!((t.se - 0.5).abs() < 1e-12);
        }
    }

    #[test]
    fn a_mirrored_view_turns_the_other_way() {
        // Down-slope −x: the image's x is mirrored, so a frame turned by δ as seen is turned by −δ in the
        // surface's own sense.
        let i = incidence_rad(seen(15.0, -0.8, 2.0), [0.0, 0.0]).unwrap();
        let t = tilt_from_fall(-0.2 + 0.8, i, 15.0, 0.5, -1.0);
        assert!((t.value + 0.2).abs() < 1e-9, "{t:?}");
    }

    #[test]
    fn a_fall_nearer_the_other_down_slope_is_told() {
        // A mirrored camera on a 2° incline with +x given: the ball falls at −2° in the frame.
        let i = incidence_rad(seen(-2.0, 0.0, 2.0), [0.0, 0.0]).unwrap();
        let given = tilt_from_fall(0.0, i, 2.0, 0.5, 1.0);
        let reversed = tilt_from_fall(0.0, i, -2.0, 0.5, 1.0);
        assert!((given.value + 4.0).abs() < 1e-9 && reversed.value.abs() < 1e-9);
        assert!(other_way_fits_as_well(m(0.0, 2.0), given, reversed.value));
        // As filmed: the given down-slope fits, the other is 2β away.
        let i = incidence_rad(seen(2.0, 0.0, 2.0), [0.0, 0.0]).unwrap();
        let given = tilt_from_fall(0.0, i, 2.0, 0.5, 1.0);
        let reversed = tilt_from_fall(0.0, i, -2.0, 0.5, 1.0);
        assert!(!other_way_fits_as_well(m(0.0, 2.0), given, reversed.value));
        // No incline: both ways are one.
        let i = incidence_rad(seen(0.0, 0.3, 2.0), [0.0, 0.0]).unwrap();
        let t = tilt_from_fall(0.0, i, 0.0, 0.5, 1.0);
        assert!(!other_way_fits_as_well(m(0.0, 2.0), t, t.value));
    }

    #[test]
    fn the_fall_tells_the_down_slope_when_the_incline_is_clear_of_its_error() {
        let at = |deg: f64, se_deg: f64| m(deg.to_radians(), se_deg.to_radians());
        // A 10° incline, the frame's tilt known to 0.9°: the fall at +10° confirms, at −10° reverses.
        assert_eq!(downslope_reversed(at(10.4, 0.9), 10.0, 0.5), Some(false));
        assert_eq!(downslope_reversed(at(-9.3, 0.9), 10.0, 0.5), Some(true));
        // Near neither (a ball thrown sideways): no answer.
        assert_eq!(downslope_reversed(at(1.0, 0.2), 10.0, 0.5), None);
        // A 1.5° incline within 2 × 2 standard errors of its mirror image: no answer either way.
        assert_eq!(downslope_reversed(at(-1.5, 0.9), 1.5, 0.5), None);
        assert_eq!(downslope_reversed(at(1.5, 0.1), 0.0, 0.5), None);
    }

    #[test]
    fn the_incidence_error_follows_the_velocity_errors() {
        // Along the surface alone: dφ = v_n dv_t / |v|².
        let i = incidence_rad([0.0, -2.0], [0.02, 0.5]).unwrap();
        assert!((i.se - 0.01).abs() < 1e-12, "{i:?}");
        assert!(
            incidence_rad([1.0, 0.5], [0.0, 0.0]).is_none(),
            "moving away from the surface"
        );
        assert!(incidence_rad([f64::NAN, -1.0], [0.0, 0.0]).is_none());
    }

    #[test]
    fn agreeing_tilts_are_weighted_and_disagreeing_ones_are_not_combined() {
        let c = combine(m(-2.0, 0.9), m(-1.0, 0.3)).unwrap();
        let (wl, wf) = (0.9f64.powi(-2), 0.3f64.powi(-2));
        assert!((c.value - (-2.0 * wl - wf) / (wl + wf)).abs() < 1e-12);
        assert!((c.se - (wl + wf).powf(-0.5)).abs() < 1e-12);
        assert!(c.se < 0.3);
        // A ball thrown 10° off gravity's direction: the cues are 10 standard errors apart.
        let z = combine(m(0.0, 0.5), m(10.0, 0.5)).unwrap_err();
        assert!(z < -AGREE_SIGMAS, "{z}");
        assert!(combine(m(0.0, 0.0), m(0.0, 0.0)).is_err(), "no error: nothing to weigh");
    }
}
