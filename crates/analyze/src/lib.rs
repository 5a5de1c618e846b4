//! The pipeline over a session folder: frames → track → estimate → fit → compare → diagnose → stats → report,
//! incremental through the results store.
//!
//! This crate owns no science: it runs each stage's library in order and writes the files of `docs/outputs.md`. Its one
//! design choice is that the SQLite store sits between measuring and everything after it: shots are tracked in
//! parallel and each one is committed on its own, the later stages read every shot back from the store, so an
//! unchanged shot is never tracked again and a run killed at any instant resumes where it stopped. Progress is
//! reported to a [`Progress`] (the CLI draws bars on a terminal, plain lines otherwise).

mod error;
mod measure;
mod outputs;
mod report;
mod shots;

pub use error::AnalyzeError;
pub use measure::{MeasureSummary, measure_session};
pub use outputs::{
    COMPARISON_COLUMNS, CURVE_COLUMNS, ESTIMATE_COLUMNS, FORCE_COLUMNS, PREDICTION_COLUMNS, SURFACE_COLUMNS,
    TrajectoryFiles, trajectory_files, write_comparison_csv, write_estimates_csv,
};
pub use report::{track_peak_deceleration, verdict_headline};
pub use shots::{ShotData, load_failed_tracks, load_shots, measured_shot};

use bouncelab_compare::{Comparison, FailureReport, ShotExtras, SpinFrame};
use bouncelab_diagnose::{Diagnosis, SearchOptions, find_missing_effect_with};
use bouncelab_fit::{FitOptions, FitResult, Problem, fit_problem};
use bouncelab_frames::{ClipOptions, Session};
use bouncelab_model::{EffectKind, EffectSetting, ModelSpec, ParamRef, ParamSetting};
use bouncelab_stats::{
    Ancova, AncovaInference, CorObservation, Dataset, PAPER_TERMS, TukeyHsd, ancova, ancova_inference, tukey_hsd_factor,
};
use bouncelab_store::{ClipFingerprint, Fingerprint, FitRecord, ModelHistoryRow, ModelVersionRecord, Store};
use std::path::{Path, PathBuf};

/// A stage of the analysis, for progress reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Tracking and estimating the shots.
    Track,
    /// Fitting the model.
    Fit,
    /// Comparing the model with every shot.
    Compare,
    /// Searching for the missing effect.
    Diagnose,
    /// ANCOVA and pairwise comparisons.
    Stats,
    /// Writing the files and the report.
    Report,
}

impl Stage {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Track => "track",
            Stage::Fit => "fit",
            Stage::Compare => "compare",
            Stage::Diagnose => "diagnose",
            Stage::Stats => "stats",
            Stage::Report => "report",
        }
    }
}

/// Where progress goes. Every method has a no-op default; calls may come from several threads.
pub trait Progress: Sync {
    /// A stage starts with `total` units of work (shots, candidates …).
    fn start(&self, _stage: Stage, _total: u64) {}
    /// `n` more units of the stage are done.
    fn advance(&self, _stage: Stage, _n: u64) {}
    /// A solver of the stage finished iteration `iteration` (0 is the starting point) at reduced χ²
    /// `chi2_red` (χ²/ν, the fit's definition); calls come from the thread that runs the stage.
    fn iteration(&self, _stage: Stage, _iteration: usize, _chi2_red: f64) {}
    /// What the stage works on now, in a few words (e.g. "+ hertz": fitting the model with `hertz` added).
    fn doing(&self, _stage: Stage, _what: &str) {}
    /// The stage is done; `summary` says what it did in one line.
    fn finish(&self, _stage: Stage, _summary: &str) {}
    /// Something a person should know (a shot that failed, a surface the model did not know …).
    fn note(&self, _message: &str) {}
}

/// Progress that goes nowhere.
pub struct Silent;
impl Progress for Silent {}

/// Settings of [`analyze`].
#[derive(Debug, Clone, PartialEq)]
pub struct AnalyzeOptions {
    /// Output folder (created).
    pub out_dir: PathBuf,
    /// The SQLite store (created if absent); results accumulate there across sessions.
    pub store_path: PathBuf,
    /// The model file; `None` uses the paper's model.
    pub model_path: Option<PathBuf>,
    /// How a clip's frames are fingerprinted to decide whether to track it again.
    pub fingerprint: ClipFingerprint,
    /// Run the missing-effect search (the slowest stage after tracking).
    pub diagnose: bool,
    /// Command-line overrides (fps, scale, diameter, region of interest, contact line) applied to every
    /// clip; each beats `clip.toml`, the camera header and `session.toml`.
    pub clip_options: ClipOptions,
}

/// What [`analyze`] did, for the summary a person reads.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The session folder.
    pub session_dir: PathBuf,
    /// Shots listed in `clips.csv`.
    pub shots_listed: usize,
    /// The measuring stage.
    pub measure: MeasureSummary,
    /// When the fit was stored (ISO 8601, UTC).
    pub fitted_at: Option<String>,
    /// The model fitted (its origin).
    pub model_origin: String,
    /// The model file as fitted: the session's ball, a table for every surface, the surface level.
    pub model: ModelSpec,
    /// The store's id of the model version fitted.
    pub model_version: i64,
    /// The fit.
    pub fit: FitResult,
    /// Every measured shot (conditions, track, estimate).
    pub shots: Vec<ShotData>,
    /// Shots left out of the fit with the reason (see [`suspect_tracks`]).
    pub excluded: Vec<(String, String)>,
    /// This model's errors against the previous model version fitted to the same session, if any.
    pub before: Option<BeforeAfter>,
    /// The diagnosis of that previous model version, when this output folder kept it.
    pub previous_diagnosis: Option<Diagnosis>,
    /// Every model version with its latest fit on this session (including this one).
    pub history: Vec<ModelHistoryRow>,
    /// The fitted model against every shot.
    pub comparison: Comparison,
    /// Where the fitted model fails, in sentences.
    pub failure: FailureReport,
    /// Which effect is missing, or why the search did not run.
    pub diagnosis: Result<Diagnosis, String>,
    /// The session's statistics, or why they could not be computed.
    pub stats: Result<SessionStats, String>,
    /// Files written.
    pub outputs: Vec<PathBuf>,
    /// Seconds per stage.
    pub timings: Vec<(Stage, f64)>,
}

/// The model for a session: `path` or the paper's, with the session's ball, and a surface table for every
/// surface of the session that the file does not list (copying the file's own values, so each surface gets its
/// own fitted parameters when any are free).
pub fn session_model(
    path: Option<&Path>,
    session: &Session,
    progress: &dyn Progress,
) -> Result<ModelSpec, AnalyzeError> {
    let mut spec = match path {
        Some(p) => ModelSpec::load(p)?,
        None => ModelSpec::paper(),
    };
    let radius = session.ball.diameter_m / 2.0;
    if (spec.ball.radius_m - radius).abs() > 1e-9 || (spec.ball.mass_kg - session.ball.mass_kg).abs() > 1e-12 {
        progress.note(&format!(
            "the session's ball (diameter {} m, mass {} kg) replaces the model file's (radius {} m, mass {} kg)",
            session.ball.diameter_m, session.ball.mass_kg, spec.ball.radius_m, spec.ball.mass_kg
        ));
        spec.ball.radius_m = radius;
        spec.ball.mass_kg = session.ball.mass_kg;
    }
    add_surface_level(&mut spec);
    if !spec.surfaces.is_empty() {
        let base = spec.settings(None)?;
        let free: Vec<_> = base.into_iter().filter(|(_, s)| s.free).collect();
        let mut added = Vec::new();
        for clip in &session.clips {
            if !spec.surfaces.iter().any(|(n, _)| *n == clip.surface) {
                spec.surfaces.push((clip.surface.clone(), free.clone()));
                added.push(clip.surface.clone());
            }
        }
        if !added.is_empty() {
            progress.note(&format!(
                "{} does not list surface(s) {}: fitted from the file's default values",
                spec.origin,
                added.join(", ")
            ));
        }
    }
    Ok(spec)
}

/// Fit range of the surface level, m (±5 px at the paper's 0.4 mm/px).
const SURFACE_LEVEL_RANGE_M: f64 = 2e-3;

/// Adds the `surface_level` nuisance, free per surface, unless the model file sets it itself: the surface
/// line a tracker finds is the band's visible edge, a fraction of a pixel (more with the camera above the
/// surface) off the plane the ball touches, and the contact's timing in every shot depends on it.
fn add_surface_level(spec: &mut ModelSpec) {
    let name = "surface_level";
    if spec.has_effect(name) {
        return;
    }
    let Some(info) = bouncelab_model::builtin(name) else {
        return;
    };
    let free = ParamSetting {
        value: 0.0,
        free: true,
        min: -SURFACE_LEVEL_RANGE_M,
        max: SURFACE_LEVEL_RANGE_M,
    };
    spec.effects.push(EffectSetting {
        name: name.into(),
        kind: EffectKind::Builtin(info),
        params: vec![("level_m".into(), Some(free))],
    });
    let r = ParamRef {
        effect: name.into(),
        param: "level_m".into(),
    };
    for (_, values) in &mut spec.surfaces {
        values.push((r.clone(), free));
    }
}

/// The surface level the fit found for `surface` (m; the `surface_level` nuisance), if it was fitted.
pub fn fitted_surface_level(fit: &FitResult, surface: &str) -> Option<f64> {
    let own = format!("{surface}:surface_level.level_m");
    fit.param(&own)
        .or_else(|| fit.param("surface_level.level_m"))
        .map(|p| p.value)
}

/// Runs the whole analysis of the session folder `session_dir`.
///
/// Shots that cannot be measured are listed in [`Analysis::measure`] (and the report) while the others go
/// on; the caller decides the exit status. An error means nothing could be analysed (a bad session folder,
/// model file or store, or no shot measured), with the file, shot or field named.
pub fn analyze(
    session_dir: &Path,
    options: &AnalyzeOptions,
    progress: &dyn Progress,
) -> Result<Analysis, AnalyzeError> {
    let mut timings = Vec::new();
    let session = Session::load_with(session_dir, &options.clip_options)?;
    for w in &session.warnings {
        progress.note(&w.to_string());
    }
    let spec = session_model(options.model_path.as_deref(), &session, progress)?;
    if let Some(parent) = options.store_path.parent().filter(|p| !p.as_os_str().is_empty()) {
        create_dir(parent)?;
    }
    let mut store = Store::open(&options.store_path)?;

    let t = std::time::Instant::now();
    let measure = measure_session(&session, &mut store, spec.gravity, options.fingerprint, progress)?;
    timings.push((Stage::Track, t.elapsed().as_secs_f64()));
    let listed = session.listed();
    let shots = load_shots(&store, measure.session_id, &listed)?;
    let failed_tracks = load_failed_tracks(&store, measure.session_id, &listed)?;
    let files = trajectory_files(listed.iter().copied());
    if shots.is_empty() {
        // Nothing to fit, but what was measured is written: the trajectories of the shots that were
        // tracked, an empty estimates.csv, and a report listing every shot's failure and how far it got.
        create_dir(&options.out_dir)?;
        outputs::clear_partials(&options.out_dir);
        let tracks: Vec<_> = failed_tracks.iter().map(|(c, t, _)| (c.clone(), t.clone())).collect();
        let mut written = vec![outputs::write_estimates_only(&options.out_dir, &shots, &spec, &files)?];
        written.extend(outputs::write_failed_trajectories(&options.out_dir, &tracks, &files)?);
        outputs::remove_stale_trajectories(&options.out_dir, &files)?;
        written.push(report::write_failure(
            &options.out_dir,
            &session,
            &measure,
            &failed_tracks,
        )?);
        let first = measure
            .failed
            .first()
            .map(|(c, m)| format!("{c}: {m}"))
            .unwrap_or_else(|| "no shot listed".into());
        return Err(AnalyzeError::NothingMeasured {
            session: session_dir.to_path_buf(),
            total: listed.len(),
            first,
            written,
        });
    }

    let t = std::time::Instant::now();
    progress.start(Stage::Fit, 1);
    let mut excluded = flagged_shots(&shots);
    for (clip, why) in suspect_tracks(&shots) {
        if !excluded.iter().any(|(c, _)| *c == clip) {
            excluded.push((clip, why));
        }
    }
    for (clip, why) in &excluded {
        progress.note(&format!("{clip} is left out of the fit: {why}"));
    }
    let fitted: Vec<&ShotData> = shots
        .iter()
        .filter(|s| !excluded.iter().any(|(c, _)| *c == s.clip))
        .collect();
    let measured: Vec<_> = fitted.iter().map(|s| s.measured.clone()).collect();
    // The surface level per surface (the nuisance above) and, per shot, an offset from it within the
    // surface line's stated error (a free offset per shot would also absorb most of a missing contact
    // effect: restitution damping's 65 µm misfit falls to 16 µm).
    let fit_options = FitOptions::default();
    let problem = Problem::new(&spec, measured, fit_options.sim)?.with_surface_offsets(fit_options.surface_offsets);
    // The fit's degrees of freedom, so each iteration's cost is shown as the reduced χ² the result reports.
    let dof = problem
        .n_residuals()
        .saturating_sub(problem.params().len() + problem.nuisance_per_shot() * problem.shots().len())
        .max(1) as f64;
    let mut observer = |it: &bouncelab_fit::Iteration<'_>| progress.iteration(Stage::Fit, it.iteration, it.cost / dof);
    let fit = fit_problem(&problem, &spec.origin, &fit_options, &mut observer)?;
    progress.finish(
        Stage::Fit,
        &format!(
            "{} parameter(s), position RMS {:.1} µm, reduced χ² {:.2}, {} after {} iteration(s)",
            fit.parameters.len(),
            fit.rms_m * 1e6,
            fit.reduced_chi2,
            fit.termination,
            fit.iterations
        ),
    );
    timings.push((Stage::Fit, t.elapsed().as_secs_f64()));
    let model_toml = match &options.model_path {
        Some(p) => std::fs::read_to_string(p).map_err(|source| AnalyzeError::Io {
            path: p.clone(),
            source,
        })?,
        None => bouncelab_model::PAPER_MODEL_TOML.to_string(),
    };
    let version = store.add_model_version(&ModelVersionRecord {
        name: model_name(options.model_path.as_deref()),
        toml: model_toml,
        parent_id: None,
    })?;
    let before = before_after(&store, measure.session_id, version, &fit)?;
    let previous_diagnosis = before
        .as_ref()
        .and_then(|b| outputs::kept_diagnosis(&options.out_dir, b.before_version));
    store.add_fit(&FitRecord {
        session_id: Some(measure.session_id),
        model_version_id: version,
        json: fit.to_json(),
        reduced_chi2: fit.reduced_chi2,
        rms_m: fit.rms_m,
        mae_pct: fit.mean_abs_cor_error_pct,
    })?;

    let history = store.model_history(Some(measure.session_id))?;
    let model_text = store
        .model_versions()?
        .into_iter()
        .find(|v| v.id == version)
        .map(|v| v.record.toml)
        .unwrap_or_default();
    let t = std::time::Instant::now();
    progress.start(Stage::Compare, 1);
    let theta: Vec<f64> = fit.parameters.iter().map(|p| p.value).collect();
    // The measured contact time, re-read from the flight arcs at the surface level the fit found.
    let radius = spec.ball.radius_m;
    let extras: Vec<ShotExtras> = fitted
        .iter()
        .zip(&fit.shots)
        .map(|(s, f)| {
            let mut e = shot_extras(s);
            let level = match (fitted_surface_level(&fit, &f.surface), f.surface_offset_m) {
                (None, None) => None,
                (a, b) => Some(a.unwrap_or(0.0) + b.unwrap_or(0.0)),
            };
            if let Some(level) = level {
                let (t0, t1) = s.estimate.contact_at_level(level, radius);
                e.contact_time_s = Some(t1 - t0).filter(|d| d.is_finite() && *d > 0.0);
            }
            e
        })
        .collect();
    let comparison = bouncelab_compare::compare_problem(&problem, &theta, &extras)?;
    let failure = bouncelab_compare::diagnose(&comparison, &bouncelab_compare::DiagnoseOptions::default());
    progress.finish(
        Stage::Compare,
        failure.sentences.first().map_or("no residuals", String::as_str),
    );
    timings.push((Stage::Compare, t.elapsed().as_secs_f64()));

    let t = std::time::Instant::now();
    let diagnosis = if !options.diagnose {
        Err("the missing-effect search was not asked for (--no-diagnose)".to_string())
    } else if fitted.len() < search_options().min_shots {
        let why = format!(
            "{} shot(s) fitted; the missing-effect search needs at least {} (held-out errors are compared across shots)",
            fitted.len(),
            search_options().min_shots
        );
        progress.finish(Stage::Diagnose, &format!("not run: {why}"));
        Err(why)
    } else {
        create_dir(&options.out_dir)?;
        Ok(diagnose_stage(
            &spec,
            &model_text,
            &fitted,
            &extras,
            &options.out_dir,
            progress,
        )?)
    };
    timings.push((Stage::Diagnose, t.elapsed().as_secs_f64()));

    let t = std::time::Instant::now();
    progress.start(Stage::Stats, 1);
    let stats = session_stats(&shots);
    progress.finish(
        Stage::Stats,
        &match &stats {
            Ok(s) => format!("ANCOVA of COR on {} with {} shots", s.terms.join(", "), shots.len()),
            Err(reason) => format!("not computed: {reason}"),
        },
    );
    timings.push((Stage::Stats, t.elapsed().as_secs_f64()));

    let t = std::time::Instant::now();
    create_dir(&options.out_dir)?;
    outputs::clear_partials(&options.out_dir);
    let mut outputs = outputs::write_all(&options.out_dir, &shots, &fit, &spec, &files)?;
    let tracks: Vec<_> = failed_tracks.iter().map(|(c, t, _)| (c.clone(), t.clone())).collect();
    outputs::write_failed_trajectories(&options.out_dir, &tracks, &files)?;
    outputs::remove_stale_trajectories(&options.out_dir, &files)?;
    outputs.push(outputs::write_comparison(&options.out_dir, &comparison)?);
    if let Ok(st) = &stats {
        outputs.push(outputs::write_anova(&options.out_dir, &st.ancova)?);
    }
    if let Ok(d) = &diagnosis {
        outputs.push(options.out_dir.join("diagnosis.json"));
        // Kept per model version, so a later run with another model can show this verdict as the earlier one.
        outputs::keep_diagnosis(&options.out_dir, version, d)?;
    }
    timings.push((Stage::Report, t.elapsed().as_secs_f64()));
    let started_report = std::time::Instant::now();
    let fitted_at = store.latest_fit(measure.session_id)?.map(|f| f.created_at);
    let description = session
        .metadata
        .get("session")
        .and_then(|t| t.get("description"))
        .and_then(|d| d.as_str())
        .map(str::to_string);
    let warnings: Vec<String> = session.warnings.iter().map(|w| w.to_string()).collect();
    let mut analysis = Analysis {
        fitted_at,
        session_dir: session_dir.to_path_buf(),
        shots_listed: session.listed().len(),
        measure,
        model_origin: spec.origin.clone(),
        model: spec.clone(),
        model_version: version,
        previous_diagnosis,
        fit,
        shots,
        excluded,
        before,
        history,
        comparison,
        failure,
        diagnosis,
        stats,
        outputs,
        timings,
    };
    let written = report::write(
        &options.out_dir,
        &analysis,
        &session.clips,
        description.as_deref(),
        &warnings,
    )?;
    analysis.outputs.extend(written);
    if let Some((_, t)) = analysis.timings.iter_mut().find(|(s, _)| *s == Stage::Report) {
        *t += started_report.elapsed().as_secs_f64();
    }
    Ok(analysis)
}

/// The error of the previous model version fitted to the session against this one's, per shot and in total.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BeforeAfter {
    /// The earlier model version's name.
    pub before_model: String,
    /// The store's id of the earlier model version.
    pub before_version: i64,
    /// The earlier model version's `model.toml` text.
    pub before_toml: String,
    /// When it was fitted (ISO 8601, UTC).
    pub before_fitted_at: String,
    /// Position RMS of all residuals, m: (before, after).
    pub total_rms_m: (f64, f64),
    /// Reduced χ²: (before, after).
    pub reduced_chi2: (f64, f64),
    /// Per shot present in both fits: (clip, RMS before, RMS after), m.
    pub shots: Vec<(String, f64, f64)>,
}

/// The latest fit of this session by another model version than `version`, against `fit`.
fn before_after(
    store: &Store,
    session_id: i64,
    version: i64,
    fit: &FitResult,
) -> Result<Option<BeforeAfter>, AnalyzeError> {
    let Some(prev) = store
        .fits(Some(session_id))?
        .into_iter()
        .rev()
        .find(|f| f.record.model_version_id != version)
    else {
        return Ok(None);
    };
    let Ok(old) = serde_json::from_str::<FitResult>(&prev.record.json) else {
        return Ok(None);
    };
    let prev_version = store
        .model_versions()?
        .into_iter()
        .find(|v| v.id == prev.record.model_version_id);
    let name = prev_version
        .as_ref()
        .map(|v| format!("{} (version {})", v.record.name, v.id))
        .unwrap_or_else(|| old.model.clone());
    let shots = fit
        .shots
        .iter()
        .filter_map(|s| {
            let b = old.shots.iter().find(|o| o.name == s.name)?;
            Some((s.name.clone(), b.rms_m, s.rms_m))
        })
        .collect();
    Ok(Some(BeforeAfter {
        before_model: name,
        before_version: prev.record.model_version_id,
        before_toml: prev_version.map(|v| v.record.toml).unwrap_or_default(),
        before_fitted_at: prev.created_at,
        total_rms_m: (old.rms_m, fit.rms_m),
        reduced_chi2: (old.reduced_chi2, fit.reduced_chi2),
        shots,
    }))
}

/// Shots whose estimate says their numbers are not to be trusted (see `Estimate::flags`: a flight that does not
/// fall like a ball …), with the reasons.
pub fn flagged_shots(shots: &[ShotData]) -> Vec<(String, String)> {
    shots
        .iter()
        .filter(|s| !s.estimate.flags.is_empty())
        .map(|s| (s.clip.clone(), s.estimate.flags.join("; ")))
        .collect()
}

/// How far a shot's flight fits may scatter beyond the session's typical shot before its track is suspect.
pub const SUSPECT_FLIGHT_FACTOR: f64 = 25.0;

/// Shots whose flight phases are not ballistic to within the tracking noise, far beyond the session's other
/// shots: the worst flight fit's reduced χ² above [`SUSPECT_FLIGHT_FACTOR`] × the session's median and above
/// 9 (3σ scatter). No contact model can fix a flight phase, so such a track (a seam or a shadow followed for
/// some frames) would only bend the shared fit; the shot keeps its estimates and is listed with the reason.
/// A missing flight effect (drag) raises every shot's χ² and so the median with it.
pub fn suspect_tracks(shots: &[ShotData]) -> Vec<(String, String)> {
    let worst = |s: &ShotData| s.estimate.chi2_red.iter().cloned().fold(0.0, f64::max);
    let mut all: Vec<f64> = shots.iter().map(worst).filter(|v| v.is_finite()).collect();
    if all.len() < 3 {
        return Vec::new();
    }
    all.sort_by(f64::total_cmp);
    let median = all[all.len() / 2];
    shots
        .iter()
        .filter(|s| {
            let w = worst(s);
            !w.is_finite() || (w > 9.0 && w > SUSPECT_FLIGHT_FACTOR * median)
        })
        .map(|s| {
            (
                s.clip.clone(),
                format!(
                    "its flight fits scatter {:.0}× more than the tracker's σ (reduced χ² {:.1}; session median {:.2}): the track is suspect",
                    worst(s).sqrt(),
                    worst(s),
                    median
                ),
            )
        })
        .collect()
}

/// The search's options: the defaults, with each shot's surface level fitted within its line's σ.
fn search_options() -> SearchOptions {
    SearchOptions {
        surface_levels: true,
        ..SearchOptions::default()
    }
}

/// The missing-effect search, or its stored result when neither the shots, their measurements, the model
/// nor the program changed since it ran (it is the slowest stage after tracking).
fn diagnose_stage(
    spec: &ModelSpec,
    model_text: &str,
    shots: &[&ShotData],
    extras: &[ShotExtras],
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<Diagnosis, AnalyzeError> {
    let options = search_options();
    let mut key = Fingerprint::new();
    key.str(env!("CARGO_PKG_VERSION"))
        .str(model_text)
        .str(&format!("{options:?}"));
    for s in shots {
        key.str(&s.clip)
            .str(&serde_json::to_string(&s.measured).unwrap_or_default());
    }
    let key = key.finish();
    let path = out_dir.join("diagnosis.json");
    let key_path = out_dir.join(".diagnosis-inputs");
    if std::fs::read_to_string(&key_path).is_ok_and(|k| k.trim() == key)
        && let Some(d) = std::fs::read_to_string(&path)
            .ok()
            .and_then(|t| serde_json::from_str::<Diagnosis>(&t).ok())
    {
        progress.finish(
            Stage::Diagnose,
            &format!(
                "unchanged since the last run ({} candidate(s) in diagnosis.json)",
                d.candidates.len()
            ),
        );
        return Ok(d);
    }
    let measured: Vec<_> = shots.iter().map(|s| s.measured.clone()).collect();
    // The current model plus every library effect it lacks.
    let total = 1 + bouncelab_model::builtin_effects()
        .iter()
        .filter(|e| !e.base && !spec.has_effect(e.name))
        .count();
    progress.start(Stage::Diagnose, total as u64);
    let last = std::sync::atomic::AtomicUsize::new(0);
    let report = |p: bouncelab_diagnose::Progress| {
        if let Some(i) = p.iteration {
            // A solver iteration of the model being fitted.
            progress.iteration(Stage::Diagnose, i, p.chi2_red.unwrap_or(f64::NAN));
            return;
        }
        let before = last.swap(p.done, std::sync::atomic::Ordering::Relaxed);
        progress.advance(Stage::Diagnose, p.done.saturating_sub(before) as u64);
        progress.doing(Stage::Diagnose, &p.what);
    };
    let d = find_missing_effect_with(spec, &measured, extras, &options, &report)?;
    outputs::write_atomic(&path, |w| w.write_all(d.to_json().as_bytes()))?;
    outputs::write_atomic(&key_path, |w| w.write_all(key.as_bytes()))?;
    progress.finish(
        Stage::Diagnose,
        &format!(
            "{} candidate effect(s) fitted in {:.1} s",
            d.candidates.len(),
            d.seconds
        ),
    );
    Ok(d)
}

/// The paper's statistics of a session (`docs/stats.md`).
#[derive(Debug, Clone)]
pub struct SessionStats {
    /// The terms fitted, in order (those with a single level are left out).
    pub terms: Vec<&'static str>,
    /// ANCOVA of COR (Type I and II), its fit and diagnostics.
    pub ancova: Ancova,
    /// Tukey–Kramer comparisons of the surfaces' raw means at α = 0.05, when there are two or more (one-way:
    /// the impact speed is not accounted for; `inference` holds the comparisons that agree with the ANCOVA).
    pub tukey: Option<TukeyHsd>,
    /// The same fit's coefficients with SE, t and p, adjusted means of every factor with Tukey–Kramer and
    /// Holm comparisons, and its residual tests (α = 0.05), or why they could not be computed.
    pub inference: Result<AncovaInference, String>,
}

/// ANCOVA of COR on surface and angle with the incoming normal speed as covariate, and Tukey–Kramer pairwise
/// comparisons of the surfaces; a factor with one level is left out. `Err` says why nothing could be fitted.
pub fn session_stats(shots: &[ShotData]) -> Result<SessionStats, String> {
    let rows: Vec<CorObservation> = shots
        .iter()
        .map(|s| CorObservation {
            surface: s.surface.clone(),
            angle: s.angle_deg,
            v_in_n: s.estimate.v_in[1].value.abs(),
            cor: s.estimate.cor.value,
        })
        .collect();
    let distinct = |f: &dyn Fn(&CorObservation) -> String| {
        let mut v: Vec<String> = rows.iter().map(f).collect();
        v.sort();
        v.dedup();
        v.len()
    };
    let surfaces = distinct(&|r| r.surface.clone());
    let angles = distinct(&|r| format!("{}", r.angle));
    let terms: Vec<&'static str> = PAPER_TERMS
        .into_iter()
        .filter(|t| match *t {
            "surface" => surfaces > 1,
            "angle" => angles > 1,
            _ => true,
        })
        .collect();
    let data = Dataset::from_cor(&rows).map_err(|e| e.to_string())?;
    let ancova = ancova(&data, &terms).map_err(|e| format!("{} shot(s): {e}", shots.len()))?;
    let tukey = if surfaces > 1 {
        Some(tukey_hsd_factor(&data, "surface", 0.05).map_err(|e| e.to_string())?)
    } else {
        None
    };
    let inference = ancova_inference(&data, &terms, 0.05).map_err(|e| e.to_string());
    Ok(SessionStats {
        terms,
        ancova,
        tukey,
        inference,
    })
}

/// The evidence a shot carries besides its frames: drop height, contact time, the camera's roll from the
/// surface line's tilt, and the spin measured before and after the impact (at the first and last fitted
/// frames, where the flight arcs hold it constant but for rolling resistance and drag, which act slowly).
fn shot_extras(s: &ShotData) -> ShotExtras {
    let frames = &s.measured.frames;
    let mut spin = Vec::new();
    if let (Some(m), Some(f)) = (s.estimate.spin_in, frames.first())
        && m.se > 0.0
        && m.value.is_finite()
    {
        spin.push(SpinFrame {
            t_s: f.t_s,
            omega_rad_s: m.value,
            sigma_rad_s: m.se,
        });
    }
    if let (Some(m), Some(f)) = (s.estimate.spin_out, frames.last())
        && m.se > 0.0
        && m.value.is_finite()
    {
        spin.push(SpinFrame {
            t_s: f.t_s,
            omega_rad_s: m.value,
            sigma_rad_s: m.se,
        });
    }
    ShotExtras {
        drop_height_m: Some(s.drop_height_m),
        contact_time_s: Some(s.estimate.contact_ms.value * 1e-3),
        camera_roll_deg: s.track.surface_tilt_deg,
        spin,
    }
}

/// The name a model version is stored under: the file's name, or the built-in model's.
fn model_name(path: Option<&Path>) -> String {
    path.and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "built-in paper model".into())
}

fn create_dir(dir: &Path) -> Result<(), AnalyzeError> {
    std::fs::create_dir_all(dir).map_err(|source| AnalyzeError::Io {
        path: dir.to_path_buf(),
        source,
    })
}
