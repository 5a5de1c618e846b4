//! The texture cue of the surface line: where the image turns from a smooth backdrop to the band's grains
//! or weave, whatever the two mean grays are.
//!
//! The local energy of the horizontal gradient — the mean of |I(x+1, y) − I(x−1, y)| over a 9 × 3 px box,
//! computed with imageproc's separable filters — is the sensor's noise on a plain backdrop and several times
//! that on clay grains or a woven tape. Each sampled column's log energy profile is searched for steps
//! (the difference of the means of six rows below and six above, in units of the column's own robust
//! scatter of that difference), and each step's edge is placed where the energy crosses half-way between
//! the levels on either side. Horizontal gradients ignore the band's own brightness step, so this cue
//! does not see what the brightness cue sees: the two are independent. A line found through those edges is
//! refitted with Tukey's biweight, since a ragged band's edges wander and spike. The 9-column box that
//! makes a column's step clear also blurs where it lies (a grain four columns away moves it), so the line's
//! tilt is then measured again in every column, near it, on a finer map: the energy of both gradients over a
//! 3 × 3 box ([`fine_edges`]). Cost ≈ 3 ms for 512×512 (three filter passes over the frame), plus five
//! filter passes over the rows within reach of each line found.

use crate::plane::{Pixel, Plane, median};
use crate::surface::{LineCue, SurfaceLine, definition_slope_var, lines_through};
use imageproc::image::{ImageBuffer, Luma};

/// Column stride, px.
const STRIDE: usize = 4;
/// Half-width of the box the energy is averaged over, px (9 columns).
const HALF_BOX: usize = 4;
/// Rows on either side whose mean log energy a step compares.
const STEP_ROWS: usize = 6;
/// Steps kept per column.
const PEAKS: usize = 8;
/// Least mean strength of a line's steps, in units of each column's robust scatter of the step measure.
const MIN_STRENGTH: f64 = 5.0;
/// The same for a faint line ([`faint_texture_lines`]), looked for only when no line was found otherwise.
const FAINT_MIN_STRENGTH: f64 = 3.0;
/// How far a column's edge may lie from a line and still support it, px: the edge of a ragged band
/// wanders by a few px (grains, fibres) about its mean line.
const TOLERANCE_PX: f64 = 4.0;
/// Energy added before taking logs, on the 0–255 scale: keeps a saturated or perfectly flat area finite.
const ENERGY_FLOOR: f32 = 0.25;
/// How far above and below a found line the fine map is searched for each column's edge, px; its levels on
/// either side are the medians of the rows from `FINE_LEVEL_GAP_PX` to this far off the line.
const FINE_REACH_PX: f64 = 24.0;
/// Rows next to the line left out of the fine map's levels, px: a ragged edge's grains reach this far.
const FINE_LEVEL_GAP_PX: f64 = 10.0;
/// Least difference of a column's two fine levels, in natural log units of energy (a third more texture on
/// one side): below it the column does not tell the band from the backdrop and gives no edge.
const FINE_MIN_STEP: f32 = 0.3;
/// Rows in a row past half-way that make a column's edge: one noisy row is not the band.
const FINE_RUN_ROWS: usize = 3;

type Gray32 = ImageBuffer<Luma<f32>, Vec<f32>>;

/// The local energy of the horizontal gradient: mean |∂I/∂x| (central difference, 0–255 scale per 2 px)
/// over a 9 × 3 box around each pixel. Cost: three filter passes, O(width × height × 15).
pub fn horizontal_gradient_energy<P: Pixel>(img: &Plane<P>) -> Vec<f32> {
    let (w, h) = (img.width as u32, img.height as u32);
    let gray: Gray32 = ImageBuffer::from_fn(w, h, |x, y| Luma([img.at(x as usize, y as usize)]));
    let mut grad = imageproc::filter::horizontal_filter(&gray, &[-1.0f32, 0.0, 1.0]);
    for p in grad.pixels_mut() {
        p.0[0] = p.0[0].abs();
    }
    let across = [1.0f32 / (2 * HALF_BOX + 1) as f32; 2 * HALF_BOX + 1];
    let energy = imageproc::filter::horizontal_filter(&grad, &across);
    let energy = imageproc::filter::vertical_filter(&energy, &[1.0f32 / 3.0; 3]);
    energy.into_raw()
}

/// The topmost line of the texture cue (see [`texture_lines`]), or `None`.
pub fn texture_line<P: Pixel>(img: &Plane<P>) -> Option<SurfaceLine> {
    texture_lines(img).into_iter().next()
}

/// The long near-horizontal changes of texture across the image, topmost first. Each line's
/// `edge_definition_px` is twice its roughness (`surface::ragged`): on a ragged band the plane the
/// ball rests on lies somewhere between the edge's mean and its highest grains.
pub fn texture_lines<P: Pixel>(img: &Plane<P>) -> Vec<SurfaceLine> {
    lines_of_strength(img, MIN_STRENGTH, None)
}

/// [`texture_lines`] with steps down to 3 rather than 5 robust scatters on average, made only of the
/// columns outside `unseen` (an x range, px: where the ball passed). A band whose grains barely
/// out-texture the backdrop (a clay band within a few DN of it) still changes the texture in most columns
/// at one height, each weakly. A caller asks for these only when no line was found otherwise, on its
/// best-averaged image, and checks them against other evidence (the tracker takes one only from its full
/// stack of frames; the estimator keeps a line only where the ball's trajectory agrees). The ball's own
/// rim, whose horizontal gradients change along it, lines up with weak noise steps beside it into a line
/// this weak, hence the columns it crossed are left out; noise alone does not line up (a line still needs
/// half the remaining columns within 4 px). Cost as [`texture_lines`].
pub fn faint_texture_lines<P: Pixel>(img: &Plane<P>, unseen: Option<(f64, f64)>) -> Vec<SurfaceLine> {
    lines_of_strength(img, FAINT_MIN_STRENGTH, unseen)
}

fn lines_of_strength<P: Pixel>(img: &Plane<P>, min_strength: f64, unseen: Option<(f64, f64)>) -> Vec<SurfaceLine> {
    let (w, h) = (img.width, img.height);
    if w < 4 * HALF_BOX || h < 4 * STEP_ROWS + 8 {
        return Vec::new();
    }
    let energy = horizontal_gradient_energy(img);
    let seen = |x: usize| unseen.is_none_or(|(lo, hi)| (x as f64) < lo || (x as f64) > hi);
    let cols: Vec<usize> = (HALF_BOX + 1..w - HALF_BOX - 1)
        .step_by(STRIDE)
        .filter(|&x| seen(x))
        .collect();
    let cands = column_edges(&energy, w, h, &cols);
    let leans = vec![0.0; cands.len()];
    let mut lines: Vec<SurfaceLine> = lines_through(&cands, &leans, cols.len(), w, TOLERANCE_PX, min_strength, 0.0)
        .into_iter()
        .map(|line| robust_refit(&cands, line, MAX_LAG))
        .map(|line| refit_on_fine_edges(img, line, &seen))
        .map(|line| {
            crate::surface::ragged(SurfaceLine {
                cue: LineCue::Texture,
                ..line
            })
        })
        .collect();
    // The refit moves a line by up to a few px: topmost first again.
    lines.sort_by(|a, b| a.y0.total_cmp(&b.y0));
    lines
}

/// Each sampled column's edges on the coarse map `energy` (`w × h`, [`horizontal_gradient_energy`]):
/// `(x, y, strength)` for its strongest steps ([`column_steps`], [`half_way_edge`]), in column order.
fn column_edges(energy: &[f32], w: usize, h: usize, cols: &[usize]) -> Vec<(f64, f64, f64)> {
    let mut cands = Vec::new();
    let mut profile = vec![0.0f32; h];
    for &x in cols {
        for (y, p) in profile.iter_mut().enumerate() {
            *p = (energy[y * w + x] + ENERGY_FLOOR).ln();
        }
        for (y, strength) in column_steps(&profile) {
            if let Some(edge) = half_way_edge(&profile, y) {
                cands.push((x as f64, edge, strength));
            }
        }
    }
    cands
}

/// How far a column's edge may lie from a line, in robust scales of the edges' scatter, and still weigh in
/// its fit (Tukey's biweight constant: 95 % efficiency for normal scatter).
const BIWEIGHT_C: f64 = 4.685;
/// Lags over which the edges' scatter along the line is taken to be correlated at most, in sampled columns
/// (64 px; the fine edges of every column are given `STRIDE` times as many lags, the same span).
const MAX_LAG: usize = 16;

/// The line refitted to its columns' edges with Tukey's biweight (iteratively reweighted least squares,
/// scale from the median absolute deviation): a ragged band's edge wanders, and its grains or fibres reach
/// above it in spikes, so the RANSAC line's fixed tolerance band would take some spikes and leave others,
/// tilting the line. Each column's edge nearest the line within three tolerances is used. The standard
/// errors count the edges' correlation along the line (a grain or bump spans several sampled columns):
/// the residuals' integrated autocorrelation time over up to `MAX_LAG` lags divides the number of columns.
fn robust_refit(cands: &[(f64, f64, f64)], line: SurfaceLine, max_lag: usize) -> SurfaceLine {
    let xc = line.x0;
    let (mut y0, mut slope) = (line.y0, line.slope);
    let mut out = line;
    for _ in 0..6 {
        let pts = nearest_per_column(cands, y0, slope, xc, 3.0 * TOLERANCE_PX);
        if pts.len() < 8 {
            return line;
        }
        let res: Vec<f64> = pts.iter().map(|p| p.1 - (y0 + slope * p.0)).collect();
        let scale = (1.4826 * median(&mut res.iter().map(|r| r.abs()).collect::<Vec<_>>())).max(0.25);
        let wts: Vec<f64> = res
            .iter()
            .map(|r| (1.0 - (r / (BIWEIGHT_C * scale)).powi(2)).max(0.0).powi(2))
            .collect();
        let sw: f64 = wts.iter().sum();
        if sw < 4.0 {
            return line;
        }
        let mx = pts.iter().zip(&wts).map(|(p, w)| w * p.0).sum::<f64>() / sw;
        let my = pts.iter().zip(&wts).map(|(p, w)| w * p.1).sum::<f64>() / sw;
        let sxx: f64 = pts.iter().zip(&wts).map(|(p, w)| w * (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().zip(&wts).map(|(p, w)| w * (p.0 - mx) * (p.1 - my)).sum();
        slope = sxy / sxx;
        y0 = my - slope * mx;
        let res: Vec<f64> = pts.iter().map(|p| p.1 - (y0 + slope * p.0)).collect();
        let wrss: f64 = res.iter().zip(&wts).map(|(r, w)| w * r * r).sum();
        let used = wts.iter().filter(|w| **w > 0.0).count() as f64;
        let tau = autocorrelation_time(&res, &wts, max_lag);
        let s2 = tau * wrss / (sw * (1.0 - 2.0 / used.max(3.0)));
        let span = pts.iter().zip(&wts).filter(|(_, w)| **w > 0.0).map(|(p, _)| p.0);
        let half_span = 0.5 * (span.clone().fold(f64::NEG_INFINITY, f64::max) - span.fold(f64::INFINITY, f64::min));
        let rough = (wrss / sw).sqrt();
        let sigma_slope = (s2 / sxx + definition_slope_var(rough, half_span)).sqrt();
        out = SurfaceLine {
            x0: xc,
            y0,
            slope,
            sigma_y0: (s2 * (1.0 / sw + mx * mx / sxx)).sqrt(),
            sigma_tilt_deg: sigma_slope.atan().to_degrees(),
            roughness_px: rough,
            ..line
        };
    }
    out
}

/// Per sampled column, the edge nearest the line `y = y0 + slope·(x − xc)` within `window` px, as
/// `(x − xc, y)`.
fn nearest_per_column(cands: &[(f64, f64, f64)], y0: f64, slope: f64, xc: f64, window: f64) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = Vec::new();
    let off = |p: &(f64, f64)| (p.1 - (y0 + slope * p.0)).abs();
    for &(x, y, _) in cands {
        let p = (x - xc, y);
        if off(&p) > window {
            continue;
        }
        match pts.last_mut() {
            Some(last) if last.0 == p.0 => {
                if off(&p) < off(last) {
                    *last = p;
                }
            }
            _ => pts.push(p),
        }
    }
    pts
}

/// The integrated autocorrelation time of weighted residuals in column order, 1 + 2·Σ ρ_k over lags
/// 1…`max_lag`, stopping at the first lag whose correlation is not positive; at least 1.
fn autocorrelation_time(res: &[f64], wts: &[f64], max_lag: usize) -> f64 {
    let r: Vec<f64> = res.iter().zip(wts).map(|(r, w)| r * w.sqrt()).collect();
    let c0: f64 = r.iter().map(|v| v * v).sum();
    if c0 <= 0.0 {
        return 1.0;
    }
    let mut tau = 1.0;
    for k in 1..=max_lag.min(r.len().saturating_sub(2)) {
        let rho = r.windows(k + 1).map(|w| w[0] * w[k]).sum::<f64>() / c0;
        if rho <= 0.0 {
            break;
        }
        tau += 2.0 * rho;
    }
    tau
}

/// The log of the local energy of both gradients over rows `top .. bottom` of an image: ln(mean over a
/// 3 × 3 box of |∂I/∂x| + |∂I/∂y| + the floor), central differences on the 0–255 scale. The band's
/// brightness step adds to it where the texture does, at the same edge.
struct FineMap {
    log_energy: Vec<f32>,
    width: usize,
    top: usize,
    bottom: usize,
}

impl FineMap {
    /// The map of `img`'s rows `top .. bottom` (clamped to the image), computed from two more rows on each
    /// side so that the box and the differences see the same pixels as over the whole frame. Cost: five
    /// filter passes over those rows, O(width × rows × 15).
    fn new<P: Pixel>(img: &Plane<P>, top: usize, bottom: usize) -> FineMap {
        let (w, h) = (img.width, img.height);
        let (top, bottom) = (top.min(h), bottom.min(h).max(top.min(h)));
        if top == bottom {
            return FineMap {
                log_energy: Vec::new(),
                width: w,
                top,
                bottom,
            };
        }
        let (lo, hi) = (top.saturating_sub(2), (bottom + 2).min(h));
        let gray: Gray32 = ImageBuffer::from_fn(w as u32, (hi - lo) as u32, |x, y| {
            Luma([img.at(x as usize, lo + y as usize)])
        });
        let gx = imageproc::filter::horizontal_filter(&gray, &[-1.0f32, 0.0, 1.0]);
        let gy = imageproc::filter::vertical_filter(&gray, &[-1.0f32, 0.0, 1.0]);
        let sum: Gray32 = ImageBuffer::from_fn(gray.width(), gray.height(), |x, y| {
            Luma([gx.get_pixel(x, y).0[0].abs() + gy.get_pixel(x, y).0[0].abs()])
        });
        let third = [1.0f32 / 3.0; 3];
        let boxed = imageproc::filter::horizontal_filter(&sum, &third);
        let boxed = imageproc::filter::vertical_filter(&boxed, &third);
        let raw = boxed.into_raw();
        let log_energy = raw[(top - lo) * w..(bottom - lo) * w]
            .iter()
            .map(|e| (e + ENERGY_FLOOR).ln())
            .collect();
        FineMap {
            log_energy,
            width: w,
            top,
            bottom,
        }
    }

    /// The map of the rows a line can reach: `FINE_REACH_PX` above and below it across the image.
    fn around<P: Pixel>(img: &Plane<P>, line: &SurfaceLine) -> FineMap {
        let ends = [line.y_at(0.0), line.y_at(img.width as f64 - 1.0)];
        let lo = ends.iter().fold(f64::INFINITY, |a, &b| a.min(b)) - FINE_REACH_PX - 1.0;
        let hi = ends.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b)) + FINE_REACH_PX + 2.0;
        FineMap::new(img, lo.max(0.0) as usize, hi.max(0.0) as usize)
    }

    fn at(&self, x: usize, y: usize) -> f32 {
        self.log_energy[(y - self.top) * self.width + x]
    }
}

/// Every column's edge near `line` on the fine map, as `(x, y, 1)`: the levels above and below are the
/// medians of the column's rows `FINE_LEVEL_GAP_PX` to `FINE_REACH_PX` off the line on each side; the edge
/// is where the map crosses half-way between them (in log energy), entering the band's side for
/// `FINE_RUN_ROWS` rows, the crossing nearest the line when there are several (marks above the band),
/// linearly interpolated. Columns whose levels differ by less than `FINE_MIN_STEP`, whose window leaves
/// the map or the image, or that `seen` leaves out give none. Cost: O(width × reach).
fn fine_edges(fine: &FineMap, line: &SurfaceLine, seen: &dyn Fn(usize) -> bool) -> Vec<(f64, f64, f64)> {
    let reach = FINE_REACH_PX as isize;
    let gap = FINE_LEVEL_GAP_PX as isize;
    let mut out = Vec::new();
    let mut col: Vec<f32> = Vec::with_capacity(2 * reach as usize + 1);
    for x in 1..fine.width.saturating_sub(1) {
        if !seen(x) {
            continue;
        }
        let ly = line.y_at(x as f64);
        let mid = ly.round() as isize;
        let (top, bottom) = (mid - reach, mid + reach);
        if top < fine.top.max(1) as isize || bottom >= fine.bottom as isize {
            continue;
        }
        col.clear();
        col.extend((top..=bottom).map(|y| fine.at(x, y as usize)));
        let level = |rows: std::ops::Range<usize>| {
            let mut v: Vec<f32> = col[rows].to_vec();
            let m = v.len() / 2;
            *v.select_nth_unstable_by(m, f32::total_cmp).1
        };
        let n = col.len();
        let (above, below) = (level(0..(reach - gap) as usize), level((reach + gap) as usize..n));
        if (below - above).abs() < FINE_MIN_STEP {
            continue;
        }
        let half = 0.5 * (above + below);
        let band_side = |v: f32| (v - half) * (below - above).signum() > 0.0;
        let entries = (1..n - FINE_RUN_ROWS + 1)
            .filter(|&i| !band_side(col[i - 1]) && col[i..i + FINE_RUN_ROWS].iter().all(|&v| band_side(v)));
        let nearest = entries.min_by(|&a, &b| {
            let off = |i: usize| (top as f64 + i as f64 - ly).abs();
            off(a).total_cmp(&off(b))
        });
        if let Some(i) = nearest {
            let (a, b) = (col[i - 1] as f64, col[i] as f64);
            let f = if b != a { (half as f64 - a) / (b - a) } else { 0.5 };
            out.push((x as f64, (top + i as isize - 1) as f64 + f, 1.0));
        }
    }
    out
}

/// `line` turned to the tilt of Tukey's biweight line through every column's edge on the fine map
/// ([`fine_edges`]) of the rows it can reach, about its own height at its reference column, with that fit's
/// tilt error (counting the edges' correlation over the same 64 px as the sampled columns'). Only the tilt:
/// where the fine map puts a ragged edge's height differs from the coarse box's by up to a pixel (the box's
/// three rows and the brightness step it also sees), and the level's later measures (the band's gray or texture,
/// the ball's touch) and their stated errors are made for the coarse one. The line as it was when fewer
/// than one column in eight gives an edge (a band that only the coarse box tells apart).
fn refit_on_fine_edges<P: Pixel>(img: &Plane<P>, line: SurfaceLine, seen: &dyn Fn(usize) -> bool) -> SurfaceLine {
    let edges = fine_edges(&FineMap::around(img, &line), &line, seen);
    if edges.len() < img.width / 8 {
        return line;
    }
    let fine = robust_refit(&edges, line, MAX_LAG * STRIDE);
    SurfaceLine {
        slope: fine.slope,
        sigma_tilt_deg: fine.sigma_tilt_deg,
        ..line
    }
}

/// The strongest steps of a column's log-energy profile: `(row, strength)`, the edge lying between `row` and
/// `row + 1`, strength = |mean of the `STEP_ROWS` rows below − mean of those at and above| over the
/// profile's robust scatter of that difference (1.4826 × its median absolute deviation).
fn column_steps(profile: &[f32]) -> Vec<(usize, f64)> {
    let h = profile.len();
    let k = STEP_ROWS;
    // Prefix sums for the two window means.
    let mut sum = vec![0.0f64; h + 1];
    for (i, v) in profile.iter().enumerate() {
        sum[i + 1] = sum[i] + *v as f64;
    }
    let mean = |a: usize, b: usize| (sum[b] - sum[a]) / (b - a) as f64;
    // d[y]: the step between row y and y + 1.
    let rows: Vec<usize> = (k - 1..h - k - 1).collect();
    let d: Vec<f64> = rows
        .iter()
        .map(|&y| mean(y + 1, y + 1 + k) - mean(y + 1 - k, y + 1))
        .collect();
    let mut abs_dev: Vec<f64> = {
        let mut s = d.clone();
        let mid = s.len() / 2;
        let median = *s.select_nth_unstable_by(mid, f64::total_cmp).1;
        d.iter().map(|v| (v - median).abs()).collect()
    };
    let mid = abs_dev.len() / 2;
    let scale = 1.4826 * *abs_dev.select_nth_unstable_by(mid, f64::total_cmp).1;
    if scale.is_nan() || scale <= 0.0 {
        return Vec::new();
    }
    let mut peaks: Vec<(usize, f64)> = (1..d.len() - 1)
        .filter(|&i| d[i].abs() >= d[i - 1].abs() && d[i].abs() > d[i + 1].abs())
        .map(|i| (rows[i], d[i].abs() / scale))
        .collect();
    peaks.sort_by(|a, b| b.1.total_cmp(&a.1));
    peaks.truncate(PEAKS);
    peaks
}

/// Where the energy crosses half-way (in energy, not log) between its level above and below a step between
/// rows `y` and `y + 1`: the levels are the median log energies of rows y − 8 … y − 2 and y + 3 … y + 9;
/// the crossing nearest the step, linearly interpolated, in px (pixel centres at integer rows). `None` near
/// the image's top or bottom, or when the profile does not cross.
fn half_way_edge(profile: &[f32], y: usize) -> Option<f64> {
    let h = profile.len();
    if y < 9 || y + 10 > h {
        return None;
    }
    let rows_median = |a: usize, b: usize| {
        let mut v: Vec<f32> = profile[a..b].to_vec();
        let mid = v.len() / 2;
        *v.select_nth_unstable_by(mid, f32::total_cmp).1
    };
    let (above, below) = (rows_median(y - 8, y - 1), rows_median(y + 3, y + 10));
    let half = 0.5 * (above.exp() + below.exp());
    let e = |k: usize| (profile[k].exp() - half) as f64;
    (0..4)
        .flat_map(|d| [y.checked_sub(d), Some(y + d)])
        .flatten()
        .filter(|&k| k + 1 < h)
        .find(|&k| e(k) * e(k + 1) <= 0.0 && e(k) != e(k + 1))
        .map(|k| k as f64 + e(k) / (e(k) - e(k + 1)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{Scene, band_edge, render};

    /// A band whose mean gray equals the backdrop's is found by its grains alone, to within its roughness.
    #[test]
    fn a_band_as_gray_as_the_backdrop_is_found_by_its_texture() {
        for (y0, deg, rough) in [(180.3, 0.0f64, 0.0), (170.6, 1.5, 2.5), (190.2, -2.0, 5.0)] {
            let s = Scene {
                surface: Some((y0, -deg.to_radians().tan())),
                backdrop: (95.0, 95.0),
                band: (95.0, 30.0),
                roughness: rough,
                noise: 2.0,
                ..Scene::default()
            };
            let px = render(&s);
            let line = texture_line(&Plane::new(&px, 256, 256)).expect("a texture line");
            assert!(
                (line.y0 - y0).abs() < 0.5 + 0.5 * rough,
                "y0 {} vs {y0} (rough {rough}): {line:?}",
                line.y0
            );
            assert!((line.tilt_deg() - deg).abs() < 0.3, "tilt {} vs {deg}", line.tilt_deg());
            assert!(line.roughness_px < 0.6 * rough + 0.6, "{line:?}");
            assert_eq!(line.cue, LineCue::Texture);
        }
    }

    /// A band 5 px rough, its mean gray near the backdrop's, 384 × 256.
    fn ragged_band(seed: u64, deg: f64) -> Scene {
        Scene {
            size: (384, 256),
            surface: Some((175.3, -deg.to_radians().tan())),
            backdrop: (95.0, 95.0),
            band: (100.0, 30.0),
            roughness: 5.0,
            noise: 3.0,
            seed,
            ..Scene::default()
        }
    }

    /// On a ragged band the stated tilt error covers the tilt's error: the edge's roughness enters it.
    #[test]
    fn a_ragged_band_s_tilt_is_within_its_stated_error() {
        let mut worst: f64 = 0.0;
        for seed in 1..=8u64 {
            let deg = -2.0 + 0.5 * seed as f64;
            let s = Scene {
                size: (256, 256),
                ..ragged_band(seed, deg)
            };
            let px = render(&s);
            let line = texture_line(&Plane::new(&px, 256, 256)).expect("a texture line");
            let z = (line.tilt_deg() - deg) / line.sigma_tilt_deg;
            worst = worst.max(z.abs());
            assert!(line.sigma_tilt_deg < 1.5, "seed {seed}: {line:?}");
        }
        assert!(worst < 3.0, "worst |error|/σ of the tilt {worst}");
    }

    #[test]
    fn a_smooth_frame_has_no_texture_line() {
        let s = Scene {
            noise: 3.0,
            ..Scene::default()
        };
        let px = render(&s);
        assert!(texture_line(&Plane::new(&px, 256, 256)).is_none());
    }

    /// Bit depth does not change the line: a 16-bit copy with the 12-bit values shifted left gives the same.
    #[test]
    fn the_line_is_the_same_in_12_bits_shifted_into_16() {
        let s = Scene {
            surface: Some((175.4, 0.0)),
            backdrop: (95.0, 95.0),
            band: (97.0, 30.0),
            roughness: 2.0,
            ..Scene::default()
        };
        let px = render(&s);
        let wide: Vec<u16> = px.iter().map(|&v| ((v as u32 * 4095 / 255) as u16) << 4).collect();
        let a = texture_line(&Plane::new(&px, 256, 256)).unwrap();
        let b = texture_line(&Plane::new(&wide, 256, 256)).unwrap();
        assert!(
            (a.y0 - b.y0).abs() < 0.05 && (a.slope - b.slope).abs() < 1e-3,
            "{a:?} vs {b:?}"
        );
    }

    /// Every column's edges on the coarse map.
    fn coarse_candidates(img: &Plane<u8>) -> Vec<(f64, f64, f64)> {
        let cols: Vec<usize> = (HALF_BOX + 1..img.width - HALF_BOX - 1).collect();
        column_edges(&horizontal_gradient_energy(img), img.width, img.height, &cols)
    }

    /// The least-squares line through the band's top edge as drawn: (y at the centre column, slope).
    fn drawn_edge_line(s: &Scene) -> (f64, f64) {
        let w = s.size.0;
        let xc = (w as f64 - 1.0) / 2.0;
        let pts: Vec<(f64, f64)> = band_edge(s)
            .into_iter()
            .enumerate()
            .map(|(x, y)| (x as f64 - xc, y))
            .collect();
        let n = pts.len() as f64;
        let (mx, my) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let slope = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
        (my - slope * mx, slope)
    }

    /// On the fine map each column's edge follows the ragged edge as drawn in that column, where the coarse
    /// box's 9 columns blur it.
    #[test]
    fn the_fine_map_finds_each_column_s_own_edge() {
        for seed in 1..=4u64 {
            let s = ragged_band(seed, 0.5);
            let px = render(&s);
            let img = Plane::new(&px, s.size.0, s.size.1);
            let line = texture_line(&img).expect("a texture line");
            let fine = fine_edges(&FineMap::around(&img, &line), &line, &|_| true);
            let coarse: Vec<(f64, f64)> =
                nearest_per_column(&coarse_candidates(&img), line.y0, line.slope, line.x0, 12.0)
                    .into_iter()
                    .map(|p| (p.0 + line.x0, p.1))
                    .collect();
            let edge = band_edge(&s);
            let rms = |e: &mut dyn Iterator<Item = (f64, f64)>| {
                let d: Vec<f64> = e.map(|(x, y)| y - edge[x as usize]).collect();
                let m = d.iter().sum::<f64>() / d.len() as f64;
                (d.iter().map(|v| (v - m).powi(2)).sum::<f64>() / d.len() as f64).sqrt()
            };
            let (f, c) = (rms(&mut fine.iter().map(|e| (e.0, e.1))), rms(&mut coarse.into_iter()));
            eprintln!("seed {seed}: fine {f:.2} px, coarse {c:.2} px");
            assert!(fine.len() > s.size.0 * 9 / 10, "seed {seed}: {} columns", fine.len());
            assert!(
                f < 0.7 * c,
                "seed {seed}: fine edges {f:.2} px RMS off the drawn one, coarse {c:.2}"
            );
        }
    }

    /// A line whose reach leaves the image (a band at the frame's bottom edge, or a line beyond it) is left
    /// as it was: no column's window fits, and nothing is read outside the image.
    #[test]
    fn a_line_at_or_beyond_the_image_s_edge_keeps_its_tilt() {
        let s = ragged_band(2, 0.5);
        let px = render(&s);
        let img = Plane::new(&px, s.size.0, s.size.1);
        let line = texture_line(&img).expect("a texture line");
        for y0 in [250.0, 255.9, 400.0, -300.0] {
            let moved = SurfaceLine { y0, ..line };
            assert_eq!(refit_on_fine_edges(&img, moved, &|_| true), moved, "y0 {y0}");
        }
    }

    /// Marks just above a band (screws, a ruler's ticks) do not take the columns they stand over: each
    /// column's edge is the crossing nearest the line.
    #[test]
    fn marks_above_the_band_do_not_take_its_edge() {
        let mut s = ragged_band(5, 0.0);
        s.roughness = 1.0;
        s.ball = (-500.0, -500.0, 1.0);
        s.distractors = (0..6).map(|i| (60.0 + 40.0 * i as f64, 159.0, 4.0, 40.0)).collect();
        let px = render(&s);
        let img = Plane::new(&px, s.size.0, s.size.1);
        let line = texture_line(&img).expect("a texture line");
        let edges = fine_edges(&FineMap::around(&img, &line), &line, &|_| true);
        let edge = band_edge(&s);
        let under: Vec<&(f64, f64, f64)> = edges
            .iter()
            .filter(|e| s.distractors.iter().any(|d| (e.0 - d.0).abs() < 4.0))
            .collect();
        assert!(under.len() >= 12, "{} columns under the marks", under.len());
        for e in under {
            let d = e.1 - edge[e.0 as usize];
            assert!(
                d > -3.0,
                "column {}: edge {:.2} px above the band's, at the marks",
                e.0,
                -d
            );
        }
    }

    /// A ragged band's line leans as its edge as drawn does, not as the coarse box's blur of it: over eight
    /// bands 5 px rough the tilt lies within 0.05° RMS of the drawn edge's own least-squares line (0.026°;
    /// 0.095° with the coarse columns alone).
    #[test]
    fn a_ragged_band_s_tilt_follows_its_drawn_edge() {
        let mut sq = 0.0;
        for seed in 1..=8u64 {
            let deg = -2.0 + 0.5 * seed as f64;
            let s = ragged_band(seed, deg);
            let px = render(&s);
            let line = texture_line(&Plane::new(&px, s.size.0, s.size.1)).expect("a texture line");
            let drawn = -drawn_edge_line(&s).1.atan().to_degrees();
            sq += (line.tilt_deg() - drawn).powi(2);
        }
        let rms = (sq / 8.0).sqrt();
        assert!(rms < 0.05, "tilt {rms:.3}° RMS off the drawn edges' lines");
    }

    /// A band whose grains out-texture the backdrop too weakly for a clear line is a faint one, found where
    /// it is; the clear search still finds nothing there.
    #[test]
    fn a_weakly_grained_band_is_found_only_as_a_faint_line() {
        for seed in 1..=3u64 {
            let s = Scene {
                surface: Some((175.3, 0.01)),
                backdrop: (95.0, 95.0),
                band: (95.0, 14.0),
                roughness: 2.0,
                noise: 4.0,
                seed,
                ball: (-500.0, -500.0, 1.0),
                ..Scene::default()
            };
            let px = render(&s);
            let img = Plane::new(&px, 256, 256);
            assert!(texture_line(&img).is_none(), "seed {seed}: a clear line");
            let line = faint_texture_lines(&img, None)[0];
            assert!((line.y0 - 175.3).abs() < 1.5, "seed {seed}: {line:?}");
            assert!(
                (line.tilt_deg() + 0.01f64.atan().to_degrees()).abs() < 3.0 * line.sigma_tilt_deg,
                "seed {seed}: {line:?}"
            );
        }
    }
}
