//! Circle candidates in a whole frame by gradient voting (the Hough transform the paper used, in the
//! gradient form): every strong edge pixel votes for the centres lying along its gradient line at every
//! radius of the range; the ball's centre collects the votes of its whole rim.
//!
//! Cost: O(pixels) for the gradient plus O(edges × radius range) votes, on an image downsampled so that
//! the smallest radius is still ≥ 12 px (one octave of radii at a time when the range is wider); ≈ 0.3–3 ms
//! for a 512×512 frame and a known radius, ≈ 22 ms for radii 8–256 px (50 ms as one band), most of it in the
//! octaves below 24 px, which cannot be downsampled. Used once per clip and after a loss.

use crate::plane::{Pixel, Plane, parabola_offset};

/// Options of [`detect_circles`].
#[derive(Debug, Clone, PartialEq)]
pub struct CircleDetection {
    /// Smallest radius to look for, px.
    pub min_radius: f64,
    /// Largest radius to look for, px.
    pub max_radius: f64,
    /// Fraction of the pixels, the strongest gradients, that vote (default 0.06).
    pub edge_fraction: f64,
    /// Most candidates returned per octave of radius (default 8).
    pub max_candidates: usize,
    /// The frame's noise σ, 0–255 scale, when known: then every gradient standing 4σ of the Sobel's noise
    /// above it votes, instead of only the strongest `edge_fraction` (default `None`). A soft, dim rim in a
    /// cluttered frame (rulers, seams, a hand) is outshone by the clutter's edges but stands well out of the
    /// noise; the price is many more votes on textured frames.
    pub noise_sigma: Option<f64>,
    /// Look only for circles centred beyond the frame's edges (default `false`: only centres inside it): a
    /// ball mostly out of view, whose centre is above the top edge while its lower rim is in the frame. Such
    /// a centre lies at most half a radius beyond an edge and needs a third of its rim inside, enough arc
    /// for a circle fit; the accumulator grows by that half radius on every side.
    pub beyond_edge: bool,
}

impl Default for CircleDetection {
    fn default() -> Self {
        CircleDetection {
            min_radius: 10.0,
            max_radius: 200.0,
            edge_fraction: 0.06,
            max_candidates: 8,
            noise_sigma: None,
            beyond_edge: false,
        }
    }
}

/// A circle candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// Centre x, px.
    pub x: f64,
    /// Centre y, px.
    pub y: f64,
    /// Radius, px.
    pub r: f64,
    /// Fraction of the circle's in-frame circumference with a radial edge on it (0–1).
    pub support: f64,
}

/// Gradient field of a (downsampled) image.
struct Gradients {
    w: usize,
    h: usize,
    gx: Vec<f32>,
    gy: Vec<f32>,
    mag: Vec<f32>,
}

fn downsample<P: Pixel>(img: &Plane<P>, f: usize) -> (Vec<f32>, usize, usize) {
    let (w, h) = (img.width / f, img.height / f);
    let mut out = vec![0.0f32; w * h];
    let norm = 1.0 / (f * f) as f32;
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for dy in 0..f {
                for dx in 0..f {
                    s += img.at(x * f + dx, y * f + dy);
                }
            }
            out[y * w + x] = s * norm;
        }
    }
    (out, w, h)
}

fn sobel(p: &[f32], w: usize, h: usize) -> Gradients {
    let mut g = Gradients {
        w,
        h,
        gx: vec![0.0; w * h],
        gy: vec![0.0; w * h],
        mag: vec![0.0; w * h],
    };
    for y in 1..h.saturating_sub(1) {
        for x in 1..w - 1 {
            let i = y * w + x;
            let (a, b, c) = (p[i - w - 1], p[i - w], p[i - w + 1]);
            let (d, f) = (p[i - 1], p[i + 1]);
            let (e, k, l) = (p[i + w - 1], p[i + w], p[i + w + 1]);
            let gx = (c + 2.0 * f + l) - (a + 2.0 * d + e);
            let gy = (e + 2.0 * k + l) - (a + 2.0 * b + c);
            g.gx[i] = gx;
            g.gy[i] = gy;
            g.mag[i] = (gx * gx + gy * gy).sqrt();
        }
    }
    g
}

/// Circle candidates in `img`, best supported first.
///
/// A radius range wider than an octave is searched an octave at a time (bands overlapping by 10 %), each
/// band on the image downsampled as far as its smallest radius allows: a vote costs the same at every
/// sampling, and a band of radii [r, 2r] at factor f casts edges/f² × r/f of them, so the bands above 24 px
/// together cost less than the full-resolution ones below it. Each band keeps its own
/// `max_candidates`, so a ball is never crowded out by the many small circles texture makes. Circles found
/// in two overlapping bands are returned once.
pub fn detect_circles<P: Pixel>(img: &Plane<P>, opts: &CircleDetection) -> Vec<Circle> {
    if img.width < 8 || img.height < 8 || !(opts.max_radius >= opts.min_radius && opts.min_radius > 0.0) {
        return Vec::new();
    }
    let mut scales: Vec<(usize, Gradients, Vec<usize>)> = Vec::new();
    let mut out: Vec<Circle> = Vec::new();
    for (lo, hi) in radius_bands(opts.min_radius, opts.max_radius) {
        let f = sampling_factor(lo);
        if !scales.iter().any(|s| s.0 == f) {
            let (p, w, h) = downsample(img, f);
            let g = sobel(&p, w, h);
            // Downsampling by f averages f² pixels; a Sobel component sums 12 of them with weights ±1, ±2.
            let floor = opts.noise_sigma.map(|s| (4.0 * 12f64.sqrt() * s / f as f64) as f32);
            let edges = strong_edges(&g, opts.edge_fraction, floor);
            scales.push((f, g, edges));
        }
        let (_, g, edges) = scales.iter().find(|s| s.0 == f).expect("just added");
        for c in detect_band(g, edges, f, (lo, hi), opts.max_candidates, opts.beyond_edge) {
            let same = |o: &Circle| (o.x - c.x).hypot(o.y - c.y) < 0.1 * c.r && (o.r - c.r).abs() < 0.1 * c.r;
            match out.iter_mut().find(|o| same(o)) {
                Some(o) if o.support < c.support => *o = c,
                Some(_) => {}
                None => out.push(c),
            }
        }
    }
    out.sort_by(|a, b| b.support.total_cmp(&a.support));
    out
}

/// The radius range `min_radius`–`max_radius` in octaves, largest first: each band spans at most a factor
/// of two, and overlaps the next by 10 % so that a circle at a band's edge lies well inside one of them.
pub fn radius_bands(min_radius: f64, max_radius: f64) -> Vec<(f64, f64)> {
    let mut bands = Vec::new();
    let mut hi = max_radius;
    loop {
        let lo = (0.5 * hi).max(min_radius);
        bands.push((lo, hi));
        if lo <= min_radius {
            return bands;
        }
        hi = 1.1 * lo;
    }
}

/// The downsampling factor for radii from `min_radius` up: the largest power of two (at most 8) that keeps
/// `min_radius` ≥ 12 px, or 1. Fewer votes, and less texture noise.
fn sampling_factor(min_radius: f64) -> usize {
    let mut f = 1;
    while min_radius / (2 * f) as f64 >= 12.0 && f < 8 {
        f *= 2;
    }
    f
}

/// The best `max_candidates` circles of radius `min_radius`–`max_radius` (full-resolution px) in the
/// gradient field `g` of the image downsampled by `f`, with its strong `edges`.
fn detect_band(
    g: &Gradients,
    edges: &[usize],
    f: usize,
    (min_radius, max_radius): (f64, f64),
    max_candidates: usize,
    beyond_edge: bool,
) -> Vec<Circle> {
    if edges.is_empty() {
        return Vec::new();
    }
    let (rmin, rmax) = (min_radius / f as f64, max_radius / f as f64);
    // The accumulator covers the frame and, for centres beyond its edges, a margin of half the largest radius
    // (plus the box filter's and the peak finder's cells) on every side.
    let margin = if beyond_edge {
        (0.5 * rmax).ceil() as usize + 2
    } else {
        0
    };
    let (w, h) = (g.w + 2 * margin, g.h + 2 * margin);
    let m = margin as f64;
    // Vote along both directions of the gradient (the ball may be brighter or darker than what is behind).
    let mut acc = vec![0.0f32; w * h];
    for &i in edges {
        let (x, y) = ((i % g.w) as f64 + m, (i / g.w) as f64 + m);
        let mag = g.mag[i] as f64;
        let (ux, uy) = (g.gx[i] as f64 / mag, g.gy[i] as f64 / mag);
        for sign in [-1.0, 1.0] {
            let mut r = rmin;
            while r <= rmax {
                let cx = (x + sign * r * ux).round();
                let cy = (y + sign * r * uy).round();
                if cx >= 0.0 && cy >= 0.0 && (cx as usize) < w && (cy as usize) < h {
                    acc[cy as usize * w + cx as usize] += 1.0;
                }
                r += 1.0;
            }
        }
    }
    let acc = box3(&acc, w, h);
    let peaks = local_maxima(&acc, w, h, (rmin * 0.25).max(2.0) as usize, max_candidates * 8);
    let mut out: Vec<Circle> = peaks
        .into_iter()
        .map(|(cx, cy)| (cx - m, cy - m))
        .filter(|&(cx, cy)| centre_in_frame(g, cx, cy) != beyond_edge)
        .filter_map(|(cx, cy)| radius_at(g, edges, cx, cy, rmin, rmax))
        .map(|(cx, cy, r, support)| Circle {
            x: (cx + 0.5) * f as f64 - 0.5,
            y: (cy + 0.5) * f as f64 - 0.5,
            r: r * f as f64,
            support,
        })
        .collect();
    out.sort_by(|a, b| b.support.total_cmp(&a.support));
    out.truncate(max_candidates);
    out
}

/// Whether (cx, cy), in the gradient field's cells, lies on a pixel of the frame.
fn centre_in_frame(g: &Gradients, cx: f64, cy: f64) -> bool {
    (-0.5..=g.w as f64 - 0.5).contains(&cx) && (-0.5..=g.h as f64 - 0.5).contains(&cy)
}

/// Indices of the gradient magnitudes above the strongest `fraction`'s threshold, or above `floor` when given,
/// that are also local maxima across the edge.
fn strong_edges(g: &Gradients, fraction: f64, floor: Option<f32>) -> Vec<usize> {
    let mut mags: Vec<f32> = g.mag.iter().copied().filter(|m| *m > 0.0).collect();
    if mags.is_empty() {
        return Vec::new();
    }
    let k = ((mags.len() as f64 * (1.0 - fraction.clamp(0.001, 1.0))) as usize).min(mags.len() - 1);
    let (_, thr, _) = mags.select_nth_unstable_by(k, f32::total_cmp);
    let thr = floor.unwrap_or(*thr).max(1e-3);
    let w = g.w;
    let mut out = Vec::new();
    for y in 1..g.h.saturating_sub(1) {
        for x in 1..w - 1 {
            let i = y * w + x;
            let m = g.mag[i];
            if m < thr {
                continue;
            }
            // Non-maximum suppression across the edge, gradient direction quantised to 45°.
            let (ax, ay) = (g.gx[i].abs(), g.gy[i].abs());
            let (di, dj) = if ax > 2.414 * ay {
                (1isize, 0isize)
            } else if ay > 2.414 * ax {
                (0, 1)
            } else if (g.gx[i] > 0.0) == (g.gy[i] > 0.0) {
                (1, 1)
            } else {
                (1, -1)
            };
            let off = dj * w as isize + di;
            let (a, b) = (g.mag[(i as isize + off) as usize], g.mag[(i as isize - off) as usize]);
            if m >= a && m >= b {
                out.push(i);
            }
        }
    }
    out
}

fn box3(a: &[f32], w: usize, h: usize) -> Vec<f32> {
    let mut out = vec![0.0; w * h];
    for y in 1..h.saturating_sub(1) {
        for x in 1..w - 1 {
            let mut s = 0.0;
            for dy in 0..3 {
                for dx in 0..3 {
                    s += a[(y + dy - 1) * w + x + dx - 1];
                }
            }
            out[y * w + x] = s;
        }
    }
    out
}

/// The `n` highest local maxima at least `sep` px apart, with sub-cell centres.
fn local_maxima(acc: &[f32], w: usize, h: usize, sep: usize, n: usize) -> Vec<(f64, f64)> {
    // Only cells at least as high as their 8 neighbours can be peaks: sorting just those is what keeps this
    // cheap on a full-resolution accumulator.
    let mut cells: Vec<(f32, usize)> = Vec::new();
    for y in 1..h.saturating_sub(1) {
        for x in 1..w - 1 {
            let i = y * w + x;
            let v = acc[i];
            if v > 0.0
                && [i - w - 1, i - w, i - w + 1, i - 1, i + 1, i + w - 1, i + w, i + w + 1]
                    .iter()
                    .all(|&j| acc[j] <= v)
            {
                cells.push((v, i));
            }
        }
    }
    cells.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut out: Vec<(usize, usize)> = Vec::new();
    for (_, i) in cells {
        if out.len() >= n {
            break;
        }
        let (x, y) = (i % w, i / w);
        if x == 0 || y == 0 || x + 1 >= w || y + 1 >= h {
            continue;
        }
        if out.iter().all(|&(ox, oy)| ox.abs_diff(x).max(oy.abs_diff(y)) > sep) {
            out.push((x, y));
        }
    }
    out.into_iter()
        .map(|(x, y)| {
            let v = |dx: isize, dy: isize| acc[(y as isize + dy) as usize * w + (x as isize + dx) as usize] as f64;
            (
                x as f64 + parabola_offset(v(-1, 0), v(0, 0), v(1, 0)),
                y as f64 + parabola_offset(v(0, -1), v(0, 0), v(0, 1)),
            )
        })
        .collect()
}

/// The radius around (cx, cy) best supported by radial edges, and the supported fraction of the in-frame
/// circumference.
fn radius_at(g: &Gradients, edges: &[usize], cx: f64, cy: f64, rmin: f64, rmax: f64) -> Option<(f64, f64, f64, f64)> {
    let bins = (rmax - rmin).ceil() as usize + 3;
    let mut hist = vec![0.0f64; bins];
    // Edges are in row order: only the rows the largest circle spans.
    let row = |y: f64| (y.max(0.0) as usize).min(g.h) * g.w;
    let (first, last) = (row(cy - rmax - 2.0), row(cy + rmax + 3.0));
    let span = &edges[edges.partition_point(|&i| i < first)..edges.partition_point(|&i| i < last)];
    for &i in span {
        let (x, y) = ((i % g.w) as f64 - cx, (i / g.w) as f64 - cy);
        let d = x.hypot(y);
        if d < rmin - 1.0 || d > rmax + 1.0 || d == 0.0 {
            continue;
        }
        let m = g.mag[i] as f64;
        let cos = (x * g.gx[i] as f64 + y * g.gy[i] as f64) / (d * m);
        if cos.abs() < 0.9 {
            continue;
        }
        let b = (d - rmin + 1.0).round() as usize;
        if b < bins {
            hist[b] += 1.0;
        }
    }
    let (best, _) = hist
        .windows(3)
        .enumerate()
        .map(|(i, w)| (i + 1, w[0] + w[1] + w[2]))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let r = best as f64 + rmin - 1.0;
    let count = hist[best - 1] + hist[best] + hist[best + 1];
    // Expected edge pixels on the in-frame part of the circumference (about one per pixel of arc).
    let steps = 360;
    let (lo, hi_x, hi_y) = (1.0 + r, (g.w - 1) as f64 - r, (g.h - 1) as f64 - r);
    let whole = cx >= lo && cy >= lo && cx < hi_x && cy < hi_y;
    let inside = if whole {
        steps
    } else {
        (0..steps)
            .filter(|k| {
                let a = *k as f64 * std::f64::consts::TAU / steps as f64;
                let (x, y) = (cx + r * a.cos(), cy + r * a.sin());
                x >= 1.0 && y >= 1.0 && x < (g.w - 1) as f64 && y < (g.h - 1) as f64
            })
            .count()
    };
    // A centre beyond the frame's edge needs a third of its rim in view (an arc of 120°) for a fit to place it.
    if inside < steps / 4 || (!centre_in_frame(g, cx, cy) && inside < steps / 3) {
        return None;
    }
    let expected = std::f64::consts::TAU * r * inside as f64 / steps as f64;
    Some((cx, cy, r, (count / expected).min(1.0)))
}

/// Keeps only the outermost of nested candidates: a circle lying inside a larger, about as well supported
/// candidate is a feature of that object (a ball's seam, a fixture's inner ring), not an object. A weak
/// larger ring (a halo, edges of the background that happen to line up) does not hide a clear circle.
pub fn outermost(circles: &[Circle]) -> Vec<Circle> {
    let inside = |c: &Circle, o: &Circle| {
        o.r > c.r + 0.5 && (c.x - o.x).hypot(c.y - o.y) + c.r <= o.r * 1.03 + 2.0 && o.support >= 0.9 * c.support
    };
    circles
        .iter()
        .filter(|c| !circles.iter().any(|o| inside(c, o)))
        .copied()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The bands cover the range without gaps, each at most an octave, largest first.
        #[test]
        fn bands_cover_the_range_in_octaves(min in 1.0f64..50.0, span in 1.0f64..40.0) {
            let max = min * span;
            let bands = radius_bands(min, max);
            prop_assert_eq!(bands[0].1, max);
            prop_assert_eq!(bands.last().unwrap().0, min);
            for (lo, hi) in &bands {
                prop_assert!(lo <= hi && *hi <= 2.0 * lo + 1e-9);
            }
            for pair in bands.windows(2) {
                // Each band reaches 10 % into the one above it.
                prop_assert!(pair[1].1 > pair[0].0);
                prop_assert!(pair[1].0 < pair[0].0);
            }
        }
    }

    /// A 200×100 frame of gray 60 with a disc of gray 180 (edge antialiased over a pixel) at (`cx`, `cy`).
    fn disc(cx: f64, cy: f64, r: f64) -> Vec<u8> {
        let (w, h) = (200, 100);
        let mut px = vec![60u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let d = (x as f64 - cx).hypot(y as f64 - cy) - r;
                px[y * w + x] = (60.0 + 120.0 * (0.5 - d).clamp(0.0, 1.0)).round() as u8;
            }
        }
        px
    }

    fn detection(beyond_edge: bool) -> CircleDetection {
        CircleDetection {
            min_radius: 30.0,
            max_radius: 60.0,
            beyond_edge,
            ..CircleDetection::default()
        }
    }

    #[test]
    fn a_disc_centred_above_the_frame_is_found_only_beyond_the_edge() {
        // Centre 15 px above the top edge: 146° of the rim in view.
        let px = disc(90.3, -15.0, 45.0);
        let img = Plane::new(&px, 200, 100);
        let beyond = detect_circles(&img, &detection(true));
        let best = beyond.first().expect("found");
        assert!(
            (best.x - 90.3).abs() < 2.0 && (best.y + 15.0).abs() < 2.0 && (best.r - 45.0).abs() < 2.0,
            "{best:?}"
        );
        let inside = detect_circles(&img, &detection(false));
        assert!(inside.iter().all(|c| c.y >= 0.0), "{inside:?}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The two searches split the candidates by where their centres lie.
        #[test]
        fn centres_lie_where_the_search_looks(cx in -20.0f64..220.0, cy in -20.0f64..120.0, r in 32.0f64..55.0) {
            let px = disc(cx, cy, r);
            let img = Plane::new(&px, 200, 100);
            let within = |c: &Circle| c.x >= -0.5 && c.y >= -0.5 && c.x <= 199.5 && c.y <= 99.5;
            for c in detect_circles(&img, &detection(false)) {
                prop_assert!(within(&c), "{:?}", c);
            }
            for c in detect_circles(&img, &detection(true)) {
                prop_assert!(!within(&c), "{:?}", c);
                // A centre beyond the edge lies within half a radius of it.
                let beyond = (-c.x).max(c.x - 199.0).max(-c.y).max(c.y - 99.0);
                prop_assert!(beyond <= 0.5 * c.r + 4.0, "{:?}", c);
            }
        }
    }

    #[test]
    fn one_octave_is_one_band() {
        assert_eq!(radius_bands(70.0, 100.0), vec![(70.0, 100.0)]);
        assert_eq!(sampling_factor(8.0), 1);
        assert_eq!(sampling_factor(24.0), 2);
        assert_eq!(sampling_factor(500.0), 8);
    }
}
