//! Where the ball will be: a least-squares parabola through its recent fixes, its acceleration bounded by
//! what a ball can take.
//!
//! A parabola through only the last three fixes is exact for a clean track but turns a noisy rim's error
//! into acceleration: its second difference carries √6 ≈ 2.4 times the centre's noise, and a tracker that
//! then searches around that prediction can follow a seam or the texture away from the ball, faster every
//! frame. Fitted through eight fixes, the acceleration's noise is about 16 times smaller, and bounded by
//! physical limits it cannot run away: no ball accelerates faster than a hard contact pushes it, and none
//! towards the surface faster than gravity (contact only ever pushes it away).

/// A motion per axis x(τ) = p + v τ + ½ a τ², with τ the time since the last fix, s; px, px/s, px/s².
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Motion {
    /// Time of the last fix, s.
    pub t_ref: f64,
    /// Position at `t_ref`, px.
    pub p: [f64; 2],
    /// Velocity at `t_ref`, px/s.
    pub v: [f64; 2],
    /// Acceleration, px/s².
    pub a: [f64; 2],
}

impl Motion {
    /// The position at `t`, px.
    pub fn at(&self, t: f64) -> (f64, f64) {
        let tau = t - self.t_ref;
        let axis = |k: usize| self.p[k] + self.v[k] * tau + 0.5 * self.a[k] * tau * tau;
        (axis(0), axis(1))
    }

    /// Speed at the last fix, px/s.
    pub fn speed(&self) -> f64 {
        self.v[0].hypot(self.v[1])
    }
}

/// The least-squares motion through `fixes` (t in s, x and y in px; in time order, the last one latest):
/// a parabola through three or more, a line through two, a point through one; `None` without any.
///
/// With `max_accel` (px/s²) the acceleration's size is held to it, with `max_down` (px/s²) its downward
/// (+y, towards the surface) part, and position and velocity are refitted under that acceleration;
/// `Some(0.0)` fits a straight line. Cost: O(n) for n fixes.
pub(crate) fn fit_motion(fixes: &[(f64, f64, f64)], max_accel: Option<f64>, max_down: Option<f64>) -> Option<Motion> {
    let &(t_ref, x_last, y_last) = fixes.last()?;
    let n = fixes.len();
    let still = Motion {
        t_ref,
        p: [x_last, y_last],
        v: [0.0; 2],
        a: [0.0; 2],
    };
    if n == 1 {
        return Some(still);
    }
    // τ scaled by the span keeps the normal equations well conditioned at any frame rate.
    let span = (t_ref - fixes[0].0).abs().max(1e-12);
    let taus: Vec<f64> = fixes.iter().map(|f| (f.0 - t_ref) / span).collect();
    let axes = [
        fixes.iter().map(|f| f.1).collect::<Vec<_>>(),
        fixes.iter().map(|f| f.2).collect::<Vec<_>>(),
    ];
    let mut a = [0.0; 2];
    if n >= 3 && max_accel != Some(0.0) {
        for k in 0..2 {
            if let Some(c) = least_squares(&taus, &axes[k], 3) {
                a[k] = 2.0 * c[2] / (span * span);
            }
        }
        if let Some(limit) = max_down {
            a[1] = a[1].min(limit);
        }
        if let Some(limit) = max_accel {
            let size = a[0].hypot(a[1]);
            if size > limit {
                a = [a[0] * limit / size, a[1] * limit / size];
            }
        }
    }
    let mut motion = still;
    motion.a = a;
    for k in 0..2 {
        // Position and velocity under the chosen acceleration.
        let rest: Vec<f64> = axes[k]
            .iter()
            .zip(&taus)
            .map(|(x, tau)| x - 0.5 * a[k] * (tau * span).powi(2))
            .collect();
        let c = least_squares(&taus, &rest, 2)?;
        motion.p[k] = c[0];
        motion.v[k] = c[1] / span;
    }
    Some(motion)
}

/// Coefficients c of the polynomial Σ c_j τ^j (`terms` of them, at most 3) closest to `values` in least
/// squares; `None` when the τ do not determine them (repeated times).
fn least_squares(taus: &[f64], values: &[f64], terms: usize) -> Option<[f64; 3]> {
    let mut m = [[0.0; 4]; 3];
    for (&tau, &x) in taus.iter().zip(values) {
        let powers = [1.0, tau, tau * tau];
        for i in 0..terms {
            for j in 0..terms {
                m[i][j] += powers[i] * powers[j];
            }
            m[i][3] += powers[i] * x;
        }
    }
    // Gaussian elimination with partial pivoting on the `terms`×`terms` normal equations.
    for col in 0..terms {
        let pivot = (col..terms).max_by(|&p, &q| m[p][col].abs().total_cmp(&m[q][col].abs()))?;
        if m[pivot][col].abs() < 1e-12 * (1.0 + m[col][col].abs()) {
            return None;
        }
        m.swap(col, pivot);
        let pivot_row = m[col];
        for (i, row) in m.iter_mut().enumerate().take(terms) {
            if i != col {
                let f = row[col] / pivot_row[col];
                for (x, p) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                    *x -= f * p;
                }
            }
        }
    }
    let mut c = [0.0; 3];
    for i in 0..terms {
        c[i] = m[i][3] / m[i][i];
    }
    Some(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parabola(n: usize, dt: f64, p: [f64; 2], v: [f64; 2], a: [f64; 2]) -> Vec<(f64, f64, f64)> {
        (0..n)
            .map(|i| {
                let t = i as f64 * dt;
                (
                    t,
                    p[0] + v[0] * t + 0.5 * a[0] * t * t,
                    p[1] + v[1] * t + 0.5 * a[1] * t * t,
                )
            })
            .collect()
    }

    #[test]
    fn a_point_and_a_line_are_extrapolated_as_such() {
        let m = fit_motion(&[(0.0, 3.0, 4.0)], None, None).unwrap();
        assert_eq!(m.at(1.0), (3.0, 4.0));
        let m = fit_motion(&[(0.0, 0.0, 0.0), (1e-4, 1.0, -2.0)], None, None).unwrap();
        let (x, y) = m.at(3e-4);
        assert!((x - 3.0).abs() < 1e-9 && (y + 6.0).abs() < 1e-9, "{x} {y}");
        assert!(fit_motion(&[], None, None).is_none());
    }

    #[test]
    fn a_bounded_acceleration_holds_a_noisy_track_from_running_away() {
        // Eight fixes of a ball at rest with ±2 px of alternating error: three of them alone make an
        // acceleration of 8 px per frame².
        let noisy: Vec<_> = (0..8)
            .map(|i| (i as f64 * 1e-4, 100.0, 100.0 + if i % 2 == 0 { 2.0 } else { -2.0 }))
            .collect();
        let three = fit_motion(&noisy[5..], None, None).unwrap();
        let eight = fit_motion(&noisy, Some(1e6), None).unwrap();
        let ahead = |m: &Motion| (m.at(noisy[7].0 + 10e-4).1 - 100.0).abs();
        assert!(ahead(&three) > 100.0, "three fixes: {}", ahead(&three));
        assert!(ahead(&eight) < 5.0, "eight fixes, bounded: {}", ahead(&eight));
        assert!(eight.a[0].hypot(eight.a[1]) <= 1e6 * (1.0 + 1e-12));
    }

    #[test]
    fn a_zero_bound_fits_a_straight_line() {
        let fixes = parabola(6, 1e-4, [10.0, 20.0], [1e4, 0.0], [0.0, 1e8]);
        let m = fit_motion(&fixes, Some(0.0), None).unwrap();
        assert_eq!(m.a, [0.0, 0.0]);
        assert!((m.v[0] - 1e4).abs() < 1e-6);
    }

    #[test]
    fn a_track_never_falls_faster_than_the_bound_towards_the_surface() {
        // Fixes that accelerate downward at 1 px per frame² (a search sliding down a seam) and sideways at
        // 0.5: the downward part is held to the bound, the sideways part kept.
        let fixes = parabola(8, 1e-4, [0.0, 0.0], [0.0, 0.0], [0.5e8, 1e8]);
        let m = fit_motion(&fixes, None, Some(1e6)).unwrap();
        assert!((m.a[1] - 1e6).abs() < 1e-6, "{:?}", m.a);
        assert!((m.a[0] - 0.5e8).abs() < 1e-3 * 0.5e8, "{:?}", m.a);
        // Upward (a bounce's push) is not bounded by it.
        let up = parabola(8, 1e-4, [0.0, 0.0], [0.0, 0.0], [0.0, -1e8]);
        assert!((fit_motion(&up, None, Some(1e6)).unwrap().a[1] + 1e8).abs() < 1e-3 * 1e8);
    }

    proptest! {
        /// An exact parabola is recovered at any frame rate and size, and its extrapolation is exact.
        #[test]
        fn an_exact_parabola_is_recovered(
            n in 3usize..12,
            dt in 1e-6f64..1e-2,
            px in -500.0f64..500.0, py in -500.0f64..500.0,
            vx in -3e3f64..3e3, vy in -3e3f64..3e3,
            ax in -1e3f64..1e3, ay in -1e3f64..1e3,
        ) {
            // Velocities and accelerations in px per frame and per frame².
            let (v, a) = ([vx / dt / 1e3, vy / dt / 1e3], [ax / (dt * dt) / 1e4, ay / (dt * dt) / 1e4]);
            let fixes = parabola(n, dt, [px, py], v, a);
            let m = fit_motion(&fixes, None, None).unwrap();
            let t = n as f64 * dt;
            let (x, y) = m.at(t);
            let (ex, ey) = (px + v[0] * t + 0.5 * a[0] * t * t, py + v[1] * t + 0.5 * a[1] * t * t);
            prop_assert!((x - ex).abs() < 1e-6 * (1.0 + ex.abs()), "x {x} vs {ex}");
            prop_assert!((y - ey).abs() < 1e-6 * (1.0 + ey.abs()), "y {y} vs {ey}");
        }
    }
}
