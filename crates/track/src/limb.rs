//! How far the ball's silhouette may lie from the circles fitted to its rim: a lit ball's limb is shaded,
//! and where that shading meets a backdrop of about its own gray, the steepest change along a ray is the
//! shading's, inside the silhouette, so the fitted circles are small and off-centre by up to a pixel.
//!
//! Measured on the mean radial profile of the full-rim flight frames that teach the rim's shape (clean or
//! not), each taken along its own fitted circle's rays (the light does not turn with the ball; the felt's
//! texture averages out): on each ray a Lambertian limb, `a + b·√(R − s)` inside the silhouette `R` and a
//! constant `c` outside, blurred by the pixel and a 0.5 px optical spread, is fitted by least squares over
//! `R`. The silhouette's mean `R` and its first harmonic round the rim are how far the fitted circles' radius
//! and centre lie from it. A limb model is one account of the shading among others (a fuzzy felt, a seam), so
//! the tracker uses these as uncertainties of the offset every centre shares, not as corrections. Cost: 53
//! samples per ray per frame learned (64 µs for 128 rays), and 4.9 ms once per clip for the fit (the track
//! bench's `limb_learn_frame` and `limb_offset`).

use crate::plane::{Pixel, Plane};

/// Sampling step along a ray, px.
const STEP_PX: f64 = 0.25;
/// Samples from the fitted rim inwards and outwards, px.
const INNER_PX: f64 = 8.0;
const OUTER_PX: f64 = 5.0;
/// The limb model is fitted from this far inside the fitted rim, px.
const FIT_FROM_PX: f64 = -6.0;
/// Silhouettes tried, px from the fitted rim: a ray whose best lies at either end is not a limb.
const R_FROM_PX: f64 = -3.0;
const R_TO_PX: f64 = 2.0;
const R_STEP_PX: f64 = 0.05;
/// The optical spread assumed beyond the pixel's own width, px (Gaussian σ).
const BLUR_PX: f64 = 0.5;
/// Fewest frames averaged before the offset is told.
const MIN_FRAMES: usize = 8;

fn samples() -> usize {
    ((INNER_PX + OUTER_PX) / STEP_PX).round() as usize + 1
}

fn sample_at(k: usize) -> f64 {
    -INNER_PX + k as f64 * STEP_PX
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

    /// Adds `img`'s profile along `rays` rays of the circle fitted to it, `(x, y, r)` px (a ray with a sample
    /// outside the image is skipped in this frame).
    pub fn add<P: Pixel>(&mut self, img: &Plane<P>, (x, y, r): (f64, f64, f64), rays: usize) {
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
                match img.sample((x + c * d) as f32, (y + s * d) as f32) {
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
        let n = samples();
        let model = LimbModel::new();
        let from = (0..n).position(|k| sample_at(k) >= FIT_FROM_PX - 1e-9)?;
        let mut edges = Vec::new();
        for i in (0..self.rays).filter(|&i| self.count[i] as usize * 2 >= self.frames) {
            let c = self.count[i] as f64;
            let y: Vec<f64> = self.sum[i * n + from..(i + 1) * n].iter().map(|v| v / c).collect();
            if let Some(r) = model.best_silhouette(&y, from) {
                edges.push((std::f64::consts::TAU * i as f64 / self.rays as f64, r));
            }
        }
        if edges.len() * 2 < self.rays {
            return None;
        }
        let [m, a, b] = crate::circle_fit::first_harmonic(edges.iter().map(|&(t, r)| (t.cos(), t.sin(), r)))?;
        Some(LimbOffset {
            radius_px: m,
            centre_px: (a, b),
            rays: edges.len(),
        })
    }
}

/// The blurred limb's two inside shapes (a step and √(R − s)) sampled at the profile's points, for every
/// silhouette tried.
struct LimbModel {
    /// Per silhouette: (R, step, root), each over all samples.
    shapes: Vec<(f64, Vec<f64>, Vec<f64>)>,
}

impl LimbModel {
    fn new() -> Self {
        // The pixel's width (a 1 px box) and the optical spread, on a 0.05 px grid.
        let dt = 0.05;
        let half = (3.0 * BLUR_PX + 0.5) / dt;
        let taps: Vec<(f64, f64)> = (-(half as i32)..=half as i32)
            .map(|j| {
                let u = j as f64 * dt;
                let box_part = |v: f64| libm::erf(v / (BLUR_PX * std::f64::consts::SQRT_2));
                // A 1 px box convolved with a Gaussian: half the difference of two error functions.
                (u, 0.5 * (box_part(u + 0.5) - box_part(u - 0.5)) * dt)
            })
            .collect();
        let norm: f64 = taps.iter().map(|t| t.1).sum();
        let n = samples();
        let steps = ((R_TO_PX - R_FROM_PX) / R_STEP_PX).round() as usize;
        let shapes = (0..=steps)
            .map(|j| {
                let r = R_FROM_PX + j as f64 * R_STEP_PX;
                let (mut step, mut root) = (vec![0.0; n], vec![0.0; n]);
                for k in 0..n {
                    let s = sample_at(k);
                    for &(u, w) in &taps {
                        let depth = r - (s + u);
                        if depth > 0.0 {
                            step[k] += w / norm;
                            root[k] += w / norm * depth.sqrt();
                        }
                    }
                }
                (r, step, root)
            })
            .collect();
        LimbModel { shapes }
    }

    /// The silhouette, px from the fitted rim, whose limb fits `y` (the samples from index `from` on) best;
    /// `None` at either end of the tried range.
    fn best_silhouette(&self, y: &[f64], from: usize) -> Option<f64> {
        let mut best = (f64::INFINITY, 0usize);
        for (j, (_, step, root)) in self.shapes.iter().enumerate() {
            let cols = [&step[from..], &root[from..]];
            let mut ata = [[0.0f64; 3]; 3];
            let mut atb = [0.0f64; 3];
            let mut yy = 0.0;
            for (k, &v) in y.iter().enumerate() {
                let row = [cols[0][k], cols[1][k], 1.0 - cols[0][k]];
                yy += v * v;
                for p in 0..3 {
                    atb[p] += row[p] * v;
                    for q in 0..3 {
                        ata[p][q] += row[p] * row[q];
                    }
                }
            }
            let Some(inv) = crate::circle_fit::invert3(&ata) else {
                continue;
            };
            let c: Vec<f64> = (0..3).map(|p| (0..3).map(|q| inv[p][q] * atb[q]).sum()).collect();
            let sse = yy - (0..3).map(|p| c[p] * atb[p]).sum::<f64>();
            if sse < best.0 {
                best = (sse, j);
            }
        }
        let j = best.1;
        (best.0.is_finite() && j > 0 && j + 1 < self.shapes.len()).then(|| self.shapes[j].0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Draws a lit sphere of radius `r` at (cx, cy) on a flat backdrop, anti-aliased by 4×4 supersampling:
    /// inside, `ambient + diffuse·√(1 − ρ²)` (light from the camera), so its limb meets the backdrop at
    /// `ambient`.
    fn sphere(w: usize, cx: f64, cy: f64, r: f64, ambient: f64, diffuse: f64, backdrop: f64) -> Vec<f32> {
        let mut px = vec![0.0f32; w * w];
        for y in 0..w {
            for x in 0..w {
                let mut acc = 0.0;
                for sy in 0..4 {
                    for sx in 0..4 {
                        let (u, v) = (x as f64 + (sx as f64 + 0.5) / 4.0, y as f64 + (sy as f64 + 0.5) / 4.0);
                        let rho2 = ((u - 0.5 - cx).powi(2) + (v - 0.5 - cy).powi(2)) / (r * r);
                        acc += if rho2 < 1.0 {
                            ambient + diffuse * (1.0 - rho2).sqrt()
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

    /// Circles fitted inside the silhouette by a known amount: the learner tells the centre's offset, and
    /// the radius's within the 0.2 px that the model's assumed optical spread (this drawing has none) costs.
    #[test]
    fn a_shaded_limb_s_silhouette_is_found_outside_a_small_circle() {
        let (cx, cy, r) = (48.3, 47.6, 30.0);
        let px = sphere(96, cx, cy, r, 100.0, 120.0, 104.0);
        let img = Plane::new(&px, 96, 96);
        let fit = (cx + 0.4, cy - 0.2, r - 0.6);
        let mut learner = LimbLearner::default();
        for _ in 0..MIN_FRAMES {
            learner.add(&img, fit, 64);
        }
        let o = learner.offset().expect("a limb on every ray");
        assert!((o.radius_px - 0.6).abs() < 0.25, "{o:?}");
        assert!(
            (o.centre_px.0 + 0.4).abs() < 0.1 && (o.centre_px.1 - 0.2).abs() < 0.1,
            "{o:?}"
        );
    }

    /// A silhouette (a flat disc on a contrasting backdrop) fitted exactly has no offset.
    #[test]
    fn a_flat_disc_fitted_on_its_rim_has_no_offset() {
        let (cx, cy, r) = (48.0, 48.5, 25.0);
        let px = sphere(96, cx, cy, r, 40.0, 0.0, 160.0);
        let img = Plane::new(&px, 96, 96);
        let fit = (cx, cy, r);
        let mut learner = LimbLearner::default();
        for _ in 0..MIN_FRAMES {
            learner.add(&img, fit, 64);
        }
        let o = learner.offset().expect("a rim on every ray");
        assert!(o.radius_px.abs() < 0.1 && o.centre_len_px() < 0.05, "{o:?}");
    }

    /// Too few frames tell nothing.
    #[test]
    fn few_frames_tell_no_offset() {
        let px = sphere(96, 48.0, 48.0, 25.0, 40.0, 0.0, 160.0);
        let img = Plane::new(&px, 96, 96);
        let fit = (48.0, 48.0, 25.0);
        let mut learner = LimbLearner::default();
        learner.add(&img, fit, 64);
        assert_eq!(learner.offset(), None);
    }
}
