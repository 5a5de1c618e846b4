//! Photron MRAW: a `.cihx` (XML behind a binary preamble) or `.cih` (text, `Key : Value` lines) header
//! beside a `.mraw` file of raw frames back to back.
//!
//! Layout as read by pyMRAW (ladisk/pyMRAW), the reader Photron users rely on, and checked here against a
//! real 12-bit recording decoded independently (`fixtures/real/photron/`): 8-bit frames are one byte a
//! pixel; 12-bit frames pack two pixels in three bytes, big-endian (`p0 = b0·16 + b1 >> 4`,
//! `p1 = (b1 & 15)·256 + b2`); 16-bit frames are little-endian words. Rows top to bottom.
//! Samples are put at 16-bit full scale: 12-bit values `<< 4`; 16-bit words whose effective depth `d < 16`
//! sits on the lower side `<< (16 − d)`.

use std::path::{Path, PathBuf};

use super::unpack::Packing;
use super::{BitSide, CameraFile, CameraInfo, Layout, SourceFormat, check_size, header_error, map};
use crate::error::{FramesError, Result};

/// Headers larger than this are not Photron headers (real ones are a few tens of KiB).
const MAX_HEADER_BYTES: u64 = 16 << 20;

/// What this reader needs from a header.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Header {
    pub width: Option<u64>,
    pub height: Option<u64>,
    pub frames: Option<u64>,
    pub fps: Option<f64>,
    pub exposure_s: Option<f64>,
    pub bits: Option<u64>,
    pub effective_depth: Option<u8>,
    pub side: Option<BitSide>,
    pub model: Option<String>,
    pub start_frame: Option<i64>,
    pub file_format: Option<String>,
    pub colour: Option<String>,
}

fn sibling(path: &Path, exts: &[&str]) -> Option<PathBuf> {
    for ext in exts {
        for e in [ext.to_string(), ext.to_ascii_uppercase()] {
            let p = path.with_extension(e);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// The header and data paths of a Photron clip given by either file.
pub(crate) fn pair(path: &Path) -> Result<(PathBuf, PathBuf)> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or_default()
        .to_ascii_lowercase();
    if ext == "mraw" {
        let header = sibling(path, &["cihx", "cih"]).ok_or_else(|| FramesError::MissingCompanion {
            path: path.into(),
            what: "its .cihx or .cih header",
            expected: path.with_extension("cihx"),
        })?;
        Ok((header, path.into()))
    } else {
        let data = sibling(path, &["mraw"]).ok_or_else(|| FramesError::MissingCompanion {
            path: path.into(),
            what: "the .mraw data file",
            expected: path.with_extension("mraw"),
        })?;
        Ok((path.into(), data))
    }
}

pub(crate) fn read_header(path: &Path) -> Result<Header> {
    let io = |source| FramesError::Io {
        path: path.into(),
        source,
    };
    let len = std::fs::metadata(path).map_err(io)?.len();
    if len > MAX_HEADER_BYTES {
        return Err(header_error(
            path,
            "header",
            format!("{len} bytes is too large for a Photron header"),
        ));
    }
    let bytes = std::fs::read(path).map_err(io)?;
    let is_xml = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("cihx"));
    if is_xml {
        parse_cihx(path, &bytes)
    } else {
        parse_cih(path, &bytes)
    }
}

fn parse_number<T: std::str::FromStr>(path: &Path, field: &str, text: &str) -> Result<T> {
    text.trim()
        .parse()
        .map_err(|_| header_error(path, field, format!("`{}` is not a number", text.trim())))
}

/// A shutter written `1/50000` or `0.00002` (seconds).
fn parse_shutter(path: &Path, field: &str, text: &str) -> Result<f64> {
    let t = text.trim();
    let s = match t.split_once('/') {
        Some((a, b)) => parse_number::<f64>(path, field, a)? / parse_number::<f64>(path, field, b)?,
        None => parse_number(path, field, t)?,
    };
    if s.is_finite() && s > 0.0 {
        Ok(s)
    } else {
        Err(header_error(path, field, format!("`{t}` is not a shutter time")))
    }
}

fn parse_side(path: &Path, field: &str, text: &str) -> Result<BitSide> {
    match text.trim().to_ascii_lowercase().as_str() {
        "lower" => Ok(BitSide::Lower),
        "higher" | "upper" => Ok(BitSide::Higher),
        other => Err(header_error(path, field, format!("`{other}` is not Lower or Higher"))),
    }
}

/// The text header: `Key : Value` lines (the first ` : `-free line or `END` ends nothing: unknown keys are
/// skipped, a repeated key keeps its first value).
pub(crate) fn parse_cih(path: &Path, bytes: &[u8]) -> Result<Header> {
    let text = String::from_utf8_lossy(bytes);
    let mut h = Header::default();
    let mut seen = std::collections::HashSet::new();
    for line in text.lines() {
        let Some((key, value)) = line.split_once(':') else {
            continue;
        };
        let (key, value) = (key.trim(), value.trim());
        if !seen.insert(key.to_string()) {
            continue;
        }
        match key {
            "Image Width" => h.width = Some(parse_number(path, key, value)?),
            "Image Height" => h.height = Some(parse_number(path, key, value)?),
            "Total Frame" => h.frames = Some(parse_number(path, key, value)?),
            "Record Rate(fps)" => h.fps = Some(parse_number(path, key, value)?),
            "Shutter Speed(s)" => h.exposure_s = Some(parse_shutter(path, key, value)?),
            "Color Bit" => h.bits = Some(parse_number(path, key, value)?),
            "EffectiveBit Depth" => h.effective_depth = Some(parse_number(path, key, value)?),
            "EffectiveBit Side" => h.side = Some(parse_side(path, key, value)?),
            "Camera Type" => h.model = Some(value.to_string()),
            "Start Frame" => h.start_frame = Some(parse_number(path, key, value)?),
            "File Format" => h.file_format = Some(value.to_string()),
            "Color Type" => h.colour = Some(value.to_string()),
            _ => {}
        }
    }
    Ok(h)
}

/// The XML header: the `<cih>` element behind a binary preamble.
pub(crate) fn parse_cihx(path: &Path, bytes: &[u8]) -> Result<Header> {
    let find = |needle: &[u8]| bytes.windows(needle.len()).position(|w| w == needle);
    let (Some(start), Some(end)) = (find(b"<cih>"), find(b"</cih>")) else {
        return Err(header_error(
            path,
            "<cih>",
            "no <cih> … </cih> XML element in the header",
        ));
    };
    if end < start {
        return Err(header_error(path, "<cih>", "</cih> comes before <cih>"));
    }
    let xml = String::from_utf8_lossy(&bytes[start..end + b"</cih>".len()]);
    let doc =
        roxmltree::Document::parse(&xml).map_err(|e| header_error(path, "<cih>", format!("malformed XML: {e}")))?;
    let get = |route: &[&str]| -> Option<String> {
        let mut node = doc.root_element();
        for name in route {
            node = node.children().find(|c| c.has_tag_name(*name))?;
        }
        node.text().map(|t| t.trim().to_string())
    };
    let field = |route: &[&str]| format!("<{}>", route.join("><"));
    let num = |route: &[&str]| -> Result<Option<f64>> {
        get(route).map(|t| parse_number(path, &field(route), &t)).transpose()
    };
    let int = |route: &[&str]| -> Result<Option<i64>> {
        get(route).map(|t| parse_number(path, &field(route), &t)).transpose()
    };
    let uint = |route: &[&str]| -> Result<Option<u64>> {
        get(route).map(|t| parse_number(path, &field(route), &t)).transpose()
    };
    let width = match uint(&["imageDataInfo", "resolution", "width"])? {
        Some(w) => Some(w),
        None => uint(&["imageFileInfo", "resolution", "width"])?,
    };
    let height = match uint(&["imageDataInfo", "resolution", "height"])? {
        Some(w) => Some(w),
        None => uint(&["imageFileInfo", "resolution", "height"])?,
    };
    let exposure_s = match num(&["recordInfo", "shutterSpeedNsec"])? {
        Some(ns) if ns > 0.0 => Some(ns * 1e-9),
        _ => match num(&["recordInfo", "shutterSpeed"])? {
            Some(per_s) if per_s > 0.0 => Some(1.0 / per_s),
            _ => None,
        },
    };
    Ok(Header {
        width,
        height,
        frames: uint(&["frameInfo", "totalFrame"])?,
        fps: num(&["recordInfo", "recordRate"])?,
        exposure_s,
        bits: uint(&["imageDataInfo", "colorInfo", "bit"])?,
        effective_depth: uint(&["imageDataInfo", "effectiveBit", "depth"])?.map(|d| u8::try_from(d).unwrap_or(u8::MAX)),
        side: get(&["imageDataInfo", "effectiveBit", "side"])
            .map(|s| parse_side(path, "<imageDataInfo><effectiveBit><side>", &s))
            .transpose()?,
        model: get(&["deviceInfo", "deviceName"]),
        start_frame: int(&["frameInfo", "startFrame"])?,
        file_format: get(&["imageFileInfo", "fileFormat"]),
        colour: get(&["imageDataInfo", "colorInfo", "type"]),
    })
}

/// A header's field names as the user's file spells them: XML paths in a `.cihx`, keys in a `.cih`.
struct FieldNames {
    xml: bool,
}

impl FieldNames {
    fn name(&self, xml_name: &str, text_name: &str) -> String {
        if self.xml {
            xml_name.to_string()
        } else {
            text_name.to_string()
        }
    }
}

/// The frame geometry a header must give: width and height (px), frame count and bits per pixel.
#[derive(Clone, Copy)]
struct FrameGeometry {
    width: u64,
    height: u64,
    frames: u64,
    bits: u64,
}

impl Header {
    /// Refuses headers of other file formats and of colour recordings.
    fn check_mono_mraw(&self, header_path: &Path, names: &FieldNames) -> Result<()> {
        if let Some(ff) = &self.file_format
            && !ff.eq_ignore_ascii_case("mraw")
        {
            return Err(header_error(
                header_path,
                &names.name("<imageFileInfo><fileFormat>", "File Format"),
                format!("`{ff}`: this header describes {ff} files, not a .mraw"),
            ));
        }
        if let Some(c) = &self.colour
            && (c.to_ascii_lowercase().contains("color") || c.to_ascii_lowercase().contains("colour"))
        {
            return Err(header_error(
                header_path,
                &names.name("<imageDataInfo><colorInfo><type>", "Color Type"),
                format!("`{c}`: colour MRAW (a Bayer mosaic) is not supported; record or save monochrome"),
            ));
        }
        Ok(())
    }

    /// Width, height, frame count and bits, each required.
    fn geometry(&self, header_path: &Path, names: &FieldNames) -> Result<FrameGeometry> {
        let missing = |f: String| header_error(header_path, &f, "missing from the header");
        Ok(FrameGeometry {
            width: self
                .width
                .ok_or_else(|| missing(names.name("<imageDataInfo><resolution><width>", "Image Width")))?,
            height: self
                .height
                .ok_or_else(|| missing(names.name("<imageDataInfo><resolution><height>", "Image Height")))?,
            frames: self
                .frames
                .ok_or_else(|| missing(names.name("<frameInfo><totalFrame>", "Total Frame")))?,
            bits: self
                .bits
                .ok_or_else(|| missing(names.name("<imageDataInfo><colorInfo><bit>", "Color Bit")))?,
        })
    }

    /// How the frames are packed: 8 bits, 12 bits packed, or 16-bit words shifted to full scale when the
    /// effective depth sits on the lower side.
    fn packing(&self, bits: u64, header_path: &Path, bits_field: &str) -> Result<Packing> {
        Ok(match bits {
            8 => Packing::U8,
            12 => Packing::P12,
            16 => Packing::U16Le(match (self.effective_depth, self.side) {
                (Some(d @ 1..=15), Some(BitSide::Lower) | None) => u32::from(16 - d),
                _ => 0,
            }),
            other => {
                return Err(header_error(
                    header_path,
                    bits_field,
                    format!("unknown bit depth {other} (this reader knows 8, 12 packed and 16)"),
                ));
            }
        })
    }
}

/// The `.mraw` must hold exactly the header's frames: a shorter file is truncated, a longer one disagrees.
fn check_data_size(data_path: &Path, g: &FrameGeometry, frame_bytes: u64, data_len: u64, field: String) -> Result<()> {
    let FrameGeometry {
        width,
        height,
        frames,
        bits,
    } = *g;
    let expected = frame_bytes.checked_mul(frames);
    if expected == Some(data_len) {
        return Ok(());
    }
    let problem = match expected {
        Some(e) if e > data_len => format!(
            "the header says {frames} frames of {width}×{height} px at {bits} bits = {e} bytes, but the .mraw has \
             {} bytes (truncated: {} whole frames)",
            data_len,
            data_len / frame_bytes
        ),
        Some(e) => format!(
            "the header says {frames} frames of {width}×{height} px at {bits} bits = {e} bytes, but the .mraw has \
             {} bytes (the header's size or frame count disagrees with the data)",
            data_len
        ),
        None => format!("{frames} frames of {frame_bytes} bytes overflow"),
    };
    Err(FramesError::CameraHeader {
        path: data_path.into(),
        field,
        problem,
    })
}

/// Opens a Photron clip from its header or its `.mraw`.
pub(crate) fn open(path: &Path, max_pixels: u64) -> Result<CameraFile> {
    let (header_path, data_path) = pair(path)?;
    let h = read_header(&header_path)?;
    let names = FieldNames {
        xml: header_path.extension().is_some_and(|e| e.eq_ignore_ascii_case("cihx")),
    };
    h.check_mono_mraw(&header_path, &names)?;
    let g = h.geometry(&header_path, &names)?;
    let bits_field = names.name("<imageDataInfo><colorInfo><bit>", "Color Bit");
    let size = check_size(&header_path, g.width, g.height, max_pixels)?;
    let packing = h.packing(g.bits, &header_path, &bits_field)?;
    let frames_field = names.name("<frameInfo><totalFrame>", "Total Frame");
    if g.frames == 0 {
        return Err(header_error(&header_path, &frames_field, "0 frames"));
    }
    let frame_bytes = packing.frame_bytes(g.width * g.height).ok_or_else(|| {
        header_error(
            &header_path,
            &bits_field,
            format!(
                "{}×{} px cannot be stored whole at {} bits packed",
                g.width, g.height, g.bits
            ),
        )
    })?;
    let map = map(&data_path)?;
    check_data_size(&data_path, &g, frame_bytes, map.len() as u64, frames_field)?;
    let count = usize::try_from(g.frames).map_err(|_| header_error(&header_path, "Total Frame", "too many frames"))?;
    let info = CameraInfo {
        format: SourceFormat::PhotronMraw,
        fps: h.fps.filter(|f| f.is_finite() && *f > 0.0),
        exposure_s: h.exposure_s,
        bit_depth: Some(packing.bits()),
        effective_bit_depth: h.effective_depth,
        effective_bit_side: h.side,
        camera_model: h.model.filter(|m| !m.is_empty()),
        camera_serial: None,
        start_frame: h.start_frame,
        trigger_frame: h.start_frame.map(|s| -s),
    };
    Ok(CameraFile {
        sources: vec![header_path.clone(), data_path.clone()],
        path: path.into(),
        data_path,
        map,
        pool: Default::default(),
        layout: Layout::Contiguous {
            packing,
            frame_bytes: frame_bytes as usize,
        },
        info,
        size,
        count,
        warnings: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_header_keys_and_fractions() {
        let text = "#Camera Information Header\nRecord Rate(fps) : 60000\nShutter Speed(s) : 1/800000\n\
                    Total Frame : 12\nStart Frame : 49300\nImage Width : 896\nImage Height : 368\nColor Type : Mono\n\
                    Color Bit : 16\nFile Format : MRaw\nEffectiveBit Depth : 12\nEffectiveBit Side : Lower\n\
                    Camera Type : FASTCAM SA-Z\nPartition Number: 1\n";
        let h = parse_cih(Path::new("a.cih"), text.as_bytes()).unwrap();
        assert_eq!(
            (h.width, h.height, h.frames, h.bits),
            (Some(896), Some(368), Some(12), Some(16))
        );
        assert_eq!((h.fps, h.start_frame), (Some(60_000.0), Some(49_300)));
        assert!((h.exposure_s.unwrap() - 1.25e-6).abs() < 1e-18);
        assert_eq!((h.effective_depth, h.side), (Some(12), Some(BitSide::Lower)));
        assert_eq!(h.model.as_deref(), Some("FASTCAM SA-Z"));
    }

    #[test]
    fn bad_numbers_name_the_key() {
        let err = parse_cih(Path::new("a.cih"), b"Image Width : wide\n").unwrap_err();
        assert!(
            err.to_string().contains("Image Width") && err.to_string().contains("a.cih"),
            "{err}"
        );
        let err = parse_cihx(Path::new("b.cihx"), b"junk").unwrap_err();
        assert!(err.to_string().contains("<cih>"), "{err}");
    }
}
