//! Small synthetic frames for tests: a shaded disc with sub-pixel centre over a gradient backdrop, marks on
//! the disc, an optional textured surface band that hides the disc below its top edge, distractor discs and
//! noise, drawn with the workspace's one seeded generator (`bouncelab_testkit::Rng`).

use bouncelab_testkit::Rng;

/// What to draw.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Image width and height, px.
    pub size: (usize, usize),
    /// Ball centre and radius, px.
    pub ball: (f64, f64, f64),
    /// Ball brightness at its centre, 0–255.
    pub ball_level: f64,
    /// Backdrop brightness at the top and bottom, 0–255.
    pub backdrop: (f64, f64),
    /// Surface line height at the centre column and its slope (dy/dx); `None` for no surface.
    pub surface: Option<(f64, f64)>,
    /// Mean brightness of the surface band, 0–255; its texture amplitude.
    pub band: (f64, f64),
    /// Other discs (x, y, r, level).
    pub distractors: Vec<(f64, f64, f64, f64)>,
    /// Discs drawn on the ball, moving with it (dx, dy from its centre, r, level): a print, a seam's lobe.
    pub marks: Vec<(f64, f64, f64, f64)>,
    /// Gaussian noise standard deviation, 0–255 scale.
    pub noise: f64,
    /// Noise seed.
    pub seed: u64,
    /// Raggedness of the band's top edge: its largest distance from the line, px (grains 2–16 px wide).
    pub roughness: f64,
}

impl Default for Scene {
    fn default() -> Self {
        Scene {
            size: (256, 256),
            ball: (120.3, 90.7, 40.0),
            ball_level: 200.0,
            backdrop: (70.0, 110.0),
            surface: None,
            band: (90.0, 25.0),
            distractors: Vec::new(),
            marks: Vec::new(),
            noise: 2.0,
            seed: 1,
            roughness: 0.0,
        }
    }
}

/// The OpenCV reference's test frame: 512×512, a bright ball over a dark gradient, a textured band below
/// (its top at y = 430, slope 0.02), a dark screw head at the top right, noise σ = 5.
pub fn opencv_scene(ball: (f64, f64, f64), seed: u64) -> Scene {
    Scene {
        size: (512, 512),
        ball,
        ball_level: 210.0,
        backdrop: (60.0, 100.0),
        surface: Some((430.0, 0.02)),
        band: (120.0, 50.0),
        distractors: vec![(450.0, 80.0, 9.0, 40.0)],
        marks: Vec::new(),
        noise: 5.0,
        seed,
        roughness: 0.0,
    }
}

/// Fraction of pixel (x, y) covered by the disc, by 8×8 supersampling near the edge.
fn coverage(x: usize, y: usize, cx: f64, cy: f64, r: f64) -> f64 {
    let d = (x as f64 - cx).hypot(y as f64 - cy);
    if d < r - 1.0 {
        return 1.0;
    }
    if d > r + 1.0 {
        return 0.0;
    }
    let mut n = 0;
    for i in 0..8 {
        for j in 0..8 {
            let (sx, sy) = (
                x as f64 - 0.5 + (i as f64 + 0.5) / 8.0,
                y as f64 - 0.5 + (j as f64 + 0.5) / 8.0,
            );
            if (sx - cx).hypot(sy - cy) <= r {
                n += 1;
            }
        }
    }
    n as f64 / 64.0
}

/// The band's top edge's offsets from its line per column, px (its pixels are half covered there): a few
/// incommensurate waves, scaled to reach ±`roughness`.
fn ragged_edge(scene: &Scene) -> Vec<f64> {
    let mut phases = Rng::new(scene.seed ^ 0x9E37_79B9_7F4A_7C15);
    let waves: Vec<(f64, f64)> = [2.3, 4.1, 7.9, 15.7]
        .iter()
        .map(|&l| (l, phases.uniform() * std::f64::consts::TAU))
        .collect();
    let ragged: Vec<f64> = (0..scene.size.0)
        .map(|x| waves.iter().map(|(l, p)| (x as f64 / l + p).sin()).sum::<f64>() / waves.len() as f64)
        .collect();
    let peak = ragged.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-9);
    ragged.iter().map(|v| scene.roughness * v / peak).collect()
}

/// The band's top edge as drawn in each column, px (its pixels are half covered there); NaN without a band.
pub fn band_edge(scene: &Scene) -> Vec<f64> {
    let xc = (scene.size.0 as f64 - 1.0) / 2.0;
    let ragged = ragged_edge(scene);
    (0..scene.size.0)
        .map(|x| {
            scene
                .surface
                .map_or(f64::NAN, |(y0, slope)| y0 + slope * (x as f64 - xc) + ragged[x])
        })
        .collect()
}

/// The mean over the image's columns of the band's top edge as drawn, at the centre column, px: the level
/// of the band's line (its `surface.0` plus the ragged edge's mean offset).
pub fn band_edge_mean(scene: &Scene) -> f64 {
    let r = ragged_edge(scene);
    scene
        .surface
        .map_or(f64::NAN, |(y0, _)| y0 + r.iter().sum::<f64>() / r.len() as f64)
}

/// Renders `scene` as 8-bit pixels, row-major.
pub fn render(scene: &Scene) -> Vec<u8> {
    let (w, h) = scene.size;
    let mut rng = Rng::new(scene.seed.wrapping_add(0x5851F42D4C957F2D));
    let tex: Vec<f64> = (0..w * h).map(|_| rng.normal()).collect();
    let (cx, cy, r) = scene.ball;
    let xc = (w as f64 - 1.0) / 2.0;
    let ragged = ragged_edge(scene);
    let mut out = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let t = y as f64 / (h - 1) as f64;
            let mut v = scene.backdrop.0 + (scene.backdrop.1 - scene.backdrop.0) * t;
            for &(dx, dy, dr, level) in &scene.distractors {
                let c = coverage(x, y, dx, dy, dr);
                v = v * (1.0 - c) + level * c;
            }
            // Shaded ball: brighter towards the upper left.
            let c = coverage(x, y, cx, cy, r);
            if c > 0.0 {
                let (nx, ny) = ((x as f64 - cx) / r, (y as f64 - cy) / r);
                let shade = 0.75 + 0.25 * (-0.5 * nx - 0.6 * ny).clamp(-1.0, 1.0);
                v = v * (1.0 - c) + scene.ball_level * shade * c;
                for &(dx, dy, dr, level) in &scene.marks {
                    let m = c.min(coverage(x, y, cx + dx, cy + dy, dr));
                    v = v * (1.0 - m) + level * m;
                }
            }
            if let Some((y0, slope)) = scene.surface {
                let edge = y0 + slope * (x as f64 - xc) + ragged[x];
                // Anti-aliased top edge of the band, which hides whatever is behind it.
                let cov = (y as f64 + 0.5 - edge).clamp(0.0, 1.0);
                if cov > 0.0 {
                    let band = scene.band.0 + scene.band.1 * tex[y * w + x] * 0.5;
                    v = v * (1.0 - cov) + band * cov;
                }
            }
            v += scene.noise * rng.normal();
            out[y * w + x] = v.round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}
