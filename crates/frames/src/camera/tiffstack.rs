//! Multi-page TIFF stacks: every page (image file directory) a frame.
//!
//! Opening walks the chain of image file directories once (offsets only, each checked against the file's
//! length, cycles refused) and reads the first page's header with the `tiff` crate. A page is then decoded
//! by the `tiff` crate from a reader over the memory map whose first bytes are a rewritten TIFF header
//! pointing straight at that page's directory: every page is one seek away whatever its position, so pages
//! decode independently and in parallel, with any compression the `tiff` crate reads.

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use image::DynamicImage;
use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult};

use super::{CameraFile, CameraInfo, Layout, SourceFormat, check_size, header_error, map};
use crate::error::{FramesError, Result};
use crate::pixels::GrayPixels;

/// Pages beyond this many are refused (a corrupt chain).
const MAX_PAGES: usize = 10_000_000;

/// The byte order and offset size of a TIFF file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Form {
    little: bool,
    big: bool,
}

impl Form {
    fn of(b: &[u8]) -> Option<Self> {
        let little = match b.get(0..2)? {
            b"II" => true,
            b"MM" => false,
            _ => return None,
        };
        let magic = read_u16(b, 2, little)?;
        match magic {
            42 => Some(Self { little, big: false }),
            43 => Some(Self { little, big: true }),
            _ => None,
        }
    }

    fn first_ifd(self, b: &[u8]) -> Option<u64> {
        if self.big {
            read_u64(b, 8, self.little)
        } else {
            read_u32(b, 4, self.little).map(u64::from)
        }
    }

    /// The offset of the directory after the one at `ifd`, 0 at the end.
    fn next_ifd(self, b: &[u8], ifd: usize) -> Option<u64> {
        if self.big {
            let n = read_u64(b, ifd, self.little)?;
            let at = (n.checked_mul(20)?).checked_add(ifd as u64 + 8)?;
            read_u64(b, usize::try_from(at).ok()?, self.little)
        } else {
            let n = u64::from(read_u16(b, ifd, self.little)?);
            read_u32(b, ifd + 2 + 12 * n as usize, self.little).map(u64::from)
        }
    }

    /// A header pointing at the directory at `ifd`.
    fn header(self, ifd: u64) -> ([u8; 16], usize) {
        let mut h = [0u8; 16];
        h[0..2].copy_from_slice(if self.little { b"II" } else { b"MM" });
        let put16 = |v: u16| if self.little { v.to_le_bytes() } else { v.to_be_bytes() };
        if self.big {
            h[2..4].copy_from_slice(&put16(43));
            h[4..6].copy_from_slice(&put16(8));
            h[8..16].copy_from_slice(&if self.little {
                ifd.to_le_bytes()
            } else {
                ifd.to_be_bytes()
            });
            (h, 16)
        } else {
            h[2..4].copy_from_slice(&put16(42));
            let ifd = ifd as u32;
            h[4..8].copy_from_slice(&if self.little {
                ifd.to_le_bytes()
            } else {
                ifd.to_be_bytes()
            });
            (h, 8)
        }
    }
}

fn read_u16(b: &[u8], at: usize, little: bool) -> Option<u16> {
    let s: [u8; 2] = b.get(at..at.checked_add(2)?)?.try_into().ok()?;
    Some(if little {
        u16::from_le_bytes(s)
    } else {
        u16::from_be_bytes(s)
    })
}

fn read_u32(b: &[u8], at: usize, little: bool) -> Option<u32> {
    let s: [u8; 4] = b.get(at..at.checked_add(4)?)?.try_into().ok()?;
    Some(if little {
        u32::from_le_bytes(s)
    } else {
        u32::from_be_bytes(s)
    })
}

fn read_u64(b: &[u8], at: usize, little: bool) -> Option<u64> {
    let s: [u8; 8] = b.get(at..at.checked_add(8)?)?.try_into().ok()?;
    Some(if little {
        u64::from_le_bytes(s)
    } else {
        u64::from_be_bytes(s)
    })
}

/// True if these TIFF bytes hold more than one page (cheap: reads the first directory's link only).
pub(crate) fn has_more_pages(b: &[u8]) -> bool {
    let Some(form) = Form::of(b) else { return false };
    form.first_ifd(b)
        .and_then(|ifd| form.next_ifd(b, usize::try_from(ifd).ok()?))
        .is_some_and(|next| next != 0)
}

/// The file's bytes with its header replaced by one that points at another directory.
struct Overlay<'a> {
    head: [u8; 16],
    head_len: usize,
    data: &'a [u8],
    pos: u64,
}

impl Read for Overlay<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let Ok(pos) = usize::try_from(self.pos) else {
            return Ok(0);
        };
        if pos >= self.data.len() {
            return Ok(0);
        }
        let n = if pos < self.head_len {
            let n = buf.len().min(self.head_len - pos);
            buf[..n].copy_from_slice(&self.head[pos..pos + n]);
            n
        } else {
            let n = buf.len().min(self.data.len() - pos);
            buf[..n].copy_from_slice(&self.data[pos..pos + n]);
            n
        };
        self.pos += n as u64;
        Ok(n)
    }
}

impl Seek for Overlay<'_> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let target = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::End(d) => (self.data.len() as u64).checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        self.pos = target.ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "seek before start"))?;
        Ok(self.pos)
    }
}

/// The directories of a stack.
#[derive(Debug)]
pub(crate) struct Pages {
    form: Form,
    ifds: Vec<u64>,
}

impl Pages {
    fn decoder<'a>(&self, map: &'a [u8], k: usize) -> tiff::TiffResult<Decoder<Overlay<'a>>> {
        let (head, head_len) = self.form.header(self.ifds[k]);
        Decoder::new(Overlay {
            head,
            head_len,
            data: map,
            pos: 0,
        })
    }

    pub(crate) fn decode(&self, map: &[u8], path: &Path, k: usize, size: (u32, u32)) -> Result<GrayPixels> {
        let err = |message: String| FramesError::Decode {
            path: path.into(),
            index: k as u64,
            message,
        };
        let mut dec = self.decoder(map, k).map_err(|e| err(e.to_string()))?;
        let dims = dec.dimensions().map_err(|e| err(e.to_string()))?;
        if dims != size {
            return Err(err(format!(
                "page is {}×{} px but the stack's first page is {}×{} px",
                dims.0, dims.1, size.0, size.1
            )));
        }
        let colour = dec.colortype().map_err(|e| err(e.to_string()))?;
        let data = dec.read_image().map_err(|e| err(e.to_string()))?;
        to_gray(colour, data, size).ok_or_else(|| err(format!("unsupported page layout {colour:?}")))
    }
}

fn to_gray(colour: ColorType, data: DecodingResult, (w, h): (u32, u32)) -> Option<GrayPixels> {
    let img = match (colour, data) {
        (ColorType::Gray(8), DecodingResult::U8(v)) => return image::GrayImage::from_raw(w, h, v).map(GrayPixels::U8),
        (ColorType::Gray(16), DecodingResult::U16(v)) => {
            return crate::Gray16Image::from_raw(w, h, v).map(GrayPixels::U16);
        }
        (ColorType::RGB(8), DecodingResult::U8(v)) => DynamicImage::ImageRgb8(image::RgbImage::from_raw(w, h, v)?),
        (ColorType::RGBA(8), DecodingResult::U8(v)) => DynamicImage::ImageRgba8(image::RgbaImage::from_raw(w, h, v)?),
        (ColorType::RGB(16), DecodingResult::U16(v)) => {
            DynamicImage::ImageRgb16(image::ImageBuffer::from_raw(w, h, v)?)
        }
        (ColorType::RGBA(16), DecodingResult::U16(v)) => {
            DynamicImage::ImageRgba16(image::ImageBuffer::from_raw(w, h, v)?)
        }
        _ => return None,
    };
    Some(match img {
        DynamicImage::ImageRgb8(_) | DynamicImage::ImageRgba8(_) => GrayPixels::U8(img.to_luma8()),
        other => GrayPixels::U16(other.to_luma16()),
    })
}

pub(crate) fn open(path: &Path, max_pixels: u64) -> Result<CameraFile> {
    let map = map(path)?;
    let b: &[u8] = &map;
    let form =
        Form::of(b).ok_or_else(|| header_error(path, "TIFF header", "not a TIFF file (no II*/MM* signature)"))?;
    let mut ifds = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut next = form.first_ifd(b).unwrap_or(0);
    while next != 0 {
        let k = ifds.len();
        let at = usize::try_from(next).ok().filter(|a| *a < b.len()).ok_or_else(|| {
            header_error(
                path,
                &format!("image file directory {k}"),
                format!("offset {next} is outside the file ({} bytes)", b.len()),
            )
        })?;
        if !seen.insert(next) || ifds.len() >= MAX_PAGES {
            return Err(header_error(
                path,
                &format!("image file directory {k}"),
                "the chain of pages loops or never ends",
            ));
        }
        ifds.push(next);
        next = form.next_ifd(b, at).ok_or_else(|| {
            header_error(
                path,
                &format!("image file directory {k}"),
                "directory runs past the end of the file (truncated)",
            )
        })?;
    }
    if ifds.is_empty() {
        return Err(header_error(path, "TIFF header", "no pages"));
    }
    let pages = Pages { form, ifds };
    let first_err = |e: tiff::TiffError| header_error(path, "image file directory 0", e.to_string());
    let mut dec = pages.decoder(b, 0).map_err(first_err)?;
    let (w, h) = dec.dimensions().map_err(first_err)?;
    let colour = dec.colortype().map_err(first_err)?;
    let size = check_size(path, u64::from(w), u64::from(h), max_pixels)?;
    let bit_depth = match colour {
        ColorType::Gray(d) | ColorType::RGB(d) | ColorType::RGBA(d) => Some(d),
        _ => None,
    };
    let count = pages.ifds.len();
    let info = CameraInfo {
        format: SourceFormat::TiffStack,
        bit_depth,
        ..CameraInfo::default()
    };
    Ok(CameraFile {
        sources: vec![path.into()],
        path: path.into(),
        data_path: path.into(),
        layout: Layout::Tiff(pages),
        map,
        pool: Default::default(),
        info,
        size,
        count,
        warnings: Vec::new(),
    })
}
