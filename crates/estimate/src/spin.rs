//! Spin before and after the impact, from the rotation of the ball's texture (felt and seam) between frames.
//!
//! The camera looks along the spin axis, so the same hemisphere faces it in every frame and the texture turns
//! rigidly in the image plane. Each frame's ball interior is sampled on a polar grid around the tracked centre
//! (rings from 0.3 R to 0.85 R, 256 angles, bilinear). What does not turn with the ball (shading from the
//! fixed light, vignetting: smooth along the angle) is divided out ring by ring: the ring is divided by its
//! own low harmonics (0–3) and only harmonics from 4 up to what the ring's circumference resolves are kept.
//! Each frame's angle relative to a reference frame (the middle one of the phase) is the peak of the circular
//! cross-correlation along the angle, summed over rings, refined to sub-sample precision on the band-limited
//! (Fourier) interpolation of the correlation. The angles are unwrapped over time and a straight line
//! θ(t) = θ₀ + ω·t fitted; ω's standard error comes from the residual scatter.
//!
//! Angles on the polar grid run counter-clockwise as seen (image y points down, so a point at angle φ is at
//! (x, y) = (cx + ρ cos φ, cy − ρ sin φ)): a positive angle is a counter-clockwise turn in the image. The
//! estimate reports ω in the local frame of `docs/outputs.md` (x down-slope, y the outward normal), which is
//! counter-clockwise as seen in the image when down-slope is +x, and clockwise as seen when the image is
//! mirrored (`downslope = "-x"`), so that the slip v_t + ω·R holds either way.

use crate::phase::PhaseFrames;
use crate::shot::Measured;
use bouncelab_frames::{Clip, GrayPixels, PngDecoder};
use bouncelab_track::{Status, Track};
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

/// How spin is measured.
#[derive(Debug, Clone, PartialEq)]
pub struct SpinOptions {
    /// Samples around each ring (a power of two).
    pub angles: usize,
    /// Number of rings.
    pub rings: usize,
    /// Innermost ring, fraction of the radius.
    pub r_inner: f64,
    /// Outermost ring, fraction of the radius.
    pub r_outer: f64,
    /// Frames read per flight phase at most (evenly spaced over the phase).
    pub max_frames: usize,
    /// Fewest frames with a clear correlation peak for a phase to be measured.
    pub min_frames: usize,
    /// Smallest normalised correlation peak (−1…1) for a frame to count: below it the texture's contrast is
    /// too low (or the texture changed) to tell the rotation.
    pub min_peak: f64,
}

impl Default for SpinOptions {
    fn default() -> Self {
        SpinOptions {
            angles: 256,
            rings: 12,
            r_inner: 0.3,
            r_outer: 0.85,
            max_frames: 40,
            min_frames: 5,
            min_peak: 0.25,
        }
    }
}

/// Lowest angular harmonic kept: 0–3 are the shading and vignetting, which do not turn with the ball.
const K_LOW: usize = 4;
/// Shortest wavelength kept along a ring, px (finer detail is interpolation, not texture).
const MIN_WAVELENGTH_PX: f64 = 2.5;

/// One frame of a flight phase: its time, pixels and the ball's circle in it.
#[derive(Debug, Clone, Copy)]
pub struct SpinImage<'a> {
    /// Time, s.
    pub t_s: f64,
    /// The frame's pixels (8- or 16-bit).
    pub pixels: &'a GrayPixels,
    /// Ball centre x, px.
    pub x_px: f64,
    /// Ball centre y, px (down).
    pub y_px: f64,
    /// Ball radius, px.
    pub r_px: f64,
}

/// The rotation of one frame relative to another.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation {
    /// Angle, rad, in (−π, π], positive counter-clockwise as seen in the image.
    pub angle: f64,
    /// Normalised correlation at the peak (1 = identical texture after turning).
    pub peak: f64,
}

/// Spin of both flight phases, in the local frame of `docs/outputs.md`, with what went wrong.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Spin {
    /// Spin before the impact, rad/s.
    pub spin_in: Option<Measured>,
    /// Spin after the impact, rad/s.
    pub spin_out: Option<Measured>,
    /// Why a phase was not measured, or what to know about it.
    pub notes: Vec<String>,
}

/// A ring's spectrum, band-limited: harmonics `K_LOW..k_max`, as (re, im).
struct Polar {
    rings: Vec<Vec<(f64, f64)>>,
    energy: f64,
}

/// Samples the ball's interior on the polar grid and keeps the rotating part of each ring's spectrum.
/// `None` when a sample falls outside the image.
fn polar(f: &SpinImage, o: &SpinOptions) -> Option<Polar> {
    let n = o.angles;
    let (w, h) = f.pixels.dimensions();
    let (w, h) = (w as f64, h as f64);
    let mut rings = Vec::with_capacity(o.rings);
    let mut energy = 0.0;
    let mut buf = vec![0.0f64; n];
    // cos and sin of 2πj/n: the sampling angles, the low-pass's k·φ_j and the FFT's twiddles are all
    // multiples of 2π/n (sin/cos was a quarter of a shot's measuring time).
    let unit = UnitCircle::new(n);
    for i in 0..o.rings {
        let frac = if o.rings == 1 {
            0.5 * (o.r_inner + o.r_outer)
        } else {
            o.r_inner + (o.r_outer - o.r_inner) * i as f64 / (o.rings - 1) as f64
        };
        let rho = frac * f.r_px;
        for (j, v) in buf.iter_mut().enumerate() {
            let (x, y) = (f.x_px + rho * unit.cos[j], f.y_px - rho * unit.sin[j]);
            if !(x >= 0.0 && y >= 0.0 && x < w - 1.0 && y < h - 1.0) {
                return None;
            }
            *v = bilinear(f.pixels, x, y);
        }
        let spec = fft_real_with(&buf, &unit);
        // Low-pass (harmonics 0..K_LOW) reconstruction: the shading along this ring.
        let low: Vec<f64> = (0..n)
            .map(|j| {
                let mut s = spec[0].0 / n as f64;
                for (k, c) in spec.iter().enumerate().take(K_LOW).skip(1) {
                    let (sn, cs) = (unit.sin[k * j % n], unit.cos[k * j % n]);
                    s += 2.0 / n as f64 * (c.0 * cs - c.1 * sn);
                }
                s
            })
            .collect();
        if low.iter().any(|&l| l <= 1e-9) {
            return None;
        }
        for (v, l) in buf.iter_mut().zip(&low) {
            *v = *v / l - 1.0;
        }
        let spec = fft_real_with(&buf, &unit);
        let k_max = ((TAU * rho / MIN_WAVELENGTH_PX) as usize).min(n / 2 - 1);
        let band: Vec<(f64, f64)> = if k_max > K_LOW {
            spec[K_LOW..=k_max].to_vec()
        } else {
            Vec::new()
        };
        energy += band.iter().map(|c| c.0 * c.0 + c.1 * c.1).sum::<f64>();
        rings.push(band);
    }
    Some(Polar { rings, energy })
}

fn bilinear(p: &GrayPixels, x: f64, y: f64) -> f64 {
    let (x0, y0) = (x.floor() as u32, y.floor() as u32);
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let w = p.width() as usize;
    let g = |x: u32, y: u32| -> f64 {
        let i = y as usize * w + x as usize;
        match p {
            GrayPixels::U8(img) => f64::from(img.as_raw()[i]),
            GrayPixels::U16(img) => f64::from(img.as_raw()[i]) / 257.0,
        }
    };
    let top = g(x0, y0) + fx * (g(x0 + 1, y0) - g(x0, y0));
    let bottom = g(x0, y0 + 1) + fx * (g(x0 + 1, y0 + 1) - g(x0, y0 + 1));
    top + fy * (bottom - top)
}

/// cos and sin of 2πj/n for j in 0..n.
struct UnitCircle {
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl UnitCircle {
    fn new(n: usize) -> UnitCircle {
        let (sin, cos) = (0..n).map(|j| (TAU * j as f64 / n as f64).sin_cos()).unzip();
        UnitCircle { cos, sin }
    }
}

/// The DFT X_k = Σ x_j e^{−2πi jk/N} of a real sequence whose length is a power of two (radix-2).
#[cfg(test)]
fn fft_real(x: &[f64]) -> Vec<(f64, f64)> {
    fft_real_with(x, &UnitCircle::new(x.len()))
}

/// [`fft_real`] with the twiddles taken from `unit` (of the same length).
fn fft_real_with(x: &[f64], unit: &UnitCircle) -> Vec<(f64, f64)> {
    let n = x.len();
    debug_assert_eq!(unit.cos.len(), n);
    assert!(n.is_power_of_two(), "FFT length must be a power of two");
    let bits = n.trailing_zeros();
    let mut a: Vec<(f64, f64)> = vec![(0.0, 0.0); n];
    for (i, &v) in x.iter().enumerate() {
        let j = if bits == 0 {
            0
        } else {
            i.reverse_bits() >> (usize::BITS - bits)
        };
        a[j] = (v, 0.0);
    }
    let mut len = 2;
    while len <= n {
        let stride = n / len;
        for start in (0..n).step_by(len) {
            for m in 0..len / 2 {
                // e^{−2πi m/len} = e^{−2πi (m·stride)/n}.
                let (s, c) = (-unit.sin[m * stride], unit.cos[m * stride]);
                let (u, v) = (a[start + m], a[start + m + len / 2]);
                let t = (v.0 * c - v.1 * s, v.0 * s + v.1 * c);
                a[start + m] = (u.0 + t.0, u.1 + t.1);
                a[start + m + len / 2] = (u.0 - t.0, u.1 - t.1);
            }
        }
        len <<= 1;
    }
    a
}

/// The rotation taking `a`'s texture to `b`'s (b(φ) = a(φ − angle)).
fn correlate(a: &Polar, b: &Polar, n: usize) -> Option<Rotation> {
    // Cross-power spectrum S_k = B_k · conj(A_k), summed over rings: C(α) = Σ_k Re(S_k e^{ikα}).
    let kmax = a.rings.iter().map(Vec::len).max().unwrap_or(0);
    let mut s = vec![(0.0f64, 0.0f64); kmax];
    for (ra, rb) in a.rings.iter().zip(&b.rings) {
        for (i, (ca, cb)) in ra.iter().zip(rb).enumerate() {
            s[i].0 += cb.0 * ca.0 + cb.1 * ca.1;
            s[i].1 += cb.1 * ca.0 - cb.0 * ca.1;
        }
    }
    let norm = (a.energy * b.energy).sqrt();
    if norm.is_nan() || norm <= 0.0 || kmax == 0 {
        return None;
    }
    // C and its derivatives at α.
    let eval = |alpha: f64| {
        let (mut c, mut d1, mut d2) = (0.0, 0.0, 0.0);
        // e^{ikα} by rotation from k = K_LOW (two sin/cos per evaluation instead of one per harmonic).
        let (s1, c1) = alpha.sin_cos();
        let (mut sn, mut cs) = (K_LOW as f64 * alpha).sin_cos();
        for (i, sk) in s.iter().enumerate() {
            let k = (K_LOW + i) as f64;
            if i > 0 {
                (sn, cs) = (sn * c1 + cs * s1, cs * c1 - sn * s1);
            }
            let re = sk.0 * cs - sk.1 * sn;
            let im = sk.0 * sn + sk.1 * cs;
            c += re;
            d1 -= k * im;
            d2 -= k * k * re;
        }
        (c, d1, d2)
    };
    // Coarse: every grid lag (four per sample, so a sharp peak is not missed between lags).
    let lags = 4 * n;
    let (mut best, mut best_c) = (0.0, f64::NEG_INFINITY);
    for j in 0..lags {
        let alpha = TAU * j as f64 / lags as f64;
        let c = eval(alpha).0;
        if c > best_c {
            best_c = c;
            best = alpha;
        }
    }
    // Fine: Newton on C'(α) = 0, kept within a quarter sample of the coarse peak.
    let step = TAU / lags as f64;
    let mut alpha = best;
    for _ in 0..8 {
        let (_, d1, d2) = eval(alpha);
        if d2 >= 0.0 {
            break;
        }
        let next = (alpha - d1 / d2).clamp(best - step, best + step);
        let done = (next - alpha).abs() < 1e-10;
        alpha = next;
        if done {
            break;
        }
    }
    let peak = eval(alpha).0 / norm;
    let angle = (alpha + PI).rem_euclid(TAU) - PI;
    Some(Rotation { angle, peak })
}

/// The rotation of `b`'s texture relative to `a`'s: positive counter-clockwise as seen in the image. `None`
/// when the polar grid leaves either image or the rings resolve no texture.
pub fn rotation_between(a: &SpinImage, b: &SpinImage, o: &SpinOptions) -> Option<Rotation> {
    correlate(&polar(a, o)?, &polar(b, o)?, o.angles)
}

/// Spin of one flight phase from its frames (in time order), rad/s, counter-clockwise as seen in the image,
/// with its standard error from the scatter about the fitted line. An error says why it cannot be measured.
pub fn spin_from_frames(frames: &[SpinImage], o: &SpinOptions) -> Result<Measured, String> {
    if frames.len() < o.min_frames {
        return Err(format!("{} frame(s), {} needed", frames.len(), o.min_frames));
    }
    let polars: Vec<(f64, Polar)> = frames.iter().filter_map(|f| polar(f, o).map(|p| (f.t_s, p))).collect();
    if polars.len() < o.min_frames {
        return Err(format!(
            "the ball's interior is inside the image in {} frame(s), {} needed",
            polars.len(),
            o.min_frames
        ));
    }
    let reference = &polars[polars.len() / 2].1;
    let rotations: Vec<(f64, Option<Rotation>)> = polars
        .iter()
        .map(|(t, p)| (*t, correlate(reference, p, o.angles)))
        .collect();
    let good: Vec<(f64, f64)> = rotations
        .iter()
        .filter_map(|(t, r)| r.filter(|r| r.peak >= o.min_peak).map(|r| (*t, r.angle)))
        .collect();
    if good.len() < o.min_frames {
        let mut peaks: Vec<f64> = rotations.iter().filter_map(|(_, r)| r.map(|r| r.peak)).collect();
        peaks.sort_by(f64::total_cmp);
        let median = peaks.get(peaks.len() / 2).copied().unwrap_or(0.0);
        return Err(format!(
            "no texture contrast to follow: a clear correlation peak in {} of {} frames ({} needed; median peak {median:.2}, {:.2} needed)",
            good.len(),
            rotations.len(),
            o.min_frames,
            o.min_peak
        ));
    }
    // Unwrap over time.
    let mut unwrapped = Vec::with_capacity(good.len());
    let mut prev: Option<f64> = None;
    for &(t, a) in &good {
        let a = match prev {
            None => a,
            Some(p) => p + (a - p + PI).rem_euclid(TAU) - PI,
        };
        unwrapped.push((t, a));
        prev = Some(a);
    }
    let n = unwrapped.len() as f64;
    let tm = unwrapped.iter().map(|p| p.0).sum::<f64>() / n;
    let am = unwrapped.iter().map(|p| p.1).sum::<f64>() / n;
    let stt: f64 = unwrapped.iter().map(|p| (p.0 - tm).powi(2)).sum();
    if stt.is_nan() || stt <= 0.0 || n < 3.0 {
        return Err("the frames span no time".into());
    }
    let omega = unwrapped.iter().map(|p| (p.0 - tm) * (p.1 - am)).sum::<f64>() / stt;
    let ssr: f64 = unwrapped.iter().map(|p| (p.1 - am - omega * (p.0 - tm)).powi(2)).sum();
    let s2 = ssr / (n - 2.0);
    Ok(Measured {
        value: omega,
        se: (s2 / stt).sqrt(),
    })
}

/// Spin before and after the impact of a tracked clip: reads the flight phases' frames (at most
/// `max_frames` per phase, evenly spaced) and follows the texture's rotation. Values are in the local frame
/// of `docs/outputs.md` (counter-clockwise as seen when down-slope is +x).
pub fn measure_spin(clip: &Clip, track: &Track, phases: &PhaseFrames, o: &SpinOptions) -> Spin {
    let position: HashMap<usize, usize> = clip
        .files()
        .iter()
        .enumerate()
        .map(|(k, f)| (f.index as usize, k))
        .collect();
    let sign = if track.downslope_negative_x { -1.0 } else { 1.0 };
    let mut spin = Spin::default();
    for (name, (first, last)) in [("incoming", phases.flight_in), ("outgoing", phases.flight_out)] {
        let fixes: Vec<_> = track
            .fixes
            .iter()
            .filter(|f| f.frame >= first && f.frame <= last && f.status == Status::Ok && f.r_px > 0.0)
            .filter(|f| position.contains_key(&f.frame))
            .collect();
        let stride = fixes.len().div_ceil(o.max_frames.max(1)).max(1);
        let mut loaded = Vec::new();
        let mut error = None;
        for f in fixes.iter().step_by(stride) {
            match clip.read(position[&f.frame], PngDecoder::Image) {
                Some(Ok(frame)) => loaded.push((f.t_s, frame.pixels, f.x_px, f.y_px, f.r_px)),
                Some(Err(e)) => {
                    error = Some(e.to_string());
                    break;
                }
                None => {}
            }
        }
        let result = match error {
            Some(e) => Err(format!("a frame could not be read: {e}")),
            None => {
                let frames: Vec<SpinImage> = loaded
                    .iter()
                    .map(|(t_s, pixels, x_px, y_px, r_px)| SpinImage {
                        t_s: *t_s,
                        pixels,
                        x_px: *x_px,
                        y_px: *y_px,
                        r_px: *r_px,
                    })
                    .collect();
                spin_from_frames(&frames, o)
            }
        };
        let value = match result {
            Ok(m) => Some(Measured {
                value: sign * m.value,
                se: m.se,
            }),
            Err(why) => {
                spin.notes.push(format!("{name} spin not measured: {why}"));
                None
            }
        };
        if name == "incoming" {
            spin.spin_in = value;
        } else {
            spin.spin_out = value;
        }
    }
    spin
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_frames::Gray16Image;

    /// A smooth random texture on the ball (in ball coordinates, y up), with a dark seam-like curve.
    fn texture(u: f64, v: f64) -> f64 {
        let waves = [
            (0.31, 0.17, 0.3, 0.08),
            (-0.22, 0.41, 1.1, 0.06),
            (0.57, -0.33, 2.0, 0.05),
            (0.12, 0.73, 0.4, 0.05),
            (-0.81, -0.29, 2.7, 0.04),
            (1.13, 0.52, 1.7, 0.03),
        ];
        let mut t = 1.0;
        for (kx, ky, ph, amp) in waves {
            t += amp * (kx * u + ky * v + ph).sin();
        }
        // Seam: a dark band along an S-shaped curve.
        let d = v - 12.0 * (u / 15.0).sin() - 3.0;
        t -= 0.3 * (-(d * d) / 4.0).exp();
        t
    }

    /// A disc of radius `r` at (cx, cy) with the texture turned counter-clockwise (as seen) by `alpha`, under a
    /// fixed light from the upper left.
    fn disc(cx: f64, cy: f64, r: f64, alpha: f64, sixteen: bool) -> GrayPixels {
        let (w, h) = (160u32, 140u32);
        let (sa, ca) = alpha.sin_cos();
        let value = |x: u32, y: u32| {
            let (dx, dy) = (x as f64 - cx, -(y as f64 - cy));
            let d2 = dx * dx + dy * dy;
            if d2 > r * r {
                return 80.0;
            }
            // Undo the turn: the ball point now at (dx, dy) was at R(−α)(dx, dy).
            let (u, v) = (ca * dx + sa * dy, -sa * dx + ca * dy);
            let nz = (1.0 - d2 / (r * r)).sqrt();
            let shade = 0.36 + 0.64 * (0.5 * nz - 0.5 * dx / r + 0.4 * dy / r).max(0.0);
            (200.0 * shade * texture(u, v)).clamp(0.0, 255.0)
        };
        let raw: Vec<u16> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                if sixteen {
                    (value(x, y) * 257.0).round() as u16
                } else {
                    value(x, y).round() as u16 * 257
                }
            })
            .collect();
        let p = GrayPixels::U16(Gray16Image::from_raw(w, h, raw).expect("size"));
        if sixteen {
            p
        } else {
            GrayPixels::U8(p.to_u8().into_owned())
        }
    }

    fn frame(p: &GrayPixels, cx: f64, cy: f64, r: f64, t: f64) -> SpinImage<'_> {
        SpinImage {
            t_s: t,
            pixels: p,
            x_px: cx,
            y_px: cy,
            r_px: r,
        }
    }

    #[test]
    fn fft_matches_the_direct_dft() {
        let x: Vec<f64> = (0..16).map(|i| ((i * 7 % 5) as f64).sin() + i as f64 * 0.1).collect();
        let f = fft_real(&x);
        for (k, c) in f.iter().enumerate() {
            let (mut re, mut im) = (0.0, 0.0);
            for (j, v) in x.iter().enumerate() {
                let a = -TAU * (j * k) as f64 / 16.0;
                re += v * a.cos();
                im += v * a.sin();
            }
            assert!((c.0 - re).abs() < 1e-9 && (c.1 - im).abs() < 1e-9, "k {k}");
        }
    }

    #[test]
    fn known_rotations_both_ways_both_depths() {
        let o = SpinOptions::default();
        for sixteen in [false, true] {
            let a = disc(70.0, 66.0, 45.0, 0.3, sixteen);
            for deg in [-25.0, -7.3, -1.0, -0.35, 0.0, 0.35, 1.0, 4.6, 12.0, 40.0] {
                let alpha = 0.3 + f64::to_radians(deg);
                // The second disc also moves by a non-integer offset, as in flight.
                let b = disc(82.3, 61.7, 45.0, alpha, sixteen);
                let r = rotation_between(&frame(&a, 70.0, 66.0, 45.0, 0.0), &frame(&b, 82.3, 61.7, 45.0, 0.0), &o)
                    .expect("measured");
                let err = r.angle.to_degrees() - deg;
                assert!(
                    err.abs() < 0.2,
                    "{deg}° (16-bit {sixteen}): measured {:.3}°",
                    r.angle.to_degrees()
                );
                assert!(r.peak > 0.5, "peak {}", r.peak);
            }
        }
    }

    #[test]
    fn spin_from_a_sequence_has_the_right_sign() {
        let o = SpinOptions::default();
        for omega in [-60.0, 25.0, 0.0] {
            let imgs: Vec<(f64, f64, GrayPixels)> = (0..12)
                .map(|i| {
                    let t = i as f64 * 1e-3;
                    let cx = 60.0 + 3.1 * i as f64;
                    (t, cx, disc(cx, 70.0, 40.0, 1.0 + omega * t, false))
                })
                .collect();
            let frames: Vec<SpinImage> = imgs.iter().map(|(t, cx, p)| frame(p, *cx, 70.0, 40.0, *t)).collect();
            let m = spin_from_frames(&frames, &o).expect("measured");
            assert!(
                (m.value - omega).abs() < 0.5,
                "ω {omega}: measured {} ± {}",
                m.value,
                m.se
            );
        }
    }

    #[test]
    fn a_flat_ball_is_not_measured() {
        let flat = GrayPixels::U16(Gray16Image::from_raw(120, 120, vec![150 * 257; 120 * 120]).expect("size"));
        let flat = GrayPixels::U8(flat.to_u8().into_owned());
        let frames: Vec<SpinImage> = (0..8)
            .map(|i| frame(&flat, 60.0, 60.0, 40.0, i as f64 * 1e-4))
            .collect();
        assert!(spin_from_frames(&frames, &SpinOptions::default()).is_err());
        assert!(spin_from_frames(&frames[..2], &SpinOptions::default()).is_err());
    }
}
