//! How far the ball's silhouette lies from the circles fitted to its rim: a lit ball's limb is shaded, and
//! where that shading meets a backdrop of about its own gray, the steepest change along a ray is the
//! shading's, inside the silhouette, so the fitted circles are small and off-centre by up to a pixel.
//!
//! Measured on the mean radial profile of the full-rim free-flight frames, before the bounce and after it
//! (clean or not), each taken along its own fitted circle's rays (the light does not turn with the ball;
//! the felt's texture, a seam turning with the ball and the backdrop passing behind the rim average out
//! over the flight): on each ray a limb `a + b·√(R − s) + e·(R − s)` inside the silhouette `R` and a
//! constant `c` outside (or `c + d·(s − R)` where that fits clearly better: a ruler's edge or a fixture
//! behind the rim), blurred by the pixel's width, the bilinear sampling along the ray and an optical
//! spread, is fitted by least squares over `R`, on the last 4 px inside the fitted rim and 5 px outside it.
//! The root is a Lambertian limb's darkening; with the linear term the model also follows a felt's sheen,
//! which brightens the last pixels of a shaded limb until they cross the backdrop's gray inside the
//! silhouette (a sheen (1 − n_z)³, with n_z ≈ √(2(R − s)/r), is 1 − 3·n_z + 3·n_z² − … there). The optical
//! spread is the one of nine (0–1.5 px) whose limbs fit all rays best: the silhouette found moves inwards
//! by 0.4–1 px per px of spread assumed, so the spread is measured, not assumed. The silhouette's mean `R`
//! and its first harmonic round the rim, each ray weighed by how closely its fit pins `R`, are how far the
//! fitted circles' radius and centre lie from it, and the track moves every circle by them. The centre is
//! fitted again on the last 3 px inside: a ball lit from high above has its shadowed side's terminator
//! 3–4 px inside the rim, whose step bends the deeper fit's rays there. Where the two centres disagree
//! beyond 3σ (χ² on their standard errors, from the rays' scatter about the harmonic with neighbouring
//! rays' correlation counted) the shallower is taken; else their mean, as each has its own model error
//! (the deeper the texture's bend, the shallower fewer samples). A limb model
//! is one account of the shading among others (a fuzzy felt, a seam), so their size stays the standard
//! uncertainty of that correction. Cost: 53 samples per ray per frame learned (51 µs for 128 rays), and
//! 66 ms once per clip for the two fits (the track bench's `limb_learn_frame` and `limb_offset`).

use crate::circle_fit::weighted_first_harmonic_with_inverse;
use crate::plane::{Pixel, Plane};
use crate::surface::SurfaceLine;

/// Sampling step along a ray, px.
const STEP_PX: f64 = 0.25;
/// Samples from the fitted rim inwards and outwards, px.
const INNER_PX: f64 = 8.0;
const OUTER_PX: f64 = 5.0;
/// The limb model is fitted from this far inside the fitted rim, px: deeper, the terminator and the felt's
/// texture bend the profile more than the model's three terms follow; shallower, the terms trade the
/// silhouette's radius against the limb's slope (`paper`'s radius 0.03 px large from 3 px).
const DEEP_FIT_FROM_PX: f64 = -4.0;
/// The centre is fitted from here too, px: a ball lit from high above has its shadowed side's terminator
/// 3–4 px inside the rim, which bends the deeper fit's rays there and moves its centre (0.5 px on one
/// `looks` clip).
const SHALLOW_FIT_FROM_PX: f64 = -3.0;
/// Silhouettes tried, px from the fitted rim: a ray whose best lies at either end is not a limb.
const R_FROM_PX: f64 = -3.0;
const R_TO_PX: f64 = 2.0;
const R_STEP_PX: f64 = 0.05;
/// The optical spreads tried beyond the pixel's width and the sampling's, px (Gaussian σ): the one whose
/// limbs fit the rays' profiles best is taken (a fixed 0.5 px put a sharp disc's silhouette 0.26 px inside
/// it).
const BLURS_PX: [f64; 9] = [0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 1.0, 1.5];
/// Beyond this χ² (2 degrees of freedom, the 0.27 % tail: 3σ) the deeper and the shallower fits' centres
/// disagree, and the deeper is taken as bent by a terminator.
const CENTRES_APART_CHI2: f64 = 11.8;
/// Rays either side of a third of the rim tried in the least-median harmonic (see [`robust_harmonic`]).
const LMS_JITTER: i64 = 3;
/// The rays' spread about the harmonic taken as at least this, px, so that a clean limb keeps its rays.
const MIN_SPREAD_PX: f64 = 0.15;
/// Added in quadrature to each ray's silhouette uncertainty when the rays are weighed, px: what the limb
/// model itself leaves unsaid (a felt's texture, the seam), so that no ray with a sharp fit outweighs the
/// rest.
const SILHOUETTE_FLOOR_PX: f64 = 0.1;
/// By how much a backdrop sloping across the rim must cut a ray's squared misfit before it is taken over a
/// constant one: an F test at 10 % with the ≈ 9 independent samples of the 37 fitted (four to a pixel,
/// blurred), `(gain − 1)·3 > 5.5`.
const SLOPE_GAIN: f64 = 3.0;
/// Fewest frames averaged before the offset is told.
const MIN_FRAMES: usize = 8;

fn samples() -> usize {
    ((INNER_PX + OUTER_PX) / STEP_PX).round() as usize + 1
}

fn sample_at(k: usize) -> f64 {
    -INNER_PX + k as f64 * STEP_PX
}

/// Samples of a profile across the rim as the learner takes it.
pub(crate) fn profile_samples() -> usize {
    samples()
}

/// Where such a profile's first sample lies from the circle it is taken along, px (inward negative).
pub(crate) fn profile_offset_px() -> f64 {
    sample_at(0)
}

/// The step between such a profile's samples, px.
pub(crate) fn profile_step_px() -> f64 {
    STEP_PX
}

/// The limb model's silhouette against the fitted circles (see the module's description).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimbOffset {
    /// The silhouettes' mean distance outside the fitted rim, px.
    pub radius_px: f64,
    /// Their first harmonic: where the silhouette's centre lies from the fitted centre, (x, y) px.
    pub centre_px: (f64, f64),
    /// Rays whose limb was fitted inside the tried range.
    pub rays: usize,
}

impl LimbOffset {
    /// How far every centre may lie off the silhouette's, px.
    pub fn centre_len_px(&self) -> f64 {
        self.centre_px.0.hypot(self.centre_px.1)
    }
}

/// Sums the radial profiles of full-rim flight frames along their fitted circles' rays.
#[derive(Debug, Clone, Default)]
pub struct LimbLearner {
    rays: usize,
    sum: Vec<f64>,
    count: Vec<u32>,
    frames: usize,
}

impl LimbLearner {
    /// Frames added so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Adds `img`'s profile along `rays` rays of the circle fitted to it, `(x, y, r)` px. A ray with a
    /// sample outside the image, or one reaching the surface band (a point that does not clear it as a
    /// disc of no radius would, [`SurfaceLine::clears_disc`]: a ball just above the band has the band's
    /// top in its lower rays' backdrop), is skipped in this frame.
    pub fn add<P: Pixel>(
        &mut self,
        img: &Plane<P>,
        (x, y, r): (f64, f64, f64),
        rays: usize,
        surface: Option<&SurfaceLine>,
    ) {
        let n = samples();
        if self.rays != rays {
            *self = LimbLearner {
                rays,
                sum: vec![0.0; rays * n],
                count: vec![0; rays],
                frames: 0,
            };
        }
        let mut profile = vec![0.0f64; n];
        for i in 0..rays {
            let (s, c) = (std::f64::consts::TAU * i as f64 / rays as f64).sin_cos();
            let inside = (0..n).all(|k| {
                let d = r + sample_at(k);
                let (px, py) = (x + c * d, y + s * d);
                if surface.is_some_and(|l| !l.clears_disc(px, py, 0.0)) {
                    return false;
                }
                match img.sample(px as f32, py as f32) {
                    Some(v) => {
                        profile[k] = v as f64;
                        true
                    }
                    None => false,
                }
            });
            if inside {
                self.count[i] += 1;
                for (acc, v) in self.sum[i * n..(i + 1) * n].iter_mut().zip(&profile) {
                    *acc += v;
                }
            }
        }
        self.frames += 1;
    }

    /// The silhouette's offset (see the module's description), or `None` with fewer than 8 frames or fewer
    /// than half the rays fitted inside the tried range.
    pub fn offset(&self) -> Option<LimbOffset> {
        if self.frames < MIN_FRAMES || self.rays < 8 {
            return None;
        }
        let harmonic = |fit_from_px: f64| {
            let edges = self.silhouettes(fit_from_px)?;
            if edges.len() * 2 < self.rays {
                return None;
            }
            Some((robust_harmonic(&edges, self.rays)?, edges.len()))
        };
        let ((deep, deep_se), rays) = harmonic(DEEP_FIT_FROM_PX)?;
        let centre_px = match harmonic(SHALLOW_FIT_FROM_PX) {
            Some(((shallow, shallow_se), _)) => {
                let apart: f64 = (1..3)
                    .map(|j| (shallow[j] - deep[j]).powi(2) / (deep_se[j].powi(2) + shallow_se[j].powi(2)))
                    .sum();
                if apart > CENTRES_APART_CHI2 {
                    (shallow[1], shallow[2])
                } else {
                    (0.5 * (deep[1] + shallow[1]), 0.5 * (deep[2] + shallow[2]))
                }
            }
            None => (deep[1], deep[2]),
        };
        Some(LimbOffset {
            radius_px: deep[0],
            centre_px,
            rays,
        })
    }

    /// Each ray's silhouette, (angle, px from the fitted rim, its standard uncertainty px), with the limb
    /// fitted from `fit_from_px` (negative: inside the fitted rim) under the optical spread whose limbs fit
    /// all rays' mean profiles best; rays whose best lies at either end of the tried range are left out.
    fn silhouettes(&self, fit_from_px: f64) -> Option<Vec<(f64, f64, f64)>> {
        let n = samples();
        let from = (0..n).position(|k| sample_at(k) >= fit_from_px - 1e-9)?;
        let profiles: Vec<(f64, Vec<f64>)> = (0..self.rays)
            .filter(|&i| self.count[i] as usize * 2 >= self.frames)
            .map(|i| {
                let c = self.count[i] as f64;
                let y = self.sum[i * n + from..(i + 1) * n].iter().map(|v| v / c).collect();
                (std::f64::consts::TAU * i as f64 / self.rays as f64, y)
            })
            .collect();
        let (_, fits) = BLURS_PX
            .iter()
            .map(|&blur| {
                let model = LimbModel::new(blur, from);
                let fits: Vec<_> = profiles.iter().map(|(t, y)| (*t, model.best_silhouette(y))).collect();
                (fits.iter().map(|f| f.1.1).sum::<f64>(), fits)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        Some(
            fits.iter()
                .filter_map(|&(t, (r, _, sd))| r.map(|r| (t, r, sd)))
                .collect(),
        )
    }
}

/// The first harmonic `[mean, cos, sin]` of the silhouettes `edges` (angle, px, standard uncertainty px)
/// round the rim, robust to a cluster of rays bent away from any limb (a seam, a fixture's edge), towards
/// which a least-squares harmonic would bend and hide it: first the harmonic through three rays a third of
/// the rim apart with the least median misfit over all rays (least median of squares), then weighted least
/// squares over the rays within 3 robust σ of it, or over all rays if that keeps fewer than half of the
/// `rays`. Each ray weighs by its silhouette's uncertainty with [`SILHOUETTE_FLOOR_PX`] added (in
/// quadrature): a limb of about the backdrop's gray pins its silhouette loosely. Cost: 49 triples per ray,
/// each with a median over all rays.
fn robust_harmonic(edges: &[(f64, f64, f64)], rays: usize) -> Option<([f64; 3], [f64; 3])> {
    let spreads: Vec<f64> = edges.iter().map(|e| e.2).collect();
    let edges: Vec<(f64, f64, f64)> = edges.iter().map(|&(t, r, _)| (t.cos(), t.sin(), r)).collect();
    let harmonic = |edges: &[(f64, f64, f64)]| crate::circle_fit::first_harmonic(edges.iter().copied());
    let misfit = |fit: &[f64; 3], &(c, s, r): &(f64, f64, f64)| (r - fit[0] - fit[1] * c - fit[2] * s).abs();
    let median_misfit = |fit: &[f64; 3]| {
        let mut dev: Vec<f64> = edges.iter().map(|e| misfit(fit, e)).collect();
        let mid = dev.len() / 2;
        *dev.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    let n = edges.len() as i64;
    let mut best: Option<(f64, [f64; 3])> = None;
    for i in 0..n {
        for dj in -LMS_JITTER..=LMS_JITTER {
            for dk in -LMS_JITTER..=LMS_JITTER {
                let j = (i + n / 3 + dj).rem_euclid(n) as usize;
                let k = (i + 2 * n / 3 + dk).rem_euclid(n) as usize;
                let Some(fit) = harmonic(&[edges[i as usize], edges[j], edges[k]]) else {
                    continue;
                };
                let m = median_misfit(&fit);
                if best.is_none_or(|(b, _)| m < b) {
                    best = Some((m, fit));
                }
            }
        }
    }
    let (median, start) = best?;
    let sigma = 1.4826 * (1.0 + 5.0 / (n as f64 - 3.0)) * median;
    let weighed =
        |(&(c, s, r), &sd): (&(f64, f64, f64), &f64)| (c, s, r, 1.0 / (sd * sd + SILHOUETTE_FLOOR_PX.powi(2)));
    let kept: Vec<(f64, f64, f64, f64)> = edges
        .iter()
        .zip(&spreads)
        .filter(|(e, _)| misfit(&start, e) <= 3.0 * sigma.max(MIN_SPREAD_PX))
        .map(weighed)
        .collect();
    if kept.len() * 2 >= rays {
        harmonic_with_errors(&kept)
    } else {
        harmonic_with_errors(&edges.iter().zip(&spreads).map(weighed).collect::<Vec<_>>())
    }
}

/// The weighted first harmonic `[mean, cos, sin]` of `points` (cos θ, sin θ, value, weight) and each
/// term's standard error, the weights taken as relative and their scale from the residuals (s² = Σ w·res²
/// / (n − 3)): the rays scatter about the harmonic by far more than their fits' own uncertainties say (a
/// felt's texture, the backdrop behind the rim). Neighbouring rays share that scatter, so the variance is
/// widened by (1 + ρ)/(1 − ρ), ρ the residuals' correlation from one ray to the next (0–0.95): 0.2–0.7 on
/// `looks` clips.
fn harmonic_with_errors(points: &[(f64, f64, f64, f64)]) -> Option<([f64; 3], [f64; 3])> {
    let (fit, inv) = weighted_first_harmonic_with_inverse(points.iter().copied())?;
    // Each residual scaled by √w, so that their squares sum to the weighed squares.
    let residuals: Vec<f64> = points
        .iter()
        .map(|&(c, s, v, w)| (v - fit[0] - fit[1] * c - fit[2] * s) * w.sqrt())
        .collect();
    let weighed_squares: f64 = residuals.iter().map(|r| r * r).sum();
    let s2 = weighed_squares / (points.len() as f64 - 3.0).max(1.0);
    let lag1: f64 = residuals
        .iter()
        .zip(residuals.iter().cycle().skip(1))
        .map(|(a, b)| a * b)
        .sum::<f64>();
    let rho = (lag1 / weighed_squares.max(1e-300)).clamp(0.0, 0.95);
    let inflation = (1.0 + rho) / (1.0 - rho);
    Some((fit, [0, 1, 2].map(|j| (s2 * inflation * inv[j][j]).sqrt())))
}

/// The blurred limb's three inside shapes (a step, √(R − s) and R − s) and two outside ones (a step and
/// s − R) sampled at the profile's points, for every silhouette tried.
struct LimbModel {
    shapes: Vec<Silhouette>,
}

/// One silhouette tried: R, the five columns of the fit over the fitted samples (step, root and linear
/// inside, step and linear outside) and their Gram matrix, which does not depend on the profile.
type Silhouette = (f64, [Vec<f64>; 5], [[f64; 5]; 5]);

impl LimbModel {
    /// The shapes blurred by the pixel's width and an optical spread of `blur_px` (Gaussian σ), over the
    /// samples from index `from` on.
    fn new(blur_px: f64, from: usize) -> Self {
        // On a 0.05 px grid: the pixel's width (a 1 px box), the bilinear sampling along the ray (a tent
        // 1 px either side) and the optical spread (a Gaussian), convolved.
        let dt = R_STEP_PX;
        let on_grid = |half_width: f64, f: &dyn Fn(f64) -> f64| -> Vec<f64> {
            let n = (half_width / dt).round() as i32;
            (-n..=n).map(|j| f(j as f64 * dt)).collect()
        };
        let pixel = on_grid(0.5, &|u| if u.abs() < 0.5 - 1e-9 { 1.0 } else { 0.5 });
        let tent = on_grid(1.0, &|u| 1.0 - u.abs());
        let optics = if blur_px > 0.0 {
            on_grid(3.0 * blur_px, &|u| (-0.5 * (u / blur_px).powi(2)).exp())
        } else {
            vec![1.0]
        };
        let kernel = convolve(&convolve(&pixel, &tent), &optics);
        let norm: f64 = kernel.iter().sum();
        let half = (kernel.len() / 2) as i64;
        // Each shape depends on the depth R − s alone, which lies on the grid: blur it once over every
        // depth the silhouettes and samples reach.
        let grid = |v: f64| (v / dt).round() as i64;
        let (lo, hi) = (
            grid(R_FROM_PX + DEEP_FIT_FROM_PX.min(SHALLOW_FIT_FROM_PX).min(0.0) - OUTER_PX) - half,
            grid(R_TO_PX + INNER_PX) + half,
        );
        let blurred: Vec<[f64; 4]> = (lo..=hi)
            .map(|d| {
                let mut acc = [0.0; 4];
                for (t, w) in kernel.iter().enumerate() {
                    let steps_in = d - (t as i64 - half);
                    let depth = steps_in as f64 * dt;
                    // A tap on the silhouette itself is half inside.
                    acc[0] += w / norm * (steps_in.signum() as f64 + 1.0) / 2.0;
                    if steps_in > 0 {
                        acc[1] += w / norm * depth.sqrt();
                        acc[2] += w / norm * depth;
                    } else {
                        acc[3] -= w / norm * depth;
                    }
                }
                acc
            })
            .collect();
        let at = |depth: f64| blurred[(grid(depth) - lo).clamp(0, blurred.len() as i64 - 1) as usize];
        let steps = ((R_TO_PX - R_FROM_PX) / R_STEP_PX).round() as usize;
        let shapes = (0..=steps)
            .map(|j| {
                let r = R_FROM_PX + j as f64 * R_STEP_PX;
                let mut cols: [Vec<f64>; 5] = Default::default();
                for k in from..samples() {
                    let [step, root, linear, outside] = at(r - sample_at(k));
                    for (col, v) in cols.iter_mut().zip([step, root, linear, 1.0 - step, outside]) {
                        col.push(v);
                    }
                }
                let mut ata = [[0.0f64; 5]; 5];
                for p in 0..5 {
                    for q in 0..5 {
                        ata[p][q] = cols[p].iter().zip(&cols[q]).map(|(a, b)| a * b).sum();
                    }
                }
                (r, cols, ata)
            })
            .collect();
        LimbModel { shapes }
    }

    /// The silhouette, px from the fitted rim, whose limb fits `y` (the samples from the model's `from` on)
    /// best (`None` at either end of the tried range), that fit's sum of squared residuals, and the
    /// silhouette's standard uncertainty, px: half the range of silhouettes whose fit lies within one unit
    /// of χ² of the best (the noise taken from the best fit's residuals). The backdrop outside is a
    /// constant, or a straight line across the rim where that fits clearly better ([`SLOPE_GAIN`]): a
    /// ruler's edge or a fixture behind the rim.
    fn best_silhouette(&self, y: &[f64]) -> (Option<f64>, f64, f64) {
        let yy: f64 = y.iter().map(|v| v * v).sum();
        let (constant, sloped): (Vec<f64>, Vec<f64>) = self
            .shapes
            .iter()
            .map(|(_, cols, ata)| {
                let atb = cols
                    .each_ref()
                    .map(|c| c.iter().zip(y).map(|(a, b)| a * b).sum::<f64>());
                let sloped =
                    solve_spd(*ata, atb).map_or(f64::INFINITY, |c| yy - (0..5).map(|p| c[p] * atb[p]).sum::<f64>());
                let a4: [[f64; 4]; 4] = std::array::from_fn(|p| std::array::from_fn(|q| ata[p][q]));
                let b4: [f64; 4] = std::array::from_fn(|p| atb[p]);
                let constant =
                    solve_spd(a4, b4).map_or(f64::INFINITY, |c| yy - (0..4).map(|p| c[p] * b4[p]).sum::<f64>());
                (constant, sloped)
            })
            .unzip();
        let least = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let sses = if least(&constant) > SLOPE_GAIN * least(&sloped) {
            sloped
        } else {
            constant
        };
        let (j, best) = sses
            .iter()
            .copied()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, f64::INFINITY));
        let inside = best.is_finite() && j > 0 && j + 1 < self.shapes.len();
        let var = (best / (y.len() as f64 - 5.0).max(1.0)).max(1e-12);
        let within: Vec<f64> = sses
            .iter()
            .zip(&self.shapes)
            .filter(|(s, _)| (*s - best) / var <= 1.0)
            .map(|(_, sh)| sh.0)
            .collect();
        let lo = within.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = within.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let spread = (0.5 * (hi - lo)).max(0.5 * R_STEP_PX);
        (inside.then(|| self.shapes[j].0), best, spread)
    }
}

/// The full discrete convolution of `a` and `b`.
fn convolve(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// Solves `a·x = b` for a symmetric positive-definite `a` by Cholesky; `None` when `a` is singular to
/// working precision. Cost: N³/6 multiply-adds.
fn solve_spd<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    let scale = (0..N).map(|i| a[i][i].abs()).fold(0.0, f64::max);
    for j in 0..N {
        for k in 0..j {
            let l = a[j][k];
            for row in a.iter_mut().skip(j) {
                row[j] -= row[k] * l;
            }
        }
        if a[j][j] <= 1e-12 * scale || !a[j][j].is_finite() {
            return None;
        }
        let d = a[j][j].sqrt();
        for row in a.iter_mut().skip(j) {
            row[j] /= d;
        }
    }
    for i in 0..N {
        b[i] = (b[i] - (0..i).map(|k| a[i][k] * b[k]).sum::<f64>()) / a[i][i];
    }
    for i in (0..N).rev() {
        b[i] = (b[i] - (i + 1..N).map(|k| a[k][i] * b[k]).sum::<f64>()) / a[i][i];
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Draws a lit sphere of radius `r` at (cx, cy) on a flat backdrop, anti-aliased by 4×4 supersampling:
    /// inside, `ambient + diffuse·√(1 − ρ²)` (light from the camera), so its limb meets the backdrop at
    /// `ambient`.
    fn sphere(w: usize, cx: f64, cy: f64, r: f64, ambient: f64, diffuse: f64, backdrop: f64) -> Vec<f32> {
        drawn(w, cx, cy, r, |_, _, n_z| ambient + diffuse * n_z, backdrop)
    }

    /// Draws a ball of radius `r` at (cx, cy) on a flat backdrop, anti-aliased by 4×4 supersampling, its gray
    /// inside a function of the position in radii from the centre, (u, v), and of the surface normal's
    /// component towards the camera, n_z = √(1 − ρ²).
    fn drawn(w: usize, cx: f64, cy: f64, r: f64, inside: impl Fn(f64, f64, f64) -> f64, backdrop: f64) -> Vec<f32> {
        let mut px = vec![0.0f32; w * w];
        for y in 0..w {
            for x in 0..w {
                let mut acc = 0.0;
                for sy in 0..4 {
                    for sx in 0..4 {
                        let (u, v) = (x as f64 + (sx as f64 + 0.5) / 4.0, y as f64 + (sy as f64 + 0.5) / 4.0);
                        let (du, dv) = ((u - 0.5 - cx) / r, (v - 0.5 - cy) / r);
                        let rho2 = du * du + dv * dv;
                        acc += if rho2 < 1.0 {
                            inside(du, dv, (1.0 - rho2).sqrt())
                        } else {
                            backdrop
                        };
                    }
                }
                px[y * w + x] = (acc / 16.0) as f32;
            }
        }
        px
    }

    /// The offset learned from `MIN_FRAMES` copies of the `w`×`w` image `px` with the circle `fit` on 64 rays.
    fn offset_of(px: &[f32], w: usize, fit: (f64, f64, f64)) -> Option<LimbOffset> {
        let img = Plane::new(px, w, w);
        let mut learner = LimbLearner::default();
        for _ in 0..MIN_FRAMES {
            learner.add(&img, fit, 64, None);
        }
        learner.offset()
    }

    /// Asserts that `o` tells a silhouette `radius_px` outside the fitted rim (within 0.25 px) and centred
    /// `centre_px` from the fitted centre (within 0.1 px in each axis).
    fn assert_told(o: &LimbOffset, radius_px: f64, centre_px: (f64, f64)) {
        assert!((o.radius_px - radius_px).abs() < 0.25, "{o:?}");
        assert!(
            (o.centre_px.0 - centre_px.0).abs() < 0.1 && (o.centre_px.1 - centre_px.1).abs() < 0.1,
            "{o:?}"
        );
    }

    /// Circles fitted inside the silhouette by a known amount: the learner tells the centre's offset and
    /// the radius's.
    #[test]
    fn a_shaded_limb_s_silhouette_is_found_outside_a_small_circle() {
        let (cx, cy, r) = (48.3, 47.6, 30.0);
        let px = sphere(96, cx, cy, r, 100.0, 120.0, 104.0);
        let o = offset_of(&px, 96, (cx + 0.4, cy - 0.2, r - 0.6)).expect("a limb on every ray");
        assert_told(&o, 0.6, (-0.4, 0.2));
    }

    /// A shaded limb whose felt sheen brightens its last pixels past the backdrop's gray (a dark limb of 70
    /// rising to 115 at the silhouette, on a backdrop of 100): the steepest change is inside the silhouette,
    /// and the learner still tells how far the circles fitted there lie from it. A limb model of the root
    /// alone, fitted from 6 px inside, put the silhouette 0.49 px inside these circles, not 0.5 px outside.
    #[test]
    fn a_limb_brightened_by_sheen_past_the_backdrop_s_gray_is_told() {
        let (cx, cy, r) = (64.4, 63.7, 50.0);
        let px = drawn(128, cx, cy, r, |_, _, n_z| 70.0 + 45.0 * (1.0 - n_z).powi(3), 100.0);
        let o = offset_of(&px, 128, (cx + 0.3, cy - 0.4, r - 0.5)).expect("a limb on every ray");
        assert_told(&o, 0.5, (-0.3, 0.4));
    }

    /// A seam, a bright band on the felt, runs along the limb 2–3.5 px inside the silhouette over a sixth
    /// of the rim: the rays there fit its edge, not the limb's, and are left out of the offset rather than
    /// pulling it.
    #[test]
    fn a_seam_crossing_the_limb_does_not_pull_the_offset() {
        let (cx, cy, r) = (64.4, 63.7, 50.0);
        let seam = |u: f64, v: f64, n_z: f64| {
            let limb = 70.0 + 45.0 * (1.0 - n_z).powi(3);
            let (rho, angle) = (u.hypot(v), v.atan2(u));
            if (0.93..0.97).contains(&rho) && (0.0..1.2).contains(&angle) {
                limb + 80.0
            } else {
                limb
            }
        };
        let px = drawn(128, cx, cy, r, seam, 100.0);
        let o = offset_of(&px, 128, (cx + 0.3, cy - 0.4, r - 0.5)).expect("a limb on most rays");
        assert_told(&o, 0.5, (-0.3, 0.4));
    }

    /// A backdrop whose gray rises away from the lower third of the rim by 6 DN a pixel (the blurred mean of
    /// a ruler's edges passing behind it over the flight): a constant backdrop puts those rays' silhouettes
    /// off and pulls the centre; a backdrop sloping across the rim, taken where it fits clearly better, does
    /// not.
    #[test]
    fn a_backdrop_sloping_across_the_rim_does_not_pull_the_offset() {
        let (w, cx, cy, r) = (128, 64.4, 63.7, 50.0);
        let limb = |_: f64, _: f64, n_z: f64| 70.0 + 60.0 * n_z;
        let mut px = drawn(w, cx, cy, r, limb, 100.0);
        let sharp = drawn(w, cx, cy, r, limb, 0.0);
        for (k, v) in px.iter_mut().enumerate() {
            let (x, y) = ((k % w) as f64 + 0.5, (k / w) as f64 + 0.5);
            // Where the backdrop shows (the part of the pixel outside the ball): the ball's own gray is the
            // same in both drawings.
            let outside = (*v - sharp[k]) / 100.0;
            let (dx, dy) = (x - cx, y - cy);
            if dy > 0.5 * dx.hypot(dy) {
                *v += outside * (6.0 * (dx.hypot(dy) - r).max(0.0)) as f32;
            }
        }
        let o = offset_of(&px, w, (cx + 0.3, cy - 0.4, r - 0.5)).expect("a limb on most rays");
        assert_told(&o, 0.5, (-0.3, 0.4));
    }

    /// The harmonic's errors come from the rays' scatter about it, widened where neighbouring rays share
    /// it: the same residuals in a slow wave round the rim (ρ near 1) give a larger error than alternating
    /// ones (ρ < 0, taken as 0), and the fit itself is the plain weighted harmonic.
    #[test]
    fn the_harmonic_s_errors_grow_with_rays_sharing_their_scatter() {
        let rays = 64;
        let at = |i: usize, res: f64| {
            let t = std::f64::consts::TAU * i as f64 / rays as f64;
            (t.cos(), t.sin(), 0.5 + 0.2 * t.cos() - 0.1 * t.sin() + res, 1.0)
        };
        let alternating: Vec<_> = (0..rays).map(|i| at(i, if i % 2 == 0 { 0.1 } else { -0.1 })).collect();
        let wave: Vec<_> = (0..rays)
            .map(|i| at(i, 0.1 * (std::f64::consts::TAU * 5.0 * i as f64 / rays as f64).sin()))
            .collect();
        let (fit, independent) = harmonic_with_errors(&alternating).unwrap();
        assert!((fit[0] - 0.5).abs() < 1e-9 && (fit[1] - 0.2).abs() < 1e-9 && (fit[2] + 0.1).abs() < 1e-9);
        // Alternating ±0.1 over 64 rays: s ≈ 0.1, the cos term's error ≈ 0.1·√(2/64).
        assert!(
            (independent[1] - 0.1 * (2.0f64 / 64.0).sqrt()).abs() < 0.003,
            "{independent:?}"
        );
        // The wave's RMS is 0.1/√2: unwidened, its error would be 0.1/√2·√(2/64); ρ = cos(2π·5/64) ≈ 0.88
        // widens it ≈ 4×.
        let (_, shared) = harmonic_with_errors(&wave).unwrap();
        let unwidened = 0.1 / 2.0f64.sqrt() * (2.0f64 / 64.0).sqrt();
        assert!(shared[1] > 3.0 * unwidened, "{shared:?} against {unwidened}");
    }

    /// Cholesky's solution satisfies its system; a singular matrix gives none.
    #[test]
    fn a_positive_definite_system_is_solved() {
        let a = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let b = [1.0, -2.0, 0.5];
        let x = solve_spd(a, b).expect("positive definite");
        for i in 0..3 {
            let ax: f64 = (0..3).map(|k| a[i][k] * x[k]).sum();
            assert!((ax - b[i]).abs() < 1e-12, "{x:?}");
        }
        assert_eq!(solve_spd([[1.0, 1.0], [1.0, 1.0]], [1.0, 1.0]), None);
    }

    /// A silhouette (a flat disc on a contrasting backdrop) fitted exactly has no offset.
    #[test]
    fn a_flat_disc_fitted_on_its_rim_has_no_offset() {
        let (cx, cy, r) = (48.0, 48.5, 25.0);
        let px = sphere(96, cx, cy, r, 40.0, 0.0, 160.0);
        let o = offset_of(&px, 96, (cx, cy, r)).expect("a rim on every ray");
        assert!(o.radius_px.abs() < 0.1 && o.centre_len_px() < 0.05, "{o:?}");
    }

    /// A disc whose edge a lens spreads by 1 px (Gaussian σ), fitted on its rim: the spread is measured, so
    /// the silhouette is still told on the rim, not inside it.
    #[test]
    fn a_blurred_disc_fitted_on_its_rim_has_no_offset() {
        let (w, cx, cy, r) = (96, 48.0, 48.5, 25.0);
        let sharp = sphere(w, cx, cy, r, 40.0, 0.0, 160.0);
        let kernel: Vec<f32> = (-4..=4i32).map(|k| (-0.5 * (k * k) as f32).exp()).collect();
        let norm: f32 = kernel.iter().sum();
        let pass = |img: &[f32], dx: usize, dy: usize| -> Vec<f32> {
            (0..w * w)
                .map(|i| {
                    let (x, y) = ((i % w) as i64, (i / w) as i64);
                    kernel.iter().enumerate().fold(0.0, |acc, (j, k)| {
                        let o = j as i64 - 4;
                        let (u, v) = (
                            (x + o * dx as i64).clamp(0, w as i64 - 1),
                            (y + o * dy as i64).clamp(0, w as i64 - 1),
                        );
                        acc + k / norm * img[v as usize * w + u as usize]
                    })
                })
                .collect()
        };
        let px = pass(&pass(&sharp, 1, 0), 0, 1);
        let o = offset_of(&px, w, (cx, cy, r)).expect("a rim on every ray");
        assert!(o.radius_px.abs() < 0.1 && o.centre_len_px() < 0.05, "{o:?}");
    }

    /// Too few frames tell nothing.
    #[test]
    fn few_frames_tell_no_offset() {
        let px = sphere(96, 48.0, 48.0, 25.0, 40.0, 0.0, 160.0);
        let img = Plane::new(&px, 96, 96);
        let fit = (48.0, 48.0, 25.0);
        let mut learner = LimbLearner::default();
        learner.add(&img, fit, 64, None);
        assert_eq!(learner.offset(), None);
    }
}
