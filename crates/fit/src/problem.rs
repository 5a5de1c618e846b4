//! The fitting problem: measured shots, the free parameters, and the weighted residuals of the simulated
//! trajectories against the measured ones.

use crate::params::{self, FreeParam, SurfaceModel};
use crate::solver::LeastSquares;
use crate::{FitError, MeasuredShot};
use bouncelab_model::{Model, ModelSpec, SimOptions, Simulation, simulate};
use rayon::prelude::*;

/// Shared parameters of a [`ModelSpec`] against many [`MeasuredShot`]s.
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
}

impl Problem {
    /// Checks the shots and builds the parameter vector of `spec` for their surfaces.
    ///
    /// Fails with the shot's name when a shot has no frames, a non-positive σ, a frame before its start,
    /// a start that is not finite or inside the surface, or a surface the model file does not know.
    pub fn new(spec: &ModelSpec, shots: Vec<MeasuredShot>, sim: SimOptions) -> Result<Problem, FitError> {
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
        Ok(Problem {
            shots,
            params,
            surfaces,
            shot_surface,
            times,
            sim,
            parallel: true,
            n_residuals,
        })
    }

    /// Simulates the shots on several threads (the default) or on one; the results are identical.
    pub fn with_parallel(mut self, parallel: bool) -> Problem {
        self.parallel = parallel;
        self
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
        let models: Vec<Model> = self.surfaces.iter().map(|s| s.model(theta)).collect::<Result<_, _>>()?;
        let one = |i: usize| -> Result<Simulation, FitError> {
            let shot = &self.shots[i];
            simulate(
                &models[self.shot_surface[i]],
                shot.incline_rad,
                shot.start.t_s,
                shot.start.state,
                &self.times[i],
                &self.sim,
            )
            .map_err(|source| FitError::Simulation {
                shot: shot.name.clone(),
                source: Box::new(source),
            })
        };
        // Collected in shot order either way, so the result does not depend on the scheduling; the first
        // failing shot in order is reported.
        let all: Vec<Result<Simulation, FitError>> = if self.parallel {
            (0..self.shots.len()).into_par_iter().map(one).collect()
        } else {
            (0..self.shots.len()).map(one).collect()
        };
        all.into_iter().collect()
    }

    /// The weighted residuals of [`Problem::simulate`]'s trajectories (see the type's doc).
    pub fn residuals_of(&self, sims: &[Simulation]) -> Vec<f64> {
        let mut r = Vec::with_capacity(self.n_residuals);
        for (shot, sim) in self.shots.iter().zip(sims) {
            for (f, s) in shot.frames.iter().zip(&sim.samples) {
                r.push((s.observed.x - f.x_m) / f.sigma_m);
                r.push((s.observed.y - f.y_m) / f.sigma_m);
            }
        }
        r
    }
}

impl LeastSquares for Problem {
    fn n_params(&self) -> usize {
        self.params.len()
    }

    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, FitError> {
        Ok(self.residuals_of(&self.simulate(theta)?))
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
