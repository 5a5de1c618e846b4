//! A small, fast, seedable random number generator (xoshiro256++ seeded by SplitMix64) and a Gaussian
//! table, so noise is cheap and every stream is derived from (seed, shot, frame) alone.

use std::sync::OnceLock;

/// SplitMix64 step: a good 64-bit mixer, used to derive independent seeds.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A seed derived from a parent seed and a stream index (shot, frame…).
pub fn derive(seed: u64, stream: u64) -> u64 {
    mix(mix(seed) ^ mix(stream.wrapping_mul(0xD1B5_4A32_D192_ED03).wrapping_add(1)))
}

/// xoshiro256++.
#[derive(Debug, Clone)]
pub struct Rng {
    s: [u64; 4],
}

impl Rng {
    /// A generator seeded from `seed`.
    pub fn new(seed: u64) -> Rng {
        let mut z = seed;
        let mut s = [0u64; 4];
        for v in &mut s {
            z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
            *v = mix(z);
        }
        Rng { s }
    }

    /// 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    #[inline]
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Standard normal (Box–Muller; for setup work, not per pixel).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Number of entries of the Gaussian table (a power of two).
pub const GAUSS_LEN: usize = 1 << 16;

/// 65,536 standard-normal values, rescaled to mean 0 and variance 1 exactly; indexed by 16 random bits
/// they give Gaussian noise at the cost of one table read (tails are cut at about ±4.4σ).
pub fn gauss_table() -> &'static [f32] {
    static T: OnceLock<Vec<f32>> = OnceLock::new();
    T.get_or_init(|| {
        let mut rng = Rng::new(0x6761_7573_735f_7462);
        let v: Vec<f64> = (0..GAUSS_LEN).map(|_| rng.normal()).collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let sd = (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n).sqrt();
        v.iter().map(|x| ((x - mean) / sd) as f32).collect()
    })
}

/// Smooth 2-D value noise in [−1, 1] on a periodic lattice of `cells` × `cells` random values, sampled
/// at (x, y) in lattice units.
#[derive(Debug, Clone)]
pub struct ValueNoise {
    n: usize,
    v: Vec<f32>,
}

impl ValueNoise {
    /// A lattice of `cells` × `cells` values from `rng`.
    pub fn new(rng: &mut Rng, cells: usize) -> ValueNoise {
        let n = cells.max(2);
        ValueNoise {
            n,
            v: (0..n * n).map(|_| rng.range(-1.0, 1.0) as f32).collect(),
        }
    }

    /// The noise at (x, y), lattice units (wraps around).
    pub fn at(&self, x: f64, y: f64) -> f32 {
        let n = self.n as i64;
        let (fx, fy) = (x.floor(), y.floor());
        let (tx, ty) = ((x - fx) as f32, (y - fy) as f32);
        let (sx, sy) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
        let (ix, iy) = ((fx as i64).rem_euclid(n) as usize, (fy as i64).rem_euclid(n) as usize);
        let (jx, jy) = ((ix + 1) % self.n, (iy + 1) % self.n);
        let g = |a: usize, b: usize| self.v[b * self.n + a];
        let top = g(ix, iy) + (g(jx, iy) - g(ix, iy)) * sx;
        let bot = g(ix, jy) + (g(jx, jy) - g(ix, jy)) * sx;
        top + (bot - top) * sy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_table_is_standard() {
        let t = gauss_table();
        let n = t.len() as f64;
        let mean: f64 = t.iter().map(|&x| x as f64).sum::<f64>() / n;
        let var: f64 = t.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / n;
        assert!(mean.abs() < 1e-6 && (var - 1.0).abs() < 1e-4);
    }

    #[test]
    fn derived_streams_differ() {
        assert_ne!(derive(1, 0), derive(1, 1));
        assert_ne!(derive(1, 0), derive(2, 0));
        assert_eq!(Rng::new(5).next_u64(), Rng::new(5).next_u64());
    }
}
