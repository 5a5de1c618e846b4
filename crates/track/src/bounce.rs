//! Which frames after a bounce the forward track may have measured off the ball, and which fix a frame
//! keeps when they are measured again backward from the outgoing flight.
//!
//! The forward track predicts each frame from a parabola through its last fixes. Through a contact those
//! fixes curve with the surface's push, and for the first frames after the ball leaves the surface the
//! parabola carries that push on: the prediction runs ahead of a ball that now only falls. At 10,000 fps a
//! frame's step is small and the search still holds the rim; at 2,000 fps (a clay bounce of the independent
//! renderer, every fifth frame) the prediction was 4.6 px ahead two frames after separation and the fix
//! followed it. Tracking is symmetric in time: a pass backward from the clean outgoing flight predicts those
//! frames from free flight, as the forward pass predicts the compression from the incoming flight. So the
//! frames from the lowest point to the first clean run after it are measured again backward, and in the
//! frames where the ball is clear of the surface and the two passes disagree the backward fix is kept; in
//! contact, where both passes predicted from a push, the clearer of the two; and nowhere a circle clearly
//! further from the ball's size than the forward one (a pass that lost the pressed ball fits what rim it
//! still sees with a smaller circle). Cost: O(n) over the fixes; the pass itself runs only when the
//! forward track was not clean from where the ball cleared the surface.

use crate::surface::SurfaceLine;
use crate::tracker::{BallFix, CLEAN_QUALITY, Status};

/// Consecutive clean flight fixes after the bounce from which the backward pass starts.
const SETTLED_AFTER_BOUNCE: usize = 5;

/// The frames after a bounce to measure again: from `lowest` (the measured fix nearest the surface, in
/// contact) up to, not including, `settled` (the first of [`SETTLED_AFTER_BOUNCE`] clean fixes clear of the
/// surface, from which the backward pass is seeded).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct AfterBounce {
    pub lowest: usize,
    pub settled: usize,
}

/// Whether `fix` is measured and its disc clear of `line` ([`SurfaceLine::clears_disc`], the tracker's own
/// test for free flight).
fn clear_of(line: &SurfaceLine, fix: &BallFix) -> bool {
    fix.status.measured() && line.clears_disc(fix.x_px, fix.y_px, fix.r_px)
}

/// The frames after the clip's bounce that the forward track may have measured off the ball: `None` when
/// the ball never touched the surface in the clip, when no run of clean flight follows the bounce to seed
/// a backward pass, or when the forward track was clean from the first frame the ball cleared the surface
/// (then it held the ball through the bounce). A fix is clean when it is `ok`, clear of the surface and at
/// least as clear as [`CLEAN_QUALITY`] or a quarter of the clip's flight fixes (a noisy clip never reaches
/// that quality). Cost: O(n).
pub(crate) fn after_bounce(fixes: &[BallFix], line: &SurfaceLine) -> Option<AfterBounce> {
    let lowest = fixes
        .iter()
        .enumerate()
        .filter(|(_, f)| f.status.measured())
        .min_by(|a, b| {
            line.height_of(a.1.x_px, a.1.y_px)
                .total_cmp(&line.height_of(b.1.x_px, b.1.y_px))
        })
        .map(|(i, _)| i)?;
    if clear_of(line, &fixes[lowest]) {
        return None;
    }
    let mut flight: Vec<f64> = fixes
        .iter()
        .filter(|f| f.status == Status::Ok && clear_of(line, f))
        .map(|f| f.quality)
        .collect();
    if flight.is_empty() {
        return None;
    }
    flight.sort_by(f64::total_cmp);
    let clean_quality = CLEAN_QUALITY.min(flight[flight.len() / 4]);
    let clean = |f: &BallFix| f.status == Status::Ok && clear_of(line, f) && f.quality >= clean_quality;
    let first_clear = (lowest + 1..fixes.len()).find(|&i| clear_of(line, &fixes[i]))?;
    // The backward pass is seeded by the run's first two fixes.
    let settled = (first_clear..fixes.len().saturating_sub(SETTLED_AFTER_BOUNCE - 1))
        .find(|&i| fixes[i..i + SETTLED_AFTER_BOUNCE].iter().all(clean))?;
    (settled > first_clear).then_some(AfterBounce { lowest, settled })
}

/// How far apart two passes' fixes of one frame may be and still be the same circle, px. Two passes
/// that both hold the rim read it a few tenths of a pixel apart where the texture or noise offers two
/// readings (0.3–0.6 px seen on the independent renderer's clips at their full rate), and neither is the
/// better there; a pass that has left the ball is pixels away (1.9–10.5 px seen after a bounce at
/// 2,000 fps).
const SAME_CIRCLE_PX: f64 = 1.0;

/// Whether two passes' fixes `a` and `b` of one frame are the same circle: centres within
/// [`SAME_CIRCLE_PX`] or 3 combined σ.
pub(crate) fn same_circle(a: &BallFix, b: &BallFix) -> bool {
    let apart = (a.x_px - b.x_px).hypot(a.y_px - b.y_px);
    apart <= (3.0 * a.sigma_px.hypot(b.sigma_px)).max(SAME_CIRCLE_PX)
}

/// Whether fix `a` is the ball's size, radius `r_px` (its free flight's), clearly more nearly than `b`:
/// its radius is nearer `r_px` by more than 3 of their radii's combined σ. A σ not stated counts as no
/// evidence (the test fails).
fn nearer_the_ball_s_size(a: &BallFix, b: &BallFix, r_px: f64) -> bool {
    let sigma = a.sigma_r_px.hypot(b.sigma_r_px);
    sigma.is_finite() && (b.r_px - r_px).abs() - (a.r_px - r_px).abs() > 3.0 * sigma
}

/// Whether the fix `back` of the backward pass replaces the forward pass's `forward` after the bounce on
/// `line`, for a ball of radius `ball_r_px` in free flight (`None` when unknown): the forward frame was not
/// measured, or the two are not the same circle (centres further apart than [`SAME_CIRCLE_PX`] and 3
/// combined σ), the forward fix is not clearly nearer the ball's size ([`nearer_the_ball_s_size`]), and
/// - with `back` clear of the surface, the forward fix is not clearly the clearer circle (quality higher by
///   more than 0.1): there the backward pass predicted from free flight, the forward one from the push;
/// - in contact, `back` is the clearer circle: both passes predicted from a push there, the backward one
///   from the restitution's.
///
/// Where they agree the forward fix stands, so a bounce the forward track held is left as it was. The size
/// test is there because a pass that has lost the ball in contact fits what rim it still sees with a
/// smaller circle: on `looks --seed 12` S038 (a 48 px plain ball under 11.9 DN) four backward fixes were
/// 0.95–2.3 px smaller than the flight's radius and 1.5–3.0 px off the ball, the forward ones within 0.34 px
/// of that radius and 0.23 px of the ball, and the noise decided which quality was the higher.
pub(crate) fn back_replaces(line: &SurfaceLine, back: &BallFix, forward: &BallFix, ball_r_px: Option<f64>) -> bool {
    if !back.status.measured() {
        return false;
    }
    if !forward.status.measured() {
        return true;
    }
    if same_circle(back, forward) {
        return false;
    }
    if ball_r_px.is_some_and(|r| nearer_the_ball_s_size(forward, back, r)) {
        return false;
    }
    if clear_of(line, back) {
        forward.quality <= back.quality + 0.1
    } else {
        back.quality > forward.quality
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line along y = 300 and a track falling onto it, pressed 3 px in at frame 10, and rising again;
    /// `quality(i)` per frame.
    fn bounce(quality: impl Fn(usize) -> f64) -> (SurfaceLine, Vec<BallFix>) {
        let line = SurfaceLine::given(0.0, 300.0, 0.0);
        let r = 40.0;
        let fixes = (0..30)
            .map(|i| {
                let depth = 3.0 - 2.0 * (i as f64 - 10.0).abs();
                BallFix {
                    frame: i,
                    t_s: i as f64 * 1e-4,
                    x_px: 100.0 + i as f64,
                    y_px: 300.0 - r + depth,
                    r_px: r,
                    sigma_px: 0.02,
                    sigma_r_px: 0.02,
                    quality: quality(i),
                    status: Status::Ok,
                }
            })
            .collect();
        (line, fixes)
    }

    #[test]
    fn a_bounce_held_cleanly_is_not_measured_again() {
        let (line, fixes) = bounce(|_| 0.95);
        assert_eq!(after_bounce(&fixes, &line), None);
    }

    #[test]
    fn weak_fixes_after_the_bounce_are_measured_again_from_the_clean_flight_after_them() {
        // Frames 13 and 14 (clear of the surface from frame 13) are weak circles.
        let (line, fixes) = bounce(|i| if (13..15).contains(&i) { 0.5 } else { 0.95 });
        assert_eq!(
            after_bounce(&fixes, &line),
            Some(AfterBounce {
                lowest: 10,
                settled: 15
            })
        );
    }

    #[test]
    fn a_track_that_never_touches_the_surface_has_no_bounce() {
        let (line, mut fixes) = bounce(|_| 0.95);
        for f in &mut fixes {
            f.y_px -= 20.0;
        }
        assert_eq!(after_bounce(&fixes, &line), None);
    }

    #[test]
    fn a_disagreeing_backward_fix_replaces_in_flight_unless_clearly_weaker_and_in_contact_when_clearer() {
        let (line, fixes) = bounce(|_| 0.9);
        let back_replaces = |b: &BallFix, f: &BallFix| back_replaces(&line, b, f, None);
        let forward = fixes[14];
        let same = BallFix {
            x_px: forward.x_px + 0.6,
            ..forward
        };
        assert!(!back_replaces(&same, &forward), "agreeing fixes keep the forward one");
        let apart = BallFix {
            y_px: forward.y_px - 4.0,
            quality: 0.85,
            ..forward
        };
        assert!(back_replaces(&apart, &forward));
        let weak = BallFix { quality: 0.6, ..apart };
        assert!(
            !back_replaces(&weak, &forward),
            "a clearly weaker backward circle does not replace"
        );
        let absent = BallFix::absent(14, forward.t_s, Status::Absent);
        assert!(back_replaces(&apart, &absent));
        assert!(!back_replaces(&absent, &forward));
        // In contact (frame 10, pressed 3 px in) only a clearer backward circle replaces the forward one.
        let pressed = BallFix {
            y_px: fixes[10].y_px + 4.0,
            ..fixes[10]
        };
        assert!(!back_replaces(&pressed, &fixes[10]));
        assert!(back_replaces(
            &BallFix {
                quality: 0.95,
                ..pressed
            },
            &fixes[10]
        ));
    }

    #[test]
    fn a_backward_fix_clearly_smaller_than_the_ball_does_not_replace_one_of_its_size() {
        let (line, fixes) = bounce(|_| 0.6);
        let forward = BallFix {
            sigma_r_px: 0.08,
            ..fixes[10]
        };
        // The pass has lost the pressed ball: a smaller circle, higher, and by the noise a little clearer.
        let shrunk = BallFix {
            y_px: forward.y_px - 2.5,
            r_px: forward.r_px - 1.5,
            sigma_r_px: 0.12,
            quality: 0.7,
            ..forward
        };
        let r = Some(forward.r_px);
        assert!(
            back_replaces(&line, &shrunk, &forward, None),
            "without the ball's size, the clearer wins"
        );
        assert!(!back_replaces(&line, &shrunk, &forward, r));
        // Only 0.3 px smaller, within 3 of the radii's combined σ (0.43 px): the size does not decide.
        let near = BallFix {
            r_px: forward.r_px - 0.3,
            ..shrunk
        };
        assert!(back_replaces(&line, &near, &forward, r));
        // A forward fix that left the ball (off in size) is replaced by a backward one of the ball's size.
        let off = BallFix {
            r_px: forward.r_px + 2.0,
            ..forward
        };
        let on = BallFix {
            y_px: forward.y_px - 2.5,
            quality: 0.7,
            ..forward
        };
        assert!(back_replaces(&line, &on, &off, r));
        // An unstated σ is no evidence either way.
        let unstated = BallFix {
            sigma_r_px: f64::NAN,
            ..shrunk
        };
        assert!(back_replaces(&line, &unstated, &forward, r));
    }
}
