//! Writers of camera files for tests, benches and examples (dev-only: included with `#[path]`, never part of
//! the library): Photron `.mraw` with a `.cihx` or `.cih` header, Phantom `.cine`, multi-page TIFF.
//!
//! They follow the layouts the readers document (`src/camera/photron.rs`, `src/camera/cine.rs`) and take
//! frames as raw samples at the file's own depth (0–255, 0–1023, 0–4095 or 0–65535), row-major, top row
//! first.
//!
//! # Panics
//! On any I/O error or a frame of the wrong length: they are for tests.

#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};

/// Which Photron header to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhotronHeader {
    /// XML behind a binary preamble.
    Cihx,
    /// `Key : Value` text.
    Cih,
}

/// A Photron recording to write.
#[derive(Clone, Debug)]
pub struct Mraw {
    pub width: u32,
    pub height: u32,
    /// 8, 12 (packed) or 16.
    pub bits: u32,
    /// `EffectiveBit Depth` (for 16-bit words).
    pub effective: u32,
    pub fps: f64,
    pub shutter_per_s: u32,
    pub start_frame: i64,
    pub header: PhotronHeader,
    pub model: String,
}

impl Mraw {
    pub fn new(width: u32, height: u32, bits: u32) -> Self {
        Self {
            width,
            height,
            bits,
            effective: bits.min(12),
            fps: 30_000.0,
            shutter_per_s: 50_000,
            start_frame: 52,
            header: PhotronHeader::Cihx,
            model: "FASTCAM test".into(),
        }
    }

    /// The header text for `frames` frames (`bits` is written as given, valid or not).
    pub fn header_text(&self, frames: usize) -> Vec<u8> {
        match self.header {
            PhotronHeader::Cih => format!(
                "#Camera Information Header\nCamera Type : {}\nRecord Rate(fps) : {}\nShutter Speed(s) : 1/{}\n\
                 Total Frame : {frames}\nStart Frame : {}\nImage Width : {}\nImage Height : {}\nColor Type : Mono\n\
                 Color Bit : {}\nFile Format : MRaw\nEffectiveBit Depth : {}\nEffectiveBit Side : Lower\n\nEND\n",
                self.model,
                self.fps,
                self.shutter_per_s,
                self.start_frame,
                self.width,
                self.height,
                self.bits,
                self.effective
            )
            .into_bytes(),
            PhotronHeader::Cihx => {
                let mut out = b"!!! This file can not be edited. !!!".to_vec();
                out.extend(std::iter::repeat_n(0x20u8, 92));
                out.extend([0x00, 0x01, 0xfe, 0xff, 0x00, 0x30]); // binary preamble bytes
                out.extend(
                    format!(
                        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<cih>\n<fileInfo><version>1.0</version></fileInfo>\n\
                         <imageFileInfo><fileFormat>Mraw</fileFormat><resolution><width>{w}</width><height>{h}</height></resolution></imageFileInfo>\n\
                         <imageDataInfo><resolution><width>{w}</width><height>{h}</height></resolution>\n\
                         <colorInfo><type>Raw</type><bit>{}</bit></colorInfo>\n\
                         <effectiveBit><depth>{}</depth><side>Lower</side></effectiveBit></imageDataInfo>\n\
                         <frameInfo><recordedFrame>2000</recordedFrame><totalFrame>{frames}</totalFrame><startFrame>{}</startFrame></frameInfo>\n\
                         <recordInfo><recordRate>{}</recordRate><shutterSpeed>{}</shutterSpeed></recordInfo>\n\
                         <deviceInfo><deviceName>{}</deviceName></deviceInfo>\n</cih>\n",
                        self.bits,
                        self.effective,
                        self.start_frame,
                        self.fps,
                        self.shutter_per_s,
                        self.model,
                        w = self.width,
                        h = self.height
                    )
                    .into_bytes(),
                );
                out
            }
        }
    }

    /// Writes `dir/stem.cihx|cih` and `dir/stem.mraw`; returns the header's path.
    pub fn write(&self, dir: &Path, stem: &str, frames: &[Vec<u16>]) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let ext = match self.header {
            PhotronHeader::Cihx => "cihx",
            PhotronHeader::Cih => "cih",
        };
        let header = dir.join(format!("{stem}.{ext}"));
        std::fs::write(&header, self.header_text(frames.len())).unwrap();
        let mut data = std::io::BufWriter::new(std::fs::File::create(dir.join(format!("{stem}.mraw"))).unwrap());
        for f in frames {
            assert_eq!(f.len(), (self.width * self.height) as usize);
            data.write_all(&pack(f, self.bits, false)).unwrap();
        }
        data.flush().unwrap();
        header
    }
}

/// Samples packed at `bits` (8; 10 or 12 big-endian packed; 16 little-endian), rows as given or reversed.
pub fn pack(samples: &[u16], bits: u32, _unused: bool) -> Vec<u8> {
    match bits {
        8 => samples.iter().map(|&v| v as u8).collect(),
        16 => samples.iter().flat_map(|v| v.to_le_bytes()).collect(),
        12 => samples
            .chunks_exact(2)
            .flat_map(|p| [(p[0] >> 4) as u8, (((p[0] & 0xF) << 4) | (p[1] >> 8)) as u8, p[1] as u8])
            .collect(),
        10 => samples
            .chunks_exact(4)
            .flat_map(|p| {
                let v = (u64::from(p[0]) << 30) | (u64::from(p[1]) << 20) | (u64::from(p[2]) << 10) | u64::from(p[3]);
                [
                    (v >> 32) as u8,
                    (v >> 24) as u8,
                    (v >> 16) as u8,
                    (v >> 8) as u8,
                    v as u8,
                ]
            })
            .collect(),
        other => panic!("pack: {other} bits"),
    }
}

/// How a CINE file's images are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CinePacking {
    /// 8-bit, bottom-up.
    U8,
    /// 16-bit little-endian, bottom-up, `RealBPP` bits used.
    U16 { real_bpp: u32 },
    /// 10-bit packed ("P10", biCompression 256), top-down.
    P10,
    /// 12-bit packed ("P12L", biCompression 1024), top-down.
    P12,
}

/// A Phantom recording to write.
#[derive(Clone, Debug)]
pub struct Cine {
    pub width: u32,
    pub height: u32,
    pub packing: CinePacking,
    pub fps: u32,
    pub shutter_ns: u32,
    pub first_image_no: i32,
    pub camera_version: u32,
    pub serial: u32,
    /// Bytes of annotation before each image (≥ 8: its size and the image size).
    pub annotation: u32,
}

/// Where the parts of a written CINE file are (for tests that corrupt them).
#[derive(Clone, Debug)]
pub struct CineLayout {
    pub off_bitmap: usize,
    pub off_setup: usize,
    pub off_offsets: usize,
    pub images: Vec<usize>,
}

const SETUP_LEN: usize = 5996;

impl Cine {
    pub fn new(width: u32, height: u32, packing: CinePacking) -> Self {
        Self {
            width,
            height,
            packing,
            fps: 25_000,
            shutter_ns: 38_000,
            first_image_no: -120,
            camera_version: 2512,
            serial: 31_337,
            annotation: 8,
        }
    }

    /// Writes the file; returns where its parts are.
    pub fn write(&self, path: &Path, frames: &[Vec<u16>]) -> CineLayout {
        let (w, h) = (self.width as usize, self.height as usize);
        let (bit_count, compression, bits) = match self.packing {
            CinePacking::U8 => (8u16, 0u32, 8),
            CinePacking::U16 { .. } => (16, 0, 16),
            CinePacking::P10 => (16, 256, 10),
            CinePacking::P12 => (16, 1024, 12),
        };
        let image_bytes = w * h * bits / 8;
        let (off_bitmap, off_setup) = (44usize, 84usize);
        let off_offsets = off_setup + SETUP_LEN;
        let first_image = off_offsets + 8 * frames.len();
        let images: Vec<usize> = (0..frames.len())
            .map(|k| first_image + k * (self.annotation as usize + image_bytes))
            .collect();
        let mut out = Vec::with_capacity(first_image + frames.len() * (image_bytes + 8));
        out.extend(b"CI");
        out.extend(44u16.to_le_bytes());
        out.extend(0u16.to_le_bytes()); // Compression: gray/colour bitmap
        out.extend(1u16.to_le_bytes()); // Version
        out.extend(self.first_image_no.to_le_bytes()); // FirstMovieImage
        out.extend((frames.len() as u32).to_le_bytes()); // TotalImageCount
        out.extend(self.first_image_no.to_le_bytes()); // FirstImageNo
        out.extend((frames.len() as u32).to_le_bytes()); // ImageCount
        out.extend((off_bitmap as u32).to_le_bytes());
        out.extend((off_setup as u32).to_le_bytes());
        out.extend((off_offsets as u32).to_le_bytes());
        out.extend(0u64.to_le_bytes()); // TriggerTime
        assert_eq!(out.len(), 44);
        out.extend(40u32.to_le_bytes());
        out.extend((self.width as i32).to_le_bytes());
        out.extend((self.height as i32).to_le_bytes());
        out.extend(1u16.to_le_bytes());
        out.extend(bit_count.to_le_bytes());
        out.extend(compression.to_le_bytes());
        out.extend((image_bytes as u32).to_le_bytes());
        out.extend([0u8; 16]);
        assert_eq!(out.len(), off_setup);
        let mut setup = vec![0u8; SETUP_LEN];
        let put = |s: &mut Vec<u8>, at: usize, b: &[u8]| s[at..at + b.len()].copy_from_slice(b);
        put(&mut setup, 0, &(self.fps.min(65_535) as u16).to_le_bytes());
        put(&mut setup, 142, &(SETUP_LEN as u16).to_le_bytes());
        put(&mut setup, 743, &self.serial.to_le_bytes());
        put(&mut setup, 768, &self.fps.to_le_bytes());
        put(&mut setup, 772, &(self.shutter_ns / 1000).to_le_bytes());
        put(&mut setup, 792, &self.camera_version.to_le_bytes());
        let real_bpp = match self.packing {
            CinePacking::U8 => 8,
            CinePacking::U16 { real_bpp } => real_bpp,
            CinePacking::P10 => 10,
            CinePacking::P12 => 12,
        };
        put(&mut setup, 896, &real_bpp.to_le_bytes());
        put(&mut setup, 1568, &self.shutter_ns.to_le_bytes());
        out.extend(setup);
        for &at in &images {
            out.extend((at as u64).to_le_bytes());
        }
        for f in frames {
            assert_eq!(f.len(), w * h);
            out.extend(self.annotation.to_le_bytes());
            out.extend(std::iter::repeat_n(0xA5u8, self.annotation as usize - 8));
            out.extend((image_bytes as u32).to_le_bytes());
            let rows: Vec<u16> = match self.packing {
                // Plain bitmaps are stored bottom-up.
                CinePacking::U8 | CinePacking::U16 { .. } => f.chunks_exact(w).rev().flatten().copied().collect(),
                _ => f.clone(),
            };
            out.extend(pack(&rows, bits as u32, false));
        }
        std::fs::write(path, out).unwrap();
        CineLayout {
            off_bitmap,
            off_setup,
            off_offsets,
            images,
        }
    }
}

/// TIFF compression for [`write_tiff_stack`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TiffCompression {
    None,
    Lzw,
    Deflate,
    PackBits,
}

/// Writes a multi-page gray TIFF (8- or 16-bit samples) with the `tiff` crate's encoder.
pub fn write_tiff_stack(path: &Path, width: u32, height: u32, bits: u32, frames: &[Vec<u16>], c: TiffCompression) {
    use tiff::encoder::{Compression, DeflateLevel, TiffEncoder, colortype};
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let compression = match c {
        TiffCompression::None => Compression::Uncompressed,
        TiffCompression::Lzw => Compression::Lzw,
        TiffCompression::Deflate => Compression::Deflate(DeflateLevel::Balanced),
        TiffCompression::PackBits => Compression::Packbits,
    };
    let mut enc = TiffEncoder::new(file).unwrap().with_compression(compression);
    for f in frames {
        if bits == 8 {
            let d: Vec<u8> = f.iter().map(|&v| v as u8).collect();
            enc.write_image::<colortype::Gray8>(width, height, &d).unwrap();
        } else {
            enc.write_image::<colortype::Gray16>(width, height, f).unwrap();
        }
    }
}

/// Deterministic frames: a bright disc moving across a gradient, plus noise, at `max` full scale.
pub fn moving_disc(width: u32, height: u32, count: usize, max: u16, seed: u64) -> Vec<Vec<u16>> {
    let mut s = seed;
    let mut next = move || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 33) as u32
    };
    (0..count)
        .map(|k| {
            let (cx, cy, r) = (
                f64::from(width) * (0.2 + 0.6 * k as f64 / count.max(1) as f64),
                f64::from(height) * 0.4,
                f64::from(width.min(height)) * 0.15,
            );
            (0..height)
                .flat_map(|y| (0..width).map(move |x| (x, y)))
                .map(|(x, y)| {
                    let d = ((f64::from(x) - cx).powi(2) + (f64::from(y) - cy).powi(2)).sqrt();
                    let base = if d < r {
                        0.85
                    } else {
                        0.2 + 0.3 * f64::from(y) / f64::from(height)
                    };
                    let noise = f64::from(next() % 1000) / 1000.0 * 0.05;
                    ((base + noise).min(1.0) * f64::from(max)).round() as u16
                })
                .collect()
        })
        .collect()
}

/// The camera files the speed figures are taken on (`benches/camera.rs`, `examples/camera_cpu.rs`): `count`
/// frames of `side`×`side` each ([`moving_disc`]) as MRAW 8/12/16-bit, CINE 8-bit, P10, P12 and 16-bit, and
/// uncompressed 8- and 16-bit TIFF stacks, plus an LZW one if `lzw`; with their labels.
pub fn speed_files(dir: &Path, side: u32, count: usize, lzw: bool) -> Vec<(String, PathBuf)> {
    let frames = |max| moving_disc(side, side, count, max, 7);
    let mut files = Vec::new();
    for bits in [8u32, 12, 16] {
        let max = if bits == 8 { 255 } else { 4095 };
        let header = Mraw::new(side, side, bits).write(dir, &format!("m{bits}"), &frames(max));
        files.push((format!("mraw_{bits}bit"), header));
    }
    for (label, packing, max) in [
        ("cine_8bit", CinePacking::U8, 255),
        ("cine_10bit_packed", CinePacking::P10, 1023),
        ("cine_12bit_packed", CinePacking::P12, 4095),
        ("cine_16bit", CinePacking::U16 { real_bpp: 12 }, 4095),
    ] {
        let path = dir.join(format!("{label}.cine"));
        Cine::new(side, side, packing).write(&path, &frames(max));
        files.push((label.to_string(), path));
    }
    let mut tiffs = vec![
        ("tiff_8bit", 8, TiffCompression::None),
        ("tiff_16bit", 16, TiffCompression::None),
    ];
    if lzw {
        tiffs.push(("tiff_8bit_lzw", 8, TiffCompression::Lzw));
    }
    for (label, bits, compression) in tiffs {
        let path = dir.join(format!("{label}.tif"));
        let max = if bits == 8 { 255 } else { 65535 };
        write_tiff_stack(&path, side, side, bits, &frames(max), compression);
        files.push((label.to_string(), path));
    }
    files
}
