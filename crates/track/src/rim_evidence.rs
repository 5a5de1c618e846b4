//! Whether a fitted circle's rim stands out of the image's noise: the test that tells a ball from a circle
//! the fit made of noise.
//!
//! Each ray of a refinement takes the strongest step within its window, so in pure noise the edge points
//! scatter about the circle the search started from and the fit returns that circle with a fair quality:
//! a track that lost the ball can follow such a circle for hundreds of frames. A real rim changes the
//! brightness across it: along each ray the mean of the image just outside the circle (0.5–2.5 px) minus
//! the mean just inside differs from zero by far more than the noise. That difference is averaged over the
//! rays of each of [`SECTORS`] sectors and compared with its standard error, from the rays' scatter about
//! their sector's mean pooled over the rim (a robust scale: a seam or a hot spot in one sector does not
//! hide the others). Neighbouring rays are kept 2 px apart so that their steps are independent: a small
//! circle has fewer rays and sectors. A lit ball whose limb matches its backdrop on one side still stands
//! out on the others; a circle in noise stands out in a sector with probability 0.27 % (|z| > 3), so in
//! three of sixteen about once in 10⁵ frames. Rays hidden by the surface or leaving the image are not
//! sampled.

use crate::plane::{Pixel, Plane, median};
use crate::surface::SurfaceLine;

/// Sectors the rim is divided into.
pub const SECTORS: usize = 16;
/// Standardized step over which a sector stands out.
const SECTOR_SIGMAS: f64 = 3.0;
/// The most a sector adds to [`rim_strength`], in standard errors.
const STRENGTH_CAP: f64 = 5.0;
/// Sectors that must stand out for a circle to be a rim ([`RimEvidence::stands_out`]).
pub const MIN_SECTORS_STANDING_OUT: usize = 3;
/// Fewest sampled rays that make a sector.
const MIN_RAYS_PER_SECTOR: usize = 4;
/// The band either side of the circle whose means are compared, px (inner and outer distance).
const BAND_PX: (f64, f64) = (0.5, 2.5);
/// Least distance between neighbouring rays at the band's inner end, px: bilinear samples 2 px apart share
/// no pixel, so the rays' steps are independent.
const MIN_RAY_GAP_PX: f64 = 2.0;
/// Sampling step across the band, px.
const STEP_PX: f64 = 0.5;

/// How a circle's rim stands out of the noise (see the module's description).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RimEvidence {
    /// Sectors with enough visible rays to be judged.
    pub sectors: usize,
    /// Of those, sectors whose step across the circle exceeds 3 standard errors.
    pub standing_out: usize,
    /// The circle is too small to be judged: its rim holds fewer than [`MIN_SECTORS_STANDING_OUT`] sectors
    /// of 4 rays 2 px apart (a radius under about 4.5 px).
    pub too_small: bool,
}

impl RimEvidence {
    /// Whether at least [`MIN_SECTORS_STANDING_OUT`] sectors stand out, or the circle is too small to tell
    /// (then nothing refutes it).
    pub fn stands_out(&self) -> bool {
        self.too_small || self.standing_out >= MIN_SECTORS_STANDING_OUT
    }
}

/// The [`RimEvidence`] of the circle (`x`, `y`, `r`) in px on `img`, over `rays` rays (128 in the
/// tracker; fewer on a circle whose rim has no room for them 2 px apart, and fewer sectors then, 4 rays
/// each at least). Rays whose rim point lies within `surface_margin` px above `surface` (or below it) are not
/// sampled, nor rays whose band leaves the image. Cost: rays × 10 bilinear reads (1,280 on the default 128
/// rays; 14.2 µs on the track bench's frame).
pub fn rim_evidence<P: Pixel>(
    img: &Plane<P>,
    circle: (f64, f64, f64),
    rays: usize,
    surface: Option<&SurfaceLine>,
    surface_margin: f64,
) -> RimEvidence {
    match rim_steps(img, circle, rays, surface, surface_margin) {
        Some(steps) => judge(&steps).0,
        None => RimEvidence {
            sectors: 0,
            standing_out: 0,
            too_small: true,
        },
    }
}

/// How strongly the circle (`x`, `y`, `r`) in px lies on a rim in `img`: the mean over the judged sectors of
/// the size of the standardized step across it (see [`rim_evidence`]), each capped at [`STRENGTH_CAP`]
/// (5); about 0.8 on a circle of noise, up to 5 on a ball's rim; 0 when the circle is too small or no sector
/// can be judged. A score that grows as a circle moves onto a rim, whatever the rim's polarity in each
/// sector, for searching where a rim is: the best circle on a grid is the one whose every sector crosses the
/// rim, while one a few px off crosses it in two sectors only, and a seam's arcs inside the ball in a few;
/// the cap keeps those few, or another object's rim crossed in two sectors, from outscoring it. Cost as
/// [`rim_evidence`].
pub fn rim_strength<P: Pixel>(
    img: &Plane<P>,
    circle: (f64, f64, f64),
    rays: usize,
    surface: Option<&SurfaceLine>,
    surface_margin: f64,
) -> f64 {
    rim_steps(img, circle, rays, surface, surface_margin).map_or(0.0, |steps| judge(&steps).1)
}

/// Grid step of [`strongest_rim`]'s coarse search, px: every point of a grid cell lies within 1.5 px of a
/// node, inside the 0.5–2.5 px band either side of a circle that each ray's step is taken over, so a rim
/// under the cell steps across the band on every ray of its nearest node.
const COARSE_STEP_PX: f64 = 2.0;
/// Grid step of the fine search about the coarse search's best node, px.
const FINE_STEP_PX: f64 = 0.5;
/// The radii, as fractions of the size looked for, a rim found by [`strongest_rim`] must outshine about its
/// centre when they differ from it by more than [`OTHER_SIZE_PX`].
const OTHER_SIZES: (f64, f64) = (0.7, 1.4);
/// How far a radius must lie from the rim's to be another size, px.
const OTHER_SIZE_PX: f64 = 2.0;

/// The circle of radius about `r` whose rim is strongest ([`rim_strength`]) among those centred within
/// `reach` px of `(x, y)`: a search over a 2 px grid at radius `r`, then a 0.5 px grid within 2 px of its best
/// node at radii `r` ± 1 px. Returns `(x, y, r, strength)`; `None` when no circle there can be judged, or
/// when a circle about the best centre of a radius more than 2 px off it (0.7 `r` to 1.4 `r`) is stronger
/// still: the strongest circle of this size is then an inner circle of a shaded disc, or lies outside a
/// dark limb, not a rim of this size.
///
/// For finding a ball whose position is known only roughly (a track that lost it, a sighting a few px
/// off): in heavy noise a refinement started more than its window's half-width off the rim takes the
/// noise's steps for edges and stays where it started, while this score, pooled over the whole rim, peaks
/// on it. Whether the circle found is the ball is the caller's to judge. Cost: `π reach² / 4 + 243 + 1.4 r`
/// evaluations of [`rim_strength`] (≈ 14 µs each at 128 rays); 13–15 ms measured for a 64 px ball within
/// 32 px before the scan of other radii was added.
pub fn strongest_rim<P: Pixel>(
    img: &Plane<P>,
    (x, y): (f64, f64),
    r: f64,
    reach: f64,
    rays: usize,
    surface: Option<&SurfaceLine>,
    surface_margin: f64,
) -> Option<(f64, f64, f64, f64)> {
    let strongest = |circles: &mut dyn Iterator<Item = (f64, f64, f64)>| {
        circles
            .map(|(cx, cy, cr)| {
                (
                    cx,
                    cy,
                    cr,
                    rim_strength(img, (cx, cy, cr), rays, surface, surface_margin),
                )
            })
            .filter(|c| c.3 > 0.0)
            .max_by(|a, b| a.3.total_cmp(&b.3))
    };
    let grid = |half: f64, step: f64| {
        let n = (half / step).floor() as i64;
        (-n..=n).flat_map(move |i| (-n..=n).map(move |j| (i as f64 * step, j as f64 * step)))
    };
    let coarse = grid(reach, COARSE_STEP_PX).filter(|(dx, dy)| dx.hypot(*dy) <= reach);
    let (bx, by, _, _) = strongest(&mut coarse.map(|(dx, dy)| (x + dx, y + dy, r)))?;
    let fine =
        grid(COARSE_STEP_PX, FINE_STEP_PX).flat_map(|(dx, dy)| [-1.0, 0.0, 1.0].map(|dr| (bx + dx, by + dy, r + dr)));
    let best = strongest(&mut fine.into_iter())?;
    // A circle inside a shaded disc or outside a dark limb steps across the disc's shading: the strongest
    // circle of this size is the rim only if no circle about its centre of another size is stronger.
    let (lo, hi) = (
        (OTHER_SIZES.0 * r / FINE_STEP_PX) as i64,
        (OTHER_SIZES.1 * r / FINE_STEP_PX) as i64,
    );
    let mut sizes = (lo..=hi).map(|i| (best.0, best.1, i as f64 * FINE_STEP_PX));
    let other = strongest(&mut sizes).filter(|o| (o.2 - best.2).abs() > OTHER_SIZE_PX);
    match other {
        Some(o) if o.3 > best.3 => None,
        _ => Some(best),
    }
}

/// Each sampled ray's step across the circle, with its sector: `(sector, step)`; `None` when the circle is
/// too small to be judged (see [`RimEvidence::too_small`]).
fn rim_steps<P: Pixel>(
    img: &Plane<P>,
    (x, y, r): (f64, f64, f64),
    rays: usize,
    surface: Option<&SurfaceLine>,
    surface_margin: f64,
) -> Option<Vec<(usize, f64)>> {
    let (near, far) = BAND_PX;
    // Rays far enough apart that their samples share no pixel, so that their scatter tells a sector
    // mean's error.
    let room = (std::f64::consts::TAU * (r - far).max(0.0) / MIN_RAY_GAP_PX).floor() as usize;
    let rays = rays.min(room);
    let sectors = SECTORS.min(rays / MIN_RAYS_PER_SECTOR);
    if sectors < MIN_SECTORS_STANDING_OUT {
        return None;
    }
    let (wmax, hmax) = ((img.width - 1) as f64, (img.height - 1) as f64);
    let inside = |px: f64, py: f64| px >= 0.0 && py >= 0.0 && px < wmax && py < hmax;
    let samples = ((far - near) / STEP_PX).round() as usize + 1;
    // (sector, step) per sampled ray.
    let mut steps: Vec<(usize, f64)> = Vec::with_capacity(rays);
    for i in 0..rays {
        let (s, c) = (std::f64::consts::TAU * i as f64 / rays as f64).sin_cos();
        let (ox, oy) = (x + (r + far) * c, y + (r + far) * s);
        let (ix, iy) = (x + (r - far).max(0.0) * c, y + (r - far).max(0.0) * s);
        if !inside(ox, oy) || !inside(ix, iy) {
            continue;
        }
        if let Some(line) = surface {
            let margin = surface_margin + line.ragged_reach_px();
            if oy > line.y_at(ox) - margin {
                continue;
            }
        }
        // The band's samples from `near` to `far` outside the circle (sign +1) or inside it (−1), summed.
        let (dx, dy) = ((STEP_PX * c) as f32, (STEP_PX * s) as f32);
        let sum = |sign: f32| {
            let (mut px, mut py) = (
                (x + (r + sign as f64 * near) * c) as f32,
                (y + (r + sign as f64 * near) * s) as f32,
            );
            let mut total = 0.0f32;
            for _ in 0..samples {
                total += img.sample_inside(px, py);
                px += sign * dx;
                py += sign * dy;
            }
            total
        };
        steps.push((i * sectors / rays, ((sum(1.0) - sum(-1.0)) / samples as f32) as f64));
    }
    Some(steps)
}

/// The evidence from per-ray steps `(sector, step)`, and the mean squared standardized step of the judged
/// sectors ([`rim_strength`]).
fn judge(steps: &[(usize, f64)]) -> (RimEvidence, f64) {
    let mut sum = [0.0f64; SECTORS];
    let mut count = [0usize; SECTORS];
    for &(k, v) in steps {
        sum[k] += v;
        count[k] += 1;
    }
    let judged: Vec<usize> = (0..SECTORS).filter(|&k| count[k] >= MIN_RAYS_PER_SECTOR).collect();
    let used: usize = judged.iter().map(|&k| count[k]).sum();
    let mean = |k: usize| sum[k] / count[k] as f64;
    let mut residuals: Vec<f64> = steps
        .iter()
        .filter(|(k, _)| count[*k] >= MIN_RAYS_PER_SECTOR)
        .map(|&(k, v)| (v - mean(k)).abs())
        .collect();
    if residuals.is_empty() {
        let none = RimEvidence {
            sectors: 0,
            standing_out: 0,
            too_small: false,
        };
        return (none, 0.0);
    }
    // The rays' scatter about their sector's mean, as a normal σ from the median absolute residual, with
    // the degrees of freedom the sectors' means took.
    let dof = used.saturating_sub(judged.len()).max(1);
    let sigma = 1.4826 * median(&mut residuals) * (used as f64 / dof as f64).sqrt();
    // A flat, noise-free image has no scatter: only a nonzero step stands out there.
    let z = |k: usize| {
        let (se, m) = (sigma / (count[k] as f64).sqrt(), mean(k));
        if se > 0.0 {
            m / se
        } else if m != 0.0 {
            f64::INFINITY
        } else {
            0.0
        }
    };
    let standing_out = judged.iter().filter(|&&k| z(k).abs() > SECTOR_SIGMAS).count();
    let strength = judged.iter().map(|&k| z(k).abs().min(STRENGTH_CAP)).sum::<f64>() / judged.len() as f64;
    let evidence = RimEvidence {
        sectors: judged.len(),
        standing_out,
        too_small: false,
    };
    (evidence, strength)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{Scene, render};

    #[test]
    fn the_strongest_rim_near_a_guess_is_the_ball_s() {
        // A faint ball with a dark seam's lobe on it in 14 DN of noise, looked for from 20 px off: found well
        // within a refinement's 4 px window of its centre (≤ 1.8 px off over these 20 frames), for the
        // refinement to measure it.
        for seed in 0..20u64 {
            let ball = (128.3 + seed as f64 * 0.37, 120.6 - seed as f64 * 0.21, 45.0);
            let px = render(&Scene {
                ball,
                ball_level: 130.0,
                backdrop: (100.0, 100.0),
                marks: vec![(-30.0, 10.0, 28.0, 60.0)],
                noise: 14.0,
                seed,
                ..Scene::default()
            });
            let plane = Plane::new(&px, 256, 256);
            let guess = (ball.0 + 16.0, ball.1 - 12.0);
            let (x, y, r, strength) = strongest_rim(&plane, guess, 45.0, 30.0, 128, None, 2.0).unwrap();
            let off = (x - ball.0).hypot(y - ball.1);
            assert!(
                off < 2.5 && (r - 45.0).abs() <= 1.0,
                "{seed}: {x} {y} {r}, {off} px off"
            );
            let noise = rim_strength(&plane, (60.0, 200.0, 45.0), 128, None, 2.0);
            assert!(strength > 2.0 * noise, "{seed}: {strength} against noise's {noise}");
        }
    }

    #[test]
    fn a_ball_stands_out_and_a_circle_in_noise_does_not() {
        // 200 frames at 2–14 DN: a ball of radius 50 and one of 12; noise circles of radius 30 and 12.
        let mut passed_noise = 0;
        let mut balls_missed = 0;
        for seed in 0..200u64 {
            let noise = 2.0 + (seed % 5) as f64 * 3.0;
            let draw = |size: usize, ball: (f64, f64, f64), ball_level: f64| {
                render(&Scene {
                    size: (size, size),
                    ball,
                    ball_level,
                    backdrop: (100.0, 100.0),
                    noise,
                    seed,
                    ..Scene::default()
                })
            };
            let ball = draw(256, (128.3, 120.6, 50.0), 120.0);
            let plane = Plane::new(&ball, 256, 256);
            if !rim_evidence(&plane, (128.3, 120.6, 50.0), 128, None, 2.0).stands_out() {
                balls_missed += 1;
            }
            // The same frame, circles clear of the ball: noise, no rim under them (a small one's rays lie
            // close together).
            for c in [(50.0, 210.0, 30.0), (215.0, 225.0, 12.0)] {
                if rim_evidence(&plane, c, 128, None, 2.0).stands_out() {
                    passed_noise += 1;
                }
            }
            // A small ball stands out too.
            let small = draw(64, (31.6, 32.2, 12.0), 160.0);
            if !rim_evidence(&Plane::new(&small, 64, 64), (31.6, 32.2, 12.0), 128, None, 2.0).stands_out() {
                balls_missed += 1;
            }
        }
        assert_eq!(balls_missed, 0);
        assert!(passed_noise <= 1, "{passed_noise} of 400 noise circles stood out");
    }
}
