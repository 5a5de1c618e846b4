//! Decoded gray frames at their native bit depth.

use image::{GrayImage, ImageBuffer, Luma};

/// A 16-bit grayscale image (one `u16` per pixel, row-major).
pub type Gray16Image = ImageBuffer<Luma<u16>, Vec<u16>>;

/// One decoded frame's pixels, gray, at the file's own bit depth.
///
/// 8-bit files (and colour 8-bit files, converted to luma) give [`GrayPixels::U8`]; 16-bit files give
/// [`GrayPixels::U16`] so that no precision is lost. A tracker that only wants one type can call
/// [`GrayPixels::to_u8`] (free for 8-bit frames), [`GrayPixels::to_f32_normalised`] (0.0 = black, 1.0 =
/// full scale, for either depth) or read a pixel with [`GrayPixels::get_normalised`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum GrayPixels {
    /// 8-bit gray, values 0–255.
    U8(GrayImage),
    /// 16-bit gray, values 0–65535.
    U16(Gray16Image),
}

impl GrayPixels {
    /// Width in pixels.
    pub fn width(&self) -> u32 {
        match self {
            Self::U8(i) => i.width(),
            Self::U16(i) => i.width(),
        }
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        match self {
            Self::U8(i) => i.height(),
            Self::U16(i) => i.height(),
        }
    }

    /// (width, height) in pixels.
    pub fn dimensions(&self) -> (u32, u32) {
        (self.width(), self.height())
    }

    /// Bits per pixel: 8 or 16.
    pub fn bit_depth(&self) -> u8 {
        match self {
            Self::U8(_) => 8,
            Self::U16(_) => 16,
        }
    }

    /// The largest possible pixel value: 255 or 65535.
    pub fn max_value(&self) -> u16 {
        match self {
            Self::U8(_) => u8::MAX.into(),
            Self::U16(_) => u16::MAX,
        }
    }

    /// The 8-bit image, if this frame is 8-bit.
    pub fn as_u8(&self) -> Option<&GrayImage> {
        match self {
            Self::U8(i) => Some(i),
            Self::U16(_) => None,
        }
    }

    /// The 16-bit image, if this frame is 16-bit.
    pub fn as_u16(&self) -> Option<&Gray16Image> {
        match self {
            Self::U8(_) => None,
            Self::U16(i) => Some(i),
        }
    }

    /// The frame as 8-bit gray: borrowed when it already is, else 16-bit values scaled to 0–255 (rounded,
    /// as `image` does).
    pub fn to_u8(&self) -> std::borrow::Cow<'_, GrayImage> {
        match self {
            Self::U8(i) => std::borrow::Cow::Borrowed(i),
            Self::U16(i) => std::borrow::Cow::Owned(image::DynamicImage::ImageLuma16(i.clone()).to_luma8()),
        }
    }

    /// Pixel (x, y) as a fraction of full scale (0.0–1.0), or `None` outside the image.
    pub fn get_normalised(&self, x: u32, y: u32) -> Option<f32> {
        match self {
            Self::U8(i) => i.get_pixel_checked(x, y).map(|p| f32::from(p.0[0]) / 255.0),
            Self::U16(i) => i.get_pixel_checked(x, y).map(|p| f32::from(p.0[0]) / 65535.0),
        }
    }

    /// All pixels, row-major, as fractions of full scale (0.0–1.0).
    pub fn to_f32_normalised(&self) -> Vec<f32> {
        match self {
            Self::U8(i) => i.as_raw().iter().map(|&v| f32::from(v) / 255.0).collect(),
            Self::U16(i) => i.as_raw().iter().map(|&v| f32::from(v) / 65535.0).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accessors_for_both_depths() {
        let a = GrayPixels::U8(GrayImage::from_pixel(3, 2, Luma([255])));
        let b = GrayPixels::U16(Gray16Image::from_pixel(3, 2, Luma([65535])));
        for p in [&a, &b] {
            assert_eq!(p.dimensions(), (3, 2));
            assert_eq!(p.get_normalised(2, 1), Some(1.0));
            assert_eq!(p.get_normalised(3, 1), None);
            assert_eq!(p.to_f32_normalised(), vec![1.0; 6]);
            assert_eq!(p.to_u8().as_raw(), &vec![255u8; 6]);
        }
        assert_eq!((a.bit_depth(), b.bit_depth()), (8, 16));
        assert!(a.as_u8().is_some() && a.as_u16().is_none() && b.as_u16().is_some());
    }
}
