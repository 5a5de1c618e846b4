//! Test helper: small synthetic frames, clips and sessions written in a line.
//!
//! Everything here is deterministic (a seeded SplitMix64 noise source, no `rand`).
//!
//! # Panics
//! The writers panic when a file cannot be written: they are for tests and benches only.

use std::path::{Path, PathBuf};

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ColorType, DynamicImage, ImageBuffer};

/// The workspace's one seeded generator (SplitMix64), by the name these helpers use for it.
pub type Noise = bouncelab_testkit::Rng;

/// A `w`×`h` diagonal gradient with ±25 % full-scale noise, in colour type `colour` (L8, L16, La8, La16,
/// Rgb8, Rgb16, Rgba8, Rgba16). Channels get different noise, so colour frames are really colour.
pub fn noisy_gradient(w: u32, h: u32, seed: u64, colour: ColorType) -> DynamicImage {
    noisy_gradient_with(w, h, seed, colour, 0.5)
}

/// As [`noisy_gradient`] with uniform noise of `noise` full scale peak to peak (0.5 = ±25 %; a camera's
/// sensor noise is more like 0.03).
pub fn noisy_gradient_with(w: u32, h: u32, seed: u64, colour: ColorType, noise: f64) -> DynamicImage {
    let mut rng = Noise::new(seed);
    let channels = usize::from(colour.channel_count());
    let n = (w as usize) * (h as usize) * channels;
    let mut samples = Vec::with_capacity(n);
    for y in 0..h {
        for x in 0..w {
            let base = f64::from(x + y) / f64::from((w + h).max(2) - 2).max(1.0);
            for _ in 0..channels {
                let r = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
                samples.push((0.25 + 0.5 * base + noise * (r - 0.5)).clamp(0.0, 1.0));
            }
        }
    }
    let u8s = || samples.iter().map(|v| (v * 255.0).round() as u8).collect::<Vec<_>>();
    let u16s = || samples.iter().map(|v| (v * 65535.0).round() as u16).collect::<Vec<_>>();
    let buf = |ok: Option<DynamicImage>| ok.expect("buffer size matches");
    match colour {
        ColorType::L8 => buf(ImageBuffer::from_raw(w, h, u8s()).map(DynamicImage::ImageLuma8)),
        ColorType::La8 => buf(ImageBuffer::from_raw(w, h, u8s()).map(DynamicImage::ImageLumaA8)),
        ColorType::Rgb8 => buf(ImageBuffer::from_raw(w, h, u8s()).map(DynamicImage::ImageRgb8)),
        ColorType::Rgba8 => buf(ImageBuffer::from_raw(w, h, u8s()).map(DynamicImage::ImageRgba8)),
        ColorType::L16 => buf(ImageBuffer::from_raw(w, h, u16s()).map(DynamicImage::ImageLuma16)),
        ColorType::La16 => buf(ImageBuffer::from_raw(w, h, u16s()).map(DynamicImage::ImageLumaA16)),
        ColorType::Rgb16 => buf(ImageBuffer::from_raw(w, h, u16s()).map(DynamicImage::ImageRgb16)),
        ColorType::Rgba16 => buf(ImageBuffer::from_raw(w, h, u16s()).map(DynamicImage::ImageRgba16)),
        other => panic!("noisy_gradient: unsupported colour type {other:?}"),
    }
}

/// The image encoded as PNG by the `image` crate.
pub fn encode_png(img: &DynamicImage) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).expect("PNG encodes");
    out.into_inner()
}

/// Writes `img` to `path` as PNG with this zlib compression (the `image` crate's own default is
/// [`CompressionType::Fast`], which stores pure noise almost uncompressed; cameras use zlib-like levels).
pub fn write_png_with(path: &Path, img: &DynamicImage, compression: CompressionType) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).expect("create frame file"));
    let enc = PngEncoder::new_with_quality(file, compression, FilterType::Adaptive);
    img.write_with_encoder(enc).expect("PNG encodes");
}

/// Writes `img` to `path` in the format of the extension (`.pgm/.ppm/.pnm` as binary netpbm).
pub fn write_frame(path: &Path, img: &DynamicImage) {
    use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or_default()
        .to_ascii_lowercase();
    if let (true, DynamicImage::ImageLuma16(g)) = (matches!(ext.as_str(), "pgm" | "pnm"), img) {
        // image's PNM encoder does not write 16-bit: write binary P5 with maxval 65535 (big-endian) by hand.
        let mut bytes = format!("P5\n{} {}\n65535\n", g.width(), g.height()).into_bytes();
        bytes.extend(g.as_raw().iter().flat_map(|v| v.to_be_bytes()));
        std::fs::write(path, bytes).expect("write PGM");
    } else if matches!(ext.as_str(), "pgm" | "ppm" | "pnm") {
        let file = std::io::BufWriter::new(std::fs::File::create(path).expect("create frame file"));
        let subtype = if img.color().has_color() {
            PnmSubtype::Pixmap(SampleEncoding::Binary)
        } else {
            PnmSubtype::Graymap(SampleEncoding::Binary)
        };
        let enc = PnmEncoder::new(file).with_subtype(subtype);
        img.write_with_encoder(enc).expect("PNM encodes");
    } else {
        img.save(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

/// A synthetic clip to write: noisy gradients named `{prefix}{number:0pad$}.{ext}`.
#[derive(Clone, Debug)]
pub struct ClipSpec {
    /// Frame width, in pixels.
    pub width: u32,
    /// Frame height, in pixels.
    pub height: u32,
    /// Frame numbers to write (files are written in this order).
    pub numbers: Vec<u64>,
    /// File name prefix.
    pub prefix: String,
    /// Zero padding of the number (digits).
    pub pad: usize,
    /// Extension (format): png, tif, bmp, pgm, jpg …
    pub ext: String,
    /// Colour type of the written images.
    pub colour: ColorType,
    /// Noise seed; frame `n` uses `seed + n`.
    pub seed: u64,
    /// If set, a `clip.toml` with `[camera] fps` = this is written too.
    pub clip_fps: Option<f64>,
    /// Noise, as a fraction of full scale peak to peak (default 0.5).
    pub noise: f64,
    /// PNG compression; `None` is the `image` crate's default.
    pub png_compression: Option<CompressionType>,
}

impl ClipSpec {
    /// `count` 8-bit gray 32×24 PNG frames numbered 1..=count as `img_0001.png` …
    pub fn new(count: u64) -> Self {
        Self {
            width: 32,
            height: 24,
            numbers: (1..=count).collect(),
            prefix: "img_".into(),
            pad: 4,
            ext: "png".into(),
            colour: ColorType::L8,
            seed: 1,
            clip_fps: None,
            noise: 0.5,
            png_compression: None,
        }
    }

    /// The same clip in another format (extension).
    pub fn ext(mut self, ext: &str) -> Self {
        self.ext = ext.into();
        self
    }

    /// The same clip in another colour type.
    pub fn colour(mut self, colour: ColorType) -> Self {
        self.colour = colour;
        self
    }

    /// The same clip with these frame numbers.
    pub fn numbers(mut self, numbers: impl IntoIterator<Item = u64>) -> Self {
        self.numbers = numbers.into_iter().collect();
        self
    }

    /// The same clip with a `clip.toml` giving this fps.
    pub fn fps(mut self, fps: f64) -> Self {
        self.clip_fps = Some(fps);
        self
    }

    /// The file name of frame `number`.
    pub fn name(&self, number: u64) -> String {
        format!("{}{:0pad$}.{}", self.prefix, number, self.ext, pad = self.pad)
    }

    /// The image of frame `number`.
    pub fn image(&self, number: u64) -> DynamicImage {
        noisy_gradient_with(
            self.width,
            self.height,
            self.seed.wrapping_add(number),
            self.colour,
            self.noise,
        )
    }

    /// Creates `dir` and writes the frames (and `clip.toml`); returns the frame paths in write order.
    pub fn write(&self, dir: &Path) -> Vec<PathBuf> {
        std::fs::create_dir_all(dir).expect("create clip dir");
        if let Some(fps) = self.clip_fps {
            std::fs::write(dir.join("clip.toml"), format!("[camera]\nfps = {fps:?}\n")).expect("write clip.toml");
        }
        self.numbers
            .iter()
            .map(|&n| {
                let path = dir.join(self.name(n));
                match self.png_compression {
                    Some(c) if self.ext.eq_ignore_ascii_case("png") => write_png_with(&path, &self.image(n), c),
                    _ => write_frame(&path, &self.image(n)),
                }
                path
            })
            .collect()
    }
}

/// Writes a session folder: `session.toml` and `clips.csv` as given, and a 2-frame clip folder for each
/// name in `clips`.
pub fn write_session(dir: &Path, session_toml: &str, clips_csv: &str, clips: &[&str]) {
    std::fs::create_dir_all(dir).expect("create session dir");
    std::fs::write(dir.join("session.toml"), session_toml).expect("write session.toml");
    std::fs::write(dir.join("clips.csv"), clips_csv).expect("write clips.csv");
    for name in clips {
        ClipSpec::new(2).write(&dir.join(name));
    }
}

/// A minimal valid `session.toml`.
pub const SESSION_TOML: &str = "[ball]\ndiameter_m = 0.067\nmass_kg = 0.0567\n[camera]\nfps = 10000\n";

// --- Hand-made PNGs for the decoder's fallback path -------------------------------------------------------

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

/// zlib stream of one stored (uncompressed) deflate block.
fn zlib_stored(raw: &[u8]) -> Vec<u8> {
    let mut z = vec![0x78, 0x01, 0x01];
    let len = raw.len() as u16;
    z.extend_from_slice(&len.to_le_bytes());
    z.extend_from_slice(&(!len).to_le_bytes());
    z.extend_from_slice(raw);
    let (mut a, mut b) = (1u32, 0u32);
    for &x in raw {
        a = (a + u32::from(x)) % 65521;
        b = (b + a) % 65521;
    }
    z.extend_from_slice(&((b << 16) | a).to_be_bytes());
    z
}

fn png(w: u32, h: u32, depth: u8, colour: u8, interlace: u8, plte: Option<&[u8]>, raw: &[u8]) -> Vec<u8> {
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&w.to_be_bytes());
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[depth, colour, 0, 0, interlace]);
    chunk(&mut out, b"IHDR", &ihdr);
    if let Some(p) = plte {
        chunk(&mut out, b"PLTE", p);
    }
    chunk(&mut out, b"IDAT", &zlib_stored(raw));
    chunk(&mut out, b"IEND", &[]);
    out
}

/// A PNG whose header claims `w`×`h` 8-bit gray pixels but whose data is a few bytes: a decompression bomb
/// header (a decoder that trusts it allocates w·h bytes before it finds the data short).
pub fn bomb_png(w: u32, h: u32) -> Vec<u8> {
    png(w, h, 8, 0, 0, None, &[0, 0, 0, 0])
}

/// A 2×1 palette PNG whose pixels are gray 10 and gray 200.
pub fn palette_png() -> Vec<u8> {
    png(2, 1, 8, 3, 0, Some(&[10, 10, 10, 200, 200, 200]), &[0, 0, 1])
}

/// A 1×1 Adam7-interlaced 8-bit gray PNG whose pixel is 77.
pub fn interlaced_png() -> Vec<u8> {
    png(1, 1, 8, 0, 1, None, &[0, 77])
}
