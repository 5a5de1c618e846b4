//! The impact's phases: which phase a frame belongs to, and the frames each phase spans in a shot.

use serde::{Deserialize, Serialize};

/// The phase of the impact a frame belongs to, as the estimate's contact frames divide a shot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Before the touch.
    FlightIn,
    /// On (or within the contact margin of) the surface.
    Contact,
    /// After the separation.
    FlightOut,
    /// Not known (no phases were given or found).
    Unknown,
}

impl Phase {
    /// Every phase, in time order, then [`Phase::Unknown`].
    pub const ALL: [Phase; 4] = [Phase::FlightIn, Phase::Contact, Phase::FlightOut, Phase::Unknown];

    /// Name as written in files (the same as its serde name).
    pub fn name(self) -> &'static str {
        match self {
            Phase::FlightIn => "flight_in",
            Phase::Contact => "contact",
            Phase::FlightOut => "flight_out",
            Phase::Unknown => "unknown",
        }
    }

    /// The phase of `frame` given the contact's first and last frames: before the first, flight in; through
    /// the last, contact; after it, flight out.
    pub fn of_frame(frame: u64, contact_first: u64, contact_last: u64) -> Phase {
        if frame < contact_first {
            Phase::FlightIn
        } else if frame <= contact_last {
            Phase::Contact
        } else {
            Phase::FlightOut
        }
    }
}

/// Frame indices (first, last) of each phase, and the frames each flight fit used.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PhaseFrames {
    /// Incoming flight: first and last frame fitted.
    pub flight_in: (usize, usize),
    /// Frames with the ball on (or within a pixel of) the surface.
    pub contact: (usize, usize),
    /// Outgoing flight: first and last frame fitted.
    pub flight_out: (usize, usize),
    /// Frames in each fit (in, out).
    pub fitted: (usize, usize),
}

impl PhaseFrames {
    /// The phase of `frame` ([`Phase::of_frame`] on the contact frames).
    pub fn phase_of(&self, frame: usize) -> Phase {
        Phase::of_frame(frame as u64, self.contact.0 as u64, self.contact.1 as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_the_serde_names_and_frames_fall_in_order() {
        for p in Phase::ALL {
            assert_eq!(serde_json::to_string(&p).unwrap(), format!("\"{}\"", p.name()));
        }
        let frames = PhaseFrames {
            flight_in: (0, 9),
            contact: (10, 14),
            flight_out: (15, 30),
            fitted: (10, 16),
        };
        let seen: Vec<Phase> = [9, 10, 14, 15].into_iter().map(|f| frames.phase_of(f)).collect();
        assert_eq!(
            seen,
            [Phase::FlightIn, Phase::Contact, Phase::Contact, Phase::FlightOut]
        );
    }
}
