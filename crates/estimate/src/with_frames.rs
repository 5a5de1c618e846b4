//! The crate's entry point: a shot measured from its track and, for the spin, its frames.

use crate::shot::{Conditions, Estimate, EstimateError, estimate};
use crate::spin::{SpinOptions, measure_spin};
use bouncelab_frames::Clip;
use bouncelab_track::Track;

/// [`estimate`] plus the spin before and after the impact, measured from the clip's frames
/// ([`measure_spin`] with default options); a phase whose spin cannot be measured gets `None` and a note.
pub fn estimate_with_frames(track: &Track, clip: &Clip, c: &Conditions) -> Result<Estimate, EstimateError> {
    Ok(with_spin(estimate(track, c)?, track, clip))
}

/// The estimate `e` of `track` with its spin measured from the clip's frames.
fn with_spin(mut e: Estimate, track: &Track, clip: &Clip) -> Estimate {
    let spin = measure_spin(clip, track, &e.phases, &SpinOptions::default());
    e.spin_in = spin.spin_in;
    e.spin_out = spin.spin_out;
    e.notes.extend(spin.notes);
    e
}

/// [`estimate_with_frames`] for a clip whose down-slope direction nobody gave (the track's is a default):
/// when an inclined shot's flights fall along the surface clearly the other way
/// ([`crate::GravityCheck::downslope_evidence`]), or a ball dropped from rest meets the surface moving
/// clearly the other way along it (`fall::downslope_reversed`), the shot is measured with the down-slope
/// they show, and a note says so. An inclined shot whose flights cannot tell keeps the default with a note;
/// one whose flights confirm it, or a level one, keeps it silently.
///
/// The ball's fall tells the surface's tilt only through the angle it makes with the down-slope direction,
/// so it is used (see [`Conditions::fall_se_deg`]) only where that direction is known: confirmed or shown by
/// the flights, or no incline.
pub fn estimate_finding_downslope(track: &Track, clip: &Clip, c: &Conditions) -> Result<Estimate, EstimateError> {
    let without_fall = Conditions {
        fall_se_deg: None,
        ..*c
    };
    let mut first = estimate(track, &without_fall)?;
    // Below 1° the direction hardly matters and gravity's pull along the surface is too small to tell it.
    let inclined = c.incline_deg.abs() >= 1.0;
    let by_gravity = first.gravity.as_ref().and_then(|g| g.downslope_evidence(c.gravity));
    let by_fall = c.fall_se_deg.and_then(|se| {
        let v = |k: usize| (first.v_in[k].value, first.v_in[k].se);
        let incidence = crate::fall::incidence_rad([v(0).0, v(1).0], [v(0).1, v(1).1])?;
        crate::fall::downslope_reversed(incidence, c.incline_deg, se)
    });
    let evidence = by_gravity.or(by_fall);
    if c.fall_se_deg.is_some() && (c.incline_deg == 0.0 || evidence == Some(false)) {
        first = estimate(track, c)?;
    }
    if !inclined || evidence != Some(true) {
        // On an incline the down-slope sets the sign of gravity's pull along the surface in the flights'
        // fits, and so the velocities at the contact: μ moved by 0.05–0.17 on the looks sweep's inclines of
        // 7° or more.
        if inclined && evidence.is_none() {
            let side = if track.downslope_negative_x { "-x" } else { "+x" };
            let fall = first.gravity.as_ref().map_or(String::new(), |g| {
                format!(
                    " (along the surface {:.1} ± {:.1} m/s², gravity's ±{:.1} either way)",
                    g.measured[0].value,
                    g.measured[0].se,
                    g.expected[0].abs()
                )
            });
            first.notes.insert(
                0,
                format!(
                    "down-slope not given and the flights do not tell it{fall}: {side} assumed; friction and spin depend on it (set `downslope` under [camera])"
                ),
            );
        }
        return Ok(with_spin(first, track, clip));
    }
    let flipped = Track {
        downslope_negative_x: !track.downslope_negative_x,
        ..track.clone()
    };
    let mut e = estimate_with_frames(&flipped, clip, c)?;
    let side = if flipped.downslope_negative_x { "-x" } else { "+x" };
    e.notes.insert(
        0,
        format!(
            "down-slope not given: {}, so {side} is taken as down-slope (set `downslope = \"{side}\"` under [camera] to say so)",
            if by_gravity.is_some() {
                format!("the flights fall along the surface towards {side} in the image")
            } else {
                format!(
                    "the ball meets the surface moving towards {side} in the image, as a ball dropped onto a {}° incline moves down-slope",
                    c.incline_deg
                )
            }
        ),
    );
    Ok(e)
}
