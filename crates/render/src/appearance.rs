//! The static images of a shot with a look ([`crate::Look`]): backdrop, surface band with its ragged edge,
//! lighting, clutter and glare, built once per shot. The per-frame work (the ball, flicker, noise,
//! quantisation) is the same as for every shot (`scene.rs`).
//!
//! The band is the surface seen along its plane: below the contact plane (the surface line in truth) lies
//! the clay or tape, whose top edge is a rough profile about that plane. The texture is normalised over
//! the band's top 16 px, so its mean and standard deviation there are exactly the look's `band_dn` and
//! `texture_dn`, and the edge profile over the visible width has mean zero and RMS exactly the look's
//! roughness: the truth describes the pixels, not the random numbers behind them.

use crate::look::{BallLook, HotSpot, Item, ItemKind, Look, SurfaceLook};
use crate::rng::{Rng, ValueNoise};
use crate::scene::{Layers, Shading, hash01, ramp};
use crate::shot::{Geometry, ShotPlan};
use std::f64::consts::{PI, TAU};

/// Depth of the band's top strip over which its level and texture are normalised, pixels.
const TOP_STRIP_PX: f64 = 16.0;

/// A rough edge: height above a mean line (pixels, up positive) sampled at every pixel along the surface.
#[derive(Debug, Clone)]
pub(crate) struct EdgeProfile {
    s0: f64,
    v: Vec<f64>,
}

impl EdgeProfile {
    /// A profile over s in [s_lo, s_hi] (pixels along the surface) with correlation length `scale` px,
    /// shifted and scaled so that over `span` its mean is 0 and its RMS is `rms`. With `grains` it is the
    /// top of a row of rounded grains (widths around `scale`, random heights) over a slow undulation;
    /// otherwise smooth noise at that scale (a tape's frayed edge).
    pub(crate) fn new(
        rng: &mut Rng,
        s_lo: f64,
        s_hi: f64,
        rms: f64,
        scale: f64,
        span: (f64, f64),
        grains: bool,
    ) -> EdgeProfile {
        let s0 = s_lo.floor() - 1.0;
        let n = ((s_hi.ceil() + 1.0 - s0).max(2.0)) as usize + 1;
        let mut v = vec![0.0f64; n];
        let smooth = |rng: &mut Rng, v: &mut [f64], len: f64, amp: f64| {
            let m = (v.len() as f64 / len).ceil() as usize + 2;
            let knots: Vec<f64> = (0..m).map(|_| rng.range(-1.0, 1.0)).collect();
            for (i, x) in v.iter_mut().enumerate() {
                let t = i as f64 / len;
                let k = t.floor() as usize;
                let f = t - k as f64;
                let sm = f * f * (3.0 - 2.0 * f);
                *x += amp * (knots[k] + (knots[k + 1] - knots[k]) * sm);
            }
        };
        if grains {
            // Grains every ~0.7 scale, each a half-ellipse of half-width 0.5–1 scale; the edge is their
            // upper envelope, so gaps between grains are notches and big grains stand out.
            let mut top = vec![f64::NEG_INFINITY; n];
            let mut c = -scale;
            while c < n as f64 + scale {
                let half = scale * rng.range(0.5, 1.0);
                let height = rng.range(-1.0, 1.0) + 0.8 * rng.uniform().powi(3);
                let (a, b) = (
                    ((c - half).floor().max(0.0)) as usize,
                    ((c + half).ceil().min(n as f64 - 1.0)).max(0.0) as usize,
                );
                for (i, t) in top.iter_mut().enumerate().take(b + 1).skip(a) {
                    let q = (i as f64 - c) / half;
                    if q.abs() < 1.0 {
                        *t = t.max(height + 0.8 * (1.0 - q * q).sqrt());
                    }
                }
                c += scale * rng.range(0.4, 1.0);
            }
            let floor = top
                .iter()
                .copied()
                .filter(|t| t.is_finite())
                .fold(f64::INFINITY, f64::min);
            for (x, t) in v.iter_mut().zip(&top) {
                *x = if t.is_finite() { *t } else { floor };
            }
            smooth(rng, &mut v, 6.0 * scale, 0.4);
        } else {
            for (len, amp) in [(scale, 1.0), ((0.5 * scale).max(1.0), 0.5), (3.0 * scale, 0.7)] {
                smooth(rng, &mut v, len, amp);
            }
        }
        let mut p = EdgeProfile { s0, v };
        let idx: Vec<usize> = (0..p.v.len())
            .filter(|&i| {
                let s = p.s0 + i as f64;
                s >= span.0 && s <= span.1
            })
            .collect();
        if idx.is_empty() {
            p.v.iter_mut().for_each(|x| *x = 0.0);
            return p;
        }
        let mean = idx.iter().map(|&i| p.v[i]).sum::<f64>() / idx.len() as f64;
        let sd = (idx.iter().map(|&i| (p.v[i] - mean).powi(2)).sum::<f64>() / idx.len() as f64).sqrt();
        let k = if sd > 1e-12 { rms / sd } else { 0.0 };
        p.v.iter_mut().for_each(|x| *x = (*x - mean) * k);
        p
    }

    /// Height at s (pixels), linearly interpolated, constant beyond the ends.
    pub(crate) fn at(&self, s: f64) -> f64 {
        let t = (s - self.s0).clamp(0.0, (self.v.len() - 1) as f64);
        let i = (t.floor() as usize).min(self.v.len() - 2);
        let f = t - i as f64;
        self.v[i] + (self.v[i + 1] - self.v[i]) * f
    }

    /// The heights at the integer positions within `span` (for tests).
    #[cfg(test)]
    pub(crate) fn samples(&self, span: (f64, f64)) -> Vec<f64> {
        (0..self.v.len())
            .filter(|&i| {
                let s = self.s0 + i as f64;
                s >= span.0 && s <= span.1
            })
            .map(|i| self.v[i])
            .collect()
    }
}

/// Granular clay: cells of a jittered lattice (one grain each), grain values with bright quartz-like and
/// dark grains, dark gaps between grains, light from the upper left on each grain, low-frequency mottling.
struct Clay {
    seed: u64,
    grain: f64,
    fore: f64,
    mottle: ValueNoise,
}

impl Clay {
    fn raw(&self, s: f64, d: f64) -> f64 {
        let (u, v) = (s / self.grain, d * self.fore / self.grain);
        let (iu, iv) = (u.floor() as i64, v.floor() as i64);
        let (mut f1, mut f2, mut id, mut cen) = (f64::INFINITY, f64::INFINITY, (0i64, 0i64), (0.0, 0.0));
        for di in -1..=1 {
            for dj in -1..=1 {
                let (i, j) = (iu + di, iv + dj);
                let px = i as f64 + hash01(self.seed ^ 0xA1, i, j);
                let py = j as f64 + hash01(self.seed ^ 0xA2, i, j);
                let dd = (u - px) * (u - px) + (v - py) * (v - py);
                if dd < f1 {
                    f2 = f1;
                    f1 = dd;
                    id = (i, j);
                    cen = (px, py);
                } else if dd < f2 {
                    f2 = dd;
                }
            }
        }
        let h = |k: u64| hash01(self.seed ^ k, id.0, id.1);
        let p = h(0xA3);
        let val = if p < 0.1 {
            2.0 + 1.5 * h(0xA4)
        } else if p < 0.2 {
            -1.5 - h(0xA4)
        } else {
            (h(0xA4) + h(0xA5) + h(0xA6) - 1.5) * 2.0
        };
        let gap = ramp(1.0 - (f2.sqrt() - f1.sqrt()) * self.grain / 1.2);
        let lit = 0.6 * (cen.0 - u) + 0.8 * (cen.1 - v);
        val - 1.5 * gap
            + 0.6 * lit
            + 0.8
                * self
                    .mottle
                    .at(s / (5.0 * self.grain), d * self.fore / (5.0 * self.grain)) as f64
            + 0.4 * (hash01(self.seed ^ 0xA7, s.floor() as i64, d.floor() as i64) - 0.5)
    }
}

/// Woven or herringbone tape, supersampled 2 × 2 (a 3-px weave aliases otherwise).
struct Tape {
    seed: u64,
    herringbone: bool,
    period: f64,
    fore: f64,
    zig: f64,
    dirt: ValueNoise,
}

impl Tape {
    fn one(&self, s: f64, d: f64) -> f64 {
        let (u, v) = (s / self.period, d * self.fore / self.period);
        let pattern = if self.herringbone {
            let col = (u / self.zig).floor() as i64;
            let diag = if col.rem_euclid(2) == 0 { u + v } else { u - v };
            (TAU * diag).cos() + 0.25 * ((TAU * 2.2 * v).cos() + (TAU * 2.2 * u).cos())
        } else {
            let (iu, iv) = (u.floor() as i64, v.floor() as i64);
            let (fu, fv) = (u - iu as f64, v - iv as f64);
            let warp_on_top = (iu + iv).rem_euclid(2) == 0;
            let (across, along) = if warp_on_top { (fv, fu) } else { (fu, fv) };
            (PI * across).sin() * (0.75 + 0.35 * (PI * along).sin()) + if warp_on_top { 0.15 } else { -0.15 }
        };
        pattern - 0.8 * (self.dirt.at(s / 25.0, d / 25.0) as f64 - 0.3).max(0.0)
    }

    fn raw(&self, s: f64, d: f64) -> f64 {
        let mut acc = 0.0;
        for (a, b) in [(-0.25, -0.25), (0.25, -0.25), (-0.25, 0.25), (0.25, 0.25)] {
            acc += self.one(s + a, d + b);
        }
        0.25 * acc + 0.3 * (hash01(self.seed ^ 0xB7, s.floor() as i64, d.floor() as i64) - 0.5)
    }
}

/// Mean and standard deviation of `v` over the indices `idx` (0 and 1 when there are none).
fn stats(v: &[f32], idx: &[usize]) -> (f64, f64) {
    if idx.is_empty() {
        return (0.0, 1.0);
    }
    let n = idx.len() as f64;
    let m = idx.iter().map(|&i| v[i] as f64).sum::<f64>() / n;
    let sd = (idx.iter().map(|&i| (v[i] as f64 - m).powi(2)).sum::<f64>() / n).sqrt();
    (m, if sd > 1e-9 { sd } else { 1.0 })
}

/// Which layers a painted object goes into.
#[derive(Clone, Copy, PartialEq)]
enum Layer {
    /// Behind the surface band (the band hides it below the line).
    Back,
    /// In the band's face.
    Band,
    /// In front of both (sits on the line, reaches in from the edge).
    Both,
}

struct Canvas<'a> {
    w: usize,
    h: usize,
    back: &'a mut [f32],
    band: &'a mut [f32],
    vig: &'a [f32],
}

impl Canvas<'_> {
    /// Adds a hot spot's Gaussian glare (under the lighting) to the backdrop and the band alike.
    fn glare(&mut self, hs: &HotSpot) {
        let (wf, hf) = (self.w as f64, self.h as f64);
        let reach = 3.0 * hs.sigma_px;
        let two_s2 = 2.0 * hs.sigma_px * hs.sigma_px;
        let (x0, x1) = (
            (hs.x_px - reach).max(0.0) as usize,
            (hs.x_px + reach).min(wf - 1.0).max(0.0) as usize,
        );
        let (y0, y1) = (
            (hs.y_px - reach).max(0.0) as usize,
            (hs.y_px + reach).min(hf - 1.0).max(0.0) as usize,
        );
        for y in y0..=y1 {
            for x in x0..=x1 {
                let i = y * self.w + x;
                let r2 = (x as f64 - hs.x_px).powi(2) + (y as f64 - hs.y_px).powi(2);
                let add = (hs.peak_dn * (-r2 / two_s2).exp() * self.vig[i] as f64) as f32;
                self.back[i] += add;
                self.band[i] += add;
            }
        }
    }

    /// Paints inside the box centred on (cx, cy) of half-size `reach`: `f(dx, dy)` gives (coverage, DN
    /// before lighting) at an offset from the centre.
    fn paint(&mut self, layer: Layer, cx: f64, cy: f64, reach: f64, f: impl Fn(f64, f64) -> Option<(f64, f64)>) {
        let x0 = (cx - reach - 2.0).floor().max(0.0) as usize;
        let y0 = (cy - reach - 2.0).floor().max(0.0) as usize;
        let x1 = (cx + reach + 2.0).ceil().min(self.w as f64 - 1.0);
        let y1 = (cy + reach + 2.0).ceil().min(self.h as f64 - 1.0);
        if x1 < 0.0 || y1 < 0.0 {
            return;
        }
        for y in y0..=y1 as usize {
            for x in x0..=x1 as usize {
                let Some((cov, val)) = f(x as f64 - cx, y as f64 - cy) else {
                    continue;
                };
                if cov <= 0.0 {
                    continue;
                }
                let i = y * self.w + x;
                let v = (val * self.vig[i] as f64) as f32;
                let c = cov.min(1.0) as f32;
                if layer != Layer::Band {
                    self.back[i] = self.back[i] * (1.0 - c) + v * c;
                }
                if layer != Layer::Back {
                    self.band[i] = self.band[i] * (1.0 - c) + v * c;
                }
            }
        }
    }
}

/// A sphere's shading at (u, v) (unit disc, v up) under `light`: Lambert with ambient and a rim term.
fn sphere(u: f64, v: f64, light: [f64; 3], sh: Shading) -> f64 {
    let nz = (1.0 - (u * u + v * v).min(0.998)).sqrt();
    let lam = (u * light[0] + v * light[1] + nz * light[2]).max(0.0);
    sh.ambient + sh.diffuse * lam + sh.rim * (1.0 - nz) * (1.0 - nz)
}

/// Seven-segment-like strokes of a digit-like mark (segments a–g) chosen by `code`, at (u, v) in a cell of
/// 1 × 2 units.
fn glyph(code: u64, u: f64, v: f64) -> bool {
    const SEG: [(f64, f64, f64, f64); 7] = [
        (0.0, 0.0, 1.0, 0.0),
        (1.0, 0.0, 1.0, 1.0),
        (1.0, 1.0, 1.0, 2.0),
        (0.0, 2.0, 1.0, 2.0),
        (0.0, 1.0, 0.0, 2.0),
        (0.0, 0.0, 0.0, 1.0),
        (0.0, 1.0, 1.0, 1.0),
    ];
    SEG.iter().enumerate().any(|(k, &(ax, ay, bx, by))| {
        (code >> k) & 1 == 1 && {
            let (dx, dy) = (bx - ax, by - ay);
            let t = (((u - ax) * dx + (v - ay) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
            (u - ax - t * dx).hypot(v - ay - t * dy) < 0.2
        }
    })
}

/// Paints one clutter item into the layers.
fn paint_item(c: &mut Canvas, it: &Item, g: Geometry, look: &Look, light: [f64; 3], shading: Shading) {
    match it.kind {
        ItemKind::Screw => paint_screw(c, it, g, light),
        ItemKind::Fixture => paint_fixture(c, it),
        ItemKind::Ruler => paint_ruler(c, it),
        ItemKind::RestingBall => paint_resting_ball(c, it, look.ball_dn, light, shading),
        ItemKind::Ring => paint_ring(c, it),
        ItemKind::Lamp => paint_lamp(c, it),
        ItemKind::Hand => paint_hand(c, it),
    }
}

/// Coverage of a pixel whose centre lies `d` px inside an edge (a 1-px ramp).
fn edge(d: f64) -> f64 {
    ramp(d + 0.5)
}

/// A screw head, bright (slotted, domed) or dark (a socket head), in the band, the backdrop or both as it
/// sits below, above or on the line.
fn paint_screw(c: &mut Canvas, it: &Item, g: Geometry, light: [f64; 3]) {
    let (cx, cy, r) = (it.x_px, it.y_px, it.r_px);
    // The surface line (the contact plane) at the screw's column.
    let ly = g.ty + g.sin * (cx - g.tx) / (g.dir * g.cos);
    let layer = if cy - r > ly {
        Layer::Band
    } else if cy + r < ly {
        Layer::Back
    } else {
        Layer::Both
    };
    let (ss, sc) = it.angle_rad.sin_cos();
    c.paint(layer, cx, cy, r, |dx, dy| {
        let q = dx.hypot(dy);
        let (u, v) = (dx / r, -dy / r);
        let across = (-ss * dx + sc * dy).abs();
        let val = if it.bright {
            let mut val = 60.0 + 130.0 * sphere(u, v, light, Shading::LAMBERT);
            val *= 1.0 - 0.65 * ramp(0.2 * r + 0.5 - across);
            val * (1.0 - 0.35 * ramp(q / r * 8.0 - 7.0))
        } else {
            // A dark socket head: a bright chamfer around a dark hexagonal recess.
            let hex = (0..3)
                .map(|k| {
                    let a = it.angle_rad + k as f64 * PI / 3.0;
                    (dx * a.cos() + dy * a.sin()).abs()
                })
                .fold(0.0f64, f64::max);
            let chamfer = ramp((q - 0.8 * r) * 2.0);
            25.0 + 90.0 * chamfer - 12.0 * ramp(0.45 * r - hex + 0.5)
        };
        Some((edge(r - q), val))
    });
}

/// A dark anodised round fixture with a bright bevel, rings and a bore.
fn paint_fixture(c: &mut Canvas, it: &Item) {
    let (cx, cy, r) = (it.x_px, it.y_px, it.r_px);
    let (bevel, gap) = (it.width_px.max(1.0), it.spacing_px.max(2.0));
    c.paint(Layer::Back, cx, cy, r, |dx, dy| {
        let q = dx.hypot(dy);
        let body = 46.0 - 10.0 * dy / r;
        let rim = ramp(q - (r - bevel) + 0.5);
        let mut ring = 0.0f64;
        let mut rr = 0.62 * r;
        while rr > 0.3 * r {
            ring = ring.max(ramp(1.2 - (q - rr).abs()));
            rr -= gap;
        }
        let bore = ramp(0.25 * r - q + 0.5);
        Some((edge(r - q), body + rim * (150.0 - body) + 45.0 * ring - 20.0 * bore))
    });
}

/// A ruler: a bright or dark strip with ticks (longer every 5 and 10) and digit-like marks.
fn paint_ruler(c: &mut Canvas, it: &Item) {
    let (cx, cy) = (it.x_px, it.y_px);
    let (sa, ca) = it.angle_rad.sin_cos();
    let (half, width, tick) = (it.r_px, it.width_px, it.spacing_px.max(2.0));
    let (body, ink) = if it.bright { (215.0, 35.0) } else { (40.0, 200.0) };
    let seed = (cx.to_bits() ^ cy.to_bits()).rotate_left(17);
    c.paint(Layer::Back, cx, cy, half + width, |dx, dy| {
        let along = dx * ca - dy * sa + half;
        let across = dx * sa + dy * ca + 0.5 * width;
        let cov = edge(along.min(2.0 * half - along)) * edge(across.min(width - across));
        if cov <= 0.0 {
            return None;
        }
        let k = (along / tick).round();
        let off = (along - k * tick).abs();
        let len = if k as i64 % 10 == 0 {
            0.6
        } else if k as i64 % 5 == 0 {
            0.4
        } else {
            0.25
        } * width;
        let line_w = (0.12 * tick).max(0.6);
        let mut ink_cov = ramp(line_w - off + 0.5) * ramp(len - across + 0.5);
        // Digit-like marks beside every tenth tick.
        let k10 = (along / (10.0 * tick)).floor();
        let (gu, gv) = (
            (along - k10 * 10.0 * tick - 0.15 * width) / (0.18 * width),
            (across - 0.62 * width) / (0.15 * width),
        );
        let code = crate::rng::mix(seed ^ k10.to_bits()) | 1;
        if (0.0..=1.0).contains(&gu) && (0.0..=2.0).contains(&gv) && glyph(code, gu, gv) {
            ink_cov = 1.0;
        }
        Some((cov, body + (ink - body) * ink_cov))
    });
}

/// A ball at rest, shaded like the moving ball (a backlit look gives a dark silhouette), without its seam.
fn paint_resting_ball(c: &mut Canvas, it: &Item, ball_dn: f64, light: [f64; 3], shading: Shading) {
    let (cx, cy, r) = (it.x_px, it.y_px, it.r_px);
    // Shaded like the moving ball (a backlit look gives a dark silhouette), without its seam.
    let seed = cx.to_bits() ^ 0x5EED;
    c.paint(Layer::Back, cx, cy, r, |dx, dy| {
        let q = dx.hypot(dy);
        let fuzz = 1.0 + 0.07 * (hash01(seed, dx.floor() as i64, dy.floor() as i64) - 0.5);
        let val = ball_dn * sphere(dx / r, -dy / r, light, shading) * fuzz;
        Some((ramp((r - q) / 1.3 + 0.5), val))
    });
}

/// A thin ring, bright or dark, lit from above.
fn paint_ring(c: &mut Canvas, it: &Item) {
    let (cx, cy, r) = (it.x_px, it.y_px, it.r_px);
    let t = it.width_px.max(1.5);
    let val = if it.bright { 205.0 } else { 30.0 };
    c.paint(Layer::Back, cx, cy, r, |dx, dy| {
        let q = dx.hypot(dy);
        let cov = edge(r - q) * edge(q - (r - t));
        Some((cov, val * (1.0 - 0.15 * dy / r)))
    });
}

/// A lamp: a bright disc with a glow that fades over a quarter of its radius.
fn paint_lamp(c: &mut Canvas, it: &Item) {
    let (cx, cy, r) = (it.x_px, it.y_px, it.r_px);
    // A bright disc with a glow that fades over a quarter of its radius.
    c.paint(Layer::Back, cx, cy, 1.6 * r, |dx, dy| {
        let q = dx.hypot(dy);
        let glow = (-(q - r).max(0.0) / (0.25 * r)).exp();
        Some((edge(r - q).max(0.6 * glow), 245.0))
    });
}

/// A dark hand-like blob reaching in from a frame edge: a palm, four fingers and a thumb.
fn paint_hand(c: &mut Canvas, it: &Item) {
    let (cx, cy, r) = (it.x_px, it.y_px, it.r_px);
    let size = r / 1.3;
    let fw = it.width_px.max(2.0);
    let (sa, ca) = it.angle_rad.sin_cos();
    let level = 30.0;
    c.paint(Layer::Both, cx, cy, r, |dx, dy| {
        // Along the fingers (into the frame) and across them, y up.
        let along = dx * ca - dy * sa;
        let across = dx * sa + dy * ca;
        let palm = 1.0 - ((along / (0.55 * size)).powi(2) + (across / (0.45 * size)).powi(2)).sqrt();
        let mut d = palm * 0.45 * size;
        for k in 0..4 {
            let off = (k as f64 - 1.5) * 0.24 * size;
            let len = size * [0.7, 0.8, 0.78, 0.62][k];
            let t = ((along - 0.35 * size) / len).clamp(0.0, 1.0) * len + 0.35 * size;
            d = d.max(0.5 * fw - (along - t).hypot(across - off));
        }
        let thumb_t = (along / (0.5 * size)).clamp(0.0, 1.0) * 0.5 * size;
        d = d.max(0.6 * fw - (along - thumb_t).hypot(across + 0.45 * size + 0.3 * along));
        let cov = ramp(d / 2.0 + 0.5);
        Some((cov, level + 8.0 * (along / size).clamp(-1.0, 1.0)))
    });
}

/// Builds the static layers of a shot with a look.
pub(crate) fn build(plan: &ShotPlan, look: &Look) -> Layers {
    let cam = &plan.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let g = plan.geom;
    let mut rng = Rng::new(look.draft.seed);
    let vig = illumination(look, w, h);
    let mut back = backdrop(look, g, w, h, &mut rng);
    let surface = Band::draw(look, g, w, h, &mut rng);
    let (mut band, front) = surface.shade(look, g, &surface.cover(g, w, h), w, h);
    for i in 0..w * h {
        back[i] *= vig[i];
        band[i] *= vig[i];
    }
    let (light, shading) = ball_light(look);

    // Clutter, then glare on top.
    let mut canvas = Canvas {
        w,
        h,
        back: &mut back,
        band: &mut band,
        vig: &vig,
    };
    for it in &look.items {
        paint_item(&mut canvas, it, g, look, light, shading);
    }
    for hs in &look.hot_spots {
        canvas.glare(hs);
    }
    Layers {
        back,
        band,
        front,
        vig,
        light,
        shading,
    }
}

/// Illumination: vignetting × a linear gradient, applied to every light in the scene.
fn illumination(look: &Look, w: usize, h: usize) -> Vec<f32> {
    let (wf, hf) = (w as f64, h as f64);
    let (cx, cy) = ((wf - 1.0) / 2.0, (hf - 1.0) / 2.0);
    let rmax2 = cx * cx + cy * cy;
    let rmax = rmax2.sqrt();
    let (gs, gc) = look.gradient_dir_deg.to_radians().sin_cos();
    let mut vig = vec![0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let (dx, dy) = (x as f64 - cx, y as f64 - cy);
            let v = 1.0 - look.vignetting * (dx * dx + dy * dy) / rmax2;
            let u = (dx * gc - dy * gs) / rmax;
            vig[y * w + x] = (v * (1.0 + look.gradient * u)) as f32;
        }
    }
    vig
}

/// Backdrop before lighting: the level just above the line, a ramp toward the top, blotches and a fine grain.
fn backdrop(look: &Look, g: Geometry, w: usize, h: usize, rng: &mut Rng) -> Vec<f32> {
    let d = &look.draft;
    let hf = h as f64;
    let blotch = ValueNoise::new(rng, 16);
    let fine = ValueNoise::new(rng, 64);
    let line_y = |x: f64| g.ty + g.sin * (x - g.tx) / (g.dir * g.cos);
    let mut back = vec![0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let (xf, yf) = (x as f64, y as f64);
            let v = look.backdrop_dn
                + d.backdrop_ramp_dn * (line_y(xf) - yf) / hf
                + d.blotch_dn * blotch.at(xf / 60.0, yf / 60.0) as f64
                + d.backdrop_grain_dn * fine.at(xf / 1.7, yf / 1.7) as f64;
            back[y * w + x] = v as f32;
        }
    }
    back
}

/// The surface band of a shot: the edge profiles and textures of its clay and tape (each absent when the
/// look has none) and where the tape lies.
struct Band {
    clay_edge: Option<EdgeProfile>,
    tape_edge: Option<EdgeProfile>,
    clay: Option<Clay>,
    tape: Option<Tape>,
    /// The surface line's extent in the frame, pixels along the surface.
    visible: (f64, f64),
    /// How far the tape stands above the clay's mean edge, pixels.
    thick: f64,
    /// Depth the tape reaches below the line, pixels (infinite when the band is all tape).
    tape_depth: f64,
    /// The tape's ends along the surface, pixels (infinite when the band is all tape).
    tape_s: (f64, f64),
}

/// Per pixel, for clay (`_c`) and tape (`_t`): coverage (0–1), depth below the layer's own edge (px) and
/// raw texture; and the pixels of each layer's top strip, over which its texture is normalised.
struct Coverage {
    cov_c: Vec<f32>,
    dep_c: Vec<f32>,
    tex_c: Vec<f32>,
    cov_t: Vec<f32>,
    dep_t: Vec<f32>,
    tex_t: Vec<f32>,
    top_c: Vec<usize>,
    top_t: Vec<usize>,
}

impl Band {
    /// Draws the edge profiles over the visible width, then the clay's and the tape's textures.
    fn draw(look: &Look, g: Geometry, w: usize, h: usize, rng: &mut Rng) -> Band {
        let d = &look.draft;
        let (wf, hf) = (w as f64, h as f64);
        let line_y = |x: f64| g.ty + g.sin * (x - g.tx) / (g.dir * g.cos);
        let corners = [(0.0, 0.0), (wf - 1.0, 0.0), (0.0, hf - 1.0), (wf - 1.0, hf - 1.0)];
        let (s_lo, s_hi) = corners
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &(x, y)| {
                let s = g.to_local_px(x, y).0;
                (a.min(s), b.max(s))
            });
        let visible = {
            let (a, b) = (
                g.to_local_px(0.0, line_y(0.0)).0,
                g.to_local_px(wf - 1.0, line_y(wf - 1.0)).0,
            );
            (a.min(b), a.max(b))
        };
        let clay_edge = look.edge_roughness_px.map(|rms| {
            let scale = look.edge_scale_px.unwrap_or(4.0);
            EdgeProfile::new(rng, s_lo, s_hi, rms, scale, visible, true)
        });
        let tape_on_clay = look.surface == SurfaceLook::TapeOnClay;
        let tape_span = if tape_on_clay {
            (d.tape_s.0.max(visible.0), d.tape_s.1.min(visible.1))
        } else {
            visible
        };
        let tape_edge = look.tape_edge_roughness_px.map(|rms| {
            let span = if tape_span.0 < tape_span.1 { tape_span } else { visible };
            EdgeProfile::new(rng, s_lo, s_hi, rms, d.tape_edge_scale_px, span, false)
        });
        let clay = look.grain_px.map(|grain| Clay {
            seed: rng.next_u64(),
            grain,
            fore: d.foreshortening,
            mottle: ValueNoise::new(rng, 32),
        });
        let tape = look.weave_period_px.map(|period| Tape {
            seed: rng.next_u64(),
            herringbone: look.weave == Some("herringbone"),
            period,
            fore: d.foreshortening,
            zig: d.zig_periods,
            dirt: ValueNoise::new(rng, 32),
        });
        Band {
            clay_edge,
            tape_edge,
            clay,
            tape,
            visible,
            thick: look.tape_thickness_px.unwrap_or(0.0),
            tape_depth: if tape_on_clay {
                d.tape_depth_frac * (hf - g.ty)
            } else {
                f64::INFINITY
            },
            tape_s: if tape_on_clay {
                d.tape_s
            } else {
                (f64::NEG_INFINITY, f64::INFINITY)
            },
        }
    }

    /// Where the clay and the tape cover each pixel, how deep below their edges, and their raw textures.
    fn cover(&self, g: Geometry, w: usize, h: usize) -> Coverage {
        let n = w * h;
        let (ts0, ts1) = self.tape_s;
        let visible = self.visible;
        let mut c = Coverage {
            cov_c: vec![0f32; n],
            dep_c: vec![0f32; n],
            tex_c: vec![0f32; n],
            cov_t: vec![0f32; n],
            dep_t: vec![0f32; n],
            tex_t: vec![0f32; n],
            top_c: Vec::new(),
            top_t: Vec::new(),
        };
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let (s, up) = g.to_local_px(x as f64, y as f64);
                let depth = -up;
                if let (Some(cl), Some(e)) = (&self.clay, &self.clay_edge) {
                    let dl = depth - self.thick + e.at(s);
                    let cv = ramp(dl + 0.5);
                    if cv > 0.0 {
                        c.cov_c[i] = cv as f32;
                        c.dep_c[i] = dl.max(0.0) as f32;
                        c.tex_c[i] = cl.raw(s, depth.max(0.0)) as f32;
                        if cv >= 0.99 && dl < TOP_STRIP_PX && s >= visible.0 && s <= visible.1 {
                            c.top_c.push(i);
                        }
                    }
                }
                if let (Some(tp), Some(e)) = (&self.tape, &self.tape_edge) {
                    let dl = depth + e.at(s);
                    let side = ramp(s - ts0 + 0.5) * ramp(ts1 - s + 0.5) * ramp(self.tape_depth - depth + 0.5);
                    let cv = ramp(dl + 0.5) * side;
                    if cv > 0.0 {
                        c.cov_t[i] = cv as f32;
                        c.dep_t[i] = dl.max(0.0) as f32;
                        c.tex_t[i] = tp.raw(s, depth.max(0.0)) as f32;
                        if cv >= 0.99 && dl < TOP_STRIP_PX {
                            c.top_t.push(i);
                        }
                    }
                }
            }
        }
        c
    }

    /// The band's radiance before lighting (tape over clay, each texture normalised over its top strip to
    /// the look's level and contrast, fading with depth, with its lip) and its coverage, per pixel.
    fn shade(&self, look: &Look, g: Geometry, c: &Coverage, w: usize, h: usize) -> (Vec<f32>, Vec<f32>) {
        let d = &look.draft;
        let n = w * h;
        let (mc, sc) = stats(&c.tex_c, &c.top_c);
        let (mt, st) = stats(&c.tex_t, &c.top_t);
        let clay_level = look.clay_dn.unwrap_or(look.band_dn);
        let depth_scale = 0.3 * h as f64;
        let mut band = vec![0f32; n];
        let mut front = vec![0f32; n];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let (ct, cc) = (c.cov_t[i] as f64, c.cov_c[i] as f64);
                let f = ct + (1.0 - ct) * cc;
                if f <= 0.0 {
                    continue;
                }
                let depth = -g.to_local_px(x as f64, y as f64).1;
                let fade = d.fade_dn * (depth.max(0.0) / depth_scale).min(1.0);
                let lip = |dl: f32| look.lip_dn * ramp(1.0 - dl as f64 / d.lip_px);
                let vc = clay_level + look.texture_dn * (c.tex_c[i] as f64 - mc) / sc - fade + lip(c.dep_c[i]);
                let vt = look.band_dn + look.texture_dn * (c.tex_t[i] as f64 - mt) / st - fade + lip(c.dep_t[i]);
                front[i] = f as f32;
                band[i] = ((ct * vt + (1.0 - ct) * cc * vc) / f) as f32;
            }
        }
        (band, front)
    }
}

/// The moving ball's light direction and shading: a backlit ball is a silhouette with a rim, a felt ball is
/// lit from the look's azimuth and elevation.
fn ball_light(look: &Look) -> ([f64; 3], Shading) {
    let d = &look.draft;
    if look.ball == BallLook::Backlit {
        (
            [0.0, 0.0, 1.0],
            Shading {
                ambient: 1.0,
                diffuse: 0.0,
                rim: d.rim,
            },
        )
    } else {
        let (az, el) = (
            look.light_azimuth_deg.to_radians(),
            look.light_elevation_deg.to_radians(),
        );
        (
            [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()],
            Shading {
                ambient: d.ambient,
                diffuse: 1.0 - d.ambient,
                rim: d.rim,
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::{any, prop_assert, proptest};

    proptest! {
        /// The edge profile's mean over its span is zero and its RMS the one asked for: the contact plane is
        /// the mean of the ragged edge.
        #[test]
        fn edge_profile_has_zero_mean_and_the_rms_asked_for(
            seed in any::<u64>(), rms in 0.0f64..8.0, scale in 1.0f64..20.0, lo in -300.0f64..0.0,
            len in 20.0f64..600.0, grains in any::<bool>()
        ) {
            let mut rng = Rng::new(seed);
            let span = (lo, lo + len);
            let p = EdgeProfile::new(&mut rng, lo - 50.0, lo + len + 50.0, rms, scale, span, grains);
            let v = p.samples(span);
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
            prop_assert!(mean.abs() < 1e-9 * (1.0 + rms));
            prop_assert!((sd - rms).abs() < 1e-9 * (1.0 + rms));
        }
    }

    #[test]
    fn glyph_draws_only_its_segments() {
        // Segment a (top bar) alone: ink on the top bar, none in the lower half.
        assert!(glyph(1, 0.5, 0.0));
        assert!(!glyph(1, 0.5, 2.0));
        assert!(glyph(0b111_1111, 0.5, 1.0));
    }
}
