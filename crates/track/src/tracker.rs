//! Frame-to-frame tracking: predict, refine around the prediction, re-detect when that fails, and say
//! what happened in every frame.

use crate::ball_search::{BALL_CANDIDATES, MIN_BALL_RADIUS_PX, radius_window};
use crate::hough::{Circle, CircleDetection};
use crate::level::{ball_columns, remeasured};
use crate::limb::{LimbLearner, LimbOffset};
use crate::motion::fit_motion;
use crate::plane::{Pixel, Plane, median};
use crate::refine::{
    EdgeSearch, Refined, RimShapeLearner, refine_circle, refine_circle_with_rays, refined_candidates, residuals_about,
    rim_residuals,
};
use crate::rim_evidence::{RimEvidence, rim_evidence, strongest_rim};
use crate::surface::{SurfaceLine, find_faint_surface_lines, find_surface_lines};
use serde::{Deserialize, Serialize};

/// What the tracker could say about the ball in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Measured.
    Ok,
    /// Measured from less than half of its rim (the rest hidden).
    Occluded,
    /// Part of the ball is outside the frame; measured from the visible arc.
    CutByBorder,
    /// Not found.
    Absent,
    /// Not taken for the ball: more than one ball-like circle and nothing to tell which is the ball, or a
    /// circle off the path the frames around it give, further than the ball can stray.
    Ambiguous,
}

impl Status {
    /// Every status, in the order of the overlay's legend.
    pub const ALL: [Status; 5] = [
        Status::Ok,
        Status::Occluded,
        Status::CutByBorder,
        Status::Absent,
        Status::Ambiguous,
    ];

    /// Name as written in files and in the store (the same as its serde name).
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Occluded => "occluded",
            Status::CutByBorder => "cut_by_border",
            Status::Absent => "absent",
            Status::Ambiguous => "ambiguous",
        }
    }

    /// The status written as `name` ([`Status::name`]); an error naming the value for anything else, so a
    /// stored or edited trajectory with a status this build does not know is refused, not skipped.
    pub fn from_name(name: &str) -> Result<Status, UnknownStatus> {
        Status::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| UnknownStatus { name: name.to_string() })
    }

    /// True if the frame gives a centre and a radius (ok, occluded, cut by the border): counted as measured,
    /// drawn, used to place the local frame.
    pub fn measured(self) -> bool {
        matches!(self, Status::Ok | Status::Occluded | Status::CutByBorder)
    }

    /// True if the frame's centre is weighed in a fit of the trajectory (ok, occluded): the estimator's
    /// flight arcs and the model's fit both use exactly these frames, so the model is fitted to the frames
    /// its start state came from. A frame cut by the border is measured (drawn, counted) but fitted by
    /// neither.
    pub fn fitted(self) -> bool {
        matches!(self, Status::Ok | Status::Occluded)
    }
}

impl std::str::FromStr for Status {
    type Err = UnknownStatus;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Status::from_name(s)
    }
}

/// A status name that is none of [`Status::ALL`]'s.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown status `{name}` (known: ok, occluded, cut_by_border, absent, ambiguous)")]
pub struct UnknownStatus {
    /// The name found.
    pub name: String,
}

/// The ball in one frame (NaN coordinates when not measured): the pixel part of a [`crate::TrajectoryRow`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BallFix {
    /// Frame index (position in the clip, dropped frames counted).
    pub frame: usize,
    /// Time, s.
    pub t_s: f64,
    /// Centre x, px.
    pub x_px: f64,
    /// Centre y, px (down).
    pub y_px: f64,
    /// Radius, px.
    pub r_px: f64,
    /// Standard error of each centre coordinate, px.
    pub sigma_px: f64,
    /// Standard error of the radius, px. Not a trajectory column ([`crate::TRAJECTORY_COLUMNS`]): NaN in a
    /// row read back from a file or the store.
    pub sigma_r_px: f64,
    /// 0–1 quality score (fraction of the rim used × contrast factor).
    pub quality: f64,
    /// What happened.
    pub status: Status,
}

impl BallFix {
    /// A frame where the ball was not measured (NaN coordinates).
    pub(crate) fn absent(frame: usize, t_s: f64, status: Status) -> BallFix {
        BallFix {
            frame,
            t_s,
            x_px: f64::NAN,
            y_px: f64::NAN,
            r_px: f64::NAN,
            sigma_px: f64::NAN,
            sigma_r_px: f64::NAN,
            quality: 0.0,
            status,
        }
    }
}

/// A circle found near the surface as far from the prediction as a contact can have moved the ball (see
/// [`Tracker::contact_look`]).
struct ContactLook {
    circle: Refined,
    /// How far from the prediction it was looked for, px.
    reach: f64,
    /// Its edge points `(ray, [x, y])`.
    rays: Vec<(usize, [f64; 2])>,
}

/// Options of the [`Tracker`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrackOptions {
    /// Expected ball radius range, px (from the ball's diameter and an approximate scale), or `None` to
    /// find it (the ball is then the circle that moves).
    pub radius_px: Option<(f64, f64)>,
    /// Edge search around the prediction.
    pub search: EdgeSearch,
    /// Largest distance between prediction and measurement before the measurement is not trusted, px.
    pub max_jump_px: f64,
    /// The ball's diameter, m, when known: with the measured radius it turns
    /// `MAX_BALL_ACCELERATION_M_S2` (3·10⁴ m/s²) into px/s² for the prediction (unbounded without it).
    pub ball_diameter_m: Option<f64>,
}

impl Default for TrackOptions {
    fn default() -> Self {
        TrackOptions {
            radius_px: None,
            search: EdgeSearch::default(),
            max_jump_px: 4.0,
            ball_diameter_m: None,
        }
    }
}

/// Tracks one ball through a clip, frame by frame, in order.
#[derive(Debug, Clone)]
pub struct Tracker {
    opts: TrackOptions,
    /// Recent measured (t, x, y), at most [`PREDICTION_FIXES`].
    history: Vec<(f64, f64, f64)>,
    /// Qualities of the recent fixes measured `ok` with their whole rim in view, at most [`QUALITY_FIXES`].
    qualities: Vec<f64>,
    /// The history holds only the sightings the tracker was seeded with: no fix measured since.
    seed_only: bool,
    /// Distances between the recent predictions and their fixes, px, at most [`QUALITY_FIXES`].
    innovations: Vec<f64>,
    /// Radii measured in free flight (the bottom clear of the surface).
    flight_radii: Vec<f64>,
    /// The ball's radius as another pass measured it, px, until this one measures its own.
    radius_told: Option<f64>,
    /// Edge-definition spread (see [`Refined::edge_definition_px`]) in the first free-flight frames, px.
    flight_edges: Vec<f64>,
    /// The rim's shape, learned from full-rim free-flight frames until the first partly hidden one.
    rim: RimShapeLearner,
    /// The same from the full-rim free-flight frames that are not clean enough to teach it (heavy noise):
    /// the shape they give is not applied, only its RMS taken for the rim's errors when no clean frame
    /// taught one (see [`Tracker::rim_shape_rms_px`]).
    rim_doubtful: RimShapeLearner,
    /// The mean radial profile of the full-rim free-flight frames, before the bounce and after it, clean or
    /// not: where the limb's silhouette lies against the fitted circles (see [`Tracker::limb_offset`]).
    limb: LimbLearner,
    rim_frozen: bool,
    /// The edge points `(ray, [x, y])` of this frame's search around the prediction while the rim's shape
    /// is being learned (its residuals teach the shape without a second search); empty otherwise.
    rim_rays: Vec<(usize, [f64; 2])>,
    surface: Option<SurfaceLine>,
    /// The other candidate lines below the ball (see [`crate::SurfaceLines`]).
    surface_alternatives: Vec<SurfaceLine>,
    surface_tries: usize,
    /// The sum of the first frames' levels, for the surface line (see [`Tracker::look_for_surface`]).
    surface_stack: Vec<f32>,
    /// Frames summed in `surface_stack`.
    stacked: usize,
    /// Leftmost and rightmost expected centre of the ball over the frames summed, px.
    stack_span: Option<(f64, f64)>,
    /// No more frames are summed: the ball has swept across a quarter of the frame.
    stack_closed: bool,
    /// Frames summed at which the surface line is next looked for.
    next_surface_try: usize,
    warnings: Vec<String>,
    /// Distance between the last prediction and its measurement, px.
    last_innovation: f64,
    /// Consecutive frames where only circles far from the prediction were found.
    missed: usize,
    /// Time of the frame observed last, s (negated when tracking backward).
    last_observed_t_s: Option<f64>,
    /// Time between the last two frames observed, s.
    observed_period_s: Option<f64>,
    /// A circle without a rim ([`Tracker::rim_stands_out`]) has been refused and said so.
    told_no_rim: bool,
    /// The first frame where the circle found at the prediction had no rim (see [`Tracker::rim_lost_at`]).
    rim_lost_at: Option<usize>,
}

/// Frames averaged at most for the surface line (see [`Tracker::look_for_surface`]).
const SURFACE_STACK_MAX: usize = 32;
/// Searches for the surface line, at most: in 1, 8 and 32 frames, and twice more in 32 while none is found.
const SURFACE_TRIES: usize = 5;

/// Free-flight frames in which the edge definition is measured (its median enters the scale's error).
const EDGE_SAMPLES: usize = 64;

/// Full-rim free-flight frames the rim's shape is learned from (at most), and before it is used (at least).
const RIM_SAMPLES: usize = 64;
const RIM_MIN_SAMPLES: usize = 16;
/// Most full-rim free-flight frames whose profiles teach the limb ([`LimbOffset`]): a drop clip's whole
/// flight at 10,000 frames/s. Cost: 48 µs a frame learned.
const LIMB_SAMPLES: usize = 256;

/// Quality of a clean circle: about 85 % of the rays kept at full contrast (a ball's rim refines to near
/// 1; a seam or a texture ghost does not).
pub(crate) const CLEAN_QUALITY: f64 = 0.85;

/// Search half-width around a confident prediction, px.
const CONFIDENT_HALF_WIDTH: f64 = 2.0;

/// Half-width of the search that looks for the rim again when a narrow one finds it less clear than the
/// track's recent fixes, px (see [`Tracker::wider_look`]).
const WIDE_HALF_WIDTH: f64 = 8.0;

/// How far a whole rim's radius in free flight may lie from the track's flight radius, as a fraction of it
/// (plus half a pixel; see [`Tracker::of_flight_size`]): healthy tracks' flight radii wander by at most
/// 0.0053 r RMS about a line in time over seven sessions (`estimate::RIM_WANDER_MAX_RADII`).
const FLIGHT_RADIUS_TOLERANCE: f64 = 0.03;

/// Widest search around a prediction that may be in contact, px (see [`Tracker::contact_reach_px`]).
const MAX_CONTACT_HALF_WIDTH: f64 = 12.0;

/// Candidates within this fraction of the best support count as rivals.
const RIVAL_SUPPORT: f64 = 0.7;

/// Fixes the prediction is fitted to, at most (see [`crate::motion`]).
const PREDICTION_FIXES: usize = 8;

/// The largest acceleration a ball takes, m/s²: a 50 m/s ball reversing its normal speed in a 4 ms contact
/// peaks near 2·10⁴ m/s², half a sine's π/2 above its mean; in flight it is g. The prediction's acceleration
/// is held to this, so that a track cannot speed away from the ball on its own noise.
pub const MAX_BALL_ACCELERATION_M_S2: f64 = 3.0e4;

/// A fix this far from its prediction, px, and four times further than the recent fixes were from theirs,
/// marks a change of motion: the prediction starts again from the last fixes.
const CHANGE_OF_MOTION_PX: f64 = 1.0;

/// The largest downward (+y, towards the surface) acceleration the prediction takes, m/s²: gravity is the
/// only force towards the surface (contact pushes away from it), so 100 g leaves room for a frame rate
/// wrong by up to 10× (accelerations scale with its square) and still stops a search that slides down a
/// seam or the texture at thousands of g.
pub const MAX_DOWNWARD_ACCELERATION_M_S2: f64 = 100.0 * 9.81;

/// Recent clean fixes whose median quality a new fix is compared with.
const QUALITY_FIXES: usize = 16;

/// A fix whose visible rim's quality falls below this fraction of the track's recent median is not the
/// rim the track has been measuring (a seam, texture or another object near the prediction), and the frame
/// is not `ok`. A ball passing behind a thin ruler keeps most of its rim, and one sinking into the surface
/// or leaving the frame loses rays that are not counted against it; a pressed ball found at its prediction
/// is not held to it at all ([`pressed_at`]).
const QUALITY_DROP: f64 = 0.6;

impl Tracker {
    /// A tracker with no history.
    pub fn new(opts: TrackOptions) -> Tracker {
        Tracker {
            opts,
            history: Vec::new(),
            qualities: Vec::new(),
            seed_only: false,
            innovations: Vec::new(),
            flight_radii: Vec::new(),
            radius_told: None,
            flight_edges: Vec::new(),
            rim: RimShapeLearner::default(),
            rim_doubtful: RimShapeLearner::default(),
            limb: LimbLearner::default(),
            rim_frozen: false,
            rim_rays: Vec::new(),
            surface: None,
            surface_alternatives: Vec::new(),
            surface_tries: 0,
            surface_stack: Vec::new(),
            stacked: 0,
            stack_span: None,
            stack_closed: false,
            next_surface_try: 1,
            warnings: Vec::new(),
            last_innovation: 0.0,
            missed: 0,
            last_observed_t_s: None,
            observed_period_s: None,
            told_no_rim: false,
            rim_lost_at: None,
        }
    }

    /// Starts the track from two known positions of the ball (t in s, x and y in px), e.g. from the
    /// acquisition that told the ball from static circles by its motion.
    pub fn seed(&mut self, a: (f64, f64, f64), b: (f64, f64, f64)) {
        self.history = vec![a, b];
        self.seed_only = true;
    }

    /// A tracker with no history that reads the ball as this one now does: on its surface line, with the
    /// rim's shape it learned (and learning no more), and the flight radius and recent qualities it saw. A
    /// pass over frames this one already measured (backward in time) then reads each rim the same way, not
    /// with a rim it has had no free flight to learn.
    pub fn fresh_on_same_rim(&self) -> Tracker {
        Tracker {
            qualities: self.qualities.clone(),
            flight_radii: self.flight_radii.clone(),
            flight_edges: self.flight_edges.clone(),
            rim_frozen: true,
            surface: self.surface,
            surface_alternatives: self.surface_alternatives.clone(),
            surface_tries: SURFACE_TRIES,
            ..Tracker::new(self.opts.clone())
        }
    }

    /// The ball's radius in free flight so far, px: the median of the radii measured in free flight, else
    /// the radius another pass over the same ball measured ([`Tracker::expect_radius`]).
    pub fn known_radius(&self) -> Option<f64> {
        self.flight_radius().or(self.radius_told)
    }

    /// Tells this tracker the ball's radius in px, as another pass over the same ball measured it in free flight
    /// (the frames before the first sighting, tracked backward): until it has measured its own, each search
    /// starts from that radius and takes only circles of that size (see [`same_size`]), not any in the
    /// acquired range of ±15 %, where a rim joined to the ball's shadow can be as clear as the ball.
    pub fn expect_radius(&mut self, r_px: f64) {
        self.radius_told = Some(r_px);
    }

    /// Uses `line` as the surface instead of finding it.
    pub fn set_surface(&mut self, line: SurfaceLine) {
        self.surface = Some(line);
        // A line given (or taken from another pass) is not replaced by one found in the frames.
        self.surface_tries = SURFACE_TRIES;
        self.surface_stack = Vec::new();
    }

    /// No surface line, and none looked for in the frames (the one found was not the surface).
    pub fn forgo_surface(&mut self) {
        self.surface = None;
        self.surface_alternatives.clear();
        self.surface_tries = SURFACE_TRIES;
        self.surface_stack = Vec::new();
    }

    /// The surface line, once found.
    pub fn surface(&self) -> Option<&SurfaceLine> {
        self.surface.as_ref()
    }

    /// The other candidate lines below the ball, topmost first.
    pub fn surface_alternatives(&self) -> &[SurfaceLine] {
        &self.surface_alternatives
    }

    /// Things a person should know (a second ball, a lost track), each naming its frame.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// How much the rim's position depends on the edge definition in free flight: the median over the first
    /// flight frames of [`Refined::edge_definition_px`], px (0 before any).
    pub fn edge_definition_px(&self) -> f64 {
        if self.flight_edges.is_empty() {
            return 0.0;
        }
        let mut e = self.flight_edges.clone();
        let mid = e.len() / 2;
        *e.select_nth_unstable_by(mid, f64::total_cmp).1
    }

    /// How far the limb's silhouette lies from the circles fitted in free flight, measured on up to
    /// [`LIMB_SAMPLES`] full-rim free-flight frames (see [`LimbOffset`]); `None` before 8 of them.
    pub fn limb_offset(&self) -> Option<LimbOffset> {
        self.limb.offset()
    }

    /// How far the apparent rim strays from a circle, px: the RMS of the rim's shape learned from clean
    /// frames, else of the shape the doubtful full-rim flight frames give (at least `RIM_MIN_SAMPLES`, 16, of
    /// them), else 0 (no full-rim flight frame to tell).
    pub fn rim_shape_rms_px(&self) -> f64 {
        let doubtful = || {
            (self.rim_doubtful.frames() >= RIM_MIN_SAMPLES)
                .then(|| self.rim_doubtful.shape())
                .flatten()
                .map(|s| s.rms_px())
        };
        self.rim_shape().map(|s| s.rms_px()).or_else(doubtful).unwrap_or(0.0)
    }

    /// The rim's shape learned so far (see [`RimShape`](crate::RimShape)), if enough full-rim frames were seen.
    pub fn rim_shape(&self) -> Option<&crate::RimShape> {
        self.opts.search.rim_shape.as_ref()
    }

    /// The radius expected from free flight so far, px.
    pub fn flight_radius(&self) -> Option<f64> {
        if self.flight_radii.is_empty() {
            return None;
        }
        let mut r = self.flight_radii.clone();
        let mid = r.len() / 2;
        Some(*r.select_nth_unstable_by(mid, f64::total_cmp).1)
    }

    /// Where the ball should be at `t`: the least-squares parabola through the recent fixes, its
    /// acceleration bounded (see [`crate::motion`]).
    fn predict(&self, t: f64) -> Option<(f64, f64)> {
        let fixes = self.motion_fixes();
        fit_motion(fixes, self.max_accel_px_s2(fixes), self.max_down_px_s2()).map(|m| m.at(t))
    }

    /// The fixes the prediction is fitted to: the recent ones; at a frame rate low enough for a contact to
    /// move the ball beyond the narrow window within a frame ([`Self::contact_reach_px`]), once the ball
    /// has left the surface (two or more fixes clear of it after some that were not) only those since, in
    /// free flight. Through a contact the fixes curve with the surface's push, and a parabola through them
    /// carries that push on: at 2,000 frames/s a tape shot of the independent renderer was tracked 0.9–2.3
    /// px ahead of the ball for four frames after it left (the track following the prediction along the
    /// rim). At 10,000 frames/s eight fixes span 0.8 ms and the narrow window holds the rim.
    fn motion_fixes(&self) -> &[(f64, f64, f64)] {
        if !self.coarse_frames() {
            return &self.history;
        }
        let n = self.history.len();
        let run = self
            .history
            .iter()
            .rev()
            .take_while(|&&(_, x, y)| self.clear_of_surface(x, y))
            .count();
        if run >= 2 && run < n {
            &self.history[n - run..]
        } else {
            &self.history
        }
    }

    /// [`MAX_BALL_ACCELERATION_M_S2`] in px/s² at the expected radius, when the ball's size is known; while
    /// every one of `fixes` is clear of the surface line the ball is in flight, where only gravity (and drag)
    /// act, and [`MAX_DOWNWARD_ACCELERATION_M_S2`] bounds it in every direction.
    fn max_accel_px_s2(&self, fixes: &[(f64, f64, f64)]) -> Option<f64> {
        let limit = if self.all_clear(fixes) {
            MAX_DOWNWARD_ACCELERATION_M_S2
        } else {
            MAX_BALL_ACCELERATION_M_S2
        };
        Some(limit * self.px_per_m()?)
    }

    /// Whether every recent fix has the ball's whole disc clear of the surface line (by 2 px beyond the
    /// band's ragged reach); false while no line is known.
    fn in_flight(&self) -> bool {
        self.all_clear(&self.history)
    }

    /// Whether `fixes` are some and each has the ball's whole disc clear of the surface line
    /// ([`Self::clear_of_surface`]).
    fn all_clear(&self, fixes: &[(f64, f64, f64)]) -> bool {
        !fixes.is_empty() && fixes.iter().all(|&(_, x, y)| self.clear_of_surface(x, y))
    }

    /// Whether a fix at (x, y) px continues free flight: the fixes the prediction is fitted to and this one
    /// all clear of the surface ([`Self::in_flight`], [`Self::clear_of_surface`]).
    fn flying_at(&self, x: f64, y: f64) -> bool {
        self.in_flight() && self.clear_of_surface(x, y)
    }

    /// Whether a ball centred at (x, y) px has its whole disc clear of the surface line, by 2 px beyond the
    /// band's ragged reach; false while no line is known.
    fn clear_of_surface(&self, x: f64, y: f64) -> bool {
        let (Some(line), Some(r)) = (self.surface.as_ref(), self.expected_radius()) else {
            return false;
        };
        line.clears_disc(x, y, r)
    }

    /// How far a contact can move the ball from its prediction by `t_s`, px: half the largest acceleration
    /// a ball takes ([`MAX_BALL_ACCELERATION_M_S2`]) times the square of the time since the last fix. A
    /// prediction fitted to the fixes before cannot know the push that has begun since: at 10,000 frames/s
    /// this is 0.3 px for a 64 px tennis ball, within the narrow window; at 2,000 frames/s it is 7 px, and a
    /// window narrower than that holds no rim. 0 before the ball's size or a fix is known.
    fn contact_reach_px(&self, t_s: f64) -> f64 {
        let (Some(&(t_last, _, _)), Some(px_per_m)) = (self.history.last(), self.px_per_m()) else {
            return 0.0;
        };
        let dt = t_s - t_last;
        0.5 * MAX_BALL_ACCELERATION_M_S2 * px_per_m * dt * dt
    }

    /// Whether the frames are far enough apart for a contact to move the ball beyond the narrow window
    /// between two of them ([`Self::contact_reach_px`] over the shortest interval between the recent
    /// fixes, with a pixel for the rim's definition): below about 5,000 frames/s for a tennis ball 64 px in
    /// radius. At such rates the prediction through a contact is looked after ([`Self::contact_look`],
    /// [`Self::motion_fixes`], [`Self::of_flight_size`]); above them the narrow window holds the rim, and a
    /// frame missed in between is no reason to search wider (at 14 DN of noise, searching as far as the
    /// time since the last fix allowed left 268 frames absent where 161 were).
    fn coarse_frames(&self) -> bool {
        let interval = self
            .history
            .windows(2)
            .map(|w| (w[1].0 - w[0].0).abs())
            .filter(|dt| *dt > 0.0)
            .fold(f64::INFINITY, f64::min);
        let Some(&(t, _, _)) = self.history.last().filter(|_| interval.is_finite()) else {
            return false;
        };
        self.contact_reach_px(t + interval) + 1.0 > CONFIDENT_HALF_WIDTH
    }

    /// Whether a ball predicted at (px, py) px may be in contact at a frame rate where that matters to the
    /// search: its disc not clear of the surface line, frames as far apart as [`Self::coarse_frames`] says,
    /// and a track of three fixes or more.
    fn near_contact(&self, px: f64, py: f64) -> bool {
        self.history.len() >= 3 && self.coarse_frames() && !self.clear_of_surface(px, py)
    }

    /// A ball near contact ([`Self::near_contact`], predicted at (px, py) px, radius `r`), looked for as far
    /// as the contact can have moved it ([`Self::contact_reach_px`]) or as the window `search` the track
    /// widened after a miss, whichever is further. A window that wide only says where the rim is: the rim's
    /// side hidden by the surface, the limb's shading and the band's texture pull its circle in (radii
    /// 1–4 px short on a pressed ball at 2,000 frames/s), so the ball is measured again in the narrow window
    /// from there, as `at_prediction` was measured at the prediction. That circle, when its visible rim is
    /// clearer than `at_prediction`'s (a faint rim can hold the prediction's circle as well as a wide search
    /// can lose it); `None` otherwise, and when the narrow window already reaches as far. Cost: two
    /// refinements, in frames near contact at low frame rates only.
    fn contact_look<P: Pixel>(
        &self,
        img: &Plane<P>,
        t_s: f64,
        (px, py, r): (f64, f64, f64),
        search: &EdgeSearch,
        at_prediction: Option<&Refined>,
    ) -> Option<ContactLook> {
        let reach = (self.contact_reach_px(t_s) + 1.0)
            .max(search.half_width)
            .min(MAX_CONTACT_HALF_WIDTH);
        if reach <= CONFIDENT_HALF_WIDTH {
            return None;
        }
        let surface = self.surface.as_ref();
        let wide = EdgeSearch {
            half_width: reach,
            ..search.clone()
        };
        let seen = refine_circle(img, px, py, r, &wide, surface)?;
        let narrow = EdgeSearch {
            half_width: CONFIDENT_HALF_WIDTH,
            ..search.clone()
        };
        let mut own = Vec::new();
        let located = refine_circle_with_rays(img, seen.fit.x, seen.fit.y, r, &narrow, surface, Some(&mut own))?;
        let clearer = at_prediction.is_none_or(|f| located.visible_quality() > f.visible_quality());
        clearer.then_some(ContactLook {
            circle: located,
            reach,
            rays: own,
        })
    }

    /// [`MAX_DOWNWARD_ACCELERATION_M_S2`] in px/s², when the ball's size is known.
    fn max_down_px_s2(&self) -> Option<f64> {
        Some(MAX_DOWNWARD_ACCELERATION_M_S2 * self.px_per_m()?)
    }

    /// The image's scale from the expected radius and the ball's diameter, px/m.
    fn px_per_m(&self) -> Option<f64> {
        let d = self.opts.ball_diameter_m.filter(|d| *d > 0.0)?;
        Some(2.0 * self.expected_radius()? / d)
    }

    fn expected_radius(&self) -> Option<f64> {
        self.known_radius()
            .or_else(|| self.opts.radius_px.map(|(a, b)| 0.5 * (a + b)))
    }

    /// Measures the ball in one frame. Frames must come in time order.
    pub fn observe<P: Pixel>(&mut self, frame: usize, t_s: f64, img: &Plane<P>) -> BallFix {
        if let Some(dt) = self.last_observed_t_s.map(|t| (t_s - t).abs()).filter(|&dt| dt > 0.0) {
            self.observed_period_s = Some(dt);
        }
        self.last_observed_t_s = Some(t_s);
        self.look_for_surface(t_s, img);
        if let Some(fix) = self.around_prediction(frame, t_s, img) {
            return fix;
        }
        self.redetect(frame, t_s, img)
    }

    /// Looks for the surface line in the mean of the clip's first frames: the band does not move, so
    /// averaging `n` frames divides the sensor's noise by √n and leaves the band's edge and texture as they are
    /// (a grainy band at high noise is found in the mean of 8 frames where single frames miss it or tilt it by
    /// degrees). Frames stop being added once the ball's expected centre has moved across a quarter of the
    /// frame's width: a ball sweeping sideways leaves a straight edge in the mean, which must not reach the
    /// half of the columns a line needs. Searches while the ball is known: first in the frames summed by then
    /// (one, for a tracker seeded with the ball), then in 8 and in [`SURFACE_STACK_MAX`] frames (or when the
    /// frames stop being added); a line found in more frames replaces one found in fewer. In the full stack,
    /// while no line has been found, a faint texture line is looked for too ([`find_faint_surface_lines`]):
    /// never from fewer frames, whose noise it could line up. Where the ball is
    /// expected, a line above it is not the surface; until the ball is known (a tracker never seeded, before
    /// its first fix) no line is looked for, as the rims of round things side by side can pass for the top of
    /// a band. Cost: one add per pixel per summed frame, and a line search (≈ 3 ms for 512×512) per try,
    /// [`SURFACE_TRIES`] at most (two searches in a full stack that shows no clear line).
    fn look_for_surface<P: Pixel>(&mut self, t_s: f64, img: &Plane<P>) {
        if self.surface_tries >= SURFACE_TRIES {
            return;
        }
        let ball = self
            .predict(t_s)
            .zip(self.expected_radius())
            .map(|((x, y), r)| (x, y, r));
        let n = img.width * img.height;
        if self.surface_stack.len() != n {
            self.surface_stack = vec![0.0; n];
            self.stacked = 0;
            self.next_surface_try = 1;
            self.stack_span = None;
            self.stack_closed = false;
        }
        if let Some((x, _, _)) = ball {
            let (lo, hi) = self.stack_span.unwrap_or((x, x));
            let span = (lo.min(x), hi.max(x));
            self.stack_closed |= span.1 - span.0 > 0.25 * img.width as f64;
            self.stack_span = Some(span);
        }
        if self.stacked < SURFACE_STACK_MAX && !self.stack_closed {
            let gain = img.gain;
            for (v, p) in self.surface_stack.iter_mut().zip(img.data) {
                *v += p.level() * gain;
            }
            self.stacked += 1;
        }
        let full = self.stacked == SURFACE_STACK_MAX || self.stack_closed;
        let due = self.stacked >= self.next_surface_try
            || (full && self.next_surface_try != usize::MAX)
            || (full && self.surface.is_none());
        if !due || ball.is_none() || self.stacked == 0 {
            return;
        }
        self.surface_tries += 1;
        self.next_surface_try = match self.stacked {
            _ if full => usize::MAX,
            1 => 8,
            n => (4 * n).min(SURFACE_STACK_MAX),
        };
        let scale = 1.0 / self.stacked as f32;
        let mean: Vec<f32> = self.surface_stack.iter().map(|v| v * scale).collect();
        let plane = Plane::new(&mean, img.width, img.height);
        let span = ball.map(|(x, _, _)| self.stack_span.unwrap_or((x, x)));
        // A faint line only from the full stack, once no clear one has been found in it.
        let lines = find_surface_lines(&plane, ball).or_else(|| {
            ball.zip(span)
                .filter(|_| full && self.surface.is_none())
                .and_then(|(b, s)| find_faint_surface_lines(&plane, b, s))
        });
        if let Some(lines) = lines {
            let skip = |l: &SurfaceLine| ball.zip(span).and_then(|(b, s)| ball_columns(l, b, s));
            let level = |l: SurfaceLine| remeasured(&plane, l, skip(&l));
            let line = level(lines.line);
            let alternatives = lines.alternatives.into_iter().map(level).collect();
            self.surface = Some(line);
            self.surface_alternatives = alternatives;
        }
        if self.next_surface_try == usize::MAX && self.surface.is_some() {
            self.surface_tries = SURFACE_TRIES;
        }
        if self.surface_tries >= SURFACE_TRIES {
            self.surface_stack = Vec::new();
        }
    }

    /// The ball refined around its predicted position, when that gives a plausible circle of the same rim. A
    /// confident track needs one narrow pass; the window widens when the last prediction missed (a sudden
    /// change of motion), in free flight a rim less clear than the recent ones is looked for again in a
    /// wider one ([`Self::wider_look`]), and near the surface at low frame rates as far as a contact can
    /// have moved the ball ([`Self::contact_look`]).
    fn around_prediction<P: Pixel>(&mut self, frame: usize, t_s: f64, img: &Plane<P>) -> Option<BallFix> {
        let confident = self.history.len() >= 3 && self.last_innovation < 0.5;
        let prediction = self.predict(t_s);
        let half_width = if confident {
            CONFIDENT_HALF_WIDTH
        } else {
            self.opts
                .search
                .half_width
                .max((2.0 * self.last_innovation + 2.0).min(12.0))
        };
        // A settled track's window sits on the rim; until then (16 clean flight radii, and the last fix
        // within half a pixel of its prediction) a band's outer side is also looked for beyond it, so that
        // a track begun on a limb's inner side moves out to the rim.
        let settled = confident && self.flight_radii.len() >= RIM_MIN_SAMPLES;
        let search = EdgeSearch {
            half_width,
            edge_definition: self.flight_edges.len() < EDGE_SAMPLES,
            beyond_window: !settled && self.opts.search.beyond_window,
            ..self.opts.search.clone()
        };
        let mut max_jump = self.opts.max_jump_px.max(2.0 * self.last_innovation + 2.0);
        let learning = !self.rim_frozen && self.rim.frames() < RIM_SAMPLES;
        let mut rays = std::mem::take(&mut self.rim_rays);
        rays.clear();
        let mut found = match (prediction, self.expected_radius()) {
            (Some((px, py)), Some(r)) => {
                // Near the surface at low frame rates a widened window reaches edges inside the pressed ball:
                // the rim is measured in the narrow one, at the prediction and where a wider look finds it.
                let near = self.near_contact(px, py);
                let measured = EdgeSearch {
                    half_width: if near { CONFIDENT_HALF_WIDTH } else { half_width },
                    ..search.clone()
                };
                let at_prediction = refine_circle_with_rays(
                    img,
                    px,
                    py,
                    r,
                    &measured,
                    self.surface.as_ref(),
                    learning.then_some(&mut rays),
                );
                let look = near
                    .then(|| self.contact_look(img, t_s, (px, py, r), &search, at_prediction.as_ref()))
                    .flatten();
                match look {
                    Some(look) => {
                        max_jump = max_jump.max(look.reach);
                        if learning {
                            rays = look.rays;
                        }
                        Some((look.circle, px, py, r))
                    }
                    None => at_prediction.map(|f| (f, px, py, r)),
                }
            }
            _ => None,
        };
        if let Some((narrow, px, py, r)) = found
            && half_width < WIDE_HALF_WIDTH
            && self.flying_at(narrow.fit.x, narrow.fit.y)
            && self.below_recent_quality(&narrow)
            && let Some(better) = self.wider_look(img, &narrow, &search, learning.then_some(&mut rays))
        {
            found = Some((better, px, py, r));
            max_jump = max_jump.max(WIDE_HALF_WIDTH);
        }
        self.rim_rays = rays;
        if let Some((found, px, py, r)) = found
            && self.plausible(&found, px, py, r, max_jump)
            && (half_width <= CONFIDENT_HALF_WIDTH || !self.coarse_frames() || self.of_flight_size(&found))
            && (self.same_rim(&found) || pressed_at(&found, (px, py)))
            && self.continues_on_rim(frame, img, &found)
        {
            self.last_innovation = (found.fit.x - px).hypot(found.fit.y - py);
            self.note_innovation(self.last_innovation, (found.fit.x, found.fit.y));
            return Some(self.accept(frame, t_s, img, found, Status::Ok));
        }
        self.last_innovation = 0.0;
        self.rim_rays.clear();
        None
    }

    /// The ball detected in the whole frame: the first sighting when there is no track to continue, else the
    /// candidate nearest the track among those where the ball can be (`absent` when there is none).
    fn redetect<P: Pixel>(&mut self, frame: usize, t_s: f64, img: &Plane<P>) -> BallFix {
        let (lo, hi) = match (self.expected_radius(), self.opts.radius_px) {
            (Some(r), _) => radius_window(r),
            (None, Some(range)) => range,
            (None, None) => (MIN_BALL_RADIUS_PX, img.width.min(img.height) as f64 / 2.0),
        };
        let det = CircleDetection {
            min_radius: lo,
            max_radius: hi,
            max_candidates: BALL_CANDIDATES,
            ..CircleDetection::default()
        };
        let mut cands = refined_candidates(img, &det, &self.opts.search, self.surface.as_ref(), 0.3);
        let Some((px, py)) = self.predict_after_gap(t_s) else {
            return self.first_sighting(frame, t_s, img, cands);
        };
        // Only a circle of the ball's size where the ball can be continues the track: within half a radius
        // of the prediction, and further by the ground the ball covers per frame for every frame it has been
        // missed (a bounce or a turn unseen). Anything else is another object (or a circle inside the ball,
        // as a pressed ball's part-hidden rim gives), and the frame is absent, never `ok`.
        let r_expected = self.expected_radius().unwrap_or(0.5 * (lo + hi));
        let gate = 0.5 * r_expected + (2.0 * self.speed_px_per_s() * self.frame_period() + 1.0) * self.missed as f64;
        let d = |c: &(Circle, Refined)| (c.1.fit.x - px).hypot(c.1.fit.y - py);
        cands.retain(|c| d(c) <= gate && self.same_rim(&c.1) && self.ball_sized(&c.1));
        cands.retain(|c| self.rim_stands_out(frame, img, &c.1));
        if cands.is_empty()
            && self.opts.search.smooth
            && let Some(found) = self.strongest_rim_near(img, (px, py), r_expected, gate)
            && d(&found) <= gate
            && self.same_rim(&found.1)
            && self.ball_sized(&found.1)
            && self.rim_stands_out(frame, img, &found.1)
            && self.rim_mostly_stands_out(img, &found.1)
        {
            // A seed that put the ball beyond any window around its prediction was not on the ball (sightings
            // made on noise, off by about as much each): it is moved onto it, keeping its velocity, as a fit
            // through it and this fix would carry its offset on as a false velocity. A measured path stands:
            // the ball may have bounced away from it.
            let (dx, dy) = (found.1.fit.x - px, found.1.fit.y - py);
            if self.seed_only && dx.hypot(dy) > WIDE_HALF_WIDTH {
                for fix in &mut self.history {
                    fix.1 += dx;
                    fix.2 += dy;
                }
            }
            cands.push(found);
        }
        if cands.is_empty() {
            self.missed += 1;
            if self.missed == 3 {
                self.warnings
                    .push(format!("frame {frame}: ball lost; looking for it along its path"));
            }
            return BallFix::absent(frame, t_s, Status::Absent);
        }
        cands.sort_by(|a, b| b.1.quality().total_cmp(&a.1.quality()));
        let best_q = cands[0].1.quality();
        let rivals = cands.iter().filter(|c| c.1.quality() >= RIVAL_SUPPORT * best_q).count();
        // Continuity decides: the candidate nearest the track.
        let (i, _) = cands
            .iter()
            .enumerate()
            .min_by(|a, b| d(a.1).total_cmp(&d(b.1)))
            .expect("non-empty");
        let chosen = cands.swap_remove(i);
        if self.missed == 0 {
            self.note_innovation(d(&chosen), (chosen.1.fit.x, chosen.1.fit.y));
        }
        if rivals > 1 {
            self.warnings.push(format!(
                "frame {frame}: {rivals} ball-like circles near the track; tracking the one at ({:.1}, {:.1}) because it continues it",
                chosen.1.fit.x, chosen.1.fit.y
            ));
        }
        self.accept(frame, t_s, img, chosen.1, Status::Ok)
    }

    /// The circle refined from the strongest rim of radius `r` centred within `reach` px (at most `r`) of
    /// `(x, y)` ([`strongest_rim`]): where the frame's circle votes hold no ball near the track, in frames
    /// noisy enough for the rays to be smoothed ([`EdgeSearch::smooth`]). There a rim's gradients are
    /// outvoted by noise and by the seam's arcs, and a refinement started more than its window's half-width
    /// off the rim stays on noise; a rim pooled over all its rays still stands out. In clean frames the votes
    /// find the ball, and a shaded disc's inner circles stand out of the little noise as a rim would.
    fn strongest_rim_near<P: Pixel>(
        &self,
        img: &Plane<P>,
        (x, y): (f64, f64),
        r: f64,
        reach: f64,
    ) -> Option<(Circle, Refined)> {
        let search = &self.opts.search;
        let surface = self.surface.as_ref();
        let (cx, cy, cr, strength) = strongest_rim(
            img,
            (x, y),
            r,
            reach.min(r),
            search.rays,
            surface,
            search.surface_margin,
        )?;
        let refined = refine_circle(img, cx, cy, cr, search, surface)?;
        let circle = Circle {
            x: cx,
            y: cy,
            r: cr,
            support: strength,
        };
        Some((circle, refined))
    }

    /// Whether a third of `f`'s rim sectors at least stand out of the noise: the best of the many circles a
    /// rim search weighs can cross another object's rim in a few sectors, the ball's rim stands out in most.
    fn rim_mostly_stands_out<P: Pixel>(&self, img: &Plane<P>, f: &Refined) -> bool {
        let e = self.rim_evidence_of(img, f);
        e.too_small || 3 * e.standing_out >= e.sectors
    }

    /// [`rim_evidence`] for `f`'s circle with the track's rays and surface line.
    fn rim_evidence_of<P: Pixel>(&self, img: &Plane<P>, f: &Refined) -> RimEvidence {
        let search = &self.opts.search;
        rim_evidence(
            img,
            (f.fit.x, f.fit.y, f.fit.r),
            search.rays,
            self.surface.as_ref(),
            search.surface_margin,
        )
    }

    /// Without any history (a tracker never seeded): the clearest circle, `ambiguous` when others are nearly
    /// as clear.
    fn first_sighting<P: Pixel>(
        &mut self,
        frame: usize,
        t_s: f64,
        img: &Plane<P>,
        mut cands: Vec<(Circle, Refined)>,
    ) -> BallFix {
        cands.retain(|c| self.rim_stands_out(frame, img, &c.1));
        if cands.is_empty() {
            return BallFix::absent(frame, t_s, Status::Absent);
        }
        cands.sort_by(|a, b| b.1.quality().total_cmp(&a.1.quality()));
        let best_q = cands[0].1.quality();
        let rivals = cands.iter().filter(|c| c.1.quality() >= RIVAL_SUPPORT * best_q).count();
        let chosen = cands.swap_remove(0);
        if rivals > 1 {
            self.warnings.push(format!(
                "frame {frame}: {rivals} ball-like circles and no track yet to tell which is the ball; taking the clearest at ({:.1}, {:.1})",
                chosen.1.fit.x, chosen.1.fit.y
            ));
            let fix = self.accept(frame, t_s, img, chosen.1, Status::Ambiguous);
            return BallFix {
                status: Status::Ambiguous,
                ..fix
            };
        }
        self.accept(frame, t_s, img, chosen.1, Status::Ok)
    }

    /// Where the ball should be at `t` after missed frames: the straight line fitted to the recent fixes
    /// once frames have been missed (a parabola extrapolated far runs away).
    fn predict_after_gap(&self, t: f64) -> Option<(f64, f64)> {
        if self.missed < 2 || self.history.len() < 2 {
            return self.predict(t);
        }
        fit_motion(&self.history, Some(0.0), None).map(|m| m.at(t))
    }

    /// The ball's speed at its last fix, from the motion fitted to the recent fixes, px/s (0 before two).
    fn speed_px_per_s(&self) -> f64 {
        if self.history.len() < 2 {
            return 0.0;
        }
        fit_motion(
            &self.history,
            self.max_accel_px_s2(&self.history),
            self.max_down_px_s2(),
        )
        .map_or(0.0, |m| m.speed())
    }

    /// The time between the last two frames observed, s (0 before two: no frame has been missed yet). Not
    /// the fixes' spacing: a seed's two sightings lie ten frames apart, and a lost ball's search widens per
    /// frame missed.
    fn frame_period(&self) -> f64 {
        self.observed_period_s.unwrap_or(0.0)
    }

    /// Keeps `innovation` (px, the distance of a fix from its prediction) among the recent ones; when it is
    /// far beyond them ([`CHANGE_OF_MOTION_PX`]) the motion changed (a bounce seen in few frames): the fixes
    /// before it no longer describe the path, and a fit through them would lag behind it.
    ///
    /// In free flight (the fixes and this one at (x, y) clear of the surface) nothing changes the motion, and
    /// a large innovation is the fix's own error: the fixes are kept, as a fit through the last two alone
    /// would carry that error on.
    fn note_innovation(&mut self, innovation: f64, (x, y): (f64, f64)) {
        if !self.flying_at(x, y) && innovation > CHANGE_OF_MOTION_PX.max(4.0 * median(&mut self.innovations.clone())) {
            let stale = self.history.len().saturating_sub(2);
            self.history.drain(..stale);
        }
        self.innovations.push(innovation);
        if self.innovations.len() > QUALITY_FIXES {
            self.innovations.remove(0);
        }
    }

    /// Whether `f`'s visible rim is not clean ([`CLEAN_QUALITY`]) and less clear than the track's recent
    /// fixes by more than their own spread (below their median by 1.4826 median absolute deviations, a
    /// standard deviation were they normal; with five known): a clean rim, or one that has merely drawn worse
    /// noise, is not looked for again.
    fn below_recent_quality(&self, f: &Refined) -> bool {
        if self.qualities.len() < 5 || f.visible_quality() >= CLEAN_QUALITY {
            return false;
        }
        let mut q = self.qualities.clone();
        let mid = median(&mut q);
        let mut dev: Vec<f64> = q.iter().map(|v| (v - mid).abs()).collect();
        f.visible_quality() < mid - 1.4826 * median(&mut dev)
    }

    /// A narrow window that drifted off the rim in free flight (onto a seam or texture inside it, while the
    /// prediction follows the drift) cannot see the rim again: a search [`WIDE_HALF_WIDTH`] wide around `narrow`
    /// finds it, and a narrow one from there measures it as every other frame is measured. That circle,
    /// when its visible rim is the clearer and it lies more than half the narrow window from `narrow` (its
    /// edge points left in `rays`); `None` otherwise (`rays` then hold `narrow`'s, untouched). Nearer, it
    /// is the rim the narrow window already holds, and taking the other fit would only trade one reading of
    /// a dim side for another from frame to frame. Cost: one refinement with a window four times as wide, and
    /// a narrow one when that lands more than a quarter of the narrow window (0.5 px) from `narrow`.
    fn wider_look<P: Pixel>(
        &self,
        img: &Plane<P>,
        narrow: &Refined,
        search: &EdgeSearch,
        rays: Option<&mut Vec<(usize, [f64; 2])>>,
    ) -> Option<Refined> {
        let surface = self.surface.as_ref();
        let r = narrow.fit.r;
        let wide = EdgeSearch {
            half_width: WIDE_HALF_WIDTH,
            ..search.clone()
        };
        let seen = refine_circle(img, narrow.fit.x, narrow.fit.y, r, &wide, surface)?;
        // The wide window held the same rim (the common case): the narrow fit stands.
        if (seen.fit.x - narrow.fit.x).hypot(seen.fit.y - narrow.fit.y) <= 0.25 * CONFIDENT_HALF_WIDTH {
            return None;
        }
        let mut own = Vec::new();
        let again = refine_circle_with_rays(img, seen.fit.x, seen.fit.y, r, search, surface, Some(&mut own))?;
        let moved = (again.fit.x - narrow.fit.x).hypot(again.fit.y - narrow.fit.y);
        if moved <= 0.5 * CONFIDENT_HALF_WIDTH || again.visible_quality() <= narrow.visible_quality() {
            return None;
        }
        if let Some(rays) = rays {
            *rays = own;
        }
        Some(again)
    }

    /// Whether `f` is as clear a rim as the track's recent fixes (see [`QUALITY_DROP`]); true until five
    /// have been seen.
    fn same_rim(&self, f: &Refined) -> bool {
        if self.qualities.len() < 5 {
            return true;
        }
        f.visible_quality() >= QUALITY_DROP * median(&mut self.qualities.clone())
    }

    /// [`Tracker::rim_stands_out`] for the circle found at the prediction; the first frame where a track
    /// that had measured the ball finds none is kept ([`Tracker::rim_lost_at`]).
    fn continues_on_rim<P: Pixel>(&mut self, frame: usize, img: &Plane<P>, f: &Refined) -> bool {
        let on_rim = self.rim_stands_out(frame, img, f);
        if !on_rim && self.rim_lost_at.is_none() && self.history.len() > 2 {
            self.rim_lost_at = Some(frame);
        }
        on_rim
    }

    /// The first frame where the circle the track found at its prediction had no rim standing out of the
    /// noise, after the track had measured the ball: the track had lost the ball's rim there, and may have
    /// drifted off it over the frames before (it follows the rim as that fades).
    pub fn rim_lost_at(&self) -> Option<usize> {
        self.rim_lost_at
    }

    /// Whether `f`'s rim stands out of the frame's noise ([`rim_evidence`]): a refinement in noise returns
    /// the circle it started from with a fair quality, and a track that lost the ball would follow it. The
    /// first refusal is told in the track's warnings.
    fn rim_stands_out<P: Pixel>(&mut self, frame: usize, img: &Plane<P>, f: &Refined) -> bool {
        let e = self.rim_evidence_of(img, f);
        if !e.stands_out() && !self.told_no_rim {
            self.told_no_rim = true;
            self.warnings.push(format!(
                "frame {frame}: the circle at ({:.1}, {:.1}) has no rim standing out of the noise ({} of {} sectors): not taken for the ball",
                f.fit.x, f.fit.y, e.standing_out, e.sectors
            ));
        }
        e.stands_out()
    }

    fn plausible(&self, f: &Refined, px: f64, py: f64, r: f64, max_jump: f64) -> bool {
        let jump = (f.fit.x - px).hypot(f.fit.y - py);
        jump <= max_jump && same_size(f.fit.r, r) && f.fit.inliers * 3 >= f.rays && f.quality() > 0.2
    }

    /// Whether `f`, when its whole rim is seen (none hidden by the surface or cut by the border), has the
    /// radius the track measured in free flight ([`FLIGHT_RADIUS_TOLERANCE`]); true otherwise, and before
    /// [`RIM_MIN_SAMPLES`] flight radii are known. [`same_size`] leaves room for a hidden rim's error; a
    /// whole rim has none, and a circle well inside it is an edge within the ball. Asked, at the frame rates
    /// of [`Self::coarse_frames`], of circles found in a window widened beyond the narrow one, which reaches
    /// such edges: at 2,000 frames/s, after a bounce, a dark limb's shading 3.7 px inside a 77.7 px ball,
    /// clearer than the silhouette. Asked of every circle at every frame rate, it refused rims the track
    /// needed at 14 DN of noise (the independent renderer's clay COR error 0.0017 → 0.0043 RMS).
    fn of_flight_size(&self, f: &Refined) -> bool {
        if self.flight_radii.len() < RIM_MIN_SAMPLES || f.rays_hidden > 0 || f.rays_outside > 0 {
            return true;
        }
        let Some(known) = self.flight_radius() else {
            return true;
        };
        (f.fit.r - known).abs() <= FLIGHT_RADIUS_TOLERANCE * known + 0.5
    }

    /// Whether `f` is the size of the ball: of its known radius ([`Tracker::known_radius`], see [`same_size`]), else
    /// within the radius range it was acquired with ([`TrackOptions::radius_px`]); true with neither.
    fn ball_sized(&self, f: &Refined) -> bool {
        match (self.known_radius(), self.opts.radius_px) {
            (Some(r), _) => same_size(f.fit.r, r),
            (None, Some((lo, hi))) => (lo..=hi).contains(&f.fit.r),
            (None, None) => true,
        }
    }

    fn accept<P: Pixel>(&mut self, frame: usize, t_s: f64, img: &Plane<P>, f: Refined, mut status: Status) -> BallFix {
        self.missed = 0;
        self.seed_only = false;
        let fit = f.fit;
        let (w, h) = (img.width as f64, img.height as f64);
        if fit.x - fit.r < -0.5 || fit.y - fit.r < -0.5 || fit.x + fit.r > w - 0.5 || fit.y + fit.r > h - 0.5 {
            status = Status::CutByBorder;
        } else if status == Status::Ok && fit.inliers * 2 < f.rays {
            status = Status::Occluded;
        }
        // The radius in free flight sets the scale: only frames with the whole rim clear of the surface.
        let clear = match &self.surface {
            Some(line) => fit.y + fit.r < line.top_at(fit.x) - 3.0,
            None => true,
        };
        if status == Status::Ok && f.rays_hidden == 0 && f.rays_outside == 0 {
            self.qualities.push(f.visible_quality());
            if self.qualities.len() > QUALITY_FIXES {
                self.qualities.remove(0);
            }
        }
        // Every full-rim flight frame, before the bounce and after it, teaches the limb: the felt's texture,
        // a seam turning with the ball and the backdrop behind the rim average out of its mean profile.
        if status == Status::Ok
            && clear
            && f.rays_hidden == 0
            && f.rays_outside == 0
            && self.limb.frames() < LIMB_SAMPLES
        {
            let rays = self.opts.search.rays.max(8);
            self.limb.add(img, (fit.x, fit.y, fit.r), rays, self.surface.as_ref());
        }
        if status == Status::Ok && clear && f.rays_hidden == 0 {
            self.flight_radii.push(fit.r);
            if self.flight_radii.len() > 64 {
                self.flight_radii.remove(0);
            }
            if f.edge_definition_px.is_finite() && self.flight_edges.len() < EDGE_SAMPLES {
                self.flight_edges.push(f.edge_definition_px);
            }
            // Only clean circles teach the rim's shape (a seam circle fits its edges less well); the others
            // only tell how large it is.
            let clean = f.quality() >= CLEAN_QUALITY;
            if !self.rim_frozen
                && f.rays_outside == 0
                && self.rim.frames() < RIM_SAMPLES
                && (clean || self.rim_doubtful.frames() < RIM_SAMPLES)
            {
                // The frame's own edge points when it was measured around the prediction; a frame found by
                // detection is searched once more.
                let res = if self.rim_rays.is_empty() {
                    rim_residuals(img, &fit, &self.opts.search, self.surface.as_ref())
                } else {
                    residuals_about(&fit, &self.rim_rays)
                };
                let rays = self.opts.search.rays.max(8);
                if clean {
                    self.rim.add(rays, &res);
                    if self.rim.frames() >= RIM_MIN_SAMPLES {
                        self.opts.search.rim_shape = self.rim.shape();
                    }
                } else {
                    self.rim_doubtful.add(rays, &res);
                }
            }
        } else if f.rays_hidden > 0 && self.rim.frames() >= RIM_MIN_SAMPLES {
            // From the first partly hidden frame on, every frame is measured on the same rim.
            self.rim_frozen = true;
        }
        // Seeds from later frames give way to real measurements.
        self.history.retain(|h| h.0 < t_s);
        self.history.push((t_s, fit.x, fit.y));
        if self.history.len() > PREDICTION_FIXES {
            self.history.remove(0);
        }
        BallFix {
            frame,
            t_s,
            x_px: fit.x,
            y_px: fit.y,
            r_px: fit.r,
            sigma_px: 0.5 * (fit.sigma_x + fit.sigma_y),
            sigma_r_px: fit.sigma_r,
            quality: f.quality(),
            status,
        }
    }
}

/// Whether `f` is the ball pressed into the surface where the track predicts it, at `prediction` (px): part
/// of its rim hidden by the surface line and its centre within the narrow window of the prediction. Its
/// visible rim is then less clear than in flight (its lowest rays run along the band, the press and the
/// band's shade darken it) and is not held to the flight's clarity ([`Tracker::same_rim`]); it must still
/// stand out of the noise ([`Tracker::continues_on_rim`]). On a copy of `looks --seed 17` with 4 DN more
/// noise, gamma 0.8 and vignetting, S014's pressed rim (a 99 px ball) read 0.18–0.57 against its flight's
/// 0.76; refused, the frame was searched whole and a lit cap's edge 4.4 px inside the ball was taken for
/// it (`tests/shading.rs`: the noise alone does it).
fn pressed_at(f: &Refined, (px, py): (f64, f64)) -> bool {
    f.rays_hidden > 0 && (f.fit.x - px).hypot(f.fit.y - py) <= CONFIDENT_HALF_WIDTH
}

/// Whether a circle of radius `r` px can be the ball measured at `expected` px: within 6 % and a pixel, room
/// for a partly hidden rim's radius error while a circle inside the ball (a seam, a limb's shading) is not.
fn same_size(r: f64, expected: f64) -> bool {
    (r - expected).abs() <= 0.06 * expected + 1.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::LineCue;
    use crate::testutil::{Scene, band_edge_mean, render};
    use bouncelab_testkit::Rng;
    use std::f64::consts::FRAC_PI_2;

    /// A grainy band as gray as the backdrop, under sensor noise drawn afresh for each frame, with the ball
    /// falling above it (frame k at t = k·0.1 ms).
    fn noisy_frame(k: usize, noise: f64) -> Vec<u8> {
        let t = k as f64;
        let clean = render(&Scene {
            ball: (120.3 + 0.3 * t, 70.2 + 0.8 * t, 30.0),
            surface: Some((180.4, -1.5f64.to_radians().tan())),
            backdrop: (95.0, 95.0),
            band: (95.0, 12.0),
            roughness: 2.0,
            noise: 0.0,
            ..Scene::default()
        });
        let mut rng = Rng::new(1000 + k as u64);
        clean
            .iter()
            .map(|&v| (v as f64 + noise * rng.normal()).round().clamp(0.0, 255.0) as u8)
            .collect()
    }

    /// A ball whose rim is not clean in any frame teaches no rim shape to correct with, yet the shape's size
    /// is still measured for the errors.
    #[test]
    fn doubtful_frames_tell_the_rim_shape_s_size() {
        // The same scene at full and at a fifth of its contrast (noise scaled alike): the dim one's rim is
        // below the contrast of a clean circle in every frame.
        let track = |dim: f64| {
            let mut tracker = Tracker::new(TrackOptions {
                radius_px: Some((35.0, 45.0)),
                ..TrackOptions::default()
            });
            let mut qualities = Vec::new();
            for k in 0..48 {
                let t = k as f64;
                let img = render(&Scene {
                    ball: (110.3 + 0.3 * t, 80.2 + 0.8 * t, 40.0),
                    ball_level: 200.0 * dim,
                    backdrop: (70.0 * dim, 110.0 * dim),
                    marks: vec![(34.0, 24.0, 16.0, 95.0 * dim)],
                    noise: 2.0 * dim,
                    seed: k as u64,
                    ..Scene::default()
                });
                let f = tracker.observe(k, t * 1e-4, &Plane::new(&img, 256, 256));
                qualities.push(f.quality);
            }
            (tracker.rim_shape().is_some(), tracker.rim_shape_rms_px(), qualities)
        };
        let (clean_learned, clean_rms, _) = track(1.0);
        let (dim_learned, dim_rms, q) = track(0.2);
        assert!(clean_learned && clean_rms > 0.0);
        assert!(!dim_learned, "a clean frame at a fifth of the contrast: {q:?}");
        // Its rays of least contrast, which carry most of the shape, drop out more often in the dim frames
        // (0.016 px against 0.071 px here): a lower bound on the shape, not its measure.
        assert!(
            dim_rms > 0.1 * clean_rms && dim_rms < 1.5 * clean_rms,
            "rim shape RMS {dim_rms:.3} px at a fifth of the contrast against {clean_rms:.3} px at full contrast"
        );
    }

    /// A band a single noisy frame does not show is found in the mean of the first frames, where its
    /// height and tilt are right within their stated errors.
    #[test]
    fn the_surface_line_is_found_in_the_mean_of_the_first_frames() {
        let one = noisy_frame(0, 10.0);
        assert!(find_surface_lines(&Plane::new(&one, 256, 256), Some((120.3, 70.2, 30.0))).is_none());
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((25.0, 35.0)),
            ..TrackOptions::default()
        });
        for k in 0..40 {
            let img = noisy_frame(k, 10.0);
            tracker.observe(k, k as f64 * 1e-4, &Plane::new(&img, 256, 256));
        }
        let line = tracker.surface().expect("a line in the mean of the frames");
        assert!((line.y0 - 180.4).abs() < 0.5, "{line:?}");
        assert!((line.tilt_deg() - 1.5).abs() < 3.0 * line.sigma_tilt_deg, "{line:?}");
        assert_eq!(line.cue, LineCue::Texture);
    }

    /// A ball falling over a band (`band` mean and texture, 0–255) whose top runs at y = 180.4 px with
    /// `slope`, `roughness` px ragged, under `noise`.
    fn ball_over_band(band: (f64, f64), slope: f64, roughness: f64, noise: f64) -> impl Fn(usize) -> Scene {
        move |k| Scene {
            ball: (120.3 + 0.3 * k as f64, 70.2 + 0.8 * k as f64, 30.0),
            surface: Some((180.4, slope)),
            backdrop: (95.0, 95.0),
            band,
            roughness,
            noise,
            seed: k as u64,
            ..Scene::default()
        }
    }

    /// A tracker seeded with the ball's size after `frames` frames of `scene`, and those frames' mean.
    fn tracked_with_mean(scene: &impl Fn(usize) -> Scene, frames: usize) -> (Tracker, Vec<f32>) {
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((25.0, 35.0)),
            ..TrackOptions::default()
        });
        let mut sum = vec![0.0f32; 256 * 256];
        for k in 0..frames {
            let img = render(&scene(k));
            sum.iter_mut().zip(&img).for_each(|(s, v)| *s += *v as f32);
            tracker.observe(k, k as f64 * 1e-4, &Plane::new(&img, 256, 256));
        }
        let mean = sum.iter().map(|s| s * (1.0 / frames as f32)).collect();
        (tracker, mean)
    }

    /// A band whose grains out-texture the backdrop too weakly for a clear line even in the mean of all the
    /// stacked frames is taken as a faint texture line, from the full stack only.
    #[test]
    fn a_faint_band_is_taken_from_the_full_stack_only() {
        let scene = ball_over_band((95.0, 14.0), 0.01, 2.0, 4.0);
        let (early, _) = tracked_with_mean(&scene, SURFACE_STACK_MAX - 1);
        assert!(early.surface().is_none(), "a faint line before the stack is full");
        let (tracker, mean) = tracked_with_mean(&scene, SURFACE_STACK_MAX);
        assert!(
            find_surface_lines(&Plane::new(&mean, 256, 256), None).is_none(),
            "a clear line in the mean"
        );
        let line = tracker.surface().expect("a faint line from the full stack");
        assert_eq!(line.cue, LineCue::Texture);
        assert!((line.y0 - 180.4).abs() < 1.5, "{line:?}");
    }

    /// The line the tracker keeps is the one found in the mean of the first frames with its level measured
    /// again from the band's mean gray, and it lies at the ragged edge's mean.
    #[test]
    fn the_tracker_s_line_has_its_level_measured_again() {
        let scene = ball_over_band((65.0, 12.0), 0.0, 5.0, 3.0);
        let truth = band_edge_mean(&scene(0));
        let (tracker, mean) = tracked_with_mean(&scene, SURFACE_STACK_MAX);
        let mean = Plane::new(&mean, 256, 256);
        let found = find_surface_lines(&mean, None).expect("a line").line;
        let shift = crate::level::mean_gray_level(&mean, &found, None).expect("a clear step");
        let line = tracker.surface().expect("a line");
        assert!(
            (line.y0 - (found.y0 + shift.offset_px)).abs() < 1e-3,
            "{line:?} against {found:?} {shift:?}"
        );
        assert!(
            shift.offset_px.abs() > 0.01 && line.sigma_y0 == shift.sigma_px,
            "{shift:?}"
        );
        assert!(
            (line.y0 - truth).abs() < 0.3,
            "{line:?} against the edge's mean {truth:.2}"
        );
    }

    /// Seeds `tracker` with the ball at (`at`) frames 0 and 1 (0.1 ms apart) and tracks it through the first
    /// `frames` of `frame` (256×256), each fix within `tolerance` px of the ball.
    fn follow(
        tracker: &mut Tracker,
        at: impl Fn(usize) -> (f64, f64),
        frame: impl Fn(usize) -> Vec<u8>,
        frames: usize,
        tolerance: f64,
    ) {
        let (a, b) = (at(0), at(1));
        tracker.seed((0.0, a.0, a.1), (1e-4, b.0, b.1));
        for k in 0..frames {
            let px = frame(k);
            let fix = tracker.observe(k, k as f64 * 1e-4, &Plane::new(&px, 256, 256));
            let (x, y) = at(k);
            assert!((fix.x_px - x).hypot(fix.y_px - y) < tolerance, "frame {k}: {fix:?}");
        }
    }

    /// A ball sweeping across the first frames leaves no edge in their mean (no band in this scene: no line
    /// is found), since frames stop being summed once it has crossed a quarter of the frame.
    #[test]
    fn a_ball_sweeping_across_the_first_frames_is_not_taken_for_a_band() {
        let at = |k: usize| (30.3 + 6.0 * k as f64, 100.4 + 0.05 * k as f64);
        let frame = |k: usize| {
            let (x, y) = at(k);
            render(&Scene {
                ball: (x, y, 30.0),
                backdrop: (90.0, 90.0),
                seed: k as u64,
                ..Scene::default()
            })
        };
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((27.0, 33.0)),
            max_jump_px: 20.0,
            ..TrackOptions::default()
        });
        follow(&mut tracker, at, frame, 34, 0.5);
        assert!(tracker.surface().is_none(), "{:?}", tracker.surface());
    }

    /// A line set on the tracker (the user's, or the forward pass's for the backward one) stays, however
    /// clearly the frames show another.
    #[test]
    fn a_line_set_on_the_tracker_is_not_replaced_by_one_found() {
        let given = SurfaceLine::given(127.5, 200.0, 0.0);
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((25.0, 35.0)),
            ..TrackOptions::default()
        });
        tracker.set_surface(given);
        for k in 0..40 {
            let img = noisy_frame(k, 2.0);
            tracker.observe(k, k as f64 * 1e-4, &Plane::new(&img, 256, 256));
        }
        assert_eq!(tracker.surface(), Some(&given));
    }

    /// In flight (every recent fix clear of the surface line) the prediction's acceleration is held to what
    /// gravity and drag can give; near the surface, to what a contact can.
    #[test]
    fn the_prediction_s_acceleration_is_held_to_flight_s_away_from_the_surface() {
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((30.0, 30.0)),
            ball_diameter_m: Some(0.06),
            ..TrackOptions::default()
        });
        let px_per_m = 1000.0;
        tracker.set_surface(SurfaceLine::given(128.0, 200.0, 0.0));
        tracker.seed((0.0, 100.0, 100.0), (1e-4, 100.5, 101.0));
        let flight = tracker.max_accel_px_s2(&tracker.history).unwrap();
        assert!((flight - MAX_DOWNWARD_ACCELERATION_M_S2 * px_per_m).abs() < 1e-6 * flight);
        // The ball's bottom 2 px above the line: it may be touching.
        tracker.seed((0.0, 100.0, 166.0), (1e-4, 100.5, 168.0));
        let contact = tracker.max_accel_px_s2(&tracker.history).unwrap();
        assert!((contact - MAX_BALL_ACCELERATION_M_S2 * px_per_m).abs() < 1e-6 * contact);
    }

    fn falling_tracker() -> Tracker {
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((30.0, 30.0)),
            ..TrackOptions::default()
        });
        tracker.set_surface(SurfaceLine::given(128.0, 400.0, 0.0));
        tracker
    }

    /// A ball falling at 2,000 frames/s, clear of the line at y = 400 while y < 368.
    fn fall(k: usize) -> (f64, f64, f64) {
        let t = k as f64 * 5e-4;
        (t, 100.0 + 600.0 * t, 100.0 + 4000.0 * t + 0.5 * 392.4 * t * t)
    }

    /// In free flight a fix far from its prediction is its own error and the fixes are kept; near the
    /// surface it is a change of motion (a bounce) and only the last ones are.
    #[test]
    fn only_a_fix_near_the_surface_starts_the_motion_again() {
        let mut tracker = falling_tracker();
        tracker.history = (0..8).map(fall).collect();
        tracker.note_innovation(5.0, (150.0, 150.0));
        assert_eq!(tracker.history.len(), 8);
        let mut tracker = falling_tracker();
        tracker.history = (0..8).map(fall).map(|(t, x, y)| (t, x, y + 280.0)).collect();
        tracker.note_innovation(5.0, (150.0, 380.0));
        assert_eq!(tracker.history.len(), 2);
    }

    /// A narrow window pulled off a dim rim (its prediction 3 px to the side, onto a bright lobe inside the
    /// ball) finds the rim again in a wider one.
    #[test]
    fn a_track_pulled_off_the_rim_finds_it_again() {
        let at = |k: usize| (120.3 + 0.3 * k as f64, 90.7 + 0.8 * k as f64);
        let frame = |k: usize| {
            let (x, y) = at(k);
            render(&Scene {
                ball: (x, y, 40.0),
                ball_level: 105.0,
                marks: vec![(12.0, 0.0, 26.0, 250.0)],
                noise: 2.0,
                seed: k as u64,
                ..Scene::default()
            })
        };
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((40.0, 40.0)),
            ..TrackOptions::default()
        });
        follow(&mut tracker, at, frame, 12, 0.3);
        // A prediction 3 px to the right, as a track drifting along a seam's lobe would make.
        let px = frame(12);
        let img = Plane::new(&px, 256, 256);
        let (x, y) = at(12);
        let search = EdgeSearch {
            half_width: CONFIDENT_HALF_WIDTH,
            ..tracker.opts.search.clone()
        };
        let narrow = refine_circle(&img, x + 3.0, y, 40.0, &search, None).unwrap();
        assert!(
            (narrow.fit.x - x).abs() > 1.0,
            "the narrow window alone stays off: {:?}",
            narrow.fit
        );
        let found = tracker
            .wider_look(&img, &narrow, &search, None)
            .expect("the rim found again");
        assert!((found.fit.x - x).hypot(found.fit.y - y) < 0.3, "{:?}", found.fit);
        // On the rim, the wider look changes nothing.
        let on_rim = refine_circle(&img, x, y, 40.0, &search, None).unwrap();
        assert!(tracker.wider_look(&img, &on_rim, &search, None).is_none());
    }

    /// A ball bouncing at 12,000 px/s (20 m/s for a 67 mm ball 40 px in radius): the centre (x, y) px at
    /// `t` s, with the band's top at y = 200 and the ball pressed up to 10 px into it (the touch at 8 ms,
    /// compression for 1.31 ms, restitution for 1.87 ms, leaving at 8,400 px/s).
    fn bounce_at(t: f64) -> (f64, f64) {
        let (touch, v_in, v_out, depth) = (8e-3, 12000.0, 8400.0, 10.0);
        let (t1, t2) = (depth * FRAC_PI_2 / v_in, depth * FRAC_PI_2 / v_out);
        let tau = t - touch;
        let y = if tau < 0.0 {
            160.0 + v_in * tau
        } else if tau < t1 {
            160.0 + depth * (FRAC_PI_2 * tau / t1).sin()
        } else if tau < t1 + t2 {
            160.0 + depth * (FRAC_PI_2 * (tau - t1) / t2).cos()
        } else {
            160.0 - v_out * (tau - t1 - t2)
        };
        (90.3 + 600.0 * t, y)
    }

    /// The worst centre error of a track of [`bounce_at`] filmed at `fps`, over the frames in contact
    /// (the ball's disc within 2 px of the band) and over the others, px (infinite for a frame not
    /// measured). The ball is faint, its rim both brighter and darker than the backdrop round its
    /// circumference (as a felt ball lit from one side), under 6 DN of noise.
    fn bounce_errors(fps: f64) -> (f64, f64) {
        let scene = |t: f64| Scene {
            ball: (bounce_at(t).0, bounce_at(t).1, 40.0),
            ball_level: 125.0,
            backdrop: (95.0, 95.0),
            surface: Some((200.0, 0.0)),
            band: (90.0, 25.0),
            noise: 6.0,
            seed: (t * 1e6) as u64,
            ..Scene::default()
        };
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((38.0, 42.0)),
            ball_diameter_m: Some(0.067),
            ..TrackOptions::default()
        });
        tracker.set_surface(SurfaceLine::given(128.0, 200.0, 0.0));
        let dt = 1.0 / fps;
        let (a, b) = (bounce_at(-2.0 * dt), bounce_at(-dt));
        tracker.seed((-2.0 * dt, a.0, a.1), (-dt, b.0, b.1));
        let (mut contact, mut flight) = (0.0f64, 0.0f64);
        for k in 0..(16e-3 * fps) as usize {
            let t = k as f64 * dt;
            let fix = tracker.observe(k, t, &Plane::new(&render(&scene(t)), 256, 256));
            let (x, y) = bounce_at(t);
            let err = if fix.status.measured() {
                (fix.x_px - x).hypot(fix.y_px - y)
            } else {
                f64::INFINITY
            };
            if y + 40.0 > 198.0 {
                contact = contact.max(err);
            } else {
                flight = flight.max(err);
            }
        }
        (contact, flight)
    }

    /// At 2,000 frames/s a contact moves the ball pixels from a prediction fitted to the frames before it:
    /// the ball is looked for as far as a contact can move it, and the track holds the rim through the
    /// bounce (0.37 px at worst). Searched only in the narrow window, the track was 2.1 px off in the
    /// contact's second frame, 1.7–13 px off in the next three and lost the ball in two more. At 10,000
    /// frames/s the narrow window is enough.
    #[test]
    fn a_bounce_filmed_at_a_low_frame_rate_is_held_in_contact() {
        for fps in [2000.0, 10000.0] {
            let (contact, flight) = bounce_errors(fps);
            assert!(contact < 1.0, "{fps} frames/s: {contact:.2} px off in contact");
            assert!(flight < 1.0, "{fps} frames/s: {flight:.2} px off in flight");
        }
    }

    /// After a bounce filmed at 2,000 frames/s the prediction is fitted to the fixes since the ball left the
    /// surface only, in free flight; at 10,000 frames/s to all the recent ones.
    #[test]
    fn after_a_bounce_at_a_low_frame_rate_only_the_flight_since_predicts() {
        for (dt, kept) in [(5e-4, 2), (1e-4, 6)] {
            let mut tracker = Tracker::new(TrackOptions {
                radius_px: Some((30.0, 30.0)),
                ball_diameter_m: Some(0.067),
                ..TrackOptions::default()
            });
            tracker.set_surface(SurfaceLine::given(128.0, 400.0, 0.0));
            // Four fixes with the disc's bottom within 2 px of the line, then two rising clear of it.
            let ys = [369.0, 371.0, 372.0, 371.0, 360.0, 350.0];
            tracker.history = (ys.iter().enumerate())
                .map(|(k, &y)| (k as f64 * dt, 100.0 + k as f64, y))
                .collect();
            assert_eq!(tracker.motion_fixes().len(), kept, "{dt} s a frame");
        }
    }

    /// Once the ball's size is known, a circle of another size near its path is not the ball, however near
    /// and clear: a circle inside a ball pressed on the surface (its rim partly hidden) or a disc where it
    /// was lost. The frame is absent rather than `ok` on it.
    #[test]
    fn a_circle_of_another_size_does_not_continue_the_track() {
        let at = |k: usize| (100.3 + 0.3 * k as f64, 80.7 + 0.8 * k as f64);
        let ball = |k: usize, r: f64| {
            let (x, y) = at(k);
            render(&Scene {
                ball: (x, y, r),
                seed: k as u64,
                ..Scene::default()
            })
        };
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some((36.0, 44.0)),
            ..TrackOptions::default()
        });
        follow(&mut tracker, at, |k| ball(k, 40.0), 20, 0.3);
        // 12 % smaller (inside the detector's ±15 %), 5 px from the prediction.
        let (x, y) = at(20);
        let px = render(&Scene {
            ball: (x + 5.0, y, 35.2),
            seed: 20,
            ..Scene::default()
        });
        let fix = tracker.observe(20, 20e-4, &Plane::new(&px, 256, 256));
        assert_eq!(fix.status, Status::Absent, "{fix:?}");
        // The ball itself, next frame, continues the track.
        let px = ball(21, 40.0);
        let fix = tracker.observe(21, 21e-4, &Plane::new(&px, 256, 256));
        let (x, y) = at(21);
        assert_eq!(fix.status, Status::Ok, "{fix:?}");
        assert!((fix.x_px - x).hypot(fix.y_px - y) < 0.3, "{fix:?}");
    }

    /// A ball in heavy noise (12 DN) that vanishes: the refinement around the prediction can still return a
    /// circle of fair quality from the noise's strongest steps, but no rim stands out under it, so no frame
    /// after the ball is gone is `ok`, and the loss is kept.
    #[test]
    fn a_circle_made_of_noise_does_not_continue_the_track() {
        let at = |k: usize| (110.3 + 0.4 * k as f64, 90.7 + 0.9 * k as f64);
        let scene = |k: usize, ball: bool| {
            let (x, y) = at(k);
            render(&Scene {
                // Gone: drawn outside the frame.
                ball: if ball { (x, y, 40.0) } else { (-500.0, -500.0, 40.0) },
                ball_level: 140.0,
                backdrop: (90.0, 90.0),
                noise: 12.0,
                seed: k as u64,
                ..Scene::default()
            })
        };
        let mut tracker = tracker_for_40px(true);
        follow(&mut tracker, at, |k| scene(k, true), 20, 1.5);
        let after: Vec<Status> = (20..40)
            .map(|k| {
                let px = scene(k, false);
                tracker.observe(k, k as f64 * 1e-4, &Plane::new(&px, 256, 256)).status
            })
            .collect();
        assert!(after.iter().all(|s| *s != Status::Ok), "{after:?}");
        assert!(
            tracker.rim_lost_at().is_some_and(|k| k >= 20),
            "{:?}",
            tracker.rim_lost_at()
        );
        assert!(
            tracker.warnings().iter().any(|w| w.contains("no rim standing out")),
            "{:?}",
            tracker.warnings()
        );
    }

    /// A track seeded with two sightings ten frames apart (as acquisition gives them) that loses the ball
    /// widens its search by the ground the ball covers in a frame, not in the sightings' gap: a still disc
    /// of the ball's size 100 px off the path is not taken for the ball in the 20 frames after.
    #[test]
    fn a_lost_ball_is_looked_for_frame_by_frame_after_a_seed() {
        let ring = (lost_path(50).0 + 100.0, lost_path(50).1, 40.0, 200.0);
        let statuses = lost_beside(ring, Scene::default(), false);
        assert!(statuses.iter().all(|s| s.1 != Status::Ok), "{statuses:?}");
    }

    /// A tracker for a ball acquired at radii 36–44 px, its rays smoothed (as in noisy frames) or not.
    fn tracker_for_40px(smooth: bool) -> Tracker {
        Tracker::new(TrackOptions {
            radius_px: Some((36.0, 44.0)),
            search: EdgeSearch {
                smooth,
                ..EdgeSearch::default()
            },
            ..TrackOptions::default()
        })
    }

    /// Where [`lost_beside`]'s track had its ball, px.
    fn lost_path(k: usize) -> (f64, f64) {
        (60.3 + 0.3 * k as f64, 60.7 + 0.8 * k as f64)
    }

    /// A track seeded with two sightings on [`lost_path`] ten frames apart (as acquisition gives them), then
    /// shown 20 frames of `look` without the ball but with a still `ring` (x, y, r, level), its rays smoothed
    /// or not: each frame's (index, status, x).
    fn lost_beside(ring: (f64, f64, f64, f64), look: Scene, smooth: bool) -> Vec<(usize, Status, f64)> {
        let mut tracker = tracker_for_40px(smooth);
        let sighting = |k: usize| (k as f64 * 1e-4, lost_path(k).0, lost_path(k).1);
        tracker.seed(sighting(30), sighting(40));
        (41..61)
            .map(|k| {
                let px = render(&Scene {
                    ball: (-500.0, -500.0, 40.0),
                    distractors: vec![ring],
                    seed: k as u64,
                    ..look.clone()
                });
                let fix = tracker.observe(k, k as f64 * 1e-4, &Plane::new(&px, 256, 256));
                (k, fix.status, fix.x_px)
            })
            .collect()
    }

    /// A track seeded 14 px off a faint ball in heavy noise (sightings refined on noise, as acquisition can
    /// give them at 14 DN) finds the ball by its rim's strength around the prediction and measures it in
    /// the frames after, where a refinement at the prediction stays on the noise.
    #[test]
    fn a_ball_seen_well_off_its_sightings_is_found_by_its_rim() {
        let at = |k: usize| (100.3 + 0.3 * k as f64, 80.7 + 0.8 * k as f64);
        let mut tracker = tracker_for_40px(true);
        let sighting = |k: usize| (k as f64 * 1e-4, at(k).0 - 12.0, at(k).1 - 7.0);
        tracker.seed(sighting(30), sighting(40));
        let errors: Vec<(usize, Status, f64)> = (41..61)
            .map(|k| {
                let px = render(&Scene {
                    ball: (at(k).0, at(k).1, 40.0),
                    ball_level: 125.0,
                    backdrop: (100.0, 100.0),
                    noise: 14.0,
                    seed: k as u64,
                    ..Scene::default()
                });
                let fix = tracker.observe(k, k as f64 * 1e-4, &Plane::new(&px, 256, 256));
                (k, fix.status, (fix.x_px - at(k).0).hypot(fix.y_px - at(k).1))
            })
            .collect();
        let on_ball = errors.iter().filter(|e| e.1 == Status::Ok && e.2 < 1.0).count();
        assert!(on_ball >= 18, "{errors:?}");
        assert!(errors.iter().all(|e| e.1 != Status::Ok || e.2 < 1.0), "{errors:?}");
    }

    /// In heavy noise, where a lost ball is looked for by its rim's strength, a still ring of the ball's size
    /// whose rim passes within the search's reach of the path is not taken for the ball: the circles that
    /// cross it do so in a few sectors of their rims only.
    #[test]
    fn a_ring_beside_a_lost_ball_s_path_is_not_its_rim() {
        let ring = (lost_path(50).0 + 70.0, lost_path(50).1, 40.0, 150.0);
        let look = Scene {
            backdrop: (100.0, 100.0),
            noise: 12.0,
            ..Scene::default()
        };
        let statuses = lost_beside(ring, look, true);
        // Judged on where the fixes lie: one frame's noise at the path itself can pass for a rim (frame 51,
        // with or without the rim search).
        let off_path = |s: &(usize, Status, f64)| (s.2 - lost_path(s.0).0).abs() > 20.0;
        assert!(statuses.iter().all(|s| !s.1.measured() || !off_path(s)), "{statuses:?}");
    }

    /// Before the track has measured the ball in free flight, a circle outside the radius range it was
    /// acquired with is not the ball: a larger circle where the ball should be (noise pulled along by part
    /// of its rim, a shadow, a fixture) leaves the frame `absent`, while the ball itself is taken.
    #[test]
    fn a_circle_not_of_the_acquired_size_is_not_the_ball() {
        let draw = |r: f64| {
            render(&Scene {
                ball: (121.3, 125.6, r),
                ball_level: 170.0,
                backdrop: (90.0, 90.0),
                noise: 2.0,
                ..Scene::default()
            })
        };
        let observe = |r: f64| {
            let mut tracker = Tracker::new(TrackOptions {
                radius_px: Some((51.0, 69.0)),
                ..TrackOptions::default()
            });
            // Sightings 1 ms apart that predict the circle's centre: a circle of another size is not
            // measured at the prediction, and the frame is searched whole.
            tracker.seed((-0.002, 101.3, 105.6), (-0.001, 111.3, 115.6));
            let fix = tracker.observe(0, 0.0, &Plane::new(&draw(r), 256, 256));
            (fix.status, fix.r_px)
        };
        let (status, r) = observe(74.0);
        assert_eq!(status, Status::Absent, "radius {r}");
        let (status, r) = observe(60.0);
        assert_eq!(status, Status::Ok);
        assert!((r - 60.0).abs() < 0.5, "{r}");
    }

    #[test]
    fn a_tracker_told_the_ball_s_radius_takes_only_that_size() {
        // A circle 10 % larger than the ball, as a rim joined to its shadow gives: inside the acquired
        // radius range, but not the size another pass measured.
        let img = render(&Scene {
            ball: (121.3, 125.6, 66.0),
            ball_level: 170.0,
            backdrop: (90.0, 90.0),
            noise: 2.0,
            ..Scene::default()
        });
        let observe = |told: Option<f64>| {
            let mut tracker = Tracker::new(TrackOptions {
                radius_px: Some((51.0, 69.0)),
                ..TrackOptions::default()
            });
            if let Some(r) = told {
                tracker.expect_radius(r);
            }
            tracker.seed((-0.002, 101.3, 105.6), (-0.001, 111.3, 115.6));
            tracker.observe(0, 0.0, &Plane::new(&img, 256, 256))
        };
        let fresh = observe(None);
        assert_eq!(fresh.status, Status::Ok, "the range alone admits it");
        assert!((fresh.r_px - 66.0).abs() < 0.5, "{}", fresh.r_px);
        let told = observe(Some(60.0));
        assert_eq!(told.status, Status::Absent, "radius {}", told.r_px);
        let told = observe(Some(66.2));
        assert_eq!(told.status, Status::Ok, "radius {}", told.r_px);
    }

    /// A fix kept `inliers` of 128 rays at full contrast: its visible quality is `inliers`/128.
    fn fix_keeping(inliers: usize) -> Refined {
        Refined {
            fit: crate::circle_fit::CircleFit {
                x: 100.0,
                y: 100.0,
                r: 40.0,
                sigma_x: 0.01,
                sigma_y: 0.01,
                sigma_r: 0.01,
                rms: 0.05,
                inliers,
            },
            rays_with_edge: 128,
            rays_outside: 0,
            rays_hidden: 0,
            rays: 128,
            contrast: 20.0,
            edge_definition_px: f64::NAN,
        }
    }

    /// A whole rim measured well inside the ball's flight radius is an edge within the ball, not its rim;
    /// a rim partly hidden by the surface keeps the room [`same_size`] gives it, and so does every circle
    /// until the flight radius is known.
    #[test]
    fn a_whole_rim_inside_the_flight_radius_is_not_the_ball() {
        let mut tracker = falling_tracker();
        let circle = |r: f64, rays_hidden: usize| {
            let mut f = fix_keeping(110);
            f.fit.r = r;
            f.rays_hidden = rays_hidden;
            f
        };
        assert!(tracker.of_flight_size(&circle(37.0, 0)), "no flight radius known yet");
        tracker.flight_radii = vec![40.0; RIM_MIN_SAMPLES];
        assert!(tracker.of_flight_size(&circle(39.0, 0)));
        assert!(tracker.of_flight_size(&circle(41.6, 0)));
        assert!(!tracker.of_flight_size(&circle(38.2, 0)), "1.8 px inside a 40 px rim");
        assert!(!tracker.of_flight_size(&circle(37.0, 0)));
        assert!(
            tracker.of_flight_size(&circle(37.0, 20)),
            "a rim partly hidden by the surface"
        );
    }

    /// The wider look is for a rim that is neither clean nor within the recent fixes' own spread of
    /// quality.
    #[test]
    fn only_a_rim_clearly_worse_than_the_recent_ones_is_looked_for_again() {
        let mut tracker = falling_tracker();
        // Recent qualities 0.70–0.80 (median 0.75, spread 1.4826 × 0.03 ≈ 0.044).
        tracker.qualities = [0.72, 0.75, 0.78, 0.70, 0.80, 0.75, 0.74, 0.76].to_vec();
        assert!(tracker.below_recent_quality(&fix_keeping(77)), "0.60");
        assert!(
            !tracker.below_recent_quality(&fix_keeping(93)),
            "0.73: within the spread"
        );
        // Below a clean track's median, but clean itself.
        tracker.qualities = vec![1.0; 8];
        assert!(!tracker.below_recent_quality(&fix_keeping(115)), "0.90");
        assert!(tracker.below_recent_quality(&fix_keeping(100)), "0.78");
        // Too few recent fixes to judge by.
        tracker.qualities = vec![1.0; 4];
        assert!(!tracker.below_recent_quality(&fix_keeping(64)));
    }
}
