//! Frames whose centre lies off the path the frames around them give, further than the ball can stray.
//!
//! Two bounds say how far the ball's centre can stray from the line through two measured frames, at times
//! τ₁ and τ₂ from them: `A·τ₁·τ₂/2` for a path whose acceleration never exceeds `A` (the ball's largest, in
//! flight and contact alike), and `V·τ₁·τ₂/(τ₁ + τ₂)` between them (`V·min(τ₁, τ₂)` beyond them) for a path
//! whose velocity changes by at most `V` in all (a bounce that turns the ball in one frame). The first needs
//! the clip's frame rate and scale; the second only the track's own speed, so a wrong frame rate (a default
//! taken for a camera that ran slower) never makes a sharp bounce look impossible: the larger of the two is
//! allowed. A fix further off than that, and than the track's own scatter allows, is a circle that is not the
//! ball (a clump of clay grains, a noise ring, the band's edge) however well it fits its edge points. Each
//! frame is judged against the lines through pairs of its nearest measured neighbours, one on each side (and
//! near the track's ends two on the one side: the same bounds hold on the line extended), by the lower median
//! over those pairs, so one wrong neighbour does not condemn a right frame; the frame furthest off is removed
//! first and the rest judged again without it. Cost: O(n · k) per removal for n fixes, k ≤ 9 pairs each.

use crate::plane::median;
use crate::tracker::BallFix;

/// How many measured neighbours on each side give the lines a frame is judged against.
const NEIGHBOURS: usize = 3;

/// How many standard deviations of the track's scatter a fix may lie off a chord beyond the ball's reach.
const SCATTER_SIGMAS: f64 = 5.0;

/// The ball's whole change of velocity, in units of its fast speed in the track (the 90th percentile of its
/// speeds between measured frames): in and out of a bounce at most twice it, with room for a spin that
/// sends it out faster along the surface than it came.
const VELOCITY_CHANGE_SPEEDS: f64 = 3.0;

/// The percentile of the track's speeds taken as its fast speed ([`VELOCITY_CHANGE_SPEEDS`]).
const FAST_SPEED_PERCENTILE: f64 = 0.9;

/// A measured fix the ball cannot have been at: `index` into the track, `off_px` from the line through a
/// pair of its neighbours, where the ball and the scatter allow `allowed_px` (the pair of lower median ratio).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct OffPath {
    pub index: usize,
    pub off_px: f64,
    pub allowed_px: f64,
}

/// The measured fixes of `fixes` (in time order) that lie off the path their neighbours give: further from
/// the lines through pairs of them than the ball can stray (a path of acceleration at most `max_accel_px_s2`,
/// or of a whole change of velocity at most [`VELOCITY_CHANGE_SPEEDS`] of its fast speed, whichever strays
/// further), plus [`SCATTER_SIGMAS`] of the centre's scatter (the larger of the fixes' own σ and the track's scatter about
/// the chord through each fix's two nearest neighbours, robustly from the median, so a track whose σ
/// understates its noise is judged by the noise it shows). Worst first.
pub(crate) fn off_path(fixes: &[BallFix], max_accel_px_s2: f64) -> Vec<OffPath> {
    let mut live: Vec<usize> = (0..fixes.len())
        .filter(|&i| fixes[i].status.measured() && fixes[i].x_px.is_finite() && fixes[i].y_px.is_finite())
        .collect();
    let scatter = scatter_px(fixes, &live);
    let reach = Reach {
        accel_px_s2: max_accel_px_s2,
        velocity_change_px_s: VELOCITY_CHANGE_SPEEDS * fast_speed_px_s(fixes, &live),
    };
    let mut found = Vec::new();
    // Never more than a third of the track: past that, the neighbours are no better than the frame judged.
    while found.len() < live.len() / 2 {
        let worst = (0..live.len())
            .filter_map(|p| judged(fixes, &live, p, reach, scatter).map(|j| (p, j)))
            .max_by(|a, b| (a.1.0 / a.1.1).total_cmp(&(b.1.0 / b.1.1)));
        let Some((p, (off_px, allowed_px))) = worst else { break };
        if off_px <= allowed_px {
            break;
        }
        found.push(OffPath {
            index: live[p],
            off_px,
            allowed_px,
        });
        live.remove(p);
    }
    found
}

/// How far the fix at `live[p]` lies from the lines through pairs of its nearest live neighbours (up to
/// [`NEIGHBOURS`] each side: one on each side, and two on one side, the line extended to it, when the other
/// side has fewer than two, so that a wrong last frame does not condemn the one before it), and how far it
/// may, px: the pair with the lower median ratio of the two (pairs sharing a time skipped). `None` without
/// such a pair.
fn judged(fixes: &[BallFix], live: &[usize], p: usize, reach: Reach, scatter: f64) -> Option<(f64, f64)> {
    let before = &live[p.saturating_sub(NEIGHBOURS)..p];
    let after = &live[(p + 1).min(live.len())..(p + 1 + NEIGHBOURS).min(live.len())];
    let within = |side: &[usize]| -> Vec<(usize, usize)> {
        (0..side.len())
            .flat_map(|m| (m + 1..side.len()).map(move |n| (side[m], side[n])))
            .collect()
    };
    let mut pairs_of: Vec<(usize, usize)> = before
        .iter()
        .flat_map(|&i| after.iter().map(move |&j| (i, j)))
        .collect();
    if after.len() < 2 {
        pairs_of.extend(within(before));
    }
    if before.len() < 2 {
        pairs_of.extend(within(after));
    }
    let k = &fixes[live[p]];
    let mut pairs: Vec<(f64, f64)> = Vec::with_capacity(pairs_of.len());
    for (i, j) in pairs_of {
        let (a, b) = (&fixes[i], &fixes[j]);
        let Some(line) = from_line(a, k, b) else { continue };
        let reach = reach.at(
            (k.t_s - a.t_s).abs(),
            (k.t_s - b.t_s).abs(),
            line.wa >= 0.0 && line.wb >= 0.0,
        );
        let sigma = scatter.max(a.sigma_px).max(b.sigma_px).max(k.sigma_px);
        pairs.push((line.off_px, reach + SCATTER_SIGMAS * sigma * line.noise_gain()));
    }
    if pairs.is_empty() {
        return None;
    }
    // The lower median: with as many pairs through a wrong neighbour as not, the frame is given the benefit.
    let mid = (pairs.len() - 1) / 2;
    let (_, &mut m, _) = pairs.select_nth_unstable_by(mid, |x, y| (x.0 / x.1).total_cmp(&(y.0 / y.1)));
    Some(m)
}

/// How far the ball can stray from the line through two fixes ([`off_path`]'s two bounds).
#[derive(Debug, Clone, Copy)]
struct Reach {
    accel_px_s2: f64,
    velocity_change_px_s: f64,
}

impl Reach {
    /// At times `ta` and `tb` (s) from the two fixes, `between` them or beyond them, px.
    fn at(self, ta: f64, tb: f64, between: bool) -> f64 {
        let by_accel = 0.5 * self.accel_px_s2 * ta * tb;
        // Beyond the two, a turn anywhere moves the point at most V times its time from the nearer one.
        let by_turn = if !between {
            self.velocity_change_px_s * ta.min(tb)
        } else if ta + tb > 0.0 {
            self.velocity_change_px_s * ta * tb / (ta + tb)
        } else {
            0.0
        };
        by_accel.max(by_turn)
    }
}

/// The track's fast speed, px/s: the [`FAST_SPEED_PERCENTILE`] of its speeds between consecutive live fixes
/// (0 with none).
fn fast_speed_px_s(fixes: &[BallFix], live: &[usize]) -> f64 {
    let mut v: Vec<f64> = live
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (&fixes[w[0]], &fixes[w[1]]);
            let dt = b.t_s - a.t_s;
            (dt > 0.0).then(|| (b.x_px - a.x_px).hypot(b.y_px - a.y_px) / dt)
        })
        .collect();
    if v.is_empty() {
        return 0.0;
    }
    let at = ((v.len() - 1) as f64 * FAST_SPEED_PERCENTILE).round() as usize;
    *v.select_nth_unstable_by(at, f64::total_cmp).1
}

/// Where a fix lies from the line through two others at its time ([`from_line`]).
#[derive(Debug, Clone, Copy)]
struct FromLine {
    /// Its distance from the line's point, px.
    off_px: f64,
    /// The weights of the two fixes in that point (interpolated between them, extended beyond).
    wa: f64,
    wb: f64,
}

impl FromLine {
    /// How much the distance's noise exceeds one centre's: √(1 + wa² + wb²).
    fn noise_gain(self) -> f64 {
        (1.0 + self.wa * self.wa + self.wb * self.wb).sqrt()
    }
}

/// Where `k` lies from the line through `a` and `b` at its time; `None` when `a` and `b` share a time.
fn from_line(a: &BallFix, k: &BallFix, b: &BallFix) -> Option<FromLine> {
    let span = b.t_s - a.t_s;
    if span == 0.0 {
        return None;
    }
    let wb = (k.t_s - a.t_s) / span;
    let wa = 1.0 - wb;
    Some(FromLine {
        off_px: (k.x_px - wa * a.x_px - wb * b.x_px).hypot(k.y_px - wa * a.y_px - wb * b.y_px),
        wa,
        wb,
    })
}

/// The track's scatter per centre coordinate, px: from the distances of each live fix from the chord
/// through its two live neighbours, robustly (their median is 1.1774 σ for a 2-D Gaussian, the chord adding
/// its own share); 0 with fewer than 3 fixes.
fn scatter_px(fixes: &[BallFix], live: &[usize]) -> f64 {
    let mut d: Vec<f64> = live
        .windows(3)
        .filter_map(|w| {
            let line = from_line(&fixes[w[0]], &fixes[w[1]], &fixes[w[2]])?;
            Some(line.off_px / line.noise_gain())
        })
        .collect();
    median(&mut d) / 1.1774
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tracker::Status;
    use bouncelab_testkit::Rng;
    use proptest::prelude::*;

    const DT: f64 = 1e-4;

    /// A ball falling and bouncing off a floor at y = 300 px: gravity of 2.5e4 px/s² in flight, a spring's
    /// push of up to 1.8e6 px/s² in the 8 ms of contact (frames 120–200), centres with Gaussian noise of
    /// `noise` px.
    fn bouncing(n: usize, noise: f64, seed: u64) -> Vec<BallFix> {
        let mut rng = Rng::new(seed);
        let (mut x, mut y, vx, mut vy) = (100.0, 250.0, 3000.0, 4000.0);
        let k = (std::f64::consts::PI / 8e-3).powi(2);
        let mut fixes = Vec::new();
        for f in 0..n {
            for _ in 0..100 {
                let a = 2.5e4 - k * (y - 300.0f64).max(0.0);
                vy += a * DT / 100.0;
                y += vy * DT / 100.0;
                x += vx * DT / 100.0;
            }
            fixes.push(fix_at(f, x + noise * rng.normal(), y + noise * rng.normal(), noise));
        }
        fixes
    }

    /// A measured fix of frame `f` (at f·[`DT`]) centred at (x, y) px, its σ `sigma` px.
    fn fix_at(f: usize, x: f64, y: f64, sigma: f64) -> BallFix {
        BallFix {
            frame: f,
            t_s: f as f64 * DT,
            x_px: x,
            y_px: y,
            r_px: 40.0,
            sigma_px: sigma,
            sigma_r_px: sigma,
            quality: 0.8,
            status: Status::Ok,
        }
    }

    /// The ball's largest acceleration in [`bouncing`], px/s², with room: what a caller passes.
    const ACCEL: f64 = 3.0e6;

    #[test]
    fn a_frame_on_something_else_is_off_the_path() {
        let mut fixes = bouncing(200, 0.05, 1);
        fixes[120].x_px -= 11.0;
        fixes[120].y_px += 38.8;
        let off = off_path(&fixes, ACCEL);
        assert_eq!(off.len(), 1, "{off:?}");
        assert_eq!(off[0].index, 120);
        assert!((off[0].off_px - 40.3).abs() < 0.5, "{off:?}");
    }

    #[test]
    fn frames_off_together_are_each_off_the_path() {
        let mut fixes = bouncing(200, 0.05, 2);
        // The ball moves 0.3–0.5 px a frame here, so once its neighbours are gone a frame 2 px off could be a
        // turn within the 5 frames around it: each of these is further off than any turn takes it.
        for (i, dx) in [(95, -2.9), (96, -4.8), (97, 3.5), (98, 4.0)] {
            fixes[i].x_px += dx;
        }
        let mut off: Vec<usize> = off_path(&fixes, ACCEL).iter().map(|o| o.index).collect();
        off.sort_unstable();
        assert_eq!(off, vec![95, 96, 97, 98]);
    }

    #[test]
    fn unmeasured_frames_are_passed_over_and_the_last_frame_judged_from_before() {
        let mut fixes = bouncing(60, 0.05, 3);
        for f in &mut fixes[20..30] {
            *f = BallFix::absent(f.frame, f.t_s, Status::Absent);
        }
        assert!(off_path(&fixes, ACCEL).is_empty());
        fixes[59].x_px += 30.0;
        let off = off_path(&fixes, ACCEL);
        assert_eq!(off.len(), 1, "{off:?}");
        assert_eq!(
            off[0].index, 59,
            "the last frame is judged by the line through the frames before it"
        );
    }

    #[test]
    fn an_understated_sigma_does_not_condemn_noisy_frames() {
        let mut fixes = bouncing(300, 0.6, 4);
        for f in &mut fixes {
            f.sigma_px = 0.05;
        }
        assert!(off_path(&fixes, ACCEL).is_empty());
    }

    /// A bounce that turns the ball within a frame, judged with an acceleration bound far too small (a
    /// frame rate taken 5× too high): the track's own speed bounds the turn, and no frame is off the path.
    #[test]
    fn a_sharp_bounce_is_on_the_path_whatever_the_frame_rate() {
        let mut rng = Rng::new(5);
        let fixes: Vec<BallFix> = (0..120)
            .map(|f| {
                let t = f as f64 - 60.3;
                let (x, y) = (100.0 + 1.7 * f as f64, 300.0 - 2.6 * t.abs());
                fix_at(f, x + 0.05 * rng.normal(), y + 0.05 * rng.normal(), 0.05)
            })
            .collect();
        assert!(off_path(&fixes, ACCEL / 25.0).is_empty());
        let mut moved = fixes.clone();
        moved[60].y_px += 6.0;
        let off = off_path(&moved, ACCEL / 25.0);
        assert_eq!(off.iter().map(|o| o.index).collect::<Vec<_>>(), vec![60], "{off:?}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(32))]
        #[test]
        fn a_ball_s_own_path_is_never_off_it(noise in 0.01f64..1.0, seed in 0u64..1000) {
            let fixes = bouncing(250, noise, seed);
            let off = off_path(&fixes, ACCEL);
            prop_assert!(off.is_empty(), "{:?}", off);
        }
    }
}
