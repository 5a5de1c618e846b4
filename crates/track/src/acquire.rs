//! Acquisition: which round thing in the clip is the ball, and roughly where it is in two frames.
//!
//! The ball is what moves. The median of a few frames spread over the clip is the scene without it (the
//! ball is elsewhere in most of them), and the frame's difference from that median keeps only what moves:
//! circles are voted for on that difference, so clay grains, rulers, screws, fixtures and a second ball at rest
//! cast no votes, then measured on the frame itself; one whose rim does not stand out of the frame's noise
//! is no sighting (in heavy noise circles of noise, and a seam's arcs on the ball, refine as clearly as the
//! ball, see `rim_evidence`). A circle counts as the ball when it moved between two frames 1 ms apart (ten
//! at 10,000 fps, see `SIGHTING_GAP_S`; 2 or 4 ms for a ball that moves too little in one, before smaller
//! circles are tried), is found again half-way between where its path puts it, and did
//! not stay put: its rim's pixels changed between the two frames by more than their noise (a still circle
//! the other frame's search missed is still all the same). When the difference holds no such circle (a
//! ball too large or slow for the median to forget it), the frames themselves are searched the same way.
//! Clean circles centred beyond the frame's edges (a ball mostly out of view) are looked for after clean ones
//! inside it and before doubtful ones, so that a seam's lobe on the visible cap of a ball whose centre is out
//! of view is not taken for the ball. Among doubtful circles, a radius band where no two files' vote peaks
//! make a pair has each file's clearest circles followed into the next file from where they were: in heavy
//! noise a ball's rim can be clear in one file and outvoted by grains and noise in the next.
//!
//! Most clips show the ball from their first frame, so the first pair of frames is tried before the clip is
//! searched one octave of radii at a time: a search through the whole clip for radii larger than the ball's
//! was most of a clip's tracking cost. A circle found there that lies inside a larger moving one is left to
//! the full search, which settles such a lobe.

use crate::ball_search::{BALL_CANDIDATES, MIN_BALL_RADIUS_PX, hint_window, radius_window};
use crate::clip::{ClipTracking, TrackError, on_plane, with_plane};
use crate::hough::{Circle, CircleDetection, detect_circles, radius_bands};
use crate::plane::{Pixel, Plane, median};
use crate::refine::{EdgeSearch, refine_candidates, refine_circle, settled_search};
use crate::rim_evidence::rim_evidence;
use crate::tracker::CLEAN_QUALITY;
use bouncelab_frames::{Clip, Frame};
use std::collections::HashMap;

/// The ball seen at (t, x, y): s, px, px.
pub(crate) type Sighting = (f64, f64, f64);

/// What acquisition learnt: the ball's radius range in px, and two positions (t, x, y).
pub(crate) struct Acquired {
    pub radius: (f64, f64),
    pub seed: (Sighting, Sighting),
    /// The file (position in the clip) of the first sighting.
    pub file: usize,
    /// Another moving ball-like circle seen at acquisition: (frame index, x, y) px.
    pub second: Option<(usize, f64, f64)>,
}

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
/// crossing a ruler, or in heavy noise; there the earliest pair nearly as clear as the clearest is taken, see
/// [`PairSearch::doubtful`]);
/// moving votes before the frame's own. When nothing moves, the error lists the static circles seen. With a
/// scale hint only radii within ±20 % of the ball's are searched.
pub(crate) fn acquire(clip: &Clip, opts: &ClipTracking, gain: f32, noise: f32) -> Result<Acquired, TrackError> {
    acquire_in(clip, opts, gain, noise, Order::Forward)
}

/// In which order acquisition goes through the clip's files.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Order {
    /// From the first file, in time.
    Forward,
    /// From the last file, in negated time: the sightings' times are −t and their first file is the later
    /// one, so that a tracker seeded with them runs back through the clip.
    Reversed,
}

impl Order {
    /// The clip's file at search position `pos` of `n`.
    fn file(self, pos: usize, n: usize) -> usize {
        match self {
            Order::Forward => pos,
            Order::Reversed => n - 1 - pos,
        }
    }
}

/// [`acquire`] through the clip's files in `order`: with [`Order::Reversed`] the ball is looked for from the
/// clip's end (where a track that lost it after the bounce can find it again), and [`Acquired`]'s times are
/// negated and its `file` the clip's file of the later sighting.
pub(crate) fn acquire_in(
    clip: &Clip,
    opts: &ClipTracking,
    gain: f32,
    noise: f32,
    order: Order,
) -> Result<Acquired, TrackError> {
    let (w, h) = opts.roi.map_or(clip.dimensions(), |r| (r.width, r.height));
    let (min_radius, max_radius) = match opts.scale_hint_m_per_px {
        Some(scale) => {
            let r = opts.ball_diameter_m / (2.0 * scale);
            hint_window(r)
        }
        None => (MIN_BALL_RADIUS_PX, w.min(h) as f64 / 2.0),
    };
    let bands = radius_bands(min_radius, max_radius);
    let mut frames = FrameCache::new(clip, opts, gain, order);
    let background = frames.background()?;
    let mut search = PairSearch {
        clip,
        order,
        width: w as f64,
        gap: sighting_gap(clip.fps(), clip.len()),
        noise,
        frames,
        background,
        found: HashMap::new(),
        still: Vec::new(),
    };
    if let Some(found) = search.at_first_pair(&bands)? {
        return Ok(found);
    }
    // Clean circles centred in the frame, then clean circles centred beyond its edges (a ball mostly out of
    // view: a third of a rim lines up by chance more easily than a whole one, so only clean ones count, and
    // before doubtful circles in the frame, which on such a ball are the seam's lobes on its visible cap),
    // then doubtful circles in the frame (see `PairSearch::doubtful`). In the clean passes, an octave of radii
    // at a time, largest first, so the ball's rim comes before the smaller circles drawn on it (the lobes,
    // which move with it); then the strongest voters before all significant ones (cheaper, and what a clear
    // ball needs), moving votes before the frame's; then pairs of frames through the first half of the clip.
    for beyond_edge in [false, true] {
        for (band, &radii) in bands.iter().enumerate() {
            for (voters, votes) in search.sources() {
                let pass = Pass {
                    threshold: CLEAN_QUALITY,
                    band,
                    radii,
                    beyond_edge,
                    votes,
                    voters,
                };
                if let Some(found) = search.through_clip_at_longer_gaps(&pass)? {
                    return Ok(found);
                }
            }
        }
    }
    if let Some(found) = search.doubtful(&bands)? {
        return Ok(found);
    }
    Err(nothing_moved(clip, search.still, min_radius, max_radius))
}

/// One pass of the search: the least quality of a sighting, the radius band (its index and range, px), whether
/// centres inside the frame or beyond its edges are looked for (see [`CircleDetection::beyond_edge`]), where
/// the votes come from and which edges vote.
#[derive(Clone, Copy)]
struct Pass {
    threshold: f64,
    band: usize,
    radii: (f64, f64),
    beyond_edge: bool,
    votes: Votes,
    voters: Voters,
}

/// The search for a moving pair of sightings, with the circles already found in each frame and pass.
struct PairSearch<'a> {
    clip: &'a Clip,
    /// The order of the files searched.
    order: Order,
    /// The searched region's width, px.
    width: f64,
    /// Frames between the two sightings of a pair.
    gap: usize,
    /// The first frame's noise σ (0–255 scale), for [`Voters::AboveNoise`].
    noise: f32,
    frames: FrameCache<'a>,
    background: Option<Vec<f32>>,
    found: HashMap<(usize, usize, bool, Votes, Voters), Vec<Seen>>,
    /// The clearest circles that did not move, for the error: (x, y, r, quality).
    still: Vec<(f64, f64, f64, f64)>,
}

impl PairSearch<'_> {
    /// The circles seen in file `k` in this pass (detected once, then remembered).
    fn circles(&mut self, k: usize, pass: &Pass) -> Result<Vec<Seen>, TrackError> {
        let key = (k, pass.band, pass.beyond_edge, pass.votes, pass.voters);
        if let Some(c) = self.found.get(&key) {
            return Ok(c.clone());
        }
        let det = CircleDetection {
            min_radius: pass.radii.0,
            max_radius: pass.radii.1,
            max_candidates: BALL_CANDIDATES,
            noise_sigma: (pass.voters == Voters::AboveNoise).then_some(self.noise as f64),
            beyond_edge: pass.beyond_edge,
            ..CircleDetection::default()
        };
        let c = self
            .frames
            .candidates(k, &det, pass.votes, self.background.as_deref())?;
        self.found.insert(key, c.clone());
        Ok(c)
    }

    /// Pairs of files `gap` apart through the first half of the clip, in this (clean) pass: the first moving
    /// pair ([`moving_pair`]) as the ball, else `None`. The clean frame pass also notes the circles that
    /// stayed.
    fn through_clip(&mut self, pass: &Pass) -> Result<Option<Acquired>, TrackError> {
        let (n, gap) = (self.clip.len(), self.gap);
        let mut k = 0;
        while k + gap < n && k <= n / 2 {
            if let Some(pair) = self.pair_at(k, pass)? {
                return Ok(Some(self.acquired(k, &pair)));
            }
            k += gap;
        }
        Ok(None)
    }

    /// [`Self::through_clip`] with the sighting gap, then with [`LONGER_GAPS`] times it: a small ball falling
    /// slowly moves less than [`MIN_PAIR_MOVE_PX`] in one gap (1.2 px at 23 px radius and 1.8 m/s), and
    /// smaller circles on it, which jitter by more, would be taken for it. Its files at the longer gaps are
    /// mostly those already searched (multiples of the gap), so a longer gap costs little beyond matching.
    fn through_clip_at_longer_gaps(&mut self, pass: &Pass) -> Result<Option<Acquired>, TrackError> {
        let gap = self.gap;
        let mut found = Ok(None);
        for times in LONGER_GAPS {
            self.gap = times * gap;
            found = self.through_clip(pass);
            if !matches!(found, Ok(None)) {
                break;
            }
        }
        self.gap = gap;
        found
    }

    /// The doubtful pass, after the clean ones found nothing: in each radius band of `bands`, the earliest
    /// pair nearly as clear (its weaker sighting's quality) as the clearest any vote source sees at any pair
    /// of files through the first half of the clip ([`Self::earliest_clear_in_band`]). A smaller band's pair takes
    /// the place of a larger band's only when clearer by [`CLEARER_BY`] and standing out from its
    /// surroundings at least as much ([`disc_contrast`]), as in [`Self::clearer_inside`]: a seam's lobe on a
    /// ball, which can be clearer than a doubtful rim, has felt on both sides, while the ball stands out from
    /// its backdrop and a circle of noise does not. The pair taken may yet give way to a clearer one inside
    /// it ([`Self::clearer_inside`]). In heavy noise circles of noise pulled along by part of the ball's rim
    /// move with it, in its band and in larger ones; the first pair found at any clarity is not the ball as
    /// often as the clearest is. The clean passes have searched the same files and bands, so their circles
    /// are known.
    fn doubtful(&mut self, bands: &[(f64, f64)]) -> Result<Option<Acquired>, TrackError> {
        let mut best: Option<(usize, MovingPair, Pass)> = None;
        for (band, &radii) in bands.iter().enumerate() {
            let Some(found) = self.earliest_clear_in_band(band, radii)? else {
                continue;
            };
            let takes_over = match &best {
                None => true,
                Some(b) => {
                    clarity(&found.1) > clarity(&b.1) + CLEARER_BY
                        && self.contrast_of(found.0, &found.2, &found.1.a)? >= self.contrast_of(b.0, &b.2, &b.1.a)?
                        && self.frames.rim_share(found.0, &found.1.a)? >= self.frames.rim_share(b.0, &b.1.a)?
                }
            };
            if takes_over {
                best = Some(found);
            }
        }
        let Some((k, pair, pass)) = best else {
            return Ok(None);
        };
        let pair = self.clearer_inside(k, &pass, pair, bands)?;
        Ok(Some(self.acquired(k, &pair)))
    }

    /// The earliest moving pair at [`CANDIDATE_QUALITY`] in radius band `band` (its range `radii`, px) nearly
    /// as clear as the clearest any vote source sees at any pair of files through the first half of the clip
    /// ([`earliest_of_the_clearest`]): the search position of its first file, the pair and the pass that saw
    /// it. When the vote peaks of the files make no pair in the band, the same files are searched again
    /// following each file's clearest circles into the next ([`Self::followed_pair_at`]); a band where the
    /// vote peaks do make pairs is left as it was.
    fn earliest_clear_in_band(
        &mut self,
        band: usize,
        radii: (f64, f64),
    ) -> Result<Option<(usize, MovingPair, Pass)>, TrackError> {
        let (n, gap) = (self.clip.len(), self.gap);
        let mut found: Vec<(usize, MovingPair, Pass)> = Vec::new();
        for follow in [false, true] {
            if !found.is_empty() {
                break;
            }
            let mut k = 0;
            while k + gap < n && k <= n / 2 {
                for (voters, votes) in self.sources() {
                    let pass = Pass {
                        threshold: CANDIDATE_QUALITY,
                        band,
                        radii,
                        beyond_edge: false,
                        votes,
                        voters,
                    };
                    let got = if follow {
                        self.followed_pair_at(k, &pass)?
                    } else {
                        self.pair_at(k, &pass)?
                    };
                    if let Some(pair) = got {
                        found.push((k, pair, pass));
                    }
                }
                k += gap;
            }
        }
        Ok(earliest_of_the_clearest(found, |f| clarity(&f.1)))
    }

    /// The clearest moving pair at files `k` and `k + gap` in the bands of `bands` smaller than `pass`'s whose
    /// first circle lies inside `found`'s, is clearer (its weaker sighting's quality above `found`'s by
    /// [`CLEARER_BY`]) and stands out from its surroundings at least as much ([`disc_contrast`]); else
    /// `found`. Largest first is right for a clean ball, whose rim comes before the seam's lobes drawn on it,
    /// but in heavy noise a doubtful circle twice the ball's size, pulled along by part of its rim, moves
    /// with it too: the ball inside is the clearer circle and the clearer disc, a lobe is neither.
    fn clearer_inside(
        &mut self,
        k: usize,
        pass: &Pass,
        found: MovingPair,
        bands: &[(f64, f64)],
    ) -> Result<MovingPair, TrackError> {
        let outer_contrast = self.contrast_of(k, pass, &found.a)?;
        let mut best: Option<MovingPair> = None;
        for (band, &radii) in bands.iter().enumerate().skip(pass.band + 1) {
            for (voters, votes) in self.sources() {
                let inner = Pass {
                    band,
                    radii,
                    votes,
                    voters,
                    ..*pass
                };
                let Some(pair) = self.pair_at(k, &inner)? else {
                    continue;
                };
                let inside = (pair.a.x - found.a.x).hypot(pair.a.y - found.a.y) < found.a.r;
                let clearer = clarity(&pair) > clarity(&found) + CLEARER_BY
                    && best.as_ref().is_none_or(|b| clarity(&pair) > clarity(b));
                if inside
                    && clearer
                    && self.contrast_of(k, &inner, &pair.a)? >= outer_contrast
                    && self.frames.rim_share(k, &pair.a)? >= self.frames.rim_share(k, &found.a)?
                {
                    best = Some(pair);
                }
            }
        }
        Ok(best.unwrap_or(found))
    }

    /// The [`disc_contrast`] of circle `c` as seen in file `k` in this pass (0 if it is not one of them).
    fn contrast_of(&mut self, k: usize, pass: &Pass, c: &Circle) -> Result<f64, TrackError> {
        let seen = self.circles(k, pass)?;
        Ok(seen
            .iter()
            .find(|s| s.circle.x == c.x && s.circle.y == c.y && s.circle.r == c.r)
            .map_or(0.0, |s| s.contrast))
    }

    /// The ball moving cleanly near the clip's start, the common case, found without going through the clip
    /// band by band: bands largest first and every vote source, as [`acquire`] orders them, at the first pair
    /// of files. The first band with a circle in the first file (any acquisition considers) ends the bands:
    /// the full search starts with the same bands and frames, so a miss costs little, where going on through
    /// the smaller bands (the costliest, at full resolution) would cost the most. When that circle is not yet
    /// the ball (cut by the frame's edge, or moving too little in one gap), the next [`EARLY_PAIRS`] pairs
    /// are tried in its band: the ball's band shows from the first file on. A circle that lies inside a larger
    /// moving one (centred in the frame or beyond its edge, at any quality acquisition considers) is not taken:
    /// it may be a seam's lobe on a ball whose rim is not yet clean or not yet in view, which the full search
    /// settles.
    fn at_first_pair(&mut self, bands: &[(f64, f64)]) -> Result<Option<Acquired>, TrackError> {
        let (n, gap) = (self.clip.len(), self.gap);
        if gap >= n {
            return Ok(None);
        }
        for band in 0..bands.len() {
            match self.early_pair_at(0, band, bands)? {
                Early::Nothing => continue,
                Early::Ball(found) => return Ok(Some(found)),
                Early::Lobe => return Ok(None),
                Early::Seen => {}
            }
            for k in (1..=EARLY_PAIRS)
                .map(|i| i * gap)
                .take_while(|&k| k + gap < n && k <= n / 2)
            {
                match self.early_pair_at(k, band, bands)? {
                    Early::Ball(found) => return Ok(Some(found)),
                    Early::Lobe => return Ok(None),
                    Early::Nothing | Early::Seen => {}
                }
            }
            return Ok(None);
        }
        Ok(None)
    }

    /// The clean pair at files `k` and `k + gap` in radius band `band` of `bands`, every vote source in turn
    /// (see [`Self::at_first_pair`]).
    fn early_pair_at(&mut self, k: usize, band: usize, bands: &[(f64, f64)]) -> Result<Early, TrackError> {
        let mut seen = false;
        for (voters, votes) in self.sources() {
            let pass = Pass {
                threshold: CLEAN_QUALITY,
                band,
                radii: bands[band],
                beyond_edge: false,
                votes,
                voters,
            };
            if let Some(pair) = self.pair_at(k, &pass)? {
                if !self.on_still_ground(k, &pair.a)? && self.inside_larger_moving(k, &pair.a, &bands[..band])? {
                    return Ok(Early::Lobe);
                }
                return Ok(Early::Ball(self.acquired(k, &pair)));
            }
            seen |= !self.circles(k, &pass)?.is_empty();
        }
        Ok(if seen { Early::Seen } else { Early::Nothing })
    }

    /// The vote sources in the order they are tried: the strongest voters before all significant ones, moving
    /// votes before the frame's (moving votes only with a background).
    fn sources(&self) -> Vec<(Voters, Votes)> {
        let mut out = Vec::new();
        for voters in [Voters::Strongest, Voters::AboveNoise] {
            for votes in [Votes::Moving, Votes::Frame] {
                if votes == Votes::Frame || self.background.is_some() {
                    out.push((voters, votes));
                }
            }
        }
        out
    }

    /// Whether what surrounds `c`, seen in file `k`, stays still ([`ring_motion`] below
    /// [`STILL_RING_SIGMAS`]): then `c` is not a mark on something larger that moves, and the search for such a
    /// thing ([`Self::inside_larger_moving`]) is not needed. `false` without a background.
    fn on_still_ground(&mut self, k: usize, c: &Circle) -> Result<bool, TrackError> {
        let Some(bg) = &self.background else {
            return Ok(false);
        };
        self.frames.keep_moving(k, bg)?;
        let (w, h) = self.frames.size();
        let z = ring_motion(&Plane::new(&self.frames.moving[&k], w, h), c, self.noise);
        Ok(z.is_some_and(|z| z < STILL_RING_SIGMAS))
    }

    /// Whether `c`, seen in file `k`, lies inside a circle of one of the `larger` radius bands that moves
    /// between files `k` and `k + gap` (its centre within that circle, which is at least 1.2 times as large),
    /// seen at [`CANDIDATE_QUALITY`] or better, centred in the frame or beyond its edge.
    fn inside_larger_moving(&mut self, k: usize, c: &Circle, larger: &[(f64, f64)]) -> Result<bool, TrackError> {
        for (band, &radii) in larger.iter().enumerate() {
            for beyond_edge in [false, true] {
                for (voters, votes) in self.sources() {
                    let pass = Pass {
                        threshold: CANDIDATE_QUALITY,
                        band,
                        radii,
                        beyond_edge,
                        votes,
                        voters,
                    };
                    let contains = |s: &Seen| {
                        let o = &s.circle;
                        o.r >= 1.2 * c.r && (o.x - c.x).hypot(o.y - c.y) < o.r
                    };
                    let here: Vec<Seen> = self.circles(k, &pass)?.into_iter().filter(contains).collect();
                    // Only a circle that holds `c` is asked whether it moved.
                    if here.is_empty() {
                        continue;
                    }
                    let there = self.circles(k + self.gap, &pass)?;
                    if !split_static(&here, &there).0.is_empty() {
                        return Ok(true);
                    }
                }
            }
        }
        Ok(false)
    }

    /// The ball's two sightings in files `k` and `k + gap` in this pass ([`moving_pair`]), if it moved there.
    /// The clean frame pass also notes the circles that stayed.
    fn pair_at(&mut self, k: usize, pass: &Pass) -> Result<Option<MovingPair>, TrackError> {
        let (gap, width) = (self.gap, self.width);
        let good = |s: &Seen| s.circle.support > pass.threshold;
        let a: Vec<Seen> = self.circles(k, pass)?.into_iter().filter(good).collect();
        // Nothing in the first file, no pair (and nothing that stayed): the second is not looked at.
        if a.is_empty() {
            return Ok(None);
        }
        let b: Vec<Seen> = self.circles(k + gap, pass)?.into_iter().filter(good).collect();
        // A circle whose pixels did not change between the two files is still, whether or not the other
        // file's search found it again.
        let (a_moved, a_static) = self.frames.split_still(k, k + gap, &a, &b)?;
        let (b_moved, _) = self.frames.split_still(k, k + gap, &b, &a)?;
        let loose = |s: &Seen| s.circle.support > CANDIDATE_QUALITY;
        let a_all: Vec<Seen> = self.circles(k, pass)?.into_iter().filter(loose).collect();
        let b_all: Vec<Seen> = self.circles(k + gap, pass)?.into_iter().filter(loose).collect();
        let (a_loose, _) = self.frames.split_still(k, k + gap, &a_all, &b_all)?;
        let (b_loose, _) = self.frames.split_still(k, k + gap, &b_all, &a_all)?;
        if pass.threshold == CLEAN_QUALITY
            && !pass.beyond_edge
            && pass.votes == Votes::Frame
            && pass.voters == Voters::Strongest
        {
            for c in a_static.iter().map(|s| &s.circle) {
                if !self.still.iter().any(|s| (s.0 - c.x).hypot(s.1 - c.y) < 0.5 * c.r) {
                    self.still.push((c.x, c.y, c.r, c.support));
                }
            }
        }
        moving_pair(
            &a_moved,
            &b_moved,
            (&a_loose, &b_loose),
            width,
            pass.threshold,
            |mx, my, r, reach, least| {
                Ok(gap < 2
                    || self
                        .circles(k + gap / 2, pass)?
                        .iter()
                        .any(|s| seen_halfway(&s.circle, (mx, my, reach), r, least)))
            },
        )
    }

    /// The clearest pair at files `k` and `k + gap` in this (doubtful) pass made by following: of the
    /// [`FOLLOWED`] clearest circles of file `k`, each that moved (by its pixels) is looked for again where it
    /// was, in file `k + gap` and, from the middle of the two, half-way ([`FrameCache::follow`]); it is a
    /// pair when both are found at [`CANDIDATE_QUALITY`] as one ball that moved ([`one_ball_moved`]), the
    /// second moved by its pixels too, and the half-way circle is of its size within the reach
    /// [`first_found`] allows. In heavy noise a ball's rim, clear in one file, may be missing from the next
    /// file's vote peaks, outvoted by grains and circles of noise, while a search from where it was finds
    /// it. `None` when no circle moved or none was found again.
    fn followed_pair_at(&mut self, k: usize, pass: &Pass) -> Result<Option<MovingPair>, TrackError> {
        let (gap, width) = (self.gap, self.width);
        let loose = |s: &Seen| s.circle.support > CANDIDATE_QUALITY;
        let mut a: Vec<Seen> = self.circles(k, pass)?.into_iter().filter(loose).collect();
        a.truncate(FOLLOWED);
        let (a_moved, _) = self.frames.split_still(k, k + gap, &a, &[])?;
        let mut best: Option<MovingPair> = None;
        for sa in &a_moved {
            let half_width = follow_half_width(sa.circle.r);
            let Some(sb) = self.frames.follow(k + gap, &sa.circle, half_width)? else {
                continue;
            };
            if !loose(&sb) || !one_ball_moved(sa, &sb, width) {
                continue;
            }
            let (b_moved, _) = self.frames.split_still(k, k + gap, std::slice::from_ref(&sb), &[])?;
            if b_moved.is_empty() {
                continue;
            }
            let (mx, my, reach) = halfway_between(&sa.circle, &sb.circle);
            if gap >= 2 {
                let middle = Circle {
                    x: mx,
                    y: my,
                    ..sa.circle
                };
                let Some(sm) = self.frames.follow(k + gap / 2, &middle, half_width)? else {
                    continue;
                };
                if !seen_halfway(&sm.circle, (mx, my, reach), sa.circle.r, CANDIDATE_QUALITY) {
                    continue;
                }
            }
            let pair = MovingPair {
                a: sa.circle,
                b: sb.circle,
                other: None,
            };
            if best.as_ref().is_none_or(|b| clarity(&pair) > clarity(b)) {
                best = Some(pair);
            }
        }
        Ok(best)
    }

    /// What acquisition learnt from the moving pair seen in files `k` and `k + gap`.
    fn acquired(&self, k: usize, pair: &MovingPair) -> Acquired {
        let r = 0.5 * (pair.a.r + pair.b.r);
        // `k` counts search positions; time follows frame indices, which count dropped frames too.
        let (clip, order, n) = (self.clip, self.order, self.clip.len());
        let sign = if order == Order::Reversed { -1.0 } else { 1.0 };
        let t = |pos: usize| sign * clip.time_of(clip.files()[order.file(pos, n)].index);
        Acquired {
            radius: radius_window(r),
            seed: ((t(k), pair.a.x, pair.a.y), (t(k + self.gap), pair.b.x, pair.b.y)),
            file: order.file(k, n),
            second: pair
                .other
                .map(|o| (clip.files()[order.file(k, n)].index as usize, o.x, o.y)),
        }
    }
}

/// The error when no pair moved: no ball at all, or the clearest circles that stayed where they were.
fn nothing_moved(clip: &Clip, mut still: Vec<(f64, f64, f64, f64)>, min_radius: f64, max_radius: f64) -> TrackError {
    still.sort_by(|p, q| q.3.total_cmp(&p.3));
    let clip_name = clip.dir().display().to_string();
    if still.is_empty() {
        return TrackError::NoBall {
            clip: clip_name,
            min_radius,
            max_radius,
        };
    }
    TrackError::NothingMoves {
        clip: clip_name,
        circles: still
            .iter()
            .take(3)
            .map(|c| format!("radius {:.1} px at ({:.0}, {:.0})", c.2, c.0, c.1))
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// What one early pair of files showed in one radius band (see [`PairSearch::at_first_pair`]).
enum Early {
    /// No circle in the pair's first file.
    Nothing,
    /// Circles, none of them the ball moving cleanly.
    Seen,
    /// The ball.
    Ball(Acquired),
    /// A moving circle inside a larger moving one: left to the full search.
    Lobe,
}

/// Pairs of files tried after the first in the band of the first circle seen (see
/// [`PairSearch::at_first_pair`]): 8 ms at the sighting gap, long enough for a ball cut by the frame's edge
/// to come into view at drop speeds, or for a slow one to move a twentieth of its radius in a gap.
const EARLY_PAIRS: usize = 8;

/// The most [`ring_motion`] round a circle standing on still ground: a few times the ≈ 0.7 σ of noise alone,
/// well under the tens of gray levels between a ball and its backdrop.
const STILL_RING_SIGMAS: f64 = 3.0;

/// How much clearer (in quality) a moving circle inside a doubtful one must be to take its place (see
/// [`PairSearch::clearer_inside`]): more than the ±0.04 or so that refining the same rim from two starts gives.
const CLEARER_BY: f64 = 0.05;

/// The multiples of the sighting gap a clean pass tries in turn (see [`PairSearch::through_clip_at_longer_gaps`]):
/// up to 4 ms at 10,000 fps, enough for a ball falling at 0.5 m/s seen at 1.5 mm/px to move [`MIN_PAIR_MOVE_PX`].
const LONGER_GAPS: [usize; 3] = [1, 2, 4];

/// The least distance between a pair's two sightings for it to count as moving, px.
const MIN_PAIR_MOVE_PX: f64 = 1.5;

/// How long apart the two sightings of a pair are, s: long enough for a falling ball to move clearly more
/// than [`MIN_PAIR_MOVE_PX`] at the speeds and scales of drop tests, short enough for gravity to leave it near
/// the middle of its path half-way.
const SIGHTING_GAP_S: f64 = 1e-3;

/// Files between the two sightings of a pair: [`SIGHTING_GAP_S`] at the clip's frame rate (10 frames at
/// 10,000 fps, 300 at 300,000), at least 1 and less than the clip. A gap counted in frames instead would
/// see a ball filmed at 40,000 fps move a pixel in it and take it for still.
fn sighting_gap(fps: f64, files: usize) -> usize {
    let frames = (SIGHTING_GAP_S * fps).round();
    let frames = if frames.is_finite() && frames >= 1.0 {
        frames as usize
    } else {
        1
    };
    frames.min(files.saturating_sub(1)).max(1)
}

/// The clearest pair (circle in the first frame, in the second) of the same size and of one ball (the same
/// look, see [`look_correlation`], or, for a plain disc, one that stands out from its surroundings in both,
/// see [`disc_contrast`]) that moved by more than a pixel and a half and less than half the frame's width, and
/// that `halfway(x, y, r, reach, least)` finds again within `reach` of its middle with a circle clearer than
/// `least` (`threshold` for the ball): half-way, the ball is near the middle of its two sightings (a quarter of
/// the distance covered allows for gravity and for a bounce between them). Of the `loose` circles (any above
/// [`CANDIDATE_QUALITY`]), the first such pair clear of the ball (two radii away in both frames) is returned
/// as a second ball: one cut by the frame's edge is less clear than the ball, but a ball all the same.
fn moving_pair(
    a: &[Seen],
    b: &[Seen],
    loose: (&[Seen], &[Seen]),
    width: f64,
    threshold: f64,
    mut halfway: impl FnMut(f64, f64, f64, f64, f64) -> Result<bool, TrackError>,
) -> Result<Option<MovingPair>, TrackError> {
    let Some((fa, fb)) = first_found(pairs(a, b, width), &mut halfway, threshold)? else {
        return Ok(None);
    };
    // Another ball: a pair of the looser circles clear of the ball (two radii) in both frames.
    let clear = |p: &(Circle, Circle)| {
        (p.0.x - fa.x).hypot(p.0.y - fa.y) >= 2.0 * fa.r && (p.1.x - fb.x).hypot(p.1.y - fb.y) >= 2.0 * fb.r
    };
    let others: Vec<(Circle, Circle)> = pairs(loose.0, loose.1, width).into_iter().filter(clear).collect();
    let other = first_found(others, &mut halfway, CANDIDATE_QUALITY)?.map(|(oa, _)| oa);
    Ok(Some(MovingPair { a: fa, b: fb, other }))
}

/// The pairs of `a` × `b` of one size and one ball (see [`moving_pair`]) that moved, clearest first.
fn pairs(a: &[Seen], b: &[Seen], width: f64) -> Vec<(Circle, Circle)> {
    let mut moving: Vec<(Circle, Circle)> = Vec::new();
    for sa in a {
        for sb in b {
            if one_ball_moved(sa, sb, width) {
                moving.push((sa.circle, sb.circle));
            }
        }
    }
    moving.sort_by(|p, q| q.0.support.min(q.1.support).total_cmp(&p.0.support.min(p.1.support)));
    moving
}

/// Whether `a` and `b`, seen in two files, are one ball that moved: of one size (within 5 % and a pixel),
/// one ball (the same look, see [`look_correlation`], or both standing out from their surroundings, see
/// [`disc_contrast`]), moved by more than [`MIN_PAIR_MOVE_PX`] and less than half the region's `width`.
fn one_ball_moved(a: &Seen, b: &Seen, width: f64) -> bool {
    let (ca, cb) = (a.circle, b.circle);
    let same_size = of_a_size(ca.r, cb.r);
    let moved = (ca.x - cb.x).hypot(ca.y - cb.y);
    let same_ball =
        look_correlation(&a.look, &b.look) >= MIN_LOOK_CORRELATION || a.contrast.min(b.contrast) >= MIN_DISC_CONTRAST;
    same_size && moved > MIN_PAIR_MOVE_PX && moved < 0.5 * width && same_ball
}

/// Whether a circle of radius `other` is of the size `r`: within 5 % of it and a pixel.
fn of_a_size(r: f64, other: f64) -> bool {
    (other - r).abs() <= 0.05 * r + 1.0
}

/// Whether `c`, seen half-way between two sightings of radius `r`, is the ball there: clearer than `least`,
/// within `reach` of their middle (x, y) ([`halfway_between`]) and of their size.
fn seen_halfway(c: &Circle, (x, y, reach): (f64, f64, f64), r: f64, least: f64) -> bool {
    c.support > least && (c.x - x).hypot(c.y - y) <= reach && of_a_size(r, c.r)
}

/// Where the ball is, half-way between two sightings `a` and `b`, give or take: a quarter of the distance
/// covered allows for gravity and for a bounce between them, and 2 px for the sightings' own errors. The
/// middle (x, y) and that reach, px.
fn halfway_between(a: &Circle, b: &Circle) -> (f64, f64, f64) {
    (
        0.5 * (a.x + b.x),
        0.5 * (a.y + b.y),
        0.25 * (a.x - b.x).hypot(a.y - b.y) + 2.0,
    )
}

/// The first of `pairs` that `halfway` finds again with a circle clearer than `least`.
fn first_found(
    pairs: Vec<(Circle, Circle)>,
    halfway: &mut impl FnMut(f64, f64, f64, f64, f64) -> Result<bool, TrackError>,
    least: f64,
) -> Result<Option<(Circle, Circle)>, TrackError> {
    for (ca, cb) in pairs {
        let (mx, my, reach) = halfway_between(&ca, &cb);
        if halfway(mx, my, ca.r, reach, least)? {
            return Ok(Some((ca, cb)));
        }
    }
    Ok(None)
}

/// The clearest circles of a file that [`PairSearch::followed_pair_at`] looks for again in the next.
const FOLLOWED: usize = 3;

/// How far either side of a followed circle's rim its next sighting is looked for, px: a third of its
/// radius (a ball moves less than that in a sighting gap unless it is small and fast, and then its vote
/// peaks find it), at least 6 px.
fn follow_half_width(r: f64) -> f64 {
    (r / 3.0).max(6.0)
}

/// The first of `found` (in search order) whose `clarity` is within [`CLEARER_BY`] of the clearest's: pairs
/// that close are as clear as one rim refined from two starts, so clarity does not choose among them, and the
/// earliest starts the track nearest the clip's start, as a clean pass would. A track started later is
/// measured back from there, and in heavy noise where it starts moves every frame's centre by up to a few
/// tenths of a pixel. `None` when `found` is empty. Cost: two passes over `found`.
fn earliest_of_the_clearest<T>(found: Vec<T>, clarity: impl Fn(&T) -> f64) -> Option<T> {
    let clearest = found.iter().map(&clarity).fold(f64::NEG_INFINITY, f64::max);
    found.into_iter().find(|f| clarity(f) >= clearest - CLEARER_BY)
}

/// How clear a pair is: its weaker sighting's quality.
fn clarity(p: &MovingPair) -> f64 {
    p.a.support.min(p.b.support)
}

/// The ball's two sightings, and a second moving ball-like circle (its first sighting) when there is one.
struct MovingPair {
    a: Circle,
    b: Circle,
    other: Option<Circle>,
}

/// The sightings of `here` that are not in `there` at the same place and size (within a pixel and a half or
/// 5 % of the radius), and those that are (static things).
fn split_static(here: &[Seen], there: &[Seen]) -> (Vec<Seen>, Vec<Seen>) {
    here.iter().cloned().partition(|s| !seen_in_place(&s.circle, there))
}

/// Whether `there` holds a circle where `c` is, of its size (see [`split_static`]).
fn seen_in_place(c: &Circle, there: &[Seen]) -> bool {
    there
        .iter()
        .map(|o| &o.circle)
        .any(|o| (o.x - c.x).hypot(o.y - c.y) <= MIN_PAIR_MOVE_PX.max(0.05 * c.r) && of_a_size(c.r, o.r))
}

/// A circle seen in a frame, with what its disc looks like there.
#[derive(Clone)]
struct Seen {
    circle: Circle,
    /// The frame's levels on a grid over the disc (see [`disc_look`]).
    look: Vec<f32>,
    /// How far the disc stands out from its surroundings (see [`disc_contrast`]), on the frame or on its
    /// difference from the background, whichever shows it more.
    contrast: f64,
}

/// The least [`look_correlation`] of two sightings of one ball.
const MIN_LOOK_CORRELATION: f64 = 0.3;

/// Points across the disc's diameter of the grid [`disc_look`] samples.
const LOOK_GRID: usize = 15;

/// What a disc looks like: the image's levels (bilinear) on a [`LOOK_GRID`]² grid over the square of side
/// 1.6 r about its centre, those within 0.8 r of it, in a fixed order (NaN where outside the image). Cost:
/// ~180 samples.
fn disc_look<P: Pixel>(img: &Plane<P>, c: &Circle) -> Vec<f32> {
    let half = (LOOK_GRID / 2) as f64;
    let mut out = Vec::with_capacity(LOOK_GRID * LOOK_GRID);
    for j in 0..LOOK_GRID {
        for i in 0..LOOK_GRID {
            let (u, v) = ((i as f64 - half) / half, (j as f64 - half) / half);
            if u.hypot(v) > 1.0 {
                continue;
            }
            let (x, y) = (c.x + 0.8 * c.r * u, c.y + 0.8 * c.r * v);
            out.push(img.sample(x as f32, y as f32).unwrap_or(f32::NAN));
        }
    }
    out
}

/// The least [`disc_contrast`] of a ball without a look of its own (a silhouette, a plain disc): it stands
/// out from what surrounds it by at least the surroundings' own scatter.
const MIN_DISC_CONTRAST: f64 = 1.0;

/// How far the disc of radius `r` at (x, y) stands out from a ring around it: |median inside 0.8 r − median
/// of the ring 1.2 r … 1.6 r| over the ring's robust scatter (1.4826 × MAD), floored at one gray level. A
/// plain ball or a silhouette is a disc of its own; a circle that rim votes find in grains or noise has the
/// same texture inside as outside (contrast well below 1). Pixels outside the image are skipped; 0 when
/// fewer than 16 remain on either side. Cost: O(r²) pixel reads on a grid of step r / 12.
fn disc_contrast<P: Pixel>(img: &Plane<P>, x: f64, y: f64, r: f64) -> f64 {
    let (mut inside, mut ring) = disc_and_ring(img, x, y, r);
    if inside.len() < 16 || ring.len() < 16 {
        return 0.0;
    }
    let m_in = median(&mut inside);
    let m_out = median(&mut ring);
    let mut dev: Vec<f64> = ring.iter().map(|v| (v - m_out).abs()).collect();
    (m_in - m_out).abs() / (1.4826 * median(&mut dev)).max(1.0)
}

/// The image's levels on a grid of step r / 12 (at least a pixel) within 0.8 r of (x, y), and on the ring
/// 1.2 r … 1.6 r around it; pixels outside the image skipped. Cost: O(r²) pixel reads.
fn disc_and_ring<P: Pixel>(img: &Plane<P>, x: f64, y: f64, r: f64) -> (Vec<f64>, Vec<f64>) {
    let reach = 1.6 * r;
    let (mut inside, mut ring) = (Vec::new(), Vec::new());
    square_grid(img, x, y, reach, (r / 12.0).max(1.0), |(dx, dy), _, v| {
        let d = dx.hypot(dy);
        if d <= 0.8 * r {
            inside.push(v);
        } else if (1.2 * r..=reach).contains(&d) {
            ring.push(v);
        }
    });
    (inside, ring)
}

/// How far the ring 1.2 r … 1.6 r around a circle is from still, in a frame's difference from the background
/// (`moving`): the ring's median difference over the sensor noise σ (floored at one gray level). Around a
/// ball the ring is the backdrop, still but for noise (≈ 0.7); around a mark printed on a ball it is the
/// ball, moving. `None` when fewer than 16 ring pixels are in view.
fn ring_motion(moving: &Plane<f32>, c: &Circle, noise: f32) -> Option<f64> {
    let (_, mut ring) = disc_and_ring(moving, c.x, c.y, c.r);
    (ring.len() >= 16).then(|| median(&mut ring) / f64::from(noise.max(1.0)))
}

/// The correlation of two discs' looks (see [`disc_look`]) over the points both have: one ball seen twice
/// a few frames apart has the same shading, print and seam (≈ 1 less what noise and spin take); two
/// unrelated patches of grains or noise, which vote for circles where they happen to line up, ≈ 0. A plain
/// disc's look is flat but for noise: such a ball is told by its [`disc_contrast`] instead. 0 when
/// fewer than 16 points are shared or either look is flat.
fn look_correlation(a: &[f32], b: &[f32]) -> f64 {
    let pairs: Vec<(f64, f64)> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(&x, &y)| (x as f64, y as f64))
        .collect();
    if pairs.len() < 16 {
        return 0.0;
    }
    let n = pairs.len() as f64;
    let (ma, mb) = (
        pairs.iter().map(|p| p.0).sum::<f64>() / n,
        pairs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in &pairs {
        sab += (x - ma) * (y - mb);
        saa += (x - ma).powi(2);
        sbb += (y - mb).powi(2);
    }
    if saa <= 0.0 || sbb <= 0.0 {
        return 0.0;
    }
    sab / (saa * sbb).sqrt()
}

/// Pixels sorted side by side in [`pixel_median`]: the compare-exchanges of a block run in SIMD lanes.
const MEDIAN_LANES: usize = 64;

/// The per-pixel median of `planes` (all of one length): at each pixel the value of rank `planes.len() / 2`
/// (the upper median for an even count). An odd–even transposition network sorts each pixel's values
/// ([`MEDIAN_LANES`] pixels at a time), branch-free, where a selection per pixel branches on every value.
/// Cost: m(m − 1)/2 min–max pairs per pixel for m planes.
fn pixel_median(planes: &[Vec<f32>]) -> Vec<f32> {
    let m = planes.len();
    let len = planes.first().map_or(0, Vec::len);
    let mut out = vec![0.0f32; len];
    if m == 0 {
        return out;
    }
    let mut block = vec![[0.0f32; MEDIAN_LANES]; m];
    for start in (0..len).step_by(MEDIAN_LANES) {
        let n = MEDIAN_LANES.min(len - start);
        for (b, p) in block.iter_mut().zip(planes) {
            b[..n].copy_from_slice(&p[start..start + n]);
        }
        for round in 0..m {
            for i in (round % 2..m.saturating_sub(1)).step_by(2) {
                let (lo, hi) = block.split_at_mut(i + 1);
                for (a, b) in lo[i].iter_mut().zip(hi[0].iter_mut()) {
                    let (x, y) = (*a, *b);
                    *a = x.min(y);
                    *b = x.max(y);
                }
            }
        }
        out[start..start + n].copy_from_slice(&block[m / 2][..n]);
    }
    out
}

/// Frames decoded once each, by search position.
struct FrameCache<'a> {
    clip: &'a Clip,
    /// Which file a search position reads.
    order: Order,
    opts: &'a ClipTracking,
    gain: f32,
    frames: HashMap<usize, Frame>,
    /// Frames' differences from the background (see [`FrameCache::keep_moving`]).
    moving: HashMap<usize, Vec<f32>>,
    /// The last difference between two files asked for, with their search positions (see
    /// [`FrameCache::change`]).
    change: Option<((usize, usize), Vec<f32>)>,
}

/// The share of a difference's squared values [`local_variance`] averages: the smallest 80 %, so that what
/// moved near a circle does not count as noise, and an average, not a median, so that 8-bit levels' few
/// distinct squares do not bias it.
const CHI2_1_KEPT: f64 = 0.8;

/// The mean of the smallest [`CHI2_1_KEPT`] of χ² with one degree of freedom: E[Z² | |Z| < a] for a standard
/// normal Z with P(|Z| < a) = 0.8 (a = 1.2816), (0.8 − 2 a φ(a)) / 0.8.
const CHI2_1_KEPT_MEAN: f64 = 0.4377;

/// The least noise variance of a difference between two files, (0–255 scale)²: a quantisation step's,
/// so that noiseless frames (synthetic or 8-bit with most pixels equal) do not make every change significant.
const MIN_CHANGE_VARIANCE: f64 = 1.0 / 6.0;

/// The half-width of the band about a rim that [`rim_change`] watches, as a share of the radius (at least
/// 2 px): narrow, so that a rim that moved a pixel and a half changes much of it.
const RIM_BAND: f64 = 0.05;

/// The least [`rim_change`] of an object that moved: a still rim's is 0 ± 1 in sensor noise, a ball's that
/// moved a pixel and a half tens to thousands.
const STILL_CHANGE_Z: f64 = 4.0;

/// How far the band r ± [`RIM_BAND`] r (at least ±2 px) about circle `c` changed between two files (their
/// difference `diff`), in standard errors of noise alone: (mean diff² over the band / the noise variance
/// − 1) / √(2 / n) for the band's n pixels, the noise variance taken about the circle ([`local_variance`]:
/// sensor noise grows with brightness). A still object's rim changes by noise alone; a moving one sweeps its
/// edge across the band. Pixels outside the image are skipped; `None` when fewer than 16 remain. Cost: O(r²)
/// pixel reads.
fn rim_change(diff: &Plane<f32>, c: &Circle) -> Option<f64> {
    let half = (RIM_BAND * c.r).max(2.0);
    let (inner, outer) = ((c.r - half).max(0.0), c.r + half);
    let (mut sum, mut n) = (0.0, 0usize);
    square_grid(diff, c.x, c.y, outer, 1.0, |_, (px, py), v| {
        if (inner..=outer).contains(&(px - c.x).hypot(py - c.y)) {
            sum += v * v;
            n += 1;
        }
    });
    let variance = local_variance(diff, c)?;
    (n >= 16).then(|| (sum / n as f64 / variance - 1.0) / (2.0 / n as f64).sqrt())
}

/// The noise variance of a difference between two files about circle `c`, (0–255 scale)²: the mean of the
/// smallest [`CHI2_1_KEPT`] of `diff`² over the square of side 4 r about it (most of which stays still),
/// over that share's mean for noise alone ([`CHI2_1_KEPT_MEAN`]), at least [`MIN_CHANGE_VARIANCE`]. `None`
/// when fewer than 16 pixels are in view. Cost: about 1,000 pixel reads (a grid of step r / 8) and a
/// selection.
fn local_variance(diff: &Plane<f32>, c: &Circle) -> Option<f64> {
    let mut squares = Vec::new();
    square_grid(diff, c.x, c.y, 2.0 * c.r, (c.r / 8.0).max(1.0), |_, _, v| {
        squares.push(v * v)
    });
    if squares.len() < 16 {
        return None;
    }
    let kept = (squares.len() as f64 * CHI2_1_KEPT).round() as usize;
    squares.select_nth_unstable_by(kept, f64::total_cmp);
    let mean = squares[..kept].iter().sum::<f64>() / kept as f64;
    Some((mean / CHI2_1_KEPT_MEAN).max(MIN_CHANGE_VARIANCE))
}

/// Calls `f((dx, dy), (px, py), value)` for the points of a grid of step `step` (px, at least 1) over the
/// square of half-side `half` about (x, y): each point's offset from (x, y), the pixel nearest it and that
/// pixel's value; pixels outside the plane are skipped.
fn square_grid<P: Pixel>(
    plane: &Plane<P>,
    x: f64,
    y: f64,
    half: f64,
    step: f64,
    mut f: impl FnMut((f64, f64), (f64, f64), f64),
) {
    let n = (half / step).ceil() as i64;
    for j in -n..=n {
        for i in -n..=n {
            let (dx, dy) = (i as f64 * step, j as f64 * step);
            let (px, py) = ((x + dx).round(), (y + dy).round());
            if px < 0.0 || py < 0.0 || px >= plane.width as f64 || py >= plane.height as f64 {
                continue;
            }
            f((dx, dy), (px, py), f64::from(plane.at(px as usize, py as usize)));
        }
    }
}

/// Whether circle `c`'s rim stands out of the noise of `img` ([`rim_evidence`], over the tracker's rays): in
/// heavy noise a circle the refinement makes of noise, or of a seam's arc on the ball, has a quality as fair
/// as the ball's, and the pair the search then takes may not be the ball. The tracker refuses such a circle
/// too. Cost: about 15 µs.
fn rim_stands_out<P: Pixel>(img: &Plane<P>, c: &Circle, search: &EdgeSearch) -> bool {
    rim_evidence(img, (c.x, c.y, c.r), search.rays, None, search.surface_margin).stands_out()
}

/// Frames' differences from the background kept at once: the pairs and half-way frames being compared (a
/// 512×512 frame's is 1 MB).
const MOVING_KEPT: usize = 8;

impl<'a> FrameCache<'a> {
    fn new(clip: &'a Clip, opts: &'a ClipTracking, gain: f32, order: Order) -> Self {
        FrameCache {
            clip,
            order,
            opts,
            gain,
            frames: HashMap::new(),
            moving: HashMap::new(),
            change: None,
        }
    }

    fn get(&mut self, k: usize) -> Result<&Frame, TrackError> {
        if !self.frames.contains_key(&k) {
            let f = crate::clip::in_region(
                self.clip
                    .read(self.order.file(k, self.clip.len()), self.opts.read.png_decoder)
                    .expect("index in range")?,
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

    /// The searched region's width and height, px.
    fn size(&self) -> (usize, usize) {
        let (w, h) = self.opts.roi.map_or(self.clip.dimensions(), |r| (r.width, r.height));
        (w as usize, h as usize)
    }

    /// Keeps frame `k`'s difference from the background `bg` (levels, 0–255 scale): what moves. Computed once
    /// for every radius band and vote source that asks; all are let go when [`MOVING_KEPT`] are held.
    fn keep_moving(&mut self, k: usize, bg: &[f32]) -> Result<(), TrackError> {
        if self.moving.contains_key(&k) {
            return Ok(());
        }
        if self.moving.len() >= MOVING_KEPT {
            self.moving.clear();
        }
        let m = self.levels(k)?.iter().zip(bg).map(|(a, b)| (a - b).abs()).collect();
        self.moving.insert(k, m);
        Ok(())
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
        let out = pixel_median(&planes);
        // Frames other than the first and last are not needed again.
        for &k in &picks[1..m - 1] {
            self.frames.remove(&k);
        }
        Ok(Some(out))
    }

    /// The difference between files `k1` and `k2` (levels, 0–255 scale), row-major, the second scaled to
    /// the first's mean level (lamps flicker; a ball moving across the frame hardly changes its mean). The
    /// last pair asked is kept. Cost: two frames' levels.
    fn change(&mut self, k1: usize, k2: usize) -> Result<&[f32], TrackError> {
        if self.change.as_ref().is_none_or(|c| c.0 != (k1, k2)) {
            let (a, b) = (self.levels(k1)?, self.levels(k2)?);
            let sum = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>();
            let (sa, sb) = (sum(&a), sum(&b));
            let scale = if sa > 0.0 && sb > 0.0 { (sa / sb) as f32 } else { 1.0 };
            self.change = Some(((k1, k2), a.iter().zip(&b).map(|(p, q)| p - scale * q).collect()));
        }
        Ok(&self.change.as_ref().expect("just set").1)
    }

    /// `here` (circles seen in file `k1` or `k2`) split into those that moved between the two files and those
    /// that stayed still: by their pixels where the rim can be measured ([`rim_change`] below
    /// [`STILL_CHANGE_Z`]: a still object, which a search of the other file may have missed or found a
    /// little elsewhere in heavy noise), else by `there` (the other file's circles) holding one at the same
    /// place and size ([`seen_in_place`]). Pixels settle it both ways: in heavy noise a slow ball's sides,
    /// which hardly move, can make a circle where it was.
    fn split_still(
        &mut self,
        k1: usize,
        k2: usize,
        here: &[Seen],
        there: &[Seen],
    ) -> Result<(Vec<Seen>, Vec<Seen>), TrackError> {
        if here.is_empty() {
            return Ok((Vec::new(), Vec::new()));
        }
        let (w, h) = self.size();
        let diff = Plane::new(self.change(k1, k2)?, w, h);
        let (mut moved, mut still) = (Vec::new(), Vec::new());
        for s in here {
            let z = rim_change(&diff, &s.circle);
            let is_still = match z {
                Some(z) => z < STILL_CHANGE_Z,
                None => seen_in_place(&s.circle, there),
            };
            if is_still {
                still.push(s.clone())
            } else {
                moved.push(s.clone())
            }
        }
        Ok((moved, still))
    }

    /// The share of circle `c`'s sectors whose rim stands out of the noise in file `k` ([`rim_evidence`]; 1
    /// for a circle too small to judge). A ball's rim stands out nearly all round, a seam's arc or a circle
    /// sharing a piece of the ball's rim in few sectors. Cost: about 15 µs once the frame is decoded.
    fn rim_share(&mut self, k: usize, c: &Circle) -> Result<f64, TrackError> {
        let rays = self.opts.tracker.search.rays;
        let margin = self.opts.tracker.search.surface_margin;
        let gain = self.gain;
        let f = self.get(k)?;
        let e = with_plane(
            &f.pixels,
            gain,
            |p| on_plane!(p, p => rim_evidence(&p, (c.x, c.y, c.r), rays, None, margin)),
        );
        Ok(if e.too_small || e.sectors == 0 {
            1.0
        } else {
            e.standing_out as f64 / e.sectors as f64
        })
    }

    /// Circle `c` looked for again in file `k` from where it is: refined on the frame with the rays'
    /// window `half_width` px either side of its rim, re-centred while it moves ([`refine_circle`]), then
    /// measured again with the window candidates end with (a wide window's quality is not theirs) and seen
    /// as candidates are (quality, look, contrast on the frame). Not grown outward as candidates are: in
    /// heavy noise that takes a ball to a circle of noise round it. `None` when too few edges are found or
    /// the circle found has no rim standing out of the noise ([`rim_stands_out`]). Cost: two refinements,
    /// each up to five passes of the rays across their window.
    fn follow(&mut self, k: usize, c: &Circle, half_width: f64) -> Result<Option<Seen>, TrackError> {
        let search = &self.opts.tracker.search;
        let wide = EdgeSearch {
            half_width,
            beyond_window: false,
            ..search.clone()
        };
        let settled = settled_search(search);
        let gain = self.gain;
        let f = self.get(k)?;
        Ok(with_plane(&f.pixels, gain, |p| {
            on_plane!(p, p => refine_circle(&p, c.x, c.y, c.r, &wide, None)
            .and_then(|f| refine_circle(&p, f.fit.x, f.fit.y, f.fit.r, &settled, None))
            .map(|f| Circle {
                x: f.fit.x,
                y: f.fit.y,
                r: f.fit.r,
                support: f.quality(),
            })
            .filter(|circle| rim_stands_out(&p, circle, search))
            .map(|circle| {
                Seen {
                    look: disc_look(&p, &circle),
                    contrast: disc_contrast(&p, circle.x, circle.y, circle.r),
                    circle,
                }
            }))
        }))
    }

    /// Circle candidates in frame `k`: vote peaks from `votes`, each measured on the frame itself, those
    /// whose rim stands out of the noise ([`rim_stands_out`]).
    fn candidates(
        &mut self,
        k: usize,
        det: &CircleDetection,
        votes: Votes,
        background: Option<&[f32]>,
    ) -> Result<Vec<Seen>, TrackError> {
        let (w, h) = self.size();
        if let Some(bg) = background {
            self.keep_moving(k, bg)?;
        }
        self.get(k)?;
        let (f, gain) = (&self.frames[&k], self.gain);
        let moving = background.map(|_| Plane::new(&self.moving[&k], w, h));
        let peaks = match (votes, &moving) {
            (Votes::Moving, Some(m)) => detect_circles(m, det),
            _ => with_plane(&f.pixels, gain, |p| on_plane!(p, p => detect_circles(&p, det))),
        };
        let search = &self.opts.tracker.search;
        Ok(with_plane(&f.pixels, gain, |p| {
            on_plane!(p, p => refine_candidates(&p, peaks, det, search, None, CANDIDATE_QUALITY)
                .into_iter()
                .filter(|(c, _)| rim_stands_out(&p, c, search))
                .map(|(circle, _)| {
                    let (x, y, r) = (circle.x, circle.y, circle.r);
                    let on_moving = moving.as_ref().map_or(0.0, |m| disc_contrast(m, x, y, r));
                    Seen {
                        look: disc_look(&p, &circle),
                        contrast: disc_contrast(&p, x, y, r).max(on_moving),
                        circle,
                    }
                })
                .collect())
        }))
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_pixel_median_is_the_middle_value_at_every_pixel() {
        use proptest::prelude::*;
        let planes = proptest::collection::vec(proptest::collection::vec(-300.0f32..300.0, 150), 1..12);
        proptest!(|(planes in planes)| {
            let got = pixel_median(&planes);
            for (i, g) in got.iter().enumerate() {
                let mut column: Vec<f32> = planes.iter().map(|p| p[i]).collect();
                let m = column.len();
                prop_assert_eq!(*g, *column.select_nth_unstable_by(m / 2, f32::total_cmp).1);
            }
        });
    }

    #[test]
    fn the_sighting_gap_is_a_time_not_a_frame_count() {
        use super::sighting_gap;
        assert_eq!(sighting_gap(10_000.0, 400), 10);
        assert_eq!(sighting_gap(40_000.0, 1600), 40);
        assert_eq!(sighting_gap(500.0, 400), 1);
        assert_eq!(sighting_gap(40_000.0, 15), 14);
        assert_eq!(sighting_gap(f64::NAN, 15), 1);
        assert_eq!(sighting_gap(10_000.0, 1), 1);
    }

    use super::*;
    use crate::testutil::{Scene, render};

    /// A folder of `frames` 256×256 PNG frames of a ball of radius `r` at `at(i)` in frame `i`.
    fn moving_ball_clip(frames: usize, at: impl Fn(usize) -> (f64, f64), r: f64) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..frames {
            let s = Scene {
                ball: (at(i).0, at(i).1, r),
                seed: i as u64,
                ..Scene::default()
            };
            let img = image::GrayImage::from_raw(256, 256, render(&s)).unwrap();
            img.save(dir.path().join(format!("f{i:04}.png"))).unwrap();
        }
        dir
    }

    /// Searched from the clip's end, the ball is sighted in its last frames: the later sighting first, at
    /// negated times, and `file` the clip's file of that sighting; searched from its start, in its first.
    #[test]
    fn the_ball_is_found_from_the_clip_s_end_in_negated_time() {
        let at = |i: usize| (60.0 + 2.5 * i as f64, 70.0 + 1.5 * i as f64);
        let dir = moving_ball_clip(40, at, 40.0);
        let clip = Clip::open(dir.path()).unwrap();
        let opts = ClipTracking::default();
        let near = |s: Sighting, i: usize| (s.1 - at(i).0).hypot(s.2 - at(i).1) < 1.0;
        let forward = acquire_in(&clip, &opts, 1.0, 2.0, Order::Forward).unwrap();
        assert_eq!(forward.file, 0);
        assert!(
            near(forward.seed.0, 0) && near(forward.seed.1, 10),
            "{:?}",
            forward.seed
        );
        assert_eq!((forward.seed.0.0, forward.seed.1.0), (0.0, clip.time_of(10)));
        let back = acquire_in(&clip, &opts, 1.0, 2.0, Order::Reversed).unwrap();
        assert_eq!(back.file, 39);
        assert!(near(back.seed.0, 39) && near(back.seed.1, 29), "{:?}", back.seed);
        assert_eq!((back.seed.0.0, back.seed.1.0), (-clip.time_of(39), -clip.time_of(29)));
        assert!((back.radius.0..=back.radius.1).contains(&40.0), "{:?}", back.radius);
    }

    /// A small ball falling slowly, 1 px per sighting gap (less than [`MIN_PAIR_MOVE_PX`]), is acquired over
    /// a longer gap at its own radius.
    #[test]
    fn a_ball_moving_less_than_a_pair_s_least_move_in_one_gap_is_sighted_over_a_longer_one() {
        let at = |i: usize| (120.0 + 0.03 * i as f64, 90.0 + 0.1 * i as f64);
        let dir = moving_ball_clip(60, at, 23.0);
        let clip = Clip::open(dir.path()).unwrap();
        let found = acquire(&clip, &ClipTracking::default(), 1.0, 2.0).unwrap();
        let ((t0, x0, y0), (t1, x1, y1)) = found.seed;
        let (i0, i1) = ((t0 * 10_000.0).round() as usize, (t1 * 10_000.0).round() as usize);
        assert!(i1 - i0 > 10, "sighted {} frames apart", i1 - i0);
        assert!((x0 - at(i0).0).hypot(y0 - at(i0).1) < 0.5, "{:?}", found.seed);
        assert!((x1 - at(i1).0).hypot(y1 - at(i1).1) < 0.5, "{:?}", found.seed);
        assert!((found.radius.0..=found.radius.1).contains(&23.0), "{:?}", found.radius);
    }

    fn look_of(scene: &Scene, c: (f64, f64, f64)) -> Vec<f32> {
        let px = render(scene);
        let circle = Circle {
            x: c.0,
            y: c.1,
            r: c.2,
            support: 1.0,
        };
        disc_look(&Plane::new(&px, scene.size.0, scene.size.1), &circle)
    }

    /// One ball seen twice, moved and with fresh noise, looks alike; two patches of the same grains drawn
    /// afresh do not, nor two places of one band.
    #[test]
    fn a_ball_looks_like_itself_and_grains_do_not() {
        let ball = |x: f64, seed: u64| Scene {
            ball: (x, 90.7, 40.0),
            noise: 6.0,
            seed,
            ..Scene::default()
        };
        let same = look_correlation(
            &look_of(&ball(120.3, 1), (120.3, 90.7, 40.0)),
            &look_of(&ball(131.8, 2), (131.8, 90.7, 40.0)),
        );
        assert!(same > 0.9, "ball {same}");
        let grains = |seed: u64| Scene {
            ball: (-500.0, -500.0, 1.0),
            surface: Some((0.0, 0.0)),
            band: (120.0, 25.0),
            seed,
            ..Scene::default()
        };
        for (a, b) in [((1, 128.0), (2, 128.0)), ((1, 100.0), (1, 160.0))] {
            let r = look_correlation(
                &look_of(&grains(a.0), (a.1, 128.0, 30.0)),
                &look_of(&grains(b.0), (b.1, 128.0, 30.0)),
            );
            assert!(r.abs() < MIN_LOOK_CORRELATION, "grains {r}");
        }
    }

    /// A plain ball stands out from its surroundings; a circle drawn in grains does not, however they are lit.
    #[test]
    fn a_ball_has_disc_contrast_and_grains_have_none() {
        let ball = render(&Scene {
            noise: 6.0,
            ..Scene::default()
        });
        let c = disc_contrast(&Plane::new(&ball, 256, 256), 120.3, 90.7, 40.0);
        assert!(c > 2.0 * MIN_DISC_CONTRAST, "ball {c}");
        for (level, grain) in [(90.0, 25.0), (160.0, 40.0)] {
            let grains = render(&Scene {
                ball: (-500.0, -500.0, 1.0),
                surface: Some((0.0, 0.0)),
                band: (level, grain),
                ..Scene::default()
            });
            let c = disc_contrast(&Plane::new(&grains, 256, 256), 128.0, 128.0, 30.0);
            assert!(c < 0.5 * MIN_DISC_CONTRAST, "grains {level}/{grain}: {c}");
        }
    }

    #[test]
    fn a_ball_stands_on_still_ground_and_a_mark_on_it_does_not() {
        let noise = 3.0;
        let scene = Scene {
            marks: vec![(5.0, 10.0, 12.0, 40.0)],
            noise,
            ..Scene::default()
        };
        let backdrop = render(&Scene {
            ball: (-500.0, -500.0, 1.0),
            seed: 2,
            ..scene.clone()
        });
        let frame = render(&scene);
        let moving: Vec<f32> = frame
            .iter()
            .zip(&backdrop)
            .map(|(&a, &b)| (f32::from(a) - f32::from(b)).abs())
            .collect();
        let moving = Plane::new(&moving, 256, 256);
        let (x, y, r) = scene.ball;
        let ball = ring_motion(&moving, &Circle { x, y, r, support: 1.0 }, noise as f32).unwrap();
        assert!(ball < STILL_RING_SIGMAS, "ball {ball}");
        let mark = Circle {
            x: x + 5.0,
            y: y + 10.0,
            r: 12.0,
            support: 1.0,
        };
        let mark = ring_motion(&moving, &mark, noise as f32).unwrap();
        assert!(mark > 3.0 * STILL_RING_SIGMAS, "mark {mark}");
    }

    /// A still disc's rim changes between two frames by their noise alone, whatever its size, level or the
    /// noise; a ball's that moved a pixel and a half sweeps its edge across the band.
    #[test]
    fn a_still_rim_changes_by_noise_alone_and_a_moving_one_does_not() {
        let (mut still_worst, mut moved_least) = (f64::NEG_INFINITY, f64::INFINITY);
        for seed in 0..24u64 {
            let noise = [0.0, 2.0, 6.0, 12.0][seed as usize % 4];
            let r = [9.0, 16.0, 30.0][seed as usize % 3];
            let level = [40.0, 200.0][seed as usize % 2];
            let scene = |ball: (f64, f64, f64), seed: u64| Scene {
                ball,
                ball_level: 170.0,
                noise,
                seed,
                distractors: vec![(190.0, 60.0, r, level), (60.0, 200.0, 0.7 * r, 255.0 - level)],
                ..Scene::default()
            };
            let (a, b) = (
                render(&scene((100.3, 110.2, 40.0), 2 * seed)),
                render(&scene((101.2, 111.4, 40.0), 2 * seed + 1)),
            );
            let diff: Vec<f32> = a.iter().zip(&b).map(|(&p, &q)| f32::from(p) - f32::from(q)).collect();
            let diff = Plane::new(&diff, 256, 256);
            let circle = |x, y, r| Circle { x, y, r, support: 1.0 };
            for c in [circle(190.0, 60.0, r), circle(60.0, 200.0, 0.7 * r)] {
                still_worst = still_worst.max(rim_change(&diff, &c).unwrap());
            }
            moved_least = moved_least.min(rim_change(&diff, &circle(100.3, 110.2, 40.0)).unwrap());
        }
        assert!(still_worst < STILL_CHANGE_Z, "a still rim changed by {still_worst}");
        assert!(
            moved_least > 3.0 * STILL_CHANGE_Z,
            "a moving rim changed by only {moved_least}"
        );
    }

    /// The two scenes drawn as the frames of a clip in a fresh folder (removed when the guard is dropped), each
    /// with its own noise seed.
    fn two_frames(scenes: [Scene; 2]) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        for (i, s) in scenes.into_iter().enumerate() {
            let s = Scene { seed: i as u64, ..s };
            let img = image::GrayImage::from_raw(s.size.0 as u32, s.size.1 as u32, render(&s)).unwrap();
            img.save(dir.path().join(format!("f{i:04}.png"))).unwrap();
        }
        dir
    }

    /// A sighting of the circle (x, y, r) at quality 0.9, its look not taken.
    fn seen(x: f64, y: f64, r: f64) -> Seen {
        Seen {
            circle: Circle { x, y, r, support: 0.9 },
            look: Vec::new(),
            contrast: 0.0,
        }
    }

    /// Whether a circle stayed put is told by the pixels: a still disc the other frame's search missed is
    /// still, and a slowly moving ball is not held still by a circle of noise where it was.
    #[test]
    fn pixels_tell_a_still_circle_from_a_slow_ball() {
        let disc = (190.0, 60.0, 14.0, 60.0);
        let dir = two_frames([(100.0, 100.0, 40.0), (101.0, 102.5, 40.0)].map(|ball| Scene {
            ball,
            noise: 12.0,
            distractors: vec![disc],
            ..Scene::default()
        }));
        let clip = Clip::open(dir.path()).unwrap();
        let opts = ClipTracking::default();
        let mut frames = FrameCache::new(&clip, &opts, 1.0, Order::Forward);
        let here = [seen(100.0, 100.0, 40.0), seen(disc.0, disc.1, disc.2)];
        // The second frame's search: a ghost where the ball was, and the disc missed.
        let there = [seen(100.2, 100.1, 40.1)];
        let (moved, still) = frames.split_still(0, 1, &here, &there).unwrap();
        let centres = |v: &[Seen]| v.iter().map(|s| (s.circle.x, s.circle.y)).collect::<Vec<_>>();
        assert_eq!(centres(&moved), vec![(100.0, 100.0)]);
        assert_eq!(centres(&still), vec![(disc.0, disc.1)]);
    }

    #[test]
    fn a_ball_is_followed_to_where_it_moved_and_a_still_disc_stays() {
        let disc = (200.0, 200.0, 20.0, 40.0);
        let dir = two_frames([(100.0, 100.0, 45.0), (108.3, 111.6, 45.0)].map(|ball| Scene {
            ball,
            noise: 14.0,
            surface: Some((230.0, 0.0)),
            band: (90.0, 40.0),
            distractors: vec![disc],
            ..Scene::default()
        }));
        let clip = Clip::open(dir.path()).unwrap();
        let opts = ClipTracking::default();
        let mut frames = FrameCache::new(&clip, &opts, 1.0, Order::Forward);
        // From where the ball was, 14 px from where it is now.
        let ball = seen(100.0, 100.0, 45.0);
        let found = frames
            .follow(1, &ball.circle, follow_half_width(45.0))
            .unwrap()
            .unwrap();
        let c = found.circle;
        assert!((c.x - 108.3).hypot(c.y - 111.6) < 0.5, "{c:?}");
        assert!((c.r - 45.0).abs() < 0.5 && c.support > CANDIDATE_QUALITY, "{c:?}");
        assert!(found.contrast >= MIN_DISC_CONTRAST, "{}", found.contrast);
        let first = frames.follow(0, &ball.circle, 6.0).unwrap().unwrap();
        assert!(
            one_ball_moved(&first, &found, 256.0),
            "{:?} {}",
            first.circle,
            first.contrast
        );
        // A still disc is found where it was: no pair.
        let still = frames
            .follow(1, &seen(disc.0, disc.1, disc.2).circle, follow_half_width(disc.2))
            .unwrap()
            .unwrap();
        assert!(
            (still.circle.x - disc.0).hypot(still.circle.y - disc.1) < 1.0,
            "{:?}",
            still.circle
        );
        let before = frames
            .follow(0, &seen(disc.0, disc.1, disc.2).circle, 6.0)
            .unwrap()
            .unwrap();
        assert!(!one_ball_moved(&before, &still, 256.0));
    }

    /// Two frames of a ball `(x, y, r)` of gray `ball_level` on a flat backdrop of 100 in `noise` (σ, DN).
    fn on_plain_backdrop(balls: [(f64, f64, f64); 2], ball_level: f64, noise: f64) -> tempfile::TempDir {
        two_frames(balls.map(|ball| Scene {
            ball,
            ball_level,
            backdrop: (100.0, 100.0),
            noise,
            ..Scene::default()
        }))
    }

    /// In heavy noise the vote peaks of a frame refine into circles of noise as clear (by quality) as a ball;
    /// none of them is a sighting, while the ball is, and a circle of noise followed is not found again.
    #[test]
    fn circles_of_noise_are_no_sightings() {
        let ball = (70.0, 75.0, 40.0);
        let dir = on_plain_backdrop([ball, (ball.0 + 6.0, ball.1 + 8.0, ball.2)], 125.0, 14.0);
        let clip = Clip::open(dir.path()).unwrap();
        let opts = ClipTracking::default();
        let mut frames = FrameCache::new(&clip, &opts, 1.0, Order::Forward);
        let (mut noise_only, mut balls) = (0, 0);
        for k in 0..2 {
            for noise_sigma in [None, Some(14.0)] {
                let det = CircleDetection {
                    min_radius: 15.0,
                    max_radius: 50.0,
                    max_candidates: BALL_CANDIDATES,
                    noise_sigma,
                    ..CircleDetection::default()
                };
                for s in frames.candidates(k, &det, Votes::Frame, None).unwrap() {
                    let c = s.circle;
                    let off_ball = (c.x - ball.0).hypot(c.y - ball.1) - c.r > ball.2 + 14.0;
                    noise_only += usize::from(off_ball);
                    balls += usize::from((c.r - ball.2).abs() < 2.0 && (c.x - ball.0).hypot(c.y - ball.1) < 3.0);
                }
            }
        }
        assert_eq!(noise_only, 0, "circles clear of the ball taken as sightings");
        assert!(balls > 0, "the ball is no sighting");
        let noise = Circle {
            x: 190.0,
            y: 190.0,
            r: 30.0,
            support: 0.7,
        };
        assert!(frames.follow(1, &noise, follow_half_width(30.0)).unwrap().is_none());
    }

    /// A ball's rim stands out nearly all round; a circle drawn inside it, felt on both sides, stands out
    /// nowhere, and one sharing a piece of the ball's rim only there.
    #[test]
    fn a_ball_s_rim_stands_out_in_more_sectors_than_a_circle_inside_it() {
        let ball = (120.3, 118.6, 60.0);
        let dir = on_plain_backdrop([ball, ball], 140.0, 12.0);
        let clip = Clip::open(dir.path()).unwrap();
        let opts = ClipTracking::default();
        let mut frames = FrameCache::new(&clip, &opts, 1.0, Order::Forward);
        let circle = |x: f64, y: f64, r: f64| Circle { x, y, r, support: 0.7 };
        let rim = frames.rim_share(0, &circle(ball.0, ball.1, ball.2)).unwrap();
        let inside = frames.rim_share(0, &circle(ball.0 + 5.0, ball.1 + 10.0, 25.0)).unwrap();
        let touching = frames.rim_share(0, &circle(ball.0, ball.1 - 20.0, 40.0)).unwrap();
        assert!(rim >= 0.75, "{rim}");
        assert!(inside < 3.0 / 16.0, "{inside}");
        assert!(touching < 0.5 && touching < rim, "{touching}");
    }

    #[test]
    fn the_earliest_pair_nearly_as_clear_as_the_clearest_is_taken() {
        let clarity = |p: &(usize, f64)| p.1;
        // Search positions and clarities: 0.62 is further than CLEARER_BY from 0.70, 0.66 is not.
        let found = vec![(0, 0.62), (10, 0.66), (20, 0.70), (30, 0.69)];
        assert_eq!(earliest_of_the_clearest(found, clarity), Some((10, 0.66)));
        let alone = vec![(40, 0.3)];
        assert_eq!(earliest_of_the_clearest(alone, clarity), Some((40, 0.3)));
        assert_eq!(earliest_of_the_clearest(Vec::<(usize, f64)>::new(), clarity), None);
    }

    #[test]
    fn a_flat_or_unseen_look_correlates_with_nothing() {
        assert_eq!(look_correlation(&[1.0; 40], &[2.0; 40]), 0.0);
        assert_eq!(look_correlation(&[f32::NAN; 40], &[2.0; 40]), 0.0);
    }
}
