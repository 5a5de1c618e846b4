//! A shot's start nuisances taken out to first order: the measured frame's turn (the surface line's tilt
//! error) and the measured incoming spin's error, each with the measurement's standard error as its prior.
//!
//! Both errors move a shot's simulated trajectory smoothly and mostly after the contact (a turn rotates the
//! start's velocity with the frames, a spin error changes how much friction works while the ball goes from
//! sliding to rolling), so each is differenced once per problem and taken out in every evaluation by a
//! weighted linear least squares of one or two unknowns: no extra simulation per evaluation.

use crate::MeasuredShot;
use bouncelab_model::Simulation;

/// One nuisance of a shot: how the shot's observed positions move per unit of it (m per unit, each frame's
/// x and y), its prior σ in that unit, and the largest correction in σ.
#[derive(Debug, Clone)]
pub(crate) struct Nuisance {
    pub gradient: Vec<[f64; 2]>,
    pub sigma: f64,
    pub cap_sigmas: f64,
}

/// A shot's nuisances (one or two).
#[derive(Debug, Clone)]
pub(crate) struct StartNuisances(pub Vec<Nuisance>);

impl StartNuisances {
    /// Moves `sim`'s observed positions as the best values `e` of the nuisances would, to first order: the
    /// minimiser of `Σ w·|r + Σ_a e_a·g_a|² + Σ_a (e_a/σ_a)²` over the frames (`r` the residual, `g_a` the
    /// gradients, `w = 1/σ_f²`), each held within its cap. Cost: two passes over the frames.
    pub fn apply(&self, shot: &MeasuredShot, sim: &mut Simulation) {
        let n = self.0.len();
        if n == 0 || n > 2 {
            return;
        }
        let mut a = [[0.0f64; 2]; 2];
        let mut b = [0.0f64; 2];
        for (k, nu) in self.0.iter().enumerate() {
            a[k][k] = 1.0 / (nu.sigma * nu.sigma);
        }
        for (i, (f, p)) in shot.frames.iter().zip(&sim.samples).enumerate() {
            let w = 1.0 / (f.sigma_m * f.sigma_m);
            let r = [p.observed.x - f.x_m, p.observed.y - f.y_m];
            for (k, nu) in self.0.iter().enumerate() {
                let g = nu.gradient[i];
                b[k] += w * (r[0] * g[0] + r[1] * g[1]);
                for (l, mu) in self.0.iter().enumerate().skip(k) {
                    let h = mu.gradient[i];
                    a[k][l] += w * (g[0] * h[0] + g[1] * h[1]);
                }
            }
        }
        let e = if n == 1 {
            [-b[0] / a[0][0], 0.0]
        } else {
            let det = a[0][0] * a[1][1] - a[0][1] * a[0][1];
            [
                -(a[1][1] * b[0] - a[0][1] * b[1]) / det,
                -(a[0][0] * b[1] - a[0][1] * b[0]) / det,
            ]
        };
        let mut e_capped = [0.0; 2];
        for (k, nu) in self.0.iter().enumerate() {
            if !e[k].is_finite() {
                return;
            }
            let cap = nu.cap_sigmas * nu.sigma;
            e_capped[k] = e[k].clamp(-cap, cap);
        }
        for (i, p) in sim.samples.iter_mut().enumerate() {
            for (k, nu) in self.0.iter().enumerate() {
                p.observed.x += e_capped[k] * nu.gradient[i][0];
                p.observed.y += e_capped[k] * nu.gradient[i][1];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MeasuredFrame, StartState};
    use bouncelab_model::{Model, SimOptions, State, simulate_drop};

    fn shot_and_sim(offsets: &[[f64; 2]]) -> (MeasuredShot, Simulation) {
        let times: Vec<f64> = (0..offsets.len()).map(|i| i as f64 * 1e-4).collect();
        let frames: Vec<MeasuredFrame> = times
            .iter()
            .map(|&t_s| MeasuredFrame {
                t_s,
                x_m: 0.0,
                y_m: 0.0,
                sigma_m: 1e-5,
            })
            .collect();
        let shot = MeasuredShot {
            name: "s".into(),
            surface: "clay".into(),
            incline_rad: 0.0,
            frames,
            start: StartState {
                t_s: 0.0,
                state: State::default(),
            },
            measured: None,
            surface_sigma_m: None,
            frame_sigma_rad: None,
            spin_sigma_rad_s: None,
            rim_change_m: None,
        };
        let model = Model::paper(25_650.0, 14.0, 0.5);
        let mut sim = simulate_drop(&model, 0.0, 0.2, &times, &SimOptions::default()).expect("a drop simulates");
        for (p, o) in sim.samples.iter_mut().zip(offsets) {
            p.observed.x = o[0];
            p.observed.y = o[1];
        }
        (shot, sim)
    }

    /// A residual that is exactly a multiple of one gradient is taken out (the prior being weak), and two
    /// independent ones are taken out together.
    #[test]
    fn residuals_along_the_gradients_are_taken_out() {
        let g1: Vec<[f64; 2]> = (0..50).map(|i| [i as f64 * 1e-6, 0.0]).collect();
        let g2: Vec<[f64; 2]> = (0..50).map(|i| [0.0, (i as f64).sqrt() * 1e-6]).collect();
        let offsets: Vec<[f64; 2]> = (0..50).map(|i| [0.3 * g1[i][0], -0.2 * g2[i][1]]).collect();
        let (shot, mut sim) = shot_and_sim(&offsets);
        let both = StartNuisances(vec![
            Nuisance {
                gradient: g1.clone(),
                sigma: 1e3,
                cap_sigmas: 2.0,
            },
            Nuisance {
                gradient: g2.clone(),
                sigma: 1e3,
                cap_sigmas: 2.0,
            },
        ]);
        both.apply(&shot, &mut sim);
        let left = sim
            .samples
            .iter()
            .map(|p| p.observed.x.abs() + p.observed.y.abs())
            .fold(0.0, f64::max);
        assert!(left < 1e-9, "{left}");
    }

    /// The correction is held within the cap, however large the residual.
    #[test]
    fn the_correction_is_capped() {
        let g: Vec<[f64; 2]> = (0..20).map(|_| [1e-6, 0.0]).collect();
        let offsets: Vec<[f64; 2]> = (0..20).map(|_| [-100.0 * 1e-6, 0.0]).collect();
        let (shot, mut sim) = shot_and_sim(&offsets);
        StartNuisances(vec![Nuisance {
            gradient: g,
            sigma: 1.0,
            cap_sigmas: 2.0,
        }])
        .apply(&shot, &mut sim);
        // Moved by +2 (the cap) × 1e-6, not the +100 that would zero it.
        assert!((sim.samples[0].observed.x - (-98e-6)).abs() < 1e-12);
    }
}
