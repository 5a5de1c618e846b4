//! Dormand–Prince 5(4) steps with Hairer's continuous extension, for the simulator's state vector.
//!
//! Hand-written because the simulator needs to stop exactly at events found on the dense output and to
//! restart with a different right-hand side, and because one impact must cost tens of microseconds.

/// Components of the ball's state: x, y, θ, vx, vy, ω.
pub(crate) const N_STATE: usize = 6;
/// Components with the contact's history u_t = ∫ slip dt and ∫ δ dt after the state (integrated only for
/// models that use it, so the others pay nothing for it).
pub(crate) const N_HISTORY: usize = 8;

/// The integrated vector: the state, then (when `N = N_HISTORY`) the contact's history.
pub(crate) type Y<const N: usize> = [f64; N];

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

#[inline]
fn comb<const N: usize>(y: &Y<N>, h: f64, terms: &[(f64, &Y<N>)]) -> Y<N> {
    let mut out = *y;
    for (c, k) in terms {
        for i in 0..N {
            out[i] += h * c * k[i];
        }
    }
    out
}

/// One attempted step from (`t0`, `y0`) of size `h`, with its error estimate and dense output.
#[derive(Debug, Clone)]
pub(crate) struct Step<const N: usize> {
    pub t0: f64,
    pub h: f64,
    pub y0: Y<N>,
    pub y1: Y<N>,
    /// Derivative at the end of the step (first stage of the next one).
    pub f1: Y<N>,
    /// Scaled error norm; the step is acceptable when ≤ 1.
    pub err: f64,
    cont: [Y<N>; 4],
}

impl<const N: usize> Step<N> {
    /// Tries a step. `f0` is the derivative at (`t0`, `y0`).
    pub fn attempt(
        f: &mut impl FnMut(f64, &Y<N>) -> Y<N>,
        t0: f64,
        y0: &Y<N>,
        f0: &Y<N>,
        h: f64,
        rtol: f64,
        atol: f64,
    ) -> Step<N> {
        let k1 = *f0;
        let k2 = f(t0 + C2 * h, &comb(y0, h, &[(A21, &k1)]));
        let k3 = f(t0 + C3 * h, &comb(y0, h, &[(A31, &k1), (A32, &k2)]));
        let k4 = f(t0 + C4 * h, &comb(y0, h, &[(A41, &k1), (A42, &k2), (A43, &k3)]));
        let k5 = f(
            t0 + C5 * h,
            &comb(y0, h, &[(A51, &k1), (A52, &k2), (A53, &k3), (A54, &k4)]),
        );
        let k6 = f(
            t0 + h,
            &comb(y0, h, &[(A61, &k1), (A62, &k2), (A63, &k3), (A64, &k4), (A65, &k5)]),
        );
        let y1 = comb(y0, h, &[(A71, &k1), (A73, &k3), (A74, &k4), (A75, &k5), (A76, &k6)]);
        let k7 = f(t0 + h, &y1);
        let mut sum = 0.0;
        let mut cont = [[0.0; N]; 4];
        for i in 0..N {
            let e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            let sc = atol + rtol * y0[i].abs().max(y1[i].abs());
            sum += (e / sc) * (e / sc);
            let ydiff = y1[i] - y0[i];
            let bspl = h * k1[i] - ydiff;
            cont[0][i] = ydiff;
            cont[1][i] = bspl;
            cont[2][i] = ydiff - h * k7[i] - bspl;
            cont[3][i] = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
        let err = (sum / N as f64).sqrt();
        Step {
            t0,
            h,
            y0: *y0,
            y1,
            f1: k7,
            err: if err.is_nan() { f64::INFINITY } else { err },
            cont,
        }
    }

    /// The state at time `t` inside the step, from the 4th-order continuous extension.
    pub fn at(&self, t: f64) -> Y<N> {
        let th = ((t - self.t0) / self.h).clamp(0.0, 1.0);
        let th1 = 1.0 - th;
        let mut out = [0.0; N];
        for (i, o) in out.iter_mut().enumerate() {
            let c = &self.cont;
            *o = self.y0[i] + th * (c[0][i] + th1 * (c[1][i] + th * (c[2][i] + th1 * c[3][i])));
        }
        out
    }

    /// Next step size after this one (Hairer's controller without memory).
    pub fn next_h(&self) -> f64 {
        let fac = if self.err == 0.0 {
            5.0
        } else {
            (0.9 * self.err.powf(-0.2)).clamp(0.2, 5.0)
        };
        self.h * fac
    }
}

/// A root of `g` on [a, b] where g(a) and g(b) have opposite signs (Illinois variant of regula falsi).
pub(crate) fn find_root(
    mut g: impl FnMut(f64) -> f64,
    mut a: f64,
    mut ga: f64,
    mut b: f64,
    mut gb: f64,
    tol: f64,
) -> f64 {
    let mut side = 0;
    for _ in 0..100 {
        if (b - a).abs() <= tol {
            break;
        }
        let c = (a * gb - b * ga) / (gb - ga);
        let c = if c.is_finite() && c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let gc = g(c);
        if gc == 0.0 {
            return c;
        }
        if (gc > 0.0) == (gb > 0.0) {
            b = c;
            gb = gc;
            if side == -1 {
                ga *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            ga = gc;
            if side == 1 {
                gb *= 0.5;
            }
            side = 1;
        }
    }
    // Return the end on the far side of the crossing, so the event is never reported early.
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Harmonic oscillator x'' = −x along components 1 and 4 (y, vy).
    fn osc(_t: f64, y: &Y<6>) -> Y<6> {
        [0.0, y[4], 0.0, 0.0, -y[1], 0.0]
    }

    /// Largest dense-output error over a step of size `h`.
    fn dense_error(h: f64) -> f64 {
        let mut f = osc;
        let y0 = [0.0, 1.0, 0.0, 0.0, 0.0, 0.0];
        let f0 = f(0.0, &y0);
        let s = Step::attempt(&mut f, 0.0, &y0, &f0, h, 1e-10, 1e-12);
        (0..=20)
            .map(|i| {
                let t = h * i as f64 / 20.0;
                let y = s.at(t);
                (y[1] - t.cos()).abs().max((y[4] + t.sin()).abs())
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn step_and_dense_output_match_the_exact_solution() {
        let mut f = osc;
        let y0 = [0.0, 1.0, 0.0, 0.0, 0.0, 0.0];
        let f0 = f(0.0, &y0);
        let s = Step::attempt(&mut f, 0.0, &y0, &f0, 0.1, 1e-10, 1e-12);
        assert!((s.y1[1] - 0.1f64.cos()).abs() < 1e-9);
        // The continuous extension is of order 4: its error over a step falls as h⁵.
        let (e1, e2) = (dense_error(0.2), dense_error(0.1));
        assert!(e2 < 1e-7, "dense error {e2:e}");
        let order = (e1 / e2).log2();
        assert!(
            (4.5..6.5).contains(&order),
            "observed local order {order} ({e1:e}, {e2:e})"
        );
    }

    #[test]
    fn root_finder_converges_on_a_smooth_crossing() {
        let r = find_root(|x| x * x - 2.0, 0.0, -2.0, 2.0, 2.0, 1e-14);
        assert!((r - 2f64.sqrt()).abs() < 1e-13);
    }
}
