//! The tracking shown: a frame with the fitted circle, its centre, the surface line, the tracker's status
//! and the impact's phase drawn on it, so a person can check the tracking by eye; crops around the ball,
//! the key-frame strip of a shot and contact sheets, as RGB images or PNG bytes (for files, or base64 data
//! URIs in the report).
//!
//! Inputs are plain data ([`BallMark`] per frame, [`SurfaceLine`]; the tracker's [`Status`] and the
//! estimate's [`Phase`], re-exported from their crates), so stored trajectory rows and a fresh track feed it
//! alike. The main design choice: the circle, line and cross are drawn anti-aliased at their
//! sub-pixel positions, at the canvas's own resolution after the frame has been resampled (bilinear) into
//! it, because imageproc's integer shapes would move them by up to half a pixel and hide the very error a
//! person is looking for. Rectangles, borders and the text of a tiny built-in bitmap font (no font file)
//! use imageproc's drawing. See `docs/overlay.md` for the colours.
//!
//! ```
//! use bouncelab_frames::GrayPixels;
//! use bouncelab_overlay::{BallMark, Phase, Status, Style, SurfaceLine, annotate_frame, encode_png};
//! let pixels = GrayPixels::U8(image::GrayImage::new(64, 48));
//! let mark = BallMark { frame: 7, x_px: 30.2, y_px: 20.7, r_px: 12.0, status: Status::Ok, phase: Phase::FlightIn };
//! let line = SurfaceLine { x0: 32.0, y0: 40.5, slope: 0.0 };
//! let picture = annotate_frame(&pixels, &mark, Some(&line), 2.0, &Style::default())?;
//! let png: Vec<u8> = encode_png(&picture)?;
//! # Ok::<(), bouncelab_overlay::OverlayError>(())
//! ```

#![warn(missing_docs)]

mod annotate;
mod error;
mod font;
mod keyframes;
mod marks;
mod paint;
mod sheet;
mod shot;
mod view;

pub use annotate::{Crop, Style, annotate_frame, ball_crop, crop_at, draw_annotations};
pub use error::OverlayError;
pub use font::{draw_text, text_size};
pub use keyframes::{ContactRule, KeyFrames, KeyRole, ShotPhases, key_frames_from_trajectory, phases_from_trajectory};
pub use marks::{BallMark, Phase, Status, SurfaceLine, phase_colour, phase_label, status_colour, status_label};
pub use paint::{Dash, draw_line_across, draw_ring, draw_segment};
pub use sheet::{SheetLayout, StripFrame, Tile, contact_sheet, key_frame_strip};
pub use shot::{choose_key_frames, shot_strip};
pub use view::{Levels, MAX_CANVAS_PIXELS, OUTSIDE, View, render_gray};

use image::RgbImage;

/// How hard the PNG encoder works.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PngSpeed {
    /// Small files (zlib level 3, adaptive filters: on a noisy 512×512 frame 4 % smaller and 5× faster than
    /// the encoder's default level); for sheets and strips embedded in a report.
    #[default]
    Small,
    /// About 12× faster than [`PngSpeed::Small`] on noisy frames, files about twice as large; for writing
    /// every frame of a clip.
    Fast,
}

/// The picture as PNG bytes (8-bit RGB), small ([`PngSpeed::Small`]).
///
/// Cost: ≈ 12 ms for a noisy 512×512 frame (`docs/performance.md`); [`PngSpeed::Fast`] takes ≈ 1 ms.
pub fn encode_png(img: &RgbImage) -> Result<Vec<u8>, OverlayError> {
    encode_png_with(img, PngSpeed::Small)
}

/// The picture as PNG bytes at the given encoder speed.
pub fn encode_png_with(img: &RgbImage, speed: PngSpeed) -> Result<Vec<u8>, OverlayError> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut out = Vec::new();
    let (compression, filter) = match speed {
        PngSpeed::Small => (CompressionType::Level(3), FilterType::Adaptive),
        PngSpeed::Fast => (CompressionType::Fast, FilterType::Sub),
    };
    PngEncoder::new_with_quality(&mut out, compression, filter).write_image(
        img.as_raw(),
        img.width(),
        img.height(),
        image::ExtendedColorType::Rgb8,
    )?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_bytes_decode_to_the_same_picture() {
        let img = RgbImage::from_fn(33, 17, |x, y| image::Rgb([x as u8 * 7, y as u8 * 13, 99]));
        for speed in [PngSpeed::Small, PngSpeed::Fast] {
            let bytes = encode_png_with(&img, speed).unwrap();
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
            let back = image::load_from_memory(&bytes).unwrap().to_rgb8();
            assert_eq!(back, img);
        }
    }
}
