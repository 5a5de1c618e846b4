//! Sub-pixel centre and radius from edge points found along rays from a first guess.
//!
//! Along each of `rays` directions the image is sampled (bilinear) across the expected rim; the edge is the
//! strongest change of brightness, located to a fraction of a pixel by a parabola through the derivative's
//! peak. Rays whose rim point lies at or below the surface line are skipped (that part of the ball is
//! pressed into or hidden by the surface), and so are rays leaving the image. The edge points then go to the
//! robust circle fit. Cost: rays × samples bilinear reads (128 × 17 ≈ 2,200, ≈ 10 µs) plus the fit.

use crate::fit::{CircleFit, fit_circle};
use crate::plane::{Pixel, Plane};
use crate::surface::SurfaceLine;

/// Options of [`refine_circle`].
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeSearch {
    /// Number of rays (default 128).
    pub rays: usize,
    /// Half-width of the search across the expected rim, px (default 4).
    pub half_width: f64,
    /// Sampling step along a ray, px (default 0.5).
    pub step: f64,
    /// Smallest brightness step that counts as an edge, on the 0–255 scale per px (default 2).
    pub min_contrast: f32,
    /// Rays whose rim point lies less than this above the surface line are skipped, px (default 2).
    pub surface_margin: f64,
    /// Also measure [`Refined::edge_definition_px`] (default false: it costs ≈ 3 µs a frame and the scale
    /// needs it in a few dozen frames only).
    pub edge_definition: bool,
}

impl Default for EdgeSearch {
    fn default() -> Self {
        EdgeSearch {
            rays: 128,
            half_width: 4.0,
            step: 0.5,
            min_contrast: 2.0,
            surface_margin: 2.0,
            edge_definition: false,
        }
    }
}

/// A refined circle and what it was made of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Refined {
    /// The fit.
    pub fit: CircleFit,
    /// Rays that gave an edge point.
    pub rays_with_edge: usize,
    /// Rays skipped because they left the image.
    pub rays_outside: usize,
    /// Rays skipped because the rim there is at or below the surface line.
    pub rays_hidden: usize,
    /// Rays searched.
    pub rays: usize,
    /// Median brightness step at the edge points, 0–255 scale per px.
    pub contrast: f32,
    /// Median distance from the gradient-maximum edge to the half-contrast crossing, px (positive outward):
    /// how much "the rim" depends on how an edge is defined. NaN unless [`EdgeSearch::edge_definition`]
    /// asked for it (or too few rays gave one).
    pub edge_definition_px: f64,
}

impl Refined {
    /// A 0–1 quality score: the fraction of rays whose edge point the fit kept, times a contrast factor
    /// that reaches 1 at 10 levels per px.
    pub fn quality(&self) -> f64 {
        let kept = self.fit.inliers as f64 / self.rays as f64;
        kept * (self.contrast as f64 / 10.0).min(1.0)
    }
}

/// Refines the circle (`x`, `y`, `r`) in px: edge points along rays, then a robust fit. With a search
/// wider than ±2 px it runs again from the first fit (re-centred while it moves) with half the width.
/// `None` when too few edges are found.
pub fn refine_circle<P: Pixel>(
    img: &Plane<P>,
    x: f64,
    y: f64,
    r: f64,
    search: &EdgeSearch,
    surface: Option<&SurfaceLine>,
) -> Option<Refined> {
    let mut fit = refine_once(img, x, y, r, search, search.half_width, surface)?;
    // A guess far off the rim puts the window astride the wrong places: re-centre until it settles.
    for _ in 0..3 {
        let moved = (fit.fit.x - x).hypot(fit.fit.y - y).max((fit.fit.r - r).abs());
        if moved < 0.25 * search.half_width {
            break;
        }
        let (x, y, r) = (fit.fit.x, fit.fit.y, fit.fit.r);
        match refine_once(img, x, y, r, search, search.half_width, surface) {
            Some(f) => fit = f,
            None => break,
        }
    }
    let narrow = (search.half_width * 0.5).max(2.0);
    if narrow >= search.half_width {
        return Some(fit);
    }
    refine_once(img, fit.fit.x, fit.fit.y, fit.fit.r, search, narrow, surface).or(Some(fit))
}

fn refine_once<P: Pixel>(
    img: &Plane<P>,
    x: f64,
    y: f64,
    r: f64,
    search: &EdgeSearch,
    half_width: f64,
    surface: Option<&SurfaceLine>,
) -> Option<Refined> {
    let n = search.rays.max(8);
    let samples = ((2.0 * half_width / search.step).round() as usize).max(4) + 1;
    let mut profile = vec![0.0f32; samples];
    let mut points = Vec::with_capacity(n);
    let mut contrasts = Vec::with_capacity(n);
    let mut offsets: Vec<f64> = Vec::with_capacity(n);
    let (mut outside, mut hidden) = (0, 0);
    // Ray directions by rotating one unit vector: no sin/cos per ray.
    let (dc, ds) = (std::f64::consts::TAU / n as f64).sin_cos();
    let (dc, ds) = (ds, dc); // (cos Δ, sin Δ)
    let (mut c, mut s) = (1.0f64, 0.0f64);
    let (wmax, hmax) = ((img.width - 1) as f64, (img.height - 1) as f64);
    for _ in 0..n {
        let (c0, s0) = (c, s);
        (c, s) = (c0 * dc - s0 * ds, s0 * dc + c0 * ds);
        let (c, s) = (c0, s0);
        let start = r - half_width;
        // The search stops short of the surface line: below it is the band, whose own edge must not be
        // taken for the ball's rim.
        let mut len = samples;
        if let Some(line) = surface {
            let (rx, ry) = (x + r * c, y + r * s);
            if ry > line.y_at(rx) - search.surface_margin {
                hidden += 1;
                continue;
            }
            let towards = s - line.slope * c;
            if towards > 1e-9 {
                let reach = (line.y_at(x) - search.surface_margin - y) / towards;
                len = len.min(((reach - start) / search.step).floor().max(0.0) as usize + 1);
                if len < samples / 2 + 3 {
                    hidden += 1;
                    continue;
                }
            }
        }
        // A straight segment is inside the image when both its ends are.
        let end = start + (len - 1) as f64 * search.step;
        let inside = |d: f64| {
            let (px, py) = (x + d * c, y + d * s);
            px >= 0.01 && py >= 0.01 && px < wmax - 0.01 && py < hmax - 0.01
        };
        if !inside(start) || !inside(end) {
            outside += 1;
            continue;
        }
        let profile = &mut profile[..len];
        let (mut px, mut py) = ((x + start * c) as f32, (y + start * s) as f32);
        let (sx, sy) = ((search.step * c) as f32, (search.step * s) as f32);
        for p in profile.iter_mut() {
            *p = img.sample_inside(px, py);
            px += sx;
            py += sy;
        }
        // Central differences; the edge is the largest |change|.
        let (mut best, mut best_j) = (0.0f32, 0);
        for j in 1..len - 1 {
            let d = (profile[j + 1] - profile[j - 1]).abs();
            if d > best {
                best = d;
                best_j = j;
            }
        }
        let per_px = best / (2.0 * search.step as f32);
        if per_px < search.min_contrast || best_j < 2 || best_j + 3 > len {
            continue;
        }
        let m = |j: usize| (profile[j + 1] - profile[j - 1]).abs() as f64;
        let (a0, a1, a2) = (m(best_j - 1), m(best_j), m(best_j + 1));
        let den = a0 - 2.0 * a1 + a2;
        let off = if den < 0.0 {
            (0.5 * (a0 - a2) / den).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        let d = start + (best_j as f64 + off) * search.step;
        points.push([x + d * c, y + d * s]);
        contrasts.push(per_px);
        if search.edge_definition
            && let Some(o) = half_level_offset(profile, best_j, best_j as f64 + off)
        {
            offsets.push(o * search.step);
        }
    }
    let mut fit = fit_circle(&points, x, y, r)?;
    // Neighbouring rays see overlapping texture, so their edge errors are correlated and the fit's σ (which
    // assumes independent points) is optimistic. Inflate it by the AR(1) factor √((1+ρ)/(1−ρ)), with ρ the
    // lag-1 correlation of the residuals around the rim (points are in ray order), measured on this frame.
    let res: Vec<f64> = points
        .iter()
        .map(|p| (p[0] - fit.x).hypot(p[1] - fit.y) - fit.r)
        .filter(|e| e.abs() < 3.0 * fit.rms.max(0.02))
        .collect();
    if res.len() > 8 {
        let m = res.iter().sum::<f64>() / res.len() as f64;
        let var: f64 = res.iter().map(|e| (e - m).powi(2)).sum();
        let lag: f64 = res.windows(2).map(|w| (w[0] - m) * (w[1] - m)).sum();
        let rho = (lag / var.max(1e-300)).clamp(0.0, 0.8);
        let k = ((1.0 + rho) / (1.0 - rho)).sqrt();
        fit.sigma_x *= k;
        fit.sigma_y *= k;
        fit.sigma_r *= k;
    }
    let mid = contrasts.len() / 2;
    let contrast = *contrasts.select_nth_unstable_by(mid, f32::total_cmp).1;
    let edge_definition_px = if offsets.len() >= 8 {
        let mid = offsets.len() / 2;
        *offsets.select_nth_unstable_by(mid, f64::total_cmp).1
    } else {
        f64::NAN
    };
    Some(Refined {
        fit,
        rays_with_edge: points.len(),
        rays_outside: outside,
        rays_hidden: hidden,
        rays: n,
        contrast,
        edge_definition_px,
    })
}

/// Where the profile crosses half-way between its levels inside and outside the edge, relative to the
/// gradient maximum at `edge` (both in samples). Two reasonable definitions of "the edge" that agree on a
/// symmetric blurred step; their difference on a real (shaded, fuzzy) rim measures how well the edge is
/// defined at all.
fn half_level_offset(profile: &[f32], j: usize, edge: f64) -> Option<f64> {
    if j < 3 || j + 3 >= profile.len() {
        return None;
    }
    let inside = profile[..j - 1].iter().sum::<f32>() / (j - 1) as f32;
    let outside = profile[j + 2..].iter().sum::<f32>() / (profile.len() - j - 2) as f32;
    let half = 0.5 * (inside + outside);
    (j - 2..j + 2).find_map(|k| {
        let (a, b) = (profile[k] - half, profile[k + 1] - half);
        (a == 0.0 || (a < 0.0) != (b < 0.0)).then(|| k as f64 + (a / (a - b)) as f64 - edge)
    })
}

/// Circle candidates found by [`detect_circles`](crate::detect_circles), each refined to sub-pixel
/// precision, duplicates merged, nested ones dropped (see [`outermost`](crate::outermost)), and scored by
/// the refined quality (stored in `support`). Best first.
pub fn refined_candidates<P: Pixel>(
    img: &Plane<P>,
    detection: &crate::CircleDetection,
    search: &EdgeSearch,
    surface: Option<&SurfaceLine>,
    min_quality: f64,
) -> Vec<(crate::Circle, Refined)> {
    let wide = EdgeSearch {
        half_width: search.half_width.max(6.0),
        ..search.clone()
    };
    let mut out: Vec<(crate::Circle, Refined)> = Vec::new();
    for c in crate::detect_circles(img, detection) {
        // A vote peak next to a circle already refined would converge onto it again.
        if out
            .iter()
            .any(|o| (o.0.x - c.x).hypot(o.0.y - c.y) < 0.1 * c.r && (o.0.r - c.r).abs() < 0.1 * c.r)
        {
            continue;
        }
        let Some(f) = refine_circle(img, c.x, c.y, c.r, &wide, surface) else {
            continue;
        };
        let f = grow_outward(img, f, &wide, surface, detection.max_radius);
        let (q, fit) = (f.quality(), f.fit);
        if q < min_quality || fit.r < detection.min_radius * 0.95 || fit.r > detection.max_radius * 1.05 {
            continue;
        }
        let same =
            |o: &(crate::Circle, Refined)| (o.0.x - fit.x).hypot(o.0.y - fit.y) < 2.0 && (o.0.r - fit.r).abs() < 2.0;
        if out.iter().any(same) {
            continue;
        }
        out.push((
            crate::Circle {
                x: fit.x,
                y: fit.y,
                r: fit.r,
                support: q,
            },
            f,
        ));
    }
    let kept = crate::outermost(&out.iter().map(|c| c.0).collect::<Vec<_>>());
    out.retain(|c| kept.contains(&c.0));
    // An object's outline separates it from what is behind: the brightness just inside differs from just
    // outside all round. A seam drawn on the ball has felt on both sides. Of two overlapping circles (a seam
    // and the rim it lies on), drop the one with less than half the other's silhouette contrast; separate
    // objects elsewhere in the frame do not compete.
    let silhouettes: Vec<f64> = out.iter().map(|c| silhouette_contrast(img, &c.0)).collect();
    let overlaps = |a: &crate::Circle, b: &crate::Circle| (a.x - b.x).hypot(a.y - b.y) < 0.5 * (a.r + b.r);
    let keep: Vec<bool> = (0..out.len())
        .map(|i| {
            !(0..out.len()).any(|j| j != i && overlaps(&out[i].0, &out[j].0) && silhouettes[i] < 0.5 * silhouettes[j])
        })
        .collect();
    let mut k = 0;
    out.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    out.sort_by(|a, b| b.0.support.total_cmp(&a.0.support));
    out
}

/// The outermost clean circle around `f`: a ball's seam or shading can form a circle inside the ball; the
/// ball's own rim is a larger circle containing it that is at least about as clean. Tries a few larger
/// radii from the same centre and takes the first such circle, until none is found.
fn grow_outward<P: Pixel>(
    img: &Plane<P>,
    mut f: Refined,
    search: &EdgeSearch,
    surface: Option<&SurfaceLine>,
    max_r: f64,
) -> Refined {
    for _ in 0..4 {
        let c = f.fit;
        let grown = [1.12, 1.25, 1.4].iter().find_map(|k| {
            let r = c.r * k;
            if r > max_r * 1.05 {
                return None;
            }
            let g = refine_circle(img, c.x, c.y, r, search, surface)?;
            let contains = (g.fit.x - c.x).hypot(g.fit.y - c.y) + c.r <= g.fit.r * 1.03 + 2.0;
            (g.fit.r > c.r + 2.0 && contains && g.quality() >= 0.9 * f.quality() && g.quality() >= 0.5).then_some(g)
        });
        match grown {
            Some(g) => f = g,
            None => break,
        }
    }
    f
}

/// Median over 64 directions of |mean brightness 3–6 px inside the circle − 3–6 px outside|, 0–255 scale.
fn silhouette_contrast<P: Pixel>(img: &Plane<P>, c: &crate::Circle) -> f64 {
    let mut diffs: Vec<f64> = (0..64)
        .filter_map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 64.0;
            let (dx, dy) = (a.cos(), a.sin());
            let mean = |from: f64, to: f64| -> Option<f64> {
                let mut sum = 0.0;
                for i in 0..4 {
                    let d = c.r + from + (to - from) * i as f64 / 3.0;
                    sum += img.sample((c.x + d * dx) as f32, (c.y + d * dy) as f32)? as f64;
                }
                Some(sum / 4.0)
            };
            Some((mean(-6.0, -3.0)? - mean(3.0, 6.0)?).abs())
        })
        .collect();
    if diffs.is_empty() {
        return 0.0;
    }
    let mid = diffs.len() / 2;
    *diffs.select_nth_unstable_by(mid, f64::total_cmp).1
}
