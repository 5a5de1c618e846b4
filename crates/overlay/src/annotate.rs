//! A frame's annotations: the surface line, the fitted circle, its centre, and labels for the frame number,
//! phase and status; on a whole frame or on a crop around the ball.

use crate::error::OverlayError;
use crate::font::{draw_label, text_size};
use crate::marks::{BallMark, Status, SurfaceLine, phase_colour, phase_label, status_colour, status_label};
use crate::paint::{Dash, draw_line_across, draw_ring, draw_segment};
use crate::view::{Levels, View, render_gray};
use bouncelab_frames::GrayPixels;
use image::{Rgb, RgbImage};
use imageproc::drawing::draw_hollow_rect_mut;
use imageproc::rect::Rect;

/// How annotations look. Sizes are canvas pixels, so they stay the same whatever the magnification.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Style {
    /// Gray levels of the frame under the annotations.
    pub levels: Levels,
    /// Width of the circle, line and cross strokes, canvas px. Default 1.25: thin enough to leave the
    /// rim's edge visible on both sides of the circle.
    pub stroke_px: f64,
    /// Opacity of the strokes (0–1). Default 0.9.
    pub opacity: f32,
    /// Half-length of the centre cross's arms, canvas px. Default 6.
    pub cross_px: f64,
    /// Length of the dashes of a circle fitted to part of the rim (occluded, cut by the border), canvas px.
    /// Default 6.
    pub dash_px: f64,
    /// Canvas px per font cell of the labels; `None` picks 1 for canvases up to 320 px wide, 2 above;
    /// `Some(0)` draws no labels.
    pub font_scale: Option<u32>,
}

impl Default for Style {
    fn default() -> Self {
        Style {
            levels: Levels::FULL,
            stroke_px: 1.25,
            opacity: 0.9,
            cross_px: 6.0,
            dash_px: 6.0,
            font_scale: None,
        }
    }
}

impl Style {
    fn check(&self) -> Result<(), OverlayError> {
        for (field, value, why) in [
            ("stroke_px", self.stroke_px, "must be a positive number of pixels"),
            ("cross_px", self.cross_px, "must be a positive number of pixels"),
            ("dash_px", self.dash_px, "must be a positive number of pixels"),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(OverlayError::BadStyle { field, value, why });
            }
        }
        if !(0.0..=1.0).contains(&self.opacity) {
            return Err(OverlayError::BadStyle {
                field: "opacity",
                value: f64::from(self.opacity),
                why: "must be between 0 and 1",
            });
        }
        Ok(())
    }

    fn font_scale_for(&self, canvas_width: u32) -> u32 {
        self.font_scale
            .unwrap_or(if canvas_width > 320 { 2 } else { 1 })
            .min(16)
    }
}

/// The background of labels.
const LABEL_BG: Rgb<u8> = Rgb([0, 0, 0]);

/// Draws one frame's annotations on `canvas`, a picture of the frame under `view` (from
/// [`render_gray`](crate::render_gray)):
///
/// - the surface line across the canvas, yellow;
/// - the fitted circle and a cross on its centre in the phase's colour (sky blue in, vermillion contact,
///   bluish green out, white unknown), solid when the whole rim was used, dashed when the status says only
///   part of it was (occluded, cut by the border); nothing for absent or ambiguous frames, which get a red
///   or magenta border instead;
/// - labels: `#frame` top left, the phase word top right in its colour, the status word bottom left in
///   its colour.
///
/// Circle, line and cross are anti-aliased at their sub-pixel positions (see `paint`).
///
/// Cost: O(r · stroke) for the circle plus O(canvas width) for the line plus ~20 rectangles per label
/// character: about 0.2 ms on a 512×512 frame with an 84 px ball (`docs/performance.md`).
pub fn draw_annotations(
    canvas: &mut RgbImage,
    view: &View,
    mark: &BallMark,
    line: Option<&SurfaceLine>,
    style: &Style,
) -> Result<(), OverlayError> {
    style.check()?;
    let circle = mark.circle()?;
    if let Some(l) = line {
        l.check()?;
        let (u0, v0) = view.to_canvas(l.x0, l.y0);
        draw_line_across(
            canvas,
            u0,
            v0,
            l.slope,
            style.stroke_px,
            SurfaceLine::colour(),
            style.opacity,
        );
    }
    let colour = phase_colour(mark.phase);
    if let Some((x, y, r)) = circle {
        let (u, v) = view.to_canvas(x, y);
        let dash = if mark.status == Status::Ok {
            Dash::Solid
        } else {
            Dash::Dashed(style.dash_px)
        };
        draw_ring(
            canvas,
            u,
            v,
            r * view.scale,
            style.stroke_px,
            colour,
            style.opacity,
            dash,
        );
        let a = style.cross_px;
        for (p, q) in [((u - a, v), (u + a, v)), ((u, v - a), (u, v + a))] {
            draw_segment(canvas, p, q, style.stroke_px, colour, style.opacity);
        }
    } else {
        // No circle to show: the whole tile says so.
        let (w, h) = canvas.dimensions();
        for k in 0..3u32 {
            if w > 2 * k && h > 2 * k {
                draw_hollow_rect_mut(
                    canvas,
                    Rect::at(k as i32, k as i32).of_size(w - 2 * k, h - 2 * k),
                    status_colour(mark.status),
                );
            }
        }
    }
    let scale = style.font_scale_for(canvas.width());
    if scale > 0 {
        let (w, h) = canvas.dimensions();
        draw_label(
            canvas,
            0,
            0,
            &format!("#{}", mark.frame),
            scale,
            Rgb([255, 255, 255]),
            LABEL_BG,
        );
        let phase = phase_label(mark.phase);
        if !phase.is_empty() {
            let (pw, _) = text_size(phase, scale);
            let x = w as i32 - (pw + 2 * scale) as i32;
            draw_label(canvas, x, 0, phase, scale, colour, LABEL_BG);
        }
        let (_, th) = text_size("", scale);
        let y = h as i32 - (th + 2 * scale) as i32;
        draw_label(
            canvas,
            0,
            y,
            status_label(mark.status),
            scale,
            status_colour(mark.status),
            LABEL_BG,
        );
    }
    Ok(())
}

/// A whole frame magnified `zoom` times with its annotations ([`draw_annotations`]).
///
/// Cost: the gray canvas (a copy at zoom 1; ~5 ns per canvas pixel otherwise) plus the annotations.
pub fn annotate_frame(
    pixels: &GrayPixels,
    mark: &BallMark,
    line: Option<&SurfaceLine>,
    zoom: f64,
    style: &Style,
) -> Result<RgbImage, OverlayError> {
    let (w, h) = pixels.dimensions();
    if w == 0 || h == 0 {
        return Err(OverlayError::EmptyFrame {
            frame: mark.frame,
            width: w,
            height: h,
        });
    }
    let view = View::full(w, h, zoom)?;
    let mut canvas = render_gray(pixels, &view, style.levels)?;
    draw_annotations(&mut canvas, &view, mark, line, style)?;
    Ok(canvas)
}

/// The size of a crop around the ball.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crop {
    /// Side of the square picture, px. Default 160.
    pub size_px: u32,
    /// Side of the square window in the frame, in ball radii. Default 3: the ball fills two thirds of the
    /// tile and the surface line is in view while the ball touches it.
    pub radii: f64,
}

impl Default for Crop {
    fn default() -> Self {
        Crop {
            size_px: 160,
            radii: 3.0,
        }
    }
}

/// A square crop around (cx, cy), frame px, `crop.radii × radius_px` frame pixels on a side, resampled to
/// `crop.size_px` and annotated with `mark` ([`draw_annotations`]).
///
/// Give every tile of a strip the same `radius_px` (e.g. the clip's flight radius) so they share one
/// magnification.
///
/// Cost: ~5 ns per output pixel plus the annotations: about 0.2 ms for 160 px.
#[allow(clippy::too_many_arguments)]
pub fn crop_at(
    pixels: &GrayPixels,
    cx: f64,
    cy: f64,
    radius_px: f64,
    mark: &BallMark,
    line: Option<&SurfaceLine>,
    crop: &Crop,
    style: &Style,
) -> Result<RgbImage, OverlayError> {
    for (field, value) in [("crop centre x", cx), ("crop centre y", cy)] {
        if !value.is_finite() {
            return Err(OverlayError::BadStyle {
                field,
                value,
                why: "must be a finite number of pixels",
            });
        }
    }
    if !(crop.radii.is_finite() && crop.radii > 0.0) {
        return Err(OverlayError::BadStyle {
            field: "crop radii",
            value: crop.radii,
            why: "must be a positive number",
        });
    }
    let view = View::around(cx, cy, crop.radii * radius_px, crop.size_px)?;
    let mut canvas = render_gray(pixels, &view, style.levels)?;
    draw_annotations(&mut canvas, &view, mark, line, style)?;
    Ok(canvas)
}

/// A crop centred on the ball of `mark` ([`crop_at`]); an error for a frame where the ball was not
/// measured (no centre).
pub fn ball_crop(
    pixels: &GrayPixels,
    mark: &BallMark,
    radius_px: f64,
    line: Option<&SurfaceLine>,
    crop: &Crop,
    style: &Style,
) -> Result<RgbImage, OverlayError> {
    let (x, y, _) = mark.circle()?.ok_or(OverlayError::NoCentre {
        frame: mark.frame,
        status: mark.status.name(),
    })?;
    crop_at(pixels, x, y, radius_px, mark, line, crop, style)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::marks::Phase;
    use bouncelab_frames::Gray16Image;
    use image::{GrayImage, Luma};

    fn frame() -> GrayImage {
        // A bright disc of radius 20 at (40.3, 30.6) on a dark ramp.
        GrayImage::from_fn(96, 64, |x, y| {
            let d = (f64::from(x) - 40.3).hypot(f64::from(y) - 30.6);
            Luma([if d < 20.0 { 200 } else { (20 + x / 4) as u8 }])
        })
    }

    fn mark(status: Status, phase: Phase) -> BallMark {
        BallMark {
            frame: 1234,
            x_px: 40.3,
            y_px: 30.6,
            r_px: 20.0,
            status,
            phase,
        }
    }

    const LINE: SurfaceLine = SurfaceLine {
        x0: 48.0,
        y0: 51.2,
        slope: 0.02,
    };

    #[test]
    fn drawing_is_deterministic() {
        let p = GrayPixels::U8(frame());
        let m = mark(Status::Occluded, Phase::Contact);
        let a = annotate_frame(&p, &m, Some(&LINE), 2.0, &Style::default()).unwrap();
        let b = annotate_frame(&p, &m, Some(&LINE), 2.0, &Style::default()).unwrap();
        assert_eq!(a, b);
        assert_eq!(crate::encode_png(&a).unwrap(), crate::encode_png(&b).unwrap());
    }

    #[test]
    fn the_circle_passes_through_the_radius_in_the_phase_colour() {
        let p = GrayPixels::U8(frame());
        let style = Style {
            font_scale: Some(0),
            opacity: 1.0,
            ..Style::default()
        };
        for zoom in [1.0, 3.0] {
            let m = mark(Status::Ok, Phase::FlightIn);
            let img = annotate_frame(&p, &m, None, zoom, &style).unwrap();
            let view = View::full(96, 64, zoom).unwrap();
            let colour = phase_colour(Phase::FlightIn);
            let plain = render_gray(&p, &view, Levels::FULL).unwrap();
            // How much of the ring's colour a canvas pixel took (0 untouched, 1 fully covered).
            let alpha = |u: i64, v: i64| {
                let (a, b) = (img.get_pixel(u as u32, v as u32), plain.get_pixel(u as u32, v as u32));
                (0..3)
                    .map(|c| {
                        let span = f64::from(colour.0[c]) - f64::from(b.0[c]);
                        if span.abs() < 40.0 {
                            0.0
                        } else {
                            (f64::from(a.0[c]) - f64::from(b.0[c])) / span
                        }
                    })
                    .fold(0.0, f64::max)
            };
            for k in 0..12 {
                let t = f64::from(k) * std::f64::consts::TAU / 12.0;
                let at = |r: f64| {
                    let (u, v) = view.to_canvas(40.3 + r * t.cos(), 30.6 + r * t.sin());
                    (u.round() as i64, v.round() as i64)
                };
                // Some canvas pixel next to the rim point is mostly ring; three frame px off it, none is touched.
                let (u, v) = at(20.0);
                let best = (-1..=1)
                    .flat_map(|i| (-1..=1).map(move |j| (i, j)))
                    .map(|(i, j)| alpha(u + i, v + j));
                let best = best.fold(0.0, f64::max);
                assert!(best > 0.6, "zoom {zoom}, angle {k}: coverage {best}");
                for r in [17.0, 23.0] {
                    let (u, v) = at(r);
                    assert_eq!(
                        img.get_pixel(u as u32, v as u32),
                        plain.get_pixel(u as u32, v as u32),
                        "zoom {zoom}, angle {k}, r {r}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_sixteen_bit_frame_gives_the_picture_of_its_eight_bit_copy() {
        let img = frame();
        let wide = Gray16Image::from_fn(96, 64, |x, y| Luma([u16::from(img.get_pixel(x, y).0[0]) * 257]));
        let (a, b) = (GrayPixels::U8(img), GrayPixels::U16(wide));
        let m = mark(Status::Ok, Phase::FlightOut);
        let s = Style::default();
        assert_eq!(
            annotate_frame(&a, &m, Some(&LINE), 1.0, &s).unwrap(),
            annotate_frame(&b, &m, Some(&LINE), 1.0, &s).unwrap()
        );
        let c = Crop::default();
        assert_eq!(
            ball_crop(&a, &m, 20.0, Some(&LINE), &c, &s).unwrap(),
            ball_crop(&b, &m, 20.0, Some(&LINE), &c, &s).unwrap()
        );
    }

    #[test]
    fn the_surface_line_is_drawn_where_it_is() {
        let p = GrayPixels::U8(GrayImage::from_pixel(96, 64, Luma([0])));
        let style = Style {
            font_scale: Some(0),
            opacity: 1.0,
            stroke_px: 1.0,
            ..Style::default()
        };
        let m = mark(Status::Absent, Phase::Unknown);
        let img = annotate_frame(&p, &m, Some(&LINE), 1.0, &style).unwrap();
        let yellow = SurfaceLine::colour();
        for x in [10u32, 48, 80] {
            let (mut s, mut sy) = (0.0, 0.0);
            for y in 5..59 {
                let a = f64::from(img.get_pixel(x, y).0[2]) / f64::from(yellow.0[2]);
                s += a;
                sy += a * f64::from(y);
            }
            let expected = LINE.y_at(f64::from(x));
            assert!((sy / s - expected).abs() < 0.03, "column {x}: {} vs {expected}", sy / s);
        }
    }

    #[test]
    fn a_crop_puts_the_ball_in_the_middle_at_the_asked_size() {
        let p = GrayPixels::U8(frame());
        let m = mark(Status::Ok, Phase::Contact);
        let style = Style {
            font_scale: Some(0),
            ..Style::default()
        };
        let img = ball_crop(&p, &m, 20.0, None, &Crop::default(), &style).unwrap();
        assert_eq!(img.dimensions(), (160, 160));
        // The disc's bright pixels are centred on the tile's centre (79.5, 79.5).
        let (mut n, mut sx, mut sy) = (0.0, 0.0, 0.0);
        for (x, y, px) in img.enumerate_pixels() {
            if px.0 == [200, 200, 200] {
                n += 1.0;
                sx += f64::from(x);
                sy += f64::from(y);
            }
        }
        assert!(
            (sx / n - 79.5).abs() < 0.3 && (sy / n - 79.5).abs() < 0.3,
            "{} {}",
            sx / n,
            sy / n
        );
    }

    #[test]
    fn absent_frames_get_a_border_and_no_circle() {
        let p = GrayPixels::U8(frame());
        let m = BallMark {
            x_px: f64::NAN,
            y_px: f64::NAN,
            r_px: f64::NAN,
            ..mark(Status::Absent, Phase::FlightIn)
        };
        let quiet = Style {
            font_scale: Some(0),
            ..Style::default()
        };
        let img = annotate_frame(&p, &m, None, 1.0, &quiet).unwrap();
        assert_eq!(*img.get_pixel(50, 2), status_colour(Status::Absent));
        let ring = phase_colour(Phase::FlightIn);
        assert!(img.pixels().all(|px| *px != ring));
        let e = ball_crop(&p, &m, 20.0, None, &Crop::default(), &Style::default()).unwrap_err();
        assert!(
            e.to_string().contains("frame 1234") && e.to_string().contains("absent"),
            "{e}"
        );
    }

    #[test]
    fn bad_marks_and_styles_are_errors() {
        let p = GrayPixels::U8(frame());
        let bad = BallMark {
            r_px: f64::INFINITY,
            ..mark(Status::Ok, Phase::FlightIn)
        };
        assert!(annotate_frame(&p, &bad, None, 1.0, &Style::default()).is_err());
        let m = mark(Status::Ok, Phase::FlightIn);
        let s = Style {
            stroke_px: 0.0,
            ..Style::default()
        };
        assert!(
            annotate_frame(&p, &m, None, 1.0, &s)
                .unwrap_err()
                .to_string()
                .contains("stroke_px")
        );
        let c = Crop {
            radii: f64::NAN,
            ..Crop::default()
        };
        assert!(ball_crop(&p, &m, 20.0, None, &c, &Style::default()).is_err());
        let empty = GrayPixels::U8(GrayImage::new(0, 0));
        assert!(annotate_frame(&empty, &m, None, 1.0, &Style::default()).is_err());
    }
}
