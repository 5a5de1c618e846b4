//! What the detector is asked for when it looks for the ball: the smallest radius, the window around a
//! radius already measured, and how many candidates it keeps. Acquisition, the tracker's re-detection and
//! the OpenCV reference use the same numbers.

/// The smallest ball radius searched without a scale, px: below it a ball's rim has too few pixels for a
/// sub-pixel circle.
pub(crate) const MIN_BALL_RADIUS_PX: f64 = 8.0;

/// The radii searched around a ball radius already measured, as factors of it (±15 %): room for the error
/// of that measurement and for the ball's apparent size changing within a clip, while circles of clearly
/// another size are not candidates.
pub(crate) const RADIUS_WINDOW: (f64, f64) = (0.85, 1.15);

/// The radii searched around the radius a scale hint gives (the ball's diameter over the hint), as factors of
/// it (±20 %): the hint is approximate ([`crate::ClipTracking::scale_hint_m_per_px`]), so the window is wider
/// than [`RADIUS_WINDOW`].
pub(crate) const HINT_WINDOW: (f64, f64) = (0.8, 1.2);

/// Circles the detector keeps per frame when it looks for the ball: a seam drawn as a dark line can out-vote
/// the rim, so enough are kept for the rim to be among them.
pub(crate) const BALL_CANDIDATES: usize = 24;

/// The radius range searched around a measured radius `r_px`, px ([`RADIUS_WINDOW`]).
pub(crate) fn radius_window(r_px: f64) -> (f64, f64) {
    (RADIUS_WINDOW.0 * r_px, RADIUS_WINDOW.1 * r_px)
}

/// The radius range searched around the radius `r_px` a scale hint gives, px ([`HINT_WINDOW`]).
pub(crate) fn hint_window(r_px: f64) -> (f64, f64) {
    (HINT_WINDOW.0 * r_px, HINT_WINDOW.1 * r_px)
}
