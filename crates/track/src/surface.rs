//! The surface line: the top edge of the surface band, and its tilt in the image.
//!
//! Two cues, each a set of per-column edges through which a line is found (RANSAC over near-horizontal
//! lines, then least squares on the inliers; among well-supported lines the topmost, since the band's own
//! texture lies below its top edge and the ball only covers some columns):
//! - **brightness**: each sampled column's vertical brightness profile (averaged over a few neighbouring
//!   columns) gives its strongest steps. Precise (a tenth of a pixel) where the band differs from the
//!   backdrop in mean gray, of either polarity; cost ≈ 0.2 ms for 512×512.
//! - **texture**: the band's grains or weave against a smooth backdrop. The local energy of the horizontal
//!   gradient (imageproc filters: a central difference, then a box mean) changes by a large factor at the
//!   band's top even when its mean gray equals the backdrop's; each column's edge is where the log energy
//!   crosses half-way between the levels above and below. Cost ≈ 3 ms for 512×512.
//!
//! Where both find the band's top they agree to within its roughness and the brightness line is kept (it is
//! the sharper); where they disagree the topmost is taken and the other is returned as an alternative, so a
//! later stage can choose with the ball's own trajectory (unless the texture line is seen along clearly more
//! of the band: then it is kept). The roughness of the edge (the scatter of the column edges about the line)
//! is reported, and widens the line's stated uncertainty on a ragged band: its height's, by a uniform
//! (Type-B) term of ± twice the roughness whichever cue found it (the plane lies between the edge's mean and
//! its highest points), and its tilt's by a uniform tilt of up to ± the roughness over the line's
//! half-length, since how each column's edge is defined can drift smoothly across the frame where no column
//! statistic sees it.
//!
//! The tracker looks for the line in the mean of a clip's first frames (`Tracker`), where the noise is
//! smaller than in any one frame, and measures the found line's level again where half of each row is
//! covered by the band, from its mean gray or its texture ([`crate::level`]): both cues put a ragged edge's
//! line at its first grains, above its middle.

use crate::plane::{Pixel, Plane, parabola_offset};

/// A straight line across the image, `y = y0 + slope·(x − x0)` in px.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SurfaceLine {
    /// Reference column, px (the image's centre column).
    pub x0: f64,
    /// Height of the line at `x0`, px (y down).
    pub y0: f64,
    /// dy/dx.
    pub slope: f64,
    /// Standard error of `y0`, px.
    pub sigma_y0: f64,
    /// Standard error of the tilt, degrees.
    pub sigma_tilt_deg: f64,
    /// Columns that agree with the line.
    pub columns: usize,
    /// How much the line's height depends on how its edge is defined, px: the median over its columns of
    /// the distance between the narrowest difference's edge and the smoothed derivative's (a lit top edge
    /// makes them differ: 0.15–0.18 px on rendered clay, 0.01–0.06 on the tapes), and at least twice the
    /// edge's roughness (the plane lies between a ragged edge's mean and its highest points) for the lines
    /// [`find_surface_lines`] returns. The estimator takes it as the half-width of a uniform (Type-B)
    /// uncertainty of the contact level. 0 in lines stored before it.
    #[serde(default)]
    pub edge_definition_px: f64,
    /// RMS distance of the supporting columns' edges from the line, px: the band edge's raggedness (grains,
    /// fibres) plus the edge measurement's own scatter. 0 in lines stored before it.
    #[serde(default)]
    pub roughness_px: f64,
    /// Which cue found the line.
    #[serde(default)]
    pub cue: LineCue,
    /// How far the line's level was moved from where its cue found the band's edge, px (+ down): measured
    /// again from the band's mean gray or texture ([`crate::remeasured`]). 0 for a line kept where it was found.
    #[serde(default)]
    pub level_shift_px: f64,
}

/// What a surface line was found from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LineCue {
    /// A step in mean brightness at the band's top.
    #[default]
    Brightness,
    /// A change of texture (local gradient energy) at the band's top.
    Texture,
    /// Given by the user (`session.toml`/`clip.toml` or the command line), not measured.
    Given,
    /// Not seen in the image: one radius below where the ball's centre left its incoming free-flight arc
    /// (the estimator's contact level from the trajectory).
    Trajectory,
}

impl LineCue {
    /// Name as written in files.
    pub fn name(self) -> &'static str {
        match self {
            LineCue::Brightness => "brightness",
            LineCue::Texture => "texture",
            LineCue::Given => "given",
            LineCue::Trajectory => "trajectory",
        }
    }
}

impl SurfaceLine {
    /// The line's height at column `x`, px.
    pub fn y_at(&self, x: f64) -> f64 {
        self.y0 + self.slope * (x - self.x0)
    }

    /// Distance of the image point (x, y) above the line, px, along the line's normal.
    pub fn height_of(&self, x: f64, y: f64) -> f64 {
        (self.y_at(x) - y) / (1.0 + self.slope * self.slope).sqrt()
    }

    /// Tilt in the image, degrees, counter-clockwise as seen (a line rising to the right is positive).
    pub fn tilt_deg(&self) -> f64 {
        (-self.slope).atan().to_degrees()
    }

    /// A line given by the user: height `y0` px at column `x0`, tilt `tilt_deg` (counter-clockwise as seen),
    /// taken as exact.
    pub fn given(x0: f64, y0: f64, tilt_deg: f64) -> SurfaceLine {
        SurfaceLine {
            x0,
            y0,
            slope: -tilt_deg.to_radians().tan(),
            sigma_y0: 0.0,
            sigma_tilt_deg: 0.0,
            columns: 0,
            edge_definition_px: 0.0,
            roughness_px: 0.0,
            cue: LineCue::Given,
            level_shift_px: 0.0,
        }
    }

    /// The line turned about its point at column `pivot_x` to the tilt `tilt_deg` (counter-clockwise as
    /// seen), with that tilt's standard error; its height there, its reference column and everything else
    /// kept.
    pub fn turned_about(&self, pivot_x: f64, tilt_deg: f64, sigma_tilt_deg: f64) -> SurfaceLine {
        let slope = -tilt_deg.to_radians().tan();
        SurfaceLine {
            y0: self.y_at(pivot_x) + slope * (self.x0 - pivot_x),
            slope,
            sigma_tilt_deg,
            ..*self
        }
    }

    /// The standard error of the line's height as a contact level, px: its columns' scatter (`sigma_y0`)
    /// and its edge's definition as the half-width of a uniform (Type-B) term, in quadrature.
    pub fn level_sigma_px(&self) -> f64 {
        (self.sigma_y0.powi(2) + self.edge_definition_px.powi(2) / 3.0).sqrt()
    }

    /// Whether a disc centred at (x, y) with radius `r` px lies wholly above the line by 2 px beyond the
    /// band's ragged reach ([`Self::ragged_reach_px`]): a ball in free flight, clear of the surface.
    pub fn clears_disc(&self, x: f64, y: f64, r: f64) -> bool {
        self.height_of(x, y) > r + 2.0 + self.ragged_reach_px()
    }

    /// How far above the line the band's ragged edge may reach, px: twice its roughness beyond the
    /// pixel of scatter any measured edge has (0 for a clean edge), measured from where the cue found the
    /// edge when the level was moved down from it ([`Self::level_shift_px`]).
    pub fn ragged_reach_px(&self) -> f64 {
        (2.0 * self.roughness_px - 1.0).max(0.0) + self.level_shift_px.max(0.0)
    }

    /// The band's top at column `x`, px: the line, or where its cue found the edge when that is higher (the
    /// level moved down from it). What hides the ball's rim, as opposed to where it rests.
    pub fn top_at(&self, x: f64) -> f64 {
        self.y_at(x) - self.level_shift_px.max(0.0)
    }
}

/// The surface line chosen and the other candidates.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceLines {
    /// The line taken: the topmost candidate (below the ball, when its position is known).
    pub line: SurfaceLine,
    /// The other candidates below it, topmost first: a later stage may prefer one if the ball's trajectory
    /// says the contact is there.
    pub alternatives: Vec<SurfaceLine>,
}

/// How far above a candidate line the ball's centre must be, in radii, for the line to be the surface: in
/// flight its whole disc is above the surface, and even pressed into it the centre stays above 0.8 radii (a
/// tennis ball sinks 0.05–0.15). A ruler or a fixture's edge the ball crosses is not the surface.
const BALL_CLEARANCE_RADII: f64 = 0.8;

/// Column stride, px.
const STRIDE: usize = 4;
/// Columns averaged around each sampled column.
const HALF_BAND: usize = 4;
/// Largest tilt considered, as a slope (≈ 10°).
const MAX_SLOPE: f64 = 0.18;

/// Finds the surface line, or `None` if no long near-horizontal edge crosses the image (see
/// [`find_surface_lines`], whose chosen line this is).
pub fn find_surface_line<P: Pixel>(img: &Plane<P>) -> Option<SurfaceLine> {
    find_surface_lines(img, None).map(|l| l.line)
}

/// Finds the band's top by both cues (see the module's description): every candidate line, the topmost taken.
/// With the ball's position `(x, y, r)` px known, a line the ball's centre is not at least 0.8 radii above is
/// not the surface (a ruler, a fixture's edge or a shadow crossing the frame above the ball) and is left
/// out. Cost ≈ 3 ms for 512×512.
pub fn find_surface_lines<P: Pixel>(img: &Plane<P>, ball: Option<(f64, f64, f64)>) -> Option<SurfaceLines> {
    surface_lines_from(img, ball, crate::texture::texture_lines(img))
}

/// [`find_surface_lines`] with the texture cue's faint lines ([`crate::texture::faint_texture_lines`]),
/// made of the columns the ball (`ball` = (x, y, r) px) never covered while its centre's x ran over `span`:
/// for an image on which [`find_surface_lines`] found none, when nothing better will come. Cost as
/// [`find_surface_lines`].
pub fn find_faint_surface_lines<P: Pixel>(
    img: &Plane<P>,
    ball: (f64, f64, f64),
    span: (f64, f64),
) -> Option<SurfaceLines> {
    let r = ball.2;
    let texture = crate::texture::faint_texture_lines(img, Some((span.0 - r, span.1 + r)));
    surface_lines_from(img, Some(ball), texture)
}

fn surface_lines_from<P: Pixel>(
    img: &Plane<P>,
    ball: Option<(f64, f64, f64)>,
    texture: Vec<SurfaceLine>,
) -> Option<SurfaceLines> {
    let step = brightness_lines(img).into_iter().map(ragged).collect();
    let mut candidates: Vec<SurfaceLine> = merge_cues(step, texture, img.width)
        .into_iter()
        .filter(|l| ball.is_none_or(|(x, y, r)| l.height_of(x, y) >= BALL_CLEARANCE_RADII * r))
        .collect();
    if candidates.is_empty() {
        return None;
    }
    let line = candidates.remove(0);
    Some(SurfaceLines {
        line,
        alternatives: candidates,
    })
}

/// `line` with its edge definition at least twice its own roughness (before [`merge_cues`] lends it a
/// twin's), whichever cue found it: on a ragged edge the plane the ball rests on lies somewhere between the
/// edge's mean, where the line runs, and its highest grains or fibres, which no column statistic tells
/// apart. Both cues' lines are made so ([`brightness_lines`]' here, [`crate::texture::texture_lines`]' there).
pub(crate) fn ragged(line: SurfaceLine) -> SurfaceLine {
    SurfaceLine {
        edge_definition_px: line.edge_definition_px.abs().max(2.0 * line.roughness_px),
        ..line
    }
}

/// One list of candidates from both cues, topmost first: where a brightness line and a texture line see the
/// same edge (within 3 px plus twice the roughness) the brightness line is kept (it is the sharper) unless
/// the texture line is supported by more than 4/3 as many columns (a low-contrast band's weak step is seen
/// in few columns, and its tilt is then the poorer), with the larger roughness of the two; a line crossing a better-supported line of the other cue inside the frame
/// (`width` px wide) is dropped, as within a cue (two edges of a scene do not cross).
fn merge_cues(step: Vec<SurfaceLine>, texture: Vec<SurfaceLine>, width: usize) -> Vec<SurfaceLine> {
    let mut used = vec![false; texture.len()];
    let mut out: Vec<SurfaceLine> = Vec::new();
    for s in step {
        let twin = texture.iter().enumerate().find(|(i, t)| {
            !used[*i] && (s.y_at(s.x0) - t.y_at(s.x0)).abs() <= 3.0 + 2.0 * t.roughness_px.max(s.roughness_px)
        });
        match twin {
            Some((i, t)) => {
                used[i] = true;
                let kept = if 4 * s.columns >= 3 * t.columns { s } else { *t };
                out.push(SurfaceLine {
                    roughness_px: s.roughness_px.max(t.roughness_px),
                    ..kept
                });
            }
            None => out.push(s),
        }
    }
    out.extend(texture.into_iter().zip(used).filter(|(_, u)| !u).map(|(t, _)| t));
    let right = width.saturating_sub(1) as f64;
    let crosses =
        |a: &SurfaceLine, b: &SurfaceLine| (a.y_at(0.0) - b.y_at(0.0)) * (a.y_at(right) - b.y_at(right)) <= 0.0;
    out.sort_by_key(|l| std::cmp::Reverse(l.columns));
    let mut kept: Vec<SurfaceLine> = Vec::new();
    for line in out {
        if !kept.iter().any(|k| k.cue != line.cue && crosses(k, &line)) {
            kept.push(line);
        }
    }
    kept.sort_by(|a, b| a.y_at(a.x0).total_cmp(&b.y_at(b.x0)));
    kept
}

/// The lines of the strongest brightness steps (the brightness cue), topmost first.
fn brightness_lines<P: Pixel>(img: &Plane<P>) -> Vec<SurfaceLine> {
    let (w, h) = (img.width, img.height);
    if w < 16 || h < 16 {
        return Vec::new();
    }
    // Per sampled column: the strongest edges (position with sub-pixel offset, strength).
    let mut cands: Vec<(f64, f64, f64)> = Vec::new(); // (x, y, strength)
    // Per candidate: its edge less the smoothed derivative's (see `SurfaceLine::edge_definition_px`).
    let mut leans: Vec<f64> = Vec::new();
    let mut prof = vec![0.0f32; h];
    let cols: Vec<usize> = (HALF_BAND..w - HALF_BAND).step_by(STRIDE).collect();
    for &x in &cols {
        for (y, p) in prof.iter_mut().enumerate() {
            *p = (x - HALF_BAND..=x + HALF_BAND).map(|xx| img.at(xx, y)).sum::<f32>() / (2 * HALF_BAND + 1) as f32;
        }
        // Smoothed derivative over ±2 rows.
        let d: Vec<f32> = (0..h)
            .map(|y| {
                if y < 2 || y + 2 >= h {
                    0.0
                } else {
                    (prof[y + 1] + prof[y + 2]) - (prof[y - 1] + prof[y - 2])
                }
            })
            .collect();
        let mut peaks: Vec<(usize, f32)> = (3..h - 3)
            .filter(|&y| d[y].abs() >= d[y - 1].abs() && d[y].abs() > d[y + 1].abs())
            .map(|y| (y, d[y].abs()))
            .collect();
        peaks.sort_by(|a, b| b.1.total_cmp(&a.1));
        for &(y, s) in peaks.iter().take(6) {
            let edge = sub_pixel_edge(&prof, y);
            cands.push((x as f64, edge, s as f64));
            leans.push(edge - smoothed_edge(&d, y));
        }
    }
    lines_through(&cands, &leans, cols.len(), w, 1.5, 0.0, 0.3)
}

/// The well-supported, strong lines through per-column edge candidates `(x, y, strength)` (in column
/// order), topmost first: RANSAC over pairs from distant columns (deterministic sampling), lines within `tol`
/// px of at least half of the `columns` sampled (and half the best line's support: a hand or a fixture may
/// hide part of the band's top where a ruler crosses the whole frame), strong = mean strength at least
/// `relative_strength` × the strongest such line's and at least `min_strength`; of lines closer than 2 × `tol`
/// the best supported stands for them all (one edge seen through the tolerance band), and a line crossing a
/// better supported one inside the frame is dropped; each refined by least squares on its inliers. `leans[i]` is candidate i's
/// edge definition (see [`SurfaceLine::edge_definition_px`]).
pub(crate) fn lines_through(
    cands: &[(f64, f64, f64)],
    leans: &[f64],
    columns: usize,
    w: usize,
    tol: f64,
    min_strength: f64,
    relative_strength: f64,
) -> Vec<SurfaceLine> {
    let mut lines: Vec<(f64, f64, f64, f64)> = Vec::new(); // (support, y at x=0, slope, mean strength)
    let n = cands.len();
    if n < 8 {
        return Vec::new();
    }
    let mut state = 0x9E3779B97F4A7C15u64;
    let mut next = |m: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % m as u64) as usize
    };
    for _ in 0..600 {
        let (i, j) = (next(n), next(n));
        let (a, b) = (cands[i], cands[j]);
        if (a.0 - b.0).abs() < w as f64 * 0.25 {
            continue;
        }
        let slope = (b.1 - a.1) / (b.0 - a.0);
        if slope.abs() > MAX_SLOPE {
            continue;
        }
        let c = a.1 - slope * a.0;
        let (support, strength) = column_support(cands, c, slope, tol);
        lines.push((support, c, slope, strength));
    }
    let best = lines.iter().map(|l| l.0).fold(0.0, f64::max);
    if best < 0.5 * columns as f64 {
        return Vec::new();
    }
    // A line must also be strong: the 8-bit steps of a smooth backdrop gradient are perfectly straight and
    // consistent across columns, but weak.
    let supported = |l: &(f64, f64, f64, f64)| l.0 >= 0.5 * best && l.0 >= 0.5 * columns as f64;
    let strongest = lines.iter().filter(|l| supported(l)).map(|l| l.3).fold(0.0, f64::max);
    let xc = (w as f64 - 1.0) / 2.0;
    let mut good: Vec<(f64, f64, f64, f64)> = lines
        .into_iter()
        .filter(|l| supported(l) && l.3 >= relative_strength * strongest && l.3 >= min_strength)
        .collect();
    // Of hypotheses within a tolerance band of each other (one edge seen through ±tol), the best supported
    // stands for them all: a weaker one a few px off would otherwise win by being higher.
    good.sort_by(|a, b| b.0.total_cmp(&a.0));
    let wf = w as f64;
    let mut kept: Vec<(f64, f64)> = Vec::new();
    let mut out: Vec<SurfaceLine> = Vec::new();
    for (_, c, slope, _) in good {
        let same =
            |k: &(f64, f64)| (k.0 - c).abs() <= 2.0 * tol && (k.0 + k.1 * wf - c - slope * wf).abs() <= 2.0 * tol;
        if kept.iter().any(same) {
            continue;
        }
        kept.push((c, slope));
        // Two edges of a scene (a band's top, a tape on it) do not cross inside the frame: a line that crosses a
        // better supported one there is made of its points and stray ones.
        let crosses = |o: &SurfaceLine, l: &SurfaceLine| {
            let gap = |x: f64| l.y_at(x) - o.y_at(x);
            gap(0.0) * gap(wf - 1.0) <= 0.0
        };
        if let Some(line) = refine_line(cands, leans, c, slope, tol, xc)
            && !out.iter().any(|o| {
                ((o.y0 - line.y0).abs() <= tol && (o.slope - line.slope).abs() * wf <= tol) || crosses(o, &line)
            })
        {
            out.push(line);
        }
    }
    // Topmost first.
    out.sort_by(|a, b| a.y0.total_cmp(&b.y0));
    out
}

/// The edge at the smoothed derivative `d`'s peak row `y`, to a fraction of a row: a parabola through
/// |d| at rows y−1, y, y+1.
fn smoothed_edge(d: &[f32], y: usize) -> f64 {
    let a = |k: usize| d[k].abs() as f64;
    y as f64 + parabola_offset(a(y - 1), a(y), a(y + 1))
}

/// The edge at row `y` of a column profile (the smoothed derivative's peak), to a fraction of a row: a
/// parabola through the narrowest central differences |p[k+1] − p[k−1]| at rows y−1, y, y+1.
///
/// The smoothed derivative finds the edge among the texture, but it mixes in the brightness slopes on either
/// side: a band whose top edge catches the light (brighter just below the edge, fading over a few rows)
/// pulls its peak up by about a third of a row, the narrowest difference by half as much. The row stays
/// the smoothed derivative's, since the narrow difference's own peak wanders on a weak edge in texture.
fn sub_pixel_edge(prof: &[f32], y: usize) -> f64 {
    let n = |k: usize| (prof[k + 1] - prof[k - 1]).abs() as f64;
    // n(k ± 1) reads rows k − 2 … k + 2.
    let k = y.clamp(2, prof.len() - 3);
    k as f64 + parabola_offset(n(k - 1), n(k), n(k + 1))
}

/// The variance of a line's slope that the definition of its edge adds, beyond the columns' scatter: what
/// one column takes for the edge (its steepest step, or the texture's half-way point) can differ from the
/// band's top by a fraction of the edge's roughness, and differ smoothly across the frame where the
/// lighting, vignetting or weave changes the edge's profile. No column statistic sees such a trend; it is
/// taken as a uniform (Type-B) tilt of up to ± `roughness_px` over the line's `half_span_px`.
pub(crate) fn definition_slope_var(roughness_px: f64, half_span_px: f64) -> f64 {
    (roughness_px / half_span_px.max(1.0)).powi(2) / 3.0
}

/// Number of distinct columns with a candidate within `tol` of the line, and their mean edge strength.
fn column_support(cands: &[(f64, f64, f64)], c: f64, slope: f64, tol: f64) -> (f64, f64) {
    let mut last_x = f64::NAN;
    let (mut count, mut strength) = (0.0, 0.0);
    for &(x, y, s) in cands {
        if (y - (c + slope * x)).abs() <= tol && x != last_x {
            count += 1.0;
            strength += s;
            last_x = x;
        }
    }
    (count, if count > 0.0 { strength / count } else { 0.0 })
}

fn refine_line(
    cands: &[(f64, f64, f64)],
    leans: &[f64],
    mut c: f64,
    mut slope: f64,
    tol: f64,
    xc: f64,
) -> Option<SurfaceLine> {
    let mut result = None;
    for _ in 0..3 {
        // One point per column (the nearest to the line), however many edges the column gave near it.
        let off = |i: usize| (cands[i].1 - (c + slope * cands[i].0)).abs();
        let mut inliers: Vec<usize> = Vec::new();
        for i in (0..cands.len()).filter(|&i| off(i) <= tol) {
            match inliers.last_mut() {
                Some(last) if cands[*last].0 == cands[i].0 => {
                    if off(i) < off(*last) {
                        *last = i;
                    }
                }
                _ => inliers.push(i),
            }
        }
        let pts: Vec<(f64, f64)> = inliers.iter().map(|&i| (cands[i].0 - xc, cands[i].1)).collect();
        let mut lean: Vec<f64> = inliers.iter().map(|&i| leans[i].abs()).collect();
        let n = pts.len() as f64;
        if n < 4.0 {
            return None;
        }
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        slope = sxy / sxx;
        let y0 = my - slope * mx;
        c = y0 - slope * xc;
        let res: Vec<f64> = pts.iter().map(|p| p.1 - (y0 + slope * p.0)).collect();
        let rss: f64 = res.iter().map(|r| r * r).sum();
        // Neighbouring columns share texture (each sample averages 2·HALF_BAND + 1 columns, grains and
        // roughness span several): the residuals are correlated along the line, and the standard errors
        // of independent residuals would be too small (3× on grainy clay). An AR(1) inflation from the
        // lag-one correlation of the residuals in column order (n_eff = n·(1 − ρ)/(1 + ρ)).
        let lag1: f64 = res.windows(2).map(|w| w[0] * w[1]).sum();
        let rho = if rss > 0.0 { (lag1 / rss).clamp(0.0, 0.95) } else { 0.0 };
        let inflation = (1.0 + rho) / (1.0 - rho);
        let s2 = inflation * rss / (n - 2.0).max(1.0);
        let roughness = (rss / n).sqrt();
        let half_span = 0.5 * (pts.last().map_or(0.0, |p| p.0) - pts.first().map_or(0.0, |p| p.0));
        let sigma_slope = (s2 / sxx + definition_slope_var(roughness, half_span)).sqrt();
        result = Some(SurfaceLine {
            x0: xc,
            y0,
            slope,
            sigma_y0: (s2 * (1.0 / n + mx * mx / sxx)).sqrt(),
            sigma_tilt_deg: sigma_slope.atan().to_degrees(),
            columns: pts.len(),
            edge_definition_px: {
                let mid = lean.len() / 2;
                *lean.select_nth_unstable_by(mid, f64::total_cmp).1
            },
            roughness_px: roughness,
            cue: LineCue::Brightness,
            level_shift_px: 0.0,
        });
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{Scene, render};

    /// A column crossing a band's top edge at row `e`: backdrop 70 above; below, a band of 90 whose top
    /// `lip` rows catch the light (up to +12, fading linearly); the edge's coverage ramps over one row.
    fn column(e: f64, lip: f64) -> Vec<f32> {
        (0..40)
            .map(|y| {
                let y = y as f64;
                let cover = (y - e + 0.5).clamp(0.0, 1.0);
                let depth = (y - e).max(0.0);
                let band = 90.0
                    + if lip > 0.0 {
                        12.0 * (1.0 - depth / lip).max(0.0)
                    } else {
                        0.0
                    };
                (70.0 * (1.0 - cover) + band * cover) as f32
            })
            .collect()
    }

    fn line(y0: f64, tilt_deg: f64, columns: usize, cue: LineCue) -> SurfaceLine {
        SurfaceLine {
            columns,
            cue,
            ..SurfaceLine::given(255.5, y0, tilt_deg)
        }
    }

    #[test]
    fn a_turned_line_keeps_its_height_at_the_pivot() {
        let l = line(300.0, 0.8, 40, LineCue::Texture);
        let t = l.turned_about(180.0, -0.4, 0.3);
        assert!((t.y_at(180.0) - l.y_at(180.0)).abs() < 1e-9);
        assert!((t.tilt_deg() + 0.4).abs() < 1e-12 && t.sigma_tilt_deg == 0.3);
        assert_eq!((t.x0, t.columns, t.cue), (l.x0, l.columns, l.cue));
        // 1.2° of turn over 75.5 px from the pivot to the reference column.
        let moved = t.y0 - l.y0;
        let expected = 75.5 * ((0.8f64.to_radians()).tan() + (0.4f64.to_radians()).tan());
        assert!((moved - expected).abs() < 1e-9, "{moved} vs {expected}");
    }

    /// A texture line crossing a better-supported brightness line inside the frame is not an edge of the
    /// scene, however high it lies; one that does not cross it stays, topmost first.
    #[test]
    fn a_line_crossing_a_better_one_of_the_other_cue_is_dropped() {
        let flat = line(265.0, -0.6, 81, LineCue::Brightness);
        let crossing = line(255.0, 3.2, 68, LineCue::Texture);
        let parallel = line(250.0, -0.5, 60, LineCue::Texture);
        let merged = merge_cues(vec![flat], vec![crossing, parallel], 512);
        let ys: Vec<f64> = merged.iter().map(|l| l.y0).collect();
        assert_eq!(ys, vec![250.0, 265.0]);
        // The better-supported line of the two stands, whichever cue found it.
        let merged = merge_cues(
            vec![line(265.0, -0.6, 40, LineCue::Brightness)],
            vec![line(255.0, 3.2, 68, LineCue::Texture)],
            512,
        );
        assert_eq!(merged.len(), 1);
        assert_eq!(merged[0].cue, LineCue::Texture);
    }

    /// Where both cues see the same edge, the line kept is the brightness cue's unless the texture cue saw
    /// the edge along clearly more of the band (a low-contrast band's weak step, found in a few columns).
    #[test]
    fn of_two_cues_seeing_one_edge_the_better_supported_is_kept() {
        let texture = line(200.4, 0.5, 90, LineCue::Texture);
        let merged = merge_cues(vec![line(201.0, -0.3, 46, LineCue::Brightness)], vec![texture], 512);
        assert_eq!(merged.len(), 1);
        assert_eq!(merged[0].cue, LineCue::Texture);
        let merged = merge_cues(vec![line(201.0, -0.3, 70, LineCue::Brightness)], vec![texture], 512);
        assert_eq!(merged.len(), 1);
        assert_eq!(merged[0].cue, LineCue::Brightness);
    }

    #[test]
    fn a_plain_step_is_found_to_a_small_fraction_of_a_row() {
        for e in [20.0, 20.25, 20.5, 20.8] {
            let p = column(e, 0.0);
            let y = sub_pixel_edge(&p, e.round() as usize);
            assert!((y - e).abs() < 0.1, "{y} vs {e}");
        }
    }

    #[test]
    fn a_lit_lip_pulls_the_edge_less_than_a_smoothed_derivative_does() {
        let e = 20.0;
        let p = column(e, 2.5);
        let y = sub_pixel_edge(&p, 20);
        // The four-row smoothed derivative's parabola puts this edge 0.28 rows high.
        let d = |k: usize| ((p[k + 1] + p[k + 2]) - (p[k - 1] + p[k - 2])).abs() as f64;
        let (a0, a1, a2) = (d(19), d(20), d(21));
        let smoothed = 20.0 + 0.5 * (a0 - a2) / (a0 - 2.0 * a1 + a2);
        assert!((smoothed - e).abs() > 0.25, "{smoothed}");
        assert!((y - e).abs() < 0.2, "{y}");
    }

    /// A step in brightness at a ragged edge: the line's stated level error holds the edge's raggedness
    /// (its edge definition at least twice its roughness), and covers where the edge was drawn.
    #[test]
    fn a_ragged_step_s_level_error_holds_its_roughness() {
        for seed in 1..=6u64 {
            let y0 = 180.3 + 0.1 * seed as f64;
            let s = Scene {
                surface: Some((y0, 0.01)),
                backdrop: (95.0, 95.0),
                band: (140.0, 4.0),
                roughness: 2.0,
                noise: 3.0,
                seed,
                ..Scene::default()
            };
            let px = render(&s);
            let line = find_surface_line(&Plane::new(&px, 256, 256)).expect("a line");
            assert_eq!(line.cue, LineCue::Brightness, "{line:?}");
            assert!(line.roughness_px > 0.3, "{line:?}");
            assert!(line.edge_definition_px >= 2.0 * line.roughness_px, "{line:?}");
            let sigma = line.level_sigma_px();
            assert!((line.y0 - y0).abs() <= 3.0 * sigma, "{} vs {y0} ± {sigma}", line.y0);
        }
    }

    /// The line's edge definition is what the two edges disagree by: about nothing on a plain step, a
    /// tenth of a row or more under a lit lip.
    #[test]
    fn the_line_reports_how_much_its_edge_depends_on_the_definition() {
        let line = |lip: f64| {
            let col = column(20.3, lip);
            let (w, h) = (64, col.len());
            let data: Vec<f32> = (0..w * h).map(|i| col[i / w]).collect();
            let px: Vec<u16> = data.iter().map(|v| (v * 257.0).round() as u16).collect();
            find_surface_line(&Plane::new(&px, w, h)).expect("a line")
        };
        let (plain, lit) = (line(0.0), line(2.5));
        assert!(plain.edge_definition_px < 0.03, "{plain:?}");
        assert!(lit.edge_definition_px > 0.1, "{lit:?}");
        assert!((plain.y0 - 20.3).abs() < 0.1, "{plain:?}");
    }

    /// A ball over a plain backdrop makes no faint line, whatever the noise: its rim lines up with weak noise
    /// steps beside it (a clear-line search takes such a line on a few of these frames at 1 DN), so the faint
    /// search leaves its columns out.
    #[test]
    fn a_ball_over_a_plain_backdrop_makes_no_faint_line() {
        let mut found = Vec::new();
        for noise in [1.0, 2.0, 4.0, 8.0] {
            for seed in 1..=30u64 {
                for (backdrop, ball_level) in [((95.0, 95.0), 200.0), ((70.0, 110.0), 60.0), ((120.0, 60.0), 100.0)] {
                    let ball = (120.3 + seed as f64, 90.7 + 2.0 * seed as f64, 30.0 + seed as f64);
                    let s = Scene {
                        noise,
                        seed,
                        ball,
                        backdrop,
                        ball_level,
                        ..Scene::default()
                    };
                    let px = render(&s);
                    if let Some(l) = find_faint_surface_lines(&Plane::new(&px, 256, 256), ball, (ball.0, ball.0)) {
                        found.push((noise, seed, l.line.y0));
                    }
                }
            }
        }
        assert!(found.is_empty(), "faint lines where there is no band: {found:?}");
    }
}
