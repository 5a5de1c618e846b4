//! Acquisition: which round thing in the clip is the ball, and roughly where it is in two frames.
//!
//! The ball is what moves. The median of a few frames spread over the clip is the scene without it (the
//! ball is elsewhere in most of them), and the frame's difference from that median keeps only what moves:
//! circles are voted for on that difference, so clay grains, rulers, screws, fixtures and a second ball at rest
//! cast no votes, then measured on the frame itself. A circle counts as the ball when it moved between two
//! frames ten apart, is found again half-way between where its path puts it, and is not one of the circles
//! that stayed put. When the difference holds no such circle (a ball too large or slow for the median to
//! forget it), the frames themselves are searched the same way.

use crate::clip::{ClipTracking, TrackError, on_plane, with_plane};
use crate::hough::{Circle, CircleDetection, detect_circles, radius_bands};
use crate::plane::Plane;
use crate::refine::refine_candidates;
use crate::tracker::CLEAN_QUALITY;
use bouncelab_frames::{Clip, Frame};
use std::collections::HashMap;

/// The ball seen at (t, x, y): s, px, px.
pub(crate) type Sighting = (f64, f64, f64);

/// What acquisition learnt: the ball's radius range in px, and two positions (t, x, y).
pub(crate) struct Acquired {
    pub radius: (f64, f64),
    pub seed: (Sighting, Sighting),
}

/// The smallest ball radius searched without a scale, px: below it a ball's rim has too few pixels for a
/// sub-pixel circle.
pub const MIN_BALL_RADIUS_PX: f64 = 8.0;

/// The least quality of a circle that acquisition considers.
const CANDIDATE_QUALITY: f64 = 0.6;

/// Frames the background median is taken over (spread evenly over the clip).
const BACKGROUND_FRAMES: usize = 9;

/// Where circle votes come from.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Votes {
    /// The frame's difference from the background: only what moves.
    Moving,
    /// The frame itself.
    Frame,
}

/// Which edges vote.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Voters {
    /// The strongest few per cent (the detector's default).
    Strongest,
    /// Every edge standing out of the frame's noise (see [`CircleDetection::noise_sigma`]).
    AboveNoise,
}

/// The ball's radius range and two sightings (see the module's description). Clean circles (quality above
/// [`CLEAN_QUALITY`]) are tried first over the whole search, then circles down to [`CANDIDATE_QUALITY`] (a ball
/// crossing a ruler, or in heavy noise); moving votes before the frame's own. When nothing moves, the error
/// lists the static circles seen. With a scale hint only radii within ±20 % of the ball's are searched.
pub(crate) fn acquire(clip: &Clip, opts: &ClipTracking, gain: f32, noise: f32) -> Result<Acquired, TrackError> {
    let n = clip.len();
    let (w, h) = opts.roi.map_or(clip.dimensions(), |r| (r.width, r.height));
    let (min_radius, max_radius) = match opts.scale_hint_m_per_px {
        Some(scale) => {
            let r = opts.ball_diameter_m / (2.0 * scale);
            (0.8 * r, 1.2 * r)
        }
        None => (MIN_BALL_RADIUS_PX, w.min(h) as f64 / 2.0),
    };
    let gap = 10.min(n.saturating_sub(1)).max(1);
    let bands = radius_bands(min_radius, max_radius);
    let mut frames = FrameCache::new(clip, opts, gain);
    let background = frames.background()?;
    let mut found: HashMap<(usize, usize, Votes, Voters), Vec<Circle>> = HashMap::new();
    // The clearest circles that did not move, for the error: (x, y, r, quality).
    let mut still: Vec<(f64, f64, f64, f64)> = Vec::new();
    // Clean circles before doubtful ones; then an octave of radii at a time, largest first, so the ball's rim
    // comes before the smaller circles drawn on it (the seam's lobes, which move with it); then the strongest
    // voters before all significant ones (cheaper, and what a clear ball needs), moving votes before the
    // frame's; then pairs of frames through the first half of the clip.
    for threshold in [CLEAN_QUALITY, CANDIDATE_QUALITY] {
        for (band, &(lo, hi)) in bands.iter().enumerate() {
            for voters in [Voters::Strongest, Voters::AboveNoise] {
                for votes in [Votes::Moving, Votes::Frame] {
                    if votes == Votes::Moving && background.is_none() {
                        continue;
                    }
                    let mut circles = |k: usize| -> Result<Vec<Circle>, TrackError> {
                        if let Some(c) = found.get(&(k, band, votes, voters)) {
                            return Ok(c.clone());
                        }
                        let det = CircleDetection {
                            min_radius: lo,
                            max_radius: hi,
                            // A seam drawn as a dark line can out-vote the rim: keep enough candidates for the
                            // rim to be among them.
                            max_candidates: 24,
                            noise_sigma: (voters == Voters::AboveNoise).then_some(noise as f64),
                            ..CircleDetection::default()
                        };
                        let c = frames.candidates(k, &det, votes, background.as_deref())?;
                        found.insert((k, band, votes, voters), c.clone());
                        Ok(c)
                    };
                    let mut k = 0;
                    while k + gap < n && k <= n / 2 {
                        let good = |c: &Circle| c.support > threshold;
                        let a: Vec<Circle> = circles(k)?.into_iter().filter(good).collect();
                        let b: Vec<Circle> = circles(k + gap)?.into_iter().filter(good).collect();
                        let (a_moved, a_static) = split_static(&a, &b);
                        let (b_moved, _) = split_static(&b, &a);
                        if threshold == CLEAN_QUALITY && votes == Votes::Frame && voters == Voters::Strongest {
                            for c in &a_static {
                                if !still.iter().any(|s| (s.0 - c.x).hypot(s.1 - c.y) < 0.5 * c.r) {
                                    still.push((c.x, c.y, c.r, c.support));
                                }
                            }
                        }
                        if let Some((ca, cb)) = moving_pair(&a_moved, &b_moved, w as f64, |mx, my, r, reach| {
                            Ok(gap < 2
                                || circles(k + gap / 2)?.iter().any(|c| {
                                    c.support > threshold
                                        && (c.x - mx).hypot(c.y - my) <= reach
                                        && (c.r - r).abs() <= 0.05 * r + 1.0
                                }))
                        })? {
                            let r = 0.5 * (ca.r + cb.r);
                            // `k` counts files; time follows frame indices, which count dropped frames too.
                            let t = |pos: usize| clip.time_of(clip.files()[pos].index);
                            return Ok(Acquired {
                                radius: (0.85 * r, 1.15 * r),
                                seed: ((t(k), ca.x, ca.y), (t(k + gap), cb.x, cb.y)),
                            });
                        }
                        k += gap;
                    }
                }
            }
        }
    }
    still.sort_by(|p, q| q.3.total_cmp(&p.3));
    let clip_name = clip.dir().display().to_string();
    if still.is_empty() {
        return Err(TrackError::NoBall {
            clip: clip_name,
            min_radius,
            max_radius,
        });
    }
    Err(TrackError::NothingMoves {
        clip: clip_name,
        circles: still
            .iter()
            .take(3)
            .map(|c| format!("radius {:.1} px at ({:.0}, {:.0})", c.2, c.0, c.1))
            .collect::<Vec<_>>()
            .join(", "),
    })
}

/// The clearest pair (circle in the first frame, in the second) of the same size that moved by more than a
/// pixel and a half and less than half the frame's width, and that `halfway(x, y, r, reach)` finds again
/// within `reach` of its middle: half-way, the ball is near the middle of its two sightings (a quarter of the
/// distance covered allows for gravity and for a bounce between them).
fn moving_pair(
    a: &[Circle],
    b: &[Circle],
    width: f64,
    mut halfway: impl FnMut(f64, f64, f64, f64) -> Result<bool, TrackError>,
) -> Result<Option<(Circle, Circle)>, TrackError> {
    let mut moving: Vec<(Circle, Circle)> = Vec::new();
    for ca in a {
        for cb in b {
            let same_size = (ca.r - cb.r).abs() <= 0.05 * ca.r + 1.0;
            let moved = (ca.x - cb.x).hypot(ca.y - cb.y);
            if same_size && moved > 1.5 && moved < 0.5 * width {
                moving.push((*ca, *cb));
            }
        }
    }
    moving.sort_by(|p, q| q.0.support.min(q.1.support).total_cmp(&p.0.support.min(p.1.support)));
    for (ca, cb) in moving {
        let reach = 0.25 * (ca.x - cb.x).hypot(ca.y - cb.y) + 2.0;
        if halfway(0.5 * (ca.x + cb.x), 0.5 * (ca.y + cb.y), ca.r, reach)? {
            return Ok(Some((ca, cb)));
        }
    }
    Ok(None)
}

/// The circles of `here` that are not in `there` at the same place and size (within a pixel and a half or 5 %
/// of the radius), and those that are (static things).
fn split_static(here: &[Circle], there: &[Circle]) -> (Vec<Circle>, Vec<Circle>) {
    here.iter().partition(|c| {
        !there
            .iter()
            .any(|o| (o.x - c.x).hypot(o.y - c.y) <= 1.5_f64.max(0.05 * c.r) && (o.r - c.r).abs() <= 0.05 * c.r + 1.0)
    })
}

/// Frames decoded once each, by file position.
struct FrameCache<'a> {
    clip: &'a Clip,
    opts: &'a ClipTracking,
    gain: f32,
    frames: HashMap<usize, Frame>,
}

impl<'a> FrameCache<'a> {
    fn new(clip: &'a Clip, opts: &'a ClipTracking, gain: f32) -> Self {
        FrameCache {
            clip,
            opts,
            gain,
            frames: HashMap::new(),
        }
    }

    fn get(&mut self, k: usize) -> Result<&Frame, TrackError> {
        if !self.frames.contains_key(&k) {
            let f = crate::clip::in_region(
                self.clip.read(k, self.opts.read.png_decoder).expect("index in range")?,
                self.opts.roi.as_ref(),
            );
            self.frames.insert(k, f);
        }
        Ok(&self.frames[&k])
    }

    /// Frame `k`'s levels (0–255 scale, with the gain), row-major.
    fn levels(&mut self, k: usize) -> Result<Vec<f32>, TrackError> {
        let gain = self.gain;
        let f = self.get(k)?;
        Ok(with_plane(
            &f.pixels,
            gain,
            |p| on_plane!(p, p => p.data.iter().map(|v| crate::plane::Pixel::level(*v) * gain).collect()),
        ))
    }

    /// The per-pixel median of [`BACKGROUND_FRAMES`] frames spread over the clip: the scene without what
    /// moves. `None` for a clip of fewer than 5 frames. Cost: that many decodes and a median of as many values
    /// per pixel.
    fn background(&mut self) -> Result<Option<Vec<f32>>, TrackError> {
        let n = self.clip.len();
        if n < 5 {
            return Ok(None);
        }
        let m = BACKGROUND_FRAMES.min(n);
        let picks: Vec<usize> = (0..m).map(|i| i * (n - 1) / (m - 1)).collect();
        let planes: Vec<Vec<f32>> = picks.iter().map(|&k| self.levels(k)).collect::<Result<_, _>>()?;
        let len = planes[0].len();
        let mut column = vec![0.0f32; m];
        let mut out = vec![0.0f32; len];
        for (i, o) in out.iter_mut().enumerate() {
            for (c, p) in column.iter_mut().zip(&planes) {
                *c = p[i];
            }
            *o = *column.select_nth_unstable_by(m / 2, f32::total_cmp).1;
        }
        // Frames other than the first and last are not needed again.
        for &k in &picks[1..m - 1] {
            self.frames.remove(&k);
        }
        Ok(Some(out))
    }

    /// Circle candidates in frame `k`: vote peaks from `votes`, each measured on the frame itself.
    fn candidates(
        &mut self,
        k: usize,
        det: &CircleDetection,
        votes: Votes,
        background: Option<&[f32]>,
    ) -> Result<Vec<Circle>, TrackError> {
        let (w, h) = self.opts.roi.map_or(self.clip.dimensions(), |r| (r.width, r.height));
        let (w, h) = (w as usize, h as usize);
        let peaks = match (votes, background) {
            (Votes::Moving, Some(bg)) => {
                let moving: Vec<f32> = self.levels(k)?.iter().zip(bg).map(|(a, b)| (a - b).abs()).collect();
                detect_circles(&Plane::new(&moving, w, h), det)
            }
            _ => {
                let gain = self.gain;
                let f = self.get(k)?;
                with_plane(&f.pixels, gain, |p| on_plane!(p, p => detect_circles(&p, det)))
            }
        };
        let gain = self.gain;
        let search = &self.opts.tracker.search;
        let f = self.get(k)?;
        let refined = with_plane(
            &f.pixels,
            gain,
            |p| on_plane!(p, p => refine_candidates(&p, peaks, det, search, None, CANDIDATE_QUALITY)),
        );
        Ok(refined.into_iter().map(|(c, _)| c).collect())
    }
}
