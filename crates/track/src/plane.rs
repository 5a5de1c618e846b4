//! A borrowed grayscale image of 8- or 16-bit pixels.

/// A pixel type the tracker reads. Values are scaled to 0–255 whatever the bit depth, so thresholds and
/// contrasts mean the same for 8- and 16-bit clips (a plane's [`Plane::gain`] then stretches a clip that
/// uses little of that range).
pub trait Pixel: Copy + Send + Sync + 'static {
    /// The value on a 0–255 scale.
    fn level(self) -> f32;
}

impl Pixel for u8 {
    #[inline(always)]
    fn level(self) -> f32 {
        self as f32
    }
}

impl Pixel for u16 {
    #[inline(always)]
    fn level(self) -> f32 {
        self as f32 * (1.0 / 257.0)
    }
}

impl Pixel for f32 {
    #[inline(always)]
    fn level(self) -> f32 {
        self
    }
}

/// A borrowed row-major grayscale image: `data[y * width + x]`, pixel centres at integer coordinates.
#[derive(Debug, Clone, Copy)]
pub struct Plane<'a, P> {
    /// Pixels, row after row.
    pub data: &'a [P],
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// Factor every level is multiplied by (1 unless set with [`Plane::with_gain`]).
    pub gain: f32,
}

impl<'a, P: Pixel> Plane<'a, P> {
    /// Wraps `data`.
    ///
    /// # Panics
    /// If `data.len() != width * height`.
    pub fn new(data: &'a [P], width: usize, height: usize) -> Self {
        assert_eq!(data.len(), width * height, "plane size");
        Plane {
            data,
            width,
            height,
            gain: 1.0,
        }
    }

    /// The same pixels with every level multiplied by `gain` (see `level_gain` in this module).
    pub fn with_gain(self, gain: f32) -> Self {
        Plane { gain, ..self }
    }

    /// The pixel at integer coordinates (no bounds check beyond the slice's).
    #[inline(always)]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x].level() * self.gain
    }

    /// Bilinear interpolation at (x, y); `None` outside the image (the last row/column excluded).
    #[inline(always)]
    pub fn sample(&self, x: f32, y: f32) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0) {
            return None;
        }
        let (x0, y0) = (x as usize, y as usize);
        if x0 + 1 >= self.width || y0 + 1 >= self.height {
            return None;
        }
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let i = y0 * self.width + x0;
        let d = self.data;
        let top = d[i].level() + fx * (d[i + 1].level() - d[i].level());
        let bottom = d[i + self.width].level() + fx * (d[i + self.width + 1].level() - d[i + self.width].level());
        Some((top + fy * (bottom - top)) * self.gain)
    }

    /// Bilinear interpolation at (x, y) known to lie in [0, width − 1) × [0, height − 1).
    #[inline(always)]
    pub fn sample_inside(&self, x: f32, y: f32) -> f32 {
        let (x0, y0) = (x as usize, y as usize);
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let i = y0 * self.width + x0;
        let d = &self.data[i..i + self.width + 2];
        let (a, b) = (d[0].level(), d[1].level());
        let (c, e) = (d[self.width].level(), d[self.width + 1].level());
        let top = a + fx * (b - a);
        let bottom = c + fx * (e - c);
        (top + fy * (bottom - top)) * self.gain
    }
}

impl<'a, P: Pixel> Plane<'a, P> {
    /// The image seen through a 3 × 3 binomial filter ([1 2 1] ⊗ [1 2 1] / 16 on the pixel grid) at (x, y):
    /// the mean of the four bilinear samples half a pixel away diagonally, which lowers white noise to 0.375
    /// of its σ and widens an edge by about a pixel. (x, y) must lie at least half a pixel inside the image.
    #[inline(always)]
    pub fn sample_smooth_inside(&self, x: f32, y: f32) -> f32 {
        0.25 * (self.sample_inside(x - 0.5, y - 0.5)
            + self.sample_inside(x + 0.5, y - 0.5)
            + self.sample_inside(x - 0.5, y + 0.5)
            + self.sample_inside(x + 0.5, y + 0.5))
    }
}

/// Levels below this spread (0–255 scale, between the 0.5th and 99.5th percentiles of a frame) are stretched
/// to it: the tracker's contrast thresholds are meant for a frame that uses at least half its scale, and a
/// 12-bit camera's values stored unshifted in 16-bit files use 1/16 of it.
pub const MIN_LEVEL_SPREAD: f32 = 128.0;

/// The gain that stretches `img`'s levels to at least [`MIN_LEVEL_SPREAD`] (1 for a frame that already
/// spans that much; at most 4096). Measured on every 7th pixel. Bit depth alone never changes it: an 8-bit
/// frame and its 12-in-16-bit copy get the same gain.
pub fn level_gain<P: Pixel>(img: &Plane<P>) -> f32 {
    let mut levels: Vec<f32> = img.data.iter().step_by(7).map(|p| p.level()).collect();
    if levels.len() < 16 {
        return 1.0;
    }
    let n = levels.len();
    let lo = *levels.select_nth_unstable_by(n / 200, f32::total_cmp).1;
    let hi = *levels.select_nth_unstable_by(n - 1 - n / 200, f32::total_cmp).1;
    let spread = hi - lo;
    if spread >= MIN_LEVEL_SPREAD {
        1.0
    } else {
        (MIN_LEVEL_SPREAD / spread.max(MIN_LEVEL_SPREAD / 4096.0)).min(4096.0)
    }
}

/// The median of `v` (the upper of the two middle values for an even count; 0 when empty), reordering `v`.
/// Cost: O(n).
pub(crate) fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Where a sampled peak lies between its samples: the vertex of the parabola through the values `a0`,
/// `a1`, `a2` at offsets −1, 0, +1, as an offset from the middle one (clamped to ±0.5; 0 when the three do
/// not bend down). The sub-sample step of every edge and vote peak in this crate.
pub(crate) fn parabola_offset(a0: f64, a1: f64, a2: f64) -> f64 {
    let den = a0 - 2.0 * a1 + a2;
    if den < 0.0 {
        (0.5 * (a0 - a2) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// The sensor noise of a frame, σ on the 0–255 scale (after `img`'s gain), from its smoothest parts: in
/// 8 × 8 blocks, the variance of the horizontal differences I(x+1, y) − I(x, y) (the block's mean
/// difference removed, so a lighting gradient does not count), the 20th percentile of the blocks taken
/// (edges and texture only raise blocks), corrected for where that percentile falls for 56 degrees of
/// freedom (× 1/0.84), and halved (a difference has twice the variance). Blocks that hold no sensor noise
/// are left out, as they would pull that percentile to 0; the vertical differences' variance tells them: a
/// block whose variance one way is under a quarter of the other's (a border padded by repeating the
/// frame's edge, a letterbox of repeated rows or columns, a straight edge; white noise never gives that
/// on 55 differences a way), and a block of one level throughout (clipped, a constant border, a padded
/// border's corner; a sensor's noise moves some pixel of 64). Quantisation adds its 1/12 DN² as it does
/// to any measurement. 0 when no block is left (a noiseless frame of flat areas and straight edges).
/// Cost: one read of the frame.
pub fn noise_sigma<P: Pixel>(img: &Plane<P>) -> f32 {
    const B: usize = 8;
    /// Least ratio of a block's smaller directional variance to its larger for it to hold sensor noise.
    const MIN_ISOTROPY: f32 = 0.25;
    let (w, h) = (img.width, img.height);
    if w < B + 1 || h < B {
        return 0.0;
    }
    let variance = |(s, s2, n): (f32, f32, f32)| (s2 - s * s / n) / (n - 1.0);
    let mut vars: Vec<f32> = Vec::with_capacity((w / B) * (h / B));
    for by in (0..=h - B).step_by(B) {
        for bx in (0..w - B).step_by(B) {
            let (mut across, mut down) = ((0.0f32, 0.0f32, 0.0f32), (0.0f32, 0.0f32, 0.0f32));
            let (mut block_lo, mut block_hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for y in by..by + B {
                for x in bx..bx + B {
                    let v = img.data[y * w + x].level();
                    (block_lo, block_hi) = (block_lo.min(v), block_hi.max(v));
                    if x + 1 < bx + B {
                        let d = img.at(x + 1, y) - img.at(x, y);
                        across = (across.0 + d, across.1 + d * d, across.2 + 1.0);
                    }
                    if y + 1 < by + B {
                        let d = img.at(x, y + 1) - img.at(x, y);
                        down = (down.0 + d, down.1 + d * d, down.2 + 1.0);
                    }
                }
            }
            if block_lo == block_hi {
                continue;
            }
            let (a, d) = (variance(across).max(0.0), variance(down).max(0.0));
            if a.min(d) < MIN_ISOTROPY * a.max(d) {
                continue;
            }
            vars.push(a);
        }
    }
    if vars.is_empty() {
        return 0.0;
    }
    let k = vars.len() / 5;
    let p20 = *vars.select_nth_unstable_by(k, f32::total_cmp).1;
    (p20 / 0.84 / 2.0).max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_testkit::Rng;

    /// A `w` × `h` frame of level 120 with white noise of `sigma` DN, in 8-bit.
    fn noisy(w: usize, h: usize, sigma: f64, seed: u64) -> Vec<u8> {
        let mut rng = Rng::new(seed);
        (0..w * h)
            .map(|_| (120.0 + sigma * rng.normal()).round().clamp(0.0, 255.0) as u8)
            .collect()
    }

    #[test]
    fn white_noise_is_measured() {
        for sigma in [2.0, 6.0, 10.0] {
            let frame = noisy(256, 256, sigma, 3);
            let measured = noise_sigma(&Plane::new(&frame, 256, 256)) as f64;
            // Rounding to whole DN adds 1/12 DN².
            let expected = (sigma * sigma + 1.0 / 12.0).sqrt();
            assert!(
                (measured / expected - 1.0).abs() < 0.05,
                "σ {sigma}: measured {measured}"
            );
        }
    }

    /// A frame padded by repeating its edge columns (as a camera's or a converter's border does), with a
    /// black letterbox above and a clipped white one below, has the noise of the picture inside: the
    /// repeated and constant blocks hold none, and without leaving them out (a third of the blocks) the
    /// 20th percentile is 0.
    #[test]
    fn padded_and_letterboxed_borders_do_not_hide_the_noise() {
        let (w, h, pad, bar) = (192, 160, 64, 24);
        let inner = noisy(w, h, 6.0, 5);
        let (pw, ph) = (w + 2 * pad, h + 2 * bar);
        let mut frame = vec![0u8; pw * ph];
        for y in 0..ph {
            for x in 0..pw {
                frame[y * pw + x] = if y < bar {
                    0
                } else if y >= bar + h {
                    255
                } else {
                    inner[(y - bar) * w + x.clamp(pad, pad + w - 1) - pad]
                };
            }
        }
        let alone = noise_sigma(&Plane::new(&inner, w, h));
        let padded = noise_sigma(&Plane::new(&frame, pw, ph));
        assert!((padded / alone - 1.0).abs() < 0.05, "alone {alone}, padded {padded}");
    }

    /// A border padded by repeating the frame's edge has corners of one level, whose blocks are a quarter
    /// of the border's when it is as wide as the picture is high (here more than a fifth of all blocks).
    #[test]
    fn a_wide_padded_border_s_corners_do_not_hide_the_noise() {
        let (w, pad) = (96, 96);
        let inner = noisy(w, w, 6.0, 9);
        let pw = w + 2 * pad;
        let at = |v: usize| v.clamp(pad, pad + w - 1) - pad;
        let frame: Vec<u8> = (0..pw * pw).map(|i| inner[at(i / pw) * w + at(i % pw)]).collect();
        let alone = noise_sigma(&Plane::new(&inner, w, w));
        let padded = noise_sigma(&Plane::new(&frame, pw, pw));
        assert!((padded / alone - 1.0).abs() < 0.05, "alone {alone}, padded {padded}");
    }

    #[test]
    fn a_noiseless_frame_has_no_noise() {
        let mut frame = vec![90u8; 64 * 64];
        frame[..64 * 8].fill(0);
        frame[64 * 56..].fill(200);
        assert_eq!(noise_sigma(&Plane::new(&frame, 64, 64)), 0.0);
    }
}
