//! One shot: phases, velocities, restitution, friction, contact time and penetration from a track.

use crate::ballistic::{BallisticFit, FreeArc, fit_ballistic, fit_free_acceleration, fit_free_acceleration_beyond_rim};
use crate::contact::{HeightPoint, TrajectoryContact, find_impact, trajectory_contact};
use crate::phase::PhaseFrames;
use bouncelab_track::{LineCue, Status, SurfaceFrame, SurfaceLine, Track};
use serde::{Deserialize, Serialize};

/// The conditions of a shot that the video does not show.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conditions {
    /// Incline of the surface β, degrees (`angle_deg` in clips.csv).
    pub incline_deg: f64,
    /// Gravitational acceleration, m/s².
    pub gravity: f64,
    /// Ball diameter, m.
    pub ball_diameter_m: f64,
    /// The surface's tilt in the image, degrees counter-clockwise as seen, where no line shows it (a known
    /// camera roll, `[surface] tilt_deg`); `None`: the image's axes, taken as level to [`LEVEL_BY_EYE_DEG`].
    pub surface_tilt_deg: Option<f64>,
    /// How well the direction of the ball's fall is known beforehand, degrees (a standard error): a ball
    /// released at rest falls along gravity, at `incline_deg` from the surface's normal, to within the
    /// incline's own error and the release's sideways push ([`FALL_SE_DEG`] by default). The fall then
    /// measures the surface's tilt in the image too, and it is combined with a line's where the two agree
    /// (`[surface] incline_se_deg`). `None`: the ball was not dropped from rest, the line's tilt alone is used.
    pub fall_se_deg: Option<f64>,
}

/// How well a dropped ball's fall direction is known by default, degrees: the precision of the paper's
/// digital angle gauge that set its inclines (±0.5°).
pub const FALL_SE_DEG: f64 = 0.5;

/// [`Conditions::fall_se_deg`] from a session's settings: whether the ball was released at rest (`None`:
/// not said, taken as dropped) and the incline's standard error (`None`: [`FALL_SE_DEG`]).
pub fn fall_se_deg(dropped_from_rest: Option<bool>, incline_se_deg: Option<f64>) -> Option<f64> {
    (dropped_from_rest != Some(false)).then(|| incline_se_deg.unwrap_or(FALL_SE_DEG))
}

impl Conditions {
    /// Refuses conditions no impact can have: an incline that is not strictly between −90° and 90°, a
    /// gravity or ball diameter that is not a positive finite number.
    pub fn check(&self) -> Result<(), EstimateError> {
        let bad = |field, value, why| Err(EstimateError::BadCondition { field, value, why });
        if self.incline_deg.is_nan() || self.incline_deg.abs() >= 90.0 {
            return bad(
                "incline",
                self.incline_deg,
                "an incline lies strictly between −90 and 90 degrees",
            );
        }
        if !(self.gravity.is_finite() && self.gravity > 0.0) {
            return bad("gravity", self.gravity, "must be a positive number of m/s²");
        }
        if !(self.ball_diameter_m.is_finite() && self.ball_diameter_m > 0.0) {
            return bad(
                "ball diameter",
                self.ball_diameter_m,
                "must be a positive number of metres",
            );
        }
        if let Some(t) = self.surface_tilt_deg
            && (t.is_nan() || t.abs() > 45.0)
        {
            return bad("surface tilt", t, "a tilt in the image lies between −45 and 45 degrees");
        }
        if let Some(s) = self.fall_se_deg
            && !(s.is_finite() && s > 0.0)
        {
            return bad("incline's standard error", s, "must be a positive number of degrees");
        }
        Ok(())
    }
}

impl Default for Conditions {
    fn default() -> Self {
        Conditions {
            incline_deg: 0.0,
            gravity: 9.81,
            ball_diameter_m: 0.067,
            surface_tilt_deg: None,
            fall_se_deg: Some(FALL_SE_DEG),
        }
    }
}

/// A measured value and its standard error, in the value's unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub se: f64,
}

impl Measured {
    fn new(value: f64, se: f64) -> Self {
        Measured { value, se }
    }
}

/// The per-shot results (local frame of `docs/outputs.md`: t along the surface down-slope, n along the normal).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// Velocity at contact start (tangential, normal), m/s.
    pub v_in: [Measured; 2],
    /// Velocity at contact end (tangential, normal), m/s.
    pub v_out: [Measured; 2],
    /// Coefficient of restitution |v_n,out / v_n,in|.
    pub cor: Measured,
    /// Effective friction −Δv_t / Δv_n (the paper's momentum ratio).
    pub mu: Measured,
    /// Contact time, ms.
    pub contact_ms: Measured,
    /// Contact start, s from the first frame.
    pub t_touch: Measured,
    /// Time of maximum compression, s.
    pub t_max: f64,
    /// Contact end, s.
    pub t_sep: Measured,
    /// Maximum penetration of the centre below one radius above the surface, m.
    pub delta_max_m: Measured,
    /// Spin before the impact, rad/s (counter-clockwise as seen), when measured.
    pub spin_in: Option<Measured>,
    /// Spin after the impact, rad/s, when measured.
    pub spin_out: Option<Measured>,
    /// The frames of each phase.
    pub phases: PhaseFrames,
    /// The incoming ballistic arc (local frame, m, s): where a simulation of the shot starts.
    pub flight_in: BallisticFit,
    /// The outgoing ballistic arc.
    pub flight_out: BallisticFit,
    /// Reduced χ² of the flight fits (in x, in y, out x, out y): ≫ 1 means the tracker's σ is too small or the
    /// flight is not ballistic (drag, a bad frame).
    pub chi2_red: [f64; 4],
    /// Shot-to-shot standard error of the contact plane's height in the local frame, m: the surface line's
    /// (with the correlation of its columns) and the scale's at one radius, without the rim shape's Type-B
    /// term, which lighting makes common to a session's clips (a fit's surface level takes that part; this
    /// is the prior of each shot's deviation from it). 0 in estimates stored before it existed.
    #[serde(default)]
    pub surface_sigma_m: f64,
    /// The contact line used, in the image: found (its `cue` says by which cue), given by the user, or taken
    /// from the ball's trajectory (`LineCue::Trajectory`).
    #[serde(default)]
    pub contact_line: Option<SurfaceLine>,
    /// The local frame the velocities are measured in: on the contact line, its axes along the line (so a
    /// rolled camera's tilt is taken out) and its normal.
    #[serde(default)]
    pub frame: Option<SurfaceFrame>,
    /// The surface's tilt in the image, degrees counter-clockwise as seen, with its standard error, when the
    /// frame follows a line found in the image or the ball's fall (a camera rolled by φ shows the surface
    /// tilted by −φ for down-slope +x); none when neither measured it (a line found but rejected, whose tilt
    /// is no measurement, and no fall from rest).
    #[serde(default)]
    pub surface_tilt_deg: Option<Measured>,
    /// The contact line's own tilt in the image, degrees, with its standard error, when the ball's fall was
    /// weighed with it (`surface_tilt_deg` is then the two combined, or the line's alone when they disagreed).
    #[serde(default)]
    pub line_tilt_deg: Option<Measured>,
    /// The surface's tilt in the image that the ball's fall implies, degrees, with its standard error (a ball
    /// released at rest falls along gravity: see [`Conditions::fall_se_deg`]), also when it disagreed with
    /// the line and was not used (a note says so); `None` when it was not measured (a line or tilt given, a
    /// ball not dropped from rest, a down-slope not known or that the fall fits as well the other way).
    #[serde(default)]
    pub fall_tilt_deg: Option<Measured>,
    /// Where the ball's own trajectory puts the contact level, px above the contact line used (≈ 0 when the
    /// two agree), with its standard error; `None` where the trajectory could not tell.
    #[serde(default)]
    pub trajectory_level_px: Option<Measured>,
    /// The share of the contact level taken from the ball's trajectory, 0–1: a line found in the image that
    /// the trajectory agrees with is moved towards the trajectory's level by their inverse-variance
    /// weights (the line's error taken with the scale's at one radius and the centres' common offset, which
    /// the trajectory, measured in the centres' own frame, does not have). 0 for a given line, a level from
    /// the trajectory alone, and estimates stored before it.
    #[serde(default)]
    pub trajectory_share: f64,
    /// How far the contact level's standard error is widened, ≥ 1: where a line found in the image and
    /// the ball's trajectory put the contact further apart than their errors allow (`|Δ| / √(σ_line² +
    /// σ_trajectory²)` > 1, the Birge ratio of the two), at least one of those errors is too small, and
    /// which cannot be told, so the combined level's error is widened by that ratio. 1 for a level from one
    /// source, and estimates stored before it.
    #[serde(default = "unwidened")]
    pub level_se_scale: f64,
    /// The flights' acceleration, m/s² in the local frame (free fits of both arcs, weighted), against gravity's.
    #[serde(default)]
    pub gravity: Option<GravityCheck>,
    /// How much the ball's measured radius changed from the incoming flight to the outgoing one, px (mean
    /// outgoing − mean incoming, with its standard error): a rigid ball's radius does not, so this is the
    /// tracker's rim-based estimate changing between the flights (a fuzzy rim turning, the light across the
    /// frame), and its centre changes with it, which no flight fit can see.
    #[serde(default)]
    pub rim_change_px: Option<Measured>,
    /// Why the shot's numbers are not to be trusted (it is kept out of the fit); empty when they are.
    #[serde(default)]
    pub flags: Vec<String>,
    /// Things a person should know.
    pub notes: Vec<String>,
}

/// [`Estimate::level_se_scale`] of estimates stored before it existed.
fn unwidened() -> f64 {
    1.0
}

/// Does the ball fall like a ball? The free-flight arcs fitted with their acceleration free.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GravityCheck {
    /// Measured acceleration (along the surface down-slope, along the normal), m/s².
    pub measured: [Measured; 2],
    /// What gravity gives on the incline, m/s².
    pub expected: [f64; 2],
    /// True if they agree within 4 standard errors plus 10 % of g (drag and the like move it by a few %).
    pub consistent: bool,
    /// True if the error is too large for the check to say anything (over half of g).
    pub inconclusive: bool,
    /// Standard error of the tilt of the frame the acceleration is measured in, rad: a frame turned by δ
    /// moves the along-surface part by about g·δ.
    #[serde(default)]
    pub sigma_frame_rad: f64,
}

/// How many standard errors of the measured along-surface acceleration (the fit's and the frame tilt's)
/// gravity's along-surface component must span for its sign to tell the down-slope direction
/// ([`GravityCheck::downslope_evidence`]).
pub const DOWNSLOPE_SIGMAS: f64 = 4.0;

impl GravityCheck {
    /// What the flights say of the down-slope direction the frame was built with: `Some(true)` when they
    /// fall as gravity would with it the other way (a camera mirrored, or a clip whose `downslope` was not
    /// given), `Some(false)` when they confirm it, `None` when they cannot tell. Either answer needs the
    /// normal part to agree and the along-surface part to have gravity's size and that sign, resolved:
    /// gravity's component spans [`DOWNSLOPE_SIGMAS`] of its error (the fit's, and the frame's tilt times
    /// g), or, for `Some(true)`, the direction as set fails the check. Noise alone answers wrongly on
    /// fewer than 1 shot in 10,000.
    pub fn downslope_evidence(&self, g: f64) -> Option<bool> {
        let [at, an] = self.measured;
        let [et, en] = self.expected;
        let near = |m: &Measured, e: f64| (m.value - e).abs() <= 4.0 * m.se + 0.1 * g;
        if self.inconclusive || et == 0.0 || !near(&an, en) {
            return None;
        }
        let resolved = et.abs() >= DOWNSLOPE_SIGMAS * at.se.hypot(g * self.sigma_frame_rad);
        if at.value * et < 0.0 && near(&at, -et) && (resolved || !near(&at, et)) {
            Some(true)
        } else if at.value * et > 0.0 && near(&at, et) && resolved {
            Some(false)
        } else {
            None
        }
    }

    /// [`Self::downslope_evidence`] says the down-slope is the other way.
    pub fn downslope_reversed(&self, g: f64) -> bool {
        self.downslope_evidence(g) == Some(true)
    }

    /// The angle from gravity's expected direction to the measured acceleration's, rad, with its standard
    /// error: how far the frame's axes are turned from the surface's, as the free fall alone tells it.
    pub fn frame_offset_rad(&self) -> Measured {
        let [at, an] = self.measured;
        let [et, en] = self.expected;
        let value = at.value.atan2(-an.value) - et.atan2(-en);
        let norm2 = at.value * at.value + an.value * an.value;
        let se = (an.value * at.se).hypot(at.value * an.se) / norm2;
        Measured::new(value, if se.is_finite() { se } else { f64::INFINITY })
    }
}

impl Estimate {
    /// Contact start and end, s, had the surface been `level_m` above the surface line found in the image (the
    /// flight arcs crossing `radius_m + level_m`): how a fitted surface level carries over to the contact
    /// time.
    pub fn contact_at_level(&self, level_m: f64, radius_m: f64) -> (f64, f64) {
        let y = radius_m + level_m;
        (
            crossing(&self.flight_in, y, self.t_touch.value).t.value,
            crossing(&self.flight_out, y, self.t_sep.value).t.value,
        )
    }
}

/// Why a shot could not be measured.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EstimateError {
    /// The track has no scale (the ball was never measured clear of the surface).
    /// A condition of the shot that no impact can have.
    #[error("{field} = {value}: {why}")]
    BadCondition {
        field: &'static str,
        value: f64,
        why: &'static str,
    },
    #[error("no scale: the ball was not measured in free flight in enough frames")]
    NoScale,
    /// No surface line was found and the trajectory could not tell the contact either.
    #[error("no surface line found and the trajectory cannot tell the contact: {why}")]
    NoSurface { why: String },
    /// The ball never came within a pixel of the surface.
    #[error("no impact in the clip: the ball comes no closer than {clearance_px:.1} px to the surface")]
    NoContact { clearance_px: f64 },
    /// The ball's track comes down and goes up again, yet its rim never comes within a pixel of the contact
    /// line: the radius measured is not the ball's edge, or the line is not the surface.
    #[error(
        "the ball turns back {clearance_px:.1} px above the {line} without reaching it: either the rim measured is not the ball's edge (its radius reads {radius_lo_px:.1}–{radius_hi_px:.1} px over the frames, 10th–90th percentile) or the line is not the surface, so the contact cannot be told; give the scale (--scale or [camera] scale_m_per_px: the radius then follows from the ball's diameter) or the contact line (--line or [surface] line_y_px)"
    )]
    TurnsAboveLine {
        clearance_px: f64,
        /// Which line, as a phrase ("surface line found (brightness cue)").
        line: String,
        radius_lo_px: f64,
        radius_hi_px: f64,
    },
    /// The trajectory never comes down and goes up again.
    #[error(
        "no impact in the clip: the ball {} through all {frames} measured frames ({:.3} ± {:.3} m/s along the normal at the last)",
        if *speed_m_s <= 0.0 { "falls" } else { "rises" },
        speed_m_s.abs(),
        se_m_s
    )]
    NoImpact { frames: usize, speed_m_s: f64, se_m_s: f64 },
    /// A flight phase has too few frames to fit.
    #[error("{phase} flight too short to fit: {frames} usable frame(s), {needed} needed ({why})")]
    FlightTooShort {
        phase: &'static str,
        frames: usize,
        needed: usize,
        /// The likely reason, as a phrase.
        why: &'static str,
    },
    /// The ball's heights before its lowest point never leave a free-flight arc clearly enough to tell when
    /// it touched (a track that wanders, or one on something other than the ball).
    #[error(
        "the track's {frames} frames before its lowest point never leave a free-flight arc clearly: the trajectory cannot tell when the ball touched"
    )]
    NoDeparture { frames: usize },
    /// A fit failed (degenerate times).
    #[error("the {phase} flight could not be fitted")]
    FitFailed { phase: &'static str },
    /// The shot could not be measured (`cause`) and the track holds frames the tracker did not take for the
    /// ball (another circle it could not tell from the ball, or off the ball's path), which the estimator
    /// does not use: the likely reason.
    #[error(
        "{cause}; {frames} frame(s) of the track were not taken for the ball (ambiguous: another circle could be the ball, or they lie off its path; see the track's warnings) and are not used"
    )]
    Ambiguous { frames: usize, cause: Box<EstimateError> },
}

/// Fewest frames a flight fit uses.
pub const MIN_FLIGHT_FRAMES: usize = 6;
/// A frame counts as flight when the ball's bottom is at least this far above the surface line, px.
const CLEARANCE_MARGIN_PX: f64 = 1.0;
/// Smallest per-frame σ used as a weight, px (the tracker's σ can be optimistic on clean frames); later
/// stages weighting the same frames use it too.
pub const MIN_SIGMA_PX: f64 = 0.01;

struct Point {
    frame: usize,
    t: f64,
    x: f64,
    y: f64,
    sigma: f64,
    clearance_px: f64,
    /// The radius the tracker measured in this frame, px.
    r_px: f64,
}

/// Measures one shot from its track.
///
/// The contact line is the best evidence available, in this order: a line the user gave; the line the
/// tracker found, if the ball's trajectory agrees that the contact is there (else the other cue's line, if
/// it agrees), its level moved towards the trajectory's by their inverse-variance weights
/// ([`Estimate::trajectory_share`]); the contact level the trajectory gives (see `contact.rs`). The local
/// frame follows that line's tilt in the image, weighed with the tilt a ball dropped from rest implies where
/// the two agree (`fall.rs`).
///
/// Frames the tracker did not take for the ball (`ambiguous`) are not used; when the track has
/// any, a shot that cannot be measured says so with its reason ([`EstimateError::Ambiguous`]: they are the
/// likely cause), and one that can gets a note.
pub fn estimate(track: &Track, c: &Conditions) -> Result<Estimate, EstimateError> {
    let ambiguous = track.fixes.iter().filter(|f| f.status == Status::Ambiguous).count();
    match estimate_from_measured(track, c) {
        Err(e) if ambiguous > 0 && !matches!(e, EstimateError::BadCondition { .. }) => Err(EstimateError::Ambiguous {
            frames: ambiguous,
            cause: Box::new(e),
        }),
        Ok(mut e) if ambiguous > 0 => {
            e.notes.push(format!(
                "{ambiguous} frame(s) the tracker did not take for the ball (ambiguous, see the track's warnings) are not used"
            ));
            Ok(e)
        }
        other => other,
    }
}

/// [`estimate`] from the track's measured frames alone: measured in the contact line's frame, then, when the
/// ball fell from rest ([`Conditions::fall_se_deg`]) and the line's tilt was not given, measured again in the
/// frame of the tilt the line and the fall agree on (see `fall.rs`).
fn estimate_from_measured(track: &Track, c: &Conditions) -> Result<Estimate, EstimateError> {
    let (mut first, fall) = measure(track, c, None)?;
    let Some(fall) = fall else {
        return Ok(first);
    };
    let incline = c.incline_deg;
    if crate::fall::other_way_fits_as_well(fall.line, fall.tilt, fall.reversed_tilt_deg) {
        first.notes.push(format!(
            "the ball's fall onto the {incline}° incline agrees with {} ({:.2} ± {:.2}°) no worse with the down-slope the other way: the fall is not used",
            fall.what, fall.line.value, fall.line.se
        ));
        return Ok(first);
    }
    // The image's axes are no measurement of the surface, only a bound on how far off it they may be.
    let tilt = if fall.measured_line {
        crate::fall::combine(fall.line, fall.tilt)
    } else {
        crate::fall::agree(fall.line, fall.tilt).map(|()| fall.tilt)
    };
    match tilt {
        Ok(tilt) => {
            let turn = Turn {
                pivot_x: fall.pivot_x,
                tilt,
            };
            let mut e = match measure(track, c, Some(turn)) {
                Ok((e, _)) => e,
                Err(err) => {
                    first.notes.push(format!(
                        "measured along the tilt {:.2} ± {:.2}° that the ball's fall gives with {}, the shot could not be measured ({err}): the first tilt is kept",
                        tilt.value, tilt.se, fall.what
                    ));
                    return Ok(first);
                }
            };
            e.notes.push(if fall.measured_line {
                format!(
                    "the surface's tilt in the image, {:.2} ± {:.2}°, weighs the line's ({:.2} ± {:.2}°) with the ball's fall onto the {incline}° incline ({:.2} ± {:.2}°)",
                    tilt.value, tilt.se, fall.line.value, fall.line.se, fall.tilt.value, fall.tilt.se
                )
            } else {
                format!(
                    "the surface's tilt in the image, {:.2} ± {:.2}°, is the ball's fall's onto the {incline}° incline (the image's axes taken as level to ± {:.1}°)",
                    tilt.value, tilt.se, fall.line.se
                )
            });
            e.line_tilt_deg = fall.measured_line.then_some(fall.line);
            e.fall_tilt_deg = Some(fall.tilt);
            Ok(e)
        }
        Err(z) => {
            let (mut e, kept) = match fall
                .measured_line
                .then(|| widened_to_the_fall(track, c, &fall))
                .flatten()
            {
                Some((e, tilt)) => (
                    e,
                    format!(
                        ", and the line's tilt is kept with a standard error of {:.2}° that covers the fall's, since either may be the wrong one",
                        tilt.se
                    ),
                ),
                None => (first, String::new()),
            };
            e.notes.push(format!(
                "the ball's fall onto the {incline}° incline puts the surface's tilt in the image at {:.2} ± {:.2}°, {:.1} standard errors from {} ({:.2} ± {:.2}°): a ball not dropped from rest, another incline, or a line that is not the surface's; the fall is not used{kept}",
                fall.tilt.value, fall.tilt.se, z.abs(), fall.what, fall.line.value, fall.line.se
            ));
            e.line_tilt_deg = fall.measured_line.then_some(fall.line);
            e.fall_tilt_deg = Some(fall.tilt);
            Ok(e)
        }
    }
}

/// The shot measured again along its line's own tilt with a standard error that covers the tilt's difference
/// from the fall's, and that tilt; `None` if it then cannot be measured. When the two disagree beyond
/// [`crate::fall::AGREE_SIGMAS`], one of them is wrong (a line drawn by the band's grains or a fixture on it,
/// a ball not dropped from rest) and the shot alone cannot tell which, so the line's is kept without claiming
/// its own precision.
fn widened_to_the_fall(track: &Track, c: &Conditions, fall: &FallEvidence) -> Option<(Estimate, Measured)> {
    let tilt = Measured {
        value: fall.line.value,
        se: fall.line.se.hypot(fall.line.value - fall.tilt.value),
    };
    let turn = Turn {
        pivot_x: fall.pivot_x,
        tilt,
    };
    measure(track, c, Some(turn)).ok().map(|(e, _)| (e, tilt))
}

/// A turn of the contact line to a tilt measured with the fall: about `pivot_x`, px, to `tilt`, degrees.
struct Turn {
    pivot_x: f64,
    tilt: Measured,
}

/// What the ball's fall says of the frame's tilt, from a shot measured in its contact line's frame.
struct FallEvidence {
    /// The frame's tilt and its standard error, degrees: the line's, or the image's axes when no line's tilt
    /// was measured.
    line: Measured,
    /// Whether `line` was measured in the image (a found line) rather than assumed (the image's axes).
    measured_line: bool,
    /// What `line` is, for notes.
    what: &'static str,
    /// The tilt the fall implies, degrees.
    tilt: Measured,
    /// The tilt it would imply were the down-slope the other way, degrees.
    reversed_tilt_deg: f64,
    /// Where the contact level is known best, px: about there the line is turned, so that the level stays.
    pivot_x: f64,
}

/// One shot measured in the frame of its contact line, turned by `turn` when given; with what its fall
/// says of the frame's tilt when that can be used (not turned yet, a ball dropped from rest, a tilt not
/// given).
fn measure(
    track: &Track,
    c: &Conditions,
    turn: Option<Turn>,
) -> Result<(Estimate, Option<FallEvidence>), EstimateError> {
    c.check()?;
    let scale = track.scale.ok_or(EstimateError::NoScale)?;
    let s = scale.m_per_px;
    let measured = fitted_fixes(track)?;
    let beta = c.incline_deg.to_radians();
    let radius = c.ball_diameter_m / 2.0;
    let choice = contact_line(
        track,
        &measured,
        scale.radius_px,
        -c.gravity * beta.cos() / s,
        c.surface_tilt_deg,
        against_centres_px(&scale, radius),
    )?;
    let line = match &turn {
        Some(t) => choice.line.turned_about(t.pivot_x, t.tilt.value, t.tilt.se),
        None => choice.line,
    };
    let (frame, points) = local_points(track, &measured, &line, &scale);
    let (first, last) = contact_run(&points, choice.no_impact, &line, s)?;
    let (incoming, outgoing) = flights(&points, first, last)?;
    let beta = c.incline_deg.to_radians();
    let a = [c.gravity * beta.sin(), -c.gravity * beta.cos()];
    let fit = |set: &[&Point], phase| {
        let pts: Vec<_> = set.iter().map(|p| (p.t, p.x, p.y, p.sigma)).collect();
        fit_ballistic(&pts, a).ok_or(EstimateError::FitFailed { phase })
    };
    let fin = fit(&incoming, "incoming")?;
    let fout = fit(&outgoing, "outgoing")?;
    // Each flight with its acceleration free: as it is, for the centres' scatter about one arc, and beyond
    // what the rim's change explains, for the fall.
    let free = |set: &[&Point]| {
        let pts: Vec<_> = set.iter().map(|p| (p.t, p.x, p.y, p.sigma)).collect();
        let radii: Vec<f64> = set.iter().map(|p| p.r_px * s).collect();
        (
            fit_free_acceleration(&pts),
            fit_free_acceleration_beyond_rim(&pts, &radii),
        )
    };
    let ((arc_in, fall_in), (arc_out, fall_out)) = (free(&incoming), free(&outgoing));
    let free_arcs = [arc_in, arc_out];
    let gravity = gravity_check(&[fall_in, fall_out], a, c.gravity);
    let mut notes = choice.notes;
    let mut level = LevelErrors::of(&line, &scale, radius, choice.trajectory_share, choice.level_se_scale);
    if line.cue == LineCue::Trajectory
        && c.surface_tilt_deg.is_none()
        && turn.is_none()
        && let Some(g) = &gravity
    {
        level.sigma_theta = unmeasured_tilt(g, &mut notes);
    }
    let gravity = gravity.map(|g| GravityCheck {
        sigma_frame_rad: level.sigma_theta,
        ..g
    });
    // The level's error is common to both crossings, so it is carried as a derivative and propagated
    // coherently into the contact time, COR and μ, not added to each crossing separately.
    let touch = crossing(&fin, radius, points[first].t);
    let sep = crossing(&fout, radius, points[last].t);
    let with_level = |c: &Crossing| Measured::new(c.t.value, c.t.se.hypot(c.dt_dlevel * level.sigma));
    let (t_touch, t_sep) = (with_level(&touch), with_level(&sep));
    // The rim's bias drifting along a flight moves its velocities by as much (see `RadiusLine`).
    let radius_lines = (RadiusLine::of(&incoming, s), RadiusLine::of(&outgoing, s));
    let drift = |l: &Option<RadiusLine>| l.as_ref().map_or(0.0, |l| l.centre_drift() * s);
    let vin = velocity_parts(&fin, &touch, &level, drift(&radius_lines.0));
    let vout = velocity_parts(&fout, &sep, &level, drift(&radius_lines.1));
    let cor = restitution(&vin, &vout, &level);
    let mu = friction(&vin, &vout, &level);
    let contact_se =
        (touch.t.se.powi(2) + sep.t.se.powi(2) + ((sep.dt_dlevel - touch.dt_dlevel) * level.sigma).powi(2)).sqrt();
    let contact = &points[first..=last];
    let (t_max, delta_max) = deepest(contact, radius, level.sigma, level.rel_scale);
    let mut flags = impossible(
        vin[1].value,
        vout[1].value,
        cor.value,
        mu.value,
        t_touch.value,
        t_sep.value,
    );
    flags.extend(saturation_flag(track));
    flags.extend(off_one_ball(&free_arcs, s, scale.radius_px));
    flags.extend(rim_wanders(&radius_lines, scale.radius_px));
    if let Some(g) = &gravity {
        note_gravity(g, c.incline_deg, c.gravity, &mut flags, &mut notes);
    }
    note_scatter(&fin, &fout, &mut notes);
    let rim_change_px = rim_change(&radius_lines);
    let found_line = matches!(line.cue, LineCue::Brightness | LineCue::Texture);
    let fall = match (turn.is_none(), c.fall_se_deg) {
        (true, Some(fall_se)) if found_line || (line.cue == LineCue::Trajectory && c.surface_tilt_deg.is_none()) => {
            let v = [vin[0].value, vin[1].value];
            // The fit's own errors: the level's moves the touch along the fall, not across it.
            crate::fall::incidence_rad(v, [vin[0].stat, vin[1].stat]).map(|incidence| {
                let sign = if track.downslope_negative_x { -1.0 } else { 1.0 };
                let frame_tilt = Measured::new(line.tilt_deg(), level.sigma_theta.to_degrees());
                // A level mostly from the trajectory is known best at the contact, a line's at its centre.
                let share = if found_line { choice.trajectory_share } else { 1.0 };
                FallEvidence {
                    line: frame_tilt,
                    measured_line: found_line,
                    what: if found_line { "the line's" } else { "the image's axes" },
                    tilt: crate::fall::tilt_from_fall(frame_tilt.value, incidence, c.incline_deg, fall_se, sign),
                    reversed_tilt_deg: crate::fall::tilt_from_fall(
                        frame_tilt.value,
                        incidence,
                        -c.incline_deg,
                        fall_se,
                        sign,
                    )
                    .value,
                    pivot_x: line.x0 + share * (frame.origin_px[0] - line.x0),
                }
            })
        }
        _ => None,
    };
    let estimate = Estimate {
        v_in: vin.map(|v| Measured::new(v.value, v.total)),
        v_out: vout.map(|v| Measured::new(v.value, v.total)),
        cor,
        mu,
        contact_ms: Measured::new((t_sep.value - t_touch.value) * 1e3, contact_se * 1e3),
        t_touch,
        t_max,
        t_sep,
        delta_max_m: delta_max,
        spin_in: None,
        spin_out: None,
        phases: PhaseFrames {
            flight_in: (incoming[0].frame, incoming[incoming.len() - 1].frame),
            contact: (points[first].frame, points[last].frame),
            flight_out: (outgoing[0].frame, outgoing[outgoing.len() - 1].frame),
            fitted: (incoming.len(), outgoing.len()),
        },
        chi2_red: [fin.chi2_red[0], fin.chi2_red[1], fout.chi2_red[0], fout.chi2_red[1]],
        flight_in: fin,
        flight_out: fout,
        surface_sigma_m: level.sigma_scatter,
        contact_line: Some(line),
        frame: Some(frame),
        surface_tilt_deg: Some(line)
            .filter(|_| found_line || turn.is_some())
            .map(|l| Measured::new(l.tilt_deg(), l.sigma_tilt_deg)),
        line_tilt_deg: None,
        fall_tilt_deg: None,
        trajectory_level_px: choice.trajectory_level_px,
        trajectory_share: choice.trajectory_share,
        level_se_scale: choice.level_se_scale,
        gravity,
        rim_change_px,
        flags,
        notes,
    };
    Ok((estimate, fall))
}

/// The change of the measured radius between the flights (incoming, outgoing), px: mean outgoing − mean
/// incoming, its standard error from each flight's scatter about a line in time (see [`RadiusLine`]);
/// `None` when a flight holds fewer than four radii.
fn rim_change(lines: &(Option<RadiusLine>, Option<RadiusLine>)) -> Option<Measured> {
    let (i, o) = (lines.0.as_ref()?, lines.1.as_ref()?);
    Some(Measured::new(o.mean - i.mean, (i.var_mean + o.var_mean).sqrt()))
}

/// The measured radius through one flight as a line in time, px.
struct RadiusLine {
    mean: f64,
    /// The radii's RMS about the line, px (n − 2 degrees of freedom).
    rms_px: f64,
    /// The median of the flight's centres' σ, px: the tracker's noise, which the radius shares.
    sigma_px: f64,
    /// The mean's variance, px², with the variance factor of the residuals' correlation
    /// (`ballistic::ar1_factor`; a drift along the flight is not counted as correlated noise).
    var_mean: f64,
    /// The radius's drift, px/s, and its standard error (with the same factor).
    slope: Measured,
}

impl RadiusLine {
    /// The least-squares line of the finite radii of `set`; `None` with fewer than four. `m_per_px` turns
    /// the centres' σ into px.
    fn of(set: &[&Point], m_per_px: f64) -> Option<Self> {
        let tr: Vec<(f64, f64)> = set
            .iter()
            .map(|p| (p.t, p.r_px))
            .filter(|(t, r)| t.is_finite() && r.is_finite())
            .collect();
        if tr.len() < 4 {
            return None;
        }
        let n = tr.len() as f64;
        let (mt, mr) = (
            tr.iter().map(|p| p.0).sum::<f64>() / n,
            tr.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let stt: f64 = tr.iter().map(|p| (p.0 - mt).powi(2)).sum();
        let slope = if stt > 0.0 {
            tr.iter().map(|p| (p.0 - mt) * (p.1 - mr)).sum::<f64>() / stt
        } else {
            0.0
        };
        let residuals: Vec<f64> = tr.iter().map(|p| p.1 - mr - slope * (p.0 - mt)).collect();
        let var = residuals.iter().map(|x| x * x).sum::<f64>() / (n - 2.0);
        let factor = crate::ballistic::ar1_factor(&residuals);
        let mut sigmas: Vec<f64> = set
            .iter()
            .map(|p| p.sigma / m_per_px)
            .filter(|v| v.is_finite())
            .collect();
        sigmas.sort_by(f64::total_cmp);
        Some(RadiusLine {
            mean: mr,
            rms_px: var.sqrt(),
            sigma_px: sigmas.get(sigmas.len() / 2).copied().unwrap_or(f64::NAN),
            var_mean: var / n * factor,
            slope: Measured::new(slope, (var / stt.max(f64::MIN_POSITIVE) * factor).sqrt()),
        })
    }

    /// How fast the rim's bias may move the centre, px/s: the radius's drift beyond its noise
    /// (√max(0, slope² − SE²), an unbiased estimate of the squared drift). A rigid ball's radius does not
    /// change in flight, but its apparent rim does where the light on its limb or the backdrop behind it
    /// changes along the path; a bias on one side moves the centre about as much as the radius (a
    /// half-wave-rectified offset by π/2 times as much, a uniform one not at all), in a direction the
    /// circle does not tell. So it is taken as a standard uncertainty of each velocity component.
    fn centre_drift(&self) -> f64 {
        (self.slope.value.powi(2) - self.slope.se.powi(2)).max(0.0).sqrt()
    }
}

/// The fixes a fit weighs ([`bouncelab_track::Status::fitted`] with a finite centre); an error when they
/// cannot hold two flights.
fn fitted_fixes(track: &Track) -> Result<Vec<&bouncelab_track::BallFix>, EstimateError> {
    let measured: Vec<&bouncelab_track::BallFix> = track
        .fixes
        .iter()
        .filter(|f| f.status.fitted() && f.x_px.is_finite() && f.y_px.is_finite())
        .collect();
    if measured.len() < 2 * MIN_FLIGHT_FRAMES {
        return Err(EstimateError::FlightTooShort {
            phase: "incoming",
            frames: measured.len(),
            needed: 2 * MIN_FLIGHT_FRAMES,
            why: "the track holds too few measured frames",
        });
    }
    Ok(measured)
}

/// The local frame on `line` (origin on it, below the lowest centre) and the fixes in it, m, with their
/// clearance above the line, px.
fn local_points(
    track: &Track,
    measured: &[&bouncelab_track::BallFix],
    line: &SurfaceLine,
    scale: &bouncelab_track::Scale,
) -> (SurfaceFrame, Vec<Point>) {
    let s = scale.m_per_px;
    let lowest = measured
        .iter()
        .min_by(|a, b| {
            line.height_of(a.x_px, a.y_px)
                .total_cmp(&line.height_of(b.x_px, b.y_px))
        })
        .expect("measured frames");
    let frame = SurfaceFrame::on_line(line, lowest.x_px, lowest.y_px, track.downslope_negative_x, s);
    let points: Vec<Point> = measured
        .iter()
        .map(|f| {
            let (x, y) = frame.to_local(f.x_px, f.y_px);
            Point {
                frame: f.frame,
                t: f.t_s,
                x,
                y,
                sigma: f.sigma_px.max(MIN_SIGMA_PX) * s,
                clearance_px: y / s - scale.radius_px,
                r_px: f.r_px,
            }
        })
        .collect();
    (frame, points)
}

/// The contact: the run of points (first, last) around the lowest one within [`CLEARANCE_MARGIN_PX`] of the
/// surface `line`; an error when even the lowest is above it: the trajectory's own `no_impact` (a fall with
/// its speed) says more than the clearance, and a track that comes down and goes up again above the line
/// has an impact that its rim or the line misplaces. `m_per_px` is the scale.
fn contact_run(
    points: &[Point],
    no_impact: Option<EstimateError>,
    line: &SurfaceLine,
    m_per_px: f64,
) -> Result<(usize, usize), EstimateError> {
    let low = (0..points.len())
        .min_by(|&a, &b| points[a].clearance_px.total_cmp(&points[b].clearance_px))
        .expect("measured frames");
    let clearance_px = points[low].clearance_px;
    if clearance_px > CLEARANCE_MARGIN_PX {
        let heights: Vec<HeightPoint> = points
            .iter()
            .map(|p| HeightPoint {
                t: p.t,
                h: p.clearance_px,
                sigma: p.sigma / m_per_px,
            })
            .collect();
        // Only whether the track turns back is asked, so the fall speed's terms are not needed.
        let turns_back = find_impact(&heights, 0.0, 1.0).is_ok();
        return Err(match no_impact {
            Some(e) => e,
            None if turns_back => {
                let mut radii: Vec<f64> = points.iter().map(|p| p.r_px).filter(|r| r.is_finite()).collect();
                radii.sort_by(f64::total_cmp);
                let at = |q: f64| {
                    radii
                        .get((radii.len().saturating_sub(1) as f64 * q).round() as usize)
                        .copied()
                };
                EstimateError::TurnsAboveLine {
                    clearance_px,
                    line: line_phrase(line),
                    radius_lo_px: at(0.1).unwrap_or(f64::NAN),
                    radius_hi_px: at(0.9).unwrap_or(f64::NAN),
                }
            }
            None => EstimateError::NoContact { clearance_px },
        });
    }
    let near = |p: &Point| p.clearance_px <= CLEARANCE_MARGIN_PX;
    let (mut first, mut last) = (low, low);
    while first > 0 && near(&points[first - 1]) {
        first -= 1;
    }
    while last + 1 < points.len() && near(&points[last + 1]) {
        last += 1;
    }
    Ok((first, last))
}

/// What `line` is, as a phrase for a sentence.
fn line_phrase(line: &SurfaceLine) -> String {
    match line.cue {
        LineCue::Brightness | LineCue::Texture => format!("surface line found ({} cue)", line.cue.name()),
        LineCue::Given => "contact line given".to_string(),
        LineCue::Trajectory => "contact level from the ball's trajectory".to_string(),
    }
}

/// The flight points before and after the contact run (first, last), clear of the surface; an error when
/// either is too short to fit.
fn flights(points: &[Point], first: usize, last: usize) -> Result<(Vec<&Point>, Vec<&Point>), EstimateError> {
    let near = |p: &Point| p.clearance_px <= CLEARANCE_MARGIN_PX;
    let incoming: Vec<&Point> = points[..first].iter().filter(|p| !near(p)).collect();
    let outgoing: Vec<&Point> = points[last + 1..].iter().filter(|p| !near(p)).collect();
    for (phase, set, why) in [
        ("incoming", &incoming, "the clip starts too close to the impact"),
        ("outgoing", &outgoing, "the clip ends too close to the impact"),
    ] {
        if set.len() < MIN_FLIGHT_FRAMES {
            return Err(EstimateError::FlightTooShort {
                phase,
                frames: set.len(),
                needed: MIN_FLIGHT_FRAMES,
                why,
            });
        }
    }
    Ok((incoming, outgoing))
}

/// What "one radius above a line seen in the image" adds to the line's own error against the measured
/// centres, px: the scale's error at one radius (`radius` m) and the rim's unseen first harmonic, which
/// offsets every centre alike and so moves the contact as much as a level error (Type-B, like the radius's
/// rim term, with the limb's silhouette's offset from the fitted circles; see `Scale::centre_offset_px`).
fn against_centres_px(scale: &bouncelab_track::Scale, radius: f64) -> f64 {
    (radius / scale.m_per_px * scale.sigma_m_per_px / scale.m_per_px).hypot(scale.centre_offset_px())
}

/// The errors of the contact level and the frame's axes that every crossing shares.
struct LevelErrors {
    /// Uncertainty of "one radius above the surface line" in the local frame, m: all of it for this shot's
    /// errors (the line's scatter and its edge's definition as a uniform Type-B term, the scale's at one
    /// radius, and the rim's common offset of the centre).
    sigma: f64,
    /// Its shot-to-shot part, m, for a fit's per-shot level: without the Type-B terms that a surface's clips
    /// share (see `Estimate::surface_sigma_m`).
    sigma_scatter: f64,
    /// The tilt's standard error, rad: a turn of the axes by dθ moves v_n by v_t·dθ and v_t by v_n·dθ, in
    /// both flights alike.
    sigma_theta: f64,
    /// The scale's relative standard error.
    rel_scale: f64,
}

impl LevelErrors {
    /// The errors for a contact `line`, at the clip's `scale`, for a ball of `radius` m, with `share` of
    /// its level taken from the trajectory ([`Estimate::trajectory_share`]) and its error widened by
    /// `widened` ([`Estimate::level_se_scale`]).
    fn of(line: &SurfaceLine, scale: &bouncelab_track::Scale, radius: f64, share: f64, widened: f64) -> Self {
        let s = scale.m_per_px;
        // A level taken from the trajectory is where the centre was at the touch, one radius above a line put
        // one radius below it: the scale's error in that radius cancels, and so does an offset of the centre.
        let from_image = line.cue != LineCue::Trajectory;
        let radius_scale = if from_image { radius / s } else { 0.0 };
        let against_centres = if from_image {
            against_centres_px(scale, radius)
        } else {
            0.0
        };
        // Inverse-variance weights: the combined variance is the line's times its own weight, 1 − share.
        let sigma =
            line.level_sigma_px().hypot(against_centres) * s * (1.0 - share).clamp(0.0, 1.0).sqrt() * widened.max(1.0);
        let scatter_scale = (scale.sigma_m_per_px.powi(2) - scale.sigma_shape_m_per_px().powi(2))
            .max(0.0)
            .sqrt();
        // Left whole for a level partly from the trajectory: the fit that takes it as a prior sees the same
        // centres.
        let sigma_scatter = ((line.sigma_y0 * s).powi(2) + (radius_scale * scatter_scale).powi(2)).sqrt();
        LevelErrors {
            sigma,
            sigma_scatter,
            sigma_theta: line.sigma_tilt_deg.to_radians(),
            rel_scale: scale.sigma_m_per_px / s,
        }
    }
}

/// Per velocity component at a crossing: the value, the fit's error with the flight's `drift` (m/s, see
/// [`RadiusLine::centre_drift`]; for ratios, where the scale and the level's common part are propagated
/// separately), its derivative with the level, and the total error.
fn velocity_parts(f: &BallisticFit, c: &Crossing, level: &LevelErrors, drift: f64) -> [VelocityPart; 2] {
    let v = f.velocity(c.t.value);
    [0, 1].map(|k| {
        let (_, sv, _) = f.errors_at(k, c.t.value);
        let stat = (sv * sv + (f.a[k] * c.t.se).powi(2) + drift * drift).sqrt();
        let dv_dlevel = f.a[k] * c.dt_dlevel;
        let tilt = v[1 - k] * level.sigma_theta;
        let total =
            (stat * stat + (dv_dlevel * level.sigma).powi(2) + (v[k] * level.rel_scale).powi(2) + tilt * tilt).sqrt();
        VelocityPart {
            value: v[k],
            stat,
            dv_dlevel,
            total,
        }
    })
}

/// The coefficient of restitution |v_n,out / v_n,in| with its error: the fits', and the level's and the
/// tilt's, each common to both velocities.
fn restitution(vin: &[VelocityPart; 2], vout: &[VelocityPart; 2], level: &LevelErrors) -> Measured {
    let (sigma_level, sigma_theta) = (level.sigma, level.sigma_theta);
    let cor = (vout[1].value / vin[1].value).abs();
    let cor_level = cor * (vout[1].dv_dlevel / vout[1].value - vin[1].dv_dlevel / vin[1].value) * sigma_level;
    let cor_tilt = cor * (vout[0].value / vout[1].value - vin[0].value / vin[1].value) * sigma_theta;
    let cor_se = (cor * cor * ((vin[1].stat / vin[1].value).powi(2) + (vout[1].stat / vout[1].value).powi(2))
        + cor_level * cor_level
        + cor_tilt * cor_tilt)
        .sqrt();
    Measured::new(cor, cor_se)
}

/// The effective friction −Δv_t / Δv_n with its error, propagated as for [`restitution`].
fn friction(vin: &[VelocityPart; 2], vout: &[VelocityPart; 2], level: &LevelErrors) -> Measured {
    let (sigma_level, sigma_theta) = (level.sigma, level.sigma_theta);
    let (dvt, dvn) = (vout[0].value - vin[0].value, vout[1].value - vin[1].value);
    let mu = -dvt / dvn;
    let (ddvt, ddvn) = (
        vout[0].dv_dlevel - vin[0].dv_dlevel,
        vout[1].dv_dlevel - vin[1].dv_dlevel,
    );
    let mu_level = (-ddvt / dvn + dvt * ddvn / (dvn * dvn)) * sigma_level;
    let mu_tilt = (1.0 + mu * mu) * sigma_theta;
    let mu_se = ((vin[0].stat.powi(2) + vout[0].stat.powi(2)) / (dvn * dvn)
        + (dvt / (dvn * dvn)).powi(2) * (vin[1].stat.powi(2) + vout[1].stat.powi(2))
        + mu_level * mu_level
        + mu_tilt * mu_tilt)
        .sqrt();
    Measured::new(mu, mu_se)
}

/// A flag when the flights do not fall at gravity's rate on the `incline_deg` incline, a note when they are
/// too short to tell.
fn note_gravity(g: &GravityCheck, incline_deg: f64, gravity: f64, flags: &mut Vec<String>, notes: &mut Vec<String>) {
    let reversed = g.downslope_reversed(gravity);
    if !g.consistent || reversed {
        let why = if reversed {
            "the part along the surface has gravity's size but the other sign: the down-slope direction looks reversed (a mirrored camera?); set `downslope` under [camera] in the clip's clip.toml or the session.toml"
        } else {
            "a wrong frame rate, scale or incline, repeated frames, or not the ball"
        };
        flags.push(format!(
            "the ball's flight accelerates at ({:.2} ± {:.2}, {:.2} ± {:.2}) m/s² along and across the surface, not gravity's ({:.2}, {:.2}) on a {}° incline: {why}",
            g.measured[0].value,
            g.measured[0].se,
            g.measured[1].value,
            g.measured[1].se,
            g.expected[0],
            g.expected[1],
            incline_deg
        ));
    } else if g.inconclusive {
        notes.push(format!(
            "the flights are too short to check that the ball falls like a ball (acceleration {:.1} ± {:.1} m/s² across the surface)",
            g.measured[1].value, g.measured[1].se
        ));
    }
}

/// How level a camera set up by eye is, degrees: the tilt's standard error assumed for a frame on the image's
/// axes when the flights cannot bound it more tightly (`[surface] tilt_deg` or `--tilt` replaces the assumption).
pub const LEVEL_BY_EYE_DEG: f64 = 2.0;

/// The standard error of a frame whose tilt nothing in the image measured (the image's own axes), rad. The
/// flights' fall direction is the only evidence of it: the frame is known to within the angle between that
/// direction and gravity's on the incline, with that angle's own error. Short flights bound it loosely (3–64°
/// on the looks sweep), so the camera is taken as level by eye ([`LEVEL_BY_EYE_DEG`]) unless the fall shows
/// a clear turn, which then sets the error and gets a note.
fn unmeasured_tilt(g: &GravityCheck, notes: &mut Vec<String>) -> f64 {
    let off = g.frame_offset_rad();
    let bound = off.value.hypot(off.se);
    if off.value.abs() > 3.0 * off.se {
        notes.push(format!(
            "the flights fall {:.1} ± {:.1}° away from gravity's direction in the image's axes: the camera looks rolled; give the surface's tilt ([surface] tilt_deg or --tilt) to take the roll out",
            off.value.abs().to_degrees(),
            off.se.to_degrees()
        ));
        return bound;
    }
    bound.min(LEVEL_BY_EYE_DEG.to_radians())
}

/// A note for each flight scattering well beyond the tracker's σ (reduced χ² above 4), whose errors the fit
/// inflated.
fn note_scatter(fin: &BallisticFit, fout: &BallisticFit, notes: &mut Vec<String>) {
    for (name, f) in [("incoming", fin), ("outgoing", fout)] {
        let worst = f.chi2_red[0].max(f.chi2_red[1]);
        if worst > 4.0 {
            notes.push(format!(
                "{name} flight scatters {:.1}× more than the tracker's σ (reduced χ² {worst:.1}): errors inflated accordingly",
                worst.sqrt()
            ));
        }
    }
}

/// Largest scatter of a flight's centres about one free-fall arc, in ball radii, for them to follow one ball.
/// A tracker on the ball's rim places its centre to a small fraction of the radius even in heavy noise (at
/// most 0.030 r over the harder copies in `docs/accuracy.md`); a tenth of the radius is beyond any rim.
pub const FLIGHT_SCATTER_MAX_RADII: f64 = 0.1;

/// Least reduced χ² of that scatter against the tracker's σ for the flag: a tracker that reports its
/// centres as that uncertain (a small ball in heavy noise) has said so, and the errors carry it.
const FLIGHT_SCATTER_MIN_CHI2: f64 = 9.0;

/// Why the flights' centres are not one ball's, when a flight scatters more than
/// [`FLIGHT_SCATTER_MAX_RADII`] of the ball's radius (`radius_px`) about its own free-fall arc and far beyond
/// the tracker's σ: the track jumps between the ball and other objects, and nothing measured from it is
/// the ball's. `free_arcs` are the incoming and outgoing flights' fits, `m_per_px` the scale.
fn off_one_ball(free_arcs: &[Option<FreeArc>; 2], m_per_px: f64, radius_px: f64) -> Option<String> {
    let (name, rms_px) = ["incoming", "outgoing"]
        .into_iter()
        .zip(free_arcs)
        .filter_map(|(name, arc)| arc.as_ref().map(|a| (name, a.rms_m / m_per_px, a.chi2_red)))
        .filter(|&(_, rms_px, chi2_red)| {
            rms_px > FLIGHT_SCATTER_MAX_RADII * radius_px && chi2_red > FLIGHT_SCATTER_MIN_CHI2
        })
        .map(|(name, rms_px, _)| (name, rms_px))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(format!(
        "the {name} flight's centres scatter {rms_px:.1} px RMS about one free-fall arc ({:.2} of the ball's {radius_px:.1} px radius; {FLIGHT_SCATTER_MAX_RADII} at most for one ball): the track jumps between the ball and something else, and cannot tell the ball's bounce",
        rms_px / radius_px
    ))
}

/// Largest scatter of a flight's measured radius about a steady change, in ball radii, for the rim followed
/// to be the ball's silhouette. A rigid ball's outline changes in flight only as smoothly as its distance
/// or its light does; a rim read on the shading inside a dark limb, or on a seam, moves from frame to frame
/// as the noise and the felt do. Over `looks`, its 8 DN copy and the independent renderer's sessions and
/// their copies to 14 DN (`docs/accuracy.md`), tracks on the ball scatter at most 0.0053 r about such a
/// line; tracks on an edge inside the ball, 0.0133 and 0.0165 r.
pub const RIM_WANDER_MAX_RADII: f64 = 0.01;

/// Least ratio of that scatter to the tracker's median σ for the flag: a tracker that reports its fixes as
/// that uncertain has said so, and the errors carry it.
const RIM_WANDER_MIN_SIGMAS: f64 = 3.0;

/// Why the rim followed is not the ball's silhouette, when a flight's measured radius scatters more than
/// [`RIM_WANDER_MAX_RADII`] of the ball's radius (`radius_px`) about a line in time and more than
/// [`RIM_WANDER_MIN_SIGMAS`] of the tracker's σ: the centres of such a rim are offset from the ball's by an
/// amount that changes with it, and the velocities with them.
fn rim_wanders(lines: &(Option<RadiusLine>, Option<RadiusLine>), radius_px: f64) -> Option<String> {
    let (name, line) = [("incoming", &lines.0), ("outgoing", &lines.1)]
        .into_iter()
        .filter_map(|(name, l)| l.as_ref().map(|l| (name, l)))
        .filter(|(_, l)| l.rms_px > RIM_WANDER_MAX_RADII * radius_px && l.rms_px > RIM_WANDER_MIN_SIGMAS * l.sigma_px)
        .max_by(|a, b| a.1.rms_px.total_cmp(&b.1.rms_px))?;
    Some(format!(
        "the {name} flight's measured radius wanders {:.2} px RMS about a steady change ({:.3} of the ball's {radius_px:.1} px radius, {:.1}× the tracker's σ; {RIM_WANDER_MAX_RADII} at most for a ball's silhouette): the track follows an edge inside or around the ball that changes from frame to frame, so its centres are off the ball's by a changing amount",
        line.rms_px,
        line.rms_px / radius_px,
        line.rms_px / line.sigma_px
    ))
}

/// Share of a shot's measured frames whose rim may be saturated before the shot is flagged: a few frames
/// passing a hot spot bias a few centres, which the flight fits' scatter absorbs.
const SATURATED_FRAMES_SHARE: f64 = 0.05;

/// Why `track` cannot be trusted when more than `SATURATED_FRAMES_SHARE` (5 %) of its measured frames have the
/// ball's rim in saturated pixels (see [`Track::saturated_frames`]); `None` otherwise. A shot that fails
/// for another reason is best explained by this too, since clipping is usually the cause.
pub fn saturation_flag(track: &Track) -> Option<String> {
    let measured = track.fixes.iter().filter(|f| f.status.measured()).count();
    (track.saturated_frames > 0 && track.saturated_frames as f64 > SATURATED_FRAMES_SHARE * measured as f64).then(|| {
        format!(
            "the ball's rim is saturated in {} of {measured} measured frames (pixels at the file's full scale): its edge, centre and radius are biased there; lower the exposure or the gain",
            track.saturated_frames
        )
    })
}

/// What no bounce of a ball can give, each as a sentence: the ball must come in towards the surface and leave
/// it, with COR in [0, 1.05] (a little over 1 for the measurement's error), a contact of 0.1–50 ms that
/// starts before it ends, and |μ_eff| ≤ 1.5.
fn impossible(v_in_n: f64, v_out_n: f64, cor: f64, mu: f64, t_touch: f64, t_sep: f64) -> Vec<String> {
    let mut flags = Vec::new();
    if !(v_in_n < 0.0 && v_out_n > 0.0) {
        flags.push(format!(
            "the normal velocity is {v_in_n:.3} m/s in and {v_out_n:.3} m/s out: the ball does not come in and go out"
        ));
    }
    if !(0.0..=1.05).contains(&cor) {
        flags.push(format!("COR {cor:.3} is impossible (it lies in 0–1)"));
    }
    let contact_ms = (t_sep - t_touch) * 1e3;
    if !(0.1..=50.0).contains(&contact_ms) {
        flags.push(format!(
            "a contact of {contact_ms:.3} ms is impossible for a ball (0.1–50 ms)"
        ));
    }
    if mu.is_nan() || mu.abs() > 1.5 {
        flags.push(format!("μ_eff {mu:.3} is implausible (|μ_eff| ≤ 1.5)"));
    }
    flags
}

/// The flights fitted with their acceleration free (beyond what their rim's change explains, see
/// [`fit_free_acceleration_beyond_rim`]), weighted together, against gravity's `expected` (m/s², local
/// frame); `None` when neither flight has enough frames for a free fit.
fn gravity_check(falls: &[Option<FreeArc>; 2], expected: [f64; 2], g: f64) -> Option<GravityCheck> {
    let fits: Vec<[Measured; 2]> = falls
        .iter()
        .flatten()
        .map(|f| [0, 1].map(|k| Measured::new(f.a[k], f.se[k])))
        .collect();
    if fits.is_empty() {
        return None;
    }
    let measured = [0, 1].map(|k| {
        let w: f64 = fits.iter().map(|f| 1.0 / f[k].se.powi(2)).sum();
        let v = fits.iter().map(|f| f[k].value / f[k].se.powi(2)).sum::<f64>() / w;
        Measured::new(v, (1.0 / w).sqrt())
    });
    let consistent = (0..2).all(|k| (measured[k].value - expected[k]).abs() <= 4.0 * measured[k].se + 0.1 * g);
    let inconclusive = measured[1].se > 0.5 * g;
    Some(GravityCheck {
        measured,
        expected,
        consistent: consistent || inconclusive,
        inconclusive,
        sigma_frame_rad: 0.0,
    })
}

/// The contact line chosen, and what the choice rests on.
struct ContactChoice {
    line: SurfaceLine,
    /// The share of the line's level taken from the trajectory (see [`Estimate::trajectory_share`]).
    trajectory_share: f64,
    /// See [`Estimate::level_se_scale`].
    level_se_scale: f64,
    trajectory_level_px: Option<Measured>,
    notes: Vec<String>,
    /// The trajectory's [`EstimateError::NoImpact`], when it holds no impact.
    no_impact: Option<EstimateError>,
}

impl ContactChoice {
    /// `line` taken whole: none of its level from the trajectory and its error not widened (as when the
    /// line is given, or only one of the line and the trajectory is there).
    fn taken(
        line: SurfaceLine,
        trajectory_level_px: Option<Measured>,
        notes: Vec<String>,
        no_impact: Option<EstimateError>,
    ) -> ContactChoice {
        ContactChoice {
            line,
            trajectory_share: 0.0,
            level_se_scale: 1.0,
            trajectory_level_px,
            notes,
            no_impact,
        }
    }
}

/// Chooses the contact line (see [`estimate`]); `a_px` is gravity along the normal, px/s² (negative).
fn contact_line(
    track: &Track,
    measured: &[&bouncelab_track::BallFix],
    radius_px: f64,
    a_px: f64,
    surface_tilt_deg: Option<f64>,
    against_centres_px: f64,
) -> Result<ContactChoice, EstimateError> {
    let given = track.surface.filter(|l| l.cue == LineCue::Given);
    let found = track.surface.filter(|l| l.cue != LineCue::Given);
    let unseen = image_axis(measured, surface_tilt_deg);
    let unseen_text = match surface_tilt_deg {
        Some(t) => format!("the surface's tilt given ({t}°) is taken"),
        None => "the camera's roll is not measured, image axes are taken as the surface's".to_string(),
    };
    let view = TrajectoryView::along(track.surface.unwrap_or(unseen), track, measured, radius_px, a_px);
    let no_impact = match &view.trajectory {
        Err(EstimateError::NoImpact {
            frames,
            speed_m_s,
            se_m_s,
        }) => Some(EstimateError::NoImpact {
            frames: *frames,
            speed_m_s: *speed_m_s,
            se_m_s: *se_m_s,
        }),
        _ => None,
    };
    let mut notes = Vec::new();
    if let Some(line) = given {
        let trajectory_level_px = view.trajectory.as_ref().ok().map(|tc| view.relative(tc, &line));
        if let Some(m) = &trajectory_level_px
            && !view.agrees(m, &line)
        {
            notes.push(format!(
                "the given contact line is {:.1} ± {:.1} px from where the ball's trajectory puts the contact",
                m.value, m.se
            ));
        }
        return Ok(ContactChoice::taken(line, trajectory_level_px, notes, no_impact));
    }
    match (found, &view.trajectory) {
        (Some(line), Ok(tc)) => {
            let choice = view.found_or_trajectory(line, tc, &track.surface_alternatives, no_impact, against_centres_px);
            if choice.line.cue != LineCue::Trajectory {
                return Ok(choice);
            }
            // A line that is not where the ball lands is no evidence of the surface's direction either: the
            // level is taken as when no line is found.
            let across = TrajectoryView::along(unseen, track, measured, radius_px, a_px);
            Ok(match &across.trajectory {
                Ok(tc) => ContactChoice::taken(
                    across.level_line(tc),
                    Some(Measured::new(0.0, tc.level_se_px)),
                    [
                        choice.notes,
                        vec![format!("the rejected line's tilt is not used: {unseen_text}")],
                    ]
                    .concat(),
                    choice.no_impact,
                ),
                Err(_) => choice,
            })
        }
        (Some(line), Err(_)) => Ok(ContactChoice::taken(line, None, notes, no_impact)),
        (None, Ok(tc)) => {
            notes.push(format!(
                "no surface line found: the contact level comes from the ball's trajectory (± {:.2} px); {unseen_text}",
                tc.level_se_px
            ));
            notes.extend(tc.notes.iter().cloned());
            Ok(ContactChoice::taken(
                view.level_line(tc),
                Some(Measured::new(0.0, tc.level_se_px)),
                notes,
                no_impact,
            ))
        }
        (None, Err(e)) => Err(no_impact.unwrap_or_else(|| EstimateError::NoSurface { why: e.to_string() })),
    }
}

/// The ball's trajectory as evidence for the contact level: its heights along the best line known and the
/// contact they give.
struct TrajectoryView {
    /// The line the heights are measured from (image axes without one).
    axis: SurfaceLine,
    /// The ball's radius, px.
    radius_px: f64,
    /// Where the trajectory puts the contact, or why it cannot.
    trajectory: Result<TrajectoryContact, EstimateError>,
}

impl TrajectoryView {
    /// The trajectory seen along `axis`.
    fn along(
        axis: SurfaceLine,
        track: &Track,
        measured: &[&bouncelab_track::BallFix],
        radius_px: f64,
        a_px: f64,
    ) -> Self {
        let heights: Vec<HeightPoint> = measured
            .iter()
            .map(|f| HeightPoint {
                t: f.t_s,
                h: axis.height_of(f.x_px, f.y_px),
                sigma: f.sigma_px.max(MIN_SIGMA_PX),
            })
            .collect();
        let m_per_px = track.scale.map_or(f64::NAN, |s| s.m_per_px);
        let trajectory =
            find_impact(&heights, a_px, m_per_px).and_then(|low| trajectory_contact(&heights, low, a_px, radius_px));
        TrajectoryView {
            axis,
            radius_px,
            trajectory,
        }
    }

    /// The trajectory's level as a line: one radius below the centre at the touch, parallel to the axis.
    fn level_line(&self, tc: &TrajectoryContact) -> SurfaceLine {
        let axis = self.axis;
        SurfaceLine {
            y0: axis.y0 + (tc.level_px - self.radius_px) * -(1.0 + axis.slope * axis.slope).sqrt(),
            sigma_y0: tc.level_se_px,
            sigma_tilt_deg: axis.sigma_tilt_deg,
            columns: 0,
            edge_definition_px: 0.0,
            roughness_px: 0.0,
            cue: LineCue::Trajectory,
            level_shift_px: 0.0,
            ..axis
        }
    }

    /// How far the trajectory's level lies above `line`, px, with its standard error.
    fn relative(&self, tc: &TrajectoryContact, line: &SurfaceLine) -> Measured {
        let l = self.level_line(tc);
        let offset = (line.y0 - l.y0) / (1.0 + line.slope * line.slope).sqrt();
        Measured::new(offset, tc.level_se_px)
    }

    /// A line agrees with the trajectory when their levels differ by less than 3σ of both plus a pixel (or
    /// 3 % of the radius): gross disagreement means the line is not where the ball lands.
    fn agrees(&self, m: &Measured, line: &SurfaceLine) -> bool {
        m.value.abs() <= 3.0 * m.se.hypot(line.level_sigma_px()) + (0.03 * self.radius_px).max(1.0)
    }

    /// The line found when the trajectory agrees with it (or contradicts itself across it), else the first
    /// of the `alternatives` that agrees, else the trajectory's own level.
    fn found_or_trajectory(
        &self,
        line: SurfaceLine,
        tc: &TrajectoryContact,
        alternatives: &[SurfaceLine],
        no_impact: Option<EstimateError>,
        against_centres_px: f64,
    ) -> ContactChoice {
        let mut notes = Vec::new();
        let m = self.relative(tc, &line);
        // A trajectory whose touch and separation disagree (an arc it does not follow, such as a drag-slowed
        // flight) cannot overrule a line that lies between the two.
        let between = !tc.consistent
            && tc.separation.is_some_and(|(_, (sep, sep_se))| {
                let m_sep = m.value + (sep - tc.touch_level.0);
                let tol = 3.0 * m.se.hypot(sep_se) + (0.03 * self.radius_px).max(1.0);
                m.value.min(m_sep) - tol <= 0.0 && 0.0 <= m.value.max(m_sep) + tol
            });
        if between && let Some((_, (sep, sep_se))) = tc.separation {
            // Such an arc moves the touch and the separation opposite ways, so the trajectory's level is
            // taken half-way, uncertain by half their difference; it then weighs no more than that allows.
            let m_sep = m.value + (sep - tc.touch_level.0);
            let half_way = Measured::new(
                0.5 * (m.value + m_sep),
                (0.25 * (m.se * m.se + sep_se * sep_se) + (0.5 * (m.value - m_sep)).powi(2)).sqrt(),
            );
            notes.push(format!(
                "the ball's touch puts the contact {:.1} ± {:.1} px from the surface line found ({} cue) and its separation {:.1} ± {:.1} px, on either side of it within their errors: the trajectory contradicts itself, so its level is taken half-way ({:.1} ± {:.1} px) and weighed with the line's",
                m.value,
                m.se,
                line.cue.name(),
                m_sep,
                sep_se,
                half_way.value,
                half_way.se
            ));
            return self.combined(line, half_way, tc, notes, no_impact, against_centres_px);
        }
        if self.agrees(&m, &line) {
            return self.combined(line, m, tc, notes, no_impact, against_centres_px);
        }
        for alt in alternatives.iter().copied() {
            let ma = self.relative(tc, &alt);
            if self.agrees(&ma, &alt) {
                notes.push(format!(
                    "the first surface line found ({} cue, y = {:.1} px) is {:.1} px from where the ball lands; a lower line ({} cue, y = {:.1} px), which agrees with the ball's trajectory, is used",
                    line.cue.name(),
                    line.y0,
                    m.value,
                    alt.cue.name(),
                    alt.y0
                ));
                return self.combined(alt, ma, tc, notes, no_impact, against_centres_px);
            }
        }
        notes.push(format!(
            "the surface line found ({} cue, y = {:.1} px) is {:.1} px from where the ball's trajectory puts the contact: the contact level comes from the trajectory (± {:.2} px)",
            line.cue.name(),
            line.y0,
            m.value,
            tc.level_se_px
        ));
        notes.extend(tc.notes.iter().cloned());
        ContactChoice::taken(
            SurfaceLine {
                sigma_tilt_deg: line.sigma_tilt_deg,
                ..self.level_line(tc)
            },
            Some(Measured::new(0.0, tc.level_se_px)),
            notes,
            no_impact,
        )
    }

    /// A `line` seen in the image that the trajectory agrees with (`m`: the trajectory's level above it), its
    /// level moved towards the trajectory's by their inverse-variance weights: two measures of one level, the line's (with
    /// `against_centres_px`, what comparing it with the centres adds) and the touch's. On a ragged band the
    /// line's is a few px and the touch's a few tenths; on a clean step the line's is a few hundredths.
    fn combined(
        &self,
        line: SurfaceLine,
        m: Measured,
        tc: &TrajectoryContact,
        mut notes: Vec<String>,
        no_impact: Option<EstimateError>,
        against_centres_px: f64,
    ) -> ContactChoice {
        let var_line = line.level_sigma_px().hypot(against_centres_px).powi(2);
        let share = if var_line + m.se * m.se > 0.0 && m.se.is_finite() {
            var_line / (var_line + m.se * m.se)
        } else {
            0.0
        };
        // Two measures of one level further apart than their errors allow: one of the errors is too small,
        // and which cannot be told, so the mean's is widened by how far (the Birge ratio, one degree of
        // freedom).
        let apart = m.value.abs() / (var_line + m.se * m.se).sqrt();
        let level_se_scale = if apart.is_finite() { apart.max(1.0) } else { 1.0 };
        if level_se_scale >= NOTED_WIDENING {
            notes.push(format!(
                "the surface line ({} cue) and the ball's trajectory put the contact {:.1} px apart, {:.1} times their combined error: the contact level's error is widened {:.1}-fold",
                line.cue.name(),
                m.value.abs(),
                apart,
                level_se_scale
            ));
        }
        let line = SurfaceLine {
            y0: line.y0 - share * m.value * (1.0 + line.slope * line.slope).sqrt(),
            ..line
        };
        ContactChoice {
            line,
            trajectory_share: share,
            level_se_scale,
            trajectory_level_px: Some(self.relative(tc, &line)),
            notes,
            no_impact,
        }
    }
}

/// A widening of the contact level's error ([`Estimate::level_se_scale`]) from which a note says so: below
/// it, two measures about one standard error apart, as one pair in three is by chance.
const NOTED_WIDENING: f64 = 2.0;

/// The surface's direction when nothing in the image shows it: a line through the middle column the fixes
/// suggest, at the tilt given, else along the image's own axes.
fn image_axis(measured: &[&bouncelab_track::BallFix], tilt_deg: Option<f64>) -> SurfaceLine {
    SurfaceLine::given((track_width(measured) - 1.0) / 2.0, 0.0, tilt_deg.unwrap_or(0.0))
}

/// The image width the fixes suggest (for a reference column when no line is known), px.
fn track_width(measured: &[&bouncelab_track::BallFix]) -> f64 {
    let (lo, hi) = measured.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), f| {
        (lo.min(f.x_px), hi.max(f.x_px))
    });
    lo + hi + 1.0
}

/// When a flight arc crosses the contact level.
struct Crossing {
    /// The time, s, with the fit's standard error (the level taken as exact).
    t: Measured,
    /// How the time moves with the level, s/m (1 / the normal velocity there).
    dt_dlevel: f64,
}

/// One velocity component at a crossing, m/s.
#[derive(Clone, Copy)]
struct VelocityPart {
    value: f64,
    /// The flight's own standard error: the fit's (its timing included) and the rim's drift along it; the
    /// level's and scale's errors not.
    stat: f64,
    /// How the value moves with the contact level (the arc's acceleration × dt/dlevel), 1/s.
    dv_dlevel: f64,
    /// All errors: the fit's, the level's and the scale's.
    total: f64,
}

/// When the arc's height is `level` (the root nearest `near`), with the fit's standard error.
fn crossing(f: &BallisticFit, level: f64, near: f64) -> Crossing {
    // ½a·d² + v0·d + (p0 − level) = 0 in d = t − t_ref.
    let (a, b, c) = (0.5 * f.a[1], f.v0[1], f.p0[1] - level);
    let d_near = near - f.t_ref;
    let d = if a.abs() < 1e-12 {
        -c / b
    } else {
        let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
        let (r1, r2) = ((-b + disc) / (2.0 * a), (-b - disc) / (2.0 * a));
        if (r1 - d_near).abs() < (r2 - d_near).abs() {
            r1
        } else {
            r2
        }
    };
    let t = f.t_ref + d;
    let vy = f.velocity(t)[1];
    let vy = if vy.abs() < 1e-9 { 1e-9_f64.copysign(vy) } else { vy };
    let (sp, _, _) = f.errors_at(1, t);
    Crossing {
        t: Measured::new(t, sp / vy.abs()),
        dt_dlevel: 1.0 / vy,
    }
}

/// Time and depth of the lowest centre: a parabola through the frames around the lowest one.
fn deepest(contact: &[Point], radius: f64, sigma_level: f64, rel_scale: f64) -> (f64, Measured) {
    let k = contact
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.y.total_cmp(&b.1.y))
        .map(|(i, _)| i)
        .unwrap_or(0);
    let lo = k.saturating_sub(4);
    let hi = (k + 5).min(contact.len());
    let pts = &contact[lo..hi];
    let lowest = &contact[k];
    let scale_part = (radius - lowest.y).abs() * rel_scale;
    let fallback = (
        lowest.t,
        Measured::new(
            radius - lowest.y,
            (lowest.sigma.powi(2) + sigma_level.powi(2) + scale_part.powi(2)).sqrt(),
        ),
    );
    if pts.len() < 5 {
        return fallback;
    }
    // Least-squares parabola y = c0 + c1·d + c2·d² in d = t − t_k.
    let t0 = lowest.t;
    let mut m = [[0.0f64; 3]; 3];
    let mut v = [0.0f64; 3];
    for p in pts {
        let d = p.t - t0;
        let basis = [1.0, d, d * d];
        for i in 0..3 {
            v[i] += basis[i] * p.y;
            for j in 0..3 {
                m[i][j] += basis[i] * basis[j];
            }
        }
    }
    let Some(c) = solve3(m, v) else { return fallback };
    if c[2] <= 0.0 {
        return fallback;
    }
    let d_min = (-c[1] / (2.0 * c[2])).clamp(pts[0].t - t0, pts[pts.len() - 1].t - t0);
    let y_min = c[0] + c[1] * d_min + c[2] * d_min * d_min;
    let sigma_fit = lowest.sigma / (pts.len() as f64 / 3.0).sqrt();
    (
        t0 + d_min,
        Measured::new(
            radius - y_min,
            (sigma_fit.powi(2) + sigma_level.powi(2) + scale_part.powi(2)).sqrt(),
        ),
    )
}

fn solve3(mut m: [[f64; 3]; 3], mut v: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[piv][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, piv);
        v.swap(col, piv);
        for r in 0..3 {
            if r != col {
                let f = m[r][col] / m[col][col];
                let pivot = m[col];
                for (x, p) in m[r].iter_mut().zip(pivot) {
                    *x -= f * p;
                }
                v[r] -= f * v[col];
            }
        }
    }
    Some([v[0] / m[0][0], v[1] / m[1][1], v[2] / m[2][2]])
}
