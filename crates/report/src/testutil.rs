//! A synthetic session report for tests, the example and the browser check: drop shots on three surfaces
//! whose COR falls with impact speed while the "fitted" model's does not (so the residuals and the
//! diagnosis have something to show), with real ANCOVA and Tukey results from `bouncelab-stats`.

use bouncelab_stats::{Ancova, AncovaInference, CorObservation, Dataset, PAPER_TERMS, ancova, ancova_inference};

use crate::data::*;

/// The workspace's one seeded generator (SplitMix64 with Box–Muller normals).
pub use bouncelab_testkit::Rng;

/// Ball radius, m.
const R: f64 = 0.0335;
/// Gravity, m/s².
const G: f64 = 9.81;
/// Frame interval, s (10,000 fps).
const DT: f64 = 1e-4;
/// Tracking noise, m.
const SIGMA: f64 = 8e-5;
/// Touch time, s from the first frame.
const T_TOUCH: f64 = 0.03;
/// Contact time, s.
const T_CONTACT: f64 = 0.0045;
/// Frames per clip.
const FRAMES: usize = 700;

/// Surfaces: name, COR at 2 m/s, speed slope (1/(m/s)), k (N/m), b (N·s/m).
const SURFACES: [(&str, f64, f64, f64, f64); 3] = [
    ("clay", 0.80, -0.035, 25_650.0, 14.0),
    ("tape1", 0.76, -0.030, 30_800.0, 15.0),
    ("tape2", 0.735, -0.030, 31_825.0, 15.0),
];

/// Centre (x, y) in the local frame at time `t` for a shot touching at `T_TOUCH` with incoming
/// (v_t, |v_n|), outgoing (v_t', v_n'), maximum penetration `dmax`, on an incline `theta` (rad).
fn position(t: f64, v_t: f64, v_n: f64, out: (f64, f64), dmax: f64, theta: f64) -> (f64, f64) {
    let (gt, gn) = (G * theta.sin(), G * theta.cos());
    if t < T_TOUCH {
        let tau = T_TOUCH - t;
        (-v_t * tau + 0.5 * gt * tau * tau, R + v_n * tau - 0.5 * gn * tau * tau)
    } else if t < T_TOUCH + T_CONTACT {
        let s = t - T_TOUCH;
        let x = v_t * s + (out.0 - v_t) * s * s / (2.0 * T_CONTACT);
        (x, R - dmax * (std::f64::consts::PI * s / T_CONTACT).sin())
    } else {
        let x_end = v_t * T_CONTACT + (out.0 - v_t) * T_CONTACT / 2.0;
        let tau = t - T_TOUCH - T_CONTACT;
        (
            x_end + out.0 * tau + 0.5 * gt * tau * tau,
            R + out.1 * tau - 0.5 * gn * tau * tau,
        )
    }
}

/// The sample "model": its COR at normal speed `v` (m/s) on a surface with COR `e2` at 2 m/s (a speed
/// dependence the measured data lack, so the diagnosis has something to show).
fn model_cor(e2: f64, v: f64) -> f64 {
    e2 - 0.021 + 0.004 * (v - 2.0)
}

/// A prediction of the sample "model" at normal speed `v` on a surface with stiffness `k`.
fn prediction(e2: f64, k: f64, v: f64) -> ShotPrediction {
    let m = 0.0567;
    let w = (k / m).sqrt();
    ShotPrediction {
        cor: model_cor(e2, v),
        mu_eff: 0.31,
        contact_time_s: std::f64::consts::PI / w,
        delta_max_m: v / w,
        spin_out_rad_s: -20.0 * v,
        peak_force_n: k * v / w,
        peak_deceleration_m_s2: k * v / w / m - G,
    }
}

/// The sample report: three surfaces, `per_surface` shots each (angles 0–22.5°, drop heights 0.3–0.9 m),
/// deterministic for a given `seed`.
pub fn sample_report_with(per_surface: usize, seed: u64) -> Report {
    let mut rng = Rng::new(seed);
    let mut shots = Vec::new();
    let mut measurements = Vec::new();
    let mut oblique = Vec::new();
    let mut before_after = Vec::new();
    let mut errors: Vec<(String, f64)> = Vec::new();
    for si in 0..SURFACES.len() {
        for j in 0..per_surface {
            let one = sample_shot(&mut rng, si, j, per_surface);
            errors.push((one.shot.surface.clone(), one.cor_error_pct));
            oblique.extend(one.oblique);
            before_after.push(one.before_after);
            measurements.push(one.measurement);
            shots.push(one.shot);
        }
    }
    let contact_force = sample_contact_force(&measurements);
    let (anc, inference) = sample_statistics(&measurements);
    let all_err = errors.iter().map(|x| x.1).sum::<f64>() / errors.len().max(1) as f64;
    let rms_all = (shots
        .iter()
        .filter_map(crate::shots::rms_of)
        .map(|r| r * r)
        .sum::<f64>()
        / shots.len().max(1) as f64)
        .sqrt();
    let rms_after =
        (before_after.iter().map(|b| b.rms_after_m.powi(2)).sum::<f64>() / before_after.len().max(1) as f64).sqrt();
    let verdict_before = format!(
        "Hunt–Crossley damping (b·δⁿ·δ̇, COR falling with impact speed) is missing: adding it lowers the RMS residual \
         from {:.1} µm to {:.1} µm and the BIC by 412.",
        rms_all * 1e6,
        rms_after * 1e6
    );
    Report {
        title: "Drop tests on clay and two line tapes (synthetic)".into(),
        session: sample_session(shots.len()),
        shots,
        measurements,
        model_curves: sample_curves(),
        contact_force,
        ancova: anc,
        inference,
        fit: Section::Available(FitSummary {
            model_name: "paper (spring + damping + coulomb)".into(),
            parameters: sample_parameters(),
            confidence: 0.95,
            reduced_chi2: Some((rms_all / SIGMA).powi(2)),
            dof: Some(2 * FRAMES * per_surface * SURFACES.len() - 7 - per_surface * SURFACES.len()),
            rms_m: Some(rms_all),
            termination: "converged: relative cost change below 1e-10 after 14 iterations".into(),
            mean_abs_error_pct: Some(all_err),
            by_surface: sample_surface_errors(&errors),
            oblique,
        }),
        diagnosis: Section::Available(sample_diagnosis(rms_all, rms_after, &verdict_before)),
        model_change: Section::Available(ModelChange {
            model_before: "v1: paper".into(),
            model_after: "v2: paper + hunt_crossley".into(),
            effects_added: vec!["hunt_crossley".into()],
            effects_removed: Vec::new(),
            verdict_before: Some(EarlierVerdict {
                kind: VerdictKind::MissingEffect,
                text: verdict_before,
            }),
            signature_before: sample_signature(1.0),
            signature_after: sample_signature(0.08),
            shots: before_after,
            total_rms_before_m: rms_all,
            total_rms_after_m: rms_after,
            reduced_chi2_before: (rms_all / SIGMA).powi(2),
            reduced_chi2_after: (rms_after / SIGMA).powi(2),
        }),
        warnings: vec![
            "S004-clay: 2 frames without the ball (311–312); timestamps follow the frame numbers".into(),
            "fps not given on the command line or in clip.toml: 10000 from session.toml".into(),
        ],
        timings: vec![
            ("decode frames".into(), 12.31),
            ("track".into(), 40.12),
            ("estimate".into(), 0.84),
            ("fit".into(), 95.2),
            ("diagnose".into(), 210.4),
            ("stats".into(), 0.05),
            ("report".into(), 0.31),
        ],
    }
}

/// One synthetic shot and what the session's tables take from it.
struct SampleShot {
    shot: ShotPlot,
    measurement: ShotMeasurement,
    /// The sample model's COR error for the shot, %.
    cor_error_pct: f64,
    /// Its row of the oblique validation, on an incline.
    oblique: Option<ObliqueRow>,
    before_after: ShotBeforeAfter,
}

/// Shot `j` of surface `si`: its trajectory with noise, the sample model over it and its measurements, drawn
/// from `rng` in a fixed order (the sample's bytes depend on it).
fn sample_shot(rng: &mut Rng, si: usize, j: usize, per_surface: usize) -> SampleShot {
    let (surface, e2, slope, _, _) = SURFACES[si];
    let angles = [0.0, 7.5, 15.0, 22.5];
    let heights = [0.3, 0.5, 0.7, 0.9];
    let angle = angles[j % angles.len()];
    let h = heights[(j / angles.len() + j) % heights.len()] + 0.01 * si as f64;
    let theta = f64::to_radians(angle);
    let v = (2.0 * G * h).sqrt();
    let (v_t, v_n) = (v * theta.sin(), v * theta.cos());
    let e_true = e2 + slope * (v_n - 2.0) + 0.008 * rng.normal();
    let e_model = model_cor(e2, v_n);
    let out_true = (0.72 * v_t, e_true * v_n);
    let out_model = (0.74 * v_t, e_model * v_n);
    let dmax = v_n * T_CONTACT / std::f64::consts::PI * 0.9;
    let clip = format!("S{:03}-{surface}", si * per_surface + j + 1);
    let gap = (j == 3).then_some(311..313);
    let truth = Flight {
        v_t,
        v_n,
        out: out_true,
        dmax,
        theta,
    };
    let model = Flight {
        out: out_model,
        dmax: dmax * 0.92,
        ..truth
    };
    let (measured, residuals) = sample_frames(rng, &truth, &model, gap.clone());
    // Every shot shares the level note; one has its own.
    let mut notes = vec!["the surface level is fitted per surface".to_string()];
    if gap.is_some() {
        notes.push("2 frames without the ball (311–312)".to_string());
    }
    let shot = ShotPlot {
        clip: clip.clone(),
        surface: surface.into(),
        angle_deg: angle,
        drop_height_m: Some(h),
        measured,
        model: (0..FRAMES * 2)
            .map(|k| {
                let t = k as f64 * DT / 2.0;
                let (x, y) = model.at(t);
                ModelPoint { t_s: t, x_m: x, y_m: y }
            })
            .collect(),
        phases: sample_phases(),
        residuals,
        rms_m: None,
        chi2_red: None,
        notes,
        frames: Vec::new(),
    };
    let rms = crate::shots::rms_of(&shot).unwrap_or(f64::NAN);
    let shot = ShotPlot {
        chi2_red: Some((rms / SIGMA).powi(2)),
        ..shot
    };
    let measurement = sample_measurement(rng, &clip, si, angle, h, &truth, e_true);
    let cor = measurement.cor.value;
    let oblique = (angle > 0.0).then(|| {
        let pct = |p: f64, m: f64| 100.0 * (p - m).abs() / m.abs();
        ObliqueRow {
            clip: clip.clone(),
            surface: surface.into(),
            angle_deg: angle,
            v_out_measured: [out_true.0, out_true.1],
            v_out_predicted: [out_model.0, out_model.1],
            error_pct: [pct(out_model.0, out_true.0), pct(out_model.1, out_true.1)],
        }
    });
    let before_after = ShotBeforeAfter {
        clip,
        surface: surface.into(),
        rms_before_m: rms,
        rms_after_m: SIGMA * (1.02 + 0.08 * rng.uniform()),
    };
    SampleShot {
        shot,
        measurement,
        cor_error_pct: 100.0 * (e_model - cor).abs() / cor,
        oblique,
        before_after,
    }
}

/// What the sample measured of a shot on surface `si` (its true path `truth`, its true COR `e_true`),
/// drawn from `rng` in a fixed order after its frames, with the sample model's prediction.
fn sample_measurement(
    rng: &mut Rng,
    clip: &str,
    si: usize,
    angle: f64,
    h: f64,
    truth: &Flight,
    e_true: f64,
) -> ShotMeasurement {
    let (surface, e2, _, k, _) = SURFACES[si];
    let Flight {
        v_t,
        v_n,
        out: out_true,
        dmax,
        ..
    } = *truth;
    let cor = e_true + 0.004 * rng.normal();
    let v_in_n = -v_n + 0.01 * rng.normal();
    let tc = T_CONTACT * (1.0 + 0.02 * rng.normal());
    let spin = (angle > 0.0).then(|| Measured::new(-25.0 * v_t + rng.normal(), 1.2));
    ShotMeasurement {
        clip: clip.into(),
        surface: surface.into(),
        angle_deg: angle,
        drop_height_m: Some(h),
        v_in_m_s: [Measured::new(v_t, 0.01), Measured::new(v_in_n, 0.012)],
        v_out_m_s: [Measured::new(out_true.0, 0.01), Measured::new(out_true.1, 0.012)],
        cor: Measured::new(cor, 0.0004 + 0.0002 * rng.uniform()),
        mu_eff: Measured::new(if angle > 0.0 { 0.3 + 0.02 * rng.normal() } else { -0.0 }, 0.01),
        contact_time_s: Measured::new(tc, 3e-5),
        delta_max_m: Measured::new(dmax, 4e-5),
        spin_in_rad_s: (angle > 0.0).then(|| Measured::new(rng.normal(), 1.0)),
        spin_out_rad_s: spin,
        peak_deceleration_track_m_s2: (v_n > 2.5).then(|| Measured::new(std::f64::consts::PI * v_n * 1.8 / tc, 60.0)),
        peak_force_track_n: (v_n > 2.5)
            .then(|| Measured::new(0.0567 * (std::f64::consts::PI * v_n * 1.8 / tc + G), 3.4)),
        model: Some(prediction(e2, k, v_n)),
    }
}

/// A flight–contact–flight path of the sample (see [`position`]).
#[derive(Debug, Clone, Copy)]
struct Flight {
    /// Incoming tangential speed and normal speed |v_n|, m/s.
    v_t: f64,
    v_n: f64,
    /// Outgoing (tangential, normal) velocity, m/s.
    out: (f64, f64),
    /// Maximum penetration, m.
    dmax: f64,
    /// Incline, rad.
    theta: f64,
}

impl Flight {
    /// The centre at time `t`, s.
    fn at(&self, t: f64) -> (f64, f64) {
        position(t, self.v_t, self.v_n, self.out, self.dmax, self.theta)
    }
}

/// The tracked centres (the truth plus noise, the frames in `gap` left out) and their residuals from the
/// model.
fn sample_frames(
    rng: &mut Rng,
    truth: &Flight,
    model: &Flight,
    gap: Option<std::ops::Range<usize>>,
) -> (Vec<MeasuredPoint>, Vec<Residual>) {
    let mut measured = Vec::with_capacity(FRAMES);
    let mut residuals = Vec::with_capacity(FRAMES);
    for f in 0..FRAMES {
        if gap.as_ref().is_some_and(|g| g.contains(&f)) {
            continue;
        }
        let t = f as f64 * DT;
        let (x, y) = truth.at(t);
        let (xm, ym) = model.at(t);
        let p = MeasuredPoint {
            t_s: t,
            x_m: x + SIGMA * rng.normal(),
            y_m: y + SIGMA * rng.normal(),
            sigma_m: SIGMA,
        };
        residuals.push(Residual {
            t_s: t,
            dx_m: p.x_m - xm,
            dy_m: p.y_m - ym,
        });
        measured.push(p);
    }
    (measured, residuals)
}

/// Every sample shot's phases: touch at [`T_TOUCH`], maximum compression half way through the contact.
fn sample_phases() -> Vec<PhaseSpan> {
    vec![
        PhaseSpan {
            phase: Phase::FlightIn,
            t0_s: 0.0,
            t1_s: T_TOUCH,
        },
        PhaseSpan {
            phase: Phase::Compression,
            t0_s: T_TOUCH,
            t1_s: T_TOUCH + T_CONTACT / 2.0,
        },
        PhaseSpan {
            phase: Phase::Restitution,
            t0_s: T_TOUCH + T_CONTACT / 2.0,
            t1_s: T_TOUCH + T_CONTACT,
        },
        PhaseSpan {
            phase: Phase::FlightOut,
            t0_s: T_TOUCH + T_CONTACT,
            t1_s: (FRAMES - 1) as f64 * DT,
        },
    ]
}

/// The sample model's curves: every surface at 0° and 22.5° from 1.6 to 4.4 m/s.
fn sample_curves() -> Vec<ModelCurve> {
    SURFACES
        .iter()
        .flat_map(|&(surface, e2, _, k, _)| {
            [0.0, 22.5].map(|angle| ModelCurve {
                surface: surface.into(),
                angle_deg: angle,
                points: (0..=30)
                    .map(|i| {
                        let v = 1.6 + 2.8 * i as f64 / 30.0;
                        CurvePoint {
                            v_in_n_m_s: v,
                            prediction: prediction(e2, k, v),
                        }
                    })
                    .collect(),
            })
        })
        .collect()
}

/// The contact force of the shot nearest the median impact speed (a spring–damper half sine).
fn sample_contact_force(measurements: &[ShotMeasurement]) -> Section<ContactForce> {
    let mut speeds: Vec<(usize, f64)> = measurements
        .iter()
        .enumerate()
        .map(|(i, m)| (i, m.v_in_m_s[1].value.abs()))
        .collect();
    speeds.sort_by(|a, b| a.1.total_cmp(&b.1));
    let chosen = &measurements[speeds[speeds.len() / 2].0];
    let (k, v) = (
        SURFACES
            .iter()
            .find(|s| s.0 == chosen.surface)
            .map_or(25_650.0, |s| s.3),
        chosen.v_in_m_s[1].value.abs(),
    );
    let w = (k / 0.0567f64).sqrt();
    Section::Available(ContactForce {
        clip: chosen.clip.clone(),
        surface: chosen.surface.clone(),
        angle_deg: chosen.angle_deg,
        v_in_n_m_s: v,
        why: "the shot nearest the session's median impact speed".into(),
        samples: (0..=100)
            .map(|i| {
                let t = std::f64::consts::PI / w * i as f64 / 100.0;
                let d = v / w * (w * t).sin();
                ForceSample {
                    t_s: t,
                    delta_m: d,
                    force_n: k * d + if i < 50 { 14.0 * v * (w * t).cos() } else { 0.0 },
                }
            })
            .collect(),
    })
}

/// The ANCOVA of the measured COR and its inference, as the pipeline computes them.
fn sample_statistics(measurements: &[ShotMeasurement]) -> (Section<Ancova>, Section<AncovaInference>) {
    let observations: Vec<CorObservation> = measurements
        .iter()
        .map(|c| CorObservation {
            surface: c.surface.clone(),
            angle: c.angle_deg,
            v_in_n: c.v_in_m_s[1].value.abs(),
            cor: c.cor.value,
        })
        .collect();
    let data = Dataset::from_cor(&observations);
    match &data {
        Ok(d) => (
            ancova(d, &PAPER_TERMS).into(),
            ancova_inference(d, &PAPER_TERMS, 0.05).into(),
        ),
        Err(e) => (Section::unavailable(e.to_string()), Section::unavailable(e.to_string())),
    }
}

/// The "fitted" parameters: k and b per surface and one μ.
fn sample_parameters() -> Vec<FitParameter> {
    let mut parameters = Vec::new();
    for &(s, _, _, k, _) in &SURFACES {
        parameters.push(FitParameter {
            name: format!("{s}:spring.k"),
            value: k,
            std_error: Some(k * 0.012),
            interval: Some([k * (1.0 - 0.024), k * (1.0 + 0.024)]),
            unit: "N/m".into(),
            at_bound: false,
        });
    }
    for &(s, _, _, _, b) in &SURFACES {
        parameters.push(FitParameter {
            name: format!("{s}:damping.b"),
            value: b,
            std_error: Some(0.4),
            interval: Some([b - 0.8, b + 0.8]),
            unit: "N·s/m".into(),
            at_bound: false,
        });
    }
    parameters.push(FitParameter {
        name: "coulomb.mu".into(),
        value: 0.52,
        std_error: Some(0.01),
        interval: Some([0.50, 0.54]),
        unit: String::new(),
        at_bound: false,
    });
    parameters
}

/// The mean absolute COR error per surface from the shots' errors, %.
fn sample_surface_errors(errors: &[(String, f64)]) -> Vec<SurfaceError> {
    SURFACES
        .iter()
        .map(|&(s, ..)| {
            let e: Vec<f64> = errors.iter().filter(|x| x.0 == s).map(|x| x.1).collect();
            SurfaceError {
                surface: s.into(),
                shots: e.len(),
                mean_abs_error_pct: e.iter().sum::<f64>() / e.len().max(1) as f64,
            }
        })
        .collect()
}

/// A signature whose systematic part falls with the phase, normal above tangential, scaled by `scale`.
fn sample_signature(scale: f64) -> Vec<SignatureRow> {
    let mut rows = Vec::new();
    for (k, phase) in Phase::ALL.iter().enumerate() {
        for normal in [true, false] {
            let sys = scale * (if normal { 60e-6 } else { 15e-6 }) / (1.0 + k as f64);
            rows.push(SignatureRow {
                phase: *phase,
                normal,
                rms_m: (sys * sys + SIGMA * SIGMA).sqrt(),
                systematic_m: sys,
                chi2_share: 0.0,
            });
        }
    }
    let total: f64 = rows.iter().map(|r| r.rms_m * r.rms_m).sum();
    for r in &mut rows {
        r.chi2_share = r.rms_m * r.rms_m / total;
    }
    rows.sort_by(|a, b| b.chi2_share.total_cmp(&a.chi2_share));
    rows
}

/// A diagnosis that names `hunt_crossley`, with four other candidates and two model versions.
fn sample_diagnosis(rms_all: f64, rms_after: f64, verdict: &str) -> DiagnosisSection {
    let history = vec![
        ModelVersion {
            version: 1,
            model: "paper (spring + damping + coulomb)".into(),
            created: "2024-05-03 14:02".into(),
            rms_m: Some(rms_all),
            chi2_red: Some((rms_all / SIGMA).powi(2)),
        },
        ModelVersion {
            version: 2,
            model: "paper + hunt_crossley".into(),
            created: "2024-05-03 14:31".into(),
            rms_m: Some(rms_after),
            chi2_red: Some((rms_after / SIGMA).powi(2)),
        },
    ];
    DiagnosisSection {
        verdict_kind: VerdictKind::MissingEffect,
        headline: format!(
            "`hunt_crossley` is missing: held-out error {:.1} → {:.1} µm",
            rms_all * 1e6,
            rms_after * 1e6
        ),
        verdict_text: verdict.to_string(),
        evidence: vec![
            "COR falls with impact speed, slope −0.033 per m/s, p < 0.001; the model predicts none.".into(),
            "72% of χ² is in flight out, normal component: the rebound height is wrong, not the contact shape.".into(),
            "The residual does not trend with the angle (p = 0.41) or the surface (p = 0.22).".into(),
        ],
        signature: sample_signature(1.0),
        error_metric: "position RMS of all frames (x and y), held-out by cross-validation across shots".into(),
        candidates: vec![
            Candidate {
                effect: "hunt_crossley".into(),
                error_before: 4.12e-5,
                error_after: 0.83e-5,
                delta_bic: -412.0,
                heldout_before: Some(4.31e-5),
                heldout_after: Some(0.91e-5),
            },
            Candidate {
                effect: "hertz".into(),
                error_before: 4.12e-5,
                error_after: 3.71e-5,
                delta_bic: -35.2,
                heldout_before: Some(4.31e-5),
                heldout_after: Some(3.98e-5),
            },
            Candidate {
                effect: "restitution_damping".into(),
                error_before: 4.12e-5,
                error_after: 4.02e-5,
                delta_bic: -3.1,
                heldout_before: Some(4.31e-5),
                heldout_after: Some(4.29e-5),
            },
            Candidate {
                effect: "plastic_dent".into(),
                error_before: 4.12e-5,
                error_after: 4.09e-5,
                delta_bic: 6.5,
                heldout_before: Some(4.31e-5),
                heldout_after: Some(4.33e-5),
            },
            Candidate {
                effect: "air_drag".into(),
                error_before: 4.12e-5,
                error_after: 4.12e-5,
                delta_bic: 9.8,
                heldout_before: Some(4.31e-5),
                heldout_after: None,
            },
        ],
        model_history: history,
    }
}

/// Where the sample came from.
fn sample_session(shots: usize) -> SessionInfo {
    SessionInfo {
        path: "sessions/synthetic-2024-05-03".into(),
        description: "Synthetic session: ball dropped from 0.3–0.9 m onto green clay and two court line tapes \
                      at 0–22.5°, filmed at 10,000 fps."
            .into(),
        shots,
        surfaces: SURFACES.iter().map(|s| s.0.to_string()).collect(),
        generated_by: format!("bouncelab-report {}", env!("CARGO_PKG_VERSION")),
        generated_at: None,
        metadata: vec![
            ("Ball".into(), "diameter 0.067 m, mass 0.0567 kg".into()),
            ("Camera".into(), "10,000 fps, 512 × 512 px, down-slope +x".into()),
        ],
    }
}

/// [`sample_report_with`] eight shots per surface (24 shots), seed 7; built once per process (its
/// statistics take a moment), cloned on each call.
pub fn sample_report() -> Report {
    static SAMPLE: std::sync::OnceLock<Report> = std::sync::OnceLock::new();
    SAMPLE.get_or_init(|| sample_report_with(8, 7)).clone()
}

/// The markup the brief's escaping test names: a surface that would run script if not escaped.
pub const SCRIPT_SURFACE: &str = "<script>alert(1)</script>";
/// A clip name with every character that must be escaped in an attribute.
pub const AMP_CLIP: &str = "a&b\"<x>";
/// A surface whose markup would log to the browser console if it were not escaped.
pub const CONSOLE_SURFACE: &str = "<img src=x onerror=\"console.error('xss')\">";

/// A report to break the renderer: every text field carries markup, numbers include NaN, infinities,
/// ±1e308 and subnormals, series are empty, single points or constant, a clip name repeats, and the
/// statistics' vectors disagree in length.
pub fn hostile_report() -> Report {
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    Report {
        title: "<b>title</b> & co".into(),
        session: SessionInfo {
            path: "C:\\data\\<session>".into(),
            description: "<i>desc</i>\u{0}".into(),
            shots: 7,
            surfaces: vec![SCRIPT_SURFACE.into(), SCRIPT_SURFACE.into()],
            generated_by: "<gen>".into(),
            generated_at: Some("<now>".into()),
            metadata: vec![("<k>".into(), "<v>".into())],
        },
        shots: hostile_shots(),
        measurements: hostile_measurements(),
        model_curves: hostile_curves(),
        contact_force: Section::Available(ContactForce {
            clip: AMP_CLIP.into(),
            surface: SCRIPT_SURFACE.into(),
            angle_deg: nan,
            v_in_n_m_s: inf,
            why: "<why>".into(),
            samples: vec![
                ForceSample {
                    t_s: nan,
                    delta_m: 0.0,
                    force_n: inf,
                },
                ForceSample::default(),
            ],
        }),
        ancova: Section::Available(hostile_ancova()),
        inference: Section::Available(hostile_inference()),
        fit: Section::Available(hostile_fit()),
        diagnosis: Section::Available(hostile_diagnosis()),
        model_change: Section::Available(hostile_model_change()),
        warnings: vec![SCRIPT_SURFACE.into(), String::new()],
        timings: vec![("<stage>".into(), nan), ("b".into(), inf), ("c".into(), -1.0)],
    }
}

/// Shots with non-finite, huge, single, constant and empty series; a clip name repeats.
fn hostile_shots() -> Vec<ShotPlot> {
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    let m = |t: f64, x: f64, y: f64| MeasuredPoint {
        t_s: t,
        x_m: x,
        y_m: y,
        sigma_m: 1e-4,
    };
    let mp = |t: f64, x: f64, y: f64| ModelPoint { t_s: t, x_m: x, y_m: y };
    let r = |t: f64, dx: f64, dy: f64| Residual {
        t_s: t,
        dx_m: dx,
        dy_m: dy,
    };
    let span = |phase, t0_s, t1_s| PhaseSpan { phase, t0_s, t1_s };
    let shot = |clip: &str, surface: &str| ShotPlot {
        clip: clip.into(),
        surface: surface.into(),
        notes: vec!["<b>note</b> & \"quote\"".into()],
        ..Default::default()
    };
    vec![
        ShotPlot {
            angle_deg: nan,
            drop_height_m: Some(inf),
            measured: vec![
                m(0.0, 0.0, 0.1),
                m(nan, 0.0, 0.1),
                m(1e-3, inf, -inf),
                m(2e-3, 0.01, nan),
                m(3e-3, 0.02, 0.05),
            ],
            model: vec![mp(0.0, 0.0, 0.1), mp(nan, nan, nan), mp(3e-3, 0.02, 0.05)],
            phases: vec![
                span(Phase::FlightIn, 0.0, nan),
                span(Phase::Compression, inf, -inf),
                span(Phase::FlightOut, 2e-3, 1.0),
            ],
            residuals: vec![r(0.0, 0.0, 1e-4), r(1e-3, inf, nan), r(2e-3, -1e-4, 2e-4)],
            rms_m: None,
            chi2_red: Some(nan),
            ..shot(AMP_CLIP, SCRIPT_SURFACE)
        },
        ShotPlot {
            measured: vec![m(0.01, 0.0, 0.0)],
            model: vec![mp(0.01, 0.0, 0.0)],
            residuals: vec![r(0.01, 0.0, 0.0)],
            phases: vec![span(Phase::Restitution, 0.01, 0.01)],
            ..shot("single", CONSOLE_SURFACE)
        },
        ShotPlot {
            angle_deg: 15.0,
            measured: (0..50).map(|i| m(0.5, 0.25, 0.25 + 0.0 * i as f64)).collect(),
            model: (0..50).map(|_| mp(0.5, 0.25, 0.25)).collect(),
            residuals: (0..50).map(|_| r(0.5, 0.0, 0.0)).collect(),
            rms_m: Some(0.0),
            ..shot("flat", "plain")
        },
        shot("empty", "plain"),
        ShotPlot {
            measured: vec![m(0.0, 1.0, 2.0)],
            ..shot(AMP_CLIP, "plain")
        },
        ShotPlot {
            measured: vec![
                m(-1e308, 1e308, -1e308),
                m(1e308, -1e308, 1e308),
                m(5e-324, 5e-324, 5e-324),
            ],
            model: vec![mp(f64::MIN, f64::MAX, 0.0), mp(f64::MAX, f64::MIN, 0.0)],
            residuals: vec![r(-1e308, 1e308, -1e308), r(1e308, f64::MAX, f64::MIN)],
            phases: vec![span(Phase::Compression, -1e308, 1e308)],
            rms_m: Some(inf),
            ..shot("huge", "plain")
        },
    ]
}

/// Measurements with NaN, infinite and missing errors, some past ±1e308.
fn hostile_measurements() -> Vec<ShotMeasurement> {
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    let q = |v: f64, se: Option<f64>| Measured { value: v, se };
    let cp = |clip: &str, surface: &str, angle_deg: f64, v_in_n: f64, cor: f64, se: Option<f64>| ShotMeasurement {
        clip: clip.into(),
        surface: surface.into(),
        angle_deg,
        drop_height_m: Some(nan),
        v_in_m_s: [q(nan, se), q(v_in_n, se)],
        v_out_m_s: [q(inf, None), q(-inf, se)],
        cor: q(cor, se),
        mu_eff: q(-0.0, Some(0.0)),
        contact_time_s: q(cor, Some(1e308)),
        delta_max_m: q(5e-324, se),
        spin_in_rad_s: Some(q(nan, None)),
        spin_out_rad_s: None,
        peak_deceleration_track_m_s2: Some(q(inf, Some(nan))),
        peak_force_track_n: Some(q(-inf, None)),
        model: Some(ShotPrediction {
            cor: nan,
            peak_force_n: inf,
            ..Default::default()
        }),
    };
    vec![
        cp(AMP_CLIP, SCRIPT_SURFACE, 0.0, -2.0, 0.8, Some(0.01)),
        cp("single", CONSOLE_SURFACE, nan, inf, nan, Some(nan)),
        cp("flat", "plain", 15.0, -3.0, 0.7, None),
        cp("flat2", "plain", 15.0, -3.0, 0.7, None),
        cp("flat3", "plain", 15.0, -3.0, 0.7, Some(inf)),
        cp("huge", "plain", 1e308, -1e308, 1e308, Some(1e308)),
    ]
}

/// A curve with a non-finite angle and speed, and an empty one.
fn hostile_curves() -> Vec<ModelCurve> {
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    vec![
        ModelCurve {
            surface: SCRIPT_SURFACE.into(),
            angle_deg: nan,
            points: vec![
                CurvePoint {
                    v_in_n_m_s: nan,
                    prediction: ShotPrediction {
                        cor: inf,
                        ..Default::default()
                    },
                },
                CurvePoint {
                    v_in_n_m_s: 1.0,
                    prediction: ShotPrediction::default(),
                },
            ],
        },
        ModelCurve {
            surface: "plain".into(),
            angle_deg: 1e308,
            points: Vec::new(),
        },
    ]
}

/// An ANCOVA whose tables hold NaN and infinities and whose vectors disagree in length.
fn hostile_ancova() -> bouncelab_stats::Ancova {
    use bouncelab_stats::{AnovaRow, AnovaTable, AnovaType, Diagnostics, LinearFit, NormalPlotPoint};
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    let row = |source: &str, ss: f64| AnovaRow {
        source: source.into(),
        ss,
        df: 1,
        ms: ss,
        f: Some(nan),
        p: Some(inf),
    };
    let table = |kind| AnovaTable {
        kind,
        terms: vec![row(SCRIPT_SURFACE, nan), row("surface", inf)],
        error: AnovaRow {
            f: None,
            p: None,
            ..row("Error", 0.0)
        },
        total: AnovaRow {
            f: None,
            p: None,
            ..row("Total", -inf)
        },
    };
    bouncelab_stats::Ancova {
        type1: table(AnovaType::TypeI),
        type2: table(AnovaType::TypeII),
        fit: LinearFit {
            terms: vec![SCRIPT_SURFACE.into()],
            coefficient_names: vec![AMP_CLIP.into(), "b".into()],
            coefficients: vec![nan],
            fitted: vec![nan, 0.5, inf],
            residuals: vec![0.0; 3],
            leverage: vec![],
            rss: nan,
            df_resid: 0,
            n: 3,
        },
        diagnostics: Diagnostics {
            fitted: vec![nan, 0.5, inf, 0.7, 0.7, 0.7],
            residuals: vec![0.0; 2],
            leverage: vec![],
            studentized_internal: vec![nan],
            studentized_external: vec![nan, 1.0, -inf, 2.5, 0.0, 0.0],
            normal_plot: vec![
                NormalPlotPoint {
                    observation: 99,
                    residual: nan,
                    probability: 0.5,
                    normal_quantile: 0.0,
                },
                NormalPlotPoint {
                    observation: 0,
                    residual: 1.0,
                    probability: 0.1,
                    normal_quantile: inf,
                },
                NormalPlotPoint {
                    observation: 1,
                    residual: 1.0,
                    probability: 0.2,
                    normal_quantile: -1.0,
                },
                NormalPlotPoint {
                    observation: 2,
                    residual: 1.0,
                    probability: 0.3,
                    normal_quantile: 1.0,
                },
                NormalPlotPoint {
                    observation: 3,
                    residual: 1.0,
                    probability: 0.4,
                    normal_quantile: 2.0,
                },
            ],
            residual_skewness: nan,
            residual_kurtosis: inf,
        },
    }
}

/// Inference with impossible α and p-values, markup in every name, a test not run.
fn hostile_inference() -> AncovaInference {
    use bouncelab_stats::{Coefficient, CoefficientTable, CovariateCurvature, FTest, ResidualTests, TestOutcome};
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    let ftest = |f: f64, p: f64| {
        TestOutcome::Ran(FTest {
            added: AMP_CLIP.into(),
            f,
            df_num: 1,
            df_den: 0,
            p,
        })
    };
    AncovaInference {
        coefficients: CoefficientTable {
            alpha: nan,
            df: 0,
            t_crit: inf,
            sigma: nan,
            rows: vec![Coefficient {
                name: SCRIPT_SURFACE.into(),
                estimate: nan,
                se: inf,
                t: -inf,
                p: nan,
                lower: -inf,
                upper: inf,
            }],
        },
        marginal_means: hostile_marginal_means(),
        residual_tests: ResidualTests {
            alpha: nan,
            reset: ftest(nan, inf),
            quadratic: vec![CovariateCurvature {
                covariate: SCRIPT_SURFACE.into(),
                test: ftest(1e308, 0.0),
            }],
            normality: TestOutcome::NotRun {
                reason: "<too few>".into(),
            },
        },
    }
}

/// Adjusted means with an α of 2, negative SEs and markup in every level, and a factor with no levels.
fn hostile_marginal_means() -> Vec<bouncelab_stats::MarginalMeans> {
    use bouncelab_stats::{GridValue, MarginalComparison, MarginalMean, MarginalMeans};
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    vec![
        MarginalMeans {
            factor: "surface".into(),
            alpha: 2.0,
            df: 0,
            mse: inf,
            t_crit: nan,
            q_crit: nan,
            covariates_at: vec![GridValue {
                name: AMP_CLIP.into(),
                value: nan,
            }],
            averaged_over: vec![CONSOLE_SURFACE.into()],
            means: vec![MarginalMean {
                level: SCRIPT_SURFACE.into(),
                n: 1,
                raw_mean: nan,
                estimate: inf,
                se: -1.0,
                lower: nan,
                upper: inf,
            }],
            pairs: vec![
                MarginalComparison {
                    level1: SCRIPT_SURFACE.into(),
                    level2: AMP_CLIP.into(),
                    estimate: nan,
                    se: inf,
                    t: nan,
                    p: -1.0,
                    p_tukey: 2.0,
                    p_holm: nan,
                    lower: -inf,
                    upper: inf,
                    reject_tukey: true,
                    reject_holm: false,
                },
                MarginalComparison {
                    level1: "x".into(),
                    level2: "y".into(),
                    estimate: 0.0,
                    se: 0.0,
                    t: 0.0,
                    p: 1.0,
                    p_tukey: 1.0,
                    p_holm: 1.0,
                    lower: 0.0,
                    upper: 0.0,
                    reject_tukey: false,
                    reject_holm: false,
                },
            ],
        },
        MarginalMeans {
            factor: "angle".into(),
            alpha: 0.05,
            df: 1,
            mse: 0.0,
            t_crit: 1.0,
            q_crit: 1.0,
            covariates_at: Vec::new(),
            averaged_over: Vec::new(),
            means: Vec::new(),
            pairs: Vec::new(),
        },
    ]
}

/// A fit whose every number is odd and every name markup.
fn hostile_fit() -> FitSummary {
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    FitSummary {
        model_name: "<model>".into(),
        parameters: vec![FitParameter {
            name: AMP_CLIP.into(),
            value: nan,
            std_error: Some(inf),
            interval: Some([-inf, nan]),
            unit: "<unit>".into(),
            at_bound: true,
        }],
        confidence: nan,
        reduced_chi2: Some(inf),
        dof: Some(0),
        rms_m: Some(nan),
        termination: "<stop>".into(),
        mean_abs_error_pct: Some(nan),
        by_surface: vec![SurfaceError {
            surface: SCRIPT_SURFACE.into(),
            shots: 0,
            mean_abs_error_pct: nan,
        }],
        oblique: vec![
            ObliqueRow {
                clip: AMP_CLIP.into(),
                surface: SCRIPT_SURFACE.into(),
                angle_deg: nan,
                v_out_measured: [nan, inf],
                v_out_predicted: [1.0, 1.0],
                error_pct: [nan, -inf],
            },
            ObliqueRow {
                clip: "one".into(),
                v_out_measured: [1.0, 1.0],
                v_out_predicted: [1.0, 1.0],
                ..Default::default()
            },
        ],
    }
}

/// A diagnosis with markup in every text and odd numbers in its rows.
fn hostile_diagnosis() -> DiagnosisSection {
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    DiagnosisSection {
        verdict_kind: VerdictKind::NoCandidateExplains,
        headline: "<headline>".into(),
        verdict_text: "<verdict>".into(),
        evidence: vec!["<evidence> & more".into()],
        signature: vec![SignatureRow {
            phase: Phase::FlightOut,
            normal: true,
            rms_m: nan,
            systematic_m: inf,
            chi2_share: -1.0,
        }],
        error_metric: "<metric>".into(),
        candidates: vec![Candidate {
            effect: SCRIPT_SURFACE.into(),
            error_before: 0.0,
            error_after: nan,
            delta_bic: -inf,
            heldout_before: None,
            heldout_after: Some(nan),
        }],
        model_history: vec![ModelVersion {
            version: u32::MAX,
            model: "<m>".into(),
            created: "<c>".into(),
            rms_m: Some(nan),
            chi2_red: None,
        }],
    }
}

/// A model change with odd errors and an empty signature after.
fn hostile_model_change() -> ModelChange {
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    ModelChange {
        model_before: "<before>".into(),
        model_after: "<after>".into(),
        effects_added: vec![SCRIPT_SURFACE.into()],
        effects_removed: vec![AMP_CLIP.into()],
        verdict_before: Some(EarlierVerdict {
            kind: VerdictKind::Ambiguous,
            text: "<earlier>".into(),
        }),
        signature_before: vec![SignatureRow {
            phase: Phase::Compression,
            normal: false,
            rms_m: inf,
            systematic_m: nan,
            chi2_share: nan,
        }],
        signature_after: Vec::new(),
        shots: vec![
            ShotBeforeAfter {
                clip: AMP_CLIP.into(),
                surface: SCRIPT_SURFACE.into(),
                rms_before_m: nan,
                rms_after_m: inf,
            },
            ShotBeforeAfter {
                clip: "flat".into(),
                surface: "plain".into(),
                rms_before_m: 0.0,
                rms_after_m: 0.0,
            },
        ],
        total_rms_before_m: nan,
        total_rms_after_m: 0.0,
        reduced_chi2_before: inf,
        reduced_chi2_after: -1.0,
    }
}
