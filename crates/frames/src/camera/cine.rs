//! Phantom (Vision Research) `.cine` files.
//!
//! Layout from Vision Research's "Cine File Format" description as implemented by the public readers
//! PIMS (`soft-matter/pims`, `pims/cine.py`) and pycine (`ottomatic-io/pycine`), little-endian throughout:
//!
//! - `CINEFILEHEADER` (44 bytes at 0): `Type` "CI", `Headersize` u16, `Compression` u16 (0 = gray or
//!   colour bitmap), `Version` u16, `FirstMovieImage` i32, `TotalImageCount` u32, `FirstImageNo` i32,
//!   `ImageCount` u32, `OffImageHeader` u32, `OffSetup` u32, `OffImageOffsets` u32, `TriggerTime` u64.
//! - `BITMAPINFOHEADER` (40 bytes at `OffImageHeader`): `biSize` u32, `biWidth` i32, `biHeight` i32
//!   (positive: rows stored bottom-up), `biPlanes` u16, `biBitCount` u16, `biCompression` u32 (0 = plain
//!   8/16-bit, 256 = 10-bit packed "P10", 1024 = 12-bit packed "P12L"), `biSizeImage` u32, …
//! - `SETUP` (at `OffSetup`, `Length` u16 at +142): `FrameRate16` u16 at +0, `Shutter16` u16 (µs) at +2,
//!   `Serial` u32 at +743, `FrameRate` u32 at +768, `Shutter` u32 (µs) at +772, `CameraVersion` u32 at +792,
//!   `CFA` u32 at +808 (0 = monochrome), `RealBPP` u32 at +896, `ShutterNs` u32 at +1568.
//! - `ImageCount` u64 image offsets at `OffImageOffsets`; at each, an annotation block whose first u32 is its
//!   size (≥ 8) and whose last u32 is the image's size in bytes, then the image.
//!
//! Plain 8/16-bit images are stored bottom-up (as a bitmap with positive height); packed images top-down
//! (both readers above agree). 16-bit samples holding `RealBPP < 16` bits are shifted to full scale; P10
//! codes are the camera's log-like encoding, passed on unlinearised (with a warning).

use std::path::Path;

use super::unpack::{Packing, Pool};
use super::{CameraFile, CameraInfo, Layout, SourceFormat, check_size, header_error, map};
use crate::error::{FramesError, Result};
use crate::pixels::GrayPixels;
use crate::settings::Warning;

/// Annotation blocks larger than this are taken as corrupt (real ones are tens of bytes).
const MAX_ANNOTATION_BYTES: u32 = 1 << 20;

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    b.get(at..at + 2).map(|s| u16::from_le_bytes([s[0], s[1]]))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4).map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

fn i32_at(b: &[u8], at: usize) -> Option<i32> {
    u32_at(b, at).map(|v| v as i32)
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    b.get(at..at + 8)
        .map(|s| u64::from_le_bytes(s.try_into().expect("8 bytes")))
}

/// Where a CINE file's frames are and how they are stored.
#[derive(Debug)]
pub(crate) struct Frames {
    table: usize,
    packing: Packing,
    bottom_up: bool,
    frame_bytes: usize,
}

impl Frames {
    pub(crate) fn decode(
        &self,
        map: &[u8],
        path: &Path,
        k: usize,
        (w, h): (u32, u32),
        pool: &Pool,
    ) -> Result<GrayPixels> {
        let err = |message: String| FramesError::Decode {
            path: path.into(),
            index: k as u64,
            message,
        };
        let offset = u64_at(map, self.table + 8 * k).ok_or_else(|| err("image offset table cut short".into()))?;
        let offset = usize::try_from(offset).map_err(|_| err(format!("image offset {offset} is outside the file")))?;
        let annotation = u32_at(map, offset).ok_or_else(|| {
            err(format!(
                "image offset {offset} is outside the file ({} bytes)",
                map.len()
            ))
        })?;
        if !(8..=MAX_ANNOTATION_BYTES).contains(&annotation) {
            return Err(err(format!(
                "annotation size {annotation} at byte {offset} is not a CINE annotation (8 to {MAX_ANNOTATION_BYTES} bytes)"
            )));
        }
        let data = offset + annotation as usize;
        let size = u32_at(map, data - 4).ok_or_else(|| err("annotation runs past the end of the file".into()))?;
        if size as usize != self.frame_bytes {
            return Err(err(format!(
                "image size {size} bytes, but {w}×{h} px at {} bits is {} bytes",
                self.packing.bits(),
                self.frame_bytes
            )));
        }
        let bytes = map.get(data..data + self.frame_bytes).ok_or_else(|| {
            err(format!(
                "image at bytes {data}–{} runs past the end of the file ({} bytes): truncated",
                data + self.frame_bytes,
                map.len()
            ))
        })?;
        Ok(self.packing.unpack(bytes, w, h, self.bottom_up, pool))
    }
}

/// The fields of `CINEFILEHEADER` the reader uses.
struct FileHeader {
    first_image_no: i32,
    image_count: u32,
    /// Byte offset of `BITMAPINFOHEADER`.
    off_bitmap: usize,
    /// Byte offset of `SETUP`.
    off_setup: usize,
    /// Byte offset of the image offset table.
    table: usize,
}

impl FileHeader {
    /// Reads and checks `CINEFILEHEADER`: the "CI" mark, uncompressed images, at least one image.
    fn read(path: &Path, b: &[u8]) -> Result<FileHeader> {
        let short = |field: &str| header_error(path, field, "the file ends before this field (truncated header)");
        if b.get(0..2) != Some(b"CI".as_slice()) {
            return Err(header_error(
                path,
                "CINEFILEHEADER.Type",
                "not \"CI\": not a Phantom .cine file",
            ));
        }
        let compression = u16_at(b, 4).ok_or_else(|| short("CINEFILEHEADER.Compression"))?;
        if compression != 0 {
            return Err(header_error(
                path,
                "CINEFILEHEADER.Compression",
                format!(
                    "{compression} ({}): only uncompressed (0) images are read; save the cine uncompressed",
                    if compression == 1 {
                        "JPEG"
                    } else {
                        "uninterpolated colour raw"
                    }
                ),
            ));
        }
        let header = FileHeader {
            first_image_no: i32_at(b, 16).ok_or_else(|| short("CINEFILEHEADER.FirstImageNo"))?,
            image_count: u32_at(b, 20).ok_or_else(|| short("CINEFILEHEADER.ImageCount"))?,
            off_bitmap: u32_at(b, 24).ok_or_else(|| short("CINEFILEHEADER.OffImageHeader"))? as usize,
            off_setup: u32_at(b, 28).ok_or_else(|| short("CINEFILEHEADER.OffSetup"))? as usize,
            table: u32_at(b, 32).ok_or_else(|| short("CINEFILEHEADER.OffImageOffsets"))? as usize,
        };
        if header.image_count == 0 {
            return Err(header_error(path, "CINEFILEHEADER.ImageCount", "0 images"));
        }
        Ok(header)
    }
}

/// The fields of `BITMAPINFOHEADER` the reader uses.
struct Bitmap {
    width: i32,
    /// Positive: rows stored bottom-up.
    height: i32,
    bit_count: u16,
    compression: u32,
}

impl Bitmap {
    fn read(path: &Path, b: &[u8], off_bitmap: usize) -> Result<Bitmap> {
        let bi = |at: usize, field: &str| -> Result<u32> {
            u32_at(b, off_bitmap + at).ok_or_else(|| {
                header_error(
                    path,
                    field,
                    format!(
                        "BITMAPINFOHEADER at byte {off_bitmap} (OffImageHeader) runs past the end of the file ({} bytes)",
                        b.len()
                    ),
                )
            })
        };
        Ok(Bitmap {
            width: bi(4, "BITMAPINFOHEADER.biWidth")? as i32,
            height: bi(8, "BITMAPINFOHEADER.biHeight")? as i32,
            bit_count: (bi(12, "BITMAPINFOHEADER.biBitCount")? >> 16) as u16,
            compression: bi(16, "BITMAPINFOHEADER.biCompression")?,
        })
    }

    /// How the images are packed, and the bits per pixel as stored, from the compression and bit count
    /// (`real_bpp`: the bits a 16-bit sample holds, from `SETUP`).
    fn packing(&self, path: &Path, real_bpp: Option<u32>) -> Result<(Packing, u32)> {
        Ok(match (self.compression, self.bit_count) {
            (0, 8) => (Packing::U8, 8),
            (0, 16) => (Packing::U16Le(real_bpp.map_or(0, |r| 16 - r)), 16),
            (256, _) => (Packing::P10, 10),
            (1024, _) => (Packing::P12, 12),
            (0, other) => {
                return Err(header_error(
                    path,
                    "BITMAPINFOHEADER.biBitCount",
                    format!(
                        "unknown bit depth {other} (this reader knows 8 and 16 bits, 10 and 12 bits packed; colour is not supported)"
                    ),
                ));
            }
            (other, _) => {
                return Err(header_error(
                    path,
                    "BITMAPINFOHEADER.biCompression",
                    format!(
                        "unknown image packing {other} (this reader knows 0 = plain, 256 = 10-bit, 1024 = 12-bit packed)"
                    ),
                ));
            }
        })
    }
}

/// The `SETUP` block: a field is read only when the block (by its own `Length`) and the file both hold it.
struct Setup<'a> {
    b: &'a [u8],
    at: usize,
    len: usize,
}

impl<'a> Setup<'a> {
    fn new(b: &'a [u8], off_setup: usize) -> Setup<'a> {
        Setup {
            b,
            at: off_setup,
            len: usize::from(u16_at(b, off_setup + 142).unwrap_or(0)),
        }
    }

    fn u32(&self, at: usize) -> Option<u32> {
        (at + 4 <= self.len).then(|| u32_at(self.b, self.at + at)).flatten()
    }

    fn u16(&self, at: usize) -> Option<u16> {
        (at + 2 <= self.len).then(|| u16_at(self.b, self.at + at)).flatten()
    }

    /// Frame rate, frames/s: `FrameRate`, else the older `FrameRate16`.
    fn fps(&self) -> Option<f64> {
        match self.u32(768).filter(|f| *f > 0) {
            Some(f) => Some(f64::from(f)),
            None => self.u16(0).filter(|f| *f > 0).map(f64::from),
        }
    }

    /// Exposure, s: `ShutterNs`, else `Shutter` or the older `Shutter16` (µs).
    fn exposure_s(&self) -> Option<f64> {
        match self.u32(1568).filter(|s| *s > 0) {
            Some(ns) => Some(f64::from(ns) * 1e-9),
            None => self
                .u32(772)
                .filter(|s| *s > 0)
                .or_else(|| self.u16(2).filter(|s| *s > 0).map(u32::from))
                .map(|us| f64::from(us) * 1e-6),
        }
    }
}

/// Checks that the image offset table lies in the file and that every offset leaves room for an image of
/// `frame_bytes` bytes.
fn check_offsets(path: &Path, b: &[u8], table: usize, image_count: u32, frame_bytes: u64) -> Result<()> {
    let table_end = (image_count as usize)
        .checked_mul(8)
        .and_then(|n| n.checked_add(table))
        .filter(|end| *end <= b.len())
        .ok_or_else(|| {
            header_error(
                path,
                "CINEFILEHEADER.OffImageOffsets",
                format!(
                    "a table of {image_count} image offsets at byte {table} runs past the end of the file ({} bytes)",
                    b.len()
                ),
            )
        })?;
    for (k, entry) in b[table..table_end].chunks_exact(8).enumerate() {
        let offset = u64::from_le_bytes(entry.try_into().expect("8 bytes"));
        if offset
            .checked_add(frame_bytes + 8)
            .is_none_or(|end| end > b.len() as u64)
        {
            return Err(header_error(
                path,
                &format!("pImage[{k}]"),
                format!(
                    "image offset {offset} leaves no room for a {frame_bytes}-byte image in the file ({} bytes)",
                    b.len()
                ),
            ));
        }
    }
    Ok(())
}

pub(crate) fn open(path: &Path, max_pixels: u64) -> Result<CameraFile> {
    let map = map(path)?;
    let b: &[u8] = &map;
    let header = FileHeader::read(path, b)?;
    let bitmap = Bitmap::read(path, b, header.off_bitmap)?;
    if bitmap.width <= 0 {
        return Err(header_error(
            path,
            "BITMAPINFOHEADER.biWidth",
            format!("{} px", bitmap.width),
        ));
    }
    let size = check_size(
        path,
        bitmap.width as u64,
        u64::from(bitmap.height.unsigned_abs()),
        max_pixels,
    )?;
    let setup = Setup::new(b, header.off_setup);
    if let Some(cfa) = setup.u32(808).filter(|c| *c != 0) {
        return Err(header_error(
            path,
            "SETUP.CFA",
            format!("{cfa}: a colour sensor's cine is not supported; record or save monochrome"),
        ));
    }
    let real_bpp = setup.u32(896).filter(|b| (1..=16).contains(b));
    let (packing, field_bits) = bitmap.packing(path, real_bpp)?;
    let pixels = u64::from(size.0) * u64::from(size.1);
    let frame_bytes = packing.frame_bytes(pixels).ok_or_else(|| {
        header_error(
            path,
            "BITMAPINFOHEADER.biCompression",
            format!(
                "{}×{} px cannot be stored whole at {field_bits} bits packed",
                size.0, size.1
            ),
        )
    })?;
    check_offsets(path, b, header.table, header.image_count, frame_bytes)?;
    let mut warnings = Vec::new();
    if packing == Packing::P10 {
        warnings.push(Warning::NonLinearPixels {
            path: path.into(),
            detail: "10-bit packed (P10) cine: pixel values are the camera's log-like codes, not linear in the \
                     light (edges are found as well; intensities are not comparable with linear files)"
                .into(),
        });
    }
    let info = CameraInfo {
        format: SourceFormat::PhantomCine,
        fps: setup.fps(),
        exposure_s: setup.exposure_s(),
        bit_depth: Some(packing.bits()),
        effective_bit_depth: real_bpp.map(|r| r as u8),
        effective_bit_side: None,
        camera_model: setup.u32(792).filter(|v| *v > 0).map(|v| format!("Phantom v{v}")),
        camera_serial: setup.u32(743).filter(|v| *v > 0).map(|v| v.to_string()),
        start_frame: Some(i64::from(header.first_image_no)),
        trigger_frame: Some(-i64::from(header.first_image_no)),
    };
    Ok(CameraFile {
        sources: vec![path.into()],
        path: path.into(),
        data_path: path.into(),
        layout: Layout::Cine(Frames {
            table: header.table,
            packing,
            bottom_up: bitmap.height > 0 && matches!(packing, Packing::U8 | Packing::U16Le(_)),
            frame_bytes: frame_bytes as usize,
        }),
        map,
        pool: Pool::default(),
        info,
        size,
        count: header.image_count as usize,
        warnings,
    })
}
