//! The level of a found surface line measured again from how much of each row parallel to it the band
//! covers: where, along the line, a row's pixels are half-way between the backdrop's and the band's.
//!
//! Both cues place a ragged edge's line above its middle: a column's strongest step, or its rise in texture
//! energy, comes where the first grains reach, and the boundary between grains and backdrop adds texture of
//! its own. A statistic of a row's raw pixels that is linear in how much of the row the band covers does
//! not: in each block of columns the row where it is half-way between its levels well above and well below
//! the line is where half the block's columns are covered, the median of the block's edge, whatever its
//! roughness (a lip, a strip along the band's top brighter or darker than the band, still moves it). Two
//! such statistics are used:
//! - the **mean gray**, where the band's differs from the backdrop's: the more precise; but not where the
//!   blocks' mean profile goes beyond the backdrop's gray away from the band's (a bright lip along a darker
//!   band, or a glow on the backdrop above it, which the mean gray cannot tell apart);
//! - else, on a ragged edge, the **share of the row's pixels the backdrop cannot explain**: further from
//!   the backdrop's gray (a straight-line trend fitted to the rows above the line, carried into the rows
//!   below) than three of the backdrop's own standard deviations about that trend, and than three
//!   quarters of the band's pixels' RMS distance from it. A covered pixel lies out there with some
//!   probability set by the band's texture and mean gray, an uncovered one hardly ever, so the share is
//!   linear in the row's cover whatever the band's mean gray; each pixel counts once, so a screw head or a
//!   grain far brighter than the rest weighs no more than any other covered pixel. It tells the level of
//!   a granular or woven band as gray as the backdrop. The second bound is for the mean of many frames
//!   the line is looked for in: its noise all but vanishes, while a faint glow or shadow along the band's
//!   top and the edge's blur stay, and would count as the band.
//!
//! On a band with neither a step in mean gray nor texture the line is kept as found. Cost: two passes over
//! the pixels within ±16 px of the line.

use crate::plane::{Pixel, Plane, median};
use crate::surface::SurfaceLine;

/// Columns per block, px: each block gives one crossing, and the level is their median.
const BLOCK_PX: usize = 16;
/// How far from the line the band's and the backdrop's levels begin, px: beyond a ragged edge's reach of a
/// few px, yet within a tape a dozen px thick.
const REACH_PX: i32 = 10;
/// Rows (1 px bins) averaged for each of the two levels.
const LEVEL_ROWS: i32 = 7;
/// How far from the line the measurement reaches on either side, px.
const SPAN_PX: i32 = REACH_PX + LEVEL_ROWS - 1;
/// Least step between the two levels, in standard errors of that difference, for a block's crossing to count.
const MIN_STEP_SE: f64 = 8.0;
/// Fewest blocks with a crossing for the level to be measured again.
const MIN_BLOCKS: usize = 5;

/// How far from the backdrop's gray a pixel must lie to count as the band's, in the backdrop's own
/// standard deviations about its trend: the conventional three, which noise alone passes 0.3 % of the time.
const OUTLIER_SD: f64 = 3.0;

/// The least standard deviation the backdrop is taken to have in that test, as a fraction of the band's
/// pixels' RMS distance from the backdrop's gray (a quarter).
const BACKDROP_FLOOR: f64 = 0.25;

/// What each row of a block is summarised by (see the module's description).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowStatistic {
    /// The row's mean gray.
    MeanGray,
    /// The share of the row's pixels further from the backdrop's gray than its noise allows (and than a
    /// quarter of the band's spread, see [`textured_share_level`]).
    TexturedShare,
}

/// How far the line's level moves and its standard error, px.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelShift {
    /// Distance from the line to the band's mean-gray half-way row, px (+ down), the median over blocks.
    pub offset_px: f64,
    /// Standard error of `offset_px`, px (the blocks' scatter).
    pub sigma_px: f64,
    /// Blocks whose crossing was used.
    pub blocks: usize,
    /// What the rows were summarised by.
    pub statistic: RowStatistic,
}

/// Sum, sum of squares and count of the pixels in one 1 px bin of distance from the line, and the sum of
/// their distances (a level line's rows all lie a fraction of a pixel off the bin's centre).
#[derive(Debug, Clone, Copy, Default)]
struct Bin {
    sum: f64,
    sum_sq: f64,
    n: usize,
    sum_d: f64,
}

impl Bin {
    fn add(&mut self, v: f64, d: f64) {
        self.sum += v;
        self.sum_sq += v * v;
        self.n += 1;
        self.sum_d += d;
    }
    fn distance(&self) -> f64 {
        self.sum_d / self.n as f64
    }
    fn mean(&self) -> f64 {
        self.sum / self.n as f64
    }
    fn var_of_mean(&self) -> f64 {
        let m = self.mean();
        ((self.sum_sq / self.n as f64 - m * m).max(0.0)) / self.n as f64
    }
}

/// The shift of `line`'s level to the half-way row of the band's mean gray (see the module's description), or
/// `None` unless at least five blocks of 16 columns, and half of those whose pixels reach ±16 px of the line
/// inside the image, show a clear step in mean gray across it: a band only here and there darker than the
/// backdrop (large grains, shading within it) is not one whose mean gray tells its edge. `None` too where
/// the blocks' profiles, averaged, go beyond the backdrop's gray away from the band's ([`beyond_the_backdrop`]).
/// Columns in `skip` (x from, x to, px) are left out: the ball, where it comes near the line. Cost:
/// O(width × 34).
pub fn mean_gray_level<P: Pixel>(img: &Plane<P>, line: &SurfaceLine, skip: Option<(f64, f64)>) -> Option<LevelShift> {
    row_statistic_level(img, line, skip, RowStatistic::MeanGray)
}

/// The same as [`mean_gray_level`] from the share of each row's pixels further from the backdrop's gray than
/// three of its standard deviations and than three quarters of the band's pixels' RMS distance from it (see
/// the module's description): the level of a band whose mean gray may equal the backdrop's but whose
/// texture does not. Cost: O(width × 34 × 2).
pub fn textured_share_level<P: Pixel>(
    img: &Plane<P>,
    line: &SurfaceLine,
    skip: Option<(f64, f64)>,
) -> Option<LevelShift> {
    row_statistic_level(img, line, skip, RowStatistic::TexturedShare)
}

fn row_statistic_level<P: Pixel>(
    img: &Plane<P>,
    line: &SurfaceLine,
    skip: Option<(f64, f64)>,
    statistic: RowStatistic,
) -> Option<LevelShift> {
    let span = SPAN_PX;
    let nbins = (2 * span + 1) as usize;
    let mut offsets = Vec::new();
    let mut shares = Vec::new();
    let mut looked = 0usize;
    let mut samples: Vec<(usize, f64, f64)> = Vec::with_capacity(BLOCK_PX * nbins);
    for x_lo in (0..img.width.saturating_sub(BLOCK_PX - 1)).step_by(BLOCK_PX) {
        let x_hi = x_lo + BLOCK_PX - 1;
        if skip.is_some_and(|(a, b)| (x_lo as f64) <= b && (x_hi as f64) >= a) {
            continue;
        }
        samples.clear();
        for x in x_lo..=x_hi {
            let yl = line.y_at(x as f64);
            let (top, bottom) = ((yl - span as f64 - 0.5).ceil(), (yl + span as f64 + 0.5).floor());
            if top < 0.0 || bottom >= img.height as f64 {
                continue;
            }
            for y in top as usize..=bottom as usize {
                let d = y as f64 - yl;
                let k = d.round() as i32 + span;
                if (0..nbins as i32).contains(&k) {
                    samples.push((k as usize, d, img.at(x, y) as f64));
                }
            }
        }
        let mut bins = vec![Bin::default(); nbins];
        for &(k, d, v) in &samples {
            bins[k].add(v, d);
        }
        if bins.iter().any(|b| b.n < BLOCK_PX / 2) {
            continue;
        }
        if statistic == RowStatistic::TexturedShare {
            let rows = LEVEL_ROWS as usize;
            let backdrop = backdrop_trend(&bins[..rows]);
            // Mean square distance from the backdrop's gray of the pixels in the bins `k` picks.
            let mean_sq = |picks: &dyn Fn(usize) -> bool| {
                let (sq, n) = samples
                    .iter()
                    .filter(|s| picks(s.0))
                    .fold((0.0, 0usize), |(a, n), &(_, d, v)| {
                        (a + (v - backdrop(d)).powi(2), n + 1)
                    });
                sq / n.max(1) as f64
            };
            let noise = mean_sq(&|k| k < rows);
            let spread = mean_sq(&|k| k >= nbins - rows);
            // In the mean of many frames the noise all but vanishes while the scene's own faint structure (a
            // glow or a shadow along the band's top, the edge's blur) stays: a departure from the backdrop
            // counts as the band's only if it is also a fair part of how far the band's pixels lie from it.
            let threshold = OUTLIER_SD * OUTLIER_SD * noise.max(BACKDROP_FLOOR * BACKDROP_FLOOR * spread);
            bins = vec![Bin::default(); nbins];
            for &(k, d, v) in &samples {
                bins[k].add(f64::from(u8::from((v - backdrop(d)).powi(2) > threshold)), d);
            }
        }
        looked += 1;
        let Some(step) = BlockStep::of(&bins) else { continue };
        if statistic == RowStatistic::MeanGray {
            shares.push(step.transition_shares(&bins, backdrop_trend(&bins[..LEVEL_ROWS as usize])));
        }
        if let Some(off) = step.crossing(&bins) {
            offsets.push(off);
        }
    }
    if offsets.len() < MIN_BLOCKS.max(looked.div_ceil(2)) || beyond_the_backdrop(&shares) {
        return None;
    }
    let n = offsets.len();
    let mid = median(&mut offsets.clone());
    let mad = median(&mut offsets.iter().map(|o| (o - mid).abs()).collect::<Vec<_>>());
    // The median's standard error for normal scatter: √(π/2)·σ/√n, σ from the MAD.
    let sigma = (std::f64::consts::FRAC_PI_2.sqrt() * 1.4826 * mad / (n as f64).sqrt()).max(0.02);
    Some(LevelShift {
        offset_px: mid,
        sigma_px: sigma,
        blocks: n,
        statistic,
    })
}

/// The backdrop's gray as a straight line in the distance from the surface line, fitted to the means of the
/// rows above the line (`above`): a lighting gradient or vignetting carried into the rows the band covers.
fn backdrop_trend(above: &[Bin]) -> impl Fn(f64) -> f64 + use<> {
    let k = above.len() as f64;
    let (md, mv) = above
        .iter()
        .fold((0.0, 0.0), |(a, b), bin| (a + bin.distance() / k, b + bin.mean() / k));
    let (sdv, sdd) = above.iter().fold((0.0, 0.0), |(a, b), bin| {
        let dd = bin.distance() - md;
        (a + dd * (bin.mean() - mv), b + dd * dd)
    });
    let slope = if sdd > 0.0 { sdv / sdd } else { 0.0 };
    move |d| mv + slope * (d - md)
}

/// A block's two levels: the means of its outermost `LEVEL_ROWS` bins on either side of the line.
struct BlockStep {
    above: f64,
    below: f64,
}

impl BlockStep {
    /// The block's levels when they differ by `MIN_STEP_SE` standard errors, else `None`.
    fn of(bins: &[Bin]) -> Option<BlockStep> {
        let rows = LEVEL_ROWS as usize;
        // A level's variance: its pixels' scatter, or its rows' when coarse grains make neighbouring pixels alike.
        let level = |part: &[Bin]| {
            let k = part.len() as f64;
            let m = part.iter().map(Bin::mean).sum::<f64>() / k;
            let within = part.iter().map(Bin::var_of_mean).sum::<f64>() / (k * k);
            let between = part.iter().map(|b| (b.mean() - m).powi(2)).sum::<f64>() / ((k - 1.0) * k);
            (m, within.max(between))
        };
        let (above, va) = level(&bins[..rows]);
        let (below, vb) = level(&bins[bins.len() - rows..]);
        ((below - above).abs() >= MIN_STEP_SE * (va + vb).sqrt()).then_some(BlockStep { above, below })
    }

    /// How far each bin between the two levels has gone from the upper side's gray (`upper`, a trend in the
    /// distance from the line: lighting and vignetting go on across it) towards the lower level, as a share
    /// of the step between the levels: 0 on the upper side, about 1 at the lower level.
    fn transition_shares(&self, bins: &[Bin], upper: impl Fn(f64) -> f64) -> Vec<f64> {
        let rows = LEVEL_ROWS as usize;
        bins[rows..bins.len() - rows]
            .iter()
            .map(|b| (b.mean() - upper(b.distance())) / (self.below - self.above))
            .collect()
    }

    /// The block's half-way row relative to the line, px: of the places where the profile crosses half-way
    /// between the levels the one nearest the line, linearly interpolated between the bins' mean distances.
    /// `None` when the profile does not cross.
    fn crossing(&self, bins: &[Bin]) -> Option<f64> {
        let f = |k: usize| (bins[k].mean() - self.above) / (self.below - self.above) - 0.5;
        (0..bins.len() - 1)
            .filter(|&k| f(k) * f(k + 1) <= 0.0 && f(k) != f(k + 1))
            .map(|k| {
                let (d0, d1) = (bins[k].distance(), bins[k + 1].distance());
                d0 + (d1 - d0) * f(k) / (f(k) - f(k + 1))
            })
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
    }
}

/// How far beyond the upper level, away from the lower, the blocks' mean profile between them may reach
/// before [`beyond_the_backdrop`] holds, as a share of the step: a tenth, where it starts to move the
/// half-way row by a fair part of the strip's width.
const BEYOND_SHARE: f64 = 0.1;
/// The same in standard errors of that mean (from the blocks' scatter): the conventional three.
const BEYOND_SE: f64 = 3.0;

/// Whether the blocks' profiles between their levels (`shares`, [`BlockStep::transition_shares`]), averaged
/// row by row, go beyond the backdrop's gray away from the band's: a strip brighter than the backdrop along
/// a darker band's top, or the reverse. A lip catching the light on the band's top and a glow on the
/// backdrop just above it make the same profile, yet the half-way row lies below the edge by up to the
/// strip's width in the first case and at it in the second: the mean gray cannot tell where the edge is.
/// Averaged over blocks, since within one block of 16 columns a woven or granular band's own texture
/// hides such a strip.
fn beyond_the_backdrop(shares: &[Vec<f64>]) -> bool {
    let n = shares.len();
    if n < 3 {
        return false;
    }
    (0..shares[0].len()).any(|k| {
        let mean = shares.iter().map(|s| s[k]).sum::<f64>() / n as f64;
        let var = shares.iter().map(|s| (s[k] - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        mean < -BEYOND_SHARE && mean + BEYOND_SE * (var / n as f64).sqrt() < 0.0
    })
}

/// The columns to leave out of [`mean_gray_level`] for a ball of radius `r` px whose centre's x spanned
/// `span` (from, to) px in the frames summed, the last at (x, y): those centres ± the radius and 4 px when its
/// disc comes within 4 px of the measurement's reach above `line`, else `None`. The ball falls through the
/// first frames, so the last summed frame's height decides.
pub fn ball_columns(line: &SurfaceLine, (x, y, r): (f64, f64, f64), span: (f64, f64)) -> Option<(f64, f64)> {
    let clear = line.height_of(x, y) - r > SPAN_PX as f64 + 4.0;
    (!clear).then_some((span.0 - r - 4.0, span.1 + r + 4.0))
}

/// `line` with its level measured again where that can be done ([`mean_gray_level`], else, on a ragged edge,
/// [`textured_share_level`]): `y0` moved by the shift, `sigma_y0` the shift's standard error, the shift kept in
/// `level_shift_px` (the band's grains still reach where the cue found them: see [`SurfaceLine::top_at`]).
/// Otherwise `line` as it was. A clean edge's line is where the edge is; counting pixels unlike the
/// backdrop there counts its blur and any glow or shadow along it as the band (on `paper`'s clay, whose
/// mean gray gives no level, it moved three lines 0.2–0.4 px up), so the texture is asked only where the
/// edge is ragged ([`SurfaceLine::ragged_reach_px`]).
pub fn remeasured<P: Pixel>(img: &Plane<P>, line: SurfaceLine, skip: Option<(f64, f64)>) -> SurfaceLine {
    let ragged = line.ragged_reach_px() > 0.0;
    let shift =
        mean_gray_level(img, &line, skip).or_else(|| ragged.then(|| textured_share_level(img, &line, skip)).flatten());
    match shift {
        Some(s) => SurfaceLine {
            y0: line.y0 + s.offset_px,
            sigma_y0: s.sigma_px,
            level_shift_px: line.level_shift_px + s.offset_px,
            ..line
        },
        None => line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::find_surface_lines;
    use crate::testutil::{Scene, band_edge_mean, render};

    fn scene(y0: f64, slope: f64, band: (f64, f64), roughness: f64, noise: f64, seed: u64) -> Scene {
        Scene {
            surface: Some((y0, slope)),
            backdrop: (95.0, 95.0),
            band,
            roughness,
            noise,
            seed,
            ball: (128.0, 60.0, 20.0),
            ..Scene::default()
        }
    }

    fn band(y0: f64, slope: f64, band: (f64, f64), roughness: f64, noise: f64, seed: u64) -> Vec<u8> {
        render(&scene(y0, slope, band, roughness, noise, seed))
    }

    /// On a ragged band darker or brighter than the backdrop, the level moves to the drawn edge's mean, from
    /// wherever the cues put it, within its stated error.
    #[test]
    fn a_ragged_band_s_level_is_its_edge_s_mean() {
        for (seed, offset, rough) in [(1u64, -30.0, 4.0), (2, 25.0, 6.0), (3, -15.0, 2.0), (4, 40.0, 0.0)] {
            let y0 = 170.3;
            let drawn = scene(y0, 0.0, (95.0 + offset, 20.0), rough, 3.0, seed);
            let px = render(&drawn);
            let img = Plane::new(&px, 256, 256);
            let truth = band_edge_mean(&drawn);
            for start in [-3.0, 0.0, 2.5] {
                let line = SurfaceLine::given(127.5, truth + start, 0.0);
                let s = mean_gray_level(&img, &line, None).expect("a clear step");
                let err = line.y0 + s.offset_px - truth;
                assert!(
                    err.abs() < 3.0 * s.sigma_px + 0.05 && s.sigma_px < 0.2 * rough + 0.05,
                    "seed {seed} rough {rough} start {start}: error {err:.3} ± {:.3}",
                    s.sigma_px
                );
            }
        }
    }

    /// A band as gray as the backdrop has no step in mean gray; its texture tells its level instead, to the
    /// drawn edge's mean within the stated error, wherever the cue put the line.
    #[test]
    fn a_band_as_gray_as_the_backdrop_has_its_level_from_its_texture() {
        for (seed, rough, texture) in [(5u64, 3.0, 30.0), (6, 6.0, 24.0), (7, 0.0, 20.0), (8, 4.0, 24.0)] {
            let drawn = scene(170.3, 0.0, (95.0, texture), rough, 3.0, seed);
            let px = render(&drawn);
            let img = Plane::new(&px, 256, 256);
            let found = find_surface_lines(&img, None).expect("a texture line").line;
            assert!(mean_gray_level(&img, &found, None).is_none());
            let s = textured_share_level(&img, &found, None)
                .unwrap_or_else(|| panic!("seed {seed}: no clear step in texture about {found:?}"));
            assert_eq!(s.statistic, RowStatistic::TexturedShare);
            let truth = band_edge_mean(&drawn);
            let err = found.y0 + s.offset_px - truth;
            assert!(
                err.abs() < 3.0 * s.sigma_px + 0.1,
                "seed {seed} rough {rough} texture {texture}: found {:.2}, remeasured error {err:.3} ± {:.3}",
                found.y0 - truth,
                s.sigma_px
            );
            // Only a ragged edge's line is measured again from its texture.
            let expected = if found.ragged_reach_px() > 0.0 {
                found.y0 + s.offset_px
            } else {
                found.y0
            };
            assert_eq!(remeasured(&img, found, None).y0, expected);
        }
    }

    /// In a frame without noise (the mean of many), a faint glow along the band's top is not the band: the
    /// level stays at the edge's mean.
    #[test]
    fn a_glow_along_the_band_s_top_is_not_the_band() {
        let drawn = scene(170.3, 0.0, (95.0, 24.0), 3.0, 0.0, 12);
        let mut px = render(&drawn);
        for (x, edge) in crate::testutil::band_edge(&drawn).into_iter().enumerate() {
            for y in (edge - 4.0).ceil() as usize..edge.floor() as usize {
                px[y * 256 + x] = px[y * 256 + x].saturating_add(3);
            }
        }
        assert_textured_level_at_edge_mean(&px, &drawn, -1.5);
    }

    /// A darker band whose top 2 px catch the light, brighter than the backdrop, has no level from its mean
    /// gray (whose half-way row lies below the lip); without the lip it has, at the edge. The test is made
    /// on the blocks' mean profile, since one block's texture hides the lip.
    #[test]
    fn a_lip_brighter_than_the_backdrop_along_a_darker_band_gives_no_mean_gray_level() {
        let drawn = scene(170.3, 0.0, (75.0, 15.0), 0.0, 2.0, 13);
        let mut px = render(&drawn);
        let line = SurfaceLine::given(127.5, 170.3, 0.0);
        let plain = mean_gray_level(&Plane::new(&px, 256, 256), &line, None).expect("a clear step");
        assert!(plain.offset_px.abs() < 0.3, "{plain:?}");
        for (x, edge) in crate::testutil::band_edge(&drawn).into_iter().enumerate() {
            for y in edge.ceil() as usize..(edge + 2.0).ceil() as usize {
                px[y * 256 + x] = px[y * 256 + x].saturating_add(28);
            }
        }
        let img = Plane::new(&px, 256, 256);
        assert!(mean_gray_level(&img, &line, None).is_none());
        assert_eq!(remeasured(&img, line, None), line);
    }

    /// Starting `start` px from the drawn edge's mean, the textured share puts the level there within three
    /// of its stated standard errors and 0.1 px.
    fn assert_textured_level_at_edge_mean(px: &[u8], drawn: &Scene, start: f64) {
        let img = Plane::new(px, 256, 256);
        let truth = band_edge_mean(drawn);
        let line = SurfaceLine::given(127.5, truth + start, 0.0);
        let s = textured_share_level(&img, &line, None).expect("a clear step in texture");
        let err = line.y0 + s.offset_px - truth;
        assert!(err.abs() < 3.0 * s.sigma_px + 0.1, "error {err:.3} ± {:.3}", s.sigma_px);
    }

    /// A band with neither a step in mean gray nor texture of its own keeps its line.
    #[test]
    fn a_band_like_the_backdrop_keeps_its_line() {
        let px = band(170.3, 0.0, (95.0, 0.0), 3.0, 3.0, 5);
        let img = Plane::new(&px, 256, 256);
        let line = SurfaceLine::given(127.5, 170.3, 0.0);
        assert!(mean_gray_level(&img, &line, None).is_none());
        assert!(textured_share_level(&img, &line, None).is_none());
        assert_eq!(remeasured(&img, line, None), line);
    }

    /// Under a lighting gradient the backdrop's gray is followed into the band's rows: the level stays at
    /// the edge's mean, not where the backdrop has drifted out of its noise.
    #[test]
    fn a_lighting_gradient_does_not_move_the_textured_level() {
        let drawn = Scene {
            backdrop: (100.0, 100.0),
            ..scene(170.3, 0.0, (100.0, 20.0), 3.0, 2.0, 11)
        };
        let mut px = render(&drawn);
        // Light falling from 40 at the top to 160 at the bottom, on the backdrop and the band alike.
        for y in 0..256 {
            let shade = -60.0 + 120.0 * y as f64 / 255.0;
            for x in 0..256 {
                px[y * 256 + x] = (px[y * 256 + x] as f64 + shade).round().clamp(0.0, 255.0) as u8;
            }
        }
        assert_textured_level_at_edge_mean(&px, &drawn, -2.0);
    }

    /// A band darker than the backdrop in fewer than half of its columns (large grains, shading) does not have
    /// its level measured from its mean gray, however clear the step is there.
    #[test]
    fn a_band_darker_only_here_and_there_keeps_its_line() {
        let mut px = band(170.3, 0.0, (95.0, 20.0), 0.0, 2.0, 9);
        // Darken the band in six of the sixteen blocks.
        for y in 171..256 {
            for x in 160..256 {
                px[y * 256 + x] = px[y * 256 + x].saturating_sub(40);
            }
        }
        let img = Plane::new(&px, 256, 256);
        let line = SurfaceLine::given(127.5, 170.3, 0.0);
        assert!(mean_gray_level(&img, &line, None).is_none());
        // Darkened across the whole width, it is measured in every block.
        for y in 171..256 {
            for x in 0..160 {
                px[y * 256 + x] = px[y * 256 + x].saturating_sub(40);
            }
        }
        let img = Plane::new(&px, 256, 256);
        let s = mean_gray_level(&img, &line, None).expect("a clear step in every block");
        assert_eq!(s.blocks, 16);
    }

    /// A tilted line is followed: the blocks measure across it, not across the image's rows.
    #[test]
    fn a_tilted_band_s_level_is_measured_across_the_line() {
        let (y0, deg) = (160.6f64, 4.0f64);
        let slope = -deg.to_radians().tan();
        let px = band(y0, slope, (60.0, 15.0), 0.0, 2.0, 7);
        let img = Plane::new(&px, 256, 256);
        let line = SurfaceLine {
            slope,
            ..SurfaceLine::given(127.5, y0 - 1.5, 0.0)
        };
        let s = mean_gray_level(&img, &line, None).expect("a clear step");
        assert!((line.y0 + s.offset_px - y0).abs() < 0.1, "{s:?}");
    }

    /// Columns left out (the ball's) do not count, and too few blocks give no level.
    #[test]
    fn skipped_columns_do_not_count() {
        let px = band(170.3, 0.0, (60.0, 15.0), 0.0, 2.0, 8);
        let img = Plane::new(&px, 256, 256);
        let line = SurfaceLine::given(127.5, 171.0, 0.0);
        let all = mean_gray_level(&img, &line, None).unwrap();
        assert_eq!(all.blocks, 16);
        let some = mean_gray_level(&img, &line, Some((40.0, 200.0))).unwrap();
        assert_eq!(some.blocks, 5);
        assert!(mean_gray_level(&img, &line, Some((20.0, 220.0))).is_none());
    }
}
