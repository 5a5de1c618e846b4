//! The report's data, filled from the analysis (the report crate takes plain data and knows no pipeline type).

use crate::{Analysis, BeforeAfter};
use bouncelab_compare::{ImpactPhase, ShotComparison};
use bouncelab_diagnose::{Diagnosis, VerdictKind};
use bouncelab_report as r;

/// Everything `report.html` shows about `a`.
pub(crate) fn build(a: &Analysis, description: Option<&str>, warnings: &[String]) -> r::Report {
    let mut surfaces: Vec<String> = a.shots.iter().map(|s| s.surface.clone()).collect();
    surfaces.sort();
    surfaces.dedup();
    let mut notes: Vec<String> = warnings.to_vec();
    notes.extend(a.measure.failed.iter().map(|(c, m)| format!("{c}: not measured: {m}")));
    notes.extend(a.excluded.iter().map(|(c, m)| format!("{c}: left out of the fit: {m}")));
    let session_name = a
        .session_dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| a.session_dir.display().to_string());
    r::Report {
        title: format!("bouncelab report: {session_name}"),
        session: r::SessionInfo {
            path: a.session_dir.display().to_string(),
            description: description.unwrap_or_default().to_string(),
            shots: a.shots_listed,
            surfaces,
            generated_by: format!("bouncelab {}", env!("CARGO_PKG_VERSION")),
            generated_at: a.fitted_at.clone(),
            metadata: vec![
                ("model".into(), a.model_origin.clone()),
                ("shots measured".into(), a.shots.len().to_string()),
                ("shots fitted".into(), a.comparison.shots.len().to_string()),
            ],
        },
        shots: a.comparison.shots.iter().map(|c| shot_plot(a, c)).collect(),
        cor_points: a
            .shots
            .iter()
            .map(|s| r::CorPoint {
                clip: s.clip.clone(),
                surface: s.surface.clone(),
                angle_deg: s.angle_deg,
                v_in_n: s.estimate.v_in[1].value.abs(),
                v_in_n_se: Some(s.estimate.v_in[1].se),
                cor: s.estimate.cor.value,
                cor_se: Some(s.estimate.cor.se),
            })
            .collect(),
        ancova: match &a.stats {
            Ok(s) => r::Section::Available(s.ancova.clone()),
            Err(e) => r::Section::unavailable(e.clone()),
        },
        tukey: match &a.stats {
            Ok(s) => match &s.tukey {
                Some(t) => r::Section::Available(t.clone()),
                None => r::Section::unavailable("one surface only: nothing to compare"),
            },
            Err(e) => r::Section::unavailable(e.clone()),
        },
        fit: r::Section::Available(fit_summary(a)),
        diagnosis: match &a.diagnosis {
            Ok(d) => r::Section::Available(diagnosis(d, a.before.as_ref(), a)),
            Err(why) => r::Section::unavailable(why.clone()),
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
    let fit = a.fit.shots.iter().find(|s| s.name == c.shot);
    let mut notes = data.map(|s| s.estimate.notes.clone()).unwrap_or_default();
    let level = match (
        crate::fitted_surface_level(&a.fit, &c.surface),
        fit.and_then(|f| f.surface_offset_m),
    ) {
        (None, None) => None,
        (a, b) => Some(a.unwrap_or(0.0) + b.unwrap_or(0.0)),
    };
    if let Some(level) = level {
        notes.push(format!(
            "fitted surface level {:+.1} µm: the surface line found in the image lies that far above the plane the ball touches",
            level * 1e6
        ));
    }
    r::ShotPlot {
        clip: c.shot.clone(),
        surface: c.surface.clone(),
        angle_deg: c.incline_deg,
        drop_height_m: c.drop_height_m,
        measured: frames
            .iter()
            .map(|f| r::MeasuredPoint {
                t_s: f.t_s,
                x_m: f.x_m,
                y_m: f.y_m,
                sigma_m: f.sigma_m,
            })
            .collect(),
        model,
        phases,
        residuals: c
            .residuals
            .iter()
            .map(|p| r::Residual {
                t_s: p.t_s,
                dx_m: p.dx_m,
                dy_m: p.dy_m,
            })
            .collect(),
        rms_m: Some(c.rms_m),
        chi2_red: (c.n > 0).then(|| c.chi2 / c.n as f64),
        notes,
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
        parameters: f
            .parameters
            .iter()
            .map(|p| r::FitParameter {
                name: p.name.clone(),
                value: p.value,
                std_error: p.std_error,
                interval: p.interval,
                unit: unit(&p.effect, &p.param),
                at_bound: p.at_bound,
            })
            .collect(),
        confidence: f.confidence,
        reduced_chi2: Some(f.reduced_chi2),
        rms_m: Some(f.rms_m),
        termination: f.termination.to_string(),
        mean_abs_error_pct: f.mean_abs_cor_error_pct,
        by_surface: f
            .cor_error_by_surface
            .iter()
            .map(|s| r::SurfaceError {
                surface: s.surface.clone(),
                shots: s.shots,
                mean_abs_error_pct: s.mean_abs_error_pct,
            })
            .collect(),
        oblique: f
            .oblique
            .iter()
            .map(|o| r::ObliqueRow {
                clip: o.shot.clone(),
                surface: o.surface.clone(),
                angle_deg: o.incline_deg,
                v_out_measured: o.v_out_measured,
                v_out_predicted: o.v_out_predicted,
                error_pct: o.error_pct,
            })
            .collect(),
    }
}

fn diagnosis(d: &Diagnosis, before: Option<&BeforeAfter>, a: &Analysis) -> r::DiagnosisSection {
    let kind = match d.verdict.kind {
        VerdictKind::MissingEffect => r::VerdictKind::MissingEffect,
        VerdictKind::NoMissingEffect => r::VerdictKind::NoMissingEffect,
        VerdictKind::Ambiguous => r::VerdictKind::Ambiguous,
        VerdictKind::NoneExplains => r::VerdictKind::NoCandidateExplains,
    };
    let mut evidence: Vec<String> = d.signature.sentences.clone();
    for reason in &d.baseline.misfit_reasons {
        if !evidence.contains(reason) {
            evidence.push(reason.clone());
        }
    }
    let surface_of = |clip: &str| {
        a.shots
            .iter()
            .find(|s| s.clip == clip)
            .map(|s| s.surface.clone())
            .unwrap_or_default()
    };
    r::DiagnosisSection {
        verdict_kind: kind,
        verdict_text: d.verdict.sentence.clone(),
        evidence,
        error_metric: "position RMS of all frames (x and y), held-out by cross-validation across shots".into(),
        candidates: d
            .candidates
            .iter()
            .map(|c| r::Candidate {
                effect: c.effect.clone(),
                error_before: c.error_before,
                error_after: c.evidence.as_ref().map_or(f64::NAN, |e| e.error_after),
                delta_bic: c.evidence.as_ref().map_or(f64::NAN, |e| e.delta_bic),
                heldout_before: Some(c.heldout_error_before),
                heldout_after: c.evidence.as_ref().map(|e| e.heldout_error_after),
            })
            .collect(),
        model_before: before.map(|b| b.before_model.clone()).unwrap_or_default(),
        model_after: a.model_origin.clone(),
        before_after: before
            .map(|b| {
                b.shots
                    .iter()
                    .map(|(clip, x, y)| r::ShotBeforeAfter {
                        clip: clip.clone(),
                        surface: surface_of(clip),
                        rms_before_m: *x,
                        rms_after_m: *y,
                    })
                    .collect()
            })
            .unwrap_or_default(),
        total_rms_before_m: before.map(|b| b.total_rms_m.0),
        total_rms_after_m: before.map(|b| b.total_rms_m.1),
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

/// Writes `report.html` into `dir` and returns its path.
pub(crate) fn write(
    dir: &std::path::Path,
    a: &Analysis,
    description: Option<&str>,
    warnings: &[String],
) -> Result<std::path::PathBuf, crate::AnalyzeError> {
    let path = dir.join("report.html");
    bouncelab_report::write_report(&path, &build(a, description, warnings))?;
    Ok(path)
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
    let name = session
        .dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| session.dir.display().to_string());
    let none = "no shot could be measured (see the notes for each shot's reason)";
    let report = r::Report {
        title: format!("bouncelab report: {name}"),
        session: r::SessionInfo {
            path: session.dir.display().to_string(),
            description: String::new(),
            shots: session.clips.len(),
            surfaces: Vec::new(),
            generated_by: format!("bouncelab {}", env!("CARGO_PKG_VERSION")),
            generated_at: None,
            metadata: vec![("shots measured".into(), "0".into())],
        },
        shots: Vec::new(),
        cor_points: Vec::new(),
        ancova: r::Section::unavailable(none),
        tukey: r::Section::unavailable(none),
        fit: r::Section::unavailable(none),
        diagnosis: r::Section::unavailable(none),
        warnings: notes,
        timings: Vec::new(),
    };
    let path = dir.join("report.html");
    bouncelab_report::write_report(&path, &report)?;
    Ok(path)
}
