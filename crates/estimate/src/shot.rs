//! One shot: phases, velocities, restitution, friction, contact time and penetration from a track.

use crate::ballistic::{BallisticFit, fit_ballistic};
use bouncelab_track::{Status, Track};
use serde::{Deserialize, Serialize};

/// The conditions of a shot that the video does not show.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conditions {
    /// Incline of the surface β, degrees (`angle_deg` in clips.csv).
    pub incline_deg: f64,
    /// Gravitational acceleration, m/s².
    pub gravity: f64,
    /// Ball diameter, m.
    pub ball_diameter_m: f64,
}

impl Default for Conditions {
    fn default() -> Self {
        Conditions {
            incline_deg: 0.0,
            gravity: 9.81,
            ball_diameter_m: 0.067,
        }
    }
}

/// A measured value and its standard error, in the value's unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub se: f64,
}

impl Measured {
    fn new(value: f64, se: f64) -> Self {
        Measured { value, se }
    }
}

/// Frame indices (first, last) of each phase, and the frames each flight fit used.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PhaseFrames {
    /// Incoming flight: first and last frame fitted.
    pub flight_in: (usize, usize),
    /// Frames with the ball on (or within a pixel of) the surface.
    pub contact: (usize, usize),
    /// Outgoing flight: first and last frame fitted.
    pub flight_out: (usize, usize),
    /// Frames in each fit (in, out).
    pub fitted: (usize, usize),
}

/// The per-shot results (local frame of SPEC §3: t along the surface down-slope, n along the normal).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// Velocity at contact start (tangential, normal), m/s.
    pub v_in: [Measured; 2],
    /// Velocity at contact end (tangential, normal), m/s.
    pub v_out: [Measured; 2],
    /// Coefficient of restitution |v_n,out / v_n,in|.
    pub cor: Measured,
    /// Effective friction −Δv_t / Δv_n (the paper's momentum ratio).
    pub mu: Measured,
    /// Contact time, ms.
    pub contact_ms: Measured,
    /// Contact start, s from the first frame.
    pub t_touch: Measured,
    /// Time of maximum compression, s.
    pub t_max: f64,
    /// Contact end, s.
    pub t_sep: Measured,
    /// Maximum penetration of the centre below one radius above the surface, m.
    pub delta_max_m: Measured,
    /// Spin before the impact, rad/s (counter-clockwise as seen), when measured.
    pub spin_in: Option<Measured>,
    /// Spin after the impact, rad/s, when measured.
    pub spin_out: Option<Measured>,
    /// The frames of each phase.
    pub phases: PhaseFrames,
    /// The incoming ballistic arc (local frame, m, s): where a simulation of the shot starts.
    pub flight_in: BallisticFit,
    /// The outgoing ballistic arc.
    pub flight_out: BallisticFit,
    /// Reduced χ² of the flight fits (in x, in y, out x, out y): ≫ 1 means the tracker's σ is too small or the
    /// flight is not ballistic (drag, a bad frame).
    pub chi2_red: [f64; 4],
    /// Shot-to-shot standard error of the contact plane's height in the local frame, m: the surface line's
    /// (with the correlation of its columns) and the scale's at one radius, without the rim shape's Type-B
    /// term, which lighting makes common to a session's clips (a fit's surface level takes that part; this
    /// is the prior of each shot's deviation from it). 0 in estimates stored before it existed.
    #[serde(default)]
    pub surface_sigma_m: f64,
    /// Things a person should know.
    pub notes: Vec<String>,
}

impl Estimate {
    /// Contact start and end, s, had the surface been `level_m` above the surface line found in the image (the
    /// flight arcs crossing `radius_m + level_m`): how a fitted surface level carries over to the contact
    /// time.
    pub fn contact_at_level(&self, level_m: f64, radius_m: f64) -> (f64, f64) {
        let y = radius_m + level_m;
        (
            crossing(&self.flight_in, y, self.t_touch.value).t.value,
            crossing(&self.flight_out, y, self.t_sep.value).t.value,
        )
    }
}

/// Why a shot could not be measured.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EstimateError {
    /// The track has no scale (the ball was never measured clear of the surface).
    #[error("no scale: the ball was not measured in free flight in enough frames")]
    NoScale,
    /// No surface line was found.
    #[error("no surface line found: cannot tell when the ball touches the surface")]
    NoSurface,
    /// The ball never came within a pixel of the surface.
    #[error("no impact in the clip: the ball comes no closer than {clearance_px:.1} px to the surface")]
    NoContact { clearance_px: f64 },
    /// A flight phase has too few frames to fit.
    #[error(
        "{phase} flight too short to fit: {frames} usable frame(s), {needed} needed (the clip {which} too close to the impact)"
    )]
    FlightTooShort {
        phase: &'static str,
        frames: usize,
        needed: usize,
        which: &'static str,
    },
    /// A fit failed (degenerate times).
    #[error("the {phase} flight could not be fitted")]
    FitFailed { phase: &'static str },
}

/// Fewest frames a flight fit uses.
pub const MIN_FLIGHT_FRAMES: usize = 6;
/// A frame counts as flight when the ball's bottom is at least this far above the surface line, px.
const CLEARANCE_MARGIN_PX: f64 = 1.0;
/// Smallest per-frame σ used as a weight, px (the tracker's σ can be optimistic on clean frames); later
/// stages weighting the same frames use it too.
pub const MIN_SIGMA_PX: f64 = 0.01;

struct Point {
    frame: usize,
    t: f64,
    x: f64,
    y: f64,
    sigma: f64,
    clearance_px: f64,
}

/// Measures one shot from its track.
pub fn estimate(track: &Track, c: &Conditions) -> Result<Estimate, EstimateError> {
    let scale = track.scale.ok_or(EstimateError::NoScale)?;
    let line = track.surface.ok_or(EstimateError::NoSurface)?;
    let s = scale.m_per_px;
    let rows = track.rows();
    let points: Vec<Point> = track
        .fixes
        .iter()
        .zip(&rows)
        .filter(|(f, r)| matches!(f.status, Status::Ok | Status::Occluded) && r.x_m.is_finite())
        .map(|(f, r)| Point {
            frame: f.frame,
            t: f.t_s,
            x: r.x_m,
            y: r.y_m,
            sigma: f.sigma_px.max(MIN_SIGMA_PX) * s,
            clearance_px: line.y_at(f.x_px) - f.y_px - scale.radius_px,
        })
        .collect();
    let Some(low) = points
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.clearance_px.total_cmp(&b.1.clearance_px))
        .map(|(i, _)| i)
    else {
        return Err(EstimateError::NoScale);
    };
    if points[low].clearance_px > CLEARANCE_MARGIN_PX {
        return Err(EstimateError::NoContact {
            clearance_px: points[low].clearance_px,
        });
    }
    // The contact: the run of frames around the lowest one within the margin of the surface.
    let near = |p: &Point| p.clearance_px <= CLEARANCE_MARGIN_PX;
    let (mut first, mut last) = (low, low);
    while first > 0 && near(&points[first - 1]) {
        first -= 1;
    }
    while last + 1 < points.len() && near(&points[last + 1]) {
        last += 1;
    }
    let incoming: Vec<&Point> = points[..first].iter().filter(|p| !near(p)).collect();
    let outgoing: Vec<&Point> = points[last + 1..].iter().filter(|p| !near(p)).collect();
    for (phase, set, which) in [("incoming", &incoming, "starts"), ("outgoing", &outgoing, "ends")] {
        if set.len() < MIN_FLIGHT_FRAMES {
            return Err(EstimateError::FlightTooShort {
                phase,
                frames: set.len(),
                needed: MIN_FLIGHT_FRAMES,
                which,
            });
        }
    }
    let beta = c.incline_deg.to_radians();
    let a = [c.gravity * beta.sin(), -c.gravity * beta.cos()];
    let fit = |set: &[&Point], phase| {
        let pts: Vec<_> = set.iter().map(|p| (p.t, p.x, p.y, p.sigma)).collect();
        fit_ballistic(&pts, a).ok_or(EstimateError::FitFailed { phase })
    };
    let fin = fit(&incoming, "incoming")?;
    let fout = fit(&outgoing, "outgoing")?;
    let radius = c.ball_diameter_m / 2.0;
    // Uncertainty of "one radius above the surface line" in the local frame, m: all of it for this shot's
    // errors (the line's scatter and its edge's definition as a uniform Type-B term, the scale's at one
    // radius), and for a fit's per-shot level only the shot-to-shot part, without the Type-B terms that a
    // surface's clips share (see `Estimate::surface_sigma_m`).
    let sigma_level = ((line.sigma_y0.powi(2) + line.edge_definition_px.powi(2) / 3.0) * s * s
        + (radius * scale.sigma_m_per_px / s).powi(2))
    .sqrt();
    let scatter_scale = (scale.sigma_m_per_px.powi(2) - scale.sigma_shape_m_per_px.powi(2))
        .max(0.0)
        .sqrt();
    let sigma_level_scatter = ((line.sigma_y0 * s).powi(2) + (radius * scatter_scale / s).powi(2)).sqrt();
    // The level's error is common to both crossings, so it is carried as a derivative and propagated
    // coherently into the contact time, COR and μ, not added to each crossing separately.
    let touch = crossing(&fin, radius, points[first].t);
    let sep = crossing(&fout, radius, points[last].t);
    let with_level = |c: &Crossing| Measured::new(c.t.value, c.t.se.hypot(c.dt_dlevel * sigma_level));
    let (t_touch, t_sep) = (with_level(&touch), with_level(&sep));
    let rel_scale = scale.sigma_m_per_px / s;
    // Per velocity component at a crossing: the value, the fit's error (for ratios, where the scale and the
    // level's common part are propagated separately), its derivative with the level, and the total error.
    let velocity = |f: &BallisticFit, c: &Crossing| {
        let v = f.velocity(c.t.value);
        [0, 1].map(|k| {
            let (_, sv, _) = f.errors_at(k, c.t.value);
            let stat = (sv * sv + (f.a[k] * c.t.se).powi(2)).sqrt();
            let dv_dlevel = f.a[k] * c.dt_dlevel;
            let total = (stat * stat + (dv_dlevel * sigma_level).powi(2) + (v[k] * rel_scale).powi(2)).sqrt();
            VelocityPart {
                value: v[k],
                stat,
                dv_dlevel,
                total,
            }
        })
    };
    let vin = velocity(&fin, &touch);
    let vout = velocity(&fout, &sep);
    let cor = (vout[1].value / vin[1].value).abs();
    let cor_level = cor * (vout[1].dv_dlevel / vout[1].value - vin[1].dv_dlevel / vin[1].value) * sigma_level;
    let cor_se = (cor * cor * ((vin[1].stat / vin[1].value).powi(2) + (vout[1].stat / vout[1].value).powi(2))
        + cor_level * cor_level)
        .sqrt();
    let (dvt, dvn) = (vout[0].value - vin[0].value, vout[1].value - vin[1].value);
    let mu = -dvt / dvn;
    let (ddvt, ddvn) = (
        vout[0].dv_dlevel - vin[0].dv_dlevel,
        vout[1].dv_dlevel - vin[1].dv_dlevel,
    );
    let mu_level = (-ddvt / dvn + dvt * ddvn / (dvn * dvn)) * sigma_level;
    let mu_se = ((vin[0].stat.powi(2) + vout[0].stat.powi(2)) / (dvn * dvn)
        + (dvt / (dvn * dvn)).powi(2) * (vin[1].stat.powi(2) + vout[1].stat.powi(2))
        + mu_level * mu_level)
        .sqrt();
    let contact_se =
        (touch.t.se.powi(2) + sep.t.se.powi(2) + ((sep.dt_dlevel - touch.dt_dlevel) * sigma_level).powi(2)).sqrt();
    let contact = &points[first..=last];
    let (t_max, delta_max) = deepest(contact, radius, sigma_level, rel_scale);
    let mut notes = Vec::new();
    for (name, f) in [("incoming", &fin), ("outgoing", &fout)] {
        let worst = f.chi2_red[0].max(f.chi2_red[1]);
        if worst > 4.0 {
            notes.push(format!(
                "{name} flight scatters {:.1}× more than the tracker's σ (reduced χ² {worst:.1}): errors inflated accordingly",
                worst.sqrt()
            ));
        }
    }
    Ok(Estimate {
        v_in: vin.map(|v| Measured::new(v.value, v.total)),
        v_out: vout.map(|v| Measured::new(v.value, v.total)),
        cor: Measured::new(cor, cor_se),
        mu: Measured::new(mu, mu_se),
        contact_ms: Measured::new((t_sep.value - t_touch.value) * 1e3, contact_se * 1e3),
        t_touch,
        t_max,
        t_sep,
        delta_max_m: delta_max,
        spin_in: None,
        spin_out: None,
        phases: PhaseFrames {
            flight_in: (incoming[0].frame, incoming[incoming.len() - 1].frame),
            contact: (points[first].frame, points[last].frame),
            flight_out: (outgoing[0].frame, outgoing[outgoing.len() - 1].frame),
            fitted: (incoming.len(), outgoing.len()),
        },
        chi2_red: [fin.chi2_red[0], fin.chi2_red[1], fout.chi2_red[0], fout.chi2_red[1]],
        flight_in: fin,
        flight_out: fout,
        surface_sigma_m: sigma_level_scatter,
        notes,
    })
}

/// When a flight arc crosses the contact level.
struct Crossing {
    /// The time, s, with the fit's standard error (the level taken as exact).
    t: Measured,
    /// How the time moves with the level, s/m (1 / the normal velocity there).
    dt_dlevel: f64,
}

/// One velocity component at a crossing, m/s.
#[derive(Clone, Copy)]
struct VelocityPart {
    value: f64,
    /// The flight fit's standard error (its timing included, the level's and scale's errors not).
    stat: f64,
    /// How the value moves with the contact level (the arc's acceleration × dt/dlevel), 1/s.
    dv_dlevel: f64,
    /// All errors: the fit's, the level's and the scale's.
    total: f64,
}

/// When the arc's height is `level` (the root nearest `near`), with the fit's standard error.
fn crossing(f: &BallisticFit, level: f64, near: f64) -> Crossing {
    // ½a·d² + v0·d + (p0 − level) = 0 in d = t − t_ref.
    let (a, b, c) = (0.5 * f.a[1], f.v0[1], f.p0[1] - level);
    let d_near = near - f.t_ref;
    let d = if a.abs() < 1e-12 {
        -c / b
    } else {
        let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
        let (r1, r2) = ((-b + disc) / (2.0 * a), (-b - disc) / (2.0 * a));
        if (r1 - d_near).abs() < (r2 - d_near).abs() {
            r1
        } else {
            r2
        }
    };
    let t = f.t_ref + d;
    let vy = f.velocity(t)[1];
    let vy = if vy.abs() < 1e-9 { 1e-9_f64.copysign(vy) } else { vy };
    let (sp, _, _) = f.errors_at(1, t);
    Crossing {
        t: Measured::new(t, sp / vy.abs()),
        dt_dlevel: 1.0 / vy,
    }
}

/// Time and depth of the lowest centre: a parabola through the frames around the lowest one.
fn deepest(contact: &[Point], radius: f64, sigma_level: f64, rel_scale: f64) -> (f64, Measured) {
    let k = contact
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.y.total_cmp(&b.1.y))
        .map(|(i, _)| i)
        .unwrap_or(0);
    let lo = k.saturating_sub(4);
    let hi = (k + 5).min(contact.len());
    let pts = &contact[lo..hi];
    let lowest = &contact[k];
    let scale_part = (radius - lowest.y).abs() * rel_scale;
    let fallback = (
        lowest.t,
        Measured::new(
            radius - lowest.y,
            (lowest.sigma.powi(2) + sigma_level.powi(2) + scale_part.powi(2)).sqrt(),
        ),
    );
    if pts.len() < 5 {
        return fallback;
    }
    // Least-squares parabola y = c0 + c1·d + c2·d² in d = t − t_k.
    let t0 = lowest.t;
    let mut m = [[0.0f64; 3]; 3];
    let mut v = [0.0f64; 3];
    for p in pts {
        let d = p.t - t0;
        let basis = [1.0, d, d * d];
        for i in 0..3 {
            v[i] += basis[i] * p.y;
            for j in 0..3 {
                m[i][j] += basis[i] * basis[j];
            }
        }
    }
    let Some(c) = solve3(m, v) else { return fallback };
    if c[2] <= 0.0 {
        return fallback;
    }
    let d_min = (-c[1] / (2.0 * c[2])).clamp(pts[0].t - t0, pts[pts.len() - 1].t - t0);
    let y_min = c[0] + c[1] * d_min + c[2] * d_min * d_min;
    let sigma_fit = lowest.sigma / (pts.len() as f64 / 3.0).sqrt();
    (
        t0 + d_min,
        Measured::new(
            radius - y_min,
            (sigma_fit.powi(2) + sigma_level.powi(2) + scale_part.powi(2)).sqrt(),
        ),
    )
}

fn solve3(mut m: [[f64; 3]; 3], mut v: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[piv][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, piv);
        v.swap(col, piv);
        for r in 0..3 {
            if r != col {
                let f = m[r][col] / m[col][col];
                let pivot = m[col];
                for (x, p) in m[r].iter_mut().zip(pivot) {
                    *x -= f * p;
                }
                v[r] -= f * v[col];
            }
        }
    }
    Some([v[0] / m[0][0], v[1] / m[1][1], v[2] / m[2][2]])
}
