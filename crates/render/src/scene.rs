//! The images: a static background per shot (backdrop, surface band, distractors, vignetting) and, per
//! frame, the shaded ball composited over it inside its bounding box, then flicker, noise and quantisation.

use crate::rng::{Rng, ValueNoise, derive, gauss_table, mix};
use crate::shot::ShotPlan;
use crate::{Texture, shot::Geometry};
use std::f64::consts::TAU;

/// A rendered frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RenderedFrame {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Gray levels, row-major.
    pub pixels: Pixels,
}

/// Gray levels of a frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Pixels {
    /// 8-bit (0–255).
    Gray8(Vec<u8>),
    /// 16-bit: the 8-bit scale × 257 (0–65535), or for 12-bit data the 12-bit value × 16 (low 4 bits zero).
    Gray16(Vec<u16>),
}

impl RenderedFrame {
    /// The gray level at (x, y) on the 8-bit scale (16-bit frames divided by 257; 12-bit data in 16-bit
    /// frames comes out within 0.4 % of it).
    pub fn get(&self, x: u32, y: u32) -> f64 {
        let i = (y * self.width + x) as usize;
        match &self.pixels {
            Pixels::Gray8(v) => v[i] as f64,
            Pixels::Gray16(v) => v[i] as f64 / 257.0,
        }
    }
}

/// Width of the ball's soft edge (the felt's fuzz and the lens), pixels.
const EDGE_W: f64 = 1.3;
/// Entries of the fuzz table over the ball's circumference.
const FUZZ_N: usize = 1024;
/// Light direction (x right, y up, z toward the camera), normalised below.
const LIGHT: [f64; 3] = [-0.35, 0.55, 0.76];
/// Ambient, diffuse and felt-rim parts of the ball's shading.
const AMBIENT: f64 = 0.36;
const DIFFUSE: f64 = 0.64;
const RIM: f64 = 0.28;
/// Brightest albedo of the felt, DN.
const BALL_ALBEDO: f64 = 228.0;

/// How a sphere is shaded: `ambient + diffuse·max(n·l, 0) + rim·(1 − n_z)²`, times its albedo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Shading {
    /// Light reaching every point.
    pub ambient: f64,
    /// Lambertian share.
    pub diffuse: f64,
    /// Brightening toward the silhouette (felt fibres catching the light, backlight wrapping round).
    pub rim: f64,
}

impl Shading {
    /// The felt ball of scenarios without a look.
    const CLASSIC: Shading = Shading {
        ambient: AMBIENT,
        diffuse: DIFFUSE,
        rim: RIM,
    };
    /// Pure Lambert (metal domes).
    pub(crate) const LAMBERT: Shading = Shading {
        ambient: 0.0,
        diffuse: 1.0,
        rim: 0.0,
    };
}

/// The static layers of a shot: backdrop and band radiance (DN, lighting applied), the band's coverage
/// (0–1, in front of the ball), the illumination map (vignetting and gradient) and the ball's light and
/// shading.
pub(crate) struct Layers {
    pub back: Vec<f32>,
    pub band: Vec<f32>,
    pub front: Vec<f32>,
    pub vig: Vec<f32>,
    pub light: [f64; 3],
    pub shading: Shading,
}

/// The pixels a frame's ball can touch: the radii (squared, px²) within which it covers a pixel wholly and
/// beyond which not at all, and the bounding box [x0, x1) × [y0, y1) of its blurred disc, pixels.
struct BallWindow {
    r_in2: f64,
    r_out2: f64,
    x0: usize,
    x1: usize,
    y0: usize,
    y1: usize,
}

/// Makes the frames of one shot.
#[derive(Debug)]
pub struct ShotRenderer<'a> {
    plan: &'a ShotPlan,
    w: usize,
    h: usize,
    back: Vec<f32>,
    band: Vec<f32>,
    front: Vec<f32>,
    stat: Vec<f32>,
    vig: Vec<f32>,
    albedo: Vec<f32>,
    amap: usize,
    acen: f64,
    fuzz: Vec<f32>,
    fuzz_max: f64,
    sigma: Vec<f32>,
    /// The sensor's fixed pattern (column and row offsets, hot pixels), DN, added after the light.
    fpn: Vec<f32>,
    light: [f64; 3],
    shading: Shading,
}

/// A uniform value in [0, 1) from a seed and two lattice indices.
pub(crate) fn hash01(seed: u64, i: i64, j: i64) -> f64 {
    let h = mix(seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F));
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// x clamped to [0, 1].
pub(crate) fn ramp(x: f64) -> f64 {
    x.clamp(0.0, 1.0)
}

struct SurfaceTex {
    seed: u64,
    kind: Texture,
    n1: ValueNoise,
    n2: ValueNoise,
    n3: ValueNoise,
    depth_scale: f64,
}

impl SurfaceTex {
    fn value(&self, s: f64, d: f64) -> f64 {
        let fade = (d / self.depth_scale).min(1.0);
        let white = hash01(self.seed, s.floor() as i64, d.floor() as i64) - 0.5;
        match self.kind {
            Texture::Clay => {
                let mut v = 90.0 - 20.0 * fade;
                v += 11.0 * self.n1.at(s / 7.0, d / 7.0) as f64 + 6.0 * self.n2.at(s / 2.3, d / 2.3) as f64;
                v += 9.0 * white;
                // Grains on a 4-px lattice: bright quartz-like grains and dark pits, 0.8–2 px in radius.
                let (ci, cj) = ((s / 4.0).floor() as i64, (d / 4.0).floor() as i64);
                let (mut up, mut down) = (0.0f64, 0.0f64);
                for di in -1..=1 {
                    for dj in -1..=1 {
                        let (i, j) = (ci + di, cj + dj);
                        let p = hash01(self.seed ^ 0x51, i, j);
                        if p > 0.5 {
                            continue;
                        }
                        let gx = (i as f64 + hash01(self.seed ^ 0x52, i, j)) * 4.0;
                        let gy = (j as f64 + hash01(self.seed ^ 0x53, i, j)) * 4.0;
                        let rad = 0.8 + 1.2 * hash01(self.seed ^ 0x54, i, j);
                        let dist = ((s - gx).powi(2) + (d - gy).powi(2)).sqrt();
                        let c = ramp(1.0 - dist / rad).sqrt();
                        if p < 0.3 {
                            up = up.max(c * (18.0 + 42.0 * hash01(self.seed ^ 0x55, i, j)));
                        } else {
                            down = down.max(c * 24.0);
                        }
                    }
                }
                v += up - down;
                // The top edge catches the light.
                v + 12.0 * ramp(1.0 - d / 2.5)
            }
            Texture::WhiteTape | Texture::GreenTape => {
                let white_tape = self.kind == Texture::WhiteTape;
                let (base, period, zig, amp) = if white_tape {
                    (198.0, 5.0, 15.0, 14.0)
                } else {
                    (118.0, 6.0, 18.0, 11.0)
                };
                let v_ = d * 1.7; // foreshortened: the camera looks along the surface
                let col = (s / zig).floor() as i64;
                let diag = if col.rem_euclid(2) == 0 { s + v_ } else { s - v_ };
                let twill = (TAU * diag / period).cos();
                let thread = 0.5 * (TAU * v_ / 2.2).cos() + 0.5 * (TAU * s / 2.2).cos();
                let dirt = (self.n3.at(s / 25.0, d / 25.0) as f64 - 0.3).max(0.0);
                base - (if white_tape { 14.0 } else { 10.0 }) * fade
                    + amp * twill
                    + 3.5 * thread
                    + 5.0 * self.n2.at(s / 5.0, v_ / 5.0) as f64
                    + 8.0 * white
                    - 14.0 * dirt
                    + 6.0 * ramp(1.0 - d / 2.0)
            }
        }
    }

    fn roughness(&self, s: f64) -> f64 {
        match self.kind {
            Texture::Clay => 0.7 * self.n2.at(s / 3.0, 7.5) as f64 + 0.3 * self.n1.at(s / 11.0, 3.5) as f64,
            _ => 0.15 * self.n2.at(s / 9.0, 7.5) as f64,
        }
    }
}

/// The sensor's fixed pattern for a session: per-column and per-row offsets and hot pixels, DN.
fn fixed_pattern(cam: &crate::Camera, session_seed: u64) -> Vec<f32> {
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut rng = Rng::new(derive(session_seed, 0xF1C5_ED00));
    let cols: Vec<f64> = (0..w).map(|_| cam.fixed_pattern_noise * rng.normal()).collect();
    let rows: Vec<f64> = (0..h).map(|_| 0.5 * cam.fixed_pattern_noise * rng.normal()).collect();
    let mut out = vec![0f32; w * h];
    for (y, r) in rows.iter().enumerate() {
        for (x, c) in cols.iter().enumerate() {
            out[y * w + x] = (r + c) as f32;
        }
    }
    let hot = (cam.hot_pixel_fraction * (w * h) as f64).round() as usize;
    for _ in 0..hot {
        let i = (rng.uniform() * (w * h) as f64) as usize % (w * h);
        out[i] += rng.range(20.0, 80.0) as f32;
    }
    out
}

impl ShotPlan {
    /// Builds the shot's static images (background, ball texture); then [`ShotRenderer::frame`] makes any
    /// frame.
    pub fn renderer(&self) -> ShotRenderer<'_> {
        ShotRenderer::new(self)
    }
}

impl<'a> ShotRenderer<'a> {
    fn new(plan: &'a ShotPlan) -> ShotRenderer<'a> {
        let cam = &plan.camera;
        let (w, h) = (cam.width as usize, cam.height as usize);
        let g: Geometry = plan.geom;
        let seed = derive(plan.truth.seed, 0xB4C6);
        let mut rng = Rng::new(seed);
        if let Some(look) = &plan.look {
            return ShotRenderer::with_look(plan, look, rng);
        }
        let tex = SurfaceTex {
            seed: rng.next_u64(),
            kind: plan.texture,
            n1: ValueNoise::new(&mut rng, 64),
            n2: ValueNoise::new(&mut rng, 64),
            n3: ValueNoise::new(&mut rng, 32),
            depth_scale: 0.3 * h as f64,
        };
        let bn1 = ValueNoise::new(&mut rng, 16);
        let bn2 = ValueNoise::new(&mut rng, 32);
        let side = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        let (cx, cy) = ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0);
        let rmax2 = cx * cx + cy * cy;
        let n = w * h;
        let (mut back, mut band, mut front, mut vig) = (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let (xf, yf) = (x as f64, y as f64);
                let v = 1.0 - cam.vignetting * ((xf - cx).powi(2) + (yf - cy).powi(2)) / rmax2;
                vig[i] = v as f32;
                let bd = 66.0
                    + 40.0 * (1.0 - yf / h as f64)
                    + 10.0 * side * (xf / w as f64 - 0.5)
                    + 5.0 * bn1.at(xf / 60.0, yf / 60.0) as f64
                    + 1.5 * bn2.at(xf / 12.0, yf / 12.0) as f64;
                back[i] = (bd * v) as f32;
                let (s, up) = g.to_local_px(xf, yf);
                let depth = -up;
                let cover = ramp(depth + tex.roughness(s) + 0.5);
                front[i] = cover as f32;
                if cover > 0.0 {
                    band[i] = (tex.value(s, depth.max(0.0)) * v) as f32;
                }
            }
        }
        let light = {
            let l = LIGHT;
            let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
            [l[0] / n, l[1] / n, l[2] / n]
        };
        let mut r = ShotRenderer::assemble(
            plan,
            Layers {
                back,
                band,
                front,
                vig,
                light,
                shading: Shading::CLASSIC,
            },
        );
        r.distractors(&mut rng);
        r.finish(&mut rng, BALL_ALBEDO, true);
        r
    }

    /// The static images of a shot with a look (`appearance.rs`).
    fn with_look(plan: &'a ShotPlan, look: &crate::Look, mut rng: Rng) -> ShotRenderer<'a> {
        let mut r = ShotRenderer::assemble(plan, crate::appearance::build(plan, look));
        r.finish(&mut rng, look.ball_dn, look.ball == crate::BallLook::FeltSeam);
        r
    }

    /// A renderer over the static layers, with the session's fixed pattern; the ball's texture and the
    /// noise table come from [`ShotRenderer::finish`].
    fn assemble(plan: &'a ShotPlan, l: Layers) -> ShotRenderer<'a> {
        let cam = &plan.camera;
        ShotRenderer {
            plan,
            w: cam.width as usize,
            h: cam.height as usize,
            back: l.back,
            band: l.band,
            front: l.front,
            stat: Vec::new(),
            vig: l.vig,
            albedo: Vec::new(),
            amap: 0,
            acen: 0.0,
            fuzz: Vec::new(),
            fuzz_max: 0.0,
            sigma: Vec::new(),
            fpn: fixed_pattern(cam, plan.session_seed),
            light: l.light,
            shading: l.shading,
        }
    }

    /// The least-squares line through the band's top edge as drawn: per column, the first y (from the top)
    /// where the band's coverage reaches one half, interpolated between rows; then y = y0 + m·(x − x_c)
    /// fitted over every column that has one, x_c the centre column. Returns (y at x_c, px; tilt, degrees
    /// counter-clockwise as seen, as [`crate::ShotTruth::surface_tilt_deg`]), or `None` for fewer than two
    /// such columns. A ragged edge's own line differs from the plane it was drawn about (the truth's surface
    /// line): that difference is what no line finder can undo. Cost: one pass over the coverage.
    pub fn drawn_edge_line(&self) -> Option<(f64, f64)> {
        let (w, h) = (self.w, self.h);
        let xc = (w as f64 - 1.0) / 2.0;
        let pts: Vec<(f64, f64)> = (0..w)
            .filter_map(|x| {
                let cov = |y: usize| self.front[y * w + x] as f64;
                (1..h).find(|&y| cov(y) >= 0.5).map(|y| {
                    let (a, b) = (cov(y - 1), cov(y));
                    let f = if b > a {
                        ((0.5 - a) / (b - a)).clamp(0.0, 1.0)
                    } else {
                        1.0
                    };
                    (x as f64 - xc, (y - 1) as f64 + f)
                })
            })
            .collect();
        if pts.len() < 2 {
            return None;
        }
        let n = pts.len() as f64;
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let m = sxy / sxx;
        Some((my - m * mx, (-m).atan().to_degrees()))
    }

    /// The composited static frame, the ball's texture (albedo `albedo` DN, with or without its seam) and
    /// the noise table.
    fn finish(&mut self, rng: &mut Rng, albedo: f64, seam: bool) {
        let n = self.w * self.h;
        self.stat = (0..n)
            .map(|i| self.front[i] * self.band[i] + (1.0 - self.front[i]) * self.back[i])
            .collect();
        self.ball_texture(rng, albedo, seam);
        let cam = &self.plan.camera;
        let (rn, gain) = (cam.read_noise, cam.shot_noise_gain);
        self.sigma = (0..1400)
            .map(|k| (rn * rn + gain * (k as f64 / 4.0)).sqrt() as f32)
            .collect();
    }

    /// Paints a disc of radius `rad` at (cx, cy) with colour `f(dx, dy)` (DN before vignetting) into the
    /// backdrop and the band alike.
    fn paint(&mut self, cx: f64, cy: f64, rad: f64, f: impl Fn(f64, f64) -> f64) {
        let (x0, x1) = (
            (cx - rad - 2.0).floor().max(0.0) as usize,
            (cx + rad + 2.0).ceil().min(self.w as f64 - 1.0),
        );
        let (y0, y1) = (
            (cy - rad - 2.0).floor().max(0.0) as usize,
            (cy + rad + 2.0).ceil().min(self.h as f64 - 1.0),
        );
        if x1 < 0.0 || y1 < 0.0 {
            return;
        }
        for y in y0..=y1 as usize {
            for x in x0..=x1 as usize {
                let (dx, dy) = (x as f64 - cx, y as f64 - cy);
                let cov = ramp(rad - (dx * dx + dy * dy).sqrt() + 0.5);
                if cov <= 0.0 {
                    continue;
                }
                let i = y * self.w + x;
                let val = (f(dx, dy) * self.vig[i] as f64) as f32;
                let c = cov as f32;
                self.back[i] = self.back[i] * (1.0 - c) + val * c;
                self.band[i] = self.band[i] * (1.0 - c) + val * c;
            }
        }
    }

    /// A screw head near the surface and part of a round fixture at a frame edge, both off the ball's path.
    fn distractors(&mut self, rng: &mut Rng) {
        let plan = self.plan;
        let (w, h) = (self.w as f64, self.h as f64);
        let r = plan.truth.r_px;
        let (mut bx0, mut bx1) = (f64::INFINITY, f64::NEG_INFINITY);
        for f in &plan.frames {
            bx0 = bx0.min(f.x_px - r);
            bx1 = bx1.max(f.x_px + r);
        }
        let g = plan.geom;
        let surface_y = |x: f64| g.ty + g.sin * (x - g.tx) / (g.dir * g.cos);
        let light = self.light;
        // Screw head (a tape nail or a fixing screw), 4.5 mm in radius, sitting on the surface line.
        let rs = (0.0045 / g.scale).max(3.0);
        let (l0, l1) = (rs + 4.0, bx0 - rs - 6.0);
        let (r0, r1) = (bx1 + rs + 6.0, w - rs - 5.0);
        let pos = if (l1 - l0).max(r1 - r0) >= 0.0 {
            let x = if l1 - l0 > r1 - r0 {
                rng.range(l0, l1.max(l0 + 1e-9))
            } else {
                rng.range(r0, r1.max(r0 + 1e-9))
            };
            Some((x, surface_y(x) - 0.35 * rs))
        } else {
            let x = rng.range(rs + 4.0, w - rs - 5.0);
            let y = surface_y(x) + plan.delta_max_px + rs + 6.0;
            (y + rs < h).then_some((x, y))
        };
        if let Some((sx, sy)) = pos {
            let slot = rng.range(0.0, std::f64::consts::PI);
            let (ss, sc) = slot.sin_cos();
            self.paint(sx, sy, rs, |dx, dy| {
                let (u, v) = (dx / rs, -dy / rs);
                let nz = (1.0 - (u * u + v * v).min(0.99)).sqrt();
                let lam = (u * light[0] + v * light[1] + nz * light[2]).max(0.0);
                let mut val = 60.0 + 130.0 * lam;
                let across = (-ss * dx + sc * dy).abs();
                val *= 1.0 - 0.65 * ramp(0.2 * rs + 0.5 - across);
                val * (1.0 - 0.35 * ramp((u * u + v * v).sqrt() * 8.0 - 7.0))
            });
        }
        // Round fixture: a dark anodised disc with a bright bevel, mostly outside the frame.
        let rf = 0.9 * r;
        let mut cands = vec![
            (-0.35 * rf, -0.35 * rf),
            (w - 1.0 + 0.35 * rf, -0.35 * rf),
            (-0.55 * rf, 0.3 * h),
            (w - 1.0 + 0.55 * rf, 0.3 * h),
        ];
        cands.retain(|&(fx, fy)| {
            plan.frames
                .iter()
                .all(|f| ((f.x_px - fx).powi(2) + (f.y_px - fy).powi(2)).sqrt() > rf + r + 6.0)
                && pos.is_none_or(|(sx, sy)| ((sx - fx).powi(2) + (sy - fy).powi(2)).sqrt() > rf + rs + 4.0)
        });
        if !cands.is_empty() {
            let (fx, fy) = cands[(rng.uniform() * cands.len() as f64) as usize % cands.len()];
            self.paint(fx, fy, rf, |dx, dy| {
                let q = (dx * dx + dy * dy).sqrt() / rf;
                let bevel = ramp((q - 0.92) * rf);
                let ring = ramp((q - 0.55) * rf) * ramp((0.62 - q) * rf);
                let hole = ramp((0.5 - q) * rf);
                let body = 46.0 - 10.0 * dy / rf;
                body + bevel * (150.0 - body) + ring * 45.0 - hole * 14.0
            });
        }
    }

    /// The felt's albedo over the visible hemisphere (fixed to the ball: the spin axis is the camera's axis)
    /// with the seam (if `with_seam`), brightest albedo `albedo_dn`, and the fuzz of the silhouette.
    fn ball_texture(&mut self, rng: &mut Rng, albedo_dn: f64, with_seam: bool) {
        let r = self.plan.truth.r_px;
        let m = 2 * (r + 3.0).ceil() as usize + 1;
        let c = (m / 2) as f64;
        let n1 = ValueNoise::new(rng, 64);
        let n2 = ValueNoise::new(rng, 64);
        let fseed = rng.next_u64();
        // Seam: the classic tennis-ball curve, turned by a random rotation.
        let (a, b) = (0.56, 0.44);
        let q = {
            let v: [f64; 4] = [rng.normal(), rng.normal(), rng.normal(), rng.normal()];
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            [v[0] / n, v[1] / n, v[2] / n, v[3] / n]
        };
        let rot = |p: [f64; 3]| {
            let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
            [
                (1.0 - 2.0 * (y * y + z * z)) * p[0] + 2.0 * (x * y - w * z) * p[1] + 2.0 * (x * z + w * y) * p[2],
                2.0 * (x * y + w * z) * p[0] + (1.0 - 2.0 * (x * x + z * z)) * p[1] + 2.0 * (y * z - w * x) * p[2],
                2.0 * (x * z - w * y) * p[0] + 2.0 * (y * z + w * x) * p[1] + (1.0 - 2.0 * (x * x + y * y)) * p[2],
            ]
        };
        let point = |i: usize, j: usize| {
            let (bx, by) = (i as f64 - c, j as f64 - c);
            let rho = (bx * bx + by * by).sqrt() / r;
            let k = if rho > 0.999 { 0.999 / rho } else { 1.0 };
            let (u, v) = (bx / r * k, -by / r * k);
            [u, v, (1.0 - u * u - v * v).max(0.0).sqrt()]
        };
        let mut dist = vec![f32::INFINITY; m * m];
        let seam_w = 0.035 * r;
        let reach = (2.5 * seam_w).ceil() as i64 + 1;
        let steps = if with_seam { (24.0 * r).ceil() as usize } else { 0 };
        for s in 0..steps {
            let t = TAU * s as f64 / steps as f64;
            let p = rot([
                a * t.cos() + b * (3.0 * t).cos(),
                a * t.sin() - b * (3.0 * t).sin(),
                2.0 * (a * b).sqrt() * (2.0 * t).sin(),
            ]);
            if p[2] < -0.3 {
                continue;
            }
            let (pi, pj) = ((p[0] * r + c).round() as i64, (-p[1] * r + c).round() as i64);
            for j in (pj - reach).max(0)..=(pj + reach).min(m as i64 - 1) {
                for i in (pi - reach).max(0)..=(pi + reach).min(m as i64 - 1) {
                    let e = point(i as usize, j as usize);
                    let d = ((e[0] - p[0]).powi(2) + (e[1] - p[1]).powi(2) + (e[2] - p[2]).powi(2)).sqrt() * r;
                    let k = j as usize * m + i as usize;
                    dist[k] = dist[k].min(d as f32);
                }
            }
        }
        let mut albedo = vec![0f32; m * m];
        for j in 0..m {
            for i in 0..m {
                let (bx, by) = (i as f64 - c, j as f64 - c);
                let felt = 1.0
                    + 0.06 * n1.at(bx / 9.0, by / 9.0) as f64
                    + 0.05 * n2.at(bx / 2.5, by / 2.5) as f64
                    + 0.07 * (hash01(fseed, i as i64, j as i64) - 0.5);
                let d = dist[j * m + i] as f64;
                let seam = 1.0 - 0.4 * (-(d / seam_w).powi(2)).exp();
                albedo[j * m + i] = (albedo_dn * felt * seam) as f32;
            }
        }
        // Fuzz of the silhouette: harmonics 6–60 (no first harmonic, so no shift of the centre) plus fibres.
        let mut fuzz = vec![0f64; FUZZ_N];
        for k in 6..=60 {
            let amp = rng.normal() / (k as f64).sqrt();
            let ph = rng.range(0.0, TAU);
            for (e, f) in fuzz.iter_mut().enumerate() {
                *f += amp * (TAU * k as f64 * e as f64 / FUZZ_N as f64 + ph).sin();
            }
        }
        let rms = (fuzz.iter().map(|f| f * f).sum::<f64>() / FUZZ_N as f64)
            .sqrt()
            .max(1e-12);
        let fuzz: Vec<f32> = fuzz
            .iter()
            .map(|f| (0.22 * f / rms + 0.12 * rng.range(-1.0, 1.0)) as f32)
            .collect();
        self.fuzz_max = fuzz.iter().fold(0.0f64, |a, &f| a.max(f.abs() as f64));
        self.fuzz = fuzz;
        self.albedo = albedo;
        self.amap = m;
        self.acen = c;
    }

    #[inline]
    fn albedo_at(&self, x: f64, y: f64) -> f64 {
        let m = self.amap;
        let (x, y) = (x.clamp(0.0, m as f64 - 1.001), y.clamp(0.0, m as f64 - 1.001));
        let (i, j) = (x as usize, y as usize);
        let (fx, fy) = ((x - i as f64) as f32, (y - j as f64) as f32);
        let k = j * m + i;
        let a = &self.albedo;
        let top = a[k] + (a[k + 1] - a[k]) * fx;
        let bot = a[k + m] + (a[k + m + 1] - a[k + m]) * fx;
        (top + (bot - top) * fy) as f64
    }

    /// The ball's radiance (DN before vignetting) at offset (dx, dy) px from its centre, pattern turned by
    /// the angle whose cosine and sine are (ca, sa).
    #[inline]
    fn shade(&self, dx: f64, dy: f64, r: f64, ca: f64, sa: f64) -> f64 {
        let (mut u, mut v) = (dx / r, -dy / r);
        let rho2 = u * u + v * v;
        if rho2 > 0.998 {
            let k = (0.998 / rho2).sqrt();
            u *= k;
            v *= k;
        }
        let nz = (1.0 - u * u - v * v).max(0.0).sqrt();
        let l = self.light;
        let lam = (u * l[0] + v * l[1] + nz * l[2]).max(0.0);
        let sh = self.shading;
        let s = sh.ambient + sh.diffuse * lam + sh.rim * (1.0 - nz) * (1.0 - nz);
        let bx = dx * ca - dy * sa;
        let by = dx * sa + dy * ca;
        self.albedo_at(bx + self.acen, by + self.acen) * s
    }

    /// The pixels the ball of a frame can touch: centre (cx, cy) and radius `r` px, blurred over the
    /// sub-exposure centres `subs`.
    fn ball_window(&self, cx: f64, cy: f64, r: f64, subs: &[(f64, f64)]) -> BallWindow {
        let (w, h) = (self.w, self.h);
        let blur = subs.iter().fold(0.0f64, |a, s| a.max((s.0 - cx).hypot(s.1 - cy)));
        let r_in = r - self.fuzz_max - blur - EDGE_W;
        let r_out = r + self.fuzz_max + blur + EDGE_W;
        let (r_in2, r_out2) = (r_in.max(0.0).powi(2), r_out * r_out);
        let (mut sx0, mut sx1, mut sy0, mut sy1) = (cx, cx, cy, cy);
        for s in subs {
            sx0 = sx0.min(s.0);
            sx1 = sx1.max(s.0);
            sy0 = sy0.min(s.1);
            sy1 = sy1.max(s.1);
        }
        BallWindow {
            r_in2,
            r_out2,
            x0: (sx0 - r_out).floor().max(0.0) as usize,
            x1: ((sx1 + r_out).ceil() + 1.0).clamp(0.0, w as f64) as usize,
            y0: (sy0 - r_out).floor().max(0.0) as usize,
            y1: ((sy1 + r_out).ceil() + 1.0).clamp(0.0, h as f64) as usize,
        }
    }

    /// The ball's coverage of pixel (x, y) on its fuzzy edge, summed over the sub-exposure centres `subs`
    /// (divide by their number): (dx, dy) is the pixel's offset from the mid-exposure centre, `alpha` the
    /// pattern's turn, rad.
    #[inline]
    fn edge_coverage(&self, (x, y): (f64, f64), (dx, dy): (f64, f64), r: f64, alpha: f64, subs: &[(f64, f64)]) -> f64 {
        let ang = (-dy).atan2(dx) - alpha;
        let e = ((ang / TAU).rem_euclid(1.0) * FUZZ_N as f64) as usize % FUZZ_N;
        let re = r + self.fuzz[e] as f64;
        let mut acc = 0.0;
        for s in subs {
            let d = (x - s.0).hypot(y - s.1);
            acc += ramp((re - d) / EDGE_W + 0.5);
        }
        acc
    }

    /// Renders frame `i` (0-based).
    ///
    /// # Panics
    /// If `i` is not a frame of the shot.
    #[allow(clippy::needless_range_loop)] // x indexes four parallel arrays
    pub fn frame(&self, i: usize) -> RenderedFrame {
        let plan = self.plan;
        let cam = &plan.camera;
        let (w, h) = (self.w, self.h);
        let ft = &plan.frames[i];
        let k = cam.blur_samples as usize;
        let subs = &plan.subs[i * k..(i + 1) * k];
        let r = ft.r_px;
        let (cx, cy) = (ft.x_px, ft.y_px);
        let (sa, ca) = plan.alpha[i].sin_cos();
        let gain = 1.0 + cam.flicker_amplitude * (TAU * cam.flicker_hz * ft.t_s + plan.flicker_phase).sin();
        let BallWindow {
            r_in2,
            r_out2,
            x0: bx0,
            x1: bx1,
            y0: by0,
            y1: by1,
        } = self.ball_window(cx, cy, r, subs);
        let gauss = gauss_table();
        let mut rng = Rng::new(plan.frame_seed(i));
        let sixteen = cam.bit_depth != 8;
        let twelve = cam.bit_depth == 12;
        let mut out8 = if sixteen { Vec::new() } else { vec![0u8; w * h] };
        let mut out16 = if sixteen { vec![0u16; w * h] } else { Vec::new() };
        let mut row = vec![0f32; w];
        let lut_max = self.sigma.len() - 1;
        let g32 = gain as f32;
        let inv_k = 1.0 / k as f64;
        for y in 0..h {
            let base = y * w;
            row.copy_from_slice(&self.stat[base..base + w]);
            if y >= by0 && y < by1 && bx0 < bx1 {
                let yf = y as f64;
                let dy = yf - cy;
                for x in bx0..bx1 {
                    let xf = x as f64;
                    let dx = xf - cx;
                    let d2 = dx * dx + dy * dy;
                    if d2 >= r_out2 {
                        continue;
                    }
                    let idx = base + x;
                    let cov = if d2 <= r_in2 {
                        1.0
                    } else {
                        self.edge_coverage((xf, yf), (dx, dy), r, plan.alpha[i], subs) * inv_k
                    };
                    if cov <= 0.0 {
                        continue;
                    }
                    let ball = self.shade(dx, dy, r, ca, sa) * self.vig[idx] as f64;
                    let f = self.front[idx] as f64;
                    let behind = cov * ball + (1.0 - cov) * self.back[idx] as f64;
                    row[x] = (f * self.band[idx] as f64 + (1.0 - f) * behind) as f32;
                }
            }
            let mut bits = 0u64;
            for (x, &v0) in row.iter().enumerate() {
                if x % 4 == 0 {
                    bits = rng.next_u64();
                }
                let v = v0 * g32 + self.fpn[base + x];
                let li = ((v.max(0.0) * 4.0) as usize).min(lut_max);
                let n = gauss[(bits & 0xFFFF) as usize];
                bits >>= 16;
                let q = v + self.sigma[li] * n;
                if twelve {
                    // 12-bit data shifted into 16-bit words, as 12-bit cameras write them.
                    out16[base + x] = ((q * (4095.0 / 255.0) + 0.5).clamp(0.0, 4095.0) as u16) << 4;
                } else if sixteen {
                    out16[base + x] = (q * 257.0 + 0.5).clamp(0.0, 65535.0) as u16;
                } else {
                    out8[base + x] = (q + 0.5).clamp(0.0, 255.0) as u8;
                }
            }
        }
        RenderedFrame {
            width: w as u32,
            height: h as u32,
            pixels: if sixteen {
                Pixels::Gray16(out16)
            } else {
                Pixels::Gray8(out8)
            },
        }
    }
}
