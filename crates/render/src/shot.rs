//! One shot: its physics (the model simulated at the frame and sub-exposure times), the camera placement,
//! and the exact truth per frame and per shot.

use crate::look::{Look, LookSpec, PathExtent, Placement};
use crate::rng::{Rng, derive};
use crate::{RenderError, Scenario};
use bouncelab_model::{
    Impact, Model, ModelError, ParamRef, ParamSetting, Phase, Sample, SimOptions, Simulation, simulate_drop,
};
use serde::Serialize;

/// Where the ball is with respect to the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Visibility {
    /// The whole disc is inside the frame.
    Full,
    /// Part of the disc is outside the frame.
    CutByBorder,
    /// The disc is entirely outside the frame.
    Absent,
}

impl Visibility {
    /// As written in truth files.
    pub fn name(self) -> &'static str {
        match self {
            Visibility::Full => "full",
            Visibility::CutByBorder => "cut_by_border",
            Visibility::Absent => "absent",
        }
    }
}

/// The truth of one frame, at its mid-exposure time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameTruth {
    /// Frame index (0-based).
    pub frame: usize,
    /// Time since the first frame, s (= frame / fps).
    pub t_s: f64,
    /// Ball centre, pixels, x to the right (pixel centres at integers).
    pub x_px: f64,
    /// Ball centre, pixels, y down.
    pub y_px: f64,
    /// Ball radius, pixels.
    pub r_px: f64,
    /// Ball centre along the surface (down-slope), m, local frame (`docs/outputs.md`).
    pub x_m: f64,
    /// Ball centre height above the surface line, m, local frame.
    pub y_m: f64,
    /// Orientation of the ball (its seam), rad, counter-clockwise, local frame (the model's θ plus the
    /// shot's random initial orientation).
    pub theta_rad: f64,
    /// Phase of the impact.
    pub phase: Phase,
    /// Where the disc is with respect to the frame.
    pub visible: Visibility,
    /// Penetration δ = max(R − y, 0), m.
    pub delta_m: f64,
}

/// The truth of one shot (a row of `truth/shots.csv`). Velocities in m/s in the local frame, spin in
/// rad/s counter-clockwise, times in s since the clip's first frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShotTruth {
    /// Clip (folder) name.
    pub clip: String,
    /// Surface name.
    pub surface: String,
    /// Incline β, degrees.
    pub angle_deg: f64,
    /// Drop height, m.
    pub drop_height_m: f64,
    /// Repeat number.
    pub repeat: u32,
    /// The shot's seed (derived from the session seed and the shot index).
    pub seed: u64,
    /// Number of frames.
    pub frames: usize,
    /// Tangential velocity at touch.
    pub v_in_t: f64,
    /// Normal velocity at touch (< 0).
    pub v_in_n: f64,
    /// Tangential velocity at separation.
    pub v_out_t: f64,
    /// Normal velocity at separation (> 0).
    pub v_out_n: f64,
    /// Coefficient of restitution |v_out_n / v_in_n|.
    pub cor: f64,
    /// Effective friction −Δv_t/Δv_n (the paper's momentum ratio).
    pub mu_eff: f64,
    /// Touch time, s.
    pub t_touch_s: f64,
    /// Maximum-compression time, s.
    pub t_max_s: f64,
    /// Separation time, s.
    pub t_sep_s: f64,
    /// Contact time, ms.
    pub contact_ms: f64,
    /// Maximum penetration, m.
    pub delta_max_m: f64,
    /// Spin at touch, rad/s.
    pub spin_in: f64,
    /// Spin at separation, rad/s.
    pub spin_out: f64,
    /// True if the ball rolled (contact point sticking) at separation.
    pub rolling_at_separation: bool,
    /// Scale, m per pixel.
    pub scale_m_per_px: f64,
    /// Ball radius, pixels.
    pub r_px: f64,
    /// y of the surface line at the image's centre column, pixels.
    pub surface_y_px: f64,
    /// Angle of the surface line in the image, degrees counter-clockwise as seen (−roll for "+x").
    pub surface_tilt_deg: f64,
    /// Total camera roll (scenario `camera.roll_deg` plus the `camera_roll` effect), degrees.
    pub roll_deg: f64,
    /// Image direction that is down-slope.
    pub downslope: String,
    /// Spring stiffness k of the shot's model, N/m (if it has a `spring`).
    pub k: Option<f64>,
    /// Compression damping b, N·s/m (if it has `damping`).
    pub b: Option<f64>,
    /// Coulomb friction μ (if it has `coulomb`).
    pub mu: Option<f64>,
    /// Every effect of the shot's model with its parameter values, as JSON (`{"spring":{"k":25650},…}`).
    pub effects_json: String,
    /// The extra (hidden) effects switched on for this shot.
    pub extra_effects: Vec<String>,
}

/// Camera placement: local metres → image pixels (roll, mirror for "-x", translation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Geometry {
    pub scale: f64,
    pub cos: f64,
    pub sin: f64,
    pub dir: f64,
    pub tx: f64,
    pub ty: f64,
}

impl Geometry {
    /// Image pixel position of the local point (x, y) m.
    pub fn to_px(self, x: f64, y: f64) -> (f64, f64) {
        let xc = self.cos * x + self.sin * y;
        let yc = -self.sin * x + self.cos * y;
        (self.tx + self.dir * xc / self.scale, self.ty - yc / self.scale)
    }

    /// Local coordinates of an image point, in pixels: (along the surface, height above the surface line).
    pub fn to_local_px(self, px: f64, py: f64) -> (f64, f64) {
        let xc = self.dir * (px - self.tx);
        let yc = self.ty - py;
        (self.cos * xc - self.sin * yc, self.sin * xc + self.cos * yc)
    }

    /// The image point of local pixel coordinates (along the surface, height above it): the inverse of
    /// [`Geometry::to_local_px`].
    pub fn local_px_to_image(self, s: f64, up: f64) -> (f64, f64) {
        let xc = self.cos * s + self.sin * up;
        let yc = -self.sin * s + self.cos * up;
        (self.tx + self.dir * xc, self.ty - yc)
    }
}

/// A planned shot: physics done, camera placed, truth known; images not yet made
/// ([`ShotPlan::renderer`] makes them).
#[derive(Debug, Clone)]
pub struct ShotPlan {
    /// Shot index in the scenario (0-based).
    pub index: usize,
    /// The shot's truth.
    pub truth: ShotTruth,
    /// The truth of every frame.
    pub frames: Vec<FrameTruth>,
    /// The shot's drawn look, if the scenario has a `[look]` (its truth, written to `truth/looks.csv`).
    pub look: Option<Look>,
    pub(crate) camera: crate::Camera,
    pub(crate) texture: crate::Texture,
    pub(crate) geom: Geometry,
    /// Ball centre (px) at each sub-exposure time, `blur_samples` per frame.
    pub(crate) subs: Vec<(f64, f64)>,
    /// Orientation of the ball's pattern in the image, rad counter-clockwise as seen, per frame.
    pub(crate) alpha: Vec<f64>,
    /// Maximum penetration, pixels.
    pub(crate) delta_max_px: f64,
    pub(crate) flicker_phase: f64,
    /// The session's seed (the sensor's fixed pattern is the same in every clip).
    pub(crate) session_seed: u64,
}

/// Shots at most this far (s) from the release cannot start earlier.
const MIN_T0: f64 = 1e-4;

/// Stream of a shot's look, derived from the shot's seed (far from the frames' streams 1, 2, …).
const LOOK_STREAM: u64 = 0x4C4F_4F4B_5354_524D;

impl ShotPlan {
    /// Simulates shot `index` of `scenario` and places the camera.
    ///
    /// Placement (per shot): the ball's whole path over the clip is centred horizontally (plus a random
    /// shift of up to ±30 px where there is room) and the surface line's origin sits at 78 % of the frame
    /// height (a look draws it from 62–85 %), moved down (to at most 94 %) when the path would otherwise
    /// leave the top of the frame. A look's frame grows (then its ball shrinks) within the `[look]` ranges
    /// until the path fits.
    pub fn new(scenario: &Scenario, index: usize) -> Result<ShotPlan, RenderError> {
        if index >= scenario.shots.len() {
            return Err(RenderError::InvalidValue {
                origin: scenario.origin.clone(),
                field: "shots".into(),
                value: index.to_string(),
                reason: format!("no shot with that index (there are {})", scenario.shots.len()),
            });
        }
        let (shot, overrides) = scenario.shot_physics(index);
        let shot = &shot;
        let clip = scenario.clip_name(index);
        let model_err = |source: ModelError| RenderError::Model {
            origin: scenario.origin.clone(),
            context: format!("shot {clip}"),
            source: Box::new(source),
        };
        let spec = scenario.model_spec_with(&shot.effects, &shot.surface, &overrides)?;
        let model = spec.build(Some(&shot.surface)).map_err(model_err)?;
        let settings = spec.settings(Some(&shot.surface)).map_err(model_err)?;
        let texture = scenario
            .surface(&shot.surface)
            .map(|s| s.texture)
            .unwrap_or(crate::Texture::Clay);
        let seed = derive(scenario.seed, index as u64);
        let r_m = scenario.ball.diameter_m / 2.0;
        let mut look_rng = Rng::new(derive(seed, LOOK_STREAM));
        let mut look = scenario.look.as_ref().map(|l| l.draw(&mut look_rng, texture));
        let mut cam = scenario.camera.clone();
        if let Some(l) = &look {
            l.apply_to(&mut cam, r_m);
        }
        let mut rng = Rng::new(seed);
        let flight = Flight::simulate(&model, shot, scenario, &cam, &mut rng).map_err(model_err)?;
        let roll_effect = model.effect("camera_roll").map(|e| e.params()[0]).unwrap_or(0.0);
        let roll_deg = cam.roll_deg + roll_effect;
        if let (Some(l), Some(spec)) = (&mut look, &scenario.look) {
            fit_look_frame(l, spec, &mut cam, &flight, roll_deg.to_radians(), r_m);
        }
        let theta0 = rng.range(0.0, std::f64::consts::TAU);
        let line_frac = look.as_ref().map_or(0.78, |l| l.draft.line_frac);
        let placed = PlacedPath::new(&cam, roll_deg, line_frac, &flight, r_m, &mut rng);
        let dir = cam.downslope.sign();
        let phi = roll_deg.to_radians();
        let alpha: Vec<f64> = flight
            .mid
            .samples
            .iter()
            .map(|s| dir * (theta0 + s.state.theta - phi))
            .collect();
        let frames = frame_truths(&flight, &placed, &cam, theta0, r_m);
        let truth = shot_truth(shot, clip, seed, &flight, &placed, &cam, &settings);
        if let Some(l) = &mut look {
            place_look_items(l, &mut look_rng, &frames, &flight, &placed, &cam);
        }
        Ok(ShotPlan {
            index,
            truth,
            frames,
            look,
            texture,
            geom: placed.geom,
            subs: placed.subs,
            alpha,
            delta_max_px: flight.impact.delta_max / cam.scale_m_per_px,
            flicker_phase: rng.range(0.0, std::f64::consts::TAU),
            camera: cam,
            session_seed: scenario.seed,
        })
    }

    /// The camera of this shot: the scenario's, with a look's frame size, scale, roll, down-slope, noise,
    /// vignetting, bits, format and naming.
    pub fn camera(&self) -> &crate::Camera {
        &self.camera
    }

    /// The seed of frame `frame`'s noise.
    pub(crate) fn frame_seed(&self, frame: usize) -> u64 {
        derive(self.truth.seed, 1 + frame as u64)
    }
}

/// A shot simulated at its frames' times: the impact, and the states at every frame's mid-exposure time
/// (the truth) and at its sub-exposure times (the motion blur).
struct Flight {
    /// Time of the first frame's mid-exposure since the release, s.
    t0: f64,
    /// Number of frames.
    frames: usize,
    impact: Impact,
    /// One sample per frame.
    mid: Simulation,
    /// `blur_samples` samples per frame.
    sub: Simulation,
}

impl Flight {
    /// The clip starts `pre_contact_s` before the touch plus a random 0–2 frames (one draw of `rng`) and
    /// ends `post_separation_s` after separation.
    fn simulate(
        model: &Model,
        shot: &crate::Shot,
        scenario: &Scenario,
        cam: &crate::Camera,
        rng: &mut Rng,
    ) -> Result<Flight, ModelError> {
        let beta = shot.angle_deg.to_radians();
        let opts = SimOptions::default();
        let impact = simulate_drop(model, beta, shot.drop_height_m, &[], &opts)?.impact;
        let dt = 1.0 / cam.fps;
        let half = cam.exposure_s / 2.0;
        let t0 = (impact.t_touch - scenario.pre_contact_s - rng.uniform() * 2.0 * dt).max(half + MIN_T0);
        let t_end = impact.t_separation + scenario.post_separation_s;
        let n = ((t_end - t0) * cam.fps).floor().max(0.0) as usize + 1;
        let k = cam.blur_samples as usize;
        let mids: Vec<f64> = (0..n).map(|i| t0 + i as f64 / cam.fps).collect();
        let subs_t: Vec<f64> = mids
            .iter()
            .flat_map(|&t| (0..k).map(move |j| t + ((j as f64 + 0.5) / k as f64 - 0.5) * cam.exposure_s))
            .collect();
        let mid = simulate_drop(model, beta, shot.drop_height_m, &mids, &opts)?;
        let sub = simulate_drop(model, beta, shot.drop_height_m, &subs_t, &opts)?;
        Ok(Flight {
            t0,
            frames: n,
            impact,
            mid,
            sub,
        })
    }
}

/// Grows a look's frame (then shrinks its ball) until the path, seen rolled by `phi` rad, fits; sets the
/// camera's frame size and scale to the result.
fn fit_look_frame(l: &mut Look, spec: &LookSpec, cam: &mut crate::Camera, flight: &Flight, phi: f64, r_m: f64) {
    // The path's extent in the rolled frame, metres: the frame must hold it at the look's scale.
    let (c, s) = (phi.cos(), phi.sin());
    let (mut xmin, mut xmax, mut top) = (f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
    for smp in flight.sub.samples.iter().chain(&flight.mid.samples) {
        let xc = c * smp.state.x + s * smp.state.y;
        let yc = -s * smp.state.x + c * smp.state.y;
        xmin = xmin.min(xc);
        xmax = xmax.max(xc);
        top = top.max(yc + r_m);
    }
    l.fit_frame(
        spec,
        PathExtent {
            width_m: xmax - xmin,
            top_m: top,
        },
        r_m,
    );
    cam.width = l.width_px;
    cam.height = l.height_px;
    cam.scale_m_per_px = r_m / l.ball_radius_px;
}

/// The camera placed over a shot's path, and the ball's centres in the image.
struct PlacedPath {
    geom: Geometry,
    /// Total camera roll, degrees.
    roll_deg: f64,
    /// Ball radius, pixels.
    r_px: f64,
    /// Ball centres at the sub-exposure times, pixels.
    subs: Vec<(f64, f64)>,
    /// Ball centres at the frames' mid-exposure times, pixels.
    centres: Vec<(f64, f64)>,
}

impl PlacedPath {
    /// The path centred horizontally (plus a random shift of up to ±30 px where there is room: one draw of
    /// `rng`), the surface line's origin at `line_frac` of the frame height, moved down (to at most 94 %)
    /// when the path would otherwise leave the top of the frame.
    fn new(cam: &crate::Camera, roll_deg: f64, line_frac: f64, flight: &Flight, r_m: f64, rng: &mut Rng) -> PlacedPath {
        let phi = roll_deg.to_radians();
        let scale = cam.scale_m_per_px;
        let r_px = r_m / scale;
        let mut geom = Geometry {
            scale,
            cos: phi.cos(),
            sin: phi.sin(),
            dir: cam.downslope.sign(),
            tx: 0.0,
            ty: 0.0,
        };
        let to_px = |samples: &[Sample]| -> Vec<(f64, f64)> {
            samples.iter().map(|s| geom.to_px(s.state.x, s.state.y)).collect()
        };
        let mut subs = to_px(&flight.sub.samples);
        let mut centres = to_px(&flight.mid.samples);
        let (w, h) = (cam.width as f64, cam.height as f64);
        let (mut xmin, mut xmax, mut ymin) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY);
        for &(x, y) in subs.iter().chain(&centres) {
            xmin = xmin.min(x - r_px);
            xmax = xmax.max(x + r_px);
            ymin = ymin.min(y - r_px);
        }
        let room = ((w - (xmax - xmin)) / 2.0 - 8.0).clamp(0.0, 30.0);
        geom.tx = (w - 1.0) / 2.0 - (xmin + xmax) / 2.0 + rng.range(-room, room);
        geom.ty = line_frac * h;
        if ymin + geom.ty < 6.0 {
            geom.ty = (6.0 - ymin).min(0.94 * h);
        }
        for p in subs.iter_mut().chain(centres.iter_mut()) {
            p.0 += geom.tx;
            p.1 += geom.ty;
        }
        PlacedPath {
            geom,
            roll_deg,
            r_px,
            subs,
            centres,
        }
    }
}

/// Where a disc of radius `r` at (x, y) px lies with respect to a `w` × `h` frame.
fn visibility(x: f64, y: f64, r: f64, w: f64, h: f64) -> Visibility {
    let (l, r, t, b) = (x - r, x + r, y - r, y + r);
    if l >= -0.5 && r <= w - 0.5 && t >= -0.5 && b <= h - 0.5 {
        Visibility::Full
    } else if r < -0.5 || l > w - 0.5 || b < -0.5 || t > h - 0.5 {
        Visibility::Absent
    } else {
        Visibility::CutByBorder
    }
}

/// The truth of every frame; `theta0` is the ball's random initial orientation, rad.
fn frame_truths(flight: &Flight, placed: &PlacedPath, cam: &crate::Camera, theta0: f64, r_m: f64) -> Vec<FrameTruth> {
    let (w, h) = (cam.width as f64, cam.height as f64);
    let r_px = placed.r_px;
    flight
        .mid
        .samples
        .iter()
        .zip(&placed.centres)
        .enumerate()
        .map(|(i, (s, &(x, y)))| FrameTruth {
            frame: i,
            t_s: i as f64 / cam.fps,
            x_px: x,
            y_px: y,
            r_px,
            x_m: s.state.x,
            y_m: s.state.y,
            theta_rad: theta0 + s.state.theta,
            phase: s.phase,
            visible: visibility(x, y, r_px, w, h),
            delta_m: (r_m - s.state.y).max(0.0),
        })
        .collect()
}

/// Every effect of the model with its parameter values, as a JSON object text.
fn effects_json(settings: &[(ParamRef, ParamSetting)]) -> String {
    let mut effects = serde_json::Map::new();
    for (r, s) in settings {
        let entry = effects
            .entry(r.effect.clone())
            .or_insert_with(|| serde_json::Value::Object(serde_json::Map::new()));
        if let serde_json::Value::Object(m) = entry {
            m.insert(r.param.clone(), serde_json::json!(s.value));
        }
    }
    serde_json::Value::Object(effects).to_string()
}

/// The shot's truth row (times since the clip's first frame).
fn shot_truth(
    shot: &crate::Shot,
    clip: String,
    seed: u64,
    flight: &Flight,
    placed: &PlacedPath,
    cam: &crate::Camera,
    settings: &[(ParamRef, ParamSetting)],
) -> ShotTruth {
    let find = |e: &str, p: &str| {
        settings
            .iter()
            .find(|(r, _)| r.effect == e && r.param == p)
            .map(|(_, s)| s.value)
    };
    let (impact, t0, geom) = (&flight.impact, flight.t0, placed.geom);
    let xcen = (cam.width as f64 - 1.0) / 2.0;
    let surface_y_px = geom.ty + geom.sin * (xcen - geom.tx) / (geom.dir * geom.cos);
    ShotTruth {
        clip,
        surface: shot.surface.clone(),
        angle_deg: shot.angle_deg,
        drop_height_m: shot.drop_height_m,
        repeat: shot.repeat,
        seed,
        frames: flight.frames,
        v_in_t: impact.state_in.vx,
        v_in_n: impact.state_in.vy,
        v_out_t: impact.state_out.vx,
        v_out_n: impact.state_out.vy,
        cor: impact.restitution,
        mu_eff: impact.effective_friction,
        t_touch_s: impact.t_touch - t0,
        t_max_s: impact.t_max_compression - t0,
        t_sep_s: impact.t_separation - t0,
        contact_ms: impact.contact_time() * 1e3,
        delta_max_m: impact.delta_max,
        spin_in: impact.omega_in(),
        spin_out: impact.omega_out(),
        rolling_at_separation: impact.rolling_at_separation,
        scale_m_per_px: geom.scale,
        r_px: placed.r_px,
        surface_y_px,
        surface_tilt_deg: -geom.dir * placed.roll_deg,
        roll_deg: placed.roll_deg,
        downslope: cam.downslope.as_str().to_string(),
        k: find("spring", "k"),
        b: find("damping", "b"),
        mu: find("coulomb", "mu"),
        effects_json: effects_json(settings),
        extra_effects: shot.effects.clone(),
    }
}

/// Places a look's clutter, hot spots and tape strip once the path is known, around the frames in contact
/// (or, for a contact shorter than a frame, the frame nearest the touch).
fn place_look_items(
    l: &mut Look,
    look_rng: &mut Rng,
    frames: &[FrameTruth],
    flight: &Flight,
    placed: &PlacedPath,
    cam: &crate::Camera,
) {
    let mut contact: Vec<(f64, f64)> = frames
        .iter()
        .filter(|f| f.phase != Phase::Flight)
        .map(|f| (f.x_px, f.y_px))
        .collect();
    if contact.is_empty() {
        let t = flight.impact.t_touch - flight.t0;
        if let Some(f) = frames
            .iter()
            .min_by(|a, b| (a.t_s - t).abs().total_cmp(&(b.t_s - t).abs()))
        {
            contact.push((f.x_px, f.y_px));
        }
    }
    l.place(
        look_rng,
        &Placement {
            geom: placed.geom,
            width: cam.width as f64,
            height: cam.height as f64,
            r_px: placed.r_px,
            path: &placed.subs,
            contact: &contact,
        },
    );
}
