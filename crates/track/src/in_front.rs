//! A line the ball passes in front of is not the surface it lands on.
//!
//! The surface finder takes the topmost well-supported line below the ball's first positions, and a ruler's
//! lower edge, a shelf or a fixture's edge behind the ball's path can be that line. The tracker hides the
//! rim below its line, so a wrong line leaves the ball measured on the arc above it through the whole fall
//! and bounce (a third of the rim lost, centres 0.3 px off, on the `looks` preset's S014, whose ruler lies
//! 34 px above the clay). After the forward pass, the frames where the ball reaches deepest below the line
//! are searched round the whole rim ([`crate::refine::rim_about_line`]): where, in most of them, the rim
//! goes on below the line as it runs above it, the ball is in front of the line, and the line is not the
//! surface. A surface's band hides the ball's rim below its top (or is pressed by it), so its rays there see
//! the band's texture, not the circle. Cost: one decoding and one edge search round the rim for each of
//! [`FRAMES`] frames, and only when the ball goes below the line at all.

use crate::refine::{EdgeSearch, RimAboutLine};
use crate::surface::SurfaceLine;
use crate::tracker::BallFix;

/// The deepest frames searched.
pub(crate) const FRAMES: usize = 5;

/// The band below the line whose rays are searched, px: a quarter of the radius (6 px at least), short of
/// how far a second line below it (the surface, when the line is a ruler's) usually lies.
pub(crate) fn band_depth_px(r_px: f64) -> f64 {
    (0.25 * r_px).max(6.0)
}

/// Why a line was judged to lie behind the ball.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InFront {
    /// Frames searched, and how many of them saw the rim go on below the line.
    pub frames: usize,
    pub seen: usize,
    /// How far the ball's lowest point went below the line, px.
    pub deepest_px: f64,
}

/// The measured fixes whose circle reaches below `line` by more than the line's margin and half the band
/// searched, deepest first, at most [`FRAMES`]: (index into `fixes`, how far below, px).
fn deepest_below(fixes: &[BallFix], line: &SurfaceLine, search: &EdgeSearch) -> Vec<(usize, f64)> {
    let margin = search.surface_margin + line.ragged_reach_px();
    let mut deep: Vec<(usize, f64)> = fixes
        .iter()
        .enumerate()
        .filter(|(_, f)| f.status.measured())
        .map(|(k, f)| (k, f.y_px + f.r_px - line.y_at(f.x_px)))
        .filter(|&(k, below)| below > margin + 0.5 * band_depth_px(fixes[k].r_px))
        .collect();
    deep.sort_by(|a, b| b.1.total_cmp(&a.1));
    deep.truncate(FRAMES);
    deep
}

/// Whether the ball is seen in front of `line` in the frames where it reaches deepest below it:
/// `rim_about(k, fix)` searches the rim of fix `k` in its frame ([`crate::refine::rim_about_line`], with
/// [`band_depth_px`]). `Some` when at least two of those frames had rays enough below the line and most of
/// them saw the rim go on there ([`RimAboutLine::rim_goes_on`]); `None` when the ball never goes so far
/// below it or its rim does not go on.
pub(crate) fn ball_in_front_of<E>(
    line: &SurfaceLine,
    fixes: &[BallFix],
    search: &EdgeSearch,
    mut rim_about: impl FnMut(usize, &BallFix) -> Result<Option<RimAboutLine>, E>,
) -> Result<Option<InFront>, E> {
    let deep = deepest_below(fixes, line, search);
    let Some(&(_, deepest_px)) = deep.first() else {
        return Ok(None);
    };
    let (mut frames, mut seen) = (0, 0);
    for &(k, _) in &deep {
        let Some(about) = rim_about(k, &fixes[k])? else {
            continue;
        };
        if about.tells() {
            frames += 1;
            seen += usize::from(about.rim_goes_on());
        }
    }
    Ok((frames >= 2 && 2 * seen > frames).then_some(InFront {
        frames,
        seen,
        deepest_px,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tracker::Status;

    fn fix(y: f64) -> BallFix {
        BallFix {
            frame: 0,
            t_s: 0.0,
            x_px: 100.0,
            y_px: y,
            r_px: 40.0,
            sigma_px: 0.05,
            sigma_r_px: 0.05,
            quality: 1.0,
            status: Status::Ok,
        }
    }

    fn about(below: usize, below_seen: usize) -> RimAboutLine {
        RimAboutLine {
            below,
            below_seen,
            above: 90,
            above_seen: 85,
        }
    }

    #[test]
    fn only_the_deepest_frames_far_enough_below_are_searched() {
        let line = SurfaceLine::given(100.0, 200.0, 0.0);
        // Bottoms at 150 … 260 px: only those beyond the margin (2 px) and half the band (5 px) below the
        // line count (six), and the five deepest of them are searched.
        let fixes: Vec<BallFix> = (0..12).map(|i| fix(110.0 + 10.0 * i as f64)).collect();
        let deep = deepest_below(&fixes, &line, &EdgeSearch::default());
        assert_eq!(deep.iter().map(|d| d.0).collect::<Vec<_>>(), vec![11, 10, 9, 8, 7]);
        assert!((deep[0].1 - 60.0).abs() < 1e-9);
        let shallow: Vec<BallFix> = (0..10).map(|i| fix(150.0 + 0.5 * i as f64)).collect();
        assert!(deepest_below(&shallow, &line, &EdgeSearch::default()).is_empty());
    }

    #[test]
    fn a_rim_going_on_below_the_line_in_most_frames_puts_the_ball_in_front() {
        let line = SurfaceLine::given(100.0, 200.0, 0.0);
        let fixes: Vec<BallFix> = (0..10).map(|i| fix(150.0 + 5.0 * i as f64)).collect();
        let search = EdgeSearch::default();
        let seen = ball_in_front_of::<()>(&line, &fixes, &search, |_, _| Ok(Some(about(20, 17)))).unwrap();
        assert_eq!(seen.map(|s| (s.frames, s.seen)), Some((5, 5)));
        // The band's texture: a ray in four on the circle by chance.
        let texture = ball_in_front_of::<()>(&line, &fixes, &search, |_, _| Ok(Some(about(20, 5)))).unwrap();
        assert_eq!(texture, None);
        // Two frames of five seeing it are not most.
        let mut k = 0;
        let some = ball_in_front_of::<()>(&line, &fixes, &search, |_, _| {
            k += 1;
            Ok(Some(if k <= 2 { about(20, 17) } else { about(20, 4) }))
        })
        .unwrap();
        assert_eq!(some, None);
        // Too few rays below the line tell nothing.
        let few = ball_in_front_of::<()>(&line, &fixes, &search, |_, _| Ok(Some(about(4, 4)))).unwrap();
        assert_eq!(few, None);
    }
}
