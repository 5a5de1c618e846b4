//! The ball and its state.

use serde::{Deserialize, Serialize};

/// The ball: a sphere of mass `m`, radius `R` and moment of inertia `I = c·m·R²`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Ball {
    /// Mass `m`, kg.
    pub mass_kg: f64,
    /// Radius `R`, m.
    pub radius_m: f64,
    /// Inertia factor `c` in `I = c·m·R²` (dimensionless): 2/3 for a thin shell, 2/5 for a solid sphere.
    pub inertia_factor: f64,
}

impl Ball {
    /// The paper's tennis ball: 56.7 g, radius 33.5 mm, thin shell.
    pub const TENNIS: Ball = Ball {
        mass_kg: 0.0567,
        radius_m: 0.0335,
        inertia_factor: 2.0 / 3.0,
    };

    /// Moment of inertia about the centre, kg·m², with the inertia factor shifted by `dc`.
    pub fn inertia(&self, dc: f64) -> f64 {
        (self.inertia_factor + dc) * self.mass_kg * self.radius_m * self.radius_m
    }
}

impl Default for Ball {
    fn default() -> Self {
        Ball::TENNIS
    }
}

/// The ball's planar state in the local frame (`docs/outputs.md`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct State {
    /// Centre position along the surface (down-slope), m.
    pub x: f64,
    /// Centre height above the surface line, m (`R` when just touching).
    pub y: f64,
    /// Orientation, rad, counter-clockwise as seen by the camera.
    pub theta: f64,
    /// Tangential (down-slope) velocity of the centre, m/s.
    pub vx: f64,
    /// Normal velocity of the centre, m/s (negative towards the surface).
    pub vy: f64,
    /// Spin, rad/s, counter-clockwise as seen by the camera.
    pub omega: f64,
}

impl State {
    /// A ball in flight at height `y` above the surface line with velocity (`vx`, `vy`), no spin.
    pub fn flying(x: f64, y: f64, vx: f64, vy: f64) -> State {
        State {
            x,
            y,
            theta: 0.0,
            vx,
            vy,
            omega: 0.0,
        }
    }

    /// The integrated vector with this state and no contact history.
    pub(crate) fn to_array<const N: usize>(self) -> [f64; N] {
        let mut a = [0.0; N];
        a[..6].copy_from_slice(&[self.x, self.y, self.theta, self.vx, self.vy, self.omega]);
        a
    }

    pub(crate) fn from_array<const N: usize>(a: [f64; N]) -> State {
        State {
            x: a[0],
            y: a[1],
            theta: a[2],
            vx: a[3],
            vy: a[4],
            omega: a[5],
        }
    }

    /// Speed of the centre, m/s.
    pub fn speed(&self) -> f64 {
        self.vx.hypot(self.vy)
    }
}
