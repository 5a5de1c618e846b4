//! Flight → contact → flight, integrated with events at every phase and stick/slip switch.

use crate::effects::{Context, Loads, Observation, Phase};
use crate::integrator::{N_HISTORY, N_STATE, Step, Y, find_root};
use crate::{Model, ModelError, State};
use serde::{Deserialize, Serialize};
use std::cell::Cell;

/// Integration settings.
///
/// The defaults hold the paper's anchor (e, contact time) to better than 1e-8 relative and conserve
/// energy of a purely elastic impact to better than 1e-9 relative; events are located to 1e-14 s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimOptions {
    /// Relative tolerance of each step's local error.
    pub rtol: f64,
    /// Absolute tolerance of each step's local error, SI units of each component.
    pub atol: f64,
    /// Longest step, s (keeps the dense output between frames accurate in long flights).
    pub max_step_s: f64,
    /// Longest simulated time to wait for the ball to reach the surface, s.
    pub max_time_s: f64,
    /// Most steps allowed in one simulation.
    pub max_steps: usize,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            rtol: 1e-10,
            atol: 1e-12,
            max_step_s: 2e-3,
            max_time_s: 10.0,
            max_steps: 200_000,
        }
    }
}

/// One sampled instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// True state in the local frame.
    pub state: State,
    /// What the camera measures (after measurement effects such as camera roll).
    pub observed: Observation,
    /// Phase at this instant.
    pub phase: Phase,
    /// True if the contact point is sticking (the ball rolls); with a compliant patch
    /// (`tangential_spring`), true while the patch holds (the ball's contact point may still move).
    pub sticking: bool,
    /// Tangential displacement of the contact patch `u_t = ∫ slip dt` since touch, m.
    #[serde(default)]
    pub u_t: f64,
    /// Displacement stored in the patch's tangential spring, m (0 without a tangential compliance): the
    /// tangential contact force is `−u/λ − c_t·slip` at every instant of the contact.
    #[serde(default)]
    pub patch_displacement: f64,
}

/// What happened at a stick/slip switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SlipEventKind {
    /// The slip stopped and friction can hold it: rolling starts.
    StartsSticking,
    /// Friction can no longer hold the contact point: sliding starts.
    StartsSliding,
    /// The slip passed through zero and changed direction.
    Reverses,
}

/// A stick/slip switch.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SlipEvent {
    /// Time, s.
    pub t: f64,
    /// What happened.
    pub kind: SlipEventKind,
}

/// The outputs of one impact (true local frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Impact {
    /// Time the ball touched the surface, s.
    pub t_touch: f64,
    /// Time of maximum compression, s.
    pub t_max_compression: f64,
    /// Time the ball left the surface, s.
    pub t_separation: f64,
    /// State at touch.
    pub state_in: State,
    /// State at separation.
    pub state_out: State,
    /// Coefficient of restitution `|v_n,out / v_n,in|` at the contact boundaries.
    pub restitution: f64,
    /// Effective friction, the paper's momentum ratio `−Δv_t / Δv_n` over the contact (positive when the
    /// contact slows the down-slope motion).
    pub effective_friction: f64,
    /// Maximum penetration δ_max, m.
    pub delta_max: f64,
    /// Normal force at maximum compression, N.
    pub force_max: f64,
    /// Penetration left at separation, m (non-zero with a plastic dent or damping in restitution).
    pub residual_depth: f64,
    /// Stick/slip switches during the contact.
    pub slip_events: Vec<SlipEvent>,
    /// True if the contact point was sticking (rolling) at separation.
    pub rolling_at_separation: bool,
}

impl Impact {
    /// Contact time, s.
    pub fn contact_time(&self) -> f64 {
        self.t_separation - self.t_touch
    }
    /// Spin at touch, rad/s.
    pub fn omega_in(&self) -> f64 {
        self.state_in.omega
    }
    /// Spin at separation, rad/s.
    pub fn omega_out(&self) -> f64 {
        self.state_out.omega
    }
}

/// A simulated shot: the trajectory at the requested times and the impact's outputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Simulation {
    /// One sample per requested time, in order.
    pub samples: Vec<Sample>,
    /// The impact.
    pub impact: Impact,
}

/// Component `i` of the contact's history in `y` (0 when the model does not integrate it).
#[inline]
fn history<const N: usize>(y: &Y<N>, i: usize) -> f64 {
    y.get(N_STATE + i).copied().unwrap_or(0.0)
}

/// Stick/slip switches allowed at one instant before the contact is reported as undecidable there.
const MAX_SWITCHES_AT_ONE_INSTANT: usize = 16;

/// Slip speed below which a slip against the sliding direction is taken as rounding, m/s.
const SLIP_EPS: f64 = 1e-12;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Friction {
    /// No friction at all (μ = 0).
    None,
    /// Sliding with slip direction σ = ±1.
    Slip(f64),
    /// Sticking: the contact point does not slip.
    Stick,
}

#[derive(Debug, Clone, Copy)]
struct Mode {
    phase: Phase,
    friction: Friction,
    delta_max: f64,
    force_max: f64,
    /// True when the contact patch is compliant: `Stick` then means "the patch holds" (force from its
    /// spring) and `Slip` "the patch slides at the Coulomb limit".
    patch: bool,
    /// u_t at which the patch's spring is relaxed while it holds: its displacement is `u_t − offset`.
    patch_offset: f64,
    /// True while a compliant patch slides on its limit because holding it failed at the instant it
    /// began (the held force exceeds the limit by rounding where both vanish, as at separation): its
    /// stop event then counts only a real crossing, not its value at the start.
    riding_limit: bool,
}

/// Quantities the events are made of.
#[derive(Debug, Clone, Copy, Default)]
struct Aux {
    normal: f64,
    slip: f64,
    /// Rigid contact: the friction force that keeps the slip at zero. Compliant patch: the force of its
    /// spring (what the patch transmits while it holds), N.
    required_friction: f64,
    friction_limit: f64,
    /// Compliant patch sliding in direction σ: `σ·(k_t·slip + c_t·d(slip)/dt) − μ·dP/dt`, how much faster
    /// the spring's force would grow than the limit if the patch held (N/s); it falls through zero when
    /// the patch stops sliding.
    patch_slide_rate: f64,
    /// Displacement stored in the patch's spring, m.
    patch_u: f64,
}

struct Dynamics<'a> {
    model: &'a Model,
    incline: f64,
    sin_b: f64,
    cos_b: f64,
    mu: f64,
    inertia: f64,
    /// 1/m + R²/I: how fast a tangential contact force changes the slip.
    slip_mobility: f64,
    /// Tangential stiffness k_t = 1/λ of a compliant contact patch, N/m (unused when rigid).
    patch_stiffness: f64,
    /// Damping of the patch's tangential spring, N·s/m.
    patch_damping: f64,
    /// True if the patch is compliant (λ ≠ 0) and friction can load it (μ ≠ 0).
    patch: bool,
}

/// Time step of the central difference that gives dP/dt for the compliant patch's slide → hold switch, s
/// (relative error ≈ (ε/T)² + 1e-16·T/ε for a contact of duration T: below 1e-9 for T between 10 µs and
/// 10 ms).
const RATE_EPS_S: f64 = 1e-9;

impl<'a> Dynamics<'a> {
    fn new(model: &'a Model, incline: f64) -> Self {
        let inertia = model.inertia();
        let (m, r) = (model.ball.mass_kg, model.ball.radius_m);
        let mu = model.friction_coefficient();
        let compliance = model.tangential_compliance();
        Dynamics {
            model,
            incline,
            sin_b: incline.sin(),
            cos_b: incline.cos(),
            mu,
            inertia,
            slip_mobility: 1.0 / m + r * r / inertia,
            patch_stiffness: 1.0 / compliance,
            patch_damping: model.tangential_damping(),
            patch: compliance != 0.0 && mu != 0.0,
        }
    }

    /// The total normal force at (`t`, `y`), N (not clipped at zero: its rate is wanted while it is still
    /// positive, including in the last instants before it vanishes).
    fn normal_load<const N: usize>(&self, t: f64, y: &Y<N>, mode: &Mode) -> f64 {
        let ball = &self.model.ball;
        let state = State::from_array(*y);
        let ctx = Context {
            delta_max: mode.delta_max,
            force_max: mode.force_max,
            u_t: history(y, 0),
            delta_int: history(y, 1),
            ..Context::of(t, &state, mode.phase, ball, self.model.gravity, self.incline)
        };
        self.model.effects().iter().map(|e| e.normal_force(&ctx)).sum()
    }

    fn eval<const N: usize>(&self, t: f64, y: &Y<N>, mode: &Mode) -> (Y<N>, Aux) {
        let ball = &self.model.ball;
        let (m, r) = (ball.mass_kg, ball.radius_m);
        let state = State::from_array(*y);
        let mut ctx = Context {
            delta_max: mode.delta_max,
            force_max: mode.force_max,
            u_t: history(y, 0),
            delta_int: history(y, 1),
            ..Context::of(t, &state, mode.phase, ball, self.model.gravity, self.incline)
        };
        let slip = ctx.slip;
        let effects = self.model.effects();
        let normal = if mode.phase.in_contact() {
            effects.iter().map(|e| e.normal_force(&ctx)).sum()
        } else {
            0.0
        };
        ctx.normal_force = normal;
        let mut loads = Loads::default();
        for e in effects {
            loads.add(&e.loads(&ctx));
        }
        let g = self.model.gravity;
        let ax_other = g * self.sin_b + (loads.force_x + loads.tangential) / m;
        let ay = -g * self.cos_b + (loads.force_y + normal) / m;
        let alpha_other = (loads.torque + r * loads.tangential) / self.inertia;
        let mut aux = Aux {
            normal,
            slip,
            ..Aux::default()
        };
        let in_contact = mode.phase.in_contact();
        let friction = if in_contact {
            aux.friction_limit = self.mu * normal.max(0.0);
            if mode.patch {
                let (k, c) = (self.patch_stiffness, self.patch_damping);
                match mode.friction {
                    Friction::None => 0.0,
                    Friction::Slip(sigma) => {
                        // The spring's displacement limited so that it transmits exactly the limit.
                        aux.patch_u = (sigma * aux.friction_limit - c * slip) / k;
                        -sigma * aux.friction_limit
                    }
                    Friction::Stick => {
                        aux.patch_u = history(y, 0) - mode.patch_offset;
                        aux.required_friction = -(k * aux.patch_u + c * slip);
                        aux.required_friction
                    }
                }
            } else {
                aux.required_friction = -(ax_other + r * alpha_other) / self.slip_mobility;
                match mode.friction {
                    Friction::None => 0.0,
                    Friction::Slip(sigma) => -sigma * aux.friction_limit,
                    Friction::Stick => aux.required_friction,
                }
            }
        } else {
            0.0
        };
        let mut dy = [0.0; N];
        dy[..N_STATE].copy_from_slice(&[
            state.vx,
            state.vy,
            state.omega,
            ax_other + friction / m,
            ay,
            alpha_other + r * friction / self.inertia,
        ]);
        if N == N_HISTORY && in_contact {
            dy[N_STATE..].copy_from_slice(&[slip, ctx.delta]);
        }
        if let (true, Friction::Slip(sigma)) = (mode.patch && in_contact, mode.friction) {
            let slip_rate = dy[3] + r * dy[5];
            let shifted = |e: f64| -> Y<N> { std::array::from_fn(|i| y[i] + e * dy[i]) };
            // Contact laws bend at δ = 0: the difference stays on the side δ > 0 (central while δ lasts
            // longer than ±ε, forward at the touch itself).
            let (delta, rate) = (ctx.delta, ctx.delta_dot.abs());
            let load_rate = if delta > 0.0 {
                let eps = if rate > 0.0 {
                    RATE_EPS_S.min(0.25 * delta / rate)
                } else {
                    RATE_EPS_S
                };
                (self.normal_load(t + eps, &shifted(eps), mode) - self.normal_load(t - eps, &shifted(-eps), mode))
                    / (2.0 * eps)
            } else {
                (self.normal_load(t + RATE_EPS_S, &shifted(RATE_EPS_S), mode) - normal) / RATE_EPS_S
            };
            aux.patch_slide_rate =
                sigma * (self.patch_stiffness * slip + self.patch_damping * slip_rate) - self.mu * load_rate;
        }
        (dy, aux)
    }
}

/// Most events active at once.
const MAX_EVENTS: usize = 3;

/// An event function, falling through zero when the event happens.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Event {
    Touch,
    MaxCompression,
    ForceVanishes,
    PenetrationVanishes,
    SlipStops,
    GripLost,
}

impl Event {
    fn value<const N: usize>(self, y: &Y<N>, aux: &Aux, mode: &Mode, r: f64) -> f64 {
        match self {
            Event::Touch => y[1] - r,
            Event::MaxCompression => -y[4],
            Event::ForceVanishes => aux.normal,
            Event::PenetrationVanishes => r - y[1],
            Event::SlipStops => match mode.friction {
                Friction::Slip(_) if mode.patch => aux.patch_slide_rate,
                Friction::Slip(sigma) => sigma * aux.slip,
                _ => 1.0,
            },
            Event::GripLost => aux.friction_limit - aux.required_friction.abs(),
        }
    }

    /// The phase a phase event starts (none for stick/slip events).
    fn next_phase(self) -> Option<Phase> {
        match self {
            Event::Touch => Some(Phase::Compression),
            Event::MaxCompression => Some(Phase::Restitution),
            Event::ForceVanishes | Event::PenetrationVanishes => Some(Phase::Flight),
            Event::SlipStops | Event::GripLost => None,
        }
    }

    fn active(mode: &Mode) -> &'static [Event] {
        use Event::*;
        match (mode.phase, mode.friction) {
            (Phase::Flight, _) => &[Touch],
            (Phase::Compression, Friction::Slip(_)) => &[MaxCompression, SlipStops],
            (Phase::Compression, Friction::Stick) => &[MaxCompression, GripLost],
            (Phase::Compression, Friction::None) => &[MaxCompression],
            (Phase::Restitution, Friction::Slip(_)) => &[ForceVanishes, PenetrationVanishes, SlipStops],
            (Phase::Restitution, Friction::Stick) => &[ForceVanishes, PenetrationVanishes, GripLost],
            (Phase::Restitution, Friction::None) => &[ForceVanishes, PenetrationVanishes],
        }
    }
}

/// The values of the active `events` at state `y` (with its quantities `aux`), in the order listed.
fn event_values<const N: usize>(events: &[Event], y: &Y<N>, aux: &Aux, mode: &Mode, r: f64) -> [f64; MAX_EVENTS] {
    let mut g = [0.0; MAX_EVENTS];
    for (gk, e) in g.iter_mut().zip(events) {
        *gk = e.value(y, aux, mode, r);
    }
    g
}

/// A compliant patch's switch leaves the new mode's stick/slip event function at zero (the force is
/// continuous): count it as just positive so that the next crossing is seen, and one at once (the other
/// mode was due right away) is found at the start.
fn patch_switch_just_positive(g: &mut [f64; MAX_EVENTS], events: &[Event]) {
    for (gk, e) in g.iter_mut().zip(events) {
        if matches!(e, Event::SlipStops | Event::GripLost) && *gk <= 0.0 {
            *gk = f64::MIN_POSITIVE;
        }
    }
}

/// An accepted step must end on finite numbers and, in contact, with the centre above the surface.
fn check_accepted<const N: usize>(step: &Step<N>, mode: &Mode, r: f64) -> Result<(), ModelError> {
    let (t, h) = (step.t0, step.h);
    if !step.y1.iter().all(|v| v.is_finite()) {
        return Err(ModelError::NonFinite {
            t_s: t + h,
            phase: mode.phase.name(),
        });
    }
    if mode.phase.in_contact() && step.y1[1] < 0.0 {
        return Err(ModelError::SankThrough {
            t_s: t + h,
            depth_m: r - step.y1[1],
        });
    }
    Ok(())
}

impl Dynamics<'_> {
    /// The earliest event whose function falls through zero in `step` (from `g` at its start to `g1` at its
    /// end), located on the step's dense output: its time and which.
    fn earliest_event<const N: usize>(
        &self,
        events: &[Event],
        step: &Step<N>,
        g: &[f64; MAX_EVENTS],
        g1: &[f64; MAX_EVENTS],
        m: &Mode,
        r: f64,
    ) -> Option<(f64, Event)> {
        let (t, h) = (step.t0, step.h);
        let mut hit: Option<(f64, Event)> = None;
        for (k, ev) in events.iter().enumerate() {
            if g[k] > 0.0 && g1[k] <= 0.0 {
                let gf = |tt: f64| {
                    let yy = step.at(tt);
                    let a = self.eval(tt, &yy, m).1;
                    ev.value(&yy, &a, m, r)
                };
                let te = find_root(gf, t, g[k], t + h, g1[k], 1e-14 * t.abs().max(1e-3));
                // Phase events are listed first and win ties, so a slip event at the same instant as
                // separation does not hide the separation.
                if hit.is_none_or(|(th, _)| te < th - 1e-13 * th.abs().max(1e-3)) {
                    hit = Some((te, *ev));
                }
            }
        }
        hit
    }
}

/// Simulates one shot of `model` on a surface inclined by `incline_rad`, from `start` at time `t0` (s),
/// through the impact, returning the trajectory at `times` (s, ascending, ≥ `t0`) and the impact's outputs.
///
/// The ball must start in flight (at or above the surface). The run continues past the last requested time
/// until the ball has left the surface, so the outputs are always complete.
pub fn simulate(
    model: &Model,
    incline_rad: f64,
    t0: f64,
    start: State,
    times: &[f64],
    opts: &SimOptions,
) -> Result<Simulation, ModelError> {
    let r = model.ball.radius_m;
    let y0: Y<N_STATE> = start.to_array();
    if !y0.iter().all(|v| v.is_finite()) || !t0.is_finite() || !incline_rad.is_finite() {
        return Err(ModelError::BadStart(
            "the start state, time or incline is not finite".into(),
        ));
    }
    if start.y < r - 1e-9 {
        return Err(ModelError::BadStart(format!(
            "the ball starts {:.3e} m inside the surface (y = {} m < R = {} m)",
            r - start.y,
            start.y,
            r
        )));
    }
    if let Some(w) = times.windows(2).find(|w| w[1] < w[0] || w[1].is_nan()) {
        return Err(ModelError::BadStart(format!(
            "sample times are not ascending ({} then {})",
            w[0], w[1]
        )));
    }
    if let Some(&first) = times.first()
        && (first < t0 || first.is_nan())
    {
        return Err(ModelError::BadStart(format!(
            "sample time {first} s is before the start time {t0} s"
        )));
    }
    if !(model.ball.mass_kg > 0.0 && r > 0.0 && model.inertia() > 0.0) {
        return Err(ModelError::BadStart(
            "the ball needs a positive mass, radius and moment of inertia".into(),
        ));
    }
    let mut run = Run::new(model, incline_rad, opts, times);
    if model.uses_contact_history() {
        run.go::<N_HISTORY>(t0, start.to_array())
    } else {
        run.go::<N_STATE>(t0, start.to_array())
    }
}

/// Simulates a ball released at rest `drop_height_m` (m, measured vertically from the ball's bottom to the
/// point it hits) above a surface inclined by `incline_rad`; t = 0 at release.
pub fn simulate_drop(
    model: &Model,
    incline_rad: f64,
    drop_height_m: f64,
    times: &[f64],
    opts: &SimOptions,
) -> Result<Simulation, ModelError> {
    if !(drop_height_m >= 0.0 && drop_height_m.is_finite()) {
        return Err(ModelError::BadStart(format!(
            "drop height {drop_height_m} m must be ≥ 0"
        )));
    }
    let (s, c) = incline_rad.sin_cos();
    let start = State::flying(-drop_height_m * s, model.ball.radius_m + drop_height_m * c, 0.0, 0.0);
    simulate(model, incline_rad, 0.0, start, times, opts)
}

struct Run<'a> {
    dynamics: Dynamics<'a>,
    opts: &'a SimOptions,
    recorder: Recorder<'a>,
    steps: usize,
}

/// Collects the requested samples as the integration passes them.
struct Recorder<'a> {
    model: &'a Model,
    times: &'a [f64],
    samples: Vec<Sample>,
}

impl Recorder<'_> {
    fn record<const N: usize>(&mut self, t: f64, y: &Y<N>, patch_u: f64, mode: &Mode) {
        let state = State::from_array(*y);
        let mut observed = Observation::from(state);
        for e in self.model.effects() {
            e.observe(&mut observed);
        }
        self.samples.push(Sample {
            t,
            state,
            observed,
            phase: mode.phase,
            sticking: mode.friction == Friction::Stick,
            u_t: history(y, 0),
            patch_displacement: patch_u,
        });
    }

    /// Records every requested time not yet recorded up to `t_hi`, with states from `at` and the patch's
    /// displacement from `patch`.
    fn record_until<const N: usize>(
        &mut self,
        t_hi: f64,
        mode: &Mode,
        at: impl Fn(f64) -> Y<N>,
        patch: impl Fn(f64, &Y<N>) -> f64,
    ) {
        while let Some(&t) = self.times.get(self.samples.len()) {
            if t > t_hi {
                break;
            }
            let y = at(t);
            let u = patch(t, &y);
            self.record(t, &y, u, mode);
        }
    }
}

impl Dynamics<'_> {
    /// The displacement stored in the patch's spring at (`t`, `y`), m (0 unless the patch is compliant
    /// and in contact).
    fn patch_displacement<const N: usize>(&self, t: f64, y: &Y<N>, mode: &Mode) -> f64 {
        if !(mode.patch && mode.phase.in_contact()) {
            return 0.0;
        }
        match mode.friction {
            Friction::Stick => history(y, 0) - mode.patch_offset,
            _ => self.eval(t, y, mode).1.patch_u,
        }
    }
}

impl<'a> Run<'a> {
    fn new(model: &'a Model, incline: f64, opts: &'a SimOptions, times: &'a [f64]) -> Self {
        let recorder = Recorder {
            model,
            times,
            samples: Vec::with_capacity(times.len()),
        };
        Run {
            dynamics: Dynamics::new(model, incline),
            opts,
            recorder,
            steps: 0,
        }
    }

    fn go<const N: usize>(&mut self, t0: f64, y0: Y<N>) -> Result<Simulation, ModelError> {
        let r = self.dynamics.model.ball.radius_m;
        let mut mode = Mode {
            phase: Phase::Flight,
            friction: Friction::None,
            delta_max: 0.0,
            force_max: 0.0,
            patch: self.dynamics.patch,
            patch_offset: 0.0,
            riding_limit: false,
        };
        self.recorder.record_until(t0, &mode, |_| y0, |_, _| 0.0);
        let (mut t, mut y) = (t0, y0);
        // Touching already, moving in: the contact starts now.
        let start_in_contact = y0[1] <= r && y0[4] < 0.0;
        if y0[1] <= r && !start_in_contact {
            return Err(ModelError::BadStart(
                "the ball starts on the surface without moving into it".into(),
            ));
        }
        if !start_in_contact {
            let deadline = t0 + self.opts.max_time_s;
            (t, y) = self.integrate(t, y, &mut mode, Some(deadline))?;
            if mode.phase == Phase::Flight {
                return Err(ModelError::NoImpact {
                    max_time_s: self.opts.max_time_s,
                });
            }
        } else {
            mode.phase = Phase::Compression;
        }
        // Touch: the contact's history starts.
        y[N_STATE..].fill(0.0);
        let (t_touch, state_in) = (t, State::from_array(y));
        mode.friction = self.initial_friction(t, &y, &mode);
        let mut slip_events = Vec::new();
        (t, y) = self.contact(t, y, &mut mode, Phase::Compression, &mut slip_events)?;
        let t_max = t;
        // Maximum compression: remember the turning point, then restitution.
        mode.phase = Phase::Restitution;
        mode.delta_max = r - y[1];
        mode.force_max = self.dynamics.eval(t, &y, &mode).1.normal;
        (t, y) = self.contact(t, y, &mut mode, Phase::Restitution, &mut slip_events)?;
        let (t_sep, state_out) = (t, State::from_array(y));
        let rolling = mode.friction == Friction::Stick;
        mode.phase = Phase::Flight;
        mode.friction = Friction::None;
        if let Some(&last) = self.recorder.times.last()
            && last > t
        {
            self.integrate(t, y, &mut mode, Some(last))?;
        }
        let dvt = state_out.vx - state_in.vx;
        let dvn = state_out.vy - state_in.vy;
        let impact = Impact {
            t_touch,
            t_max_compression: t_max,
            t_separation: t_sep,
            state_in,
            state_out,
            restitution: (state_out.vy / state_in.vy).abs(),
            effective_friction: -dvt / dvn,
            delta_max: mode.delta_max,
            force_max: mode.force_max,
            residual_depth: (r - state_out.y).max(0.0),
            slip_events,
            rolling_at_separation: rolling,
        };
        Ok(Simulation {
            samples: std::mem::take(&mut self.recorder.samples),
            impact,
        })
    }

    fn initial_friction<const N: usize>(&self, t: f64, y: &Y<N>, mode: &Mode) -> Friction {
        if self.dynamics.mu == 0.0 {
            return Friction::None;
        }
        if mode.patch {
            // The patch holds unless its damper alone already asks for more than the limit. A tie (no load
            // and no damping yet) holds too: the hold's event then switches at once if the spring's force
            // outgrows the limit.
            let hold = Mode {
                friction: Friction::Stick,
                patch_offset: history(y, 0),
                ..*mode
            };
            let aux = self.dynamics.eval(t, y, &hold).1;
            return if aux.required_friction.abs() <= aux.friction_limit {
                Friction::Stick
            } else {
                Friction::Slip(-aux.required_friction.signum())
            };
        }
        let probe = Mode {
            friction: Friction::Slip(0.0),
            ..*mode
        };
        let aux = self.dynamics.eval(t, y, &probe).1;
        if aux.slip != 0.0 {
            Friction::Slip(aux.slip.signum())
        } else if aux.required_friction.abs() <= aux.friction_limit {
            Friction::Stick
        } else {
            Friction::Slip(-aux.required_friction.signum())
        }
    }

    /// Integrates one contact phase, handling stick/slip switches, until the phase ends.
    fn contact<const N: usize>(
        &mut self,
        mut t: f64,
        mut y: Y<N>,
        mode: &mut Mode,
        phase: Phase,
        slip_events: &mut Vec<SlipEvent>,
    ) -> Result<(f64, Y<N>), ModelError> {
        mode.phase = phase;
        let mut same_instant = 0;
        loop {
            // A slip that already points against the sliding direction (its zero fell on the same instant
            // as a phase switch) is handled as a slip event right away.
            if let (false, Friction::Slip(sigma)) = (mode.patch, mode.friction) {
                let slip = self.dynamics.eval(t, &y, mode).1.slip;
                if sigma * slip < -SLIP_EPS {
                    slip_events.push(SlipEvent {
                        t,
                        kind: self.slip_stops(t, &mut y, mode),
                    });
                }
            }
            let before = *mode;
            (t, y) = self.integrate(t, y, mode, None)?;
            if mode.phase != before.phase {
                return Ok((t, y));
            }
            // A stick/slip event ended the segment.
            mode.riding_limit = false;
            let kind = match mode.friction {
                Friction::Slip(_) if mode.patch => {
                    // The patch stops sliding: it holds from the displacement it had, so the force is
                    // continuous.
                    let aux = self.dynamics.eval(t, &y, mode).1;
                    mode.patch_offset = history(&y, 0) - aux.patch_u;
                    mode.friction = Friction::Stick;
                    SlipEventKind::StartsSticking
                }
                Friction::Slip(_) => self.slip_stops(t, &mut y, mode),
                Friction::Stick => {
                    let aux = self.dynamics.eval(t, &y, mode).1;
                    mode.friction = Friction::Slip(-aux.required_friction.signum());
                    SlipEventKind::StartsSliding
                }
                Friction::None => unreachable!("no stick/slip events without friction"),
            };
            // Switches piling up on one instant mean the law cannot decide there (a tangency of the force
            // with its limit, within rounding): say so rather than spin through the step budget.
            let at_once = slip_events
                .last()
                .is_some_and(|last| t - last.t <= 1e-12 * t.abs().max(1e-3));
            same_instant = if at_once { same_instant + 1 } else { 0 };
            if same_instant >= MAX_SWITCHES_AT_ONE_INSTANT {
                return Err(ModelError::Chatter {
                    t_s: t,
                    phase: phase.name(),
                    switches: same_instant + 1,
                });
            }
            if at_once && mode.patch && kind == SlipEventKind::StartsSliding {
                // The patch could not hold for any time: it never stopped sliding, and rides its limit
                // (the force stays continuous and within it) until its stop is really due.
                slip_events.pop();
                mode.riding_limit = true;
                continue;
            }
            slip_events.push(SlipEvent { t, kind });
        }
    }

    /// The slip has reached zero: stick if friction can hold the contact point, else slide the other way.
    fn slip_stops<const N: usize>(&self, t: f64, y: &mut Y<N>, mode: &mut Mode) -> SlipEventKind {
        let Friction::Slip(sigma) = mode.friction else {
            unreachable!("called while sliding")
        };
        let aux = self.dynamics.eval(t, y, mode).1;
        if aux.required_friction.abs() <= aux.friction_limit {
            // Remove the residual slip with the tangential impulse that would have done it.
            let r = self.dynamics.model.ball.radius_m;
            let j = -aux.slip / self.dynamics.slip_mobility;
            y[3] += j / self.dynamics.model.ball.mass_kg;
            y[5] += r * j / self.dynamics.inertia;
            mode.friction = Friction::Stick;
            SlipEventKind::StartsSticking
        } else {
            mode.friction = Friction::Slip(-sigma);
            SlipEventKind::Reverses
        }
    }

    /// Integrates in the current mode until an event fires (returning its time and state; the phase is
    /// advanced for phase events) or until `until` is reached.
    fn integrate<const N: usize>(
        &mut self,
        mut t: f64,
        mut y: Y<N>,
        mode: &mut Mode,
        until: Option<f64>,
    ) -> Result<(f64, Y<N>), ModelError> {
        let dynamics = &self.dynamics;
        let r = dynamics.model.ball.radius_m;
        let events = Event::active(mode);
        let m = *mode;
        // The last stage of a step is evaluated at its end: keep its event quantities instead of recomputing.
        let last_aux = Cell::new(Aux::default());
        let mut rhs = |tt: f64, yy: &Y<N>| {
            let (dy, a) = dynamics.eval(tt, yy, &m);
            last_aux.set(a);
            dy
        };
        let (mut f, aux) = dynamics.eval(t, &y, &m);
        let mut g = event_values(events, &y, &aux, &m, r);
        if m.patch && !m.riding_limit {
            patch_switch_just_positive(&mut g, events);
        }
        let scale = dynamics.model.ball.radius_m.max(1e-3) / y[3].hypot(y[4]).max(0.1);
        let mut h = (1e-3 * scale).min(self.opts.max_step_s);
        loop {
            if let Some(end) = until {
                if t >= end {
                    return Ok((t, y));
                }
                h = h.min(end - t);
            }
            self.steps += 1;
            if self.steps > self.opts.max_steps {
                return Err(ModelError::TooManySteps {
                    max_steps: self.opts.max_steps,
                    t_s: t,
                    phase: m.phase.name(),
                });
            }
            let step = Step::attempt(&mut rhs, t, &y, &f, h, self.opts.rtol, self.opts.atol);
            if step.err > 1.0 {
                h = step.next_h();
                if h < 1e-15 * t.abs().max(1e-3) || !h.is_finite() {
                    return Err(ModelError::NonFinite {
                        t_s: t,
                        phase: m.phase.name(),
                    });
                }
                continue;
            }
            check_accepted(&step, &m, r)?;
            let g1 = event_values(events, &step.y1, &last_aux.get(), &m, r);
            if let Some((te, ev)) = dynamics.earliest_event(events, &step, &g, &g1, &m, r) {
                // Re-step exactly to the event so its state has the integrator's full accuracy.
                let he = te - t;
                let (ye, at) = if he > 0.0 {
                    let s = Step::attempt(&mut rhs, t, &y, &f, he, self.opts.rtol, self.opts.atol);
                    (s.y1, Some(s))
                } else {
                    (y, None)
                };
                if let Some(s) = &at {
                    self.recorder
                        .record_until(te, &m, |tt| s.at(tt), |tt, yy| dynamics.patch_displacement(tt, yy, &m));
                }
                if let Some(phase) = ev.next_phase() {
                    mode.phase = phase;
                }
                return Ok((te, ye));
            }
            self.recorder.record_until(
                t + h,
                &m,
                |tt| step.at(tt),
                |tt, yy| dynamics.patch_displacement(tt, yy, &m),
            );
            t += h;
            y = step.y1;
            f = step.f1;
            g = g1;
            h = step.next_h().min(self.opts.max_step_s);
        }
    }
}
