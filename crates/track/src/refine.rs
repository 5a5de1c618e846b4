//! Sub-pixel centre and radius from edge points found along rays from a first guess.
//!
//! Along each of `rays` directions the image is sampled (bilinear) across the expected rim; the edge is the
//! strongest change of brightness, or the outer side of a thin band it starts (a dark limb, a ring under a
//! bright limb) when the neighbouring rays see the same band, located to a fraction of a pixel by a parabola
//! through the derivative's peak. Rays whose rim point lies at or below the surface line are skipped (that
//! part of the ball is pressed into or hidden by the surface), and so are rays leaving the image. The edge
//! points then go to the robust circle fit. Cost: rays × samples bilinear reads (128 × 17 ≈ 2,200, ≈ 10 µs,
//! for the default ±4 px; 16 more a ray with [`EdgeSearch::beyond_window`]) plus the fit.

use crate::circle_fit::{CircleFit, fit_circle};
use crate::plane::{Pixel, Plane, parabola_offset};
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
    /// Rays whose rim point lies less than this above the surface line are skipped, px (default 2; a
    /// ragged band's [`SurfaceLine::ragged_reach_px`] is added).
    pub surface_margin: f64,
    /// Also measure [`Refined::edge_definition_px`] (default false: it costs ≈ 3 µs a frame and the scale
    /// needs it in a few dozen frames only).
    pub edge_definition: bool,
    /// The rim's own shape (see [`RimShape`]), subtracted from each ray's edge distance; `None` for a
    /// perfect circle (default).
    pub rim_shape: Option<RimShape>,
    /// Sample the rays through a 3 × 3 binomial filter ([`Plane::sample_smooth_inside`]): in heavy sensor
    /// noise a single noisy sample otherwise out-steps a soft rim (default false; the clip tracker turns it
    /// on when a frame's noise exceeds `NOISY_SIGMA`, 5 on the 0–255 scale).
    pub smooth: bool,
    /// Also sample each ray 8 px beyond the window's outer end, so that a band's outer side within
    /// `LIMB_PX` (6 px) of the strongest step, and the level 2 px past it, are seen there too (default true). A
    /// search sitting on a wide limb's inner side sees the rim outside it only so; a settled track, whose
    /// window already sits on the rim, turns it off (sampled in every frame, they cost +80 % on the track
    /// bench's steady case).
    pub beyond_window: bool,
}

/// Sensor noise σ (0–255 scale) above which rays are sampled smoothed: where the per-sample noise of a
/// central difference reaches the step of a soft, dim rim (a few DN per px).
pub const NOISY_SIGMA: f32 = 5.0;

impl Default for EdgeSearch {
    fn default() -> Self {
        EdgeSearch {
            rays: 128,
            half_width: 4.0,
            step: 0.5,
            min_contrast: 2.0,
            surface_margin: 2.0,
            edge_definition: false,
            rim_shape: None,
            smooth: false,
            beyond_window: true,
        }
    }
}

/// How the ball's apparent rim departs from a circle, learned where the whole rim is seen.
///
/// Lighting and the limb's shading move the edge a little differently at each angle (0.1 px here and there
/// on a lit felt ball). Over the whole rim the constant and first-harmonic parts of that are absorbed by the
/// circle's radius and centre, and the rest averages out; but when the surface hides the bottom, the
/// remaining arc's uneven offsets pull the centre (≈ 0.02 px on the renderer's clay: 8 µm, the size of a
/// contact effect). So the mean residual per ray over free-flight frames, less its mean and first
/// harmonic, is subtracted from the edge points of every later frame whose rim is partly hidden, which is
/// then measured on the same rim as in flight (full-rim frames are measured without it). The shape is
/// fixed to the camera (the light does not turn with the ball), and a texture turning with the ball
/// averages out of it.
#[derive(Debug, Clone, PartialEq)]
pub struct RimShape {
    /// Offset per ray, px (ray `i` at angle `i·2π/len` from +x towards +y), positive outward.
    pub offsets_px: std::sync::Arc<[f64]>,
}

impl RimShape {
    /// The RMS of the offsets over the rim, px: how far the apparent rim strays from a circle.
    pub fn rms_px(&self) -> f64 {
        let n = self.offsets_px.len().max(1) as f64;
        (self.offsets_px.iter().map(|o| o * o).sum::<f64>() / n).sqrt()
    }
}

/// Highest harmonic of the rim's shape kept (see [`RimShapeLearner::shape`]).
const RIM_HARMONICS: usize = 8;

/// Accumulates per-ray edge residuals of full-rim frames into a [`RimShape`].
#[derive(Debug, Clone, Default)]
pub struct RimShapeLearner {
    sum: Vec<f64>,
    count: Vec<u32>,
    frames: usize,
    /// `(sin kθ_i, cos kθ_i)` for k = 1..=RIM_HARMONICS (row k − 1) and every ray i: the shape is rebuilt
    /// after every learning frame, and these would otherwise be most of its cost.
    harmonics: Vec<Vec<(f64, f64)>>,
}

impl RimShapeLearner {
    /// Frames added so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Adds one frame's residuals `(ray, edge distance − radius)` from [`rim_residuals`].
    pub fn add(&mut self, rays: usize, residuals: &[(usize, f64)]) {
        if self.sum.len() != rays {
            let angle = |i: usize| std::f64::consts::TAU * i as f64 / rays as f64;
            *self = RimShapeLearner {
                sum: vec![0.0; rays],
                count: vec![0; rays],
                frames: 0,
                harmonics: (1..=RIM_HARMONICS)
                    .map(|k| (0..rays).map(|i| (k as f64 * angle(i)).sin_cos()).collect())
                    .collect(),
            };
        }
        for &(i, e) in residuals {
            if i < rays {
                self.sum[i] += e;
                self.count[i] += 1;
            }
        }
        self.frames += 1;
    }

    /// The shape so far: the mean residual per ray less its least-squares mean and first harmonic, then
    /// its harmonics 2 to 8 only. `None` before any frame, or when fewer than half the rays were measured.
    pub fn shape(&self) -> Option<RimShape> {
        let n = self.sum.len();
        let seen = self.count.iter().filter(|&&c| c > 0).count();
        if n == 0 || seen * 2 < n {
            return None;
        }
        let trig = |k: usize, i: usize| self.harmonics[k - 1][i];
        let mean = |i: usize| self.sum[i] / self.count[i] as f64;
        // The mean residual per measured ray less its least-squares mean and first harmonic.
        let coef = crate::circle_fit::first_harmonic((0..n).filter(|&i| self.count[i] > 0).map(|i| {
            let (s, c) = trig(1, i);
            (c, s, mean(i))
        }))?;
        let rest: Vec<f64> = (0..n)
            .map(|i| {
                if self.count[i] == 0 {
                    return 0.0;
                }
                let (s, c) = trig(1, i);
                mean(i) - coef[0] - coef[1] * c - coef[2] * s
            })
            .collect();
        // Light and shading vary slowly round the rim; the felt's texture does not. Only harmonics 2 to
        // RIM_HARMONICS are kept, so the shape is not the texture seen in the learning frames.
        let mut offsets = vec![0.0; n];
        for k in 2..=RIM_HARMONICS.min(n / 2 - 1) {
            let (mut a, mut b) = (0.0, 0.0);
            for (i, r) in rest.iter().enumerate() {
                let (s, c) = trig(k, i);
                a += r * c;
                b += r * s;
            }
            let (a, b) = (2.0 * a / seen as f64, 2.0 * b / seen as f64);
            for (i, o) in offsets.iter_mut().enumerate() {
                let (s, c) = trig(k, i);
                *o += a * c + b * s;
            }
        }
        Some(RimShape {
            offsets_px: offsets.into(),
        })
    }
}

/// Per-ray edge residuals `(ray, distance from the fitted centre − fitted radius)` around `fit`, px, with
/// the rays of `search` but no rim shape applied; points beyond 3 robust RMS of the fit are left out (a seam
/// crossing the rim). Cost: one edge search (≈ 10 µs); the tracker takes them from its own search instead
/// (`refine_circle_with_rays`).
pub fn rim_residuals<P: Pixel>(
    img: &Plane<P>,
    fit: &CircleFit,
    search: &EdgeSearch,
    surface: Option<&SurfaceLine>,
) -> Vec<(usize, f64)> {
    let raw = EdgeSearch {
        rim_shape: None,
        edge_definition: false,
        ..search.clone()
    };
    let mut rays = Vec::new();
    let Some(refit) = refine_once(img, fit.x, fit.y, fit.r, &raw, 2.0, surface, Some(&mut rays)) else {
        return Vec::new();
    };
    residuals_about(&refit.fit, &rays)
}

/// The residuals `(ray, distance from the centre − radius)` of edge points `(ray, point)` about `fit`, px,
/// without those beyond 3 robust RMS of the fit.
pub(crate) fn residuals_about(fit: &CircleFit, rays: &[(usize, [f64; 2])]) -> Vec<(usize, f64)> {
    let limit = 3.0 * fit.rms.max(0.02);
    rays.iter()
        .map(|&(i, p)| (i, (p[0] - fit.x).hypot(p[1] - fit.y) - fit.r))
        .filter(|(_, e)| e.abs() < limit)
        .collect()
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

    /// [`Refined::quality`] over the rays that could see the rim: those outside the image or below the
    /// surface line are not counted against it (a ball leaving the frame or sinking into the surface keeps
    /// the quality of the rim it still shows).
    pub fn visible_quality(&self) -> f64 {
        let visible = self.rays.saturating_sub(self.rays_outside + self.rays_hidden).max(1);
        (self.fit.inliers as f64 / visible as f64).min(1.0) * (self.contrast as f64 / 10.0).min(1.0)
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
    refine_circle_with_rays(img, x, y, r, search, surface, None)
}

/// [`refine_circle`], leaving in `rays` the edge points `(ray, [x, y])` the returned fit was made of, as
/// found (before any rim-shape correction); empty when there is no fit.
pub(crate) fn refine_circle_with_rays<P: Pixel>(
    img: &Plane<P>,
    x: f64,
    y: f64,
    r: f64,
    search: &EdgeSearch,
    surface: Option<&SurfaceLine>,
    mut rays: Option<&mut Vec<(usize, [f64; 2])>>,
) -> Option<Refined> {
    // Each search starts the points afresh; a search that fails leaves none (its points are not the fit's).
    let mut once = |x: f64, y: f64, r: f64, half_width: f64| {
        if let Some(v) = rays.as_deref_mut() {
            v.clear();
        }
        let found = refine_once(img, x, y, r, search, half_width, surface, rays.as_deref_mut());
        if found.is_none()
            && let Some(v) = rays.as_deref_mut()
        {
            v.clear();
        }
        found
    };
    let mut fit = once(x, y, r, search.half_width)?;
    // A guess far off the rim puts the window astride the wrong places: re-centre until it settles.
    for _ in 0..3 {
        let moved = (fit.fit.x - x).hypot(fit.fit.y - y).max((fit.fit.r - r).abs());
        if moved < 0.25 * search.half_width {
            break;
        }
        let (x, y, r) = (fit.fit.x, fit.fit.y, fit.fit.r);
        match once(x, y, r, search.half_width) {
            Some(f) => fit = f,
            None => break,
        }
    }
    let narrow = (search.half_width * 0.5).max(2.0);
    if narrow >= search.half_width {
        return Some(fit);
    }
    once(fit.fit.x, fit.fit.y, fit.fit.r, narrow).or(Some(fit))
}

#[allow(clippy::too_many_arguments)] // private; `raw_points` is only for the rim shape's residuals
fn refine_once<P: Pixel>(
    img: &Plane<P>,
    x: f64,
    y: f64,
    r: f64,
    search: &EdgeSearch,
    half_width: f64,
    surface: Option<&SurfaceLine>,
    raw_points: Option<&mut Vec<(usize, [f64; 2])>>,
) -> Option<Refined> {
    let mut edges = rim_edges(img, (x, y, r), search, half_width, surface, raw_points);
    edges.apply_rim_shape();
    let mut fit = fit_circle(&edges.points, x, y, r)?;
    inflate_for_correlated_rays(&mut fit, &edges.points, &edges.shifts);
    let mid = edges.contrasts.len() / 2;
    let contrast = *edges.contrasts.select_nth_unstable_by(mid, f32::total_cmp).1;
    let edge_definition_px = if edges.offsets.len() >= 8 {
        let mid = edges.offsets.len() / 2;
        *edges.offsets.select_nth_unstable_by(mid, f64::total_cmp).1
    } else {
        f64::NAN
    };
    Some(Refined {
        fit,
        rays_with_edge: edges.points.len(),
        rays_outside: edges.outside,
        rays_hidden: edges.hidden,
        rays: edges.rays,
        contrast,
        edge_definition_px,
    })
}

/// The edge points one pass of [`refine_once`] found along its rays, in ray order, with what each ray saw.
struct RimEdges {
    /// Rays cast.
    rays: usize,
    /// Edge points, px.
    points: Vec<[f64; 2]>,
    /// Per point: the rim-shape offset of its ray (0 without a shape), px, and the ray's direction (cos, sin).
    shifts: Vec<(f64, f64, f64)>,
    /// Per point: the edge's brightness step, 0–255 scale per px.
    contrasts: Vec<f32>,
    /// Edge definitions ([`half_level_offset`]) where measured, px.
    offsets: Vec<f64>,
    /// Rays leaving the image.
    outside: usize,
    /// Rays stopped by the surface line.
    hidden: usize,
}

impl RimEdges {
    /// Subtracts the rim shape along each ray when part of the rim is hidden; a full rim's fit absorbs what
    /// the shape corrects, so full-rim frames are measured exactly as without it (their offsets zeroed).
    fn apply_rim_shape(&mut self) {
        if self.hidden > 0 {
            for (p, &(sh, c, s)) in self.points.iter_mut().zip(&self.shifts) {
                p[0] -= sh * c;
                p[1] -= sh * s;
            }
        } else {
            self.shifts.iter_mut().for_each(|s| s.0 = 0.0);
        }
    }
}

/// Where a ray's search can run: the number of samples, or why it cannot.
enum RaySpan {
    /// Samples along the ray: those of the search window, and in all (the window and the samples beyond
    /// its outer end where a band's outer side may lie, see [`EdgeSearch::beyond_window`]).
    Samples { window: usize, total: usize },
    /// The rim point is at or below the surface line, or too little of the ray lies above it.
    Hidden,
    /// The ray leaves the image.
    Outside,
}

/// The samples along the ray from `start` in direction (c, s) about (x, y) that can be searched: `samples`
/// in the window, up to `beyond` more outside it.
#[allow(clippy::too_many_arguments)] // private; the ray's geometry and the window's two lengths
fn ray_span<P: Pixel>(
    img: &Plane<P>,
    (x, y, r): (f64, f64, f64),
    (c, s): (f64, f64),
    start: f64,
    samples: usize,
    beyond: usize,
    search: &EdgeSearch,
    surface: Option<&SurfaceLine>,
) -> RaySpan {
    // The search stops short of the surface line: below it is the band, whose own edge (and, on a ragged
    // band, its highest grains) must not be taken for the ball's rim.
    let mut len = samples + beyond;
    if let Some(line) = surface {
        let margin = search.surface_margin + line.ragged_reach_px();
        let (rx, ry) = (x + r * c, y + r * s);
        if ry > line.y_at(rx) - margin {
            return RaySpan::Hidden;
        }
        let towards = s - line.slope * c;
        if towards > 1e-9 {
            let reach = (line.y_at(x) - margin - y) / towards;
            len = len.min(((reach - start) / search.step).floor().max(0.0) as usize + 1);
            if len.min(samples) < samples / 2 + 3 {
                return RaySpan::Hidden;
            }
        }
    }
    // A straight segment is inside the image when both its ends are (with the smoothing's half pixel).
    let (wmax, hmax) = ((img.width - 1) as f64, (img.height - 1) as f64);
    let end = |len: usize| start + (len - 1) as f64 * search.step;
    let m = if search.smooth { 0.51 } else { 0.01 };
    let inside = |d: f64| {
        let (px, py) = (x + d * c, y + d * s);
        px >= m && py >= m && px < wmax - m && py < hmax - m
    };
    let window = len.min(samples);
    if !inside(start) || !inside(end(window)) {
        return RaySpan::Outside;
    }
    while len > window && !inside(end(len)) {
        len -= 1;
    }
    RaySpan::Samples { window, total: len }
}

/// Fills `profile` with the image sampled along the ray from (x, y) + start·(c, s), `step` apart.
fn sample_ray<P: Pixel>(
    img: &Plane<P>,
    profile: &mut [f32],
    (x, y): (f64, f64),
    (c, s): (f64, f64),
    start: f64,
    search: &EdgeSearch,
) {
    let (mut px, mut py) = ((x + start * c) as f32, (y + start * s) as f32);
    let (sx, sy) = ((search.step * c) as f32, (search.step * s) as f32);
    if search.smooth {
        for p in profile.iter_mut() {
            *p = img.sample_smooth_inside(px, py);
            px += sx;
            py += sy;
        }
    } else {
        for p in profile.iter_mut() {
            *p = img.sample_inside(px, py);
            px += sx;
            py += sy;
        }
    }
}

/// An edge on a ray's profile: (sample index, step per px on the 0–255 scale, sub-sample offset of the peak).
type ProfileEdge = (usize, f32, f64);

/// The ray's strongest brightness step in the search window (the profile's first `window` samples), and
/// the outer side of a band that step starts when there is one: a step of the other sign at least
/// [`RIM_STEP_SHARE`] of the strongest's size within [`LIMB_PX`] outside it, and so on outward within
/// [`THIN_BAND_PX`] of each. The band's side may lie beyond the window: a track sitting on a limb's inner
/// side would otherwise never see the rim outside it. `None` when the strongest step is weaker than
/// `search.min_contrast` or lies too near the window's ends for the parabola; no band when its side lies
/// too near the profile's end. Cost: one pass of central differences over the window, and one over the
/// band's reach.
fn ray_edges(profile: &[f32], window: usize, search: &EdgeSearch) -> Option<(ProfileEdge, Option<ProfileEdge>)> {
    let len = profile.len();
    let d = |j: usize| profile[j + 1] - profile[j - 1];
    let (mut best, mut strongest) = (0.0f32, 0);
    for (i, w) in profile[..window].windows(3).enumerate() {
        let a = (w[2] - w[0]).abs();
        if a > best {
            best = a;
            strongest = i + 1;
        }
    }
    let to_per_px = 1.0 / (2.0 * search.step as f32);
    if best * to_per_px < search.min_contrast {
        return None;
    }
    let edge = |j: usize, len: usize| -> Option<ProfileEdge> {
        if j < 2 || j + 3 > len {
            return None;
        }
        let sign = d(j).signum() as f64;
        let m = |j: usize| sign * d(j) as f64;
        Some((j, d(j).abs() * to_per_px, parabola_offset(m(j - 1), m(j), m(j + 1))))
    };
    let mut j = strongest;
    loop {
        let reach_px = if j == strongest { LIMB_PX } else { THIN_BAND_PX };
        let reach = (reach_px / search.step).round() as usize;
        let other = -d(j).signum();
        let (mut k, mut size) = (j, RIM_STEP_SHARE * best);
        for (i, w) in profile[j..].windows(3).take(reach).enumerate() {
            let (a, e) = (other * (w[2] - w[0]), j + 1 + i);
            // A band's side is a change of level that lasts; a noise spike outside a faint rim returns.
            // (Unchecked at the profile's end, where there is nothing after it.)
            let lasts = profile
                .get(e + PERSIST_SAMPLES)
                .is_none_or(|after| other * (after - profile[e - 1]) >= RIM_STEP_SHARE * best);
            if a >= size && lasts {
                (k, size) = (e, a);
            }
        }
        if k == j {
            break;
        }
        j = k;
    }
    Some((
        edge(strongest, window)?,
        if j > strongest { edge(j, len) } else { None },
    ))
}

/// How strong a step of the other sign just outside the strongest must be, as a share of it, to be the rim
/// instead. A ball can show a thin band at its silhouette, a dark limb or a dark ring under a bright limb,
/// whose inner side out-steps the silhouette (25 against 20 DN/px seen); taking that puts the rim 1–2 px
/// inside the ball. A sharpened edge's undershoot is a step of the other sign too, but a small one.
const RIM_STEP_SHARE: f32 = 0.5;

/// How far outside the strongest step a band's outer side is looked for, px. A limb darker than the
/// backdrop spans up to about 6 px on a lit felt ball of 68 px radius (the `looks` preset's S017); a band
/// under a bright limb, ≤ 2.1 px.
const LIMB_PX: f64 = 6.0;

/// How many samples past a band's side the level must still be changed by [`RIM_STEP_SHARE`] of the
/// strongest step (2 px at the default step).
const PERSIST_SAMPLES: usize = 4;

/// How far outside one side of a band the next is looked for, px (the bands seen are ≤ 2.1 px wide).
const THIN_BAND_PX: f64 = 3.0;

/// How closely a ray within two of it must agree on a band's width for a ray to take its band's outer side,
/// px. A band on the ball runs along the rim; a noise spike outside a weak rim looks like a band on one ray
/// and would push every weak rim outward.
const BAND_AGREEMENT_PX: f64 = 0.75;

/// What one ray saw, kept between [`rim_edges`]'s two passes.
struct RaySeen {
    ray: usize,
    dir: (f64, f64),
    /// The strongest step and its edge definition ([`half_level_offset`], samples) when asked for.
    strongest: (ProfileEdge, Option<f64>),
    /// The band's outer side, likewise.
    band: Option<(ProfileEdge, Option<f64>)>,
}

impl RaySeen {
    /// The band's width (outer side's distance outside the strongest step), samples.
    fn band_width(&self) -> Option<f64> {
        let at = |e: &ProfileEdge| e.0 as f64 + e.2;
        self.band.map(|b| at(&b.0) - at(&self.strongest.0))
    }
}

/// The rim's edge along each of `search.rays` rays about the guess (x, y, r), searched ± `half_width`
/// across it; `raw_points` also receives each edge as (ray, point). A ray's edge is its strongest step, or
/// the outer side of the thin band that step starts when a ray within two of it sees a band of the same
/// width ([`ray_edges`], [`BAND_AGREEMENT_PX`]).
fn rim_edges<P: Pixel>(
    img: &Plane<P>,
    (x, y, r): (f64, f64, f64),
    search: &EdgeSearch,
    half_width: f64,
    surface: Option<&SurfaceLine>,
    mut raw_points: Option<&mut Vec<(usize, [f64; 2])>>,
) -> RimEdges {
    let n = search.rays.max(8);
    let shape = search
        .rim_shape
        .as_ref()
        .map(|s| &s.offsets_px[..])
        .filter(|o| o.len() == n);
    let samples = ((2.0 * half_width / search.step).round() as usize).max(4) + 1;
    let beyond = if search.beyond_window {
        (LIMB_PX / search.step).round() as usize + PERSIST_SAMPLES
    } else {
        0
    };
    let mut profile = vec![0.0f32; samples + beyond];
    let mut seen: Vec<RaySeen> = Vec::with_capacity(n);
    let mut edges = RimEdges {
        rays: n,
        points: Vec::with_capacity(n),
        shifts: Vec::with_capacity(n),
        contrasts: Vec::with_capacity(n),
        offsets: Vec::with_capacity(n),
        outside: 0,
        hidden: 0,
    };
    let start = r - half_width;
    // Ray directions by rotating one unit vector: no sin/cos per ray.
    let (dc, ds) = (std::f64::consts::TAU / n as f64).sin_cos();
    let (dc, ds) = (ds, dc); // (cos Δ, sin Δ)
    let (mut c, mut s) = (1.0f64, 0.0f64);
    for ray in 0..n {
        let (c0, s0) = (c, s);
        (c, s) = (c0 * dc - s0 * ds, s0 * dc + c0 * ds);
        let (c, s) = (c0, s0);
        let (window, len) = match ray_span(img, (x, y, r), (c, s), start, samples, beyond, search, surface) {
            RaySpan::Samples { window, total } => (window, total),
            RaySpan::Hidden => {
                edges.hidden += 1;
                continue;
            }
            RaySpan::Outside => {
                edges.outside += 1;
                continue;
            }
        };
        let profile = &mut profile[..len];
        sample_ray(img, profile, (x, y), (c, s), start, search);
        let Some((strongest, band)) = ray_edges(profile, window, search) else {
            continue;
        };
        // The strongest step's definition on the window alone, as without the samples beyond it.
        let definition = |e: ProfileEdge, profile: &[f32]| {
            let o = search
                .edge_definition
                .then(|| half_level_offset(profile, e.0, e.0 as f64 + e.2));
            (e, o.flatten())
        };
        seen.push(RaySeen {
            ray,
            dir: (c, s),
            strongest: definition(strongest, &profile[..window]),
            band: band.map(|b| definition(b, profile)),
        });
    }
    // Rays in ray order with gaps: a neighbour is found by its ray number.
    let width_of = |ray: usize| {
        seen.binary_search_by_key(&ray, |r| r.ray)
            .ok()
            .and_then(|i| seen[i].band_width())
    };
    for ray_seen in &seen {
        let ray = ray_seen.ray;
        let agreed = ray_seen.band_width().is_some_and(|w| {
            [n - 2, n - 1, 1, 2]
                .iter()
                .any(|&k| width_of((ray + k) % n).is_some_and(|wk| (wk - w).abs() * search.step <= BAND_AGREEMENT_PX))
        });
        let ((best_j, per_px, off), definition) = match ray_seen.band {
            Some(band) if agreed => band,
            _ => ray_seen.strongest,
        };
        let (c, s) = ray_seen.dir;
        let d = start + (best_j as f64 + off) * search.step;
        if let Some(raw) = raw_points.as_deref_mut() {
            raw.push((ray, [x + d * c, y + d * s]));
        }
        edges.points.push([x + d * c, y + d * s]);
        edges.shifts.push((shape.map_or(0.0, |o| o[ray]), c, s));
        edges.contrasts.push(per_px);
        if let Some(o) = definition {
            edges.offsets.push(o * search.step);
        }
    }
    edges
}

/// How far an edge may lie from the circle for its ray to count as seeing the rim, px: the edge search's
/// own scatter on a soft, noisy rim is a few tenths of a pixel, and a circle fitted to the arc above a
/// line extrapolates its bottom to a fraction of one, while a ray on something else finds its strongest
/// step anywhere in the ±4 px window (within 0.75 px of the circle one time in five).
const RIM_SEEN_PX: f64 = 0.75;

/// What the rays of a circle saw of its rim in a band just below a line, against what they saw above it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct RimAboutLine {
    /// Rays whose rim point lies in the band below the line (past the line's margin, `depth_px` deep).
    pub below: usize,
    /// Of those, the rays whose edge lies within [`RIM_SEEN_PX`] of the circle.
    pub below_seen: usize,
    /// Rays whose rim point lies above the line's margin.
    pub above: usize,
    /// Of those, the rays whose edge lies within [`RIM_SEEN_PX`] of the circle.
    pub above_seen: usize,
}

impl RimAboutLine {
    /// Whether enough rays lie below the line to tell anything: at least 6.
    pub fn tells(&self) -> bool {
        self.below >= 6
    }

    /// Whether the rim goes on below the line as it runs above it: rays enough below it ([`Self::tells`]),
    /// half of them seeing the rim, and seeing it at least 0.6 times as often as the rays above. A surface's
    /// band hides the ball's rim below its top, or replaces it with its own texture, whose strongest steps
    /// fall on the circle by chance only (about one ray in four or five).
    pub fn rim_goes_on(&self) -> bool {
        let share = |seen: usize, of: usize| seen as f64 / of.max(1) as f64;
        self.tells()
            && 2 * self.below_seen >= self.below
            && share(self.below_seen, self.below) >= 0.6 * share(self.above_seen, self.above)
    }
}

/// The rim of circle (x, y, r) searched on every ray, the surface ignored, and counted against `line`: the
/// rays whose rim point lies below the line by more than its margin (`search.surface_margin` and the line's
/// ragged reach, within which [`refine_circle`] hides a ray either way) and at most `depth_px` more, and the
/// rays above it by more than the margin, each with how many
/// found their edge on the circle. Tells a line the ball passes in front of (a ruler's edge, a shelf) from
/// the surface it lands on. Cost: one edge search round the rim (≈ 10 µs).
pub(crate) fn rim_about_line<P: Pixel>(
    img: &Plane<P>,
    (x, y, r): (f64, f64, f64),
    search: &EdgeSearch,
    line: &SurfaceLine,
    depth_px: f64,
) -> RimAboutLine {
    let mut raw = Vec::new();
    let plain = EdgeSearch {
        rim_shape: None,
        ..search.clone()
    };
    rim_edges(img, (x, y, r), &plain, plain.half_width, None, Some(&mut raw));
    let n = plain.rays.max(8);
    let margin = plain.surface_margin + line.ragged_reach_px();
    let mut seen = vec![false; n];
    for &(ray, [px, py]) in &raw {
        seen[ray] = ((px - x).hypot(py - y) - r).abs() <= RIM_SEEN_PX;
    }
    let mut about = RimAboutLine::default();
    for (ray, &on_rim) in seen.iter().enumerate() {
        let (s, c) = (std::f64::consts::TAU * ray as f64 / n as f64).sin_cos();
        let (rx, ry) = (x + r * c, y + r * s);
        let below = ry - line.y_at(rx);
        if below <= -margin {
            about.above += 1;
            about.above_seen += usize::from(on_rim);
        } else if below > margin && below <= margin + depth_px {
            about.below += 1;
            about.below_seen += usize::from(on_rim);
        }
    }
    about
}

/// Neighbouring rays see overlapping texture, so their edge errors are correlated and the fit's σ (which
/// assumes independent points) is optimistic: σ is inflated by the AR(1) factor √((1+ρ)/(1−ρ)), with ρ the
/// lag-1 correlation of the residuals around the rim (points are in ray order), measured on this frame.
///
/// With a rim shape the residuals are taken before its correction: the part of the rim's departure from a
/// circle that the shape cannot hold (its mean and first harmonic, which move the radius and centre exactly
/// as a shift would) is of the size of the part it corrects, so σ keeps both.
fn inflate_for_correlated_rays(fit: &mut CircleFit, points: &[[f64; 2]], shifts: &[(f64, f64, f64)]) {
    let (res, corrected): (Vec<f64>, Vec<f64>) = points
        .iter()
        .zip(shifts)
        .map(|(p, (sh, _, _))| {
            let e = (p[0] - fit.x).hypot(p[1] - fit.y) - fit.r;
            (e + sh, e)
        })
        .filter(|(_, e)| e.abs() < 3.0 * fit.rms.max(0.02))
        .unzip();
    if res.len() > 8 {
        let m = res.iter().sum::<f64>() / res.len() as f64;
        let var: f64 = res.iter().map(|e| (e - m).powi(2)).sum();
        let lag: f64 = res.windows(2).map(|w| (w[0] - m) * (w[1] - m)).sum();
        let rho = (lag / var.max(1e-300)).clamp(0.0, 0.8);
        let mc = corrected.iter().sum::<f64>() / corrected.len() as f64;
        let var_corrected: f64 = corrected.iter().map(|e| (e - mc).powi(2)).sum();
        let spread = (var / var_corrected.max(1e-300)).sqrt().max(1.0);
        let k = ((1.0 + rho) / (1.0 - rho)).sqrt() * spread;
        fit.sigma_x *= k;
        fit.sigma_y *= k;
        fit.sigma_r *= k;
    }
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
    // Most vote peaks are texture, not circles. Each is first followed to where it settles with a quarter of
    // the rays (the wide, re-centring searches are most of the cost), and only a peak that is still a
    // plausible circle there (half the quality asked for: a quarter of the rays measures the kept fraction to
    // about ±0.08) is measured with every ray.
    refine_candidates(
        img,
        crate::detect_circles(img, detection),
        detection,
        search,
        surface,
        min_quality,
    )
}

/// [`refined_candidates`] from vote peaks found elsewhere (e.g. on the part of the frame that moves): each
/// peak refined on `img` (followed with a quarter of the rays, grown out to a containing rim, measured with
/// every ray), duplicates merged, nested and seam-like circles dropped. Best first. With
/// [`CircleDetection::beyond_edge`](crate::CircleDetection::beyond_edge) a circle is judged by its
/// [`Refined::visible_quality`] (the rays that leave the frame are not counted against it), else by its
/// [`Refined::quality`].
pub fn refine_candidates<P: Pixel>(
    img: &Plane<P>,
    peaks: Vec<crate::Circle>,
    detection: &crate::CircleDetection,
    search: &EdgeSearch,
    surface: Option<&SurfaceLine>,
    min_quality: f64,
) -> Vec<(crate::Circle, Refined)> {
    // Candidates are judged on the edges within their windows alone: in heavy noise, sides found beyond them
    // let large circles of noise out-score the ball (a 147 px circle was taken for an 84 px ball at 20 DN).
    let wide = EdgeSearch {
        half_width: search.half_width.max(6.0),
        beyond_window: false,
        ..search.clone()
    };
    let screen = EdgeSearch {
        rays: (search.rays / 4).max(16),
        ..wide.clone()
    };
    let settled = settled_search(search);
    // A circle centred beyond the frame's edge is judged on the rim the frame can show.
    let quality = |f: &Refined| {
        if detection.beyond_edge {
            f.visible_quality()
        } else {
            f.quality()
        }
    };
    let mut out: Vec<(crate::Circle, Refined)> = Vec::new();
    for c in peaks {
        // A vote peak next to a circle already refined would converge onto it again.
        if out
            .iter()
            .any(|o| (o.0.x - c.x).hypot(o.0.y - c.y) < 0.1 * c.r && (o.0.r - c.r).abs() < 0.1 * c.r)
        {
            continue;
        }
        let Some(f) = refine_circle(img, c.x, c.y, c.r, &screen, surface) else {
            continue;
        };
        if quality(&f) < 0.5 * min_quality {
            continue;
        }
        let f = grow_outward(img, f, &screen, surface, detection.max_radius);
        let Some(f) = refine_circle(img, f.fit.x, f.fit.y, f.fit.r, &settled, surface) else {
            continue;
        };
        let (q, fit) = (quality(&f), f.fit);
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

/// The search a candidate is measured with at the end, once followed to where it settles: half the
/// candidates' window (at least 6 px, so ±3 px), on the window's edges alone (see [`refine_candidates`]).
pub(crate) fn settled_search(search: &EdgeSearch) -> EdgeSearch {
    EdgeSearch {
        half_width: 0.5 * search.half_width.max(6.0),
        beyond_window: false,
        ..search.clone()
    }
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
        let grown = [1.06, 1.12, 1.25, 1.4].iter().find_map(|k| {
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

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: usize = 220;

    /// A bright disc on a dark backdrop whose rim departs from the circle (`cx`, `cy`, `r`) by
    /// 0.3·cos 2θ + 0.15·sin 3θ px (no mean, no first harmonic: the circle is its best fit), an edge ramp
    /// 1.5 px wide, and a flat band below `line_y` hiding the disc there.
    fn lit_ball(cx: f64, cy: f64, r: f64, line_y: Option<f64>) -> Vec<u8> {
        let mut img = vec![0u8; SIZE * SIZE];
        for (k, v) in img.iter_mut().enumerate() {
            let (x, y) = ((k % SIZE) as f64, (k / SIZE) as f64);
            if line_y.is_some_and(|l| y >= l) {
                *v = 110;
                continue;
            }
            let (dx, dy) = (x - cx, y - cy);
            let th = dy.atan2(dx);
            let edge = r + 0.3 * (2.0 * th).cos() + 0.15 * (3.0 * th).sin();
            let inside = (0.5 - (dx.hypot(dy) - edge) / 1.5).clamp(0.0, 1.0);
            *v = (40.0 + 160.0 * inside).round() as u8;
        }
        img
    }

    fn line_at(y: f64) -> SurfaceLine {
        SurfaceLine {
            x0: SIZE as f64 / 2.0,
            y0: y,
            slope: 0.0,
            sigma_y0: 0.0,
            sigma_tilt_deg: 0.0,
            columns: SIZE,
            edge_definition_px: 0.0,
            roughness_px: 0.0,
            cue: Default::default(),
            level_shift_px: 0.0,
        }
    }

    #[test]
    fn a_learned_rim_shape_keeps_a_partly_hidden_ball_on_its_full_rim_centre() {
        let search = EdgeSearch::default();
        let mut learner = RimShapeLearner::default();
        for k in 0..8 {
            let (cx, cy) = (105.0 + 0.37 * k as f64, 90.0 + 0.21 * k as f64);
            let img = lit_ball(cx, cy, 60.0, None);
            let plane = Plane::new(&img, SIZE, SIZE);
            let f = refine_circle(&plane, cx + 0.4, cy - 0.3, 60.0, &search, None).unwrap();
            learner.add(search.rays, &rim_residuals(&plane, &f.fit, &search, None));
        }
        let shaped = EdgeSearch {
            rim_shape: learner.shape(),
            ..search.clone()
        };
        assert!(shaped.rim_shape.is_some());
        let (cx, cy) = (110.3, 100.6);
        let err = |f: CircleFit| (f.x - cx).hypot(f.y - cy);
        // Full rim: the shape is not applied (the fit absorbs what it would correct).
        let img = lit_ball(cx, cy, 60.0, None);
        let plane = Plane::new(&img, SIZE, SIZE);
        let plain = refine_circle(&plane, cx, cy, 60.0, &search, None).unwrap().fit;
        let with = refine_circle(&plane, cx, cy, 60.0, &shaped, None).unwrap().fit;
        assert_eq!((plain.x, plain.y, plain.r), (with.x, with.y, with.r));
        assert!(err(plain) < 0.04, "{plain:?}");
        // The bottom fifth hidden: without the shape the remaining arc's offsets pull the centre.
        let line = line_at(cy + 0.6 * 60.0);
        let img = lit_ball(cx, cy, 60.0, Some(line.y0));
        let plane = Plane::new(&img, SIZE, SIZE);
        let plain = refine_circle(&plane, cx, cy, 60.0, &search, Some(&line)).unwrap().fit;
        let with = refine_circle(&plane, cx, cy, 60.0, &shaped, Some(&line)).unwrap().fit;
        eprintln!(
            "hidden bottom: centre error {:.4} px plain, {:.4} px with the shape",
            err(plain),
            err(with)
        );
        assert!(
            err(plain) > 0.05,
            "the test's rim should pull a partial fit: {}",
            err(plain)
        );
        assert!(err(with) < 0.25 * err(plain), "{} vs {}", err(with), err(plain));
    }

    /// An image of `level(distance from (cx, cy), above the centre)` sampled 4 × 4 per pixel.
    fn drawn(cx: f64, cy: f64, level: impl Fn(f64, bool) -> f64) -> Vec<u8> {
        (0..SIZE * SIZE)
            .map(|k| {
                let (px, py) = ((k % SIZE) as f64, (k / SIZE) as f64);
                let mut sum = 0.0;
                for i in 0..16 {
                    let (x, y) = (px - 0.375 + 0.25 * (i % 4) as f64, py - 0.375 + 0.25 * (i / 4) as f64);
                    sum += level((x - cx).hypot(y - cy), y < cy);
                }
                (sum / 16.0).round() as u8
            })
            .collect()
    }

    #[test]
    fn the_rim_is_the_silhouette_not_a_ring_or_dark_limb_inside_it() {
        let (cx, cy, r) = (108.4, 104.7, 70.0);
        type Level = Box<dyn Fn(f64, bool) -> f64>;
        // Lit from behind: bright on top; below, as dim as the backdrop with a dark ring (70) inside a bright
        // limb (118), the ring's inner side the strongest step.
        let bright_limb = move |d: f64, top: bool| match d {
            d if d > r => 90.0,
            _ if top => 190.0,
            d if d > r - 1.4 => 118.0,
            d if d > r - 2.6 && d < r - 1.6 => 70.0,
            _ => 100.0,
        };
        let looks: [(&str, Level); 4] = [
            ("bright limb", Box::new(bright_limb)),
            // The same mirrored about 128: a ball darker than its backdrop.
            ("mirrored", Box::new(move |d, top| 256.0 - bright_limb(d, top))),
            // A light ball whose limb is darker than the backdrop, the limb's inner side the stronger step.
            (
                "dark limb",
                Box::new(move |d, _| match d {
                    d if d > r => 120.0,
                    d if d > r - 2.0 => 70.0,
                    _ => 150.0,
                }),
            ),
            // Lit from above: lighter than the backdrop on top, darker below.
            (
                "shaded",
                Box::new(move |d, top| match d {
                    d if d > r => 110.0,
                    _ if top => 190.0,
                    _ => 50.0,
                }),
            ),
        ];
        for (look, level) in &looks {
            let img = drawn(cx, cy, level);
            let plane = Plane::new(&img, SIZE, SIZE);
            // The guess 1 px small, as a track that had settled inside the rim would give.
            let f = refine_circle(&plane, cx, cy - 0.5, r - 1.0, &EdgeSearch::default(), None)
                .unwrap()
                .fit;
            let (centre, radius) = ((f.x - cx).hypot(f.y - cy), f.r - r);
            assert!(centre < 0.1 && radius.abs() < 0.1, "{look}: {f:?}");
        }
    }

    #[test]
    fn a_search_sitting_on_a_wide_dark_limb_s_inner_side_finds_the_rim_outside_it() {
        // A light ball whose limb, 5 px wide, is darker than the backdrop (the `looks` preset's S017): the
        // limb's inner side is the stronger step. A track that settled there searches ±2 px about it, a
        // window that does not reach the rim; the rim is still found outside it, and the circle moves out.
        let (cx, cy, r) = (108.4, 104.7, 70.0);
        let img = drawn(cx, cy, |d, _| match d {
            d if d > r => 120.0,
            d if d > r - 5.0 => 70.0,
            _ => 150.0,
        });
        let plane = Plane::new(&img, SIZE, SIZE);
        let search = EdgeSearch {
            half_width: 2.0,
            ..EdgeSearch::default()
        };
        let f = refine_circle(&plane, cx, cy, r - 5.0, &search, None).unwrap().fit;
        let (centre, radius) = ((f.x - cx).hypot(f.y - cy), f.r - r);
        assert!(centre < 0.1 && radius.abs() < 0.1, "{f:?}");
    }

    #[test]
    fn a_noise_spike_outside_a_rim_is_not_a_band_s_side() {
        // A single sample's spike of the other sign just outside the strongest step is as large as a band's
        // side would be, but the level after it returns: it is not taken.
        let mut profile = vec![100.0f32; 24];
        for p in profile.iter_mut().skip(8) {
            *p = 160.0;
        }
        profile[14] = 120.0;
        let (strongest, band) = ray_edges(&profile, 12, &EdgeSearch::default()).unwrap();
        assert_eq!(strongest.0, 7);
        assert!(band.is_none(), "{band:?}");
    }

    #[test]
    fn noise_outside_a_faint_rim_does_not_push_it_outward() {
        // A rim only 20 DN above the backdrop in 8 DN of noise, sampled unsmoothed: on single rays a noise
        // spike just outside looks like a band's outer side (taken on every ray alone, +0.15 px).
        let (cx, cy, r) = (108.4, 104.7, 70.0);
        let clean = drawn(cx, cy, |d, _| if d > r { 90.0 } else { 110.0 });
        let search = EdgeSearch::default();
        let mut rng = bouncelab_testkit::Rng::new(7);
        let bias: f64 = (0..12)
            .map(|_| {
                let noisy: Vec<u8> = clean
                    .iter()
                    .map(|&v| (v as f64 + 8.0 * rng.normal()).round().clamp(0.0, 255.0) as u8)
                    .collect();
                let plane = Plane::new(&noisy, SIZE, SIZE);
                refine_circle(&plane, cx, cy, r, &search, None).unwrap().fit.r - r
            })
            .sum::<f64>()
            / 12.0;
        assert!(bias.abs() < 0.05, "mean radius error {bias:+.3} px");
    }

    #[test]
    fn the_learner_needs_half_the_rays() {
        let mut learner = RimShapeLearner::default();
        assert!(learner.shape().is_none());
        learner.add(16, &[(0, 0.1), (1, 0.2), (2, -0.1)]);
        assert!(learner.shape().is_none());
        learner.add(16, &(0..16).map(|i| (i, 0.1 * (i as f64).sin())).collect::<Vec<_>>());
        let s = learner.shape().unwrap();
        assert_eq!(s.offsets_px.len(), 16);
        // Mean and first harmonic removed.
        let n = 16.0;
        let mean: f64 = s.offsets_px.iter().sum::<f64>() / n;
        let c1: f64 = s
            .offsets_px
            .iter()
            .enumerate()
            .map(|(i, o)| o * (std::f64::consts::TAU * i as f64 / n).cos())
            .sum();
        assert!(mean.abs() < 1e-12 && c1.abs() < 1e-12, "{mean} {c1}");
    }

    /// A ball in front of a dark strip whose lower edge is the line: its rim goes on below the line as it
    /// runs above it. The same ball behind a grainy band whose top is the line: the rays below it find
    /// the grains' steps, on the circle by chance only.
    #[test]
    fn the_rim_goes_on_below_a_line_behind_the_ball_not_below_a_band_in_front() {
        let (cx, cy, r, line_y) = (110.4, 100.7, 50.0, 135.0);
        let disc = lit_ball(cx, cy, r, None);
        let behind: Vec<u8> = disc
            .iter()
            .enumerate()
            .map(|(k, &v)| {
                let (x, y) = ((k % SIZE) as f64, (k / SIZE) as f64);
                let outside = (x - cx).hypot(y - cy) > r + 1.0;
                if outside && (120.0..line_y).contains(&y) { 10 } else { v }
            })
            .collect();
        let grain = |k: usize| ((k * 7919) % 97) as u8;
        let in_front: Vec<u8> = disc
            .iter()
            .enumerate()
            .map(|(k, &v)| if (k / SIZE) as f64 >= line_y { 70 + grain(k) } else { v })
            .collect();
        let search = EdgeSearch::default();
        let about = |img: &[u8]| {
            rim_about_line(
                &Plane::new(img, SIZE, SIZE),
                (cx, cy, r),
                &search,
                &line_at(line_y),
                12.5,
            )
        };
        let seen = about(&behind);
        assert!(seen.tells() && seen.rim_goes_on(), "{seen:?}");
        let hidden = about(&in_front);
        assert!(hidden.tells() && !hidden.rim_goes_on(), "{hidden:?}");
        assert_eq!((seen.below, seen.above), (hidden.below, hidden.above));
    }
}
