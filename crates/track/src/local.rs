//! The surface's local frame in the image: where the physics is measured.

use crate::surface::SurfaceLine;
use serde::{Deserialize, Serialize};

/// The local frame of the surface in the image: x along the surface line, pointing down-slope; y along its outward normal (up, away from the band); origin on the
/// line; metres. A rolled camera tilts the line in the image, and the frame turns with it, so an impact's
/// normal and tangential velocities are the surface's, not the image's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SurfaceFrame {
    /// The origin in the image, px.
    pub origin_px: [f64; 2],
    /// The line's slope in the image, dy/dx (y down).
    pub slope: f64,
    /// +1 when down-slope is +x in the image, −1 when it is −x.
    pub downslope_sign: f64,
    /// Metres per pixel.
    pub m_per_px: f64,
}

impl SurfaceFrame {
    /// The frame on `line` whose origin is the foot of the perpendicular from the image point (x, y) px.
    pub fn on_line(line: &SurfaceLine, x: f64, y: f64, downslope_negative_x: bool, m_per_px: f64) -> Self {
        let (_, n) = axes(line.slope);
        // A point on the line, then the foot: p − ((p − q)·n) n.
        let q = [x, line.y_at(x)];
        let h = (x - q[0]) * n[0] + (y - q[1]) * n[1];
        SurfaceFrame {
            origin_px: [x - h * n[0], y - h * n[1]],
            slope: line.slope,
            downslope_sign: if downslope_negative_x { -1.0 } else { 1.0 },
            m_per_px,
        }
    }

    /// The local coordinates (x down-slope, y up from the surface), m, of the image point (x, y) px.
    pub fn to_local(&self, x: f64, y: f64) -> (f64, f64) {
        let (t, n) = axes(self.slope);
        let d = [x - self.origin_px[0], y - self.origin_px[1]];
        (
            self.downslope_sign * (d[0] * t[0] + d[1] * t[1]) * self.m_per_px,
            (d[0] * n[0] + d[1] * n[1]) * self.m_per_px,
        )
    }

    /// Height of the image point (x, y) above the line, px (along the normal).
    pub fn height_px(&self, x: f64, y: f64) -> f64 {
        self.to_local(x, y).1 / self.m_per_px
    }

    /// The surface's tilt in the image, degrees, counter-clockwise as seen.
    pub fn tilt_deg(&self) -> f64 {
        (-self.slope).atan().to_degrees()
    }
}

/// Unit tangent (along +x of the image) and outward normal (up in the image) of a line of slope `slope`.
fn axes(slope: f64) -> ([f64; 2], [f64; 2]) {
    let k = 1.0 / (1.0 + slope * slope).sqrt();
    ([k, slope * k], [slope * k, -k])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_line_gives_image_axes() {
        let line = SurfaceLine::given(100.0, 300.0, 0.0);
        let f = SurfaceFrame::on_line(&line, 120.0, 200.0, false, 1e-3);
        assert_eq!(f.origin_px, [120.0, 300.0]);
        let (x, y) = f.to_local(130.0, 250.0);
        assert!((x - 0.010).abs() < 1e-12 && (y - 0.050).abs() < 1e-12, "{x} {y}");
        let m = SurfaceFrame::on_line(&line, 120.0, 200.0, true, 1e-3);
        assert!((m.to_local(130.0, 250.0).0 + 0.010).abs() < 1e-12);
    }

    /// A point 50 px up the normal of a tilted line is 50 px high and on the origin's normal.
    #[test]
    fn a_tilted_line_turns_the_frame() {
        let line = SurfaceLine::given(256.0, 400.0, 3.0);
        let f = SurfaceFrame::on_line(&line, 200.0, 300.0, false, 1.0);
        let th = 3f64.to_radians();
        // Up the normal of a line rising to the right (counter-clockwise tilt) is up and to the left.
        let p = (f.origin_px[0] - 50.0 * th.sin(), f.origin_px[1] - 50.0 * th.cos());
        let (x, y) = f.to_local(p.0, p.1);
        assert!(x.abs() < 1e-9 && (y - 50.0).abs() < 1e-9, "{x} {y}");
        // Along the line, 10 px to the right and up.
        let (x, y) = f.to_local(f.origin_px[0] + 10.0 * th.cos(), f.origin_px[1] - 10.0 * th.sin());
        assert!((x - 10.0).abs() < 1e-9 && y.abs() < 1e-9, "{x} {y}");
        assert!((f.tilt_deg() - 3.0).abs() < 1e-12);
    }
}
