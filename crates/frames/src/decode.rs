//! Decoding one frame file into [`GrayPixels`].
//!
//! Every format goes through the `image` crate by default. PNG, the lab's usual format and the pipeline's
//! bottleneck, can also go through `zune-png` ([`PngDecoder::Zune`]) for the plain variants it is checked
//! byte-identical to `image` on (8/16-bit gray, gray+alpha, RGB, RGBA, not interlaced; palette, sub-8-bit
//! and interlaced PNGs and anything it rejects fall back to `image`). Measured on noisy 512×512 8-bit
//! frames (`docs/frames-decoding.md`), `image` 0.25 (png 0.18) was the faster of the two — 1.1–3.5× — so
//! it is the default and `zune-png` stays as the measured alternative. Colour is converted to luma with
//! `image`'s Rec. 709 weights on both paths.

use std::path::Path;

use image::{DynamicImage, ImageBuffer, ImageFormat};

use crate::pixels::GrayPixels;

/// Which PNG decoder to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum PngDecoder {
    /// The `image` crate's decoder (png 0.18): the default, measured fastest here, and the reference.
    #[default]
    Image,
    /// `zune-png` 0.4 for the variants it handles, `image` for the rest (byte-identical, measured slower).
    Zune,
}

/// An image file format a clip may hold, from the file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum FrameFormat {
    /// `.png`
    Png,
    /// `.tif`, `.tiff`
    Tiff,
    /// `.bmp`
    Bmp,
    /// `.pgm`, `.ppm`, `.pnm` (binary or ASCII netpbm)
    Pnm,
    /// `.jpg`, `.jpeg`
    Jpeg,
}

impl FrameFormat {
    /// The format of a file from its extension (case-insensitive), or `None` if it is not a frame.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "png" => Self::Png,
            "tif" | "tiff" => Self::Tiff,
            "bmp" => Self::Bmp,
            "pgm" | "ppm" | "pnm" => Self::Pnm,
            "jpg" | "jpeg" => Self::Jpeg,
            _ => return None,
        })
    }

    fn image_format(self) -> ImageFormat {
        match self {
            Self::Png => ImageFormat::Png,
            Self::Tiff => ImageFormat::Tiff,
            Self::Bmp => ImageFormat::Bmp,
            Self::Pnm => ImageFormat::Pnm,
            Self::Jpeg => ImageFormat::Jpeg,
        }
    }
}

/// Why one frame file could not be decoded.
#[derive(Debug)]
pub(crate) enum DecodeError {
    /// A TIFF with more than one page, met among other frame files.
    MultiPage,
    /// The header gives this width and height, in pixels, not the clip's (nothing was decoded).
    Size((u32, u32)),
    /// The decoder's (or the OS's) message.
    Other(String),
}

/// A frame file's width and height, in pixels, from its header only (nothing is decoded).
pub(crate) fn header_dimensions(path: &Path) -> Result<(u32, u32), String> {
    image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| e.to_string())
        .and_then(|r| r.into_dimensions().map_err(|e| e.to_string()))
}

/// Reads and decodes one file to gray pixels, if its header says it is `expected` (width, height) pixels:
/// a frame of another size (a corrupt or hostile header among them) is refused before its buffer exists.
pub(crate) fn decode_path(path: &Path, png: PngDecoder, expected: (u32, u32)) -> Result<GrayPixels, DecodeError> {
    let other = DecodeError::Other;
    let format = FrameFormat::from_path(path).ok_or_else(|| other("not a supported image file".to_string()))?;
    let bytes = std::fs::read(path).map_err(|e| other(e.to_string()))?;
    // Only a stack's first page would be decoded: refuse rather than lose the others.
    if format == FrameFormat::Tiff && crate::camera::tiff_has_more_pages(&bytes) {
        return Err(DecodeError::MultiPage);
    }
    let size = image::ImageReader::with_format(std::io::Cursor::new(&bytes), format.image_format())
        .into_dimensions()
        .map_err(|e| other(e.to_string()))?;
    if size != expected {
        return Err(DecodeError::Size(size));
    }
    decode_bytes(&bytes, format, png).map(to_gray).map_err(other)
}

/// Decodes encoded bytes to an `image` image, keeping the file's own colour type and depth.
#[doc(hidden)]
pub fn decode_bytes(bytes: &[u8], format: FrameFormat, png: PngDecoder) -> Result<DynamicImage, String> {
    if format == FrameFormat::Png && png == PngDecoder::Zune && zune_handles(bytes) {
        // zune-png is strict; whatever it rejects, `image` gets a chance at (and gives the error message).
        if let Ok(img) = decode_png_zune(bytes) {
            return Ok(img);
        }
    }
    if format == FrameFormat::Jpeg && !has_jpeg_end(bytes) {
        // The JPEG decoder fills a truncated scan with gray instead of failing: catch it here.
        return Err("truncated JPEG (no end-of-image marker)".to_string());
    }
    image::load_from_memory_with_format(bytes, format.image_format()).map_err(|e| e.to_string())
}

/// True if a JPEG's end-of-image marker (FF D9) is within its last 64 bytes (trailing padding allowed).
/// Entropy-coded data cannot contain FF D9 (FF is byte-stuffed), so a cut file fails this test.
fn has_jpeg_end(bytes: &[u8]) -> bool {
    let tail = &bytes[bytes.len().saturating_sub(64)..];
    tail.windows(2).any(|w| w == [0xFF, 0xD9])
}

/// True for PNGs whose IHDR says 8/16-bit, gray/gray+alpha/RGB/RGBA, not interlaced.
fn zune_handles(bytes: &[u8]) -> bool {
    const SIG: &[u8] = b"\x89PNG\r\n\x1a\n";
    if bytes.len() < 33 || &bytes[..8] != SIG || &bytes[12..16] != b"IHDR" {
        return false;
    }
    let (depth, colour, interlace) = (bytes[24], bytes[25], bytes[28]);
    matches!(depth, 8 | 16) && matches!(colour, 0 | 2 | 4 | 6) && interlace == 0
}

fn decode_png_zune(bytes: &[u8]) -> Result<DynamicImage, String> {
    use zune_png::zune_core::{colorspace::ColorSpace, result::DecodingResult};
    // Guard against a panic inside the decoder on hostile input: fall back to `image` instead.
    std::panic::catch_unwind(|| {
        let mut dec = zune_png::PngDecoder::new(bytes);
        dec.decode_headers().map_err(|e| format!("{e:?}"))?;
        let (w, h) = dec.get_dimensions().ok_or("no PNG header")?;
        let cs = dec.get_colorspace().ok_or("no PNG header")?;
        let (w, h) = (
            u32::try_from(w).map_err(|_| "too wide")?,
            u32::try_from(h).map_err(|_| "too tall")?,
        );
        let bad = || "decoded buffer has the wrong size".to_string();
        let img = match (dec.decode().map_err(|e| format!("{e:?}"))?, cs) {
            (DecodingResult::U8(v), ColorSpace::Luma) => {
                DynamicImage::ImageLuma8(ImageBuffer::from_raw(w, h, v).ok_or_else(bad)?)
            }
            (DecodingResult::U8(v), ColorSpace::LumaA) => {
                DynamicImage::ImageLumaA8(ImageBuffer::from_raw(w, h, v).ok_or_else(bad)?)
            }
            (DecodingResult::U8(v), ColorSpace::RGB) => {
                DynamicImage::ImageRgb8(ImageBuffer::from_raw(w, h, v).ok_or_else(bad)?)
            }
            (DecodingResult::U8(v), ColorSpace::RGBA) => {
                DynamicImage::ImageRgba8(ImageBuffer::from_raw(w, h, v).ok_or_else(bad)?)
            }
            (DecodingResult::U16(v), ColorSpace::Luma) => {
                DynamicImage::ImageLuma16(ImageBuffer::from_raw(w, h, v).ok_or_else(bad)?)
            }
            (DecodingResult::U16(v), ColorSpace::LumaA) => {
                DynamicImage::ImageLumaA16(ImageBuffer::from_raw(w, h, v).ok_or_else(bad)?)
            }
            (DecodingResult::U16(v), ColorSpace::RGB) => {
                DynamicImage::ImageRgb16(ImageBuffer::from_raw(w, h, v).ok_or_else(bad)?)
            }
            (DecodingResult::U16(v), ColorSpace::RGBA) => {
                DynamicImage::ImageRgba16(ImageBuffer::from_raw(w, h, v).ok_or_else(bad)?)
            }
            _ => return Err("unsupported PNG layout".to_string()),
        };
        Ok(img)
    })
    .unwrap_or_else(|_| Err("zune-png panicked".to_string()))
}

/// Gray at native depth: 8-bit stays 8-bit, 16-bit (and float) becomes 16-bit, colour becomes luma.
fn to_gray(img: DynamicImage) -> GrayPixels {
    match img {
        DynamicImage::ImageLuma8(i) => GrayPixels::U8(i),
        DynamicImage::ImageLuma16(i) => GrayPixels::U16(i),
        DynamicImage::ImageLumaA8(_) | DynamicImage::ImageRgb8(_) | DynamicImage::ImageRgba8(_) => {
            GrayPixels::U8(img.to_luma8())
        }
        other => GrayPixels::U16(other.to_luma16()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{encode_png, noisy_gradient};
    use image::ColorType;

    fn both(bytes: &[u8]) -> (DynamicImage, DynamicImage) {
        let fast = decode_png_zune(bytes).expect("zune decodes");
        let reference = decode_bytes(bytes, FrameFormat::Png, PngDecoder::Image).expect("image decodes");
        (fast, reference)
    }

    #[test]
    fn zune_matches_image_byte_for_byte_on_every_plain_layout() {
        for colour in [
            ColorType::L8,
            ColorType::L16,
            ColorType::La8,
            ColorType::La16,
            ColorType::Rgb8,
            ColorType::Rgb16,
            ColorType::Rgba8,
            ColorType::Rgba16,
        ] {
            let img = noisy_gradient(67, 41, 7, colour);
            let bytes = encode_png(&img);
            assert!(zune_handles(&bytes), "{colour:?}");
            let (fast, reference) = both(&bytes);
            assert_eq!(fast.color(), reference.color(), "{colour:?}");
            assert_eq!(fast.as_bytes(), reference.as_bytes(), "{colour:?}");
            assert_eq!(fast.as_bytes(), img.as_bytes(), "{colour:?}: round trip");
            assert_eq!(to_gray(fast), to_gray(reference), "{colour:?}");
        }
    }

    #[test]
    fn palette_and_interlaced_pngs_fall_back_to_image() {
        // A 2×1 palette PNG (colour type 3) and a 1×1 Adam7-interlaced gray PNG, written by hand.
        for (bytes, expect) in [
            (crate::testutil::palette_png(), vec![10u8, 200]),
            (crate::testutil::interlaced_png(), vec![77u8]),
        ] {
            assert!(!zune_handles(&bytes));
            let px = to_gray(decode_bytes(&bytes, FrameFormat::Png, PngDecoder::Zune).unwrap());
            assert_eq!(px.as_u8().unwrap().as_raw(), &expect);
        }
    }

    #[test]
    fn truncated_png_is_an_error_for_both_decoders() {
        let bytes = encode_png(&noisy_gradient(64, 64, 1, ColorType::L8));
        for cut in [bytes.len() / 2, bytes.len() - 20, 40] {
            for dec in [PngDecoder::Zune, PngDecoder::Image] {
                assert!(
                    decode_bytes(&bytes[..cut], FrameFormat::Png, dec).is_err(),
                    "cut {cut} {dec:?}"
                );
            }
        }
    }

    #[test]
    fn formats_from_extensions() {
        assert_eq!(
            FrameFormat::from_path(Path::new("a/B_01.TIFF")),
            Some(FrameFormat::Tiff)
        );
        assert_eq!(FrameFormat::from_path(Path::new("x.jpeg")), Some(FrameFormat::Jpeg));
        assert_eq!(FrameFormat::from_path(Path::new("clip.toml")), None);
        assert_eq!(FrameFormat::from_path(Path::new("noext")), None);
    }
}
