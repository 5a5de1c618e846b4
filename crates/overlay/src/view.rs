//! Which part of a frame is shown, at what magnification, with which gray levels: the frame's pixels
//! resampled into an RGB canvas that the annotations are then drawn on at the canvas's own resolution.

use crate::error::OverlayError;
use bouncelab_frames::GrayPixels;
use image::{Rgb, RgbImage};

/// The largest canvas made, pixels (a guard against unbounded allocation from a wild zoom or size).
pub const MAX_CANVAS_PIXELS: u64 = 64 << 20;

/// The colour of canvas pixels that fall outside the frame (a crop near the border).
pub const OUTSIDE: Rgb<u8> = Rgb([48, 16, 48]);

/// A window onto a frame: canvas pixel (u, v) shows the frame at `(left + u / scale, top + v / scale)`,
/// in frame pixels with pixel centres at integer coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Frame x shown at canvas column 0, px.
    pub left: f64,
    /// Frame y shown at canvas row 0, px.
    pub top: f64,
    /// Canvas pixels per frame pixel.
    pub scale: f64,
    /// Canvas width, px.
    pub width: u32,
    /// Canvas height, px.
    pub height: u32,
}

impl View {
    /// The whole frame, magnified `zoom` times: each frame pixel's square maps onto `zoom`×`zoom` canvas
    /// pixels exactly (zoom 1 is the frame itself, pixel for pixel).
    pub fn full(width: u32, height: u32, zoom: f64) -> Result<View, OverlayError> {
        if !(zoom.is_finite() && zoom > 0.0) {
            return Err(OverlayError::BadStyle {
                field: "zoom",
                value: zoom,
                why: "must be a positive number",
            });
        }
        let (w, h) = ((f64::from(width) * zoom).round(), (f64::from(height) * zoom).round());
        check_size("an annotated frame", w, h)?;
        // Canvas pixel 0's centre lies half a canvas pixel inside the frame's left edge (x = −0.5).
        let left = -0.5 + 0.5 / zoom;
        Ok(View {
            left,
            top: left,
            scale: zoom,
            width: w as u32,
            height: h as u32,
        })
    }

    /// A square window of `side_px` frame pixels centred on (cx, cy), shown on a `size`×`size` canvas.
    pub fn around(cx: f64, cy: f64, side_px: f64, size: u32) -> Result<View, OverlayError> {
        if !(side_px.is_finite() && side_px > 0.0) {
            return Err(OverlayError::BadStyle {
                field: "crop side",
                value: side_px,
                why: "must be a positive number of pixels",
            });
        }
        if size == 0 {
            return Err(OverlayError::BadStyle {
                field: "crop size",
                value: 0.0,
                why: "must be at least 1 px",
            });
        }
        check_size("a crop", f64::from(size), f64::from(size))?;
        let scale = f64::from(size) / side_px;
        let half = (f64::from(size) - 1.0) / 2.0;
        Ok(View {
            left: cx - half / scale,
            top: cy - half / scale,
            scale,
            width: size,
            height: size,
        })
    }

    /// Frame coordinates → canvas coordinates, px.
    pub fn to_canvas(&self, x: f64, y: f64) -> (f64, f64) {
        ((x - self.left) * self.scale, (y - self.top) * self.scale)
    }

    /// Canvas coordinates → frame coordinates, px.
    pub fn to_frame(&self, u: f64, v: f64) -> (f64, f64) {
        (self.left + u / self.scale, self.top + v / self.scale)
    }
}

fn check_size(what: &'static str, w: f64, h: f64) -> Result<(), OverlayError> {
    if w < 1.0 || h < 1.0 || w * h > MAX_CANVAS_PIXELS as f64 {
        return Err(OverlayError::TooLarge {
            what,
            width: w as u64,
            height: h as u64,
            limit: MAX_CANVAS_PIXELS,
        });
    }
    Ok(())
}

/// How gray values become display levels: fractions of full scale shown as black and as white.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Levels {
    /// Fraction of full scale (0–1) shown black.
    pub black: f32,
    /// Fraction of full scale (0–1) shown white; above `black`.
    pub white: f32,
}

impl Levels {
    /// Full scale: 0 is black, the bit depth's maximum is white (an 8-bit frame is shown as it is).
    pub const FULL: Levels = Levels { black: 0.0, white: 1.0 };

    /// Stretched to the frame's own range: the `low` and `high` percentiles (e.g. 0.5 and 99.5) become
    /// black and white, so a 12-bit camera's frames in 16-bit files, or a dark 8-bit frame, are seen.
    ///
    /// Cost: one pass over the frame and a histogram of 256 or 65,536 bins.
    pub fn stretch(pixels: &GrayPixels, low: f32, high: f32) -> Levels {
        fn percentiles<T: Copy + Into<usize>>(data: &[T], bins: usize, low: f32, high: f32) -> (usize, usize) {
            let mut hist = vec![0u64; bins];
            for &v in data {
                hist[v.into()] += 1;
            }
            let n = data.len() as f64;
            let at = |p: f32| {
                let target = (f64::from(p.clamp(0.0, 100.0)) / 100.0 * n).ceil().max(1.0) as u64;
                let mut sum = 0;
                for (v, &c) in hist.iter().enumerate() {
                    sum += c;
                    if sum >= target {
                        return v;
                    }
                }
                bins - 1
            };
            (at(low), at(high))
        }
        let (lo, hi, max) = match pixels {
            GrayPixels::U8(i) => {
                let (a, b) = percentiles(i.as_raw(), 256, low, high);
                (a, b, 255.0f32)
            }
            GrayPixels::U16(i) => {
                let (a, b) = percentiles(i.as_raw(), 65536, low, high);
                (a, b, 65535.0f32)
            }
        };
        if hi <= lo {
            return Levels::FULL;
        }
        Levels {
            black: lo as f32 / max,
            white: hi as f32 / max,
        }
    }

    fn check(&self) -> Result<(), OverlayError> {
        if !(self.black.is_finite() && self.white.is_finite() && self.white > self.black) {
            return Err(OverlayError::BadStyle {
                field: "levels.white - levels.black",
                value: f64::from(self.white - self.black),
                why: "must be positive",
            });
        }
        Ok(())
    }
}

/// The frame's pixels under `view` as an RGB canvas (gray, so annotations stand out in colour), bilinear
/// between pixel centres; canvas pixels outside the frame are [`OUTSIDE`].
///
/// Values are taken as fractions of full scale (v / 255 or v / 65535) before anything else, so a 16-bit
/// frame gives exactly the picture of its 8-bit copy (v₁₆ = 257 · v₈).
///
/// Cost: about 5 ns per canvas pixel (a 160×160 crop ≈ 0.15 ms); a whole frame at zoom 1 is copied without
/// interpolation (see `docs/performance.md`).
pub fn render_gray(pixels: &GrayPixels, view: &View, levels: Levels) -> Result<RgbImage, OverlayError> {
    levels.check()?;
    let (w, h) = pixels.dimensions();
    if w == 0 || h == 0 {
        return Err(OverlayError::EmptyFrame {
            frame: 0,
            width: w,
            height: h,
        });
    }
    Ok(match pixels {
        GrayPixels::U8(i) => render_plane(i.as_raw(), w, h, 255.0, view, levels),
        GrayPixels::U16(i) => render_plane(i.as_raw(), w, h, 65535.0, view, levels),
    })
}

/// Sampling positions along one axis: for each canvas column (or row), the two frame pixels either side and
/// the weight of the second, or `None` outside the frame.
fn axis_taps(start: f64, scale: f64, n: u32, size: u32) -> Vec<Option<(usize, usize, f32)>> {
    let last = size as usize - 1;
    let limit = f64::from(size) - 0.5;
    (0..n)
        .map(|k| {
            let f = start + f64::from(k) / scale;
            if !(-0.5..limit).contains(&f) {
                return None;
            }
            let base = f.floor();
            let i = base.max(0.0) as usize;
            Some((i.min(last), (i + usize::from(base >= 0.0)).min(last), (f - base) as f32))
        })
        .collect()
}

/// Gray value (fraction of full scale) → display level, rounded half up.
#[inline]
fn to_level(n: f32, black: f32, gain: f32) -> u8 {
    (((n - black) * gain).clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

fn render_plane<T: Copy + Into<f32>>(data: &[T], w: u32, h: u32, full: f32, view: &View, levels: Levels) -> RgbImage {
    let gain = 1.0 / (levels.white - levels.black);
    let black = levels.black;
    let mut out = RgbImage::new(view.width, view.height);
    let wi = w as usize;
    // A whole frame at zoom 1 lands pixel on pixel: no interpolation to do.
    if view.scale == 1.0 && view.left == 0.0 && view.top == 0.0 && view.width == w && view.height == h {
        // 8-bit values through a table of their 256 levels (the same formula, so the same picture).
        let table: Option<Vec<u8>> = (full == 255.0).then(|| {
            (0..=255u8)
                .map(|v| to_level(f32::from(v) / full, black, gain))
                .collect()
        });
        for (o, &v) in out.pixels_mut().zip(data) {
            let n: f32 = v.into();
            let g = match &table {
                Some(t) => t[n as usize],
                None => to_level(n / full, black, gain),
            };
            *o = Rgb([g, g, g]);
        }
        return out;
    }
    // Bilinear between the four nearest pixel centres, clamped at the frame's edge; the taps of every
    // column and row are worked out once.
    let cols = axis_taps(view.left, view.scale, view.width, w);
    let rows = axis_taps(view.top, view.scale, view.height, h);
    let width = view.width as usize;
    let outside = OUTSIDE.0;
    for (row, line) in rows.iter().zip(out.chunks_exact_mut(3 * width)) {
        let Some((ya, yb, ay)) = *row else {
            for px in line.chunks_exact_mut(3) {
                px.copy_from_slice(&outside);
            }
            continue;
        };
        let (ra, rb) = (&data[ya * wi..(ya + 1) * wi], &data[yb * wi..(yb + 1) * wi]);
        for (col, px) in cols.iter().zip(line.chunks_exact_mut(3)) {
            let rgb = match *col {
                Some((xa, xb, ax)) => {
                    let top = ra[xa].into() / full * (1.0 - ax) + ra[xb].into() / full * ax;
                    let bottom = rb[xa].into() / full * (1.0 - ax) + rb[xb].into() / full * ax;
                    let g = to_level(top * (1.0 - ay) + bottom * ay, black, gain);
                    [g, g, g]
                }
                None => outside,
            };
            px.copy_from_slice(&rgb);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_frames::Gray16Image;
    use image::{GrayImage, Luma};

    fn ramp(w: u32, h: u32) -> GrayImage {
        GrayImage::from_fn(w, h, |x, y| Luma([((x * 7 + y * 13) % 256) as u8]))
    }

    fn sixteen(img: &GrayImage) -> GrayPixels {
        GrayPixels::U16(Gray16Image::from_fn(img.width(), img.height(), |x, y| {
            Luma([u16::from(img.get_pixel(x, y).0[0]) * 257])
        }))
    }

    #[test]
    fn zoom_one_is_the_frame_pixel_for_pixel() {
        let img = ramp(37, 23);
        let v = View::full(37, 23, 1.0).unwrap();
        let out = render_gray(&GrayPixels::U8(img.clone()), &v, Levels::FULL).unwrap();
        for (x, y, p) in out.enumerate_pixels() {
            let g = img.get_pixel(x, y).0[0];
            assert_eq!(p.0, [g, g, g]);
        }
    }

    #[test]
    fn integer_zoom_repeats_each_pixel_and_keeps_centres_in_place() {
        let img = ramp(9, 7);
        let v = View::full(9, 7, 3.0).unwrap();
        assert_eq!((v.width, v.height), (27, 21));
        // Frame pixel (x, y) covers canvas pixels 3x..3x+2; its centre is canvas 3x+1.
        assert_eq!(v.to_canvas(4.0, 2.0), (13.0, 7.0));
        let out = render_gray(&GrayPixels::U8(img.clone()), &v, Levels::FULL).unwrap();
        let g = img.get_pixel(4, 2).0[0];
        assert_eq!(out.get_pixel(13, 7).0, [g, g, g]);
    }

    #[test]
    fn sixteen_bit_frames_look_like_their_eight_bit_copies() {
        let img = ramp(40, 30);
        let (a, b) = (GrayPixels::U8(img.clone()), sixteen(&img));
        for view in [
            View::full(40, 30, 1.0).unwrap(),
            View::full(40, 30, 2.5).unwrap(),
            View::around(17.3, 11.8, 13.7, 64).unwrap(),
        ] {
            for levels in [Levels::FULL, Levels { black: 0.1, white: 0.7 }] {
                assert_eq!(
                    render_gray(&a, &view, levels).unwrap(),
                    render_gray(&b, &view, levels).unwrap()
                );
            }
        }
        assert_eq!(Levels::stretch(&a, 1.0, 99.0), Levels::stretch(&b, 1.0, 99.0));
    }

    #[test]
    fn a_crop_centres_the_point_asked_for() {
        let v = View::around(100.25, 50.5, 30.0, 160).unwrap();
        let (u, w) = v.to_canvas(100.25, 50.5);
        assert!((u - 79.5).abs() < 1e-9 && (w - 79.5).abs() < 1e-9);
        let (x, y) = v.to_frame(u, w);
        assert!((x - 100.25).abs() < 1e-9 && (y - 50.5).abs() < 1e-9);
        // A crop over the corner shows the outside in its own colour.
        let out = render_gray(
            &GrayPixels::U8(ramp(20, 20)),
            &View::around(0.0, 0.0, 10.0, 20).unwrap(),
            Levels::FULL,
        )
        .unwrap();
        assert_eq!(*out.get_pixel(0, 0), OUTSIDE);
        assert_ne!(*out.get_pixel(19, 19), OUTSIDE);
    }

    #[test]
    fn stretch_maps_a_twelve_bit_range_to_black_and_white() {
        let img = Gray16Image::from_fn(64, 64, |x, _| Luma([(x as u16) * 64]));
        let p = GrayPixels::U16(img);
        let l = Levels::stretch(&p, 0.0, 100.0);
        assert_eq!((l.black, l.white), (0.0, 63.0 * 64.0 / 65535.0));
        let out = render_gray(&p, &View::full(64, 64, 1.0).unwrap(), l).unwrap();
        assert_eq!(out.get_pixel(0, 5).0[0], 0);
        assert_eq!(out.get_pixel(63, 5).0[0], 255);
        // A flat frame has no range to stretch: full scale.
        let flat = GrayPixels::U8(GrayImage::from_pixel(4, 4, Luma([9])));
        assert_eq!(Levels::stretch(&flat, 1.0, 99.0), Levels::FULL);
    }

    #[test]
    fn wild_sizes_are_errors_not_allocations() {
        assert!(matches!(View::full(512, 512, 1e6), Err(OverlayError::TooLarge { .. })));
        assert!(View::full(512, 512, f64::NAN).is_err());
        assert!(View::around(0.0, 0.0, 0.0, 160).is_err());
        assert!(View::around(0.0, 0.0, 10.0, 0).is_err());
        assert!(View::around(0.0, 0.0, 10.0, 1 << 20).is_err());
        let bad = Levels { black: 0.5, white: 0.5 };
        assert!(render_gray(&GrayPixels::U8(ramp(4, 4)), &View::full(4, 4, 1.0).unwrap(), bad).is_err());
    }
}
