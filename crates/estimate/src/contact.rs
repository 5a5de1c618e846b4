//! Where the contact is, from the ball's own trajectory: the evidence that needs no surface line.
//!
//! In free flight the centre follows a parabola whose acceleration is gravity's; from the touch on, the
//! surface pushes it up off that parabola. The push starts at zero displacement and grows smoothly: a force
//! `P(τ) ≈ P₀ + P₁τ` (a damping force already at the touch, then the spring's) lifts the centre by
//! `A·τ² + B·τ³` above the arc, `A, B ≥ 0`, `τ` the time since the touch. So the touch time is found by
//! fitting the arc and that onset together to the frames from the first one to half-way to the lowest centre,
//! for every candidate touch time on a fine grid (a tenth of a frame), and taking the best; its standard error
//! is where the profile χ² rises by one (scaled by the fit's reduced χ² times the variance factor of the
//! early arc's residual correlation, (1+ρ)/(1−ρ), when that exceeds one). The centre's height on the arc
//! at that time is the contact level. The same from the other side (time reversed) gives where the ball
//! rejoins its outgoing arc: a check of the touch, not a second measure of the level, since the push is
//! zero there and grows only as the ball sinks back (a cubic onset, seen late), and with damping while it
//! unloads or a dented surface the ball leaves while still pressed in. The lowest centre must lie below
//! the touch.
//!
//! This is model-free (any contact force that is positive and growing from the touch) but it is slow to
//! see the first frames of contact, so its error is a few tenths of a pixel where a surface line's is a few
//! hundredths; a fit of a contact model to every shot (the fit crate's surface level) refines it.

use crate::shot::{EstimateError, MIN_FLIGHT_FRAMES};

/// One measured centre: time (s), height along the surface normal (px, up positive, any origin), its
/// standard error (px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightPoint {
    /// Time, s.
    pub t: f64,
    /// Height, px.
    pub h: f64,
    /// Standard error, px.
    pub sigma: f64,
}

/// Where the trajectory says the contact is.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryContact {
    /// Height of the centre at the contact level, px (same origin as the points): at the touch.
    pub level_px: f64,
    /// Its standard error, px.
    pub level_se_px: f64,
    /// Touch: the time the ball leaves its incoming arc (s) and its standard error.
    pub t_touch: (f64, f64),
    /// The touch's level alone (px, se).
    pub touch_level: (f64, f64),
    /// Where the ball rejoins its outgoing arc, when it could be measured: the time (s, se) and level
    /// (px, se).
    pub separation: Option<((f64, f64), (f64, f64))>,
    /// Height of the lowest centre, px.
    pub lowest_px: f64,
    /// What a person should know (a separation lower than the touch, a level poorly determined).
    pub notes: Vec<String>,
    /// False when the touch and the separation put the contact at levels more than 2σ apart: the trajectory
    /// contradicts itself (an arc it does not follow, such as a drag-slowed flight), so it can place a contact
    /// when nothing else does but cannot overrule a line seen in the image.
    pub consistent: bool,
}

/// Whether the trajectory holds an impact: `Ok(index of the lowest point)` when the centre comes down and
/// goes up again, else [`EstimateError::NoImpact`] with the speed along the normal at the clip's end.
pub fn find_impact(points: &[HeightPoint], a_px: f64, m_per_px: f64) -> Result<usize, EstimateError> {
    let n = points.len();
    let low = (0..n)
        .min_by(|&a, &b| points[a].h.total_cmp(&points[b].h))
        .ok_or(EstimateError::NoScale)?;
    // An impact needs the ball to come down to the lowest point and go up again, each by more than the
    // noise and over more than a couple of frames.
    let rise = |range: &[HeightPoint]| range.iter().map(|p| p.h).fold(f64::NEG_INFINITY, f64::max) - points[low].h;
    let margin = |p: &HeightPoint| 5.0 * p.sigma.max(0.05);
    let before = &points[..low];
    let after = &points[low + 1..];
    if before.len() >= 3
        && after.len() >= 3
        && rise(before) > margin(&points[low])
        && rise(after) > margin(&points[low])
    {
        return Ok(low);
    }
    // No impact: the normal speed at the last frame from a ballistic fit of the whole clip (or of its last
    // frames, should that fail), with its error.
    let (speed, se) = end_speed(points, a_px).unwrap_or((f64::NAN, f64::NAN));
    Err(EstimateError::NoImpact {
        frames: n,
        speed_m_s: speed * m_per_px,
        se_m_s: se * m_per_px,
    })
}

/// Normal velocity (px/s) at the last point of a ballistic arc fitted to all points, and its standard error.
fn end_speed(points: &[HeightPoint], a_px: f64) -> Option<(f64, f64)> {
    let t_last = points.last()?.t;
    let dt = median_step(points)?;
    let clock = Clock { t_ref: t_last, dt };
    let (c, cov, chi2) = fit_onset(points, a_px, &clock, None)?;
    let inflate = (chi2 / (points.len() as f64 - 2.0).max(1.0)).max(1.0);
    Some((c[1] / dt, (cov[1][1] * inflate).max(0.0).sqrt() / dt))
}

/// The contact level from the trajectory around the impact at `low` (see the module's description).
/// `a_px` is gravity's component along the normal, px/s² (negative: down), `radius_px` the ball's radius.
pub fn trajectory_contact(
    points: &[HeightPoint],
    low: usize,
    a_px: f64,
    radius_px: f64,
) -> Result<TrajectoryContact, EstimateError> {
    let lowest = points[low].h;
    let touch = onset(&points[..=low], lowest, a_px, radius_px).ok_or(if low < 2 * MIN_FLIGHT_FRAMES {
        EstimateError::FlightTooShort {
            phase: "incoming",
            frames: low,
            needed: 2 * MIN_FLIGHT_FRAMES,
            why: "the clip starts too close to the impact",
        }
    } else {
        EstimateError::NoDeparture { frames: low }
    })?;
    // The outgoing side, time reversed: the ball rejoining its arc is, backwards, the ball leaving it.
    let reversed: Vec<HeightPoint> = points[low..]
        .iter()
        .rev()
        .map(|p| HeightPoint { t: -p.t, ..*p })
        .collect();
    let sep = onset(&reversed, lowest, a_px, radius_px);
    let mut notes = Vec::new();
    for (side, o) in [("touch", Some(&touch)), ("separation", sep.as_ref())] {
        if let Some(o) = o.filter(|o| o.bounded) {
            notes.push(format!(
                "the trajectory does not place the {side} (its best time lies at the edge of the frames searched): its level is uncertain by ± {:.2} px",
                o.level_se
            ));
        }
    }
    // The surface's level is where the ball touched; where it leaves only checks that. The push falls to
    // zero at the separation, so the lift there starts as τ³ and is seen late (on noise-free renders of
    // the paper's model, which leaves where it touched, 0.13–0.69 px below the touch, the touch within
    // 0.15 px), and with damping while it unloads, or a surface that keeps a dent, the ball leaves while
    // still pressed in.
    let (level, level_se) = (touch.level, touch.level_se);
    let mut consistent = true;
    let separation = sep.as_ref().map(|s| ((-s.t0, s.t0_se), (s.level, s.level_se)));
    if let Some(s) = &sep {
        let gap = s.level - touch.level;
        let se = s.level_se.hypot(touch.level_se);
        if gap.abs() > 2.0 * se {
            consistent = false;
            notes.push(format!(
                "the ball leaves its contact {:.2} ± {:.2} px {} where it touched (from its trajectory)",
                gap.abs(),
                se,
                if gap < 0.0 { "lower than" } else { "higher than" }
            ));
        }
    }
    if lowest > level {
        notes.push(format!(
            "the lowest centre is {:.2} px above the contact level the trajectory gives: the level is poorly determined",
            lowest - level
        ));
    }
    Ok(TrajectoryContact {
        level_px: level,
        level_se_px: level_se,
        t_touch: (touch.t0, touch.t0_se),
        touch_level: (touch.level, touch.level_se),
        separation,
        lowest_px: lowest,
        notes,
        consistent,
    })
}

/// The best onset on one side of the impact.
struct Onset {
    t0: f64,
    t0_se: f64,
    level: f64,
    level_se: f64,
    /// The best onset lay at the first time searched (see [`onset`]): a bound, not a placement.
    bounded: bool,
}

/// Grid step of candidate touch times, in frames.
const GRID_FRAMES: f64 = 0.1;
/// Standardized residual that counts as a departure from the arc (three frames in a row).
const DEPARTURE_SIGMAS: f64 = 3.0;
/// Standardized residual under which the centre is back on its arc (see [`onset`]).
const RETURN_SIGMAS: f64 = 2.0;
/// How far before the first clear departure the touch may lie, frames (the onset grows as τ², so a touch
/// is seen at 3σ some frames later; 12 frames covers a damping-free spring's cubic onset at 0.05 px noise).
const LOOK_BACK_FRAMES: f64 = 12.0;

/// The onset fit on `side` (flight first, the lowest point last): the arc of the first half of the frames
/// (in time) extrapolated until the centre departs from it for three frames in a row after its last frame
/// back within [`RETURN_SIGMAS`] of it, then the onset model fitted for touch times on a grid up to that
/// departure, over the frames up to 40 % of the way from the departure to the lowest centre.
fn onset(side: &[HeightPoint], _lowest: f64, a_px: f64, _radius_px: f64) -> Option<Onset> {
    if side.len() < MIN_FLIGHT_FRAMES + 4 {
        return None;
    }
    let dt = median_step(side)?;
    let (t_first, t_low) = (side[0].t, side[side.len() - 1].t);
    let early: Vec<HeightPoint> = side
        .iter()
        .copied()
        .filter(|p| p.t <= 0.5 * (t_first + t_low))
        .collect();
    if early.len() < MIN_FLIGHT_FRAMES {
        return None;
    }
    let clock = Clock {
        t_ref: early[early.len() - 1].t,
        dt,
    };
    let (c, _, chi2) = fit_onset(&early, a_px, &clock, None)?;
    let inflate = (chi2 / (early.len() as f64 - 2.0).max(1.0)).max(1.0).sqrt();
    let a_u = a_px * dt * dt;
    let off_arc = |p: &HeightPoint| {
        let u = clock.u(p.t);
        (p.h - (c[0] + c[1] * u + 0.5 * a_u * u * u)) / (p.sigma * inflate)
    };
    let departs = |p: &HeightPoint| off_arc(p) > DEPARTURE_SIGMAS;
    let rest = &side[early.len()..];
    // The push only grows from the touch to the lowest centre, so a track back on its arc had not touched
    // yet: a track biased differently across the frame creeps off its arc and back before the contact.
    let from = rest
        .iter()
        .rposition(|p| off_arc(p) < RETURN_SIGMAS)
        .map_or(0, |i| i + 1);
    let first_departure = (from..rest.len().saturating_sub(2)).find(|&i| rest[i..i + 3].iter().all(departs))?;
    let t_dep = rest[first_departure].t;
    let t_end = t_dep + 0.4 * (t_low - t_dep);
    let used: Vec<HeightPoint> = side.iter().copied().filter(|p| p.t <= t_end).collect();
    let clock = Clock { t_ref: t_dep, dt };
    // Profile χ² over candidate touch times.
    let t_from = (t_dep - LOOK_BACK_FRAMES * dt).max(early[early.len() / 2].t);
    let steps = ((t_dep - t_from) / (GRID_FRAMES * dt)).ceil().max(1.0) as usize;
    // (touch time, χ², coefficients, their covariance)
    type ProfilePoint = (f64, f64, [f64; 4], [[f64; 4]; 4]);
    let profile: Vec<ProfilePoint> = (0..=steps)
        .filter_map(|i| {
            let t0 = t_from + (t_dep - t_from) * i as f64 / steps as f64;
            let (c, cov, chi2) = fit_onset(&used, a_px, &clock, Some(t0))?;
            Some((t0, chi2, c, cov))
        })
        .collect();
    let best = profile.iter().min_by(|a, b| a.1.total_cmp(&b.1))?;
    let dof = (used.len() as f64 - 4.0).max(1.0);
    // Neighbouring residuals of a tracker drift together: the fit's scatter counts as its variance factor
    // (1+ρ)/(1−ρ) over independent ones (the same factor as the flights' fits), ρ measured on the best fit's
    // residuals over the frames it used, in time order.
    let correlated = crate::ballistic::ar1_factor(&onset_residuals(&used, a_px, &clock, Some(best.0), &best.2));
    let scale = (best.1 / dof * correlated).max(1.0);
    // The Δχ² = 1 interval (in units of the fit's own scatter), its half-width the standard error.
    let inside: Vec<f64> = profile.iter().filter(|p| p.1 - best.1 <= scale).map(|p| p.0).collect();
    let (lo, hi) = (
        inside.iter().cloned().fold(f64::INFINITY, f64::min),
        inside.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
    );
    let mut t0_se = (0.5 * (hi - lo)).max(0.5 * GRID_FRAMES * dt);
    // Best at the first time searched: the χ² still falls there, so the frames bound the onset (it lies that
    // far back or further) but do not place it; its error is then the whole window searched.
    let bounded = best.0 <= t_from + 0.5 * GRID_FRAMES * dt && t_dep > t_from;
    if bounded {
        t0_se = t0_se.max(t_dep - t_from);
    }
    let (t0, c, cov) = (best.0, best.2, best.3);
    let u0 = clock.u(t0);
    let level = c[0] + c[1] * u0 + 0.5 * a_u * u0 * u0;
    let v = (c[1] + a_u * u0) / dt;
    // The arc's own error at t0 (its position and velocity correlated), plus the touch time's.
    let arc_var = cov[0][0] + 2.0 * u0 * cov[0][1] + u0 * u0 * cov[1][1];
    let level_se = (arc_var.max(0.0) * scale + (v * t0_se).powi(2)).sqrt();
    Some(Onset {
        t0,
        t0_se,
        level,
        level_se,
        bounded,
    })
}

/// The onset's terms at `p` (see [`fit_onset`]): its basis 1, u, τ², τ³ (τ the frames since the touch at
/// `u0`, 0 before it or without one) and the arc's known part ½·a·u², `a_u` the acceleration per frame².
fn onset_terms(p: &HeightPoint, clock: &Clock, a_u: f64, u0: Option<f64>) -> ([f64; 4], f64) {
    let u = clock.u(p.t);
    let tau = u0.map_or(0.0, |u0| (u - u0).max(0.0));
    ([1.0, u, tau * tau, tau * tau * tau], 0.5 * a_u * u * u)
}

/// The residuals (in units of each point's σ) of the onset `c` with the touch at `t0` (none: the arc alone).
fn onset_residuals(points: &[HeightPoint], a_px: f64, clock: &Clock, t0: Option<f64>, c: &[f64; 4]) -> Vec<f64> {
    let (a_u, u0) = (a_px * clock.dt * clock.dt, t0.map(|t| clock.u(t)));
    points
        .iter()
        .map(|p| {
            let (b, known) = onset_terms(p, clock, a_u, u0);
            let model = (0..4).map(|k| c[k] * b[k]).sum::<f64>() + known;
            (p.h - model) / p.sigma
        })
        .collect()
}

/// The median time between consecutive points, s.
fn median_step(points: &[HeightPoint]) -> Option<f64> {
    let mut d: Vec<f64> = points
        .windows(2)
        .map(|w| (w[1].t - w[0].t).abs())
        .filter(|d| *d > 0.0)
        .collect();
    if d.is_empty() {
        return None;
    }
    let mid = d.len() / 2;
    Some(*d.select_nth_unstable_by(mid, f64::total_cmp).1)
}

/// Time in frames from a reference: the fits' variable, for well-conditioned normal equations.
struct Clock {
    /// Reference time, s.
    t_ref: f64,
    /// One frame, s.
    dt: f64,
}

impl Clock {
    fn u(&self, t: f64) -> f64 {
        (t - self.t_ref) / self.dt
    }
}

/// Weighted least squares of `h = c₀ + c₁·u + ½a·u² + c₂·τ₊² + c₃·τ₊³` in frames `u` from the clock's
/// reference (τ₊ = max(u − u₀, 0) with u₀ the candidate touch `t0`; without it a plain arc), `c₂, c₃ ≥ 0`
/// (the best of the feasible subsets): coefficients `[c₀ px, c₁ px/frame, c₂ px/frame², c₃ px/frame³]`, their
/// covariance (from the tracker's σ, unscaled), and χ².
fn fit_onset(
    points: &[HeightPoint],
    a_px: f64,
    clock: &Clock,
    t0: Option<f64>,
) -> Option<([f64; 4], [[f64; 4]; 4], f64)> {
    let a_u = a_px * clock.dt * clock.dt;
    let u0 = t0.map(|t| clock.u(t));
    let basis = |p: &HeightPoint| onset_terms(p, clock, a_u, u0).0;
    let known = |p: &HeightPoint| onset_terms(p, clock, a_u, u0).1;
    let subsets: &[&[usize]] = if t0.is_some() {
        &[&[0, 1, 2, 3], &[0, 1, 2], &[0, 1, 3], &[0, 1]]
    } else {
        &[&[0, 1]]
    };
    let mut best: Option<([f64; 4], [[f64; 4]; 4], f64)> = None;
    for cols in subsets {
        let Some((c, cov)) = weighted_lsq(points, cols, &basis, &known) else {
            continue;
        };
        if c[2] < 0.0 || c[3] < 0.0 {
            continue;
        }
        let chi2: f64 = onset_residuals(points, a_px, clock, t0, &c).iter().map(|r| r * r).sum();
        if best.as_ref().is_none_or(|b| chi2 < b.2) {
            best = Some((c, cov, chi2));
        }
    }
    best
}

/// Weighted least squares on the columns `cols` of `basis` (the others held at 0), `known` removed first.
fn weighted_lsq(
    points: &[HeightPoint],
    cols: &[usize],
    basis: &dyn Fn(&HeightPoint) -> [f64; 4],
    known: &dyn Fn(&HeightPoint) -> f64,
) -> Option<([f64; 4], [[f64; 4]; 4])> {
    let m = cols.len();
    if points.len() <= m {
        return None;
    }
    let mut ata = vec![vec![0.0f64; m]; m];
    let mut atb = vec![0.0f64; m];
    for p in points {
        let b = basis(p);
        let w = 1.0 / (p.sigma * p.sigma);
        let z = p.h - known(p);
        for i in 0..m {
            atb[i] += w * b[cols[i]] * z;
            for j in 0..m {
                ata[i][j] += w * b[cols[i]] * b[cols[j]];
            }
        }
    }
    let inv = invert(ata)?;
    let mut c = [0.0; 4];
    let mut cov = [[0.0; 4]; 4];
    for i in 0..m {
        c[cols[i]] = (0..m).map(|j| inv[i][j] * atb[j]).sum();
        for j in 0..m {
            cov[cols[i]][cols[j]] = inv[i][j];
        }
    }
    Some((c, cov))
}

/// The inverse of a small symmetric positive-definite matrix (Gauss–Jordan with partial pivoting), `None`
/// when it is singular.
fn invert(mut a: Vec<Vec<f64>>) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let mut inv: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    for col in 0..n {
        let piv = (col..n).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))?;
        let scale = a.iter().map(|r| r[col].abs()).fold(0.0, f64::max);
        let p = a[piv][col].abs();
        if p.is_nan() || p <= 1e-14 * scale {
            return None;
        }
        a.swap(col, piv);
        inv.swap(col, piv);
        let d = a[col][col];
        for j in 0..n {
            a[col][j] /= d;
            inv[col][j] /= d;
        }
        for r in 0..n {
            if r != col {
                let f = a[r][col];
                if f != 0.0 {
                    for j in 0..n {
                        a[r][j] -= f * a[col][j];
                        inv[r][j] -= f * inv[col][j];
                    }
                }
            }
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear spring–damper bounce (the paper's model, normal only) in px at 10 kHz: flight at `v_in` px/s
    /// down onto level `level` (centre height at touch), noise-free. Returns the points and the touch time.
    fn bounce(level: f64, v_in: f64, phase: f64) -> (Vec<HeightPoint>, f64) {
        bounce_damped(level, v_in, phase, false)
    }

    /// [`bounce`], with the damping also while the ball comes back up when `damped_out` (a Kelvin–Voigt
    /// contact): the push falls to zero, and the ball leaves, while it is still pressed in.
    fn bounce_damped(level: f64, v_in: f64, phase: f64, damped_out: bool) -> (Vec<HeightPoint>, f64) {
        let (k, b, m, scale) = (25_650.0, 14.0, 0.0567, 4e-4);
        let g = -9.81 / scale; // px/s²
        let dt = 1e-4;
        let t_touch = 0.01 + phase * dt;
        let mut pts = Vec::new();
        // Contact by small Euler steps in metres.
        let (mut y, mut v) = (0.0f64, -v_in * scale);
        let mut t = t_touch;
        let mut contact: Vec<(f64, f64)> = Vec::new();
        loop {
            let f = if v < 0.0 || damped_out { -k * y - b * v } else { -k * y };
            if y > 0.0 || (v > 0.0 && f <= 0.0) {
                break;
            }
            contact.push((t, y / scale));
            let acc = f / m - 9.81;
            v += acc * 1e-7;
            y += v * 1e-7;
            t += 1e-7;
        }
        let (t_sep, v_out, h_sep) = (t, v / scale, y.min(0.0) / scale);
        for i in 0..400 {
            let ti = i as f64 * dt;
            let h = if ti < t_touch {
                let d = ti - t_touch;
                level - v_in * d + 0.5 * g * d * d
            } else if ti < t_sep {
                let j = contact.partition_point(|c| c.0 < ti).min(contact.len() - 1);
                level + contact[j].1
            } else {
                let d = ti - t_sep;
                level + h_sep + v_out * d + 0.5 * g * d * d
            };
            if ti > t_sep + 0.01 {
                break;
            }
            pts.push(HeightPoint { t: ti, h, sigma: 0.05 });
        }
        (pts, t_touch)
    }

    #[test]
    fn the_level_of_a_clean_bounce_is_found() {
        for phase in [0.0, 0.3, 0.7] {
            let (pts, t_touch) = bounce(100.0, 5000.0, phase);
            let low = find_impact(&pts, -9.81 / 4e-4, 4e-4).unwrap();
            let tc = trajectory_contact(&pts, low, -9.81 / 4e-4, 84.0).unwrap();
            eprintln!("{phase}: {tc:?} (touch at {t_touch})");
            assert!((tc.level_px - 100.0).abs() < 0.3, "{tc:?}");
        }
    }

    /// A Kelvin–Voigt ball leaves 1.6 px below where it touched (its push is zero while it is still
    /// pressed in): the level is the touch's, not a mean with the separation's.
    #[test]
    fn a_ball_that_leaves_still_pressed_in_gives_the_touch_s_level() {
        for phase in [0.0, 0.5] {
            let (pts, _) = bounce_damped(100.0, 5000.0, phase, true);
            let low = find_impact(&pts, -9.81 / 4e-4, 4e-4).unwrap();
            let tc = trajectory_contact(&pts, low, -9.81 / 4e-4, 84.0).unwrap();
            let (_, (sep_level, _)) = tc.separation.expect("a separation");
            assert!(
                sep_level < 99.7,
                "the separation should lie below the touch here: {tc:?}"
            );
            assert!((tc.level_px - 100.0).abs() < 0.15, "{tc:?}");
        }
    }

    /// A side whose centre creeps off its arc long before it is seen to (a lift growing as τ^1.5 from 20 ms, a
    /// contact's τ³ from 3 ms later): the profile still falls at the first time searched, so the onset is
    /// only bounded, and its level's error spans the frames searched instead of the profile's sharp edge.
    #[test]
    fn an_onset_the_frames_only_bound_gets_the_error_of_the_window_searched() {
        let (dt, v, a) = (1e-4, 5000.0, -9.81 / 4e-4);
        let t_start = 0.02;
        let side: Vec<HeightPoint> = (0..=240)
            .map(|i| {
                let t = i as f64 * dt;
                let tau = ((t - t_start) / dt).max(0.0);
                let h = 200.0 - v * t + 0.5 * a * t * t + 0.001 * tau.powf(1.5) + 2e-4 * (tau - 30.0).max(0.0).powi(3);
                HeightPoint { t, h, sigma: 0.05 }
            })
            .collect();
        let low = (0..side.len())
            .min_by(|&a, &b| side[a].h.total_cmp(&side[b].h))
            .unwrap();
        let o = onset(&side[..=low], side[low].h, a, 84.0).expect("an onset");
        assert!(o.bounded);
        assert!(o.t0_se >= 11.0 * dt, "{}", o.t0_se);
        // The level moves by v·t0_se over such a window: at least a pixel here.
        assert!(o.level_se > 1.0, "{}", o.level_se);
    }

    #[test]
    fn a_track_that_creeps_off_its_arc_and_back_has_not_touched_yet() {
        // A track biased differently across the frame: 0.2 px (4σ) off its arc for 1 ms, back on it 1.5 ms
        // before the touch.
        let (mut pts, t_touch) = bounce(100.0, 5000.0, 0.3);
        for p in &mut pts {
            let s = (p.t - (t_touch - 0.0025)) / 0.001;
            if (0.0..1.0).contains(&s) {
                p.h += 0.2 * (std::f64::consts::PI * s).sin();
            }
        }
        let low = find_impact(&pts, -9.81 / 4e-4, 4e-4).unwrap();
        let tc = trajectory_contact(&pts, low, -9.81 / 4e-4, 84.0).unwrap();
        eprintln!("{tc:?} (touch at {t_touch})");
        assert!(
            (tc.t_touch.0 - t_touch).abs() < 2e-4,
            "touch {:?} for {t_touch}",
            tc.t_touch
        );
        assert!((tc.level_px - 100.0).abs() < 2.0 * tc.level_se_px, "{tc:?}");
    }
}
