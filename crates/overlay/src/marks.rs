//! The plain data drawn: one ball fix per frame and the surface line, as stored rows give them; the colours
//! and words of the tracker's statuses and the impact's phases.

use crate::error::OverlayError;
use image::Rgb;

pub use bouncelab_track::Status;

/// The word drawn on a frame for a tracker status.
pub fn status_label(status: Status) -> &'static str {
    match status {
        Status::Ok => "OK",
        Status::Occluded => "OCCLUDED",
        Status::CutByBorder => "CUT",
        Status::Absent => "ABSENT",
        Status::Ambiguous => "AMBIGUOUS",
    }
}

/// A status's colour: white when all is well, warmer as the measurement gets weaker, red when there is none.
pub fn status_colour(status: Status) -> Rgb<u8> {
    match status {
        Status::Ok => Rgb([255, 255, 255]),
        Status::Occluded => Rgb([240, 228, 66]),
        Status::CutByBorder => Rgb([230, 159, 0]),
        Status::Absent => Rgb([255, 60, 60]),
        Status::Ambiguous => Rgb([255, 60, 200]),
    }
}

pub use bouncelab_estimate::Phase;

/// The word drawn on a frame for a phase.
pub fn phase_label(phase: Phase) -> &'static str {
    match phase {
        Phase::FlightIn => "IN",
        Phase::Contact => "CONTACT",
        Phase::FlightOut => "OUT",
        Phase::Unknown => "",
    }
}

/// The colour of the circle and centre in a phase (Okabe–Ito colours, told apart with colour-blind vision):
/// sky blue coming in, vermillion in contact, bluish green going out, white when unknown.
pub fn phase_colour(phase: Phase) -> Rgb<u8> {
    match phase {
        Phase::FlightIn => Rgb([86, 180, 233]),
        Phase::Contact => Rgb([213, 94, 0]),
        Phase::FlightOut => Rgb([0, 158, 115]),
        Phase::Unknown => Rgb([255, 255, 255]),
    }
}

/// One frame's ball, as a trajectory row gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallMark {
    /// Frame index in the clip (dropped frames counted).
    pub frame: u64,
    /// Centre x, px (pixel centres at integer coordinates, x right).
    pub x_px: f64,
    /// Centre y, px (y down).
    pub y_px: f64,
    /// Radius, px.
    pub r_px: f64,
    /// What the tracker said.
    pub status: Status,
    /// The impact's phase at this frame.
    pub phase: Phase,
}

impl BallMark {
    /// A mark from a stored row, its status given by name (`ok`, `occluded`, `cut_by_border`, `absent`,
    /// `ambiguous`); checked as [`BallMark::check`] does.
    pub fn from_row(
        frame: u64,
        x_px: f64,
        y_px: f64,
        r_px: f64,
        status: &str,
        phase: Phase,
    ) -> Result<BallMark, OverlayError> {
        let status = Status::from_name(status).map_err(|e| OverlayError::UnknownStatus { frame, name: e.name })?;
        let mark = BallMark {
            frame,
            x_px,
            y_px,
            r_px,
            status,
            phase,
        };
        mark.check()?;
        Ok(mark)
    }

    /// The centre and radius when the status says the ball was measured; an error if they are then not
    /// finite (or the radius is not positive). `None` for absent and ambiguous frames.
    pub fn circle(&self) -> Result<Option<(f64, f64, f64)>, OverlayError> {
        if !self.status.measured() {
            return Ok(None);
        }
        for (field, value) in [("x_px", self.x_px), ("y_px", self.y_px), ("r_px", self.r_px)] {
            if !value.is_finite() {
                return Err(OverlayError::NotFinite {
                    frame: self.frame,
                    field,
                    value,
                    status: self.status.name(),
                });
            }
        }
        if self.r_px <= 0.0 {
            return Err(OverlayError::BadRadius {
                frame: self.frame,
                r_px: self.r_px,
            });
        }
        Ok(Some((self.x_px, self.y_px, self.r_px)))
    }

    /// Checks that a measured frame has a finite centre and a positive radius.
    pub fn check(&self) -> Result<(), OverlayError> {
        self.circle().map(|_| ())
    }
}

/// The surface line in the image: `y = y0 + slope · (x − x0)`, px (y down).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceLine {
    /// Reference column, px.
    pub x0: f64,
    /// Height of the line at `x0`, px.
    pub y0: f64,
    /// dy/dx.
    pub slope: f64,
}

impl SurfaceLine {
    /// The line's height at column `x`, px.
    pub fn y_at(&self, x: f64) -> f64 {
        self.y0 + self.slope * (x - self.x0)
    }

    /// An error naming the first field that is not a finite number.
    pub fn check(&self) -> Result<(), OverlayError> {
        for (field, value) in [("x0", self.x0), ("y0", self.y0), ("slope", self.slope)] {
            if !value.is_finite() {
                return Err(OverlayError::BadLine { field, value });
            }
        }
        Ok(())
    }

    /// Its colour: Okabe–Ito yellow.
    pub fn colour() -> Rgb<u8> {
        Rgb([240, 228, 66])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_names_round_trip() {
        for s in Status::ALL {
            assert_eq!(Status::from_name(s.name()), Ok(s));
        }
        assert!(Status::from_name("OK").is_err());
    }

    #[test]
    fn rows_are_checked_naming_the_frame_and_field() {
        let e = BallMark::from_row(7, 1.0, 2.0, 3.0, "lost", Phase::Unknown).unwrap_err();
        assert!(
            e.to_string().contains("frame 7") && e.to_string().contains("`lost`"),
            "{e}"
        );
        let e = BallMark::from_row(8, f64::NAN, 2.0, 3.0, "ok", Phase::Unknown).unwrap_err();
        assert!(e.to_string().contains("frame 8: x_px is NaN"), "{e}");
        let e = BallMark::from_row(9, 1.0, 2.0, -3.0, "occluded", Phase::Contact).unwrap_err();
        assert!(e.to_string().contains("frame 9: radius -3"), "{e}");
        // An absent frame carries no circle: NaN is what the tracker writes there.
        let m = BallMark::from_row(10, f64::NAN, f64::NAN, f64::NAN, "absent", Phase::FlightIn).unwrap();
        assert_eq!(m.circle().unwrap(), None);
    }

    #[test]
    fn a_line_with_a_nan_is_refused() {
        let l = SurfaceLine {
            x0: 0.0,
            y0: 1.0,
            slope: f64::INFINITY,
        };
        assert!(l.check().unwrap_err().to_string().contains("slope is inf"));
        assert_eq!(SurfaceLine { slope: 0.5, ..l }.y_at(4.0), 3.0);
    }
}
