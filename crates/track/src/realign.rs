//! Every frame's circle measured again against its neighbours' mean rim: where a ray's steepest step is
//! ambiguous (a shaded limb rising slowly to a faint silhouette, a seam running just inside it), the whole
//! profile across the rim still says where the rim is.
//!
//! The edge search takes one step per ray, and on a limb of about the backdrop's gray, or with a seam's
//! band inside it, that step can jump between two places from one frame to the next (up to 2 px), and the
//! circle with it. The mean profile of each ray over the neighbouring frames (the template: up to
//! [`HALF_WINDOW`] frames either side, each profile taken along that frame's own fitted circle, the frame
//! itself left out) holds the rim's shape as it is at that time: the light does not turn with the ball,
//! and a seam turning with it moves little over the window, where over a whole clip it would not average
//! out and would bias one flight against the other. Each ray's profile in the frame is slid along the ray
//! onto the template (least squares with a free offset, over the last 6 px inside the circle and 3.5 px
//! outside, in 0.25 px steps, with a parabola through the best three), and the slides
//! `δ(θ) ≈ dr + dx·cos θ + dy·sin θ` move the circle: weighted by each ray's information (the template's
//! squared gradient over the slide's own misfit: a limb of about the backdrop's gray, or a ray crossed by
//! the seam, tells little), with Tukey's biweight against rays on something else (a fixture behind the
//! rim). The template's reference is the mean of the neighbours' fitted circles, so the circles keep their
//! common offset from the silhouette (which [`crate::LimbOffset`] corrects) and lose most of their jitter.
//! Cost: 128 × 73 bilinear samples and 128 × 21 × 39 differences a frame, with one more decoding of the
//! clip's frames (0.02 s over the 203 TIFF frames of the `looks` preset's S034, 0.28 s over 380 PNG frames:
//! `docs/performance.md`).

use crate::circle_fit::weighted_first_harmonic;
use crate::limb::{profile_offset_px, profile_samples, profile_step_px};
use crate::plane::{Pixel, Plane};
use crate::surface::SurfaceLine;
use std::collections::VecDeque;

/// Frames either side whose profiles make a frame's template (25: 5 ms at 5,000 frames/s, while a seam
/// turns by a fraction of a turn at a tennis ball's spin).
pub const HALF_WINDOW: usize = 25;
/// Fewest neighbours that must have seen a ray for its template to count.
const MIN_NEIGHBOURS: usize = 8;
/// The part of the profile compared with the template, px from the circle: the limb and the silhouette,
/// and a few px of backdrop beyond it (farther out, the backdrop behind a moving ball changes).
const WINDOW_PX: (f64, f64) = (-6.0, 3.5);
/// Largest slide tried either way, px: beyond it the edge search did not lose the rim, it found another.
const MAX_SLIDE_PX: f64 = 2.5;
/// Fewest rays that must see the whole profile (inside the image, clear of the surface band) for a frame
/// to be measured again.
const MIN_RAYS: usize = 16;
/// Tukey's biweight constant (95 % efficiency for normal scatter).
const BIWEIGHT_C: f64 = 4.685;

/// Samples beyond the template's on either side of a frame's profile, for the slides.
fn reach() -> usize {
    (MAX_SLIDE_PX / profile_step_px()).round() as usize
}

/// Samples of a frame's profile along one ray.
fn extended() -> usize {
    profile_samples() + 2 * reach()
}

/// The profiles of `img` across the circle (x, y, r) px along `rays` rays (ray i at angle 2πi/rays, y down),
/// each [`extended`] samples [`profile_step_px`] apart, from `reach` samples inside the limb learner's
/// first; a ray leaving the image or reaching the surface band (a point that does not clear it as a disc of
/// no radius would, [`SurfaceLine::clears_disc`]: the band's texture, and the ball pressed into it) is all
/// NaN. Cost: rays × 73 bilinear reads.
pub fn profiles_along<P: Pixel>(
    img: &Plane<P>,
    (x, y, r): (f64, f64, f64),
    rays: usize,
    surface: Option<&SurfaceLine>,
) -> Vec<f32> {
    let m = extended();
    let step = profile_step_px();
    let d0 = r + profile_offset_px() - reach() as f64 * step;
    let mut out = vec![f32::NAN; rays * m];
    for (i, ray) in out.chunks_mut(m).enumerate() {
        let (s, c) = (std::f64::consts::TAU * i as f64 / rays as f64).sin_cos();
        let seen = ray.iter_mut().enumerate().all(|(k, v)| {
            let d = d0 + k as f64 * step;
            let (px, py) = (x + c * d, y + s * d);
            surface.is_none_or(|l| l.clears_disc(px, py, 0.0))
                && img.sample(px as f32, py as f32).map(|g| *v = g).is_some()
        });
        if !seen {
            ray.fill(f32::NAN);
        }
    }
    out
}

/// A frame's circle measured against its neighbours: how far it moves from the circle its profiles were
/// taken along.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Realigned {
    /// Centre shift, (x, y) px.
    pub dx: f64,
    pub dy: f64,
    /// Radius change, px.
    pub dr: f64,
}

struct Entry {
    index: usize,
    profiles: Vec<f32>,
    teaches: bool,
}

/// The profiles of the frames within [`HALF_WINDOW`] of the one being measured, and the running sums of
/// those that teach the template. Frames are pushed in order; a frame is measured once every frame up to
/// [`HALF_WINDOW`] after it was pushed.
pub struct NeighbourRims {
    rays: usize,
    frames: VecDeque<Entry>,
    sum: Vec<f64>,
    count: Vec<u32>,
}

impl NeighbourRims {
    /// No frames yet, for profiles along `rays` rays.
    pub fn new(rays: usize) -> Self {
        NeighbourRims {
            rays,
            frames: VecDeque::new(),
            sum: vec![0.0; rays * profile_samples()],
            count: vec![0; rays],
        }
    }

    /// Adds frame `index`'s `profiles` ([`profiles_along`]); `teaches` when they enter the neighbours'
    /// templates (a ball measured `ok`, not one cut by the border or on another object).
    pub fn push(&mut self, index: usize, profiles: Vec<f32>, teaches: bool) {
        if teaches {
            self.add(&profiles, 1.0);
        }
        self.frames.push_back(Entry {
            index,
            profiles,
            teaches,
        });
    }

    /// Adds (`sign` 1) or takes away (−1) a teaching frame's rays from the sums.
    fn add(&mut self, profiles: &[f32], sign: f64) {
        let (n, m, r) = (profile_samples(), extended(), reach());
        for i in 0..self.rays {
            let ray = &profiles[i * m..(i + 1) * m];
            if ray[0].is_nan() {
                continue;
            }
            for (acc, v) in self.sum[i * n..(i + 1) * n].iter_mut().zip(&ray[r..r + n]) {
                *acc += sign * *v as f64;
            }
            self.count[i] = (self.count[i] as f64 + sign) as u32;
        }
    }

    /// Measures frame `index` against the mean of the teaching frames within [`HALF_WINDOW`] of it, itself
    /// left out, after dropping the frames before that window. `None` when the frame was not pushed, or too
    /// few rays have both its profile and a template ([`MIN_RAYS`], [`MIN_NEIGHBOURS`]), or the fit moves
    /// further than the slides tried.
    pub fn realign(&mut self, index: usize) -> Option<Realigned> {
        while self.frames.front().is_some_and(|e| e.index + HALF_WINDOW < index) {
            let e = self.frames.pop_front().expect("a front frame");
            if e.teaches {
                self.add(&e.profiles, -1.0);
            }
        }
        let own = self.frames.iter().find(|e| e.index == index)?;
        let (n, m) = (profile_samples(), extended());
        let (lo, hi) = window();
        let step = profile_step_px();
        let own_weight = if own.teaches { 1.0 } else { 0.0 };
        let mut slides = Vec::with_capacity(self.rays);
        let mut template = vec![0.0f64; n];
        for i in 0..self.rays {
            let p = &own.profiles[i * m..(i + 1) * m];
            if p[0].is_nan() {
                continue;
            }
            let others = self.count[i] as f64 - own_weight;
            if others < MIN_NEIGHBOURS as f64 {
                continue;
            }
            for (k, t) in template.iter_mut().enumerate() {
                *t = (self.sum[i * n + k] - own_weight * p[reach() + k] as f64) / others;
            }
            let info: f64 = (lo..hi)
                .map(|k| ((template[k + 1] - template[k - 1]) / (2.0 * step)).powi(2) * step)
                .sum();
            if let Some((delta, misfit)) = slide(p, &template)
                && info > 0.0
            {
                let (s, c) = (std::f64::consts::TAU * i as f64 / self.rays as f64).sin_cos();
                slides.push((c, s, delta, info, misfit));
            }
        }
        fit_slides(&weighed(slides))
    }
}

/// Each ray's slide `(cos θ, sin θ, δ, information, misfit)` with its weight, the information over the
/// misfit, which is floored at half the rays' median misfit so that a few rays fitting by chance do not
/// outweigh the rest (a noiseless profile fits exactly).
fn weighed(slides: Vec<(f64, f64, f64, f64, f64)>) -> Vec<(f64, f64, f64, f64)> {
    let mut misfits: Vec<f64> = slides.iter().map(|s| s.4).collect();
    let floor = if misfits.is_empty() {
        0.0
    } else {
        let mid = misfits.len() / 2;
        0.5 * *misfits.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    slides
        .into_iter()
        .map(|(c, s, d, info, misfit)| {
            let w = if floor > 0.0 { info / misfit.max(floor) } else { info };
            (c, s, d, w)
        })
        .collect()
}

/// The template's samples compared: indices into the limb learner's profile.
fn window() -> (usize, usize) {
    let at = |s: f64| ((s - profile_offset_px()) / profile_step_px()).round() as usize;
    (at(WINDOW_PX.0), at(WINDOW_PX.1) + 1)
}

/// How far (px, outward positive) the frame's profile `p` ([`extended`] samples) lies from the template
/// `m`: the shift in samples minimising the squared difference with a free offset over the window, refined
/// by a parabola through the best and its neighbours; and the misfit there, the residuals' variance per
/// sample (level²). `None` when the best lies at either end of the shifts tried.
fn slide(p: &[f32], m: &[f64]) -> Option<(f64, f64)> {
    let (lo, hi) = window();
    let len = (hi - lo) as f64;
    let sse = |j: usize| {
        let (mut sum, mut sum2) = (0.0, 0.0);
        for k in lo..hi {
            let d = p[k + j] as f64 - m[k];
            sum += d;
            sum2 += d * d;
        }
        sum2 - sum * sum / len
    };
    let errs: Vec<f64> = (0..=2 * reach()).map(sse).collect();
    let best = (0..errs.len()).min_by(|&a, &b| errs[a].total_cmp(&errs[b]))?;
    if best == 0 || best == errs.len() - 1 {
        return None;
    }
    let off = crate::plane::parabola_offset(-errs[best - 1], -errs[best], -errs[best + 1]);
    Some((
        (best as f64 + off - reach() as f64) * profile_step_px(),
        errs[best] / (len - 2.0),
    ))
}

/// The circle's shift from the rays' slides `(cos θ, sin θ, δ, weight)`: weighted least squares of
/// `δ ≈ dr + dx·cos θ + dy·sin θ` with Tukey's biweight on the weighted residuals (scale from their median
/// absolute value).
fn fit_slides(slides: &[(f64, f64, f64, f64)]) -> Option<Realigned> {
    if slides.len() < MIN_RAYS {
        return None;
    }
    let mut tukey = vec![1.0f64; slides.len()];
    let mut coef = [0.0f64; 3];
    let mut res = vec![0.0f64; slides.len()];
    for _ in 0..10 {
        coef = weighted_first_harmonic(slides.iter().zip(&tukey).map(|(&(c, s, d, w), t)| (c, s, d, w * t)))?;
        for (r, &(c, s, d, w)) in res.iter_mut().zip(slides) {
            *r = (d - coef[0] - coef[1] * c - coef[2] * s) * w.sqrt();
        }
        let mut abs: Vec<f64> = res.iter().map(|r| r.abs()).collect();
        let mid = abs.len() / 2;
        let scale = 1.4826 * *abs.select_nth_unstable_by(mid, f64::total_cmp).1;
        if scale <= 0.0 {
            break;
        }
        for (t, r) in tukey.iter_mut().zip(&res) {
            let u = r / (BIWEIGHT_C * scale);
            *t = if u.abs() < 1.0 { (1.0 - u * u).powi(2) } else { 0.0 };
        }
    }
    let kept = tukey.iter().filter(|t| **t > 0.0).count();
    if kept < MIN_RAYS || coef.iter().any(|c| c.abs() > MAX_SLIDE_PX) {
        return None;
    }
    Some(Realigned {
        dx: coef[1],
        dy: coef[2],
        dr: coef[0],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A disc of radius `r` at (cx, cy), `inside` on an `outside` backdrop, its limb darkening over the last
    /// `limb` px (a shaded ball), anti-aliased by area over a 4 × 4 grid, with `noise` DN of uniform noise
    /// from `seed`.
    fn disc(w: usize, (cx, cy, r): (f64, f64, f64), inside: f64, outside: f64, noise: (f64, u64)) -> Vec<f32> {
        let mut state = noise
            .1
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut img = vec![0.0f32; w * w];
        for (k, v) in img.iter_mut().enumerate() {
            let (px, py) = ((k % w) as f64, (k / w) as f64);
            let mut acc = 0.0;
            for a in 0..4 {
                for b in 0..4 {
                    let (sx, sy) = (px - 0.375 + 0.25 * a as f64, py - 0.375 + 0.25 * b as f64);
                    let d = (sx - cx).hypot(sy - cy);
                    acc += if d <= r {
                        let shade = ((r - d) / 4.0).min(1.0);
                        outside + (inside - outside) * (0.3 + 0.7 * shade)
                    } else {
                        outside
                    };
                }
            }
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            *v = (acc / 16.0 + noise.0 * u * 12f64.sqrt()) as f32;
        }
        img
    }

    /// The ball's true circle in frame k of a clip: falling to the right.
    fn truth(k: usize) -> (f64, f64, f64) {
        (30.3 + 0.37 * k as f64, 40.1 + 0.21 * k as f64, 22.0)
    }

    /// A frame, the circle its profiles were taken along, and what realigning it gave.
    type Measured = (usize, (f64, f64, f64), Option<Realigned>);

    /// Frames 0..n pushed with their true circles moved by `off(k)` (the edge search's errors), measured
    /// in order as their windows fill.
    fn run(n: usize, off: impl Fn(usize) -> (f64, f64, f64), noise: f64) -> Vec<Measured> {
        let w = 112;
        let mut rims = NeighbourRims::new(64);
        let mut out = Vec::new();
        let mut pending = Vec::new();
        for k in 0..n {
            let (t, o) = (truth(k), off(k));
            let c = (t.0 + o.0, t.1 + o.1, t.2 + o.2);
            let img = disc(w, t, 200.0, 60.0, (noise, k as u64));
            rims.push(k, profiles_along(&Plane::new(&img, w, w), c, 64, None), true);
            pending.push((k, c));
            while pending.first().is_some_and(|(j, _)| j + HALF_WINDOW <= k || k + 1 == n) {
                let (j, c) = pending.remove(0);
                out.push((j, c, rims.realign(j)));
            }
        }
        out
    }

    #[test]
    fn jumps_of_the_edge_search_are_taken_out() {
        // Every fifth frame's circle 0.8 px off to the left and 0.4 px small (one side's edge misread).
        let off = |k: usize| if k % 5 == 2 { (-0.8, 0.0, -0.4) } else { (0.0, 0.0, 0.0) };
        for (k, c, got) in run(40, off, 2.0) {
            let got = got.unwrap_or_else(|| panic!("frame {k} not realigned"));
            let t = truth(k);
            // The neighbours' mean circle is 0.16 px off on average: what is left is that mean's error.
            let (ex, ey) = (c.0 + got.dx - t.0, c.1 + got.dy - t.1);
            assert!(
                ex.hypot(ey) < 0.25,
                "frame {k}: off by ({ex:.3}, {ey:.3}) after {got:?}"
            );
        }
    }

    /// Ten noiseless frames 96 px wide of a still ball at `c` pushed as teachers, and the first of them.
    fn still_ball(c: (f64, f64, f64)) -> (NeighbourRims, Vec<f32>) {
        let w = 96;
        let img = disc(w, c, 200.0, 60.0, (0.0, 0));
        let mut rims = NeighbourRims::new(64);
        for k in 0..10 {
            rims.push(k, profiles_along(&Plane::new(&img, w, w), c, 64, None), true);
        }
        (rims, img)
    }

    #[test]
    fn an_arc_of_rays_on_something_else_does_not_move_the_circle() {
        let w = 96;
        let c = (48.0, 48.0, 30.0);
        let (mut rims, clean) = still_ball(c);
        // A dark band 2 px inside the rim along a fifth of it (a seam).
        let mut seam = clean;
        for (k, v) in seam.iter_mut().enumerate() {
            let (px, py) = ((k % w) as f64 - c.0, (k / w) as f64 - c.1);
            if py.atan2(px).abs() < 0.6 && (px.hypot(py) - (c.2 - 2.0)).abs() < 1.0 {
                *v *= 0.5;
            }
        }
        rims.push(10, profiles_along(&Plane::new(&seam, w, w), c, 64, None), false);
        let got = rims.realign(10).expect("realigned");
        assert!(got.dx.hypot(got.dy) < 0.05 && got.dr.abs() < 0.05, "{got:?}");
    }

    #[test]
    fn rays_reaching_the_band_are_left_out() {
        let w = 96;
        let c = (48.0, 40.0, 30.0);
        let img = disc(w, c, 200.0, 60.0, (0.0, 0));
        // The band's top 4 px above the ball's lowest point.
        let line = SurfaceLine::given(w as f64 / 2.0, c.1 + c.2 - 4.0, 0.0);
        let all = profiles_along(&Plane::new(&img, w, w), c, 64, None);
        let above = profiles_along(&Plane::new(&img, w, w), c, 64, Some(&line));
        let seen = |p: &[f32]| p.chunks(extended()).filter(|r| !r[0].is_nan()).count();
        assert_eq!(seen(&all), 64);
        assert!(seen(&above) < 56, "{}", seen(&above));
        // Rays pointing down (y grows) are the ones hidden.
        assert!(above[16 * extended()].is_nan() && !above[48 * extended()].is_nan());
    }

    #[test]
    fn a_frame_without_the_ball_is_not_realigned() {
        let w = 96;
        let c = (48.0, 48.0, 30.0);
        let (mut rims, _) = still_ball(c);
        let blank = vec![60.0f32; w * w];
        rims.push(10, profiles_along(&Plane::new(&blank, w, w), c, 64, None), false);
        assert!(rims.realign(10).is_none());
        assert!(rims.realign(99).is_none());
    }
}
