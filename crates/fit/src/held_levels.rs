//! Each shot's surface level held at given values: the residuals there, and the Jacobian of the shared
//! parameters with the levels projected out. That reduced Jacobian is the one a fit with profiled levels
//! steps with (variable projection) and the one its standard errors come from: differences taken through
//! the profile are noisy and cost a profile per column.

use crate::solver::{Differences, LeastSquares, LevenbergMarquardt};
use crate::{FitError, Problem, surface_prior, weighted_residuals};
use nalgebra::{DMatrix, DVector};

/// Step of a surface level in its finite differences, m (as the profile of a level steps).
const LEVEL_STEP_M: f64 = 1e-6;

impl Problem {
    /// All residuals (frames, then each shot's level prior) with `theta` and every shot at its level in
    /// `levels` (one per shot, m). One simulation of every shot.
    pub fn residuals_held(&self, theta: &[f64], levels: &[f64]) -> Result<DVector<f64>, FitError> {
        let all: Vec<usize> = (0..self.shots().len()).collect();
        let sims = self.simulate_at_levels(theta, levels, &all)?;
        let mut r = Vec::with_capacity(self.n_residuals() + levels.len());
        for (shot, sim) in self.shots().iter().zip(&sims) {
            r.extend(weighted_residuals(shot, sim));
        }
        r.extend(
            self.shots()
                .iter()
                .zip(levels)
                .map(|(shot, &l)| surface_prior(shot, l).unwrap_or(0.0)),
        );
        Ok(DVector::from_vec(r))
    }

    /// The Jacobian of the residuals with respect to the shared parameters at `theta`, with every shot's
    /// surface level (m, `levels`) marginalised: differences with the levels held, then each shot's level
    /// column (all levels stepped at once: a level moves only its own shot's residuals and prior)
    /// projected out of that shot's rows, the Schur complement of the joint Jacobian. Its `(JᵀJ)⁻¹` is the
    /// shared parameters' covariance with the levels free, as profiling them gives, without the noise that
    /// profiling inside each difference puts into the columns (which made the nearly collinear λ and n of
    /// Hunt–Crossley look determined to 0.05 %); at profiled levels, `Jᵀr` is the profiled cost's exact
    /// gradient. Cost: 2p + 2 simulations of every shot with central differences, p + 2 with forward
    /// ones, less for a parameter of one surface (only its shots are simulated again).
    pub fn reduced_jacobian(
        &self,
        solver: &LevenbergMarquardt,
        theta: &[f64],
        levels: &[f64],
        differences: Differences,
    ) -> Result<DMatrix<f64>, FitError> {
        let mut jac = solver.jacobian_with(&HeldLevels { problem: self, levels }, theta, differences)?;
        let h = LEVEL_STEP_M;
        let up: Vec<f64> = levels.iter().map(|l| l + h).collect();
        let dl = match differences {
            Differences::Central => {
                let dn: Vec<f64> = levels.iter().map(|l| l - h).collect();
                (self.residuals_held(theta, &up)? - self.residuals_held(theta, &dn)?) / (2.0 * h)
            }
            Differences::Forward => (self.residuals_held(theta, &up)? - self.residuals_held(theta, levels)?) / h,
        };
        let n_frames = self.n_residuals();
        for (i, shot) in self.shots().iter().enumerate() {
            let at = self.first_residual(i);
            let rows: Vec<usize> = (at..at + 2 * shot.frames.len()).chain([n_frames + i]).collect();
            let ll: f64 = rows.iter().map(|&k| dl[k] * dl[k]).sum();
            if ll <= 0.0 {
                continue;
            }
            for j in 0..theta.len() {
                let coef = rows.iter().map(|&k| dl[k] * jac[(k, j)]).sum::<f64>() / ll;
                for &k in &rows {
                    jac[(k, j)] -= coef * dl[k];
                }
            }
        }
        Ok(jac)
    }
}

/// A problem's residuals with every shot's surface level held at `levels` (m), as a least-squares problem
/// in the shared parameters only.
struct HeldLevels<'a> {
    problem: &'a Problem,
    levels: &'a [f64],
}

impl LeastSquares for HeldLevels<'_> {
    fn n_params(&self) -> usize {
        self.problem.params().len()
    }

    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, FitError> {
        Ok(self.problem.residuals_held(theta, self.levels)?.data.into())
    }

    /// Only the shots of parameter `j`'s surface are simulated again (the levels, so their priors, held).
    fn residuals_changing(&self, theta: &[f64], j: usize, base: &[f64]) -> Result<Vec<f64>, FitError> {
        let p = self.problem;
        let Some(which) = p.shots_of_param(j) else {
            return self.residuals(theta);
        };
        let sims = p.simulate_at_levels(theta, self.levels, &which)?;
        let mut r = base.to_vec();
        for (&i, sim) in which.iter().zip(&sims) {
            let at = p.first_residual(i);
            r[at..at + 2 * p.shots()[i].frames.len()].copy_from_slice(&weighted_residuals(&p.shots()[i], sim));
        }
        Ok(r)
    }

    fn bounds(&self, j: usize) -> (f64, f64) {
        self.problem.bounds(j)
    }

    fn scale(&self, j: usize) -> f64 {
        self.problem.scale(j)
    }
}
