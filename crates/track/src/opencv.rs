//! OpenCV's `HoughCircles` behind the same interface as [`detect_circles`](crate::detect_circles), as a
//! reference detector: "what a lab would otherwise use" (feature `opencv`).
//!
//! [`detect_circles_opencv`] converts the plane to an 8-bit `Mat` (16-bit planes scaled by 1/257, the same
//! 0–255 scale as [`Pixel::level`]), applies the pre-blur `HoughCircles` needs (without it a noisy, textured
//! frame costs seconds and yields false circles), and calls `imgproc::hough_circles` with the radius range
//! of [`CircleDetection`], `minDist` = the smallest radius, and per-method parameters ([`OpencvParams`]):
//!
//! | method | pre-blur | dp | param1 (Canny high) | param2 |
//! | --- | --- | --- | --- | --- |
//! | [`OpencvMethod::Gradient`] (`HOUGH_GRADIENT`) | median 5 | 1 | 100 | 30 (accumulator votes) |
//! | [`OpencvMethod::GradientAlt`] (`HOUGH_GRADIENT_ALT`) | Gaussian 9×9, σ = 2 | 1.5 | 300 (Scharr) | 0.8 (perfectness) |
//!
//! The pre-blurs were chosen by measurement on noisy (σ = 5) frames with a textured surface band (the
//! `compare_opencv` example's second table): for `HOUGH_GRADIENT` a 5×5 median gives ≈ 0.9 px centre RMS
//! against ≈ 1.15 px after the Gaussian (which, on a shaded ball, also pulls the centre ≈ 0.6 px towards the
//! bright side), at ≈ 2.5 instead of ≈ 1.3 ms per frame; for `HOUGH_GRADIENT_ALT` the Gaussian is both better (≈ 1.3
//! against ≈ 1.4 px) and faster. Both remove the false circles the band's texture makes without a blur.
//! `minDist` = the smallest radius (one ball per neighbourhood). param1/param2: the usual values for
//! `HOUGH_GRADIENT` (Canny 100, 30 votes; 50 votes or Canny 60 change nothing here), and OpenCV's
//! recommendation for `HOUGH_GRADIENT_ALT` (Scharr threshold 300, dp 1.5) with param2 0.8 rather than 0.9,
//! a margin for the ball whose bottom is hidden in contact. dp = 2 for `HOUGH_GRADIENT` only coarsens the
//! centres (≈ 1.5 px RMS) and adds false circles; dp = 1 for the ALT variant is no better and twice slower.
//!
//! [`Circle::support`] is OpenCV's own score turned into 0–1: for `HOUGH_GRADIENT` the radius votes OpenCV
//! returns (edge pixels on the circle) over the circumference 2πr, capped at 1 (close to our support, the
//! fraction of the rim with an edge on it); for `HOUGH_GRADIENT_ALT`, 1 − rank/len in OpenCV's output
//! order (best first).
//!
//! Cost: one 8-bit copy, the pre-blur and the Hough transform on the whole frame, every frame: ≈ 2–2.5 ms
//! per 512×512 frame on one thread with these defaults (≈ 4–8 ms without a pre-blur), against ≈ 0.03 ms
//! for our tracker's refinement around a prediction.
//!
//! Known limitations: centres are quantised to the accumulator grid: `HOUGH_GRADIENT` returns
//! (cell + 0.5)·dp, i.e. centres on the half-pixel grid (…, 199.5, 200.5, …) with dp = 1, and
//! `HOUGH_GRADIENT_ALT` in OpenCV 4.6 returns centres on a dp-spaced grid too (1.5 px with dp = 1.5), so
//! each coordinate carries up to ±0.5 (±0.75) px of quantisation on top of everything else; radii are
//! finer. Neither method knows about the surface, so in contact the hidden, flattened bottom of the ball
//! pulls the circle; and there is no per-frame uncertainty.
//!
//! [`track_clip_opencv`] runs the detection on every frame of a clip (no refinement, no prediction) and
//! keeps per frame the candidate of the expected size nearest the previous centre.

use crate::ball_search::{MIN_BALL_RADIUS_PX, hint_window, radius_window};
use crate::clip::{ClipTracking, Track, TrackError};
use crate::hough::{Circle, CircleDetection};
use crate::plane::{Pixel, Plane};
use crate::surface::{SurfaceLine, find_surface_line};
use crate::tracker::{BallFix, Status};
use ::opencv::core::{CV_8UC1, Mat, Scalar, Size, Vec4f, Vector};
use ::opencv::imgproc;
use ::opencv::prelude::*;
use bouncelab_frames::{Clip, GrayPixels};

/// Which `HoughCircles` variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OpencvMethod {
    /// `HOUGH_GRADIENT`: Canny edges vote along their gradient; centres on the accumulator grid.
    Gradient,
    /// `HOUGH_GRADIENT_ALT`: Scharr gradients, sub-pixel centres, circles ranked by "perfectness".
    GradientAlt,
}

impl OpencvMethod {
    /// Name for tables and logs.
    pub fn name(self) -> &'static str {
        match self {
            OpencvMethod::Gradient => "HOUGH_GRADIENT",
            OpencvMethod::GradientAlt => "HOUGH_GRADIENT_ALT",
        }
    }
}

/// The smoothing applied before `HoughCircles`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PreBlur {
    /// None (slow and noisy on real frames; for comparison only).
    None,
    /// Gaussian of the given odd kernel size and σ, px.
    Gaussian {
        /// Kernel size (odd), px.
        ksize: i32,
        /// Standard deviation, px.
        sigma: f64,
    },
    /// Median of the given odd aperture, px.
    Median {
        /// Aperture (odd, ≥ 3), px.
        ksize: i32,
    },
}

/// All `HoughCircles` settings; [`OpencvParams::for_method`] gives the defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OpencvParams {
    /// The variant.
    pub method: OpencvMethod,
    /// Smoothing before the transform.
    pub blur: PreBlur,
    /// Inverse accumulator resolution.
    pub dp: f64,
    /// Higher Canny threshold (the lower is half of it).
    pub param1: f64,
    /// Accumulator threshold (`Gradient`) or perfectness 0–1 (`GradientAlt`).
    pub param2: f64,
}

impl OpencvParams {
    /// The defaults of this module for `method` (see the module doc).
    pub fn for_method(method: OpencvMethod) -> OpencvParams {
        match method {
            OpencvMethod::Gradient => OpencvParams {
                method,
                blur: PreBlur::Median { ksize: 5 },
                dp: 1.0,
                param1: 100.0,
                param2: 30.0,
            },
            OpencvMethod::GradientAlt => OpencvParams {
                method,
                blur: PreBlur::Gaussian { ksize: 9, sigma: 2.0 },
                dp: 1.5,
                param1: 300.0,
                param2: 0.8,
            },
        }
    }
}

/// Errors of the OpenCV detector.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OpencvError {
    /// Options OpenCV cannot take.
    #[error("invalid OpenCV circle detection options: {0}")]
    Options(String),
    /// OpenCV itself failed.
    #[error("OpenCV: {0}")]
    Cv(#[from] ::opencv::Error),
}

/// Circle candidates in `img` by OpenCV's `HoughCircles` with this module's default parameters for
/// `method`, best first. Images smaller than 8×8 give no circle.
pub fn detect_circles_opencv<P: Pixel>(
    img: &Plane<P>,
    opts: &CircleDetection,
    method: OpencvMethod,
) -> Result<Vec<Circle>, OpencvError> {
    detect_circles_opencv_with(img, opts, &OpencvParams::for_method(method))
}

/// [`detect_circles_opencv`] with explicit parameters.
pub fn detect_circles_opencv_with<P: Pixel>(
    img: &Plane<P>,
    opts: &CircleDetection,
    params: &OpencvParams,
) -> Result<Vec<Circle>, OpencvError> {
    check(opts, params)?;
    if img.width < 8 || img.height < 8 {
        return Ok(Vec::new());
    }
    let (w, h) = (
        i32::try_from(img.width).map_err(|_| OpencvError::Options("image too wide".into()))?,
        i32::try_from(img.height).map_err(|_| OpencvError::Options("image too tall".into()))?,
    );
    let mut src = Mat::new_rows_cols_with_default(h, w, CV_8UC1, Scalar::all(0.0))?;
    for (b, p) in src.data_bytes_mut()?.iter_mut().zip(img.data) {
        *b = p.level().round() as u8;
    }
    let mut blurred = Mat::default();
    let input: &Mat = match params.blur {
        PreBlur::None => &src,
        PreBlur::Gaussian { ksize, sigma } => {
            imgproc::gaussian_blur_def(&src, &mut blurred, Size::new(ksize, ksize), sigma)?;
            &blurred
        }
        PreBlur::Median { ksize } => {
            imgproc::median_blur(&src, &mut blurred, ksize)?;
            &blurred
        }
    };
    let mut found: Vector<Vec4f> = Vector::new();
    let method = match params.method {
        OpencvMethod::Gradient => imgproc::HOUGH_GRADIENT,
        OpencvMethod::GradientAlt => imgproc::HOUGH_GRADIENT_ALT,
    };
    imgproc::hough_circles(
        input,
        &mut found,
        method,
        params.dp,
        opts.min_radius.max(1.0),
        params.param1,
        params.param2,
        opts.min_radius.floor() as i32,
        opts.max_radius.ceil() as i32,
    )?;
    let n = found.len();
    let mut out: Vec<Circle> = found
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let (x, y, r, votes) = (c[0] as f64, c[1] as f64, c[2] as f64, c[3] as f64);
            let support = match params.method {
                OpencvMethod::Gradient if r > 0.0 => (votes / (std::f64::consts::TAU * r)).min(1.0),
                _ => 1.0 - k as f64 / n as f64,
            };
            Circle { x, y, r, support }
        })
        .filter(|c| c.r >= opts.min_radius - 1.0 && c.r <= opts.max_radius + 1.0)
        .collect();
    out.truncate(opts.max_candidates);
    Ok(out)
}

fn check(opts: &CircleDetection, p: &OpencvParams) -> Result<(), OpencvError> {
    let bad = |m: String| Err(OpencvError::Options(m));
    if !(opts.min_radius > 0.0 && opts.max_radius >= opts.min_radius && opts.max_radius < 1e6) {
        return bad(format!(
            "radius range {}–{} px must be positive and increasing",
            opts.min_radius, opts.max_radius
        ));
    }
    if !(p.dp >= 1.0 && p.dp <= 8.0) {
        return bad(format!("dp = {} must lie in 1–8", p.dp));
    }
    if !(p.param1 > 0.0 && p.param1.is_finite() && p.param2 > 0.0 && p.param2.is_finite()) {
        return bad(format!("param1 = {}, param2 = {} must be positive", p.param1, p.param2));
    }
    if p.method == OpencvMethod::GradientAlt && p.param2 > 1.0 {
        return bad(format!(
            "HOUGH_GRADIENT_ALT's param2 = {} is a perfectness in 0–1",
            p.param2
        ));
    }
    match p.blur {
        PreBlur::Gaussian { ksize, sigma } if ksize < 1 || ksize % 2 == 0 || sigma.is_nan() || sigma < 0.0 => bad(
            format!("Gaussian pre-blur {ksize}×{ksize}, σ = {sigma}: the size must be odd"),
        ),
        PreBlur::Median { ksize } if ksize < 3 || ksize % 2 == 0 => {
            bad(format!("median pre-blur {ksize}: the aperture must be odd and ≥ 3"))
        }
        _ => Ok(()),
    }
}

/// Nominal centre uncertainty given to OpenCV's fixes, px: OpenCV gives none; this is the half-pixel grid
/// of `HOUGH_GRADIENT` (dp = 1), not a measurement.
const NOMINAL_SIGMA_PX: f64 = 0.5;

fn with_plane<R>(px: &GrayPixels, f8: impl FnOnce(&Plane<u8>) -> R, f16: impl FnOnce(&Plane<u16>) -> R) -> R {
    let (w, h) = (px.width() as usize, px.height() as usize);
    match px {
        GrayPixels::U8(img) => f8(&Plane::new(img.as_raw(), w, h)),
        GrayPixels::U16(img) => f16(&Plane::new(img.as_raw(), w, h)),
    }
}

fn detect_frame(px: &GrayPixels, det: &CircleDetection, params: &OpencvParams) -> Result<Vec<Circle>, OpencvError> {
    with_plane(
        px,
        |p| detect_circles_opencv_with(p, det, params),
        |p| detect_circles_opencv_with(p, det, params),
    )
}

/// The ball's radius range, px: from the scale hint, else the circle that moved between two frames (as
/// [`track_clip`](crate::track_clip) does, with OpenCV's detector), else the clearest circle.
fn radius_range(
    clip: &Clip,
    opts: &ClipTracking,
    params: &OpencvParams,
    warnings: &mut Vec<String>,
) -> Result<Option<(f64, f64)>, TrackError> {
    if let Some(scale) = opts.scale_hint_m_per_px {
        let r = opts.ball_diameter_m / (2.0 * scale);
        return Ok(Some(hint_window(r)));
    }
    let n = clip.len();
    let (w, h) = clip.dimensions();
    let det = CircleDetection {
        min_radius: MIN_BALL_RADIUS_PX,
        max_radius: w.min(h) as f64 / 2.0,
        ..CircleDetection::default()
    };
    let circles_in = |k: usize| -> Result<Vec<Circle>, TrackError> {
        let frame = clip.read(k, opts.read.png_decoder).expect("index in range")?;
        Ok(detect_frame(&frame.pixels, &det, params).unwrap_or_default())
    };
    let gap = 10.min(n.saturating_sub(1)).max(1);
    let mut k = 0;
    let mut fallback = None;
    while k + gap < n && k <= n / 2 {
        let (a, b) = (circles_in(k)?, circles_in(k + gap)?);
        for ca in &a {
            for cb in &b {
                let same_size = (ca.r - cb.r).abs() <= 0.05 * ca.r + 1.5;
                let moved = (ca.x - cb.x).hypot(ca.y - cb.y);
                if same_size && moved > 1.5 && moved < 0.5 * w as f64 {
                    let r = 0.5 * (ca.r + cb.r);
                    return Ok(Some(radius_window(r)));
                }
            }
        }
        if fallback.is_none() {
            fallback = a.first().map(|c| c.r);
        }
        k += gap;
    }
    if let Some(r) = fallback {
        warnings.push(format!(
            "could not tell the ball by its motion; tracking circles of radius ≈ {r:.1} px — give the scale to be sure"
        ));
        return Ok(Some(radius_window(r)));
    }
    Ok(None)
}

/// Tracks the ball through `clip` with OpenCV's `HoughCircles` on every whole frame (no refinement, no
/// prediction): the baseline a lab would otherwise use. Per frame, among the circles of the expected radius
/// (from the scale hint, else from the circle that moved, as [`track_clip`](crate::track_clip)), the one
/// nearest the previous centre is kept, if it lies within one radius of it; with no previous centre, the
/// best-ranked one (`ambiguous` if there are several). Statuses: `ok`, `cut_by_border`, `ambiguous`,
/// `absent`. `sigma_px` is a nominal 0.5 px, `sigma_r_px` NaN, `quality` OpenCV's support.
/// Scale, surface line and [`Track::rows`] as with `track_clip`. A frame where OpenCV fails is `absent`
/// and named in the warnings. `progress` is called with (frames done, frames total).
pub fn track_clip_opencv(
    clip: &Clip,
    opts: &ClipTracking,
    method: OpencvMethod,
    mut progress: impl FnMut(usize, usize),
) -> Result<Track, TrackError> {
    let params = OpencvParams::for_method(method);
    let mut warnings = Vec::new();
    let Some((lo, hi)) = radius_range(clip, opts, &params, &mut warnings)? else {
        let (w, h) = clip.dimensions();
        return Err(TrackError::NoBall {
            clip: clip.dir().display().to_string(),
            min_radius: MIN_BALL_RADIUS_PX,
            max_radius: w.min(h) as f64 / 2.0,
        });
    };
    let det = CircleDetection {
        min_radius: lo,
        max_radius: hi,
        ..CircleDetection::default()
    };
    let mut surface: Option<SurfaceLine> = None;
    let mut surface_tries = 0;
    let mut previous: Option<(f64, f64)> = None;
    let (fixes, waiting, tracking) = crate::clip::stream_fixes(
        clip.frames_with(&opts.read)?,
        clip.len(),
        &mut progress,
        |frame| {
            if surface.is_none() && surface_tries < 5 {
                surface_tries += 1;
                surface = with_plane(&frame.pixels, find_surface_line, find_surface_line);
            }
            let (index, t_s) = (frame.index as usize, frame.t_s);
            let cands = match detect_frame(&frame.pixels, &det, &params) {
                Ok(c) => c,
                Err(e) => {
                    warnings.push(format!("frame {index}: {e}"));
                    Vec::new()
                }
            };
            let (w, h) = (frame.pixels.width() as f64, frame.pixels.height() as f64);
            let fix = pick(&cands, previous, index, t_s, (w, h));
            if fix.status == Status::Ambiguous {
                warnings.push(format!(
                "frame {index}: {} ball-like circles and no track yet to tell which is the ball; taking OpenCV's first at ({:.1}, {:.1})",
                cands.len(),
                fix.x_px,
                fix.y_px
            ));
            }
            if fix.status == Status::Absent && previous.is_some() {
                warnings.push(format!("frame {index}: ball lost"));
            }
            previous = fix.status.measured().then_some((fix.x_px, fix.y_px));
            fix
        },
    )?;
    if !fixes.iter().any(|f| f.status.measured()) {
        return Err(TrackError::NoBall {
            clip: clip.dir().display().to_string(),
            min_radius: lo,
            max_radius: hi,
        });
    }
    let absent = fixes.iter().filter(|f| f.status == Status::Absent).count();
    if absent > 0 {
        warnings.push(format!("ball not found in {absent} of {} frames", fixes.len()));
    }
    // OpenCV gives no edge profile, so no edge-definition term: statistical error only.
    let scale = crate::clip::scale_from(&fixes, surface.as_ref(), opts.ball_diameter_m, 0.0, 0.0, None);
    Ok(Track {
        fixes,
        surface,
        surface_alternatives: Vec::new(),
        scale,
        warnings,
        seconds_waiting: waiting,
        seconds_tracking: tracking,
        downslope_negative_x: opts.downslope_negative_x,
        camera: clip.camera().clone(),
        saturated_frames: 0,
    })
}

/// The fix of one frame from OpenCV's candidates (already restricted to the expected radius range).
fn pick(cands: &[Circle], previous: Option<(f64, f64)>, frame: usize, t_s: f64, (w, h): (f64, f64)) -> BallFix {
    let absent = BallFix::absent(frame, t_s, Status::Absent);
    let (c, mut status) = match previous {
        Some((px, py)) => {
            let d = |c: &Circle| (c.x - px).hypot(c.y - py);
            match cands.iter().min_by(|a, b| d(a).total_cmp(&d(b))) {
                Some(c) if d(c) <= c.r => (*c, Status::Ok),
                _ => return absent,
            }
        }
        None => match cands {
            [] => return absent,
            [c] => (*c, Status::Ok),
            [c, ..] => (*c, Status::Ambiguous),
        },
    };
    if status == Status::Ok && (c.x - c.r < -0.5 || c.y - c.r < -0.5 || c.x + c.r > w - 0.5 || c.y + c.r > h - 0.5) {
        status = Status::CutByBorder;
    }
    BallFix {
        frame,
        t_s,
        x_px: c.x,
        y_px: c.y,
        r_px: c.r,
        sigma_px: NOMINAL_SIGMA_PX,
        sigma_r_px: f64::NAN,
        quality: c.support,
        status,
    }
}
