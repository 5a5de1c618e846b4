//! A whole clip: find the ball, track it through every frame, measure the scale and the surface line, and
//! put the centres in the local frame (`docs/outputs.md`).
//!
//! Frames are decoded in parallel by the frames crate's stream while this thread tracks them in order, so
//! tracking hides behind decoding. When the ball's size in pixels is not known, the ball is told from other
//! round things (screw heads, fixtures, a second ball at rest) by its motion: it is the circle that moved
//! between two frames.
//!
//! Tracking is symmetric in time, and one pass is no single point of failure: frames before the ball is
//! first sighted, or before the track first settles, are tracked again backward from there; and a track that
//! steps further than the ball can move (it left the ball for noise or texture, as after a bounce in heavy
//! noise) is taken over by a pass tracked back from the clip's end, when that pass meets it on the ball
//! before the step and holds the clearer circles after it.

use crate::acquire::Sighting;
use crate::local::SurfaceFrame;
use crate::plane::{Pixel, Plane};
use crate::realign::{HALF_WINDOW, NeighbourRims, profiles_along};
use crate::refine::{EdgeSearch, NOISY_SIGMA};
use crate::surface::SurfaceLine;
use crate::tracker::{BallFix, CLEAN_QUALITY, MAX_BALL_ACCELERATION_M_S2, Status, TrackOptions, Tracker};
use crate::trajectory::TrajectoryRow;
use bouncelab_frames::{CameraInfo, Clip, ClipSettings, ContactLine, Frame, FramesError, GrayPixels, ReadOptions, Roi};
use serde::Serialize;
use std::time::Instant;

/// Errors of clip tracking.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TrackError {
    /// Reading a frame failed.
    #[error(transparent)]
    Frames(#[from] FramesError),
    /// The ball was not found anywhere in the clip.
    #[error("{clip}: no ball found in any frame (looked for circles of radius {min_radius:.0}–{max_radius:.0} px)")]
    NoBall {
        clip: String,
        min_radius: f64,
        max_radius: f64,
    },
    /// Round things were seen but none moved: static objects are never taken for the ball.
    #[error(
        "{clip}: no moving ball: the circles seen ({circles}) stay where they are between frames, so none is a ball in flight (give the scale if the ball is in view but not found)"
    )]
    NothingMoves { clip: String, circles: String },
    /// No ball was found, and the first frame is mostly clipped: at the file's full scale or at zero.
    #[error(
        "{clip}: no ball found: {percent:.1} % of the first frame's pixels are {level} (an exposure or a gain far off, a lens cap, or a conversion that clipped the levels)"
    )]
    Clipped {
        clip: String,
        percent: f64,
        level: &'static str,
    },
}

/// Options of [`track_clip`].
#[derive(Debug, Clone)]
pub struct ClipTracking {
    /// Ball diameter, m (sets the scale).
    pub ball_diameter_m: f64,
    /// Approximate scale, m/px, if known (narrows the search); found from the ball's motion otherwise.
    pub scale_hint_m_per_px: Option<f64>,
    /// True if down-slope is −x in the image (`downslope = "-x"`, `docs/session.md`).
    pub downslope_negative_x: bool,
    /// Frame decoding.
    pub read: ReadOptions,
    /// Tracker settings.
    pub tracker: TrackOptions,
    /// Only this part of each frame is searched (the ball, the surface line); results stay in the whole
    /// frame's pixels. `None`: the whole frame.
    pub roi: Option<Roi>,
    /// The contact line the user gives (y at the frame's centre column, tilt): used instead of one found in
    /// the image. `None`: found.
    pub contact_line: Option<ContactLine>,
}

impl Default for ClipTracking {
    fn default() -> Self {
        ClipTracking {
            ball_diameter_m: 0.067,
            scale_hint_m_per_px: None,
            downslope_negative_x: false,
            read: ReadOptions::default(),
            tracker: TrackOptions::default(),
            roi: None,
            contact_line: None,
        }
    }
}

impl ClipTracking {
    /// Options that follow a clip's resolved settings (diameter, scale, region of interest, contact line;
    /// `docs/session.md`), everything else default.
    pub fn for_settings(settings: &ClipSettings, downslope_negative_x: bool) -> Self {
        ClipTracking {
            ball_diameter_m: settings.ball_diameter_m,
            scale_hint_m_per_px: settings.scale_m_per_px,
            downslope_negative_x,
            roi: settings.roi,
            contact_line: settings.contact_line,
            ..ClipTracking::default()
        }
    }
}

/// The clip's scale from the ball's radius in free flight.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Scale {
    /// Metres per pixel.
    pub m_per_px: f64,
    /// Its standard error, m/px.
    pub sigma_m_per_px: f64,
    /// The rim shape's RMS, px (see `scale_from`): the Type-B standard uncertainty of the radius, and of
    /// the centre's offset common to every frame, which moves the ball's lowest point as the radius does.
    pub rim_shape_px: f64,
    /// How far the limb's silhouette lay from the fitted circles' centres, px (see [`crate::LimbOffset`]),
    /// before the track's circles were moved onto it: the standard uncertainty of that correction of the
    /// centre's common offset. 0 when not measured.
    pub limb_centre_px: f64,
    /// How far it lay outside their radius, px: the standard uncertainty of that correction of the radius.
    /// 0 when not measured.
    pub limb_radius_px: f64,
    /// Mean free-flight radius, px.
    pub radius_px: f64,
    /// Frames it was measured on.
    pub frames: usize,
}

impl Scale {
    /// The part of `sigma_m_per_px` that is the rim shape's Type-B term, m/px (see `scale_from`): lighting
    /// that is the same for every clip of a session gives every clip about the same radius bias, so it is
    /// not a shot-to-shot scatter.
    pub fn sigma_shape_m_per_px(&self) -> f64 {
        self.m_per_px * self.rim_shape_px.hypot(self.limb_radius_px) / self.radius_px
    }

    /// The standard uncertainty of the offset every centre shares, px: the rim shape's and the limb's.
    pub fn centre_offset_px(&self) -> f64 {
        self.rim_shape_px.hypot(self.limb_centre_px)
    }
}

/// A tracked clip.
#[derive(Debug, Clone)]
pub struct Track {
    /// One fix per decoded frame, in order.
    pub fixes: Vec<BallFix>,
    /// The surface line: found by one of its cues, or given by the user; `None` when neither.
    pub surface: Option<SurfaceLine>,
    /// The other candidate lines below the ball, topmost first (the estimator chooses by the ball's
    /// trajectory).
    pub surface_alternatives: Vec<SurfaceLine>,
    /// The scale, if the ball was measured in free flight.
    pub scale: Option<Scale>,
    /// Things a person should know, each naming its frame.
    pub warnings: Vec<String>,
    /// Seconds spent decoding (wall time waiting for frames) and tracking.
    pub seconds_waiting: f64,
    /// Seconds spent tracking.
    pub seconds_tracking: f64,
    /// True if down-slope is −x in the image.
    pub downslope_negative_x: bool,
    /// What the clip's camera file header says (model, rate, exposure, bit depth, trigger); for a folder of
    /// images only its format.
    pub camera: CameraInfo,
    /// Measured frames whose rim lies in saturated pixels (at the file's full scale).
    pub saturated_frames: usize,
}

impl Track {
    /// The local frame on the surface line (origin at the foot of the perpendicular from the lowest measured
    /// centre, axes along the line and its normal), when both the line and the scale are known.
    pub fn surface_frame(&self) -> Option<SurfaceFrame> {
        let (line, scale) = (self.surface.as_ref()?, self.scale.as_ref()?);
        let lowest = self.fixes.iter().filter(|f| f.status.measured()).min_by(|a, b| {
            line.height_of(a.x_px, a.y_px)
                .total_cmp(&line.height_of(b.x_px, b.y_px))
        })?;
        Some(SurfaceFrame::on_line(
            line,
            lowest.x_px,
            lowest.y_px,
            self.downslope_negative_x,
            scale.m_per_px,
        ))
    }

    /// The rows of `trajectories/<clip>.csv` in the frame on the surface line ([`Track::surface_frame`]).
    pub fn rows(&self) -> Vec<TrajectoryRow> {
        self.rows_in(self.surface_frame().as_ref())
    }

    /// The rows of `trajectories/<clip>.csv`: pixels, and the local frame `frame` where given (NaN metres
    /// otherwise and in frames where the ball was not measured).
    pub fn rows_in(&self, frame: Option<&SurfaceFrame>) -> Vec<TrajectoryRow> {
        self.fixes
            .iter()
            .map(|f| {
                let (x_m, y_m) = match frame {
                    Some(fr) if f.status.measured() => fr.to_local(f.x_px, f.y_px),
                    _ => (f64::NAN, f64::NAN),
                };
                TrajectoryRow { fix: *f, x_m, y_m }
            })
            .collect()
    }
}

/// The frame cut to `roi` (whole when `None`). Cost: a copy of the region.
pub(crate) fn in_region(frame: Frame, roi: Option<&Roi>) -> Frame {
    let Some(r) = roi else {
        return frame;
    };
    use imageproc::image::imageops::crop_imm;
    let pixels = match &frame.pixels {
        GrayPixels::U8(img) => GrayPixels::U8(crop_imm(img, r.x, r.y, r.width, r.height).to_image()),
        GrayPixels::U16(img) => GrayPixels::U16(crop_imm(img, r.x, r.y, r.width, r.height).to_image()),
    };
    Frame { pixels, ..frame }
}

/// Runs `f` on the frame's pixels as a plane with `gain` (see [`crate::plane::level_gain`]).
pub(crate) fn with_plane<R>(px: &GrayPixels, gain: f32, f: impl FnOnce(PlaneRef<'_>) -> R) -> R {
    let (w, h) = (px.width() as usize, px.height() as usize);
    match px {
        GrayPixels::U8(img) => f(PlaneRef::U8(Plane::new(img.as_raw(), w, h).with_gain(gain))),
        GrayPixels::U16(img) => f(PlaneRef::U16(Plane::new(img.as_raw(), w, h).with_gain(gain))),
    }
}

/// A plane of either bit depth.
pub(crate) enum PlaneRef<'a> {
    U8(Plane<'a, u8>),
    U16(Plane<'a, u16>),
}

/// Runs `$body` with `$v` bound to the plane, whatever its bit depth.
macro_rules! on_plane {
    ($p:expr, $v:ident => $body:expr) => {
        match $p {
            $crate::clip::PlaneRef::U8($v) => $body,
            $crate::clip::PlaneRef::U16($v) => $body,
        }
    };
}
pub(crate) use on_plane;

/// Tracks the ball through `clip`. `progress` is called with (frames done, frames total).
pub fn track_clip(
    clip: &Clip,
    opts: &ClipTracking,
    mut progress: impl FnMut(usize, usize),
) -> Result<Track, TrackError> {
    let mut warnings = Vec::new();
    // The stream starts decoding at once, so its first frames are ready when acquisition is done.
    let frames = clip.frames_with(&opts.read)?;
    let (opts, gain, noise) = first_frame_levels(clip, opts, &mut warnings)?;
    let opts = &for_noise(&opts, noise);
    if gain >= 2.0 {
        warnings.push(format!(
            "the frames use little of their gray scale: levels stretched {gain:.1}× for the ball and line searches"
        ));
    }
    let crate::acquire::Acquired {
        radius,
        seed,
        file: seed_file,
        second,
    } = crate::acquire::acquire(clip, opts, gain, noise).map_err(|e| clipped_instead(e, clip, opts))?;
    if let Some((frame, x, y)) = second {
        warnings.push(format!(
            "a second moving ball-like circle at ({x:.0}, {y:.0}) in frame {frame}: tracking the clearer one, at ({:.0}, {:.0}) then (crop with --roi if that is the wrong one)",
            seed.0.1, seed.0.2
        ));
    }
    // A ball first seen after the clip's first frames is followed back to its start from there: the
    // forward track then begins from where it was, not from its sightings extrapolated back.
    let given = given_line(clip, opts);
    let mut backward = Backward {
        clip,
        opts,
        gain,
        radius,
        surface: given,
    };
    let (early, early_radius) = backward.before_seed(seed, seed_file)?;
    let (a, b) = forward_seed(&early, seed);
    let seeded = || {
        let mut tracker = Tracker::new(TrackOptions {
            radius_px: Some(radius),
            ..opts.tracker.clone()
        });
        tracker.seed(a, b);
        if let Some(r) = early_radius {
            tracker.expect_radius(r);
        }
        tracker
    };
    let mut tracker = seeded();
    if let Some(line) = given {
        tracker.set_surface(line);
    }
    let mut forward = track_forward(frames, clip.len(), opts.roi, gain, &mut tracker, &mut progress)?;
    let mut alternatives = tracker.surface_alternatives().to_vec();
    if given.is_none()
        && let Some(line) = tracker.surface().copied()
        && let Some(seen) = ball_in_front(clip, opts, gain, &forward.fixes, &line)?
    {
        let mut rest = alternatives.into_iter();
        let mut surface = None;
        for alt in rest.by_ref() {
            if ball_in_front(clip, opts, gain, &forward.fixes, &alt)?.is_none() {
                surface = Some(alt);
                break;
            }
        }
        alternatives = rest.collect();
        warnings.push(format!(
            "the line found at y = {:.1} px is not the surface: the ball passes in front of it (its rim goes on {:.0} px below it in {} of {} frames searched); {}",
            line.y0 + roi_origin(opts.roi.as_ref()).1,
            seen.deepest_px,
            seen.seen,
            seen.frames,
            match &surface {
                Some(l) => format!("tracked again on the line below it, at y = {:.1} px", l.y0 + roi_origin(opts.roi.as_ref()).1),
                None => "tracked again without a surface line".to_string(),
            }
        ));
        tracker = seeded();
        match surface {
            Some(line) => tracker.set_surface(line),
            None => tracker.forgo_surface(),
        }
        forward = track_forward(
            clip.frames_with(&opts.read)?,
            clip.len(),
            opts.roi,
            gain,
            &mut tracker,
            &mut progress,
        )?;
    }
    warnings.extend(tracker.warnings().iter().cloned());
    let mut fixes = forward.fixes;
    for (fix, old) in early.into_iter().zip(fixes.iter_mut()) {
        if fix.status.measured() && clearer(&fix, old) {
            *old = fix;
        }
    }
    backward.surface = tracker.surface().copied();
    backward.retrack_start(&mut fixes, &mut warnings)?;
    let doubtful = backward.retrack_end(&mut fixes, noise, &mut warnings)?;
    if doubtful.is_none() {
        backward.retrack_after_lost_rim(&mut fixes, &tracker, noise, &mut warnings)?;
    }
    let remeasured = backward.retrack_bounce(&mut fixes, &tracker, &mut warnings)?;
    if let Some(doubt) = doubtful {
        let off = fixes[doubt.at].frame;
        if doubt.settled_by(remeasured, &fixes, 0.5 * (radius.0 + radius.1)) {
            warnings.push(format!(
                "{}; the frames from the bounce, measured again backward from the clean flight after it, join the track without a step the ball cannot make: the frames from {off} on are kept",
                doubt.said
            ));
        } else {
            warnings.push(format!("{}: frames from {off} on may not be the ball", doubt.said));
            let n = doubt_from(&mut fixes, doubt.at);
            warnings.push(format!(
                "{n} measured frame(s) from frame {off} on marked ambiguous: they may not be the ball"
            ));
        }
    }
    mark_off_path(&mut fixes, opts.ball_diameter_m, &mut warnings);
    let measured = fixes.iter().filter(|f| f.status.measured()).count();
    if forward.saturated > 0 {
        warnings.push(format!(
            "the ball's rim is saturated (pixels at the file's full scale) in {} of {measured} measured frames: its edge, and so the centre and radius there, are biased; lower the exposure or the gain",
            forward.saturated
        ));
    }
    if measured == 0 {
        return Err(TrackError::NoBall {
            clip: clip.dir().display().to_string(),
            min_radius: radius.0,
            max_radius: radius.1,
        });
    }
    let absent = fixes.iter().filter(|f| f.status == Status::Absent).count();
    if absent > 0 {
        warnings.push(format!("ball not found in {absent} of {} frames", fixes.len()));
    }
    remeasure_on_neighbours(clip, opts, gain, &mut fixes, tracker.surface())?;
    let limb = tracker.limb_offset();
    if let Some(l) = limb {
        to_silhouette(&mut fixes, &l);
    }
    let scale = scale_from(
        &fixes,
        tracker.surface(),
        opts.ball_diameter_m,
        tracker.edge_definition_px(),
        tracker.rim_shape_rms_px(),
        limb,
    );
    let (ox, oy) = roi_origin(opts.roi.as_ref());
    // Back to the whole frame's pixels.
    for f in &mut fixes {
        f.x_px += ox;
        f.y_px += oy;
    }
    let whole = |l: &SurfaceLine| SurfaceLine {
        x0: l.x0 + ox,
        y0: l.y0 + oy,
        ..*l
    };
    Ok(Track {
        fixes,
        surface: tracker.surface().map(whole),
        surface_alternatives: alternatives.iter().map(whole).collect(),
        scale,
        warnings,
        seconds_waiting: forward.seconds_waiting,
        seconds_tracking: forward.seconds_tracking,
        downslope_negative_x: opts.downslope_negative_x,
        camera: clip.camera().clone(),
        saturated_frames: forward.saturated,
    })
}

/// Measures every measured circle again against its neighbours' mean rim ([`NeighbourRims`]) in one more
/// pass over the clip's frames: each frame's profiles across the rim are taken along its circle (rays clear
/// of the surface band and inside the image), the `ok` frames teach their neighbours' templates, and each
/// measured frame's circle moves by its slides onto its own template where enough rays allow. The circles'
/// standard errors stay the edge search's: a moved circle shares its neighbours' mean circle, whose error
/// runs smoothly over the window, so a flight's fit takes it for motion, not scatter (stated as the
/// slides' own, the trajectory's contact levels read 1.3 of their standard errors on the `looks` sweep).
fn remeasure_on_neighbours(
    clip: &Clip,
    opts: &ClipTracking,
    gain: f32,
    fixes: &mut [BallFix],
    surface: Option<&SurfaceLine>,
) -> Result<(), TrackError> {
    let rays = opts.tracker.search.rays.max(8);
    let mut rims = NeighbourRims::new(rays);
    let mut moved = Vec::new();
    // Decoded ahead on the stream's threads, as for the forward pass.
    let mut frames = clip.frames_with(&opts.read)?;
    // Frame `next` is measured once every frame up to `HALF_WINDOW` after it was pushed.
    let (mut k, mut next) = (0, 0);
    while let Some(frame) = frames.next() {
        let frame = frame?;
        if let Some(f) = fixes.get(k).filter(|f| f.status.measured()) {
            // Only a region is copied; a whole frame is read where it lies.
            let cut;
            let image = match opts.roi {
                Some(r) => {
                    cut = in_region(frame.clone(), Some(&r));
                    &cut
                }
                None => &frame,
            };
            let profiles = with_plane(
                &image.pixels,
                gain,
                |p| on_plane!(p, p => profiles_along(&p, (f.x_px, f.y_px, f.r_px), rays, surface)),
            );
            rims.push(k, profiles, f.status == Status::Ok);
        }
        frames.recycle(frame);
        while next + HALF_WINDOW <= k && next < fixes.len() {
            moved.push((next, rims.realign(next)));
            next += 1;
        }
        k += 1;
    }
    for j in next..fixes.len() {
        moved.push((j, rims.realign(j)));
    }
    for (j, m) in moved {
        if let Some(m) = m {
            let f = &mut fixes[j];
            f.x_px += m.dx;
            f.y_px += m.dy;
            f.r_px += m.dr;
        }
    }
    Ok(())
}

/// Whether the forward track's ball is seen in front of `line` ([`crate::in_front`]): the frames where it
/// reaches deepest below the line are read again and their rims searched round.
fn ball_in_front(
    clip: &Clip,
    opts: &ClipTracking,
    gain: f32,
    fixes: &[BallFix],
    line: &SurfaceLine,
) -> Result<Option<crate::in_front::InFront>, TrackError> {
    let search = &opts.tracker.search;
    crate::in_front::ball_in_front_of(line, fixes, search, |k, f| {
        let Some(frame) = clip.read(k, opts.read.png_decoder) else {
            return Ok(None);
        };
        let image = in_region(frame?, opts.roi.as_ref());
        let depth = crate::in_front::band_depth_px(f.r_px);
        Ok(Some(with_plane(
            &image.pixels,
            gain,
            |p| on_plane!(p, p => crate::refine::rim_about_line(&p, (f.x_px, f.y_px, f.r_px), search, line, depth)),
        )))
    })
}

/// Moves every measured circle onto the limb's silhouette (see [`LimbOffset`](crate::LimbOffset)): its
/// centre by the silhouette's first harmonic and its radius by their mean. Frames whose rim is partly hidden
/// were measured on the same rim as in flight (the learned [`RimShape`](crate::RimShape)), so one shift
/// serves them all.
fn to_silhouette(fixes: &mut [BallFix], limb: &crate::LimbOffset) {
    for f in fixes.iter_mut().filter(|f| f.status.measured()) {
        f.x_px += limb.centre_px.0;
        f.y_px += limb.centre_px.1;
        f.r_px += limb.radius_px;
    }
}

/// Marks `ambiguous` the measured fixes the ball cannot have been at ([`crate::path::off_path`]: off the
/// path their neighbours give by more than the ball strays, by [`MAX_BALL_ACCELERATION_M_S2`] at the scale
/// of the fixes' median radius and the ball's `diameter_m`, or by its own speed in the track), and says
/// which.
fn mark_off_path(fixes: &mut [BallFix], diameter_m: f64, warnings: &mut Vec<String>) {
    let mut radii: Vec<f64> = fixes.iter().filter(|f| f.status.measured()).map(|f| f.r_px).collect();
    if radii.is_empty() || diameter_m <= 0.0 {
        return;
    }
    let px_per_m = 2.0 * crate::plane::median(&mut radii) / diameter_m;
    let mut off = crate::path::off_path(fixes, MAX_BALL_ACCELERATION_M_S2 * px_per_m);
    if off.is_empty() {
        return;
    }
    off.sort_by_key(|o| o.index);
    let listed: Vec<String> = off
        .iter()
        .take(5)
        .map(|o| {
            format!(
                "{} ({:.1} px off, {:.1} px possible)",
                fixes[o.index].frame, o.off_px, o.allowed_px
            )
        })
        .collect();
    let more = if off.len() > listed.len() { ", …" } else { "" };
    for o in &off {
        fixes[o.index].status = Status::Ambiguous;
    }
    warnings.push(format!(
        "{} measured frame(s) off the path the frames around them give, further than the ball can stray there: frame(s) {}{more}: marked ambiguous, not the ball",
        off.len(),
        listed.join(", ")
    ));
}

/// The first frame's (searched region's) level gain ([`crate::plane::level_gain`]) and sensor noise σ
/// (0–255 scale) at that gain, with the options that search it: the region of interest set to the picture
/// inside a border that holds none ([`picture_inside_border`]), when the user gave no region; (1, 0) for an
/// empty clip. One decode of the first frame, and of [`STEADY_SAMPLES`] more when it may have a bar.
fn first_frame_levels(
    clip: &Clip,
    opts: &ClipTracking,
    warnings: &mut Vec<String>,
) -> Result<(ClipTracking, f32, f32), TrackError> {
    let Some(first) = clip.read(0, opts.read.png_decoder) else {
        return Ok((opts.clone(), 1.0, 0.0));
    };
    let first = in_region(first?, opts.roi.as_ref());
    let (gain, noise) = levels(&first.pixels);
    if opts.roi.is_some() || noise < MIN_NOISE_FOR_BORDER {
        return Ok((opts.clone(), gain, noise));
    }
    let steady = steady_lines(clip, opts, &first.pixels);
    let Some(roi) = picture_inside_border(&first.pixels, gain, steady.as_ref(), warnings) else {
        return Ok((opts.clone(), gain, noise));
    };
    let (gain, noise) = levels(&in_region(first, Some(&roi)).pixels);
    let opts = ClipTracking {
        roi: Some(roi),
        ..opts.clone()
    };
    Ok((opts, gain, noise))
}

/// The level gain of `pixels` and their sensor noise at that gain.
fn levels(pixels: &GrayPixels) -> (f32, f32) {
    let gain = with_plane(pixels, 1.0, |p| on_plane!(p, p => crate::plane::level_gain(&p)));
    let noise = with_plane(pixels, gain, |p| on_plane!(p, p => crate::plane::noise_sigma(&p)));
    (gain, noise)
}

/// Sensor noise σ (0–255 scale) below which a frame's repeated or one-level outer rows and columns are
/// not taken for a border ([`crate::border::picture_box`]): a noiseless render's smooth margins repeat too.
const MIN_NOISE_FOR_BORDER: f32 = 0.5;

/// Least width and height of a picture inside a border, px: a smaller one is not taken for the picture.
const MIN_PICTURE_PX: usize = 32;

/// Frames looked at through the clip, besides the first, before a row or column of one level is taken for
/// a bar ([`crate::border::SteadyLines`]): a clipped field the ball crosses changes in some of them.
const STEADY_SAMPLES: usize = 16;

/// The rows and columns of one level throughout in `first` (the clip's first frame) and in
/// [`STEADY_SAMPLES`] frames spread evenly over the rest of the clip; `None` when `first` cannot have a
/// pair of bars (its opposite edges not both of one level) or the clip has no other frame. A frame that
/// fails to decode is passed over: the track reports it when it gets there.
fn steady_lines(clip: &Clip, opts: &ClipTracking, first: &GrayPixels) -> Option<crate::border::SteadyLines> {
    let of = |px: &GrayPixels| with_plane(px, 1.0, |p| on_plane!(p, p => crate::border::SteadyLines::of(&p)));
    let mut steady = of(first);
    let n = clip.len();
    if !steady.may_have_bars() || n < 2 {
        return None;
    }
    let samples = STEADY_SAMPLES.min(n - 1);
    for k in 1..=samples {
        let index = k * (n - 1) / samples;
        if let Some(Ok(frame)) = clip.read(index, opts.read.png_decoder) {
            steady.and(&of(&frame.pixels));
        }
        if !steady.may_have_bars() {
            return None;
        }
    }
    Some(steady)
}

/// The picture inside a border that holds none ([`crate::border::picture_box`]: edges padded by repeating
/// the frame's, or bars of one level in every frame of `steady`), as a region of interest, when the frame
/// (whose sensor noise shows that such lines cannot be the scene's) has one; a warning says so. The track's
/// results stay in the whole frame's pixels, as with a region given.
fn picture_inside_border(
    pixels: &GrayPixels,
    gain: f32,
    steady: Option<&crate::border::SteadyLines>,
    warnings: &mut Vec<String>,
) -> Option<Roi> {
    let (w, h) = (pixels.width() as usize, pixels.height() as usize);
    let (x, y, bw, bh) = with_plane(
        pixels,
        gain,
        |p| on_plane!(p, p => crate::border::picture_box(&p, steady)),
    );
    if (bw, bh) == (w, h) || bw.min(bh) < MIN_PICTURE_PX {
        return None;
    }
    warnings.push(format!(
        "the frames have a border with no picture in it (repeated edges or bars of one level): left {x}, right {}, top {y}, bottom {} px; only the picture inside is searched (--roi chooses another region)",
        w - x - bw,
        h - y - bh
    ));
    Some(Roi {
        x: x as u32,
        y: y as u32,
        width: bw as u32,
        height: bh as u32,
    })
}

/// The options with the ball's diameter given to the tracker and, in heavy sensor noise (a ray's largest
/// step as often a noise spike as the rim), the rays sampled smoothed.
fn for_noise(opts: &ClipTracking, noise: f32) -> ClipTracking {
    ClipTracking {
        tracker: TrackOptions {
            ball_diameter_m: Some(opts.ball_diameter_m),
            search: EdgeSearch {
                smooth: opts.tracker.search.smooth || noise > NOISY_SIGMA,
                ..opts.tracker.search.clone()
            },
            ..opts.tracker.clone()
        },
        ..opts.clone()
    }
}

/// The region of interest's top-left corner in the whole frame, px ((0, 0) without one).
fn roi_origin(roi: Option<&Roi>) -> (f64, f64) {
    roi.map_or((0.0, 0.0), |r| (r.x as f64, r.y as f64))
}

/// The contact line the user gives, in the searched region's pixels.
fn given_line(clip: &Clip, opts: &ClipTracking) -> Option<SurfaceLine> {
    let (w, _) = clip.dimensions();
    let (ox, oy) = roi_origin(opts.roi.as_ref());
    opts.contact_line
        .map(|l| SurfaceLine::given((w as f64 - 1.0) / 2.0 - ox, l.y_px - oy, l.tilt_deg))
}

/// What the forward pass over the clip measured.
struct Forward {
    /// One fix per decoded frame, in the searched region's pixels.
    fixes: Vec<BallFix>,
    /// Measured frames whose rim lies in saturated pixels.
    saturated: usize,
    /// Seconds waiting for decoded frames.
    seconds_waiting: f64,
    /// Seconds tracking.
    seconds_tracking: f64,
}

/// Streams every frame through `tracker`, in order, counting the measured frames whose rim is saturated.
fn track_forward(
    frames: bouncelab_frames::FrameStream<'_>,
    total: usize,
    roi: Option<Roi>,
    gain: f32,
    tracker: &mut Tracker,
    progress: &mut impl FnMut(usize, usize),
) -> Result<Forward, TrackError> {
    let mut saturated = 0;
    let (fixes, seconds_waiting, seconds_tracking) = stream_fixes(frames, total, progress, |frame| {
        // Only a region is copied; a whole frame is read where it lies.
        let cut;
        let frame = match roi {
            Some(r) => {
                cut = in_region(frame.clone(), Some(&r));
                &cut
            }
            None => frame,
        };
        let fix = with_plane(
            &frame.pixels,
            gain,
            |p| on_plane!(p, p => observe(tracker, frame.index as usize, frame.t_s, &p)),
        );
        if fix.status.measured() && rim_saturated(&frame.pixels, &fix) {
            saturated += 1;
        }
        fix
    })?;
    Ok(Forward {
        fixes,
        saturated,
        seconds_waiting,
        seconds_tracking,
    })
}

/// What the passes tracking backward in time share: each runs a fresh tracker over files in reverse order,
/// on `surface` (the line given, before the forward track; the forward track's after it).
struct Backward<'a> {
    clip: &'a Clip,
    opts: &'a ClipTracking,
    gain: f32,
    radius: (f64, f64),
    surface: Option<SurfaceLine>,
}

impl Backward<'_> {
    /// A fresh tracker for the ball's radius range, on `surface` when there is one.
    fn tracker(&self) -> Tracker {
        let mut back = Tracker::new(TrackOptions {
            radius_px: Some(self.radius),
            ..self.opts.tracker.clone()
        });
        if let Some(line) = self.surface {
            back.set_surface(line);
        }
        back
    }

    /// The clip's first `files` files, none measured yet (absent fixes at their frames' times).
    fn unmeasured(&self, files: usize) -> Vec<BallFix> {
        self.clip.files()[..files]
            .iter()
            .map(|f| BallFix::absent(f.index as usize, self.clip.time_of(f.index), Status::Absent))
            .collect()
    }

    /// Measures file `k` (frame index `frame`) with `tracker` at time `t_back` (negated time).
    fn measure(&self, tracker: &mut Tracker, k: usize, frame: usize, t_back: f64) -> Result<BallFix, TrackError> {
        let image = in_region(
            self.clip.read(k, self.opts.read.png_decoder).expect("index in range")?,
            self.opts.roi.as_ref(),
        );
        Ok(with_plane(
            &image.pixels,
            self.gain,
            |p| on_plane!(p, p => observe(tracker, frame, t_back, &p)),
        ))
    }

    /// The files before the ball's first sighting (file `start`), tracked backward from its two sightings
    /// `seed` (absent where the ball was not found), and the radius that pass measured in free flight.
    fn before_seed(&self, seed: (Sighting, Sighting), start: usize) -> Result<(Vec<BallFix>, Option<f64>), TrackError> {
        let mut fixes = self.unmeasured(start);
        if start == 0 {
            return Ok((fixes, None));
        }
        let mut back = self.tracker();
        let ((ta, xa, ya), (tb, xb, yb)) = seed;
        back.seed((-tb, xb, yb), (-ta, xa, ya));
        track_back(
            &mut fixes,
            &mut back,
            start,
            |tr, k, frame, t| self.measure(tr, k, frame, t),
            |_, _| true,
        )?;
        Ok((fixes, back.flight_radius()))
    }

    /// Tracks the frames before the forward track first settled again, backward from there
    /// ([`retrack_start`]); when fixes are replaced, the forward pass's warnings about those frames are
    /// dropped and the re-measurement is said.
    fn retrack_start(&self, fixes: &mut [BallFix], warnings: &mut Vec<String>) -> Result<(), TrackError> {
        let mut back = self.tracker();
        let retracked = retrack_start(fixes, &mut back, |tr, k, frame, t| self.measure(tr, k, frame, t))?;
        if let Some((settled, replaced)) = retracked
            && replaced > 0
        {
            // What the forward pass said of the frames now measured again no longer describes the track.
            let first = fixes[settled].frame;
            warnings.retain(|w| frame_of_warning(w).is_none_or(|n| n >= first));
            warnings.push(format!(
                "the track settled at frame {}: {replaced} of the {settled} frames before it re-measured by tracking backward from there",
                fixes[settled].frame
            ));
        }
        Ok(())
    }

    /// The frames after the bounce that the forward track may have measured off the ball, measured again
    /// backward ([`retrack_bounce`]); what was replaced is said, and the files measured again (from the
    /// bounce's lowest point up to the clean flight after it) returned when any was replaced.
    fn retrack_bounce(
        &self,
        fixes: &mut [BallFix],
        forward: &Tracker,
        warnings: &mut Vec<String>,
    ) -> Result<Option<std::ops::Range<usize>>, TrackError> {
        let Some(span) = retrack_bounce(fixes, forward, |tr, k, frame, t| self.measure(tr, k, frame, t))? else {
            return Ok(None);
        };
        if span.replaced > 0 {
            warnings.push(format!(
                "frame {}: {} of the {} frames from the bounce's lowest point to the clean flight after it re-measured by tracking backward from that flight ({} not measured by the forward track, the others moved by up to {:.1} px)",
                fixes[span.lowest].frame,
                span.replaced,
                span.settled - span.lowest,
                span.unmeasured,
                span.moved_px,
            ));
        }
        Ok((span.replaced > 0).then_some(span.lowest..span.settled))
    }

    /// When the forward track leaves the ball ([`left_the_ball`]), the ball is looked for again from the
    /// clip's end and tracked back through the clip ([`Self::track_from_end`]); that pass's fixes take the
    /// place of the forward ones from where the forward track left, when the two passes met before it and
    /// that pass holds the clearer circles after it ([`take_from_end`]); the forward pass's warnings about
    /// the frames it no longer measures are then dropped, and what happened is said. `noise` is the first
    /// frame's noise σ. When no pass could tell, the step is returned, with what was found, for the caller
    /// to settle ([`Doubt`]).
    fn retrack_end(
        &self,
        fixes: &mut [BallFix],
        noise: f32,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Doubt>, TrackError> {
        let Some(jump) = left_the_ball(fixes.iter(), 0.5 * (self.radius.0 + self.radius.1)) else {
            return Ok(None);
        };
        let off = fixes[jump.at].frame;
        let said = format!(
            "frame {off}: the track moved {:.1} px in {} frame(s), more than the ball can (≤ {:.1} px a frame from how it moved before)",
            jump.moved_px, jump.frames, jump.limit_px
        );
        let doubt = |why: &str| Doubt {
            at: jump.at,
            said: format!("{said}; {why}"),
        };
        let Some(from_end) = self.track_from_end(noise)? else {
            return Ok(Some(doubt("the ball was not found again from the clip's end")));
        };
        match take_from_end(fixes, &from_end, jump.at) {
            Ok(replaced) => {
                warnings.retain(|w| frame_of_warning(w).is_none_or(|n| n < off));
                warnings.push(format!(
                    "{said}: the ball found again from the clip's end and tracked back, {replaced} frame(s) re-measured from there"
                ));
                Ok(None)
            }
            Err(NotTaken::NeverMet) => Ok(Some(doubt(&format!(
                "the circle found from the clip's end and tracked back never meets this track before frame {off} (another object, or this track was not on the ball)"
            )))),
            Err(NotTaken::NoClearer) => Ok(Some(doubt("tracked back from the clip's end, the ball was no clearer"))),
        }
    }

    /// When the forward track lost the ball's rim ([`Tracker::rim_lost_at`]) but made no step the ball
    /// cannot make ([`left_the_ball`]), it found the ball again near its path, and the frames just before
    /// the loss may have followed the rim as it faded (into a band in contact, at a low frame rate). The
    /// ball is then looked for from the clip's end and tracked back ([`Self::track_from_end`]), and the
    /// frames before the loss compared, going back, until the two passes hold the same circle
    /// ([`crate::bounce::same_circle`]): where they differ before that, the pass from the end's fix replaces
    /// the forward one unless that is clearly the clearer ([`clearer`]), as the forward track was losing
    /// the rim there. A pass that never meets the forward track before the loss replaces nothing. What was
    /// replaced is said.
    fn retrack_after_lost_rim(
        &self,
        fixes: &mut [BallFix],
        forward: &Tracker,
        noise: f32,
        warnings: &mut Vec<String>,
    ) -> Result<(), TrackError> {
        let Some(at) = forward
            .rim_lost_at()
            .and_then(|frame| fixes.iter().position(|f| f.frame == frame))
        else {
            return Ok(());
        };
        let said = format!(
            "frame {}: the track lost the ball's rim and found the ball again near its path",
            fixes[at].frame
        );
        let outcome = match self.track_from_end(noise)? {
            None => "the ball was not found again from the clip's end: the forward track stands".to_string(),
            Some(from_end) => match before_the_loss(fixes, &from_end, at) {
                None => {
                    "the pass from the clip's end never met this track before it: the forward track stands".to_string()
                }
                Some(replace) => {
                    for &k in &replace {
                        fixes[k] = from_end[k];
                    }
                    format!(
                        "tracked back from the clip's end, {} frame(s) before it re-measured where the two passes differ",
                        replace.len()
                    )
                }
            },
        };
        warnings.push(format!("{said}; {outcome}"));
        Ok(())
    }

    /// Every file measured by a fresh tracker run back in time from the ball's sightings near the clip's end
    /// (files up to the later sighting in reverse order, the files after it forward from it); `None` when
    /// the ball is not found there.
    fn track_from_end(&self, noise: f32) -> Result<Option<Vec<BallFix>>, TrackError> {
        let found =
            match crate::acquire::acquire_in(self.clip, self.opts, self.gain, noise, crate::acquire::Order::Reversed) {
                Ok(a) => a,
                Err(TrackError::NoBall { .. } | TrackError::NothingMoves { .. }) => return Ok(None),
                Err(e) => return Err(e),
            };
        let mut fixes = self.unmeasured(self.clip.len());
        let (a, b) = found.seed;
        let mut back = self.tracker();
        back.seed(a, b);
        track_back(
            &mut fixes,
            &mut back,
            found.file + 1,
            |tr, k, frame, t| self.measure(tr, k, frame, t),
            |_, _| true,
        )?;
        // Files after the later sighting (when it is not the last): forward in time from both sightings.
        let mut ahead = self.tracker();
        ahead.seed((-b.0, b.1, b.2), (-a.0, a.1, a.2));
        for (k, old) in fixes.iter_mut().enumerate().skip(found.file + 1) {
            let fix = self.measure(&mut ahead, k, old.frame, old.t_s)?;
            if fix.status.measured() {
                *old = fix;
            }
        }
        Ok(Some(fixes))
    }
}

/// The frame a tracker's warning is about (it starts "frame N: "), if any.
fn frame_of_warning(w: &str) -> Option<usize> {
    w.strip_prefix("frame ")
        .and_then(|rest| rest.split(':').next())
        .and_then(|n| n.parse::<usize>().ok())
}

/// A step of a track larger than the ball can make: at fix `at`, `moved_px` from the measured fix before,
/// `frames` frames earlier, where the ball could have moved `limit_px` a frame at most.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Jump {
    at: usize,
    moved_px: f64,
    frames: usize,
    limit_px: f64,
}

/// A step the ball cannot make ([`left_the_ball`]) that no pass from the clip's end explained: the fix
/// after it (`at`) and what was found, said.
struct Doubt {
    at: usize,
    said: String,
}

impl Doubt {
    /// Whether the frames from the bounce, measured again backward (the files `remeasured`,
    /// [`Backward::retrack_bounce`]), settled the step: it lay among them, and the track, with them, makes
    /// no step the ball cannot make ([`left_the_ball`], the ball of `radius` px). In contact a forward
    /// track can slide off the ball and come back to it in one step; the pass back from the clean flight
    /// after the bounce then measures the ball through those frames.
    fn settled_by(&self, remeasured: Option<std::ops::Range<usize>>, fixes: &[BallFix], radius: f64) -> bool {
        remeasured.is_some_and(|span| span.start <= self.at && self.at <= span.end)
            && left_the_ball(fixes.iter(), radius).is_none()
    }
}

/// How many of a track's first steps between measured fixes tell how fast its ball moves.
const JUMP_REFERENCE_STEPS: usize = 8;

/// Marks the measured fixes from `at` on `ambiguous`, and says how many there were: the track jumped there
/// further than the ball can, and no pass could tell which side of the jump holds the ball, so no frame from
/// there on is reported as measured on it (the estimator then has only the frames before the jump).
fn doubt_from(fixes: &mut [BallFix], at: usize) -> usize {
    let mut n = 0;
    for f in fixes[at..].iter_mut().filter(|f| f.status.measured()) {
        f.status = Status::Ambiguous;
        n += 1;
    }
    n
}

/// How many times its typical step a ball's step may be ([`left_the_ball`]): it speeds up under gravity and
/// may leave the surface faster along it than it came (spin), but not by this much within a clip.
const JUMP_FACTOR: f64 = 3.0;

/// The first step of a track (its measured fixes, in the order given) that the ball cannot have made: more
/// than [`JUMP_FACTOR`] times the ball's typical step (the median per frame of the first
/// [`JUMP_REFERENCE_STEPS`] steps, a third of the steps at most) plus a quarter of its `radius` px, per
/// frame between the two fixes. A ball bounces off a passive surface no faster than it came in and its
/// centre moves smoothly through the contact; a track that steps a quarter of a radius beyond that has
/// left the ball for noise, texture or another object. `None` when fewer than 3 steps tell the typical
/// one, or no step is that large.
fn left_the_ball<'a>(fixes: impl Iterator<Item = &'a BallFix>, radius: f64) -> Option<Jump> {
    let measured: Vec<(usize, &BallFix)> = fixes.enumerate().filter(|(_, f)| f.status.measured()).collect();
    let steps: Vec<(usize, f64, usize)> = measured
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0].1, w[1].1);
            (
                w[1].0,
                (b.x_px - a.x_px).hypot(b.y_px - a.y_px),
                a.frame.abs_diff(b.frame).max(1),
            )
        })
        .collect();
    let reference = JUMP_REFERENCE_STEPS.min(steps.len() / 3);
    if reference < 3 {
        return None;
    }
    let mut per_frame: Vec<f64> = steps[..reference].iter().map(|s| s.1 / s.2 as f64).collect();
    let limit = JUMP_FACTOR * crate::plane::median(&mut per_frame) + 0.25 * radius;
    steps
        .iter()
        .find(|s| s.1 > limit * s.2 as f64)
        .map(|&(at, moved_px, frames)| Jump {
            at,
            moved_px,
            frames,
            limit_px: limit,
        })
}

/// How many of the forward track's last measured fixes before it left the ball the pass from the clip's end
/// is compared with ([`passes_meet`]).
const MEETING_FIXES: usize = 10;

/// Whether two passes over the same files followed the same circle where they overlap: of the last
/// [`MEETING_FIXES`] fixes that both measured (`forward`, `from_end`, file by file), at least half are the
/// same circle (centres within a tenth of the radius, radii within 5 % and a pixel), and at least 3 are
/// compared. A pass from the clip's end that started on a seam's lobe or another moving thing never meets
/// the track that was on the ball.
fn passes_meet(forward: &[BallFix], from_end: &[BallFix]) -> bool {
    let both: Vec<(&BallFix, &BallFix)> = forward
        .iter()
        .zip(from_end)
        .filter(|(a, b)| a.status.measured() && b.status.measured())
        .collect();
    let last = &both[both.len().saturating_sub(MEETING_FIXES)..];
    let same = |(a, b): &&(&BallFix, &BallFix)| {
        (a.x_px - b.x_px).hypot(a.y_px - b.y_px) <= 0.1 * a.r_px && (a.r_px - b.r_px).abs() <= 0.05 * a.r_px + 1.0
    };
    last.len() >= 3 && 2 * last.iter().filter(same).count() >= last.len()
}

/// Puts the fixes of the pass from the clip's end (`from_end`, one per file) in place of the forward ones
/// from file `off` on, where the forward track left the ball, when the two passes met on the ball before
/// `off` ([`passes_meet`]) and that pass holds the clearer circles from `off` on (the higher median quality
/// over the files both measured). That pass is trusted back to where it left the ball itself
/// ([`left_the_ball`], going back in time), if it did; before `off` (and where trusted) one of its fixes is
/// taken where it is clearly the clearer ([`clearer`]). Returns how many fixes were replaced, or why the
/// pass from the end is not taken.
fn take_from_end(fixes: &mut [BallFix], from_end: &[BallFix], off: usize) -> Result<usize, NotTaken> {
    let mut radii: Vec<f64> = from_end
        .iter()
        .filter(|f| f.status.measured())
        .map(|f| f.r_px)
        .collect();
    if radii.is_empty() {
        return Err(NotTaken::NeverMet);
    }
    let radius = crate::plane::median(&mut radii);
    let trusted_from = left_the_ball(from_end.iter().rev(), radius).map_or(0, |j| from_end.len() - j.at);
    if !passes_meet(&fixes[..off], &from_end[..off]) {
        return Err(NotTaken::NeverMet);
    }
    let start = off.max(trusted_from);
    let (mut qa, mut qb): (Vec<f64>, Vec<f64>) = fixes
        .iter()
        .zip(from_end)
        .skip(start)
        .filter(|(a, b)| a.status.measured() && b.status.measured())
        .map(|(a, b)| (a.quality, b.quality))
        .unzip();
    if qa.is_empty() || crate::plane::median(&mut qb) <= crate::plane::median(&mut qa) {
        return Err(NotTaken::NoClearer);
    }
    let mut replaced = 0;
    for (k, (old, new)) in fixes.iter_mut().zip(from_end).enumerate() {
        let takes = new.status.measured() && k >= trusted_from && (k >= start || clearer(new, old));
        if takes {
            *old = *new;
            replaced += 1;
        }
    }
    Ok(replaced)
}

/// Why the pass from the clip's end was not taken ([`take_from_end`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum NotTaken {
    /// It never followed the same circle as the forward track before that left the ball.
    NeverMet,
    /// It was no clearer where the forward track left the ball.
    NoClearer,
}

/// Share of a frame's pixels at one end of the scale above which a clip where no ball was found is said to
/// be clipped ([`clipped_instead`]).
const CLIPPED_FRAME_SHARE: f64 = 0.5;

/// `e` (acquisition's failure), or [`TrackError::Clipped`] when no ball was found and more than
/// [`CLIPPED_FRAME_SHARE`] of the first frame's searched pixels are at the file's full scale or at zero
/// ([`pixel_clipped`]): then nothing could be seen, and the reason is that, not the ball. A backlit ball
/// on a clipped backdrop is still looked for: only a failed search is explained so.
fn clipped_instead(e: TrackError, clip: &Clip, opts: &ClipTracking) -> TrackError {
    if !matches!(e, TrackError::NoBall { .. } | TrackError::NothingMoves { .. }) {
        return e;
    }
    let Some(Ok(first)) = clip.read(0, opts.read.png_decoder) else {
        return e;
    };
    let first = in_region(first, opts.roi.as_ref());
    let px = &first.pixels;
    let (mut full, mut zero) = (0usize, 0usize);
    for y in 0..px.height() {
        for x in 0..px.width() {
            match pixel_clipped(px, x, y) {
                Some(true) => full += 1,
                Some(false) => zero += 1,
                None => {}
            }
        }
    }
    let n = px.width() as usize * px.height() as usize;
    let share = |k: usize| k as f64 / n.max(1) as f64;
    let (count, level) = if full >= zero {
        (full, "at the file's full scale")
    } else {
        (zero, "at zero")
    };
    if share(count) <= CLIPPED_FRAME_SHARE {
        return e;
    }
    TrackError::Clipped {
        clip: clip.dir().display().to_string(),
        percent: 100.0 * share(count),
        level,
    }
}

/// Whether pixel (x, y) is clipped: `Some(true)` at the pixel type's full scale (255, or 0xFFC0 and above
/// in 16-bit files, which hold 10- and 12-bit data shifted up), `Some(false)` at zero, `None` between.
fn pixel_clipped(px: &bouncelab_frames::GrayPixels, x: u32, y: u32) -> Option<bool> {
    let (v, full) = match px {
        bouncelab_frames::GrayPixels::U8(img) => (u32::from(img.get_pixel(x, y).0[0]), u32::from(u8::MAX)),
        bouncelab_frames::GrayPixels::U16(img) => (u32::from(img.get_pixel(x, y).0[0]), 0xFFC0),
    };
    if v >= full {
        Some(true)
    } else if v == 0 {
        Some(false)
    } else {
        None
    }
}

/// Share of the samples around a rim at the file's full scale above which the rim counts as saturated.
const SATURATED_SHARE: f64 = 0.1;

/// Whether the ball's rim at `fix` lies in saturated pixels: of 64 samples just inside and just outside the
/// rim (±2 px), more than [`SATURATED_SHARE`] at the pixel type's full scale ([`pixel_clipped`]). A clipped
/// edge has no gradient where the tracker looks for one, so the centre and radius there are biased. Cost: 64
/// pixel reads.
fn rim_saturated(px: &bouncelab_frames::GrayPixels, fix: &BallFix) -> bool {
    let (w, h) = (px.width() as f64, px.height() as f64);
    let full = |x: u32, y: u32| pixel_clipped(px, x, y) == Some(true);
    let (mut seen, mut clipped) = (0u32, 0u32);
    for k in 0..32 {
        let a = std::f64::consts::TAU * k as f64 / 32.0;
        for d in [-2.0, 2.0] {
            let (x, y) = (fix.x_px + (fix.r_px + d) * a.cos(), fix.y_px + (fix.r_px + d) * a.sin());
            if x >= 0.0 && y >= 0.0 && x < w && y < h {
                seen += 1;
                clipped += u32::from(full(x as u32, y as u32));
            }
        }
    }
    seen > 0 && f64::from(clipped) > SATURATED_SHARE * f64::from(seen)
}

/// Consecutive clean fixes (status ok, quality ≥ [`CLEAN_QUALITY`]) from which a track counts as settled.
const SETTLED_RUN: usize = 5;

/// The frames before the track first settled, tracked again backward from there.
///
/// A track can start on the wrong circle and only later lock onto the ball: a seam drawn nearly as large
/// as the ball and a few px off its centre (clip S095 of the `paper` preset) out-votes the rim in the
/// first frames, its fixes a weak circle (quality 0.25–0.65 against the rim's 0.97). Tracking is
/// symmetric in time, so `back` (a fresh tracker) runs over the frames before the first run of
/// [`SETTLED_RUN`] clean fixes in reverse order, in negated time, seeded by the two settled fixes;
/// `measure(back, k, frame, −t)` measures file `k`. A frame takes the backward fix when the forward one
/// is not measured or is a clearly weaker circle (quality lower by more than 0.1). Returns the settled
/// position and how many fixes were replaced, `None` when the track never settles or settled at once.
fn retrack_start(
    fixes: &mut [BallFix],
    back: &mut Tracker,
    measure: impl FnMut(&mut Tracker, usize, usize, f64) -> Result<BallFix, TrackError>,
) -> Result<Option<(usize, usize)>, TrackError> {
    let clean = |f: &BallFix| f.status == Status::Ok && f.quality >= CLEAN_QUALITY;
    let Some(settled) =
        (0..fixes.len().saturating_sub(SETTLED_RUN - 1)).find(|&i| fixes[i..i + SETTLED_RUN].iter().all(clean))
    else {
        return Ok(None);
    };
    if settled == 0 {
        return Ok(None);
    }
    let (a, b) = (fixes[settled + 1], fixes[settled]);
    back.seed((-a.t_s, a.x_px, a.y_px), (-b.t_s, b.x_px, b.y_px));
    let replaced = track_back(fixes, back, settled, measure, clearer)?;
    Ok(Some((settled, replaced)))
}

/// What [`retrack_bounce`] measured again: the files from `lowest` up to `settled`, `replaced` of them,
/// `unmeasured` of those not measured by the forward track, the others moved by up to `moved_px`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Retracked {
    lowest: usize,
    settled: usize,
    replaced: usize,
    unmeasured: usize,
    moved_px: f64,
}

/// The frames after the bounce that the forward track may have measured off the ball
/// ([`crate::bounce::after_bounce`]), measured again backward in time from the clean flight after them by
/// a fresh tracker that reads the rim as `forward` does ([`Tracker::fresh_on_same_rim`]), seeded by that
/// flight's first two fixes; `measure(back, k, frame, −t)` measures file `k`. Where the two passes disagree
/// a frame takes the backward fix as [`crate::bounce::back_replaces`] says, for the ball's radius `forward`
/// measured in free flight. `None` when there is nothing to measure again (no line, no bounce, or a bounce
/// the forward track held cleanly).
fn retrack_bounce(
    fixes: &mut [BallFix],
    forward: &Tracker,
    mut measure: impl FnMut(&mut Tracker, usize, usize, f64) -> Result<BallFix, TrackError>,
) -> Result<Option<Retracked>, TrackError> {
    let Some(line) = forward.surface() else {
        return Ok(None);
    };
    let Some(span) = crate::bounce::after_bounce(fixes, line) else {
        return Ok(None);
    };
    let (lowest, settled) = (span.lowest, span.settled);
    let mut back = forward.fresh_on_same_rim();
    let ball_r_px = forward.known_radius();
    let (a, b) = (fixes[settled + 1], fixes[settled]);
    back.seed((-a.t_s, a.x_px, a.y_px), (-b.t_s, b.x_px, b.y_px));
    let mut unmeasured = 0;
    let mut moved_px = 0.0f64;
    let replaced = track_back(
        &mut fixes[lowest..],
        &mut back,
        settled - lowest,
        |tr, k, frame, t| measure(tr, lowest + k, frame, t),
        |back, forward| {
            let takes = crate::bounce::back_replaces(line, back, forward, ball_r_px);
            if takes && forward.status.measured() {
                moved_px = moved_px.max((back.x_px - forward.x_px).hypot(back.y_px - forward.y_px));
            } else if takes {
                unmeasured += 1;
            }
            takes
        },
    )?;
    Ok(Some(Retracked {
        lowest,
        settled,
        replaced,
        unmeasured,
        moved_px,
    }))
}

/// The files before `at` (where the forward track lost the ball's rim, and found it again or not) whose fix
/// the pass from the clip's end replaces (see [`Backward::retrack_after_lost_rim`]): going back from `at`
/// until both passes measured the same circle, those where `from_end` is measured and the forward fix is
/// not clearly the clearer ([`clearer`]). `None` when they never meet.
fn before_the_loss(fixes: &[BallFix], from_end: &[BallFix], at: usize) -> Option<Vec<usize>> {
    let mut replace = Vec::new();
    for k in (0..at).rev() {
        let (old, new) = (&fixes[k], &from_end[k]);
        if old.status.measured() && new.status.measured() && crate::bounce::same_circle(new, old) {
            return Some(replace);
        }
        // The forward track was losing the rim here: its fix stands only where it is clearly the clearer.
        if new.status.measured() && !(old.status.measured() && clearer(old, new)) {
            replace.push(k);
        }
    }
    None
}

/// Whether a fix measured on another pass replaces `old`: `old` is not measured, or is a clearly weaker
/// circle (quality lower by more than 0.1).
fn clearer(fix: &BallFix, old: &BallFix) -> bool {
    !old.status.measured() || fix.quality > old.quality + 0.1
}

/// Where the forward track starts: from the two earliest fixes of the unbroken run the backward pass over
/// the frames before the ball's first sighting measured back from it ([`Backward::before_seed`]), the second
/// at least the sightings' gap after the first (else the first sighting itself); from the sightings `seed`
/// when that pass measured nothing next to them. A fix beyond a frame the pass lost is not trusted: its
/// widened search may have caught something else.
fn forward_seed(early: &[BallFix], seed: (Sighting, Sighting)) -> (Sighting, Sighting) {
    let run = early.iter().rev().take_while(|f| f.status.measured()).count();
    let measured: Vec<&BallFix> = early[early.len() - run..].iter().collect();
    let Some(a) = measured.first() else {
        return seed;
    };
    let gap = seed.1.0 - seed.0.0;
    let b = measured
        .iter()
        .find(|f| f.t_s - a.t_s >= 0.999 * gap)
        .map_or(seed.0, |f| (f.t_s, f.x_px, f.y_px));
    ((a.t_s, a.x_px, a.y_px), b)
}

/// Files `start − 1` down to 0 measured by `back` (already seeded, in negated time) through
/// `measure(back, k, frame, −t)`; a measured fix replaces the one in `fixes` where `takes(fix, old)`.
/// Returns how many were replaced.
fn track_back(
    fixes: &mut [BallFix],
    back: &mut Tracker,
    start: usize,
    mut measure: impl FnMut(&mut Tracker, usize, usize, f64) -> Result<BallFix, TrackError>,
    mut takes: impl FnMut(&BallFix, &BallFix) -> bool,
) -> Result<usize, TrackError> {
    let mut replaced = 0;
    for k in (0..start).rev() {
        let old = fixes[k];
        let fix = measure(back, k, old.frame, -old.t_s)?;
        if fix.status.measured() && takes(&fix, &old) {
            fixes[k] = BallFix { t_s: old.t_s, ..fix };
            replaced += 1;
        }
    }
    Ok(replaced)
}

/// Streams the `total` frames of `frames` in order through `fix_of`, reporting progress and timing how long
/// was spent waiting for decoded frames and how long on the frames themselves (seconds).
pub(crate) fn stream_fixes(
    frames: bouncelab_frames::FrameStream<'_>,
    total: usize,
    progress: &mut impl FnMut(usize, usize),
    mut fix_of: impl FnMut(&bouncelab_frames::Frame) -> BallFix,
) -> Result<(Vec<BallFix>, f64, f64), TrackError> {
    let mut fixes = Vec::with_capacity(total);
    let (mut waiting, mut working) = (0.0, 0.0);
    let mut t_wait = Instant::now();
    let mut frames = frames;
    while let Some(frame) = frames.next() {
        let frame = frame?;
        let t_work = Instant::now();
        waiting += (t_work - t_wait).as_secs_f64();
        fixes.push(fix_of(&frame));
        // The decoder reuses the buffer for a frame to come rather than asking the system for fresh memory.
        frames.recycle(frame);
        t_wait = Instant::now();
        working += (t_wait - t_work).as_secs_f64();
        progress(fixes.len(), total);
    }
    Ok((fixes, waiting, working))
}

fn observe<P: Pixel>(tracker: &mut Tracker, frame: usize, t_s: f64, p: &Plane<P>) -> BallFix {
    tracker.observe(frame, t_s, p)
}

/// m/px from the mean radius of frames where the whole ball is clear of the surface and the border.
///
/// Its standard error holds the radius's scatter over those frames and two Type-B terms for where "the rim"
/// is, both measured on the clip:
/// - the edge's definition, `edge_definition_px / √3`: the median distance between the gradient-maximum
///   edge and the half-contrast crossing, taken as the half-width of a uniform uncertainty;
/// - the rim's shape, `rim_shape_rms_px`: lighting and the limb's shading move the apparent edge by
///   different amounts at different angles (the learned [`RimShape`](crate::RimShape)). Their mean over the
///   rim, which is what biases the radius, cannot be seen (a circle absorbs it), so it is taken to be as
///   uncertain as the part that can: the shape's RMS, as a standard uncertainty. The same reasoning keeps
///   the uncorrected spread in each frame's centre σ, and the estimator takes the first harmonic, which
///   offsets every frame's centre alike, to be as uncertain (`Scale::rim_shape_px`);
/// - the limb's silhouette, `limb`: how far a shaded limb's silhouette lies outside the fitted circles (see
///   [`LimbOffset`](crate::LimbOffset)), its mean a standard uncertainty of the radius and its first
///   harmonic one of the centre's common offset (`Scale::limb_radius_px`, `Scale::limb_centre_px`).
pub(crate) fn scale_from(
    fixes: &[BallFix],
    surface: Option<&SurfaceLine>,
    diameter: f64,
    edge_definition_px: f64,
    rim_shape_rms_px: f64,
    limb: Option<crate::LimbOffset>,
) -> Option<Scale> {
    let clear_of_line: Vec<f64> = fixes
        .iter()
        .filter(|f| f.status == Status::Ok)
        .filter(|f| surface.is_none_or(|l| f.y_px + f.r_px < l.top_at(f.x_px) - 3.0))
        .map(|f| f.r_px)
        .collect();
    // A line the ball never clears is not where it lands (the estimator will say so): the frames well above
    // the lowest centre (half a radius, where no contact flattens the ball) then give the radius.
    let radii = if clear_of_line.len() >= 3 {
        clear_of_line
    } else {
        let lowest = fixes
            .iter()
            .filter(|f| f.status.measured())
            .map(|f| f.y_px)
            .fold(f64::NEG_INFINITY, f64::max);
        fixes
            .iter()
            .filter(|f| f.status == Status::Ok && f.y_px < lowest - 0.5 * f.r_px)
            .map(|f| f.r_px)
            .collect()
    };
    if radii.len() < 3 {
        return None;
    }
    let n = radii.len() as f64;
    let mean = radii.iter().sum::<f64>() / n;
    let sd = (radii.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let m_per_px = diameter / (2.0 * mean);
    let (limb_radius_px, limb_centre_px) = limb.map_or((0.0, 0.0), |l| (l.radius_px.abs(), l.centre_len_px()));
    let var_px = sd * sd / n + edge_definition_px.powi(2) / 3.0 + rim_shape_rms_px.powi(2) + limb_radius_px.powi(2);
    Some(Scale {
        m_per_px,
        sigma_m_per_px: m_per_px * var_px.sqrt() / mean,
        rim_shape_px: rim_shape_rms_px,
        limb_centre_px,
        limb_radius_px,
        radius_px: mean,
        frames: radii.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{Scene, render};

    /// The ball falling through 30 frames (px, frame k at t = k·0.1 ms).
    fn ball_at(k: usize) -> (f64, f64) {
        let t = k as f64;
        (100.3 + 0.4 * t, 60.7 + 1.1 * t + 0.02 * t * t)
    }

    fn frame(k: usize) -> Vec<u8> {
        let (x, y) = ball_at(k);
        render(&Scene {
            ball: (x, y, 40.0),
            seed: k as u64,
            ..Scene::default()
        })
    }

    /// A fix of frame `k` at (x, y) with `quality`.
    fn fix_at(k: usize, (x, y): (f64, f64), quality: f64) -> BallFix {
        BallFix {
            frame: k,
            t_s: k as f64 * 1e-4,
            x_px: x,
            y_px: y,
            r_px: 40.0,
            sigma_px: 0.05,
            sigma_r_px: 0.05,
            quality,
            status: Status::Ok,
        }
    }

    /// Before the frame where the forward track lost the rim, the frames it drifted on (down into a band)
    /// take the pass from the end's fixes back to where the two passes meet, but where the forward fix is
    /// clearly the clearer; frames before the meeting are left alone, and a pass that never meets the
    /// forward track replaces nothing.
    #[test]
    fn frames_drifted_before_a_lost_rim_take_the_pass_from_the_end() {
        let from_end: Vec<BallFix> = (0..12).map(|k| fix_at(k, ball_at(k), 0.7)).collect();
        let mut forward = from_end.clone();
        for (k, f) in forward.iter_mut().enumerate().take(9).skip(5) {
            let (x, y) = ball_at(k);
            *f = fix_at(k, (x, y + (k - 3) as f64), 0.5);
        }
        // Frame 6 drifted too, but its circle is clearly the clearer: it stands.
        forward[6].quality = 0.85;
        forward[9] = BallFix::absent(9, 9e-4, Status::Absent);
        forward[2].y_px += 3.0;
        assert_eq!(before_the_loss(&forward, &from_end, 9), Some(vec![8, 7, 5]));
        let elsewhere: Vec<BallFix> = from_end
            .iter()
            .map(|f| BallFix {
                x_px: f.x_px + 30.0,
                ..*f
            })
            .collect();
        assert_eq!(before_the_loss(&forward, &elsewhere, 9), None);
    }

    /// The rim shape's RMS enters the scale's error as a standard uncertainty of the radius.
    #[test]
    fn the_scale_error_holds_the_rim_shape() {
        let fixes: Vec<BallFix> = (0..20)
            .map(|k| BallFix {
                frame: k,
                t_s: k as f64 * 1e-4,
                x_px: 100.0,
                y_px: 100.0 + k as f64,
                r_px: if k % 2 == 0 { 79.99 } else { 80.01 },
                sigma_px: 0.02,
                sigma_r_px: 0.02,
                quality: 1.0,
                status: Status::Ok,
            })
            .collect();
        let plain = scale_from(&fixes, None, 0.067, 0.0, 0.0, None).unwrap();
        let shaped = scale_from(&fixes, None, 0.067, 0.0, 0.08, None).unwrap();
        assert_eq!(plain.m_per_px, shaped.m_per_px);
        // The radii's scatter alone: 0.01 px / √20 of 80 px.
        let scatter = plain.sigma_m_per_px / plain.m_per_px;
        assert!(scatter < 5e-5, "{plain:?}");
        let rel = shaped.sigma_m_per_px / shaped.m_per_px;
        assert!((rel - scatter.hypot(0.08 / 80.0)).abs() < 1e-9, "{rel}");
        // That part is named, for what is common to a session's clips.
        assert!((shaped.sigma_shape_m_per_px() / shaped.m_per_px - 0.08 / 80.0).abs() < 1e-12);
        assert_eq!(plain.sigma_shape_m_per_px(), 0.0);
        // The limb's silhouette 0.06 px outside the circles and 0.3 px off their centres: the radius's part
        // enters the scale's error and the session-common part, the centre's only the common offset's.
        let limb = crate::LimbOffset {
            radius_px: -0.06,
            centre_px: (0.18, -0.24),
            rays: 128,
        };
        let both = scale_from(&fixes, None, 0.067, 0.0, 0.08, Some(limb)).unwrap();
        assert_eq!(both.m_per_px, plain.m_per_px);
        let rel = both.sigma_m_per_px / both.m_per_px;
        assert!((rel - scatter.hypot(0.1 / 80.0)).abs() < 1e-9, "{rel}");
        assert!((both.sigma_shape_m_per_px() / both.m_per_px - 0.1 / 80.0).abs() < 1e-12);
        assert!((both.centre_offset_px() - 0.08f64.hypot(0.3)).abs() < 1e-12, "{both:?}");
    }

    /// A ball first sighted in frames 20 and 25 is measured in the frames before from there, backward, and the
    /// forward track starts from the earliest of those fixes.
    #[test]
    fn frames_before_the_first_sighting_are_tracked_backward_from_it() {
        let mut back = Tracker::new(TrackOptions {
            radius_px: Some((34.0, 46.0)),
            ..TrackOptions::default()
        });
        let sighting = |k: usize| (k as f64 * 1e-4, ball_at(k).0, ball_at(k).1);
        let seed = (sighting(20), sighting(25));
        back.seed((-seed.1.0, seed.1.1, seed.1.2), (-seed.0.0, seed.0.1, seed.0.2));
        let mut early: Vec<BallFix> = (0..20)
            .map(|k| BallFix::absent(k, k as f64 * 1e-4, Status::Absent))
            .collect();
        let replaced = track_back(
            &mut early,
            &mut back,
            20,
            |tr, k, frame_index, t| {
                let img = frame(k);
                Ok(tr.observe(frame_index, t, &Plane::new(&img, 256, 256)))
            },
            |_, _| true,
        )
        .unwrap();
        assert_eq!(replaced, 20);
        for (k, f) in early.iter().enumerate() {
            let (x, y) = ball_at(k);
            assert_eq!(f.t_s, k as f64 * 1e-4);
            assert!(
                (f.x_px - x).hypot(f.y_px - y) < 0.2,
                "frame {k}: {f:?} against ({x}, {y})"
            );
        }
        // The forward track starts at frame 0, its second position the sightings' gap (5 frames) later.
        let (a, b) = forward_seed(&early, seed);
        assert_eq!((a.1, a.2), (early[0].x_px, early[0].y_px));
        assert_eq!((b.1, b.2), (early[5].x_px, early[5].y_px));
        // Without a measured frame before them, the sightings themselves.
        let none: Vec<BallFix> = (0..20)
            .map(|k| BallFix::absent(k, k as f64 * 1e-4, Status::Absent))
            .collect();
        assert_eq!(forward_seed(&none, seed), seed);
        // A frame the backward pass lost breaks the run: fixes beyond it do not start the track.
        let mut broken = early.clone();
        broken[9] = BallFix::absent(9, 9e-4, Status::Absent);
        let (a, b) = forward_seed(&broken, seed);
        assert_eq!((a.1, a.2), (early[10].x_px, early[10].y_px));
        assert_eq!((b.1, b.2), (early[15].x_px, early[15].y_px));
    }

    #[test]
    fn frames_before_the_track_settled_are_measured_again_backward() {
        let opts = TrackOptions {
            radius_px: Some((34.0, 46.0)),
            ..TrackOptions::default()
        };
        let mut forward = Tracker::new(opts.clone());
        let mut fixes: Vec<BallFix> = (0..30)
            .map(|k| {
                let img = frame(k);
                forward.observe(k, k as f64 * 1e-4, &Plane::new(&img, 256, 256))
            })
            .collect();
        assert!(
            fixes
                .iter()
                .all(|f| f.status == Status::Ok && f.quality >= CLEAN_QUALITY)
        );
        // The first 8 frames as if the track had followed a weaker circle 7 px off, or lost the ball.
        for (k, f) in fixes.iter_mut().enumerate().take(8) {
            if k == 3 {
                *f = BallFix::absent(k, f.t_s, Status::Absent);
            } else {
                f.x_px += 7.0;
                f.quality = 0.4;
            }
        }
        let mut back = Tracker::new(opts);
        let out = retrack_start(&mut fixes, &mut back, |tr, k, frame_index, t| {
            let img = frame(k);
            Ok(tr.observe(frame_index, t, &Plane::new(&img, 256, 256)))
        })
        .unwrap();
        assert_eq!(out, Some((8, 8)));
        for (k, f) in fixes.iter().enumerate().take(8) {
            let (x, y) = ball_at(k);
            assert_eq!(f.t_s, k as f64 * 1e-4);
            assert!(
                (f.x_px - x).hypot(f.y_px - y) < 0.2,
                "frame {k}: {f:?} against ({x}, {y})"
            );
        }
        // A track that is clean from its first frame is left alone.
        let before = fixes.clone();
        let mut back = Tracker::new(TrackOptions::default());
        assert_eq!(
            retrack_start(&mut fixes, &mut back, |_, _, _, _| unreachable!()).unwrap(),
            None
        );
        assert_eq!(fixes, before);
    }

    /// A ball pressed 3 px into a band whose top is at y = 200 at frame 10, rising again after it (px).
    fn bouncing_at(k: usize) -> (f64, f64) {
        let t = k as f64 - 10.0;
        (80.3 + 3.0 * k as f64, 163.0 - 0.6 * t * t)
    }

    fn bounce_frame(k: usize) -> Vec<u8> {
        render(&Scene {
            ball: (bouncing_at(k).0, bouncing_at(k).1, 40.0),
            surface: Some((200.0, 0.0)),
            seed: k as u64,
            ..Scene::default()
        })
    }

    #[test]
    fn frames_after_the_bounce_measured_off_the_ball_are_measured_again_backward() {
        let mut forward = Tracker::new(TrackOptions {
            radius_px: Some((34.0, 46.0)),
            ..TrackOptions::default()
        });
        forward.set_surface(SurfaceLine::given(128.0, 200.0, 0.0));
        let measure = |tr: &mut Tracker, k: usize, frame: usize, t: f64| {
            Ok(tr.observe(frame, t, &Plane::new(&bounce_frame(k), 256, 256)))
        };
        let mut fixes: Vec<BallFix> = (0..24)
            .map(|k| measure(&mut forward, k, k, k as f64 * 1e-4).unwrap())
            .collect();
        let on_path = |f: &BallFix, k: usize| {
            let (x, y) = bouncing_at(k);
            (f.x_px - x).hypot(f.y_px - y)
        };
        for (k, f) in fixes.iter().enumerate() {
            assert!(
                f.status == Status::Ok && on_path(f, k) < 0.2,
                "forward frame {k}: {f:?}"
            );
        }
        // The forward track held the bounce: nothing is measured again.
        let held = fixes.clone();
        assert_eq!(
            retrack_bounce(&mut fixes, &forward, |_, _, _, _| unreachable!()).unwrap(),
            None
        );
        assert_eq!(fixes, held);
        // Frames 13-15 (the ball clear of the band from frame 13) as if the forward prediction had carried
        // the contact's push on: 5 px ahead of the ball, a weak circle, one frame lost.
        for (k, f) in fixes.iter_mut().enumerate().take(16).skip(13) {
            if k == 14 {
                *f = BallFix::absent(k, f.t_s, Status::Absent);
            } else {
                f.y_px -= 5.0;
                f.quality = 0.5;
            }
        }
        let out = retrack_bounce(&mut fixes, &forward, measure).unwrap().unwrap();
        assert_eq!((out.lowest, out.settled, out.replaced, out.unmeasured), (10, 16, 3, 1));
        assert!((out.moved_px - 5.0).abs() < 0.3, "{out:?}");
        for (k, f) in fixes.iter().enumerate() {
            assert!(on_path(f, k) < 0.2, "frame {k}: {f:?}");
            assert_eq!(f.t_s, k as f64 * 1e-4);
        }
        // The frames where the passes agree keep the forward fix.
        assert_eq!(fixes[..13], held[..13]);
    }

    /// Fixes of a ball on the path `ball_at` (quality `q`), every frame measured.
    fn on_the_ball(frames: std::ops::Range<usize>, q: f64) -> Vec<BallFix> {
        frames.map(|k| fix_at(k, ball_at(k), q)).collect()
    }

    /// A track that moves as a ball does, through a bounce, has not left it; one that steps a quarter of a
    /// radius beyond the ball's pace has, at that step, whichever way the fixes are read; a gap in the track
    /// allows for the frames missed.
    #[test]
    fn a_track_that_jumps_further_than_the_ball_moves_has_left_it() {
        let mut fixes = on_the_ball(0..30, 0.9);
        // A bounce at frame 15: the vertical motion turns round at 1.1 px a frame.
        for f in fixes.iter_mut().skip(15) {
            f.y_px = ball_at(15).1 - (ball_at(f.frame).1 - ball_at(15).1);
        }
        assert_eq!(left_the_ball(fixes.iter(), 40.0), None);
        assert_eq!(left_the_ball(fixes.iter().rev(), 40.0), None);
        // From frame 20 on, a circle 22 px away: a step of 22 px where the ball moves 1.2–2.8 px a frame.
        let mut off = fixes.clone();
        for f in off.iter_mut().skip(20) {
            f.x_px += 22.0;
        }
        let jump = left_the_ball(off.iter(), 40.0).expect("a jump");
        assert_eq!(jump.at, 20);
        assert!((jump.moved_px - 22.0).abs() < 1.5 && jump.frames == 1, "{jump:?}");
        assert!(jump.limit_px > 10.0 && jump.limit_px < 20.0, "{jump:?}");
        // Read back in time, the same step is found at the same frame (the 10th fix from the end).
        assert_eq!(left_the_ball(off.iter().rev(), 40.0).map(|j| j.at), Some(10));
        // Missing the five frames before it, the same circle is within reach of the ball: not a jump.
        for f in off.iter_mut().take(20).skip(15) {
            *f = BallFix::absent(f.frame, f.t_s, Status::Absent);
        }
        assert_eq!(left_the_ball(off.iter(), 40.0), None);
    }

    /// A step no pass from the clip's end explained is settled by the frames from the bounce measured again
    /// only when it lay among them and the track they leave makes no step the ball cannot make.
    #[test]
    fn a_step_is_settled_only_by_frames_measured_again_around_it() {
        let doubt = Doubt {
            at: 20,
            said: String::new(),
        };
        // The frames measured again joined the track: no step left.
        let joined = on_the_ball(0..30, 0.9);
        assert!(doubt.settled_by(Some(15..25), &joined, 40.0));
        // The step lay outside the frames measured again, or none was replaced.
        assert!(!doubt.settled_by(Some(5..15), &joined, 40.0));
        assert!(!doubt.settled_by(None, &joined, 40.0));
        // A step is still there (a circle 22 px away from frame 24 on).
        let mut stepped = joined.clone();
        for f in stepped.iter_mut().skip(24) {
            f.x_px += 22.0;
        }
        assert!(!doubt.settled_by(Some(15..25), &stepped, 40.0));
    }

    /// Frames from a jump no pass could explain are not reported as the ball: the measured ones become
    /// `ambiguous`, frames not found stay so, and the frames before the jump are left as they were.
    #[test]
    fn frames_from_an_unexplained_jump_are_ambiguous() {
        let before = on_the_ball(0..30, 0.8);
        let mut fixes = before.clone();
        fixes[25] = BallFix::absent(25, fixes[25].t_s, Status::Absent);
        assert_eq!(doubt_from(&mut fixes, 20), 9);
        assert_eq!(fixes[..20], before[..20]);
        assert_eq!(fixes[25].status, Status::Absent);
        for (f, b) in fixes[20..].iter().zip(&before[20..]).filter(|(f, _)| f.frame != 25) {
            assert_eq!(f.status, Status::Ambiguous);
            assert_eq!((f.x_px, f.y_px), (b.x_px, b.y_px));
        }
    }

    /// The pass from the clip's end takes the frames from where the forward track left the ball when it holds
    /// clearer circles there; before that, only frames where it is clearly the clearer; and not at all when
    /// it is the weaker.
    #[test]
    fn the_pass_from_the_end_takes_over_where_the_forward_track_left_the_ball() {
        let truth = on_the_ball(0..30, 0.8);
        let mut forward = truth.clone();
        for f in forward.iter_mut().skip(20) {
            f.x_px += 40.0;
            f.quality = 0.4;
        }
        // Frame 5 is a weaker circle of the ball: the pass from the end, clearer by 0.15 there, replaces it.
        forward[5].quality = 0.65;
        let from_end = truth.clone();
        let mut fixes = forward.clone();
        assert_eq!(take_from_end(&mut fixes, &from_end, 20), Ok(11));
        assert_eq!(fixes[20..], truth[20..]);
        assert_eq!(fixes[5], truth[5]);
        assert_eq!(fixes[..5], forward[..5]);
        assert_eq!(fixes[6..20], forward[6..20]);
        // A pass from the end no clearer than the forward track there leaves the forward track as it was.
        let weaker: Vec<BallFix> = truth.iter().map(|f| BallFix { quality: 0.3, ..*f }).collect();
        let mut fixes = forward.clone();
        assert_eq!(take_from_end(&mut fixes, &weaker, 20), Err(NotTaken::NoClearer));
        assert_eq!(fixes, forward);
        // A pass from the end on another circle moving with the ball (a seam's lobe, 20 px off its centre and
        // smaller) never met the forward track on the ball: not taken, however clear.
        let lobe: Vec<BallFix> = truth
            .iter()
            .map(|f| BallFix {
                x_px: f.x_px + 20.0,
                r_px: 25.0,
                quality: 0.95,
                ..*f
            })
            .collect();
        let mut fixes = forward.clone();
        assert_eq!(take_from_end(&mut fixes, &lobe, 20), Err(NotTaken::NeverMet));
        assert_eq!(fixes, forward);
        // A pass from the end that itself left the ball (going back) at frame 8 is not taken before it: not at
        // frame 5, where it would be the clearer.
        let mut astray = truth.clone();
        for f in astray.iter_mut().take(8) {
            f.y_px -= 60.0;
        }
        let mut fixes = forward.clone();
        assert_eq!(take_from_end(&mut fixes, &astray, 20), Ok(10));
        assert_eq!(fixes[20..], truth[20..]);
        assert_eq!(fixes[..20], forward[..20]);
        // One that left it at frame 25, before reaching where the forward track left it, cannot meet it there.
        let mut astray = truth.clone();
        for f in astray.iter_mut().take(25) {
            f.y_px -= 60.0;
        }
        let mut fixes = forward.clone();
        assert_eq!(take_from_end(&mut fixes, &astray, 20), Err(NotTaken::NeverMet));
        assert_eq!(fixes, forward);
    }
}
