//! The fitting problem: measured shots, the free parameters, and the weighted residuals of the simulated
//! trajectories against the measured ones.

use crate::measurement::{observe, observes, true_start};
use crate::nuisance::{Nuisance, StartNuisances};
use crate::params::{self, FreeParam, SurfaceModel};
use crate::solver::LeastSquares;
use crate::{FitError, MeasuredShot};
use bouncelab_model::{Model, ModelSpec, SimOptions, Simulation, State, simulate};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Shared parameters of a [`ModelSpec`] against many [`MeasuredShot`]s.
///
/// With [`Problem::with_surface_offsets`] each shot also has its own surface level: the height of the true
/// surface in the measured frame (the surface line found in the image is off by a fraction of a pixel on a
/// grainy or blurred edge, which shifts the moment of touch and biases the stiffness). That nuisance level is
/// profiled out shot by shot inside every evaluation (a few Gauss–Newton/secant steps on the shot's own
/// residuals, warm-started from the previous evaluation), so the parameter vector holds only the shared
/// parameters and the cost is a few extra simulations per shot.
///
/// A shot with [`MeasuredShot::frame_sigma_rad`] may also turn its frame: the estimator's frame follows the
/// surface line's measured tilt, whose error (0.01–0.02° on a sharp 512 px line) turns the start's velocity
/// with the incoming frames; the bounce reverses the normal part but not the error, so the outgoing
/// tangential flight drifts by the tilt error times the normal speeds, tens of µm over 35 ms of flight, and
/// the fit would read it as friction or a missing effect. Each such shot's turn ε is a nuisance with the
/// line's σ as its prior, taken out to first order in every evaluation (the residuals' change per radian
/// of turn is differenced once per problem, under the model at its starting values) and held within
/// ±2σ: the prior hardly binds against a shot's hundreds of frames, and they tell the turn only through
/// the contact, where a turn and a tangential effect (a compliant patch, rolling resistance) move the
/// outgoing flight alike; left free, the turns took up a hidden tangential spring's misfit shot by shot
/// and it went unnamed. The prior's own term (ε/σ)² is not added to the residual vector.
///
/// A shot with [`MeasuredShot::spin_sigma_rad_s`] has its incoming spin's error as a second such nuisance,
/// taken out with the first: a ball that ends its contact rolling leaves with `c·R·Δω/(1 + c)` more
/// tangential speed per Δω of incoming spin (6.7 mm/s for 0.5 rad/s with a thin shell), and the spin
/// estimator's error grows with the sensor's noise (±0.6 rad/s at 14 DN, ±0.03 rad/s on clean frames).
///
/// The residual vector holds, for every shot in order and every frame in order, `(x_sim − x_m)/σ` and
/// `(y_sim − y_m)/σ`, where `x_sim, y_sim` is what the camera sees of the simulated ball (the sample's
/// `observed` position, so measurement effects such as camera roll apply) at the frame's time. Each
/// shot's simulation starts from its measured start state, in the frames' own coordinates, so the
/// arbitrary x origin of the tracker cancels: only the trajectory's shape relative to its start matters.
#[derive(Debug, Clone)]
pub struct Problem {
    shots: Vec<MeasuredShot>,
    params: Vec<FreeParam>,
    surfaces: Vec<SurfaceModel>,
    shot_surface: Vec<usize>,
    times: Vec<Vec<f64>>,
    sim: SimOptions,
    parallel: bool,
    n_residuals: usize,
    offsets: Option<OffsetCache>,
    /// Per shot: the measured x of the centre when it touched the surface line, m.
    touch_x: Vec<f64>,
    /// Per shot: the index of its first residual.
    first_residual: Vec<usize>,
    /// Per shot with a stated frame direction σ or incoming spin σ: how its residuals move as its frame
    /// turns and its incoming spin changes.
    nuisances: Vec<Option<StartNuisances>>,
}

/// The largest correction of a start nuisance, in its prior σ: the prior hardly binds against a shot's
/// hundreds of frames, and the frames tell a turn or a spin error only through the contact, where a
/// tangential effect moves the outgoing flight alike. Left unbounded, the turns took up a hidden
/// tangential spring's misfit shot by shot and it went unnamed, and spins 0.3 rad/s off took up rolling
/// resistance's.
const CAP_SIGMAS: f64 = 2.0;

/// The turn, rad, over which a frame turn's effect on the residuals is differenced.
const TURN_STEP_RAD: f64 = 1e-4;

/// How much better than its prior the frames must tell a shot's incoming spin (`Σ w·|g|²·σ²`, the ratio
/// of the prior's variance to the frames' own) for the spin to be a nuisance. Below it the correction
/// would be shrunk to a fraction of a σ anyway, and on clean frames (σ 0.003–0.03 rad/s, a ratio near 1)
/// it only cost time: corrections pressed on the cap where a candidate misfits, and the search's fits took
/// more iterations over that kink.
const SPIN_TOLD_MIN: f64 = 4.0;

/// The change of incoming spin, rad/s, over which its effect on the residuals is differenced (centred).
const SPIN_STEP_RAD_S: f64 = 0.05;

/// The last profiled surface level of each shot (f64 bits), the warm start of the next evaluation.
#[derive(Debug)]
struct OffsetCache(Vec<AtomicU64>);

impl Clone for OffsetCache {
    fn clone(&self) -> Self {
        OffsetCache(
            self.0
                .iter()
                .map(|a| AtomicU64::new(a.load(Ordering::Relaxed)))
                .collect(),
        )
    }
}

/// Largest surface level the profile accepts, m (5 px at the paper's 0.4 mm/px).
const MAX_OFFSET_M: f64 = 2e-3;
/// Finite-difference step of the profile, m.
const OFFSET_STEP_M: f64 = 1e-6;

impl Problem {
    /// Checks the shots and builds the parameter vector of `spec` for their surfaces.
    ///
    /// Fails with the shot's name when a shot has no frames, a non-positive σ, a frame before its start,
    /// a start that is not finite or inside the surface, or a surface the model file does not know.
    pub fn new(spec: &ModelSpec, shots: Vec<MeasuredShot>, sim: SimOptions) -> Result<Problem, FitError> {
        let mut problem = Problem::build(spec, shots, sim)?;
        problem.nuisances = problem.start_nuisances(&problem.initial())?;
        Ok(problem)
    }

    /// [`Problem::new`] for a subset of `source`'s shots (`which`, indices into `source`'s shots, in the
    /// order of `shots`), taking each shot's start nuisances from `source` as they were differenced there
    /// instead of simulating them again: the cross-validation folds of a problem whose nuisances were
    /// differenced under one model ([`Problem::difference_nuisances_at`]).
    pub fn with_nuisances_of(
        spec: &ModelSpec,
        shots: Vec<MeasuredShot>,
        sim: SimOptions,
        source: &Problem,
        which: &[usize],
    ) -> Result<Problem, FitError> {
        let mut problem = Problem::build(spec, shots, sim)?;
        problem.nuisances = which
            .iter()
            .map(|&i| source.nuisances.get(i).cloned().flatten())
            .collect();
        problem.nuisances.resize(problem.shots.len(), None);
        Ok(problem)
    }

    /// The problem without its start nuisances.
    fn build(spec: &ModelSpec, shots: Vec<MeasuredShot>, sim: SimOptions) -> Result<Problem, FitError> {
        if shots.is_empty() {
            return Err(FitError::NoShots);
        }
        let radius = spec.ball.radius_m;
        for shot in &shots {
            check_shot(shot, radius)?;
            if !spec.surfaces.is_empty() && !spec.surfaces.iter().any(|(s, _)| s == &shot.surface) {
                return Err(FitError::UnknownSurface {
                    shot: shot.name.clone(),
                    surface: shot.surface.clone(),
                    known: spec.surface_names().join(", "),
                });
            }
        }
        let used: Vec<String> = shots.iter().map(|s| s.surface.clone()).collect();
        let (params, surfaces) = params::build(spec, &used)?;
        if params.is_empty() {
            return Err(FitError::NoFreeParameters);
        }
        let shot_surface = shots
            .iter()
            .map(|s| {
                surfaces
                    .iter()
                    .position(|m| m.name == s.surface)
                    .expect("every used surface has a model")
            })
            .collect();
        let times = shots.iter().map(|s| s.frames.iter().map(|f| f.t_s).collect()).collect();
        let n_residuals = 2 * shots.iter().map(|s| s.frames.len()).sum::<usize>();
        if n_residuals <= params.len() {
            return Err(FitError::TooFewResiduals {
                residuals: n_residuals,
                params: params.len(),
            });
        }
        let touch_x = shots.iter().map(|s| crate::measurement::touch_x(s, radius)).collect();
        let first_residual = shots
            .iter()
            .scan(0, |at, s| {
                let first = *at;
                *at += 2 * s.frames.len();
                Some(first)
            })
            .collect();
        let problem = Problem {
            touch_x,
            first_residual,
            shots,
            params,
            surfaces,
            shot_surface,
            times,
            sim,
            parallel: true,
            n_residuals,
            offsets: None,
            nuisances: Vec::new(),
        };
        Ok(problem)
    }

    /// Differences each shot's start nuisances (frame turn, incoming spin) again under the model at `theta`
    /// instead of the starting values: problems that must agree where their models agree (a model and the
    /// same model with one more effect at its neutral value, started elsewhere) then take them out alike.
    pub fn difference_nuisances_at(&mut self, theta: &[f64]) -> Result<(), FitError> {
        self.nuisances = self.start_nuisances(theta)?;
        Ok(())
    }

    /// Each shot's [`StartNuisances`]: its frame's turn (for shots with [`MeasuredShot::frame_sigma_rad`])
    /// and its incoming spin's error (with [`MeasuredShot::spin_sigma_rad_s`]), each differenced
    /// (centred) under the model at `theta`: their effect is smooth and hardly depends on the parameters,
    /// so it is taken once per problem rather than in every evaluation. Two simulations per nuisance and
    /// shot.
    fn start_nuisances(&self, theta: &[f64]) -> Result<Vec<Option<StartNuisances>>, FitError> {
        let positive = |s: Option<f64>| s.filter(|s| s.is_finite() && *s > 0.0);
        if self
            .shots
            .iter()
            .all(|s| positive(s.frame_sigma_rad).is_none() && positive(s.spin_sigma_rad_s).is_none())
        {
            return Ok(vec![None; self.shots.len()]);
        }
        let models: Vec<Model> = self.surfaces.iter().map(|s| s.model(theta)).collect::<Result<_, _>>()?;
        let one = |i: usize| -> Option<StartNuisances> {
            let model = &models[self.shot_surface[i]];
            let observed = |shot: &MeasuredShot| -> Option<Vec<[f64; 2]>> {
                let sim = self.simulate_measured(i, shot, model, 0.0).ok()?;
                Some(
                    shot.frames
                        .iter()
                        .zip(&sim.samples)
                        .map(|(f, p)| [p.observed.x - f.x_m, p.observed.y - f.y_m])
                        .collect(),
                )
            };
            let centred = |up: Vec<[f64; 2]>, down: Vec<[f64; 2]>, step: f64| -> Vec<[f64; 2]> {
                up.iter()
                    .zip(&down)
                    .map(|(u, d)| [(u[0] - d[0]) / (2.0 * step), (u[1] - d[1]) / (2.0 * step)])
                    .collect()
            };
            let shot = &self.shots[i];
            let mut all = Vec::new();
            if let Some(sigma) = positive(shot.frame_sigma_rad) {
                let turned = |eps: f64| observed(&turned_shot(shot, self.touch_x[i], eps));
                let (up, down) = (turned(TURN_STEP_RAD)?, turned(-TURN_STEP_RAD)?);
                all.push(Nuisance {
                    gradient: centred(up, down, TURN_STEP_RAD),
                    sigma,
                    cap_sigmas: CAP_SIGMAS,
                });
            }
            if let Some(sigma) = positive(shot.spin_sigma_rad_s) {
                let spun = |d: f64| {
                    let mut s = shot.clone();
                    s.start.state.omega += d;
                    observed(&s)
                };
                let (up, down) = (spun(SPIN_STEP_RAD_S)?, spun(-SPIN_STEP_RAD_S)?);
                let gradient = centred(up, down, SPIN_STEP_RAD_S);
                // How well the frames tell the spin, against its prior: Σ w·|g|²·σ².
                let told: f64 = shot
                    .frames
                    .iter()
                    .zip(&gradient)
                    .map(|(f, g)| (g[0] * g[0] + g[1] * g[1]) * sigma * sigma / (f.sigma_m * f.sigma_m))
                    .sum();
                if told >= SPIN_TOLD_MIN {
                    all.push(Nuisance {
                        gradient,
                        sigma,
                        cap_sigmas: CAP_SIGMAS,
                    });
                }
            }
            (!all.is_empty()).then_some(StartNuisances(all))
        };
        let all: Vec<usize> = (0..self.shots.len()).collect();
        Ok(if self.parallel {
            all.par_iter().map(|&i| one(i)).collect()
        } else {
            all.iter().map(|&i| one(i)).collect()
        })
    }

    /// Simulates the shots on several threads (the default) or on one; the results are identical.
    pub fn with_parallel(mut self, parallel: bool) -> Problem {
        self.parallel = parallel;
        self
    }

    /// Fits each shot's surface level as a nuisance (see the type's doc); off by default.
    pub fn with_surface_offsets(mut self, on: bool) -> Problem {
        self.offsets = on.then(|| OffsetCache(self.shots.iter().map(|_| AtomicU64::new(0)).collect()));
        self
    }

    /// True when each shot's surface level is profiled.
    pub fn surface_offsets(&self) -> bool {
        self.offsets.is_some()
    }

    /// The surface level of each shot from the last evaluation, m (zeros when not profiled).
    pub fn offsets(&self) -> Vec<f64> {
        match &self.offsets {
            Some(c) => c.0.iter().map(|a| f64::from_bits(a.load(Ordering::Relaxed))).collect(),
            None => vec![0.0; self.shots.len()],
        }
    }

    /// Each shot's surface level the next evaluation profiles from (one per shot, m): a fit read back
    /// gives its problem the levels it ended at, so that what is computed from it (the comparison) starts
    /// where the fit did. Ignored without surface offsets or when the count differs.
    pub fn start_offsets_at(&self, levels: &[f64]) {
        if let Some(cache) = &self.offsets
            && levels.len() == cache.0.len()
        {
            for (a, l) in cache.0.iter().zip(levels) {
                a.store(l.clamp(-MAX_OFFSET_M, MAX_OFFSET_M).to_bits(), Ordering::Relaxed);
            }
        }
    }

    /// Nuisance parameters per shot (1 with surface offsets, else 0), for degrees of freedom and BIC.
    pub fn nuisance_per_shot(&self) -> usize {
        usize::from(self.offsets.is_some())
    }

    /// The free parameters, in the order of the parameter vector.
    pub fn params(&self) -> &[FreeParam] {
        &self.params
    }

    /// The shots.
    pub fn shots(&self) -> &[MeasuredShot] {
        &self.shots
    }

    /// The starting parameter vector (the model file's values).
    pub fn initial(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.initial).collect()
    }

    /// Number of residuals (two per frame).
    pub fn n_residuals(&self) -> usize {
        self.n_residuals
    }

    /// The model of `surface` with the parameter vector `theta` set into it.
    pub fn model_for(&self, surface: &str, theta: &[f64]) -> Result<Model, FitError> {
        let s = self
            .surfaces
            .iter()
            .find(|m| m.name == surface)
            .ok_or_else(|| FitError::UnknownSurface {
                shot: "-".into(),
                surface: surface.into(),
                known: self
                    .surfaces
                    .iter()
                    .map(|m| m.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
        s.model(theta)
    }

    /// Simulates every shot with `theta` at its frame times, in shot order.
    pub fn simulate(&self, theta: &[f64]) -> Result<Vec<Simulation>, FitError> {
        let all: Vec<usize> = (0..self.shots.len()).collect();
        self.simulate_some(theta, &all)
    }

    /// Simulates the shots `which` with `theta`, in that order (see [`Problem::simulate`]).
    pub fn simulate_some(&self, theta: &[f64], which: &[usize]) -> Result<Vec<Simulation>, FitError> {
        let models: Vec<Model> = self.surfaces.iter().map(|s| s.model(theta)).collect::<Result<_, _>>()?;
        let one = |&i: &usize| -> Result<Simulation, FitError> {
            let model = &models[self.shot_surface[i]];
            match &self.offsets {
                None => self.simulate_shot(i, model, 0.0),
                Some(cache) => {
                    let start = f64::from_bits(cache.0[i].load(Ordering::Relaxed));
                    let (sim, level) = self.profile(i, model, start)?;
                    cache.0[i].store(level.to_bits(), Ordering::Relaxed);
                    Ok(sim)
                }
            }
        };
        // Collected in shot order either way, so the result does not depend on the scheduling; the first
        // failing shot in order is reported.
        let all: Vec<Result<Simulation, FitError>> = if self.parallel {
            which.par_iter().map(one).collect()
        } else {
            which.iter().map(one).collect()
        };
        all.into_iter().collect()
    }

    /// Simulates the shots `which` with `theta`, each at its level in `levels` (one per shot, m), in that
    /// order.
    pub(crate) fn simulate_at_levels(
        &self,
        theta: &[f64],
        levels: &[f64],
        which: &[usize],
    ) -> Result<Vec<Simulation>, FitError> {
        let models: Vec<Model> = self.surfaces.iter().map(|s| s.model(theta)).collect::<Result<_, _>>()?;
        let one = |&i: &usize| self.simulate_shot(i, &models[self.shot_surface[i]], levels[i]);
        if self.parallel {
            which.par_iter().map(one).collect()
        } else {
            which.iter().map(one).collect()
        }
    }

    /// The shots whose simulation parameter `j` changes: those of its surface for a per-surface parameter,
    /// `None` (every shot) for a shared one.
    pub fn shots_of_param(&self, j: usize) -> Option<Vec<usize>> {
        let surface = self.params.get(j)?.surface.as_deref()?;
        Some(
            (0..self.shots.len())
                .filter(|&i| self.shots[i].surface == surface)
                .collect(),
        )
    }

    /// Index of shot `i`'s first residual in [`Problem::residuals_of`]'s vector.
    pub fn first_residual(&self, i: usize) -> usize {
        self.first_residual[i]
    }

    /// Shot `i` simulated with the true surface at height `level` in the measured frame (m): the measured
    /// start is taken about the contact point on that surface, mapped back through the model's measurement
    /// effects (so the simulation starts from the state whose observation was measured), and what the
    /// camera would see is mapped to the measured frame again. Without measurement effects and at level 0
    /// this is the plain simulation from the measured start.
    pub fn simulate_shot(&self, i: usize, model: &Model, level: f64) -> Result<Simulation, FitError> {
        let mut sim = self.simulate_measured(i, &self.shots[i], model, level)?;
        if let Some(nuisances) = self.nuisances.get(i).and_then(Option::as_ref) {
            nuisances.apply(&self.shots[i], &mut sim);
        }
        Ok(sim)
    }

    /// [`Problem::simulate_shot`] of `shot` (shot `i` or a copy of it turned), without the frame's turn.
    fn simulate_measured(
        &self,
        i: usize,
        shot: &MeasuredShot,
        model: &Model,
        level: f64,
    ) -> Result<Simulation, FitError> {
        let measured = shot.start.state;
        let observing = observes(model);
        // The contact point in data coordinates (its x only matters with a measurement effect).
        let origin_x = if observing {
            let touching = State {
                y: model.ball.radius_m,
                ..State::default()
            };
            self.touch_x[i] - observe(model, &touching).x
        } else {
            0.0
        };
        let local = State {
            x: measured.x - origin_x,
            y: measured.y - level,
            ..measured
        };
        let run = |local: &State| -> Result<Simulation, FitError> {
            let start = if observing { true_start(model, local) } else { *local };
            let mut sim = simulate(
                model,
                shot.incline_rad,
                shot.start.t_s,
                start,
                &self.times[i],
                &self.sim,
            )
            .map_err(|source| FitError::Simulation {
                shot: shot.name.clone(),
                source: Box::new(source),
            })?;
            if origin_x != 0.0 || level != 0.0 {
                for s in &mut sim.samples {
                    s.observed.x += origin_x;
                    s.observed.y += level;
                }
            }
            Ok(sim)
        };
        let mut local = local;
        let mut sim = run(&local)?;
        // The measured start comes from a ballistic arc. Under a model whose flight is not ballistic (drag,
        // a custom flight term) that arc's start is biased, and the model could never fit the flight it
        // predicts; so its start is re-measured under the model itself: position and velocity corrected to
        // fit the incoming frames, by Gauss–Newton with the ballistic Jacobian (exact without flight loads,
        // within the loads' small share of gravity otherwise). A fixed number of steps keeps the residuals
        // a smooth function of the parameters.
        let loads = model.flight_loads(&local, shot.incline_rad);
        if loads.force_x != 0.0 || loads.force_y != 0.0 {
            for _ in 0..INCOMING_STEPS {
                let Some([dx, dvx, dy, dvy]) = incoming_correction(shot, &sim) else {
                    break;
                };
                local.x += dx;
                local.vx += dvx;
                local.y += dy;
                local.vy += dvy;
                sim = run(&local)?;
            }
        }
        Ok(sim)
    }

    /// The surface level that best fits shot `i` under `model`, from `start` (see [`profile_surface_level`]).
    fn profile(&self, i: usize, model: &Model, start: f64) -> Result<(Simulation, f64), FitError> {
        profile_surface_level(&self.shots[i], start, |level| self.simulate_shot(i, model, level))
    }

    /// The weighted residuals of [`Problem::simulate`]'s trajectories (see the type's doc).
    pub fn residuals_of(&self, sims: &[Simulation]) -> Vec<f64> {
        let mut r = Vec::with_capacity(self.n_residuals);
        for (shot, sim) in self.shots.iter().zip(sims) {
            r.extend(weighted_residuals(shot, sim));
        }
        r
    }
}

impl LeastSquares for Problem {
    fn n_params(&self) -> usize {
        self.params.len()
    }

    /// The frames' residuals ([`Problem::residuals_of`]), then with surface offsets each shot's prior
    /// residual ([`surface_prior`]; 0 for a shot without a stated σ), so the fit minimises what the
    /// profile does.
    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, FitError> {
        let mut r = self.residuals_of(&self.simulate(theta)?);
        if self.offsets.is_some() {
            let levels = self.offsets();
            r.extend(
                self.shots
                    .iter()
                    .zip(levels)
                    .map(|(shot, l)| surface_prior(shot, l).unwrap_or(0.0)),
            );
        }
        Ok(r)
    }

    /// Only the shots of parameter `j`'s surface are simulated again (see [`Problem::shots_of_param`]).
    fn residuals_changing(&self, theta: &[f64], j: usize, base: &[f64]) -> Result<Vec<f64>, FitError> {
        let Some(which) = self.shots_of_param(j) else {
            return self.residuals(theta);
        };
        let sims = self.simulate_some(theta, &which)?;
        let mut r = base.to_vec();
        let levels = self.offsets.as_ref().map(|_| self.offsets());
        for (&i, sim) in which.iter().zip(&sims) {
            let shot = &self.shots[i];
            let at = self.first_residual[i];
            r[at..at + 2 * shot.frames.len()].copy_from_slice(&weighted_residuals(shot, sim));
            if let Some(levels) = &levels {
                r[self.n_residuals + i] = surface_prior(shot, levels[i]).unwrap_or(0.0);
            }
        }
        Ok(r)
    }

    fn bounds(&self, j: usize) -> (f64, f64) {
        (self.params[j].min, self.params[j].max)
    }

    fn scale(&self, j: usize) -> f64 {
        self.params[j].scale
    }
}

fn check_shot(shot: &MeasuredShot, radius: f64) -> Result<(), FitError> {
    let invalid = |reason: String| FitError::InvalidShot {
        shot: shot.name.clone(),
        reason,
    };
    if shot.frames.is_empty() {
        return Err(invalid("no frames to fit".into()));
    }
    if !shot.incline_rad.is_finite() {
        return Err(invalid(format!("incline {} rad is not finite", shot.incline_rad)));
    }
    let st = &shot.start.state;
    let finite = [shot.start.t_s, st.x, st.y, st.theta, st.vx, st.vy, st.omega]
        .iter()
        .all(|v| v.is_finite());
    if !finite {
        return Err(FitError::BadStart {
            shot: shot.name.clone(),
            reason: "the start time or state is not finite".into(),
        });
    }
    if st.y < radius - 1e-9 {
        return Err(FitError::BadStart {
            shot: shot.name.clone(),
            reason: format!(
                "the start at t = {} s is {:.3e} m inside the surface (y = {} m < R = {} m); the start must be an incoming state in flight",
                shot.start.t_s,
                radius - st.y,
                st.y,
                radius
            ),
        });
    }
    let mut prev = f64::NEG_INFINITY;
    for (i, f) in shot.frames.iter().enumerate() {
        if !(f.t_s.is_finite() && f.x_m.is_finite() && f.y_m.is_finite()) {
            return Err(invalid(format!("frame {i} (t = {} s) is not finite", f.t_s)));
        }
        if !(f.sigma_m.is_finite() && f.sigma_m > 0.0) {
            return Err(invalid(format!(
                "frame {i} (t = {} s) has σ = {} m; it must be > 0",
                f.t_s, f.sigma_m
            )));
        }
        if f.t_s < shot.start.t_s {
            return Err(invalid(format!(
                "frame {i} (t = {} s) is before the start (t = {} s)",
                f.t_s, shot.start.t_s
            )));
        }
        if f.t_s < prev {
            return Err(invalid(format!(
                "frame {i} (t = {} s) is earlier than the frame before it",
                f.t_s
            )));
        }
        prev = f.t_s;
    }
    Ok(())
}

/// `shot` with its frames and start turned by `eps` (rad, counter-clockwise) about the point `(x0, 0)` on
/// the surface line.
fn turned_shot(shot: &MeasuredShot, x0: f64, eps: f64) -> MeasuredShot {
    let (s, c) = eps.sin_cos();
    let turn = |x: f64, y: f64| (x0 + c * (x - x0) - s * y, s * (x - x0) + c * y);
    let mut out = shot.clone();
    for f in &mut out.frames {
        (f.x_m, f.y_m) = turn(f.x_m, f.y_m);
    }
    let st = &mut out.start.state;
    (st.x, st.y) = turn(st.x, st.y);
    (st.vx, st.vy) = (c * st.vx - s * st.vy, s * st.vx + c * st.vy);
    out
}

/// Shot `shot`'s weighted residuals `(x_sim − x_m)/σ, (y_sim − y_m)/σ` frame by frame, against what the
/// camera sees of a simulation sampled at its frame times.
pub fn weighted_residuals(shot: &MeasuredShot, sim: &Simulation) -> Vec<f64> {
    let mut r = Vec::with_capacity(2 * sim.samples.len());
    for (f, s) in shot.frames.iter().zip(&sim.samples) {
        r.push((s.observed.x - f.x_m) / f.sigma_m);
        r.push((s.observed.y - f.y_m) / f.sigma_m);
    }
    r
}

/// The surface level (the true surface's height in the measured frame, m, within ±2 mm) that best fits
/// `shot`, starting from `start`: `simulate_at(level)` must simulate the shot with its start lowered by
/// `level` and what the camera sees raised by it (as [`Problem::with_surface_offsets`] does). A Gauss–Newton
/// step with a finite-difference slope, then secant steps, each kept only if it lowers the shot's χ²;
/// typically three to five simulations from a warm start. Returns the best simulation and its level.
pub fn profile_surface_level(
    shot: &MeasuredShot,
    start: f64,
    simulate_at: impl Fn(f64) -> Result<Simulation, FitError>,
) -> Result<(Simulation, f64), FitError> {
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    // The shot's residuals and, with a stated σ of its surface line, the prior's (level / σ).
    let resid = |sim: &Simulation, level: f64| {
        let mut r = weighted_residuals(shot, sim);
        if let Some(p) = surface_prior(shot, level) {
            r.push(p);
        }
        r
    };
    let mut level = start.clamp(-MAX_OFFSET_M, MAX_OFFSET_M);
    let mut sim = simulate_at(level)?;
    let mut r = resid(&sim, level);
    let mut c = cost(&r);
    // Slope of the residuals with respect to the level, from a forward difference.
    let probe = resid(&simulate_at(level + OFFSET_STEP_M)?, level + OFFSET_STEP_M);
    let mut slope: Vec<f64> = probe.iter().zip(&r).map(|(a, b)| (a - b) / OFFSET_STEP_M).collect();
    for _ in 0..10 {
        let jj: f64 = slope.iter().map(|j| j * j).sum();
        if jj.is_nan() || jj <= 0.0 {
            break;
        }
        let jr: f64 = slope.iter().zip(&r).map(|(j, r)| j * r).sum();
        let mut step = -jr / jj;
        let mut accepted = false;
        for _ in 0..4 {
            let trial = (level + step).clamp(-MAX_OFFSET_M, MAX_OFFSET_M);
            if trial == level {
                break;
            }
            let s2 = simulate_at(trial)?;
            let r2 = resid(&s2, trial);
            let c2 = cost(&r2);
            if c2 <= c {
                let d = trial - level;
                slope = r2.iter().zip(&r).map(|(a, b)| (a - b) / d).collect();
                (level, sim, r, c, accepted) = (trial, s2, r2, c2, true);
                break;
            }
            step *= 0.5;
        }
        // 1e-12 m: far below what moves a finite-difference column of the outer fit.
        if !accepted || step.abs() < 1e-12 {
            break;
        }
    }
    Ok((sim, level))
}

/// The prior residual of a shot's surface offset, `level / σ`, when the shot states the σ of its surface
/// line: the offset is a deviation from the surface's level (the `surface_level` effect), as large as the
/// line's error, not a free shift that could also absorb a missing contact effect.
pub fn surface_prior(shot: &MeasuredShot, level: f64) -> Option<f64> {
    shot.surface_sigma_m.filter(|s| *s > 0.0).map(|s| level / s)
}

/// Gauss–Newton steps of the incoming state under a model with flight loads (one: its ballistic Jacobian
/// leaves ~1 % of a correction that is itself a few mm/s) (see [`Problem::simulate_shot`]).
const INCOMING_STEPS: usize = 1;

/// The change of start position and velocity `[dx, dvx, dy, dvy]` that best fits the frames before the
/// simulated touch, to first order (weighted by σ; per axis, position and velocity against `t − t_start`).
/// `None` with fewer than 3 such frames.
fn incoming_correction(shot: &MeasuredShot, sim: &Simulation) -> Option<[f64; 4]> {
    let t0 = shot.start.t_s;
    // Weighted sums for the two-parameter line fit of each axis' residual.
    let (mut sw, mut st, mut stt, mut sx, mut stx, mut sy, mut sty) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut n = 0;
    for (f, s) in shot.frames.iter().zip(&sim.samples) {
        if f.t_s >= sim.impact.t_touch || s.phase.in_contact() {
            break;
        }
        let w = 1.0 / (f.sigma_m * f.sigma_m);
        let tau = f.t_s - t0;
        let (rx, ry) = (f.x_m - s.observed.x, f.y_m - s.observed.y);
        sw += w;
        st += w * tau;
        stt += w * tau * tau;
        sx += w * rx;
        stx += w * tau * rx;
        sy += w * ry;
        sty += w * tau * ry;
        n += 1;
    }
    let det = sw * stt - st * st;
    if n < 3 || det.is_nan() || det <= 0.0 {
        return None;
    }
    let line = |s: f64, ts: f64| ((stt * s - st * ts) / det, (sw * ts - st * s) / det);
    let (dx, dvx) = line(sx, stx);
    let (dy, dvy) = line(sy, sty);
    Some([dx, dvx, dy, dvy])
}
