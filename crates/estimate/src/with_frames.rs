//! The crate's entry point: a shot measured from its track and, for the spin, its frames.

use crate::shot::{Conditions, Estimate, EstimateError, estimate};
use crate::spin::{SpinOptions, measure_spin};
use bouncelab_frames::Clip;
use bouncelab_track::Track;

/// [`estimate`] plus the spin before and after the impact, measured from the clip's frames
/// ([`measure_spin`] with default options); a phase whose spin cannot be measured gets `None` and a note.
pub fn estimate_with_frames(track: &Track, clip: &Clip, c: &Conditions) -> Result<Estimate, EstimateError> {
    let mut e = estimate(track, c)?;
    let spin = measure_spin(clip, track, &e.phases, &SpinOptions::default());
    e.spin_in = spin.spin_in;
    e.spin_out = spin.spin_out;
    e.notes.extend(spin.notes);
    Ok(e)
}
