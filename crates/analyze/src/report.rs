//! The report's data, filled from the analysis (the report crate takes plain data and knows no pipeline type),
//! and the files that hold the same numbers as its figures (`model_predictions.csv`, `model_curves.csv`,
//! `contact_force.csv`, `surfaces.csv`).

use crate::{Analysis, ShotData};
use bouncelab_compare::{Component, ImpactPhase, ShotComparison};
use bouncelab_diagnose::{Diagnosis, VerdictKind};
use bouncelab_fit::{FitResult, SimOptions, fitted_model, predict_impact};
use bouncelab_model::{Model, ModelSpec};
use bouncelab_report as r;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Points of each model curve.
const CURVE_POINTS: usize = 25;
/// The curves reach this far beyond a surface's measured speeds, as a fraction of their range.
const CURVE_MARGIN: f64 = 0.1;
/// Instants of the contact force, touch to separation.
const FORCE_SAMPLES: usize = 200;
/// Half-width of the local quadratic that gives the track's deceleration, s.
const DECEL_HALF_WINDOW_S: f64 = 4e-4;
/// Least frames in that quadratic.
const DECEL_MIN_FRAMES: usize = 7;
/// Least ratio of the peak deceleration to its standard error for it to count as measured.
const DECEL_MIN_Z: f64 = 5.0;

/// The peak normal deceleration of the ball's centre from its track (`frames` in the local frame, contact
/// from `t0` to `t1`, s), m/s², with its standard error: a
/// quadratic fitted by least squares to the height over ±0.4 ms around each contact frame (at least 7
/// frames), twice its leading coefficient being the acceleration there; the largest over the contact. `None`
/// when the contact holds too few frames for one such window (a slow camera) or the peak is not 5 standard
/// errors above zero: then the track does not resolve it.
///
/// The window rounds the peak of a contact lasting T by about (2π·0.4 ms/T)²/10 (≈ 2 % at 4.5 ms), and the
/// largest of several noisy windows leans high by about one to two standard errors: both are stated where
/// the number is shown.
pub fn track_peak_deceleration(frames: &[bouncelab_fit::MeasuredFrame], t0: f64, t1: f64) -> Option<(f64, f64)> {
    if !(t0.is_finite() && t1 > t0) {
        return None;
    }
    let mut best: Option<(f64, f64)> = None;
    for (i, f) in frames.iter().enumerate() {
        if f.t_s < t0 || f.t_s > t1 {
            continue;
        }
        let window: Vec<&bouncelab_fit::MeasuredFrame> = frames
            .iter()
            .filter(|g| (g.t_s - f.t_s).abs() <= DECEL_HALF_WINDOW_S + 1e-9)
            .collect();
        if window.len() < DECEL_MIN_FRAMES {
            continue;
        }
        let Some((a, se)) = curvature(&window, frames[i].t_s) else {
            continue;
        };
        if best.is_none_or(|(b, _)| a > b) {
            best = Some((a, se));
        }
    }
    best.filter(|(a, se)| *se > 0.0 && *a > DECEL_MIN_Z * se)
}

/// Weighted least squares of y = c₀ + c₁τ + c₂τ² (τ = t − `at`): (2c₂, its standard error from the frames'
/// σ, inflated by the fit's reduced χ² when that is above 1).
fn curvature(window: &[&bouncelab_fit::MeasuredFrame], at: f64) -> Option<(f64, f64)> {
    let mut ata = [[0.0f64; 3]; 3];
    let mut aty = [0.0f64; 3];
    for f in window {
        let tau = f.t_s - at;
        let w = 1.0 / (f.sigma_m * f.sigma_m);
        let row = [1.0, tau, tau * tau];
        for j in 0..3 {
            aty[j] += w * row[j] * f.y_m;
            for k in 0..3 {
                ata[j][k] += w * row[j] * row[k];
            }
        }
    }
    let inv = invert3(&ata)?;
    let c: Vec<f64> = (0..3).map(|j| (0..3).map(|k| inv[j][k] * aty[k]).sum()).collect();
    let chi2: f64 = window
        .iter()
        .map(|f| {
            let tau = f.t_s - at;
            ((f.y_m - c[0] - c[1] * tau - c[2] * tau * tau) / f.sigma_m).powi(2)
        })
        .sum();
    let dof = window.len().saturating_sub(3).max(1) as f64;
    let scale = (chi2 / dof).max(1.0);
    let se = 2.0 * (inv[2][2] * scale).sqrt();
    (c[2].is_finite() && se.is_finite()).then_some((2.0 * c[2], se))
}

fn invert3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if !(det.is_finite() && det.abs() > 0.0) {
        return None;
    }
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            let (a, b) = ((j + 1) % 3, (j + 2) % 3);
            let (c, d) = ((i + 1) % 3, (i + 2) % 3);
            *v = (m[a][c] * m[b][d] - m[a][d] * m[b][c]) / det;
        }
    }
    Some(inv)
}

/// What the fitted model predicts for the session: per shot, per surface against speed, and one contact.
pub(crate) struct Predictions {
    /// Per shot of `Analysis::shots`, in order.
    pub per_shot: Vec<Option<r::ShotPrediction>>,
    /// One curve per surface and incline.
    pub curves: Vec<r::ModelCurve>,
    /// The contact force of the shot nearest the median impact speed.
    pub force: Result<r::ContactForce, String>,
    /// Predictions that failed, one line each.
    pub failures: Vec<String>,
}

/// The fit's prediction of one impact as the report shows it. Like every mapper below, it names each of
/// the producer's fields (no `..`), so a field the producer gains, loses or renames stops this crate
/// compiling until it is shown here or left out on purpose (`field: _`).
fn prediction(p: &bouncelab_fit::ImpactPrediction) -> r::ShotPrediction {
    let bouncelab_fit::ImpactPrediction {
        // The incoming velocity is the shot's measured one; the outgoing one is shown as COR and μ_eff.
        v_in: _,
        v_out: _,
        cor,
        mu_eff,
        contact_time_s,
        delta_max_m,
        omega_out_rad_s,
        peak_force_n,
        peak_deceleration_m_s2,
        // Shown for one shot only, as the contact force section.
        force: _,
    } = *p;
    r::ShotPrediction {
        cor,
        mu_eff,
        contact_time_s,
        delta_max_m,
        spin_out_rad_s: omega_out_rad_s,
        peak_force_n,
        peak_deceleration_m_s2,
    }
}

fn force_sample(f: &bouncelab_fit::ForceSample) -> r::ForceSample {
    let bouncelab_fit::ForceSample { t_s, delta_m, force_n } = *f;
    r::ForceSample { t_s, delta_m, force_n }
}

fn measured_point(f: &bouncelab_fit::MeasuredFrame) -> r::MeasuredPoint {
    let bouncelab_fit::MeasuredFrame { t_s, x_m, y_m, sigma_m } = *f;
    r::MeasuredPoint { t_s, x_m, y_m, sigma_m }
}

fn residual(p: &bouncelab_compare::ResidualPoint) -> r::Residual {
    let bouncelab_compare::ResidualPoint {
        t_s,
        // Shown as the shot's phase spans.
        phase: _,
        dx_m,
        dy_m,
        // The tracking σ is drawn from the measured points.
        sigma_m: _,
        // Spin residuals are not plotted.
        d_omega_rad_s: _,
        sigma_omega_rad_s: _,
    } = *p;
    r::Residual { t_s, dx_m, dy_m }
}

/// The surfaces of `a`'s shots in order of first appearance.
fn surfaces_of(shots: &[ShotData]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for s in shots {
        if !out.contains(&s.surface) {
            out.push(s.surface.clone());
        }
    }
    out
}

/// The fitted model's predictions for every shot, every surface and incline over its measured speeds, and
/// the contact force of the shot nearest the session's median impact speed.
pub(crate) fn predictions(spec: &ModelSpec, fit: &FitResult, shots: &[ShotData]) -> Predictions {
    let sim = SimOptions::default();
    let mut failures = Vec::new();
    let models = surface_models(spec, fit, shots, &mut failures);
    let per_shot = shots
        .iter()
        .map(|s| match predict_shot(&models, s, PREDICTION_SAMPLES, &sim)? {
            Ok(p) => Some(prediction(&p)),
            Err(e) => {
                failures.push(e);
                None
            }
        })
        .collect();
    let curves = model_curves(&models, shots, &sim, &mut failures);
    let force = contact_force(&models, shots, &sim);
    Predictions {
        per_shot,
        curves,
        force,
        failures,
    }
}

/// Force samples of a prediction whose contact force is not shown (per shot, along the curves).
const PREDICTION_SAMPLES: usize = 20;

/// The fitted model of every surface of `shots`, or why there is none (also pushed to `failures`).
fn surface_models(
    spec: &ModelSpec,
    fit: &FitResult,
    shots: &[ShotData],
    failures: &mut Vec<String>,
) -> BTreeMap<String, Result<Model, String>> {
    let mut models = BTreeMap::new();
    for s in surfaces_of(shots) {
        let m = fitted_model(spec, fit, &s).map_err(|e| e.to_string());
        if let Err(e) = &m {
            failures.push(format!("surface {s}: no fitted model to predict with: {e}"));
        }
        models.insert(s, m);
    }
    models
}

/// The fitted model hit at shot `s`'s measured incoming velocity and spin, with `samples` instants of its
/// contact force; `None` when its surface has no fitted model.
fn predict_shot(
    models: &BTreeMap<String, Result<Model, String>>,
    s: &ShotData,
    samples: usize,
    sim: &SimOptions,
) -> Option<Result<bouncelab_fit::ImpactPrediction, String>> {
    let model = models.get(&s.surface).and_then(|m| m.as_ref().ok())?;
    let e = &s.estimate;
    let v = [e.v_in[0].value, e.v_in[1].value];
    Some(
        predict_impact(
            model,
            s.angle_deg.to_radians(),
            v,
            e.spin_in.map_or(0.0, |w| w.value),
            samples,
            sim,
        )
        .map_err(|err| format!("{}: the fitted model's prediction failed: {err}", s.clip)),
    )
}

/// One curve per surface with a fitted model and per incline of its shots, over the surface's measured
/// normal speeds widened by [`CURVE_MARGIN`]; a point the model cannot predict ends up in `failures`.
fn model_curves(
    models: &BTreeMap<String, Result<Model, String>>,
    shots: &[ShotData],
    sim: &SimOptions,
    failures: &mut Vec<String>,
) -> Vec<r::ModelCurve> {
    let mut curves = Vec::new();
    for (surface, model) in models {
        let Ok(model) = model else { continue };
        let of: Vec<&ShotData> = shots.iter().filter(|s| &s.surface == surface).collect();
        let Some((lo, hi)) = curve_speeds(&of) else {
            continue;
        };
        let mut angles: Vec<f64> = of.iter().map(|s| s.angle_deg).filter(|a| a.is_finite()).collect();
        angles.sort_by(f64::total_cmp);
        angles.dedup();
        for angle in angles {
            curves.push(model_curve(model, surface, angle, (lo, hi), sim, failures));
        }
    }
    curves
}

/// The normal speeds a surface's curves span: its shots' measured range widened by [`CURVE_MARGIN`] (at
/// least 5 % of the lowest speed) and kept above 0.05 m/s; `None` when no shot has a measured speed.
fn curve_speeds(of: &[&ShotData]) -> Option<(f64, f64)> {
    let speeds: Vec<f64> = of
        .iter()
        .map(|s| s.estimate.v_in[1].value.abs())
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    let (lo, hi) = speeds
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(*v), b.max(*v)));
    if !lo.is_finite() {
        return None;
    }
    let pad = ((hi - lo) * CURVE_MARGIN).max(0.05 * lo);
    Some(((lo - pad).max(0.05), hi + pad))
}

/// The model of `surface` at incline `angle` (degrees) over `speeds` (m/s), [`CURVE_POINTS`] evenly spaced.
fn model_curve(
    model: &Model,
    surface: &str,
    angle: f64,
    (lo, hi): (f64, f64),
    sim: &SimOptions,
    failures: &mut Vec<String>,
) -> r::ModelCurve {
    let beta = angle.to_radians();
    let mut points = Vec::with_capacity(CURVE_POINTS);
    for k in 0..CURVE_POINTS {
        let v = lo + (hi - lo) * k as f64 / (CURVE_POINTS - 1) as f64;
        // A vertical drop onto the incline: the tangential speed is v_n·tan β.
        match predict_impact(model, beta, [v * beta.tan(), -v], 0.0, PREDICTION_SAMPLES, sim) {
            Ok(p) => points.push(r::CurvePoint {
                v_in_n_m_s: v,
                prediction: prediction(&p),
            }),
            Err(e) => failures.push(format!(
                "surface {surface} at {angle}°: the model's curve stops at {v:.3} m/s: {e}"
            )),
        }
    }
    r::ModelCurve {
        surface: surface.to_string(),
        angle_deg: angle,
        points,
    }
}

/// The contact force over the impact of the shot nearest the session's median impact speed.
fn contact_force(
    models: &BTreeMap<String, Result<Model, String>>,
    shots: &[ShotData],
    sim: &SimOptions,
) -> Result<r::ContactForce, String> {
    let s = median_shot(shots).ok_or_else(|| "no shot with a measured impact speed".to_string())?;
    let p = predict_shot(models, s, FORCE_SAMPLES, sim)
        .ok_or_else(|| format!("no fitted model for surface {}", s.surface))??;
    Ok(r::ContactForce {
        clip: s.clip.clone(),
        surface: s.surface.clone(),
        angle_deg: s.angle_deg,
        v_in_n_m_s: s.estimate.v_in[1].value.abs(),
        why: "the shot nearest the session's median impact speed".into(),
        samples: p.force.iter().map(force_sample).collect(),
    })
}

/// The shot whose incoming normal speed is nearest the session's median (the lower median for an even
/// count).
fn median_shot(shots: &[ShotData]) -> Option<&ShotData> {
    let mut v: Vec<(f64, usize)> = shots
        .iter()
        .enumerate()
        .map(|(i, s)| (s.estimate.v_in[1].value.abs(), i))
        .filter(|(v, _)| v.is_finite())
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v.get(v.len().saturating_sub(1) / 2).map(|&(_, i)| &shots[i])
}

fn measured(m: bouncelab_estimate::Measured) -> r::Measured {
    let bouncelab_estimate::Measured { value, se } = m;
    r::Measured::new(value, se)
}

/// Every measured quantity of a shot, with the model's prediction for it; `ball_mass_kg` and `gravity`
/// turn the track's deceleration into a force.
pub(crate) fn measurement(
    s: &ShotData,
    model: Option<r::ShotPrediction>,
    ball_mass_kg: f64,
    gravity: f64,
) -> r::ShotMeasurement {
    let e = &s.estimate;
    let decel = track_peak_deceleration(&s.measured.frames, e.t_touch.value, e.t_sep.value);
    let g_n = gravity * s.angle_deg.to_radians().cos();
    r::ShotMeasurement {
        clip: s.clip.clone(),
        surface: s.surface.clone(),
        angle_deg: s.angle_deg,
        drop_height_m: Some(s.drop_height_m).filter(|h| h.is_finite()),
        v_in_m_s: [measured(e.v_in[0]), measured(e.v_in[1])],
        v_out_m_s: [measured(e.v_out[0]), measured(e.v_out[1])],
        cor: measured(e.cor),
        // −0 (a vertical drop's exact zero) is shown as 0.
        mu_eff: r::Measured::new(e.mu.value + 0.0, e.mu.se),
        contact_time_s: r::Measured::new(e.contact_ms.value * 1e-3, e.contact_ms.se * 1e-3),
        delta_max_m: measured(e.delta_max_m),
        spin_in_rad_s: e.spin_in.map(measured),
        spin_out_rad_s: e.spin_out.map(measured),
        peak_deceleration_track_m_s2: decel.map(|(a, se)| r::Measured::new(a, se)),
        peak_force_track_n: decel.map(|(a, se)| r::Measured::new(ball_mass_kg * (a + g_n), ball_mass_kg * se)),
        model,
    }
}

/// A shot's reduced χ²: its χ² over its share of the fit's degrees of freedom, in proportion to its
/// residuals (two per frame), so the shots' values weighted by frames average to the fit's.
pub(crate) fn shot_chi2_red(fit: &FitResult, shot: &str) -> Option<f64> {
    let total: usize = fit.shots.iter().map(|s| 2 * s.frames).sum();
    let s = fit.shots.iter().find(|s| s.name == shot)?;
    let nu = (2 * s.frames) as f64 * fit.dof as f64 / total as f64;
    (nu > 0.0).then(|| s.chi2 / nu)
}

/// The page title: the session folder's name.
fn title(session_dir: &Path) -> String {
    let name = session_dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| session_dir.display().to_string());
    format!("bouncelab report: {name}")
}

/// The program and version that made the report.
fn generated_by() -> String {
    format!("bouncelab {}", env!("CARGO_PKG_VERSION"))
}

/// When some shots were measured along the image's axes (no line of their own, no tilt given) while the
/// lines found on the others show the surface tilted: which shots, and the setting that would take the tilt
/// into their frames.
fn unseen_tilt_note<'a>(
    lines: impl Iterator<Item = (&'a str, Option<bouncelab_track::SurfaceLine>)>,
    tilt: bouncelab_estimate::Measured,
) -> Option<String> {
    let unseen: Vec<&str> = lines
        .filter(|(_, l)| l.is_some_and(|l| l.cue == bouncelab_track::LineCue::Trajectory && l.slope == 0.0))
        .map(|(clip, _)| clip)
        .collect();
    (!unseen.is_empty() && tilt.value.abs() > 2.0 * tilt.se).then(|| {
        format!(
            "{} shot(s) ({}) had no surface line of their own and are measured along the image's axes, while the lines found on the others lie tilted by {:.3} ± {:.3}°: if the camera did not move between shots, set `[surface] tilt_deg = {:.2}` in session.toml (docs/session.md) to measure them along the surface",
            unseen.len(),
            unseen.join(", "),
            tilt.value,
            tilt.se,
            tilt.value
        )
    })
}

/// Everything `report.html` shows about `a`.
pub(crate) fn build(a: &Analysis, p: &Predictions, description: Option<&str>, warnings: &[String]) -> r::Report {
    let surfaces = surfaces_of(&a.shots);
    let mut notes: Vec<String> = warnings.to_vec();
    notes.extend(a.measure.failed.iter().map(|(c, m)| format!("{c}: not measured: {m}")));
    notes.extend(a.excluded.iter().map(|(c, m)| format!("{c}: left out of the fit: {m}")));
    notes.extend(p.failures.iter().cloned());
    notes.extend(camera_notes(&a.shots));
    let tilts: Vec<_> = a.shots.iter().filter_map(|s| s.estimate.surface_tilt_deg).collect();
    if let Some(t) = bouncelab_estimate::session_tilt_deg(&tilts) {
        notes.push(format!(
            "the surface lies tilted by {} ± {:.3}° in the image over {} shot(s) (counter-clockwise as seen: a camera roll, or the surface's own slope across the view); each shot is measured along its own tilt (its line's, weighed with its fall's), so the tilt is taken out of its velocities",
            format!("{:+.3}", t.value).replace('-', "\u{2212}"),
            t.se,
            tilts.len()
        ));
        let lines = a.shots.iter().map(|s| (s.clip.as_str(), s.estimate.contact_line));
        notes.extend(unseen_tilt_note(lines, t));
    }
    r::Report {
        title: title(&a.session_dir),
        session: r::SessionInfo {
            path: a.session_dir.display().to_string(),
            description: description.unwrap_or_default().to_string(),
            shots: a.shots_listed,
            surfaces,
            generated_by: generated_by(),
            generated_at: a.fitted_at.clone(),
            metadata: vec![("Model".into(), a.model_origin.clone())],
        },
        shots: a.comparison.shots.iter().map(|c| shot_plot(a, c)).collect(),
        measurements: a
            .shots
            .iter()
            .zip(&p.per_shot)
            .map(|(s, m)| measurement(s, *m, a.model.ball.mass_kg, a.model.gravity))
            .collect(),
        model_curves: p.curves.clone(),
        contact_force: p.force.clone().into(),
        ancova: a.stats.as_ref().map(|s| s.ancova.clone()).map_err(String::clone).into(),
        inference: a
            .stats
            .as_ref()
            .map_err(String::clone)
            .and_then(|s| s.inference.clone())
            .into(),
        fit: r::Section::Available(fit_summary(a)),
        diagnosis: a
            .diagnosis
            .as_ref()
            .map(|d| diagnosis(d, a))
            .map_err(String::clone)
            .into(),
        model_change: match &a.before {
            Some(_) => r::Section::Available(model_change(a)),
            None => r::Section::unavailable("this is the first model fitted to this session in the store"),
        },
        warnings: notes,
        timings: a.timings.iter().map(|(s, t)| (s.name().to_string(), *t)).collect(),
    }
}

fn phase(p: ImpactPhase) -> r::Phase {
    match p {
        ImpactPhase::FlightIn => r::Phase::FlightIn,
        ImpactPhase::Compression => r::Phase::Compression,
        ImpactPhase::Restitution => r::Phase::Restitution,
        ImpactPhase::FlightOut => r::Phase::FlightOut,
    }
}

/// The fitted surface level of a shot (the surface's plus the shot's own offset), m.
fn surface_level(a: &Analysis, surface: &str, shot: &str) -> Option<f64> {
    let fit = a.fit.shots.iter().find(|s| s.name == shot);
    match (
        crate::fitted_surface_level(&a.fit, surface),
        fit.and_then(|f| f.surface_offset_m),
    ) {
        (None, None) => None,
        (a, b) => Some(a.unwrap_or(0.0) + b.unwrap_or(0.0)),
    }
}

/// One shot: its measured frames, the fitted model where the camera would see it (measured − residual), the
/// residuals, and the model's phases as time spans.
fn shot_plot(a: &Analysis, c: &ShotComparison) -> r::ShotPlot {
    let data = a.shots.iter().find(|s| s.clip == c.shot);
    let frames = data.map(|s| s.measured.frames.as_slice()).unwrap_or_default();
    let mut phases: Vec<r::PhaseSpan> = Vec::new();
    for p in &c.residuals {
        match phases.last_mut() {
            Some(span) if span.phase == phase(p.phase) => span.t1_s = p.t_s,
            _ => phases.push(r::PhaseSpan {
                phase: phase(p.phase),
                t0_s: p.t_s,
                t1_s: p.t_s,
            }),
        }
    }
    let model = frames
        .iter()
        .zip(&c.residuals)
        .map(|(f, p)| r::ModelPoint {
            t_s: f.t_s,
            x_m: f.x_m - p.dx_m,
            y_m: f.y_m - p.dy_m,
        })
        .collect();
    let mut notes = data.map(|s| s.estimate.notes.clone()).unwrap_or_default();
    if let Some(source) = data.and_then(|s| contact_source(&s.estimate)) {
        notes.push(source);
    }
    if let Some(level) = surface_level(a, &c.surface, &c.shot) {
        // The level is the true surface's height in the measured frame: a negative one lies below the contact
        // line used (found, leaning on the touch, given or from the trajectory), so that line lies above the
        // plane the ball touches.
        let (where_, size) = if level <= 0.0 {
            ("above", -level)
        } else {
            ("below", level)
        };
        notes.push(format!(
            "fitted surface level {} µm: the contact line used lies {:.1} µm {where_} the plane the ball touches",
            format!("{:+.1}", level * 1e6).replace('-', "\u{2212}"),
            size * 1e6
        ));
    }
    r::ShotPlot {
        clip: c.shot.clone(),
        surface: c.surface.clone(),
        angle_deg: c.incline_deg,
        drop_height_m: c.drop_height_m,
        measured: frames.iter().map(measured_point).collect(),
        model,
        phases,
        residuals: c.residuals.iter().map(residual).collect(),
        rms_m: Some(c.rms_m),
        chi2_red: shot_chi2_red(&a.fit, &c.shot),
        notes,
        frames: Vec::new(),
    }
}

/// A parameter's unit from the effect library.
fn unit(effect: &str, param: &str) -> String {
    bouncelab_model::builtin_effects()
        .iter()
        .find(|e| e.name == effect)
        .and_then(|e| e.params.iter().find(|p| p.name == param))
        .map(|p| p.unit.to_string())
        .unwrap_or_default()
}

fn fit_summary(a: &Analysis) -> r::FitSummary {
    let f = &a.fit;
    r::FitSummary {
        model_name: a.model_origin.clone(),
        parameters: f.parameters.iter().map(fit_parameter).collect(),
        confidence: f.confidence,
        reduced_chi2: Some(f.reduced_chi2),
        dof: Some(f.dof),
        rms_m: Some(f.rms_m),
        termination: format!("{} after {} iteration(s)", f.termination, f.iterations),
        mean_abs_error_pct: f.mean_abs_cor_error_pct,
        by_surface: f.cor_error_by_surface.iter().map(surface_error).collect(),
        oblique: f.oblique.iter().map(oblique_row).collect(),
    }
}

fn fit_parameter(p: &bouncelab_fit::FittedParam) -> r::FitParameter {
    let bouncelab_fit::FittedParam {
        name,
        effect,
        param,
        // Part of the name already (`clay:spring.k`).
        surface: _,
        // The solver's start and bounds are the model file's, not results.
        initial: _,
        bounds: _,
        value,
        std_error,
        interval,
        at_bound,
        // Not shown yet: the report shows such a parameter's value and its missing standard error.
        not_identified: _,
    } = p;
    r::FitParameter {
        name: name.clone(),
        value: *value,
        std_error: *std_error,
        interval: *interval,
        unit: unit(effect, param),
        at_bound: *at_bound,
    }
}

fn surface_error(e: &bouncelab_fit::SurfaceError) -> r::SurfaceError {
    let bouncelab_fit::SurfaceError {
        surface,
        shots,
        mean_abs_error_pct,
    } = e;
    r::SurfaceError {
        surface: surface.clone(),
        shots: *shots,
        mean_abs_error_pct: *mean_abs_error_pct,
    }
}

fn oblique_row(o: &bouncelab_fit::ObliqueRow) -> r::ObliqueRow {
    let bouncelab_fit::ObliqueRow {
        shot,
        surface,
        incline_deg,
        // The shot's measured incoming velocity is in its measurements.
        v_in: _,
        v_out_measured,
        v_out_predicted,
        error_pct,
    } = o;
    r::ObliqueRow {
        clip: shot.clone(),
        surface: surface.clone(),
        angle_deg: *incline_deg,
        v_out_measured: *v_out_measured,
        v_out_predicted: *v_out_predicted,
        error_pct: *error_pct,
    }
}

fn verdict_kind(k: VerdictKind) -> r::VerdictKind {
    match k {
        VerdictKind::MissingEffect => r::VerdictKind::MissingEffect,
        VerdictKind::NoMissingEffect => r::VerdictKind::NoMissingEffect,
        VerdictKind::Ambiguous => r::VerdictKind::Ambiguous,
        VerdictKind::NoneExplains => r::VerdictKind::NoCandidateExplains,
    }
}

/// The verdict in a few words: the kind, the effect(s) named and the held-out error they leave.
pub fn verdict_headline(d: &Diagnosis) -> String {
    let named = |e: &str| d.candidate(e).and_then(|c| c.evidence.as_ref().map(|ev| (c, ev)));
    match d.verdict.kind {
        VerdictKind::MissingEffect => match d.verdict.effect.as_deref().and_then(|e| named(e).map(|x| (e, x))) {
            Some((_, (c, ev))) => {
                // The verdict's effects are the ones the search kept (a search that went on names the rest in
                // `then`, which may hold an effect it did not keep); the error left is the last kept one's.
                let names: Vec<String> = d.verdict.effects.iter().map(|e| format!("`{e}`")).collect();
                let mut after = ev.heldout_error_after;
                let mut next = d.then.as_deref();
                while let Some(n) = next {
                    let kept = n
                        .verdict
                        .effect
                        .as_deref()
                        .filter(|e2| d.verdict.effects.iter().any(|k| k == e2));
                    let Some(ev2) = kept.and_then(|e2| n.candidate(e2)).and_then(|c2| c2.evidence.as_ref()) else {
                        break;
                    };
                    after = ev2.heldout_error_after;
                    next = n.then.as_deref();
                }
                let verb = if names.len() > 1 { "are" } else { "is" };
                format!(
                    "{} {verb} missing: held-out error {:.1} → {:.1} µm",
                    names.join(" and "),
                    c.heldout_error_before * 1e6,
                    after * 1e6
                )
            }
            None => "an effect is missing".into(),
        },
        VerdictKind::Ambiguous => {
            let names: Vec<String> = d.verdict.effects.iter().map(|e| format!("`{e}`")).collect();
            format!("these explain the misfit about equally well: {}", names.join(", "))
        }
        VerdictKind::NoMissingEffect => {
            // Above the floor only with one shot: that shot's misfit, not the model's (the diagnose crate).
            let but_for = match &d.signature.worst_shot {
                Some(w) if d.baseline.systematic_m > d.thresholds.tolerance_m => {
                    format!(" but for one shot, `{}`, whose track to look at", w.shot)
                }
                _ => String::new(),
            };
            format!(
                "the model fits within the measurement floor{but_for} (position RMS {:.1} µm, noise {:.1} µm, floor {:.1} µm)",
                d.baseline.fit.rms_m * 1e6,
                d.noise.noise_m * 1e6,
                d.floor.floor_m * 1e6
            )
        }
        VerdictKind::NoneExplains => format!(
            "no library effect explains the misfit (systematic {:.1} µm); see its signature{}",
            d.baseline.systematic_m * 1e6,
            if d.proposal.is_some() {
                " and the proposed formula term"
            } else {
                ""
            }
        ),
    }
}

fn signature(d: &Diagnosis) -> Vec<r::SignatureRow> {
    d.signature
        .phases
        .iter()
        .filter(|p| p.component != Component::Spin)
        .map(|p| {
            let bouncelab_diagnose::PhaseResidual {
                phase,
                component,
                // The counts, the reduced χ² and the worst shot are in the diagnosis' own output, not the
                // report's table (the verdict's sentence names a shot that alone makes a phase misfit).
                n: _,
                rms_m,
                systematic_m,
                chi2_share,
                chi2_red: _,
                worst_shot: _,
            } = p;
            signature_row(*phase, *component, *rms_m, *systematic_m, *chi2_share)
        })
        .collect()
}

/// One row of a residual's signature (position components only).
fn signature_row(
    p: ImpactPhase,
    component: Component,
    rms_m: f64,
    systematic_m: f64,
    chi2_share: f64,
) -> r::SignatureRow {
    r::SignatureRow {
        phase: phase(p),
        normal: component == Component::Normal,
        rms_m,
        systematic_m,
        chi2_share,
    }
}

/// The signature of the current fit from its comparison, when no diagnosis ran: the systematic part taken
/// above the RMS of the tracker's σ.
fn signature_of_comparison(a: &Analysis) -> Vec<r::SignatureRow> {
    let c = &a.comparison;
    let (s2, n) = a
        .shots
        .iter()
        .flat_map(|s| &s.measured.frames)
        .fold((0.0, 0usize), |(acc, n), f| (acc + f.sigma_m * f.sigma_m, n + 1));
    let noise2 = s2 / n.max(1) as f64;
    let chi2: f64 = c
        .overall
        .iter()
        .filter(|s| s.component != Component::Spin)
        .map(|s| s.chi2)
        .sum();
    let mut rows: Vec<r::SignatureRow> = c
        .overall
        .iter()
        .filter(|s| s.component != Component::Spin)
        .map(|s| {
            signature_row(
                s.phase,
                s.component,
                s.rms_m,
                (s.rms_m * s.rms_m - noise2).max(0.0).sqrt(),
                if chi2 > 0.0 { s.chi2 / chi2 } else { 0.0 },
            )
        })
        .collect();
    rows.sort_by(|a, b| b.chi2_share.total_cmp(&a.chi2_share));
    rows
}

fn diagnosis(d: &Diagnosis, a: &Analysis) -> r::DiagnosisSection {
    let mut evidence: Vec<String> = d.signature.sentences.clone();
    for reason in &d.baseline.misfit_reasons {
        if !evidence.contains(reason) {
            evidence.push(reason.clone());
        }
    }
    r::DiagnosisSection {
        verdict_kind: verdict_kind(d.verdict.kind),
        headline: verdict_headline(d),
        verdict_text: d.verdict.sentence.clone(),
        evidence,
        signature: signature(d),
        error_metric: "position RMS of all frames (x and y), held-out by cross-validation across shots".into(),
        candidates: d.candidates.iter().map(candidate).collect(),
        model_history: a
            .history
            .iter()
            .filter_map(|h| {
                let f = h.latest.as_ref()?;
                Some(r::ModelVersion {
                    version: h.version.id as u32,
                    model: h.version.record.name.clone(),
                    created: f.created_at.clone(),
                    rms_m: Some(f.record.rms_m),
                    chi2_red: Some(f.record.reduced_chi2),
                })
            })
            .collect(),
    }
}

/// One candidate's errors before and after; a failed fit shows NaN after.
fn candidate(c: &bouncelab_diagnose::Candidate) -> r::Candidate {
    let bouncelab_diagnose::Candidate {
        effect,
        // The table is in rank order already; the checks and reasons are in the verdict's evidence.
        rank: _,
        explains: _,
        partly_explains: _,
        checks: _,
        reasons: _,
        error_before,
        heldout_error_before,
        param: _,
        neutral: _,
        evidence,
        failed: _,
        seconds: _,
    } = c;
    let after = evidence.as_ref().map(|e| {
        let bouncelab_diagnose::Evidence {
            error_after,
            delta_bic,
            heldout_error_after,
            // The rest supports the verdict, whose sentence and evidence the report shows.
            error_fall: _,
            heldout_log_ratio: _,
            heldout_p: _,
            heldout_p_holm: _,
            shots_improved: _,
            explained_fraction: _,
            systematic_after_m: _,
            chi2_red_after: _,
            chi2_red_noise_after: _,
            param_value: _,
            param_interval: _,
            param_z: _,
            detection_limit: _,
            cross_validated: _,
            kept_at_neutral: _,
            fit: _,
        } = e;
        (*error_after, *delta_bic, *heldout_error_after)
    });
    r::Candidate {
        effect: effect.clone(),
        error_before: *error_before,
        error_after: after.map_or(f64::NAN, |a| a.0),
        delta_bic: after.map_or(f64::NAN, |a| a.1),
        heldout_before: Some(*heldout_error_before),
        heldout_after: after.map(|a| a.2),
    }
}

/// The effects of a model file's text, by name; empty when it does not parse.
fn effect_names(toml: &str) -> Vec<String> {
    ModelSpec::parse(toml, "earlier model")
        .map(|s| s.effects.iter().map(|e| e.name.clone()).collect())
        .unwrap_or_default()
}

fn model_change(a: &Analysis) -> r::ModelChange {
    let b = a.before.as_ref().expect("called with a previous fit");
    let before: Vec<String> = effect_names(&b.before_toml);
    // The analysis adds the surface level itself to every model; it is no change of the model file.
    let before_has = |e: &str| before.iter().any(|x| x == e) || e == "surface_level";
    let after: Vec<String> = a.model.effects.iter().map(|e| e.name.clone()).collect();
    let surface_of = |clip: &str| {
        a.shots
            .iter()
            .find(|s| s.clip == clip)
            .map(|s| s.surface.clone())
            .unwrap_or_default()
    };
    r::ModelChange {
        model_before: b.before_model.clone(),
        model_after: a.model_origin.clone(),
        effects_added: after.iter().filter(|e| !before_has(e)).cloned().collect(),
        effects_removed: before.iter().filter(|e| !after.contains(e)).cloned().collect(),
        verdict_before: a.previous_diagnosis.as_ref().map(|d| r::EarlierVerdict {
            kind: verdict_kind(d.verdict.kind),
            text: d.verdict.sentence.clone(),
        }),
        signature_before: a.previous_diagnosis.as_ref().map(signature).unwrap_or_default(),
        signature_after: match &a.diagnosis {
            Ok(d) => signature(d),
            Err(_) => signature_of_comparison(a),
        },
        shots: b
            .shots
            .iter()
            .map(|(clip, x, y)| r::ShotBeforeAfter {
                clip: clip.clone(),
                surface: surface_of(clip),
                rms_before_m: *x,
                rms_after_m: *y,
            })
            .collect(),
        total_rms_before_m: b.total_rms_m.0,
        total_rms_after_m: b.total_rms_m.1,
        reduced_chi2_before: b.reduced_chi2.0,
        reduced_chi2_after: b.reduced_chi2.1,
    }
}

/// Writes `report.html` and the files of its figures' numbers into `dir`; returns their paths.
pub(crate) fn write(
    dir: &Path,
    a: &Analysis,
    clips: &[bouncelab_frames::ClipEntry],
    description: Option<&str>,
    warnings: &[String],
) -> Result<Vec<PathBuf>, crate::AnalyzeError> {
    let p = predictions(&a.model, &a.fit, &a.shots);
    let mut report = build(a, &p, description, warnings);
    draw_key_frames(&mut report, &a.shots, clips);
    let mut written = crate::outputs::write_figure_data(dir, &report)?;
    let path = dir.join("report.html");
    bouncelab_report::write_report(&path, &report)?;
    written.push(path);
    Ok(written)
}

/// `report.html` when no shot could be measured: the session, and every shot's failure with how far it got
/// (tracked in how many frames, or not at all).
pub(crate) fn write_failure(
    dir: &std::path::Path,
    session: &bouncelab_frames::Session,
    measure: &crate::MeasureSummary,
    failed_tracks: &[(String, bouncelab_store::TrackRecord, String)],
) -> Result<std::path::PathBuf, crate::AnalyzeError> {
    let mut notes: Vec<String> = session.warnings.iter().map(|w| w.to_string()).collect();
    for (clip, why) in &measure.failed {
        let got = match failed_tracks.iter().find(|(c, _, _)| c == clip) {
            Some((_, t, _)) => format!(
                "tracked: ball measured in {} of {} frames; trajectory written",
                t.measured, t.frames
            ),
            None => "not tracked".to_string(),
        };
        notes.push(format!("{clip}: not measured: {why} ({got})"));
    }
    let none = "no shot could be measured (see the notes for each shot's reason)";
    let report = r::Report {
        title: title(&session.dir),
        session: r::SessionInfo {
            path: session.dir.display().to_string(),
            description: String::new(),
            shots: session.listed().len(),
            surfaces: Vec::new(),
            generated_by: generated_by(),
            generated_at: None,
            metadata: vec![("shots measured".into(), "0".into())],
        },
        contact_force: r::Section::unavailable(none),
        ancova: r::Section::unavailable(none),
        inference: r::Section::unavailable(none),
        fit: r::Section::unavailable(none),
        diagnosis: r::Section::unavailable(none),
        model_change: r::Section::unavailable(none),
        warnings: notes,
        ..Default::default()
    };
    let path = dir.join("report.html");
    bouncelab_report::write_report(&path, &report)?;
    Ok(path)
}

/// Where a shot's contact level came from, for a person: the cue, the line's tilt and how the ball's own
/// trajectory agrees with it.
fn contact_source(e: &bouncelab_estimate::Estimate) -> Option<String> {
    use bouncelab_track::LineCue;
    let line = e.contact_line?;
    let what = match line.cue {
        LineCue::Given => "the contact line given in the settings",
        LineCue::Brightness => "the surface line found by its brightness step",
        LineCue::Texture => "the surface line found by its change of texture",
        LineCue::Trajectory => "the ball's trajectory (no surface line it agrees with was found)",
    };
    let mut text = format!("contact level from {what}");
    if e.trajectory_share > 0.005 {
        text += &format!(
            ", moved towards the ball's trajectory's level by {:.0} % (their inverse-variance weights)",
            100.0 * e.trajectory_share
        );
    }
    if e.level_se_scale > 1.005 {
        text += &format!(
            ", its error widened {:.1}-fold as the line and the ball's trajectory lie further apart than their errors allow",
            e.level_se_scale
        );
    }
    if let Some(t) = e.surface_tilt_deg {
        text += &format!(", tilt {:+.3} ± {:.3}°", t.value, t.se).replace('-', "\u{2212}");
        let same = |a: bouncelab_estimate::Measured| (a.value - t.value).abs() < 1e-6 && (a.se - t.se).abs() < 1e-6;
        match (e.line_tilt_deg, e.fall_tilt_deg) {
            (Some(l), Some(f)) if !same(l) => {
                text += &format!(
                    " (the line's {:+.3} ± {:.3}°, the fall's {:+.3} ± {:.3}°)",
                    l.value, l.se, f.value, f.se
                )
                .replace('-', "\u{2212}");
            }
            (None, Some(f)) if same(f) => text += " (from the ball's fall)",
            _ => {}
        }
    }
    if line.cue != LineCue::Trajectory
        && let Some(level) = e.trajectory_level_px
    {
        text += &format!(
            "; the trajectory puts it {:.2} ± {:.2} px {}",
            level.value.abs(),
            level.se,
            if level.value >= 0.0 { "higher" } else { "lower" }
        );
    }
    Some(text)
}

/// One line per distinct camera (as its files' headers describe it) with the shots it recorded: model,
/// format, rate, exposure, bit depth and where the trigger fell. Nothing for folders of images.
fn camera_notes(shots: &[ShotData]) -> Vec<String> {
    // Each camera's description, its shots, and the trigger's file frame of those that state one.
    let mut cameras: Vec<(String, usize, Vec<String>)> = Vec::new();
    for s in shots {
        let Some(c) = &s.track.camera else { continue };
        let mut text = format!(
            "{} ({})",
            c.model.as_deref().unwrap_or("camera model not stated"),
            c.format
        );
        if let Some(fps) = c.fps {
            text += &format!(", {fps} frames/s");
        }
        if let Some(e) = c.exposure_s {
            text += &format!(", exposure {} µs", e * 1e6);
        }
        if let Some(b) = c.bit_depth {
            text += &format!(", {b}-bit");
        }
        let i = match cameras.iter().position(|(t, _, _)| *t == text) {
            Some(i) => i,
            None => {
                cameras.push((text, 0, Vec::new()));
                cameras.len() - 1
            }
        };
        cameras[i].1 += 1;
        if let Some(t) = c.trigger_frame {
            cameras[i].2.push(format!("{} {t}", s.clip));
        }
    }
    cameras
        .into_iter()
        .map(|(text, n, triggers)| {
            let mut line = format!("camera: {text}; {n} shot(s)");
            if !triggers.is_empty() {
                line += &format!("; trigger at file frame {}", triggers.join(", "));
            }
            line
        })
        .collect()
}

/// Fills each shot's strip of key frames (approach, touch, deepest, separation, leave), read back from its
/// clip with the stored track drawn on them, so the tracking can be checked by eye. A shot whose strip cannot
/// be drawn (the clip moved since it was measured, a frame unreadable) gets a note saying why instead.
fn draw_key_frames(report: &mut r::Report, shots: &[ShotData], clips: &[bouncelab_frames::ClipEntry]) {
    use rayon::prelude::*;
    let strips: Vec<Result<r::FrameImage, String>> = report
        .shots
        .par_iter()
        .map(|plot| {
            let shot = shots.iter().find(|s| s.clip == plot.clip).ok_or("no stored track")?;
            let entry = clips.iter().find(|c| c.name == plot.clip).ok_or("not in clips.csv")?;
            key_frame_strip(entry, shot)
        })
        .collect();
    for (plot, strip) in report.shots.iter_mut().zip(strips) {
        match strip {
            Ok(image) => plot.frames.push(image),
            Err(why) => plot.notes.push(format!("key frames not drawn: {why}")),
        }
    }
}

/// One shot's key-frame strip as PNG, captioned with its frames.
fn key_frame_strip(entry: &bouncelab_frames::ClipEntry, shot: &ShotData) -> Result<r::FrameImage, String> {
    use bouncelab_overlay as o;
    let clip = entry.open().map_err(|e| e.to_string())?;
    let marks: Vec<o::BallMark> = shot
        .track
        .rows
        .iter()
        .map(|&bouncelab_track::TrajectoryRow { fix: f, .. }| o::BallMark {
            frame: f.frame as u64,
            x_px: f.x_px,
            y_px: f.y_px,
            r_px: f.r_px,
            status: f.status,
            phase: o::Phase::Unknown,
        })
        .collect();
    let line = shot.estimate.contact_line.map(|l| o::SurfaceLine {
        x0: l.x0,
        y0: l.y0,
        slope: l.slope,
    });
    let mut radii: Vec<f64> = marks
        .iter()
        .filter(|m| m.status == o::Status::Ok)
        .map(|m| m.r_px)
        .collect();
    radii.sort_by(f64::total_cmp);
    let rule = o::ContactRule {
        radius_px: radii.get(radii.len() / 2).copied(),
        ..o::ContactRule::default()
    };
    let style = o::Style {
        levels: clip
            .read(0, bouncelab_frames::PngDecoder::default())
            .and_then(Result::ok)
            .map_or(o::Levels::FULL, |f| o::Levels::stretch(&f.pixels, 0.5, 99.5)),
        ..o::Style::default()
    };
    let (image, caption) = o::shot_strip(&clip, &marks, line.as_ref(), &rule, &style).map_err(|e| e.to_string())?;
    Ok(r::FrameImage {
        caption: format!("key frames: {caption}"),
        png: o::encode_png(&image).map_err(|e| e.to_string())?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_fit::MeasuredFrame;
    use bouncelab_track::{LineCue, SurfaceLine};
    use serde::Serialize;

    /// A search that went on after its first effect (`fixtures/diagnosis/two-effects.json`, a 16-shot
    /// Hunt–Crossley + rolling-resistance session's diagnosis with the unnamed candidates left out) is
    /// summed up with both effects and the error the second leaves.
    #[test]
    fn the_headline_names_every_effect_of_a_search_that_went_on() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/diagnosis/two-effects.json");
        let mut d: Diagnosis = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        assert_eq!(
            verdict_headline(&d),
            "`rolling_resistance` and `hunt_crossley` are missing: held-out error 181.1 → 8.2 µm"
        );
        // A search that went on but whose second effect was not kept names the first alone.
        d.verdict.effects.truncate(1);
        assert_eq!(
            verdict_headline(&d),
            "`rolling_resistance` is missing: held-out error 181.1 → 93.9 µm"
        );
        d.then = None;
        assert_eq!(
            verdict_headline(&d),
            "`rolling_resistance` is missing: held-out error 181.1 → 93.9 µm"
        );
    }

    #[test]
    fn shots_on_the_image_axes_are_named_when_the_lines_found_show_a_tilt() {
        let found = SurfaceLine {
            cue: LineCue::Brightness,
            ..SurfaceLine::given(255.5, 400.0, -1.5)
        };
        let axes = SurfaceLine {
            cue: LineCue::Trajectory,
            ..SurfaceLine::given(255.5, 400.0, 0.0)
        };
        let told = SurfaceLine {
            cue: LineCue::Trajectory,
            ..SurfaceLine::given(255.5, 400.0, -1.5)
        };
        let shots = [("a", Some(found)), ("b", Some(axes)), ("c", Some(told)), ("d", None)];
        let tilt = bouncelab_estimate::Measured { value: -1.5, se: 0.01 };
        let note = unseen_tilt_note(shots.into_iter(), tilt).expect("a note");
        assert!(note.starts_with("1 shot(s) (b)"), "{note}");
        assert!(note.contains("tilt_deg = -1.50"), "{note}");
        // A tilt the lines do not show clearly, or no shot on the image's axes: nothing to say.
        let faint = bouncelab_estimate::Measured { value: -0.01, se: 0.01 };
        assert!(unseen_tilt_note(shots.into_iter(), faint).is_none());
        assert!(unseen_tilt_note(shots[..1].iter().copied(), tilt).is_none());
    }

    /// Every key of `mirror` (a report type, serialised) carries the producer's value under the same key,
    /// or under the key `renamed` pairs it with; `derived` keys are filled from elsewhere. Catches a mapper
    /// that puts a value in the wrong field or the wrong unit, and a mirror field without a source.
    fn assert_mirrors(producer: &impl Serialize, mirror: &impl Serialize, renamed: &[(&str, &str)], derived: &[&str]) {
        let p = serde_json::to_value(producer).unwrap();
        let m = serde_json::to_value(mirror).unwrap();
        let (p, m) = (p.as_object().unwrap(), m.as_object().unwrap());
        for (key, value) in m {
            if derived.contains(&key.as_str()) {
                continue;
            }
            let from = renamed.iter().find(|r| r.0 == key).map_or(key.as_str(), |r| r.1);
            assert_eq!(
                p.get(from),
                Some(value),
                "report field `{key}` against producer field `{from}`"
            );
        }
        for (to, from) in renamed {
            assert!(
                m.contains_key(*to) && p.contains_key(*from),
                "stale rename {from} → {to}"
            );
        }
    }

    #[test]
    fn the_report_mirrors_carry_the_producers_values() {
        let force = bouncelab_fit::ForceSample {
            t_s: 1e-4,
            delta_m: 2e-4,
            force_n: 310.0,
        };
        assert_mirrors(&force, &force_sample(&force), &[], &[]);
        let p = bouncelab_fit::ImpactPrediction {
            v_in: [0.5, -3.0],
            v_out: [0.4, 2.2],
            cor: 0.73,
            mu_eff: 0.31,
            contact_time_s: 4.5e-3,
            delta_max_m: 2.1e-3,
            omega_out_rad_s: -41.0,
            peak_force_n: 820.0,
            peak_deceleration_m_s2: 14_000.0,
            force: vec![force],
        };
        assert_mirrors(&p, &prediction(&p), &[("spin_out_rad_s", "omega_out_rad_s")], &[]);
        let f = MeasuredFrame {
            t_s: 0.01,
            x_m: 0.02,
            y_m: 0.03,
            sigma_m: 4e-5,
        };
        assert_mirrors(&f, &measured_point(&f), &[], &[]);
        let rp = bouncelab_compare::ResidualPoint {
            t_s: 0.01,
            phase: ImpactPhase::Compression,
            dx_m: 1e-5,
            dy_m: -2e-5,
            sigma_m: 4e-5,
            d_omega_rad_s: Some(1.0),
            sigma_omega_rad_s: Some(0.5),
        };
        assert_mirrors(&rp, &residual(&rp), &[], &[]);
        let fp = bouncelab_fit::FittedParam {
            name: "clay:spring.k".into(),
            effect: "spring".into(),
            param: "k".into(),
            surface: Some("clay".into()),
            initial: 20_000.0,
            value: 25_650.0,
            std_error: Some(300.0),
            interval: Some([25_000.0, 26_300.0]),
            bounds: [1.0, 1e7],
            at_bound: true,
            not_identified: None,
        };
        let mapped = fit_parameter(&fp);
        assert_mirrors(&fp, &mapped, &[], &["unit"]);
        assert_eq!(mapped.unit, "N/m", "the unit from the effect library");
        let se = bouncelab_fit::SurfaceError {
            surface: "clay".into(),
            shots: 8,
            mean_abs_error_pct: 2.5,
        };
        assert_mirrors(&se, &surface_error(&se), &[], &[]);
        let o = bouncelab_fit::ObliqueRow {
            shot: "S001".into(),
            surface: "clay".into(),
            incline_deg: 15.0,
            v_in: [0.7, -2.9],
            v_out_measured: [0.5, 2.1],
            v_out_predicted: [0.52, 2.0],
            error_pct: [4.0, 4.8],
        };
        assert_mirrors(
            &o,
            &oblique_row(&o),
            &[("clip", "shot"), ("angle_deg", "incline_deg")],
            &[],
        );
        let m = bouncelab_estimate::Measured { value: 0.73, se: 0.002 };
        let mapped = measured(m);
        assert_eq!((mapped.value, mapped.se), (m.value, Some(m.se)));
    }

    #[test]
    fn the_phases_keep_their_names_and_order() {
        let shown: Vec<r::Phase> = ImpactPhase::ALL.iter().map(|p| phase(*p)).collect();
        assert_eq!(shown, r::Phase::ALL, "the same phases in the same time order");
        for (p, q) in ImpactPhase::ALL.iter().zip(r::Phase::ALL) {
            assert_eq!(serde_json::to_value(p).unwrap(), serde_json::to_value(q).unwrap());
        }
    }

    #[test]
    fn the_inverse_of_a_3x3_matrix() {
        let m = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let inv = invert3(&m).unwrap();
        for (i, row) in m.iter().enumerate() {
            for j in 0..3 {
                let v: f64 = row.iter().zip(&inv).map(|(a, b)| a * b[j]).sum();
                assert!((v - f64::from(u8::from(i == j))).abs() < 1e-12, "{i}{j}: {v}");
            }
        }
        assert!(invert3(&[[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]]).is_none());
    }

    /// A half-sine contact sampled at `fps` with noise σ, and the true peak deceleration.
    fn contact(fps: f64, sigma: f64, seed: u64) -> (Vec<MeasuredFrame>, f64, f64, f64) {
        let (t0, tc, v) = (0.01, 4.5e-3, 2.5);
        let w = std::f64::consts::PI / tc;
        let mut state = seed;
        let mut normal = || {
            // Box–Muller from a SplitMix64 stream.
            let mut u = || {
                state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let mut z = state;
                z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 + 1e-12
            };
            let (a, b) = (u(), u());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        };
        let frames = (0..((0.02 * fps) as usize))
            .map(|k| {
                let t = k as f64 / fps;
                let y = if t < t0 {
                    0.0335 + v * (t0 - t)
                } else if t < t0 + tc {
                    0.0335 - v / w * (w * (t - t0)).sin()
                } else {
                    0.0335 + v * (t - t0 - tc)
                };
                MeasuredFrame {
                    t_s: t,
                    x_m: 0.0,
                    y_m: y + sigma * normal(),
                    sigma_m: sigma,
                }
            })
            .collect();
        (frames, t0, t0 + tc, v * w)
    }

    #[test]
    fn the_track_gives_the_peak_deceleration_of_a_half_sine() {
        // 10,000 fps, 5 µm noise: the truth within three standard errors plus the window's rounding (the
        // largest of several windows leans high, the quadratic low).
        for seed in 1..9 {
            let (frames, t0, t1, truth) = contact(10_000.0, 5e-6, seed);
            let (a, se) = track_peak_deceleration(&frames, t0, t1).expect("resolved at 10 kHz");
            assert!(
                (a - truth).abs() < 3.0 * se + 0.03 * truth,
                "seed {seed}: {a} ± {se} vs {truth}"
            );
            assert!(se > 0.0 && se < 0.05 * truth, "{se}");
        }
        // A slow camera has too few contact frames for the quadratic: not measured, not guessed.
        let (frames, t0, t1, _) = contact(1_000.0, 5e-6, 1);
        assert!(track_peak_deceleration(&frames, t0, t1).is_none());
        // Noise far above the signal: not measured either.
        let (frames, t0, t1, _) = contact(10_000.0, 2e-3, 1);
        assert!(track_peak_deceleration(&frames, t0, t1).is_none());
    }
}
