//! Anti-aliased strokes at sub-pixel positions: a ring, a straight line across the canvas, a segment.
//!
//! imageproc's conics and lines take integer centres and radii (or round their end points), which would
//! move a drawn circle by up to half a pixel and hide exactly the sub-pixel error a person is checking.
//! So these strokes are drawn as the ideal stroke (a band `width` px wide around its centre line) seen
//! through a *tent* pixel footprint (linear interpolation), not a box one: with a tent, the
//! coverage-weighted position of the drawn pixels is the stroke's own position exactly, whatever its
//! sub-pixel offset, while a box footprint rounds it by up to 0.2 px (measured). Lines and segments are
//! integrated in closed form; a ring is splatted from points spaced ≤ 0.35 px along and across it
//! (bilinear splats are tent footprints), symmetric about its centre, so its drawn centre is its centre.
//! A 0.1 px shift moves the drawn stroke by 0.1 px (tested to 0.003 px; the drawn centre lies within 0.01 px
//! of the true one, the rest being the 8-bit rounding of blended pixels).

use image::{Rgb, RgbImage};

/// Blends `colour` over pixel (x, y) with weight `alpha` (0–1); outside the canvas nothing happens.
#[inline]
fn blend(img: &mut RgbImage, x: i64, y: i64, colour: Rgb<u8>, alpha: f32) {
    if alpha <= 0.0 || x < 0 || y < 0 || x >= i64::from(img.width()) || y >= i64::from(img.height()) {
        return;
    }
    let a = alpha.min(1.0);
    let p = img.get_pixel_mut(x as u32, y as u32);
    for k in 0..3 {
        let v = f32::from(p.0[k]) * (1.0 - a) + f32::from(colour.0[k]) * a;
        p.0[k] = (v + 0.5) as u8;
    }
}

/// The integral of the unit tent `max(1 − |v|, 0)` from −∞ to `x`.
#[inline]
fn tent_cdf(x: f64) -> f64 {
    if x <= -1.0 {
        0.0
    } else if x <= 0.0 {
        0.5 * (1.0 + x) * (1.0 + x)
    } else if x <= 1.0 {
        1.0 - 0.5 * (1.0 - x) * (1.0 - x)
    } else {
        1.0
    }
}

/// Coverage of a pixel whose centre is `u` px across from the centre line of a band `width` px wide,
/// through a tent footprint: `∫ tent(u − s) ds` over the band.
#[inline]
fn across(u: f64, width: f64) -> f64 {
    tent_cdf(u + width / 2.0) - tent_cdf(u - width / 2.0)
}

/// How a ring is stroked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Dash {
    /// One continuous stroke.
    Solid,
    /// On and off arcs of this length each, canvas px along the circle.
    Dashed(f64),
}

/// Spacing of a ring's splatted points along and across it, canvas px: bilinear splats this far apart sum
/// to the band of dense ones (tested against 0.125 px spacing: within 2 % of full coverage; 0.5 px was 4 %
/// off on a thin small ring).
const SPLAT_STEP: f64 = 0.35;
/// Most points around a ring (a guard for absurd radii; a 10,000 px ring still keeps the 0.35 px spacing).
const MAX_RING_POINTS: usize = 1 << 18;

/// Draws a circle of radius `r` centred on (cx, cy), all in canvas px, as an anti-aliased stroke `width`
/// px wide, blended at `opacity` (0–1); `Dash::Dashed` leaves gaps along it.
///
/// Cost: ~ (2πr / 0.35) · (width / 0.35) bilinear splats into a buffer the size of the ring's box, then
/// one blend per pixel of that box: about 0.2 ms for r = 84 px, width 1.25 px (`docs/performance.md`). A
/// ring outside the canvas costs nothing; a huge one is bounded by the canvas and `MAX_RING_POINTS`.
#[allow(clippy::too_many_arguments)]
pub fn draw_ring(img: &mut RgbImage, cx: f64, cy: f64, r: f64, width: f64, colour: Rgb<u8>, opacity: f32, dash: Dash) {
    ring_with_step(img, cx, cy, r, width, colour, opacity, dash, SPLAT_STEP);
}

#[allow(clippy::too_many_arguments)]
fn ring_with_step(
    img: &mut RgbImage,
    cx: f64,
    cy: f64,
    r: f64,
    width: f64,
    colour: Rgb<u8>,
    opacity: f32,
    dash: Dash,
    step: f64,
) {
    if !(cx.is_finite() && cy.is_finite() && r.is_finite() && width.is_finite()) || r <= 0.0 || width <= 0.0 {
        return;
    }
    let reach = r + width / 2.0 + 1.0;
    let (w, h) = (f64::from(img.width()), f64::from(img.height()));
    let x0 = (cx - reach).floor().max(0.0);
    let x1 = (cx + reach).ceil().min(w - 1.0);
    let y0 = (cy - reach).floor().max(0.0);
    let y1 = (cy + reach).ceil().min(h - 1.0);
    if x0 > x1 || y0 > y1 {
        return;
    }
    // A ring that encloses the whole canvas without touching it draws nothing.
    let far = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
        .iter()
        .map(|&(x, y)| (x - cx).hypot(y - cy))
        .fold(0.0, f64::max);
    let near_x = cx.clamp(x0, x1) - cx;
    let near_y = cy.clamp(y0, y1) - cy;
    if far < r - width / 2.0 - 1.0 || near_x.hypot(near_y) > r + width / 2.0 + 1.0 {
        return;
    }
    let (bw, bh) = ((x1 - x0) as usize + 1, (y1 - y0) as usize + 1);
    let mut acc = vec![0f32; bw * bh];
    let across_n = (width / step).ceil().max(1.0) as usize;
    // A multiple of 4 points around, so they are symmetric about both axes through the centre.
    let around_n = (((std::f64::consts::TAU * (r + width / 2.0) / step).ceil() as usize).div_ceil(4) * 4)
        .clamp(16, MAX_RING_POINTS);
    // Directions of the first quadrant, mirrored into the others: exactly symmetric, a quarter of the trig.
    let quarter = around_n / 4;
    let mut dirs = vec![(0.0, 0.0, true); around_n];
    for j in 0..quarter {
        let t = std::f64::consts::TAU * j as f64 / around_n as f64;
        let (s, c) = t.sin_cos();
        for (q, (dc, ds)) in [(c, s), (-s, c), (-c, -s), (s, -c)].into_iter().enumerate() {
            let k = j + q * quarter;
            let on = match dash {
                Dash::Dashed(len) if len > 0.0 => {
                    let arc = std::f64::consts::TAU * k as f64 / around_n as f64 * r;
                    (arc / len) as i64 % 2 == 0
                }
                _ => true,
            };
            dirs[k] = (dc, ds, on);
        }
    }
    for i in 0..across_n {
        let rr = r - width / 2.0 + (i as f64 + 0.5) * width / across_n as f64;
        // Each point stands for its share of the band's area, so a wide band's inside sums to 1.
        let weight = (std::f64::consts::TAU * rr / around_n as f64 * width / across_n as f64) as f32;
        let (ox, oy) = (cx - x0, cy - y0);
        for &(c, s, on) in &dirs {
            if on {
                splat(&mut acc, bw, bh, ox + rr * c, oy + rr * s, weight);
            }
        }
    }
    for (k, &a) in acc.iter().enumerate() {
        if a > 0.0 {
            let (x, y) = (x0 as i64 + (k % bw) as i64, y0 as i64 + (k / bw) as i64);
            blend(img, x, y, colour, a.min(1.0) * opacity);
        }
    }
}

/// Adds `weight` at (x, y) in a `bw`×`bh` buffer, shared bilinearly among the four nearest pixels.
#[inline]
fn splat(acc: &mut [f32], bw: usize, bh: usize, x: f64, y: f64, weight: f32) {
    // Points lie within a pixel or two of the buffer (it is the ring's box, clipped to the canvas): shift by
    // 2 so truncation is the floor.
    let (sx, sy) = (x + 2.0, y + 2.0);
    if sx < 0.0 || sy < 0.0 {
        return;
    }
    let (ix, iy) = (sx as i64, sy as i64);
    let (ax, ay) = ((sx - ix as f64) as f32, (sy - iy as f64) as f32);
    let (fx, fy) = (ix - 2, iy - 2);
    for (dy, wy) in [(0i64, 1.0 - ay), (1, ay)] {
        for (dx, wx) in [(0i64, 1.0 - ax), (1, ax)] {
            let (px, py) = (fx + dx, fy + dy);
            if px >= 0 && py >= 0 && (px as usize) < bw && (py as usize) < bh {
                acc[py as usize * bw + px as usize] += weight * wx * wy;
            }
        }
    }
}

/// Draws the line `y = y0 + slope · (x − x0)` (canvas px) across the whole canvas as an anti-aliased
/// stroke `width` px wide (measured across the line), blended at `opacity`.
///
/// Each column (each row, for a line steeper than 45°) is the band's cross-section through a tent
/// footprint, so its coverage-weighted height is the line's height there exactly.
///
/// Cost: a few pixels per column: about 25 µs across 512 px.
pub fn draw_line_across(img: &mut RgbImage, x0: f64, y0: f64, slope: f64, width: f64, colour: Rgb<u8>, opacity: f32) {
    if !(x0.is_finite() && y0.is_finite() && slope.is_finite() && width.is_finite()) || width <= 0.0 {
        return;
    }
    let (w, h) = (i64::from(img.width()), i64::from(img.height()));
    let norm = slope.hypot(1.0);
    if slope.abs() <= 1.0 {
        // The band's height in a column.
        let thick = width * norm;
        for x in 0..w {
            let yl = y0 + slope * (x as f64 - x0);
            let reach = thick / 2.0 + 1.0;
            let (lo, hi) = ((yl - reach).floor().max(0.0), (yl + reach).ceil().min((h - 1) as f64));
            for y in lo as i64..=hi as i64 {
                blend(img, x, y, colour, across(y as f64 - yl, thick) as f32 * opacity);
            }
        }
    } else {
        // The band's width in a row.
        let thick = width * norm / slope.abs();
        for y in 0..h {
            let xl = x0 + (y as f64 - y0) / slope;
            let reach = thick / 2.0 + 1.0;
            let (lo, hi) = ((xl - reach).floor().max(0.0), (xl + reach).ceil().min((w - 1) as f64));
            for x in lo as i64..=hi as i64 {
                blend(img, x, y, colour, across(x as f64 - xl, thick) as f32 * opacity);
            }
        }
    }
}

/// Draws the segment from `a` to `b` (canvas px) as an anti-aliased stroke `width` px wide with square
/// ends at the end points, blended at `opacity`; exact (separable tent footprint) when it is horizontal or
/// vertical, as the arms of a centre cross are.
///
/// Cost: the pixels of the segment's bounding box, O(length · width): ≈ 0.3 µs for a 10 px arm.
pub fn draw_segment(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), width: f64, colour: Rgb<u8>, opacity: f32) {
    let finite = [a.0, a.1, b.0, b.1, width].iter().all(|v| v.is_finite());
    if !finite || width <= 0.0 {
        return;
    }
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len = dx.hypot(dy);
    if len == 0.0 {
        return;
    }
    let (ux, uy) = (dx / len, dy / len);
    let reach = width / 2.0 + 1.0;
    let (w, h) = (f64::from(img.width()), f64::from(img.height()));
    let x_lo = (a.0.min(b.0) - reach).floor().max(0.0);
    let x_hi = (a.0.max(b.0) + reach).ceil().min(w - 1.0);
    let y_lo = (a.1.min(b.1) - reach).floor().max(0.0);
    let y_hi = (a.1.max(b.1) + reach).ceil().min(h - 1.0);
    if x_lo > x_hi || y_lo > y_hi {
        return;
    }
    for y in y_lo as i64..=y_hi as i64 {
        for x in x_lo as i64..=x_hi as i64 {
            let (px, py) = (x as f64 - a.0, y as f64 - a.1);
            let along = px * ux + py * uy;
            let off = px * uy - py * ux;
            let c = across(off, width) * (tent_cdf(along) - tent_cdf(along - len));
            blend(img, x, y, colour, c as f32 * opacity);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const BG: Rgb<u8> = Rgb([0, 0, 0]);
    const INK: Rgb<u8> = Rgb([255, 255, 255]);

    /// Each pixel's coverage, read back from a white stroke on black.
    fn alpha(img: &RgbImage, x: u32, y: u32) -> f64 {
        f64::from(img.get_pixel(x, y).0[0]) / 255.0
    }

    /// The coverage-weighted centre and mean distance from (cx, cy) of a ring's pixels, and the total.
    fn ring_moments(img: &RgbImage, cx: f64, cy: f64) -> ((f64, f64), f64, f64) {
        let (mut s, mut sx, mut sy, mut sd) = (0.0, 0.0, 0.0, 0.0);
        for (x, y, _) in img.enumerate_pixels() {
            let a = alpha(img, x, y);
            let (fx, fy) = (f64::from(x), f64::from(y));
            s += a;
            sx += a * fx;
            sy += a * fy;
            sd += a * (fx - cx).hypot(fy - cy);
        }
        ((sx / s, sy / s), sd / s, s)
    }

    #[test]
    fn the_tent_profile_integrates_to_the_width() {
        for width in [0.5, 1.0, 1.25, 3.0] {
            let total: f64 = (-400..=400)
                .map(|k| across(f64::from(k) / 100.0 + 0.003, width) / 100.0)
                .sum();
            assert!((total - width).abs() < 1e-3, "{width}: {total}");
        }
        assert_eq!(across(5.0, 1.0), 0.0);
        assert!((across(0.0, 4.0) - 1.0).abs() < 1e-12);
    }

    proptest! {
        #[test]
        fn a_ring_is_drawn_on_its_centre_and_radius(
            cx in 40.0f64..60.0, cy in 40.0f64..60.0, r in 8.0f64..35.0, width in 1.0f64..2.5
        ) {
            let mut img = RgbImage::from_pixel(100, 100, BG);
            draw_ring(&mut img, cx, cy, r, width, INK, 1.0, Dash::Solid);
            let ((mx, my), mean_d, total) = ring_moments(&img, cx, cy);
            // Exact but for the 8-bit rounding of each blended pixel.
            prop_assert!((mx - cx).abs() < 0.01 && (my - cy).abs() < 0.01, "centre ({mx}, {my}) vs ({cx}, {cy})");
            // The band seen through a tent has a radial variance of about w²/12 + 1/6, so the mean distance
            // is r + var / r (to the grid's 2-D sampling).
            let expected = r + (width * width / 12.0 + 1.0 / 6.0) / r;
            prop_assert!((mean_d - expected).abs() < 0.02, "mean radius {mean_d} vs {expected}");
            // Its area is 2πr·w, to the rounding of 8-bit blending.
            let area = std::f64::consts::TAU * r * width;
            prop_assert!((total - area).abs() / area < 0.02, "area {total} vs {area}");
        }

        #[test]
        fn a_line_lies_on_its_equation_in_every_column(
            y0 in 45.0f64..55.0, slope in -0.8f64..0.8, width in 1.0f64..2.5
        ) {
            let mut img = RgbImage::from_pixel(100, 100, BG);
            draw_line_across(&mut img, 50.0, y0, slope, width, INK, 1.0);
            for x in [0u32, 13, 50, 99] {
                let (mut s, mut sy) = (0.0, 0.0);
                for y in 0..100 {
                    let a = alpha(&img, x, y);
                    s += a;
                    sy += a * f64::from(y);
                }
                let expected = y0 + slope * (f64::from(x) - 50.0);
                prop_assert!((sy / s - expected).abs() < 0.01, "column {x}: {} vs {expected}", sy / s);
                // The band's area in one column.
                prop_assert!((s - width * slope.hypot(1.0)).abs() < 0.02, "column {x}: {s}");
            }
        }
    }

    #[test]
    fn a_tenth_of_a_pixel_moves_the_drawn_ring_a_tenth_of_a_pixel() {
        let centre = |cx: f64| {
            let mut img = RgbImage::from_pixel(64, 64, BG);
            draw_ring(&mut img, cx, 32.0, 20.0, 1.25, INK, 1.0, Dash::Solid);
            ring_moments(&img, cx, 32.0).0
        };
        let (a, b) = (centre(32.0), centre(32.1));
        assert!((b.0 - a.0 - 0.1).abs() < 0.003, "{a:?} → {b:?}");
        assert!((b.1 - a.1).abs() < 0.003, "{a:?} → {b:?}");
    }

    #[test]
    fn sparse_splats_draw_the_ring_of_dense_ones() {
        for (r, width) in [(8.3, 1.0), (41.7, 1.25), (84.0, 2.5)] {
            let mut a = RgbImage::from_pixel(200, 200, BG);
            let mut b = a.clone();
            draw_ring(&mut a, 100.4, 99.8, r, width, INK, 1.0, Dash::Solid);
            ring_with_step(&mut b, 100.4, 99.8, r, width, INK, 1.0, Dash::Solid, 0.125);
            let worst = a
                .pixels()
                .zip(b.pixels())
                .map(|(p, q)| p.0[0].abs_diff(q.0[0]))
                .max()
                .unwrap();
            assert!(worst <= 5, "r {r}, width {width}: {worst} / 255");
        }
    }

    #[test]
    fn the_ring_passes_through_its_radius_at_every_angle_and_nowhere_else() {
        let (cx, cy, r) = (50.3, 47.8, 30.0);
        let mut img = RgbImage::from_pixel(100, 100, BG);
        draw_ring(&mut img, cx, cy, r, 1.5, INK, 1.0, Dash::Solid);
        for k in 0..16 {
            let t = f64::from(k) * std::f64::consts::TAU / 16.0;
            let at = |rr: f64| {
                let (x, y) = ((cx + rr * t.cos()).round() as u32, (cy + rr * t.sin()).round() as u32);
                alpha(&img, x, y)
            };
            assert!(at(r) > 0.3, "angle {k}: {}", at(r));
            assert_eq!(at(r - 3.0), 0.0, "inside at angle {k}");
            assert_eq!(at(r + 3.0), 0.0, "outside at angle {k}");
        }
    }

    #[test]
    fn dashes_leave_gaps_of_their_length() {
        let mut solid = RgbImage::from_pixel(100, 100, BG);
        let mut dashed = solid.clone();
        draw_ring(&mut solid, 50.0, 50.0, 30.0, 1.5, INK, 1.0, Dash::Solid);
        draw_ring(&mut dashed, 50.0, 50.0, 30.0, 1.5, INK, 1.0, Dash::Dashed(6.0));
        let (_, _, a) = ring_moments(&solid, 50.0, 50.0);
        let (_, _, b) = ring_moments(&dashed, 50.0, 50.0);
        assert!((b / a - 0.5).abs() < 0.06, "{}", b / a);
        // On at angle 0 (arc 0–6 px), off just past it (arc 6–12 px).
        assert!(alpha(&dashed, 80, 52) > 0.2);
        assert_eq!(alpha(&dashed, 79, 59), 0.0);
    }

    #[test]
    fn a_steep_line_is_drawn_by_rows() {
        let mut img = RgbImage::from_pixel(60, 60, BG);
        draw_line_across(&mut img, 30.0, 30.0, 20.0, 1.0, INK, 1.0);
        // Through (30, 30) and, 20 rows down, one column right.
        assert!(alpha(&img, 30, 30) > 0.6 && alpha(&img, 31, 50) > 0.6);
        assert_eq!(alpha(&img, 33, 30), 0.0);
    }

    #[test]
    fn strokes_off_the_canvas_or_degenerate_draw_nothing() {
        let mut img = RgbImage::from_pixel(20, 20, BG);
        draw_ring(&mut img, -500.0, 3.0, 10.0, 1.0, INK, 1.0, Dash::Solid);
        draw_ring(&mut img, 10.0, 10.0, f64::NAN, 1.0, INK, 1.0, Dash::Solid);
        draw_ring(&mut img, 10.0, 10.0, 1e12, 1.0, INK, 1.0, Dash::Solid);
        draw_line_across(&mut img, 0.0, 400.0, 0.0, 1.0, INK, 1.0);
        draw_segment(&mut img, (5.0, 5.0), (5.0, 5.0), 1.0, INK, 1.0);
        draw_segment(&mut img, (-50.0, -50.0), (-40.0, -50.0), 1.0, INK, 1.0);
        assert!(img.pixels().all(|p| *p == BG));
        // A huge ring crossing the canvas is drawn where it crosses, in bounded time.
        draw_ring(&mut img, 10.0, 1e5 + 10.0, 1e5, 1.0, INK, 1.0, Dash::Solid);
        assert!(alpha(&img, 10, 10) > 0.3);
    }

    #[test]
    fn a_segment_covers_its_length_times_its_width_centred_where_it_is() {
        let mut img = RgbImage::from_pixel(40, 40, BG);
        draw_segment(&mut img, (10.3, 20.6), (30.3, 20.6), 1.0, INK, 1.0);
        let (mut s, mut sx, mut sy) = (0.0, 0.0, 0.0);
        for (x, y, _) in img.enumerate_pixels() {
            let a = alpha(&img, x, y);
            s += a;
            sx += a * f64::from(x);
            sy += a * f64::from(y);
        }
        assert!((s - 20.0).abs() < 0.2, "{s}");
        assert!(
            (sx / s - 20.3).abs() < 0.01 && (sy / s - 20.6).abs() < 0.01,
            "{} {}",
            sx / s,
            sy / s
        );
    }
}
