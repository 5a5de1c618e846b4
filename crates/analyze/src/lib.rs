//! The pipeline over a session folder: frames → track → estimate → fit → compare → diagnose → stats → report,
//! incremental through the results store.
//!
//! This crate owns no science: [`analyze`] runs each stage's library in order as named steps (the model is fitted
//! and compared once, and the missing-effect search starts from that fit) and writes the files of
//! `docs/outputs.md`. Its one design choice is that the SQLite store sits between measuring and everything after
//! it: shots are tracked in parallel and each one is committed on its own, the later stages read every shot back
//! from the store, so an unchanged shot is never tracked again and a run killed at any instant resumes where it
//! stopped. Progress is reported to a [`Progress`] (the CLI draws bars on a terminal, plain lines otherwise).

mod error;
mod evidence;
mod history;
mod measure;
mod outputs;
mod report;
mod reuse;
mod search;
mod session_model;
mod shots;

pub use bouncelab_stats::SessionStats;
pub use error::AnalyzeError;
pub use history::BeforeAfter;
pub use measure::{MeasureSummary, measure_session};
pub use outputs::{
    COMPARISON_COLUMNS, CURVE_COLUMNS, ESTIMATE_COLUMNS, FORCE_COLUMNS, PREDICTION_COLUMNS, SURFACE_COLUMNS,
    TrajectoryFiles, trajectory_files, write_comparison_csv, write_estimates_csv,
};
pub use report::{track_peak_deceleration, verdict_headline};
pub use session_model::session_model;
pub use shots::{ShotData, load_failed_tracks, load_shots, measured_shot};

use bouncelab_compare::{Comparison, FailureReport, ShotExtras};
use bouncelab_diagnose::{Diagnosis, FittedBaseline};
use bouncelab_fit::{FitOptions, FitResult, Problem, fit_problem};
use bouncelab_frames::{ClipOptions, Session};
use bouncelab_model::ModelSpec;
use bouncelab_stats::CorObservation;
use bouncelab_store::{ClipFingerprint, ModelHistoryRow, Store, TrackRecord};
use std::path::{Path, PathBuf};
use std::time::Instant;

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
pub struct NoProgress;
impl Progress for NoProgress {}

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
    /// Shots left out of the fit with the reason (see [`flagged_shots`], [`suspect_tracks`]).
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

/// The surface level the fit found for `surface` (m; the `surface_level` nuisance), if it was fitted
/// ([`FitResult::surface_level_m`]).
pub fn fitted_surface_level(fit: &FitResult, surface: &str) -> Option<f64> {
    fit.surface_level_m(surface)
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
    let mut timings = Timings::default();
    let session = Session::load_with(session_dir, &options.clip_options)?;
    for w in &session.warnings {
        progress.note(&w.to_string());
    }
    let spec = session_model(options.model_path.as_deref(), &session, progress)?;
    let mut store = open_store(&options.store_path)?;

    let measure = timings.time(Stage::Track, || {
        measure_session(&session, &mut store, spec.gravity, options.fingerprint, progress)
    })?;
    let listed = session.listed();
    let shots = load_shots(&store, measure.session_id, &listed)?;
    let failed_tracks = load_failed_tracks(&store, measure.session_id, &listed)?;
    let files = trajectory_files(listed.iter().copied());
    if shots.is_empty() {
        return Err(nothing_measured(
            session_dir,
            &session,
            &measure,
            &failed_tracks,
            &spec,
            &files,
            &options.out_dir,
        )?);
    }

    let FitStage {
        excluded,
        fitted,
        problem,
        fit,
        inputs_key,
    } = timings.time(Stage::Fit, || fit_stage(&spec, &shots, options, progress))?;
    let recorded = history::record_fit(&mut store, measure.session_id, options, &fit)?;
    let extras = evidence::fitted_extras(&fitted, &fit, spec.ball.radius_m);
    let (comparison, failure) = timings.time(Stage::Compare, || compare_stage(&problem, &fit, &extras, progress))?;
    let baseline = FittedBaseline::new(&fit, &comparison, &failure);
    let diagnosis = timings.time(Stage::Diagnose, || {
        search::search_stage(
            &spec,
            &recorded.model_text,
            &fitted,
            &extras,
            baseline,
            options,
            progress,
        )
    })?;
    let stats = timings.time(Stage::Stats, || stats_stage(&shots, progress));

    let written = Written {
        shots: &shots,
        fit: &fit,
        spec: &spec,
        files: &files,
        failed_tracks: &failed_tracks,
        comparison: &comparison,
        stats: &stats,
        diagnosis: &diagnosis,
        version: recorded.version,
    };
    let outputs = timings.time(Stage::Report, || write_outputs(&options.out_dir, &written))?;
    // After fit.json: the key of the inputs it was fitted from, for the next run to reuse it.
    outputs::write_atomic(&options.out_dir.join(FIT_INPUTS), |w| {
        w.write_all(inputs_key.as_bytes())
    })?;
    let started_report = Instant::now();
    let fitted_at = store.latest_fit(measure.session_id)?.map(|f| f.created_at);
    let mut analysis = Analysis {
        fitted_at,
        session_dir: session_dir.to_path_buf(),
        shots_listed: listed.len(),
        measure,
        model_origin: spec.origin.clone(),
        model: spec,
        model_version: recorded.version,
        previous_diagnosis: recorded.previous_diagnosis,
        fit,
        shots,
        excluded,
        before: recorded.before,
        history: recorded.history,
        comparison,
        failure,
        diagnosis,
        stats,
        outputs,
        timings: timings.0,
    };
    write_report(&options.out_dir, &mut analysis, &session)?;
    if let Some((_, t)) = analysis.timings.iter_mut().find(|(s, _)| *s == Stage::Report) {
        *t += started_report.elapsed().as_secs_f64();
    }
    Ok(analysis)
}

/// Seconds per stage, in the order the stages ran.
#[derive(Default)]
struct Timings(Vec<(Stage, f64)>);

impl Timings {
    /// Runs `stage` (`f`) and records how long it took.
    fn time<T>(&mut self, stage: Stage, f: impl FnOnce() -> T) -> T {
        let since = Instant::now();
        let out = f();
        self.0.push((stage, since.elapsed().as_secs_f64()));
        out
    }
}

/// The results store at `path`, its folder created.
fn open_store(path: &Path) -> Result<Store, AnalyzeError> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        create_dir(parent)?;
    }
    Ok(Store::open(path)?)
}

/// With no shot measured there is nothing to fit, but what was measured is written: the trajectories of
/// the shots that were tracked, an empty estimates.csv, and a report listing every shot's failure and how
/// far it got. Returns the error to give (or the one that stopped the writing).
fn nothing_measured(
    session_dir: &Path,
    session: &Session,
    measure: &MeasureSummary,
    failed_tracks: &[(String, TrackRecord, String)],
    spec: &ModelSpec,
    files: &TrajectoryFiles,
    out_dir: &Path,
) -> Result<AnalyzeError, AnalyzeError> {
    create_dir(out_dir)?;
    outputs::clear_partials(out_dir);
    let tracks: Vec<_> = failed_tracks.iter().map(|(c, t, _)| (c.clone(), t.clone())).collect();
    let mut written = vec![outputs::write_estimates_only(out_dir, &[], spec, files)?];
    written.extend(outputs::write_failed_trajectories(out_dir, &tracks, files)?);
    outputs::remove_stale_trajectories(out_dir, files)?;
    written.push(report::write_failure(out_dir, session, measure, failed_tracks)?);
    let first = measure
        .failed
        .first()
        .map(|(c, m)| format!("{c}: {m}"))
        .unwrap_or_else(|| "no shot listed".into());
    Ok(AnalyzeError::NothingMeasured {
        session: session_dir.to_path_buf(),
        total: session.listed().len(),
        first,
        written,
    })
}

/// The shots left out of the fit with the reason: those whose estimate is flagged, then those whose
/// flight fits are suspect ([`suspect_tracks`]); each is noted to `progress`.
fn excluded_shots(shots: &[ShotData], progress: &dyn Progress) -> Vec<(String, String)> {
    let mut excluded = flagged_shots(shots);
    for (clip, why) in suspect_tracks(shots) {
        if !excluded.iter().any(|(c, _)| *c == clip) {
            excluded.push((clip, why));
        }
    }
    for (clip, why) in &excluded {
        progress.note(&format!("{clip} is left out of the fit: {why}"));
    }
    excluded
}

/// What the fit stage leaves: the shots left out with the reason, those fitted, the problem, the fit and
/// the key of the inputs it depends on.
struct FitStage<'a> {
    excluded: Vec<(String, String)>,
    fitted: Vec<&'a ShotData>,
    problem: Problem,
    fit: FitResult,
    inputs_key: String,
}

/// Beside `fit.json` in the output folder: the key of the inputs it was fitted from.
const FIT_INPUTS: &str = ".fit-inputs";

/// The model fitted to the shots not excluded ([`excluded_shots`]): the surface level per surface (the
/// nuisance of [`bouncelab_fit::add_surface_level`]) and, per shot, an offset from it within the surface
/// line's stated error (a free offset per shot would also absorb most of a missing contact effect:
/// restitution damping's 65 µm misfit falls to 16 µm). Every solver iteration is reported as the reduced χ²
/// the result reports. The fit in the output folder's `fit.json` is taken instead when nothing it depends on
/// changed ([`fit_inputs_key`]): a session re-run with nothing new is not fitted again.
fn fit_stage<'a>(
    spec: &ModelSpec,
    shots: &'a [ShotData],
    options: &AnalyzeOptions,
    progress: &dyn Progress,
) -> Result<FitStage<'a>, AnalyzeError> {
    progress.start(Stage::Fit, 1);
    let excluded = excluded_shots(shots, progress);
    let fitted: Vec<&ShotData> = shots
        .iter()
        .filter(|s| !excluded.iter().any(|(c, _)| *c == s.clip))
        .collect();
    let measured: Vec<_> = fitted.iter().map(|s| s.measured.clone()).collect();
    let fit_options = FitOptions::default();
    let problem = Problem::new(spec, measured, fit_options.sim)?.with_surface_offsets(fit_options.surface_offsets);
    let dof = problem
        .n_residuals()
        .saturating_sub(problem.params().len() + problem.nuisance_per_shot() * problem.shots().len())
        .max(1) as f64;
    let inputs_key = fit_inputs_key(spec, &history::model_toml(options)?, &fit_options, &problem, &fitted);
    let out = &options.out_dir;
    let (fit, reused) = match reuse::read_back::<FitResult>(&out.join("fit.json"), &out.join(FIT_INPUTS), &inputs_key) {
        Some(fit) => {
            // The comparison profiles each shot's level from where the fit left it.
            if fit
                .shots
                .iter()
                .map(|s| &s.name)
                .eq(problem.shots().iter().map(|s| &s.name))
            {
                let levels: Vec<f64> = fit.shots.iter().map(|s| s.surface_offset_m.unwrap_or(0.0)).collect();
                problem.start_offsets_at(&levels);
            }
            (fit, true)
        }
        None => {
            reuse::forget(&out.join(FIT_INPUTS))?;
            let mut observer =
                |it: &bouncelab_fit::Iteration<'_>| progress.iteration(Stage::Fit, it.iteration, it.cost / dof);
            (fit_problem(&problem, &spec.origin, &fit_options, &mut observer)?, false)
        }
    };
    progress.finish(
        Stage::Fit,
        &format!(
            "{}{} parameter(s), position RMS {:.1} µm, reduced χ² {:.2}, {} after {} iteration(s)",
            if reused {
                "unchanged since the last run (fit.json): "
            } else {
                ""
            },
            fit.parameters.len(),
            fit.rms_m * 1e6,
            fit.reduced_chi2,
            fit.termination,
            fit.iterations
        ),
    );
    Ok(FitStage {
        excluded,
        fitted,
        problem,
        fit,
        inputs_key,
    })
}

/// The key of what the fit depends on: the program's version, the model file's text and the model as the
/// session made it (ball, gravity, effects' settings, per-surface values), the fit's options, the free
/// parameters and every fitted shot's measurement.
fn fit_inputs_key(
    spec: &ModelSpec,
    model_toml: &str,
    fit_options: &FitOptions,
    problem: &Problem,
    fitted: &[&ShotData],
) -> String {
    let mut key = bouncelab_store::Fingerprint::new();
    key.str(env!("CARGO_PKG_VERSION"))
        .str(model_toml)
        .str(&format!("{:?} {:?} {:?}", spec.ball, spec.gravity, spec.surfaces))
        .str(&format!("{fit_options:?}"))
        .str(&format!("{:?}", problem.params()));
    for e in &spec.effects {
        key.str(&e.name).str(&format!("{:?}", e.params));
    }
    reuse::add_shots(&mut key, fitted);
    key.finish()
}

/// The fitted model against every fitted shot, and where it fails.
fn compare_stage(
    problem: &Problem,
    fit: &FitResult,
    extras: &[ShotExtras],
    progress: &dyn Progress,
) -> Result<(Comparison, FailureReport), AnalyzeError> {
    progress.start(Stage::Compare, 1);
    let theta: Vec<f64> = fit.parameters.iter().map(|p| p.value).collect();
    let comparison = bouncelab_compare::compare_problem(problem, &theta, extras)?;
    let failure = bouncelab_compare::diagnose(&comparison, &bouncelab_compare::DiagnoseOptions::default());
    progress.finish(
        Stage::Compare,
        failure.sentences.first().map_or("no residuals", String::as_str),
    );
    Ok((comparison, failure))
}

/// The session's statistics ([`session_stats`]), reported to `progress`.
fn stats_stage(shots: &[ShotData], progress: &dyn Progress) -> Result<SessionStats, String> {
    progress.start(Stage::Stats, 1);
    let stats = session_stats(shots);
    progress.finish(
        Stage::Stats,
        &match &stats {
            Ok(s) => format!("ANCOVA of COR on {} with {} shots", s.terms.join(", "), shots.len()),
            Err(reason) => format!("not computed: {reason}"),
        },
    );
    stats
}

/// What [`write_outputs`] writes from.
struct Written<'a> {
    shots: &'a [ShotData],
    fit: &'a FitResult,
    spec: &'a ModelSpec,
    files: &'a TrajectoryFiles,
    failed_tracks: &'a [(String, TrackRecord, String)],
    comparison: &'a Comparison,
    stats: &'a Result<SessionStats, String>,
    diagnosis: &'a Result<Diagnosis, String>,
    /// The store's id of the model version fitted (the kept diagnosis is filed under it).
    version: i64,
}

/// The output files of `docs/outputs.md` but the report; returns those listed as written.
fn write_outputs(out_dir: &Path, w: &Written<'_>) -> Result<Vec<PathBuf>, AnalyzeError> {
    create_dir(out_dir)?;
    outputs::clear_partials(out_dir);
    let mut written = outputs::write_all(out_dir, w.shots, w.fit, w.spec, w.files)?;
    let tracks: Vec<_> = w.failed_tracks.iter().map(|(c, t, _)| (c.clone(), t.clone())).collect();
    outputs::write_failed_trajectories(out_dir, &tracks, w.files)?;
    outputs::remove_stale_trajectories(out_dir, w.files)?;
    written.push(outputs::write_comparison(out_dir, w.comparison)?);
    if let Ok(st) = w.stats {
        written.push(outputs::write_anova(out_dir, &st.ancova)?);
    }
    if let Ok(d) = w.diagnosis {
        written.push(out_dir.join("diagnosis.json"));
        // Kept per model version, so a later run with another model can show this verdict as the earlier one.
        outputs::keep_diagnosis(out_dir, w.version, d)?;
    }
    Ok(written)
}

/// `report.html` (and the figures' data) from `analysis`, added to its outputs.
fn write_report(out_dir: &Path, analysis: &mut Analysis, session: &Session) -> Result<(), AnalyzeError> {
    let description = session
        .metadata
        .get("session")
        .and_then(|t| t.get("description"))
        .and_then(|d| d.as_str())
        .map(str::to_string);
    let warnings: Vec<String> = session.warnings.iter().map(|w| w.to_string()).collect();
    let written = report::write(out_dir, analysis, &session.clips, description.as_deref(), &warnings)?;
    analysis.outputs.extend(written);
    Ok(())
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

/// Frames next to the contact left out of a flight arc when judging the track's own scatter.
const SUSPECT_CONTACT_MARGIN_FRAMES: f64 = 3.0;

/// Shots whose flight phases scatter far beyond the session's other shots, with the reason: the fit
/// crate's rule ([`bouncelab_fit::suspect_flights`]) over each shot's flight arcs, each fitted on its own
/// by a cubic in time ([`bouncelab_fit::flight_structure_chi2`]), so that drag, which bends every long
/// flight away from the estimator's ballistic arcs, does not hide a track that followed something else.
pub fn suspect_tracks(shots: &[ShotData]) -> Vec<(String, String)> {
    let structure: Vec<Vec<f64>> = shots
        .iter()
        .map(|s| {
            let frames = &s.measured.frames;
            let mut dt: Vec<f64> = frames.windows(2).map(|w| w[1].t_s - w[0].t_s).collect();
            dt.sort_by(f64::total_cmp);
            let margin = dt.get(dt.len() / 2).copied().unwrap_or(0.0) * SUSPECT_CONTACT_MARGIN_FRAMES;
            bouncelab_fit::flight_structure_chi2(&s.measured, s.estimate.t_touch.value, s.estimate.t_sep.value, margin)
        })
        .collect();
    let flights: Vec<&[f64]> = structure.iter().map(Vec::as_slice).collect();
    bouncelab_fit::suspect_flights(&flights)
        .into_iter()
        .map(|(i, why)| (shots[i].clip.clone(), why))
        .collect()
}

/// The paper's statistics of the session's shots ([`bouncelab_stats::session_stats`] of their COR,
/// angle and incoming normal speed); `Err` says why nothing could be fitted.
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
    bouncelab_stats::session_stats(&rows).map_err(|e| e.to_string())
}

fn create_dir(dir: &Path) -> Result<(), AnalyzeError> {
    std::fs::create_dir_all(dir).map_err(|source| AnalyzeError::Io {
        path: dir.to_path_buf(),
        source,
    })
}
