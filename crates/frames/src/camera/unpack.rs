//! Bit unpacking from camera files into 16-bit samples: the hot loops of camera-file decoding.
//!
//! Every loop writes exactly `dst.len()` samples and asserts that `src` holds exactly the bytes for them
//! (the callers check sizes against the header first). A narrower sample is shifted to 16-bit full scale
//! (12-bit values `<< 4`), so that [`crate::GrayPixels::U16`] always means 0–65535. Each frame is written once
//! into a buffer that is either new or given back by the consumer ([`Pool`]).

use std::mem::MaybeUninit;
use std::sync::Mutex;

/// 12-bit big-endian packing, two pixels in three bytes: `p0 = b0·16 + b1 >> 4`,
/// `p1 = (b1 & 15)·256 + b2` (Photron MRAW 12-bit; Phantom CINE "P12L"), at 16-bit full scale (`<< 4`).
///
/// Writes every sample of `dst`; `src` must hold exactly 3 bytes for each 2 samples.
#[inline(always)]
fn unpack12(src: &[u8], dst: &mut [MaybeUninit<u16>]) {
    assert_eq!(src.len() * 2, dst.len() * 3, "12-bit packing: 3 bytes for 2 samples");
    let (groups, _) = src.as_chunks::<3>();
    let (out, _) = dst.as_chunks_mut::<2>();
    for (s, d) in groups.iter().zip(out) {
        let (b0, b1, b2) = (u16::from(s[0]), u16::from(s[1]), u16::from(s[2]));
        d[0].write(((b0 << 4) | (b1 >> 4)) << 4);
        d[1].write((((b1 & 0x0F) << 8) | b2) << 4);
    }
}

/// 10-bit big-endian packing, four pixels in five bytes (Phantom CINE "P10"), at 16-bit full scale (`<< 6`).
///
/// Writes every sample of `dst`; `src` must hold exactly 5 bytes for each 4 samples.
#[inline(always)]
fn unpack10(src: &[u8], dst: &mut [MaybeUninit<u16>]) {
    assert_eq!(src.len() * 4, dst.len() * 5, "10-bit packing: 5 bytes for 4 samples");
    let (groups, _) = src.as_chunks::<5>();
    let (out, _) = dst.as_chunks_mut::<4>();
    for (s, d) in groups.iter().zip(out) {
        let (b0, b1, b2, b3, b4) = (
            u16::from(s[0]),
            u16::from(s[1]),
            u16::from(s[2]),
            u16::from(s[3]),
            u16::from(s[4]),
        );
        d[0].write(((b0 << 2) | (b1 >> 6)) << 6);
        d[1].write((((b1 & 0x3F) << 4) | (b2 >> 4)) << 6);
        d[2].write((((b2 & 0x0F) << 6) | (b3 >> 2)) << 6);
        d[3].write((((b3 & 0x03) << 8) | b4) << 6);
    }
}

/// Little-endian 16-bit samples, shifted, appended to `out` (a whole row or frame at a time, so that the
/// compiler sees one long loop).
#[inline(always)]
fn extend16_le(out: &mut Vec<u16>, src: &[u8], shift: u32) {
    out.extend(src.chunks_exact(2).map(|s| u16::from_le_bytes([s[0], s[1]]) << shift));
}

/// Appends a frame of little-endian 16-bit samples to `out` (empty, with room for them), rows reversed if
/// `bottom_up`: each sample is written once (no zero-fill first).
#[inline(always)]
fn copy16_le(src: &[u8], w: usize, shift: u32, bottom_up: bool, mut out: Vec<u16>) -> Vec<u16> {
    if bottom_up {
        for row in src.chunks_exact(2 * w).rev() {
            extend16_le(&mut out, row, shift);
        }
    } else {
        extend16_le(&mut out, src, shift);
    }
    out
}

/// Frame buffers the consumer gave back ([`crate::Clip::recycle`]), reused for the next frames decoded.
///
/// Why: frames are decoded on worker threads and dropped on the consumer's, so the allocator hands each new
/// frame fresh pages from the kernel (a page fault and the kernel's zero-fill a page, and an `madvise` when
/// the consumer frees it): on the 2-thread stream this cost about 3× the unpacking itself. A reused buffer
/// is already mapped.
#[derive(Debug, Default)]
pub(crate) struct Pool {
    gray8: Mutex<Vec<Vec<u8>>>,
    gray16: Mutex<Vec<Vec<u16>>>,
}

/// Most bytes of buffers a pool keeps (beyond two buffers): enough for the frames in flight of a stream of
/// 512×512 frames, bounded for large frames.
const POOL_BYTES: usize = 64 << 20;

/// Most buffers a pool keeps.
const POOL_BUFFERS: usize = 32;

impl Pool {
    /// An empty buffer with room for `n` samples: a recycled one when there is one.
    fn take<T>(list: &Mutex<Vec<Vec<T>>>, n: usize) -> Vec<T> {
        let mut v = list.lock().map(|mut l| l.pop()).ok().flatten().unwrap_or_default();
        v.clear();
        v.reserve_exact(n);
        v
    }

    fn keep<T>(list: &Mutex<Vec<Vec<T>>>, v: Vec<T>) {
        let bytes = v.capacity() * std::mem::size_of::<T>();
        let most = (POOL_BYTES / bytes.max(1)).clamp(2, POOL_BUFFERS);
        if let Ok(mut l) = list.lock()
            && l.len() < most
        {
            l.push(v);
        }
    }

    /// Keeps a frame's buffer for reuse if it holds at least `n` samples (and the pool is not full).
    pub(crate) fn give(&self, pixels: crate::GrayPixels, n: usize) {
        match pixels {
            crate::GrayPixels::U8(i) if i.as_raw().capacity() >= n => Self::keep(&self.gray8, i.into_raw()),
            crate::GrayPixels::U16(i) if i.as_raw().capacity() >= n => Self::keep(&self.gray16, i.into_raw()),
            _ => {}
        }
    }
}

/// How a frame's samples are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Packing {
    /// One byte a pixel.
    U8,
    /// Two little-endian bytes a pixel, shifted left by this many bits to full scale.
    U16Le(u32),
    /// 10-bit packed, shifted left by 6.
    P10,
    /// 12-bit packed, shifted left by 4.
    P12,
}

impl Packing {
    /// Bytes of a row of `width` pixels, or `None` if the packing cannot hold that row whole (packed
    /// groups straddling rows are fine when the frame as a whole is whole: see [`Packing::frame_bytes`]).
    pub(crate) fn frame_bytes(self, pixels: u64) -> Option<u64> {
        match self {
            Self::U8 => Some(pixels),
            Self::U16Le(_) => pixels.checked_mul(2),
            Self::P10 => pixels.is_multiple_of(4).then(|| pixels / 4 * 5),
            Self::P12 => pixels.is_multiple_of(2).then(|| pixels / 2 * 3),
        }
    }

    /// Stored bits per pixel.
    pub(crate) fn bits(self) -> u8 {
        match self {
            Self::U8 => 8,
            Self::U16Le(_) => 16,
            Self::P10 => 10,
            Self::P12 => 12,
        }
    }

    /// Unpacks `src` (exactly one frame, `rows` of `width` pixels, stored top row first unless
    /// `bottom_up`) to gray pixels, in a buffer from `pool` when it has one.
    pub(crate) fn unpack(self, src: &[u8], width: u32, height: u32, bottom_up: bool, pool: &Pool) -> crate::GrayPixels {
        let (w, h) = (width as usize, height as usize);
        match self {
            Self::U8 => {
                let mut buf = Pool::take(&pool.gray8, w * h);
                if bottom_up {
                    for row in src.chunks_exact(w).rev() {
                        buf.extend_from_slice(row);
                    }
                } else {
                    buf.extend_from_slice(src);
                }
                crate::GrayPixels::U8(image::GrayImage::from_raw(width, height, buf).expect("size checked by caller"))
            }
            Self::U16Le(shift) => {
                let out = fast_copy16_le(src, w, shift, bottom_up, Pool::take(&pool.gray16, w * h));
                crate::GrayPixels::U16(
                    crate::Gray16Image::from_raw(width, height, out).expect("size checked by caller"),
                )
            }
            Self::P10 | Self::P12 => {
                let out = unpack_packed(self, src, w * h, Pool::take(&pool.gray16, w * h));
                crate::GrayPixels::U16(
                    crate::Gray16Image::from_raw(width, height, out).expect("size checked by caller"),
                )
            }
        }
    }
}

/// Unpacks a frame of `n` packed samples (stored top-down) into `out` (emptied first), written once: the
/// loops fill the buffer's uninitialised capacity, which saves a zero-fill pass over a frame's memory.
fn unpack_packed(packing: Packing, src: &[u8], n: usize, mut out: Vec<u16>) -> Vec<u16> {
    out.clear();
    out.reserve_exact(n);
    let dst = &mut out.spare_capacity_mut()[..n];
    match packing {
        Packing::P10 => fast_unpack10(src, dst),
        Packing::P12 => fast_unpack12(src, dst),
        Packing::U8 | Packing::U16Le(_) => unreachable!("only packed samples are unpacked here"),
    }
    // SAFETY: `unpack10`, `unpack12` and their AVX2 versions write every element of the `dst` they are given
    // (they assert that `src` holds exactly the bytes of `dst.len()` samples, then cover `dst` in whole
    // groups), and `dst` is the first `n` elements of the capacity.
    unsafe { out.set_len(n) };
    out
}

/// Picks the AVX2 build of a loop when the CPU has it, else the baseline x86-64 build of the same loop.
macro_rules! dispatched {
    (fn $name:ident($($arg:ident: $ty:ty),*) -> $ret:ty; avx2: $wide:path, baseline: $narrow:path) => {
        fn $name($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2, checked on the line above.
                return unsafe { $wide($($arg),*) };
            }
            $narrow($($arg),*)
        }
    };
}

dispatched!(fn fast_unpack12(src: &[u8], dst: &mut [MaybeUninit<u16>]) -> ();
    avx2: avx2::unpack12, baseline: unpack12);
dispatched!(fn fast_unpack10(src: &[u8], dst: &mut [MaybeUninit<u16>]) -> ();
    avx2: avx2::unpack10, baseline: unpack10);
dispatched!(fn fast_copy16_le(src: &[u8], w: usize, shift: u32, bottom_up: bool, out: Vec<u16>) -> Vec<u16>;
    avx2: avx2::copy16_le, baseline: copy16_le);

/// The same loops for CPUs with AVX2.
///
/// 16-bit samples: the scalar loop, compiled with AVX2 (the compiler vectorises it). Packed samples: written
/// by hand, because the compiler does not vectorise 5-byte groups (the scalar 10-bit loop took 86 µs of a
/// 512×512 frame against 22 µs here) and vectorises 3-byte groups less well than this (43 → 28 µs). Each
/// 128-bit lane turns one run of packed bytes into 8 big-endian 16-bit windows with one byte shuffle; a
/// multiply by a power of two per lane moves each sample to the top of its window (a per-lane left
/// shift, which AVX2 has only for 32-bit lanes) and a mask clears the neighbour's bits below it, which
/// leaves the sample at 16-bit full scale.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::{
        __m128i, __m256i, _mm_loadu_si128, _mm256_and_si256, _mm256_castsi128_si256, _mm256_inserti128_si256,
        _mm256_mullo_epi16, _mm256_set1_epi16, _mm256_setr_epi8, _mm256_setr_epi16, _mm256_shuffle_epi8,
        _mm256_storeu_si256,
    };
    use std::mem::MaybeUninit;

    #[target_feature(enable = "avx2")]
    pub(super) fn copy16_le(src: &[u8], w: usize, shift: u32, bottom_up: bool, out: Vec<u16>) -> Vec<u16> {
        super::copy16_le(src, w, shift, bottom_up, out)
    }

    /// Loads `lo[..16]` into the low lane and `hi[..16]` into the high lane.
    #[target_feature(enable = "avx2")]
    fn load_lanes(lo: &[u8], hi: &[u8]) -> __m256i {
        let (lo, hi) = (&lo[..16], &hi[..16]);
        // SAFETY: both slices hold the 16 bytes read (checked by the slicing above); unaligned loads.
        unsafe {
            let lo = _mm_loadu_si128(lo.as_ptr().cast::<__m128i>());
            let hi = _mm_loadu_si128(hi.as_ptr().cast::<__m128i>());
            _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(lo), hi)
        }
    }

    /// Stores 16 samples into `dst[..16]`.
    #[target_feature(enable = "avx2")]
    fn store16(dst: &mut [MaybeUninit<u16>], v: __m256i) {
        let dst = &mut dst[..16];
        // SAFETY: `dst` holds the 16 samples written (checked by the slicing above); unaligned store.
        unsafe { _mm256_storeu_si256(dst.as_mut_ptr().cast::<__m256i>(), v) }
    }

    /// How one kind of packing becomes 16 samples a step (see the module's doc).
    struct Lanes {
        /// Packed bytes read a step: 8 samples a lane.
        step: usize,
        /// Byte pairs (high, low) of each sample's 16-bit window, within a lane's bytes.
        windows: __m256i,
        /// The power of two that moves each sample to the top of its window.
        to_top: __m256i,
        /// The bits of a sample at the top of its window.
        keep: __m256i,
    }

    /// Unpacks `src` into `dst`, 16 samples a step, then the last groups (whose 16-byte loads would run
    /// past `src`) by the scalar loop `tail`.
    #[target_feature(enable = "avx2")]
    fn unpack(src: &[u8], dst: &mut [MaybeUninit<u16>], l: &Lanes, tail: fn(&[u8], &mut [MaybeUninit<u16>])) {
        let half = l.step / 2;
        let (mut i, mut o) = (0, 0);
        // The high lane's load reads bytes i + half .. i + half + 16.
        while src.len() - i >= half + 16 {
            let v = _mm256_shuffle_epi8(load_lanes(&src[i..], &src[i + half..]), l.windows);
            store16(&mut dst[o..], _mm256_and_si256(_mm256_mullo_epi16(v, l.to_top), l.keep));
            i += l.step;
            o += 16;
        }
        tail(&src[i..], &mut dst[o..]);
    }

    /// 10-bit packing, 20 bytes a step.
    #[target_feature(enable = "avx2")]
    pub(super) fn unpack10(src: &[u8], dst: &mut [MaybeUninit<u16>]) {
        assert_eq!(src.len() * 4, dst.len() * 5, "10-bit packing: 5 bytes for 4 samples");
        #[rustfmt::skip]
        let lanes = Lanes {
            step: 20,
            // Sample j of a 5-byte group starts in byte j, 6 − 2j bits up its window: × 4^j, keep 10 bits.
            windows: _mm256_setr_epi8(
                1, 0, 2, 1, 3, 2, 4, 3, 6, 5, 7, 6, 8, 7, 9, 8,
                1, 0, 2, 1, 3, 2, 4, 3, 6, 5, 7, 6, 8, 7, 9, 8,
            ),
            to_top: _mm256_setr_epi16(1, 4, 16, 64, 1, 4, 16, 64, 1, 4, 16, 64, 1, 4, 16, 64),
            keep: _mm256_set1_epi16(0xFFC0_u16 as i16),
        };
        unpack(src, dst, &lanes, super::unpack10);
    }

    /// 12-bit packing, 24 bytes a step.
    #[target_feature(enable = "avx2")]
    pub(super) fn unpack12(src: &[u8], dst: &mut [MaybeUninit<u16>]) {
        assert_eq!(src.len() * 2, dst.len() * 3, "12-bit packing: 3 bytes for 2 samples");
        #[rustfmt::skip]
        let lanes = Lanes {
            step: 24,
            // Sample 2k fills the top 12 bits of the window of bytes 3k, 3k + 1 (× 1), sample 2k + 1 the
            // low 12 bits of bytes 3k + 1, 3k + 2 (× 16); keep 12 bits.
            windows: _mm256_setr_epi8(
                1, 0, 2, 1, 4, 3, 5, 4, 7, 6, 8, 7, 10, 9, 11, 10,
                1, 0, 2, 1, 4, 3, 5, 4, 7, 6, 8, 7, 10, 9, 11, 10,
            ),
            to_top: _mm256_setr_epi16(1, 16, 1, 16, 1, 16, 1, 16, 1, 16, 1, 16, 1, 16, 1, 16),
            keep: _mm256_set1_epi16(0xFFF0_u16 as i16),
        };
        unpack(src, dst, &lanes, super::unpack12);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The obvious bit-by-bit reader: `bits` bits a sample, most significant bit first.
    fn slow(src: &[u8], bits: usize, n: usize) -> Vec<u16> {
        (0..n)
            .map(|i| {
                (0..bits).fold(0u16, |acc, b| {
                    let bit = i * bits + b;
                    acc << 1 | u16::from(src[bit / 8] >> (7 - bit % 8) & 1)
                })
            })
            .collect()
    }

    /// A plain reference decoder of a whole frame: samples read one at a time, shifted to full scale, rows
    /// flipped afterwards if stored bottom-up.
    fn reference(packing: Packing, src: &[u8], w: usize, h: usize, bottom_up: bool) -> Vec<u16> {
        let samples: Vec<u16> = match packing {
            Packing::U8 => src.iter().map(|&b| u16::from(b)).collect(),
            Packing::U16Le(shift) => (0..w * h)
                .map(|i| (u16::from(src[2 * i]) | u16::from(src[2 * i + 1]) << 8) << shift)
                .collect(),
            Packing::P10 => slow(src, 10, w * h).iter().map(|v| v << 6).collect(),
            Packing::P12 => slow(src, 12, w * h).iter().map(|v| v << 4).collect(),
        };
        if bottom_up {
            samples.chunks_exact(w).rev().flatten().copied().collect()
        } else {
            samples
        }
    }

    fn decoded(packing: Packing, src: &[u8], w: usize, h: usize, bottom_up: bool) -> Vec<u16> {
        match packing.unpack(src, w as u32, h as u32, bottom_up, &Pool::default()) {
            crate::GrayPixels::U8(i) => i.into_raw().into_iter().map(u16::from).collect(),
            crate::GrayPixels::U16(i) => i.into_raw(),
        }
    }

    /// Runs a packed loop into a fresh buffer (a stand-in for the capacity of `unpack_packed`).
    fn run(f: impl FnOnce(&[u8], &mut [MaybeUninit<u16>]), src: &[u8], n: usize) -> Vec<u16> {
        let mut out = vec![MaybeUninit::new(0xDEAD); n];
        f(src, &mut out);
        // Safe read-back: every element was initialised above (and, the test checks, overwritten).
        out.iter().map(|v| unsafe { v.assume_init() }).collect()
    }

    fn packing() -> impl Strategy<Value = Packing> {
        prop_oneof![
            Just(Packing::U8),
            (0u32..=4).prop_map(Packing::U16Le),
            Just(Packing::P10),
            Just(Packing::P12),
        ]
    }

    proptest! {
        /// Each fast path (the one this CPU runs, through `Packing::unpack`) equals the reference decoder on
        /// random bytes and odd sizes, including frames smaller than one vector step and ragged tails.
        #[test]
        fn every_packing_matches_a_reference_decoder(
            packing in packing(),
            w in 1usize..90,
            h in 1usize..7,
            bottom_up in any::<bool>(),
            seed in any::<u64>(),
        ) {
            let bottom_up = bottom_up && matches!(packing, Packing::U8 | Packing::U16Le(_));
            let Some(bytes) = packing.frame_bytes((w * h) as u64) else {
                return Ok(()); // the header checks refuse these sizes
            };
            let mut rng = crate::testutil::Noise::new(seed);
            let src: Vec<u8> = (0..bytes).map(|_| rng.next_u64() as u8).collect();
            prop_assert_eq!(decoded(packing, &src, w, h, bottom_up), reference(packing, &src, w, h, bottom_up));
        }

        /// The baseline loops and the AVX2 loops each equal the bit-by-bit reader, whichever one the
        /// dispatch picks on this CPU.
        #[test]
        fn both_builds_of_the_packed_loops_match_a_bit_by_bit_reader(groups in 0usize..60, seed in any::<u64>()) {
            let mut rng = crate::testutil::Noise::new(seed);
            let bytes: Vec<u8> = (0..groups * 15).map(|_| rng.next_u64() as u8).collect();
            let want12: Vec<u16> = slow(&bytes, 12, groups * 10).iter().map(|v| v << 4).collect();
            let want10: Vec<u16> = slow(&bytes, 10, groups * 12).iter().map(|v| v << 6).collect();
            prop_assert_eq!(&run(unpack12, &bytes, groups * 10), &want12);
            prop_assert_eq!(&run(unpack10, &bytes, groups * 12), &want10);
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2, checked on the line above.
                prop_assert_eq!(&run(|s, d| unsafe { avx2::unpack12(s, d) }, &bytes, groups * 10), &want12);
                prop_assert_eq!(&run(|s, d| unsafe { avx2::unpack10(s, d) }, &bytes, groups * 12), &want10);
            }
        }
    }

    #[test]
    fn a_mismatched_length_is_refused_before_anything_is_written() {
        let result = std::panic::catch_unwind(|| run(unpack12, &[0; 4], 2));
        assert!(result.is_err(), "4 bytes are not 2 packed 12-bit samples");
        let result = std::panic::catch_unwind(|| run(unpack10, &[0; 5], 5));
        assert!(result.is_err(), "5 bytes are not 5 packed 10-bit samples");
    }

    #[test]
    fn a_recycled_buffer_is_reused_and_overwritten_whole() {
        let pool = Pool::default();
        let (w, h) = (40usize, 3usize);
        let src: Vec<u8> = (0..w * h * 2).map(|i| (i * 37 % 256) as u8).collect();
        for packing in [Packing::P12, Packing::U16Le(4), Packing::U8] {
            let bytes = &src[..packing.frame_bytes((w * h) as u64).unwrap() as usize];
            let first = packing.unpack(bytes, w as u32, h as u32, false, &pool);
            let ptr = match &first {
                crate::GrayPixels::U8(i) => i.as_raw().as_ptr() as usize,
                crate::GrayPixels::U16(i) => i.as_raw().as_ptr() as usize,
            };
            // A buffer holding other values, given back, comes out holding this frame's values only.
            let dirty = match first {
                crate::GrayPixels::U8(_) => {
                    crate::GrayPixels::U8(image::GrayImage::from_pixel(w as u32, h as u32, image::Luma([7])))
                }
                crate::GrayPixels::U16(_) => {
                    crate::GrayPixels::U16(crate::Gray16Image::from_pixel(w as u32, h as u32, image::Luma([7])))
                }
            };
            let dirty_ptr = match &dirty {
                crate::GrayPixels::U8(i) => i.as_raw().as_ptr() as usize,
                crate::GrayPixels::U16(i) => i.as_raw().as_ptr() as usize,
            };
            assert_ne!(ptr, dirty_ptr);
            pool.give(dirty, w * h);
            let again = packing.unpack(bytes, w as u32, h as u32, false, &pool);
            let again_ptr = match &again {
                crate::GrayPixels::U8(i) => i.as_raw().as_ptr() as usize,
                crate::GrayPixels::U16(i) => i.as_raw().as_ptr() as usize,
            };
            assert_eq!(again_ptr, dirty_ptr, "{packing:?}: the given buffer is reused");
            assert_eq!(
                decoded(packing, bytes, w, h, false),
                reference(packing, bytes, w, h, false)
            );
            let values: Vec<u16> = match again {
                crate::GrayPixels::U8(i) => i.into_raw().into_iter().map(u16::from).collect(),
                crate::GrayPixels::U16(i) => i.into_raw(),
            };
            assert_eq!(values, reference(packing, bytes, w, h, false), "{packing:?}");
        }
    }

    #[test]
    fn the_pool_keeps_a_bounded_number_of_buffers_and_none_too_small() {
        let pool = Pool::default();
        for _ in 0..100 {
            pool.give(crate::GrayPixels::U16(crate::Gray16Image::new(8, 8)), 64);
        }
        assert_eq!(pool.gray16.lock().unwrap().len(), POOL_BUFFERS);
        pool.give(crate::GrayPixels::U8(image::GrayImage::new(4, 4)), 64);
        assert!(
            pool.gray8.lock().unwrap().is_empty(),
            "a 16-pixel buffer is no use for 64-pixel frames"
        );
    }

    #[test]
    fn sixteen_bit_rows_flip_when_stored_bottom_up() {
        let src: Vec<u8> = [1u16, 2, 3, 4, 5, 6].iter().flat_map(|v| v.to_le_bytes()).collect();
        let px = Packing::U16Le(0).unpack(&src, 3, 2, true, &Pool::default());
        assert_eq!(px.as_u16().unwrap().as_raw(), &vec![4, 5, 6, 1, 2, 3]);
        let px = Packing::U8.unpack(&[1, 2, 3, 4], 2, 2, true, &Pool::default());
        assert_eq!(px.as_u8().unwrap().as_raw(), &vec![3, 4, 1, 2]);
    }
}
