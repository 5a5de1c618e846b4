//! What the report shows: plain data filled by the caller from the pipeline's results.
//!
//! Every text field may come from input files (clip and surface names, descriptions, warnings, model
//! names) and is HTML-escaped when rendered. Every number may be NaN or infinite: it is shown as such in
//! tables and left out of plots (with a note under the plot saying how many values were left out).

use serde::{Deserialize, Serialize};

use bouncelab_stats::{Ancova, AncovaInference};

/// A report section that may be missing; a missing one is shown as one line, "not available: reason".
///
/// `From<Result<T, E>>` keeps the error's message as the reason, so a stage's result can be put in as it
/// is: `report.ancova = bouncelab_stats::ancova(&data, &PAPER_TERMS).into();`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Section<T> {
    /// The section's content.
    Available(T),
    /// Why the section is missing, in one line (e.g. "fewer than two surfaces").
    Unavailable(String),
}

impl<T> Section<T> {
    /// A missing section with its reason.
    pub fn unavailable(reason: impl Into<String>) -> Self {
        Section::Unavailable(reason.into())
    }

    /// The content, if available.
    pub fn get(&self) -> Option<&T> {
        match self {
            Section::Available(t) => Some(t),
            Section::Unavailable(_) => None,
        }
    }
}

impl<T> Default for Section<T> {
    fn default() -> Self {
        Section::Unavailable("not computed".into())
    }
}

impl<T> From<T> for Section<T> {
    fn from(t: T) -> Self {
        Section::Available(t)
    }
}

impl<T, E: std::fmt::Display> From<Result<T, E>> for Section<T> {
    fn from(r: Result<T, E>) -> Self {
        match r {
            Ok(t) => Section::Available(t),
            Err(e) => Section::Unavailable(e.to_string()),
        }
    }
}

/// Everything one report shows. Build it with `Report { title, session, ..Default::default() }` and fill
/// what the run computed; every part may be empty or missing.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Page title and top heading (e.g. "Session 2024-05-03, clay and tapes").
    pub title: String,
    /// Where the data came from and what made the report.
    pub session: SessionInfo,
    /// One entry per shot: trajectory, model and residuals, in the order shown in the shot table.
    pub shots: Vec<ShotPlot>,
    /// Every measured quantity of every measured shot, with the fitted model's prediction for it (the
    /// per-shot tables, the per-surface summary and the paper's Figures 6–8).
    pub measurements: Vec<ShotMeasurement>,
    /// The fitted model's COR, contact time, δ_max and peak loads against impact speed, one curve per
    /// surface and angle, drawn over the measured points.
    pub model_curves: Vec<ModelCurve>,
    /// The contact force over time of one shot as the fitted model predicts it (the paper's Figure 2).
    pub contact_force: Section<ContactForce>,
    /// ANCOVA of COR on surface and angle with the incoming normal speed as covariate (Table 1, Figure 11).
    ///
    /// When `measurements` has exactly as many entries as the ANCOVA has observations, they are taken to be
    /// in the same order (as when the ANCOVA is fitted from them) and residual points are labelled with
    /// their clip.
    pub ancova: Section<Ancova>,
    /// The inference of the same fit: coefficients with SE, t, p; covariate-adjusted (estimated marginal)
    /// means of every factor with Tukey–Kramer and Holm comparisons; residual tests with their caption.
    pub inference: Section<AncovaInference>,
    /// The contact model fitted to the measured trajectories.
    pub fit: Section<FitSummary>,
    /// Which effect is missing from the model.
    pub diagnosis: Section<DiagnosisSection>,
    /// What changed since the previous model fitted to this session: effects added, the earlier verdict,
    /// the residual's signature and the error per shot before and after.
    pub model_change: Section<ModelChange>,
    /// Warnings of the run (dropped frames, frames without the ball, default fps, …), one line each.
    pub warnings: Vec<String>,
    /// Wall-clock time per pipeline stage: (stage name, seconds).
    pub timings: Vec<(String, f64)>,
}

/// Where the data came from and what made the report.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SessionInfo {
    /// The session folder as given on the command line.
    pub path: String,
    /// Free text from `session.toml`'s `[session]` description; may be empty.
    pub description: String,
    /// Number of shots in the session (listed in `clips.csv`), analysed or not.
    pub shots: usize,
    /// Surface names, in the order the report lists them (colours and markers follow this order; surfaces
    /// met only in the data are added after these, sorted).
    pub surfaces: Vec<String>,
    /// Program and version that made the report (e.g. "bouncelab 0.1.0").
    pub generated_by: String,
    /// When the report was made, as the caller wants it shown (e.g. an RFC 3339 time); the renderer never
    /// reads the clock, so the same input gives the same bytes.
    pub generated_at: Option<String>,
    /// More facts to list, as (key, value) text pairs in the given order (e.g. ("ball diameter", "0.067 m"),
    /// ("fps", "10000")).
    pub metadata: Vec<(String, String)>,
}

/// Phase of an impact, in time order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Free flight before touching the surface.
    FlightIn,
    /// Contact, penetration growing.
    Compression,
    /// Contact, penetration shrinking.
    Restitution,
    /// Free flight after leaving the surface.
    FlightOut,
}

impl Phase {
    /// All phases in time order.
    pub const ALL: [Phase; 4] = [
        Phase::FlightIn,
        Phase::Compression,
        Phase::Restitution,
        Phase::FlightOut,
    ];

    /// The phase's name as shown: "flight in", "compression", "restitution", "flight out".
    pub fn label(self) -> &'static str {
        match self {
            Phase::FlightIn => "flight in",
            Phase::Compression => "compression",
            Phase::Restitution => "restitution",
            Phase::FlightOut => "flight out",
        }
    }
}

/// One tracked frame of a shot, in the local frame of `docs/outputs.md` (x down-slope, y the outward normal, origin
/// on the surface line).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeasuredPoint {
    /// Time from the clip's first frame, s.
    pub t_s: f64,
    /// Ball centre along the surface, m.
    pub x_m: f64,
    /// Ball centre along the surface normal (height above the surface line), m.
    pub y_m: f64,
    /// Tracking uncertainty (1σ) of each coordinate, m.
    pub sigma_m: f64,
}

/// One sample of the fitted model simulated for a shot (what the camera would see), local frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModelPoint {
    /// Time from the clip's first frame, s.
    pub t_s: f64,
    /// Ball centre along the surface, m.
    pub x_m: f64,
    /// Ball centre along the surface normal, m.
    pub y_m: f64,
}

/// A time interval during which a shot is in one phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PhaseSpan {
    /// The phase.
    pub phase: Phase,
    /// Start, s from the clip's first frame.
    pub t0_s: f64,
    /// End, s.
    pub t1_s: f64,
}

/// One frame's residual, measured − model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Residual {
    /// Time from the clip's first frame, s.
    pub t_s: f64,
    /// Tangential residual, m.
    pub dx_m: f64,
    /// Normal residual, m.
    pub dy_m: f64,
}

/// One shot's trajectory with the fitted model over it.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ShotPlot {
    /// Clip name (the `clip` column of `clips.csv`); the shot's anchor in the page is made from it.
    pub clip: String,
    /// Surface name.
    pub surface: String,
    /// Surface incline, degrees.
    pub angle_deg: f64,
    /// Drop height from `clips.csv`, m, if known.
    pub drop_height_m: Option<f64>,
    /// Tracked frames (frames without a valid fix left out). Plots are thinned to a few hundred points,
    /// keeping every contact frame.
    pub measured: Vec<MeasuredPoint>,
    /// The fitted model simulated for this shot, at any time step; empty when there is no model.
    pub model: Vec<ModelPoint>,
    /// Phase intervals (from the estimator or the simulation); shaded behind the plots.
    pub phases: Vec<PhaseSpan>,
    /// Residuals measured − model, one per fitted frame; empty when there is no model.
    pub residuals: Vec<Residual>,
    /// RMS of the position residuals (x and y together), m; when `None` it is computed from `residuals`
    /// as √(Σ(dx² + dy²) / 2n).
    pub rms_m: Option<f64>,
    /// Reduced χ² of the shot against the tracking σ ([`FitSummary::reduced_chi2`]'s definition, the shot's
    /// χ² over its share of the degrees of freedom), if known.
    pub chi2_red: Option<f64>,
    /// Status notes of the shot, one line each (e.g. "3 frames without the ball", "re-used from the store").
    /// A note every shot carries is shown once for the session.
    pub notes: Vec<String>,
    /// Annotated frames of the shot (approach, touch, maximum compression, separation, leave), shown as a
    /// strip above its plots; empty when none were drawn.
    pub frames: Vec<FrameImage>,
}

/// One annotated video frame, embedded in the page.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameImage {
    /// What the frame shows (e.g. "touch, frame 312").
    pub caption: String,
    /// The image as PNG bytes.
    pub png: Vec<u8>,
}

/// A measured value and its standard error, in the value's unit.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    /// The value.
    pub value: f64,
    /// Its standard error, same unit; `None` when not known.
    pub se: Option<f64>,
}

impl Measured {
    /// A value with its standard error.
    pub fn new(value: f64, se: f64) -> Measured {
        Measured { value, se: Some(se) }
    }
}

/// Every quantity measured for one shot, in SI units, and what the fitted model predicts for it.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ShotMeasurement {
    /// Clip name; links to the shot's plots when a shot of that name is in the report.
    pub clip: String,
    /// Surface name.
    pub surface: String,
    /// Surface incline, degrees.
    pub angle_deg: f64,
    /// Drop height from `clips.csv`, m, if known.
    pub drop_height_m: Option<f64>,
    /// Incoming velocity at touch (tangential down-slope, normal), m/s; the normal one is negative.
    pub v_in_m_s: [Measured; 2],
    /// Outgoing velocity at separation (tangential, normal), m/s.
    pub v_out_m_s: [Measured; 2],
    /// Coefficient of restitution |v_n,out / v_n,in|.
    pub cor: Measured,
    /// Effective friction −Δv_t / Δv_n.
    pub mu_eff: Measured,
    /// Contact time, s.
    pub contact_time_s: Measured,
    /// Maximum penetration δ_max, m.
    pub delta_max_m: Measured,
    /// Spin before the impact, rad/s (counter-clockwise as seen), when measured.
    pub spin_in_rad_s: Option<Measured>,
    /// Spin after the impact, rad/s, when measured.
    pub spin_out_rad_s: Option<Measured>,
    /// Peak normal deceleration of the ball's centre from the track's second difference, m/s², when the
    /// track resolves it.
    pub peak_deceleration_track_m_s2: Option<Measured>,
    /// Peak normal contact force from the same, N: the mass times (the deceleration + gravity's normal
    /// component).
    pub peak_force_track_n: Option<Measured>,
    /// The fitted model hit at this shot's measured incoming velocity, when a model was fitted.
    pub model: Option<ShotPrediction>,
}

impl ShotMeasurement {
    /// Impact speed |v_in|, m/s, with its standard error (components taken as independent).
    pub fn impact_speed(&self) -> Measured {
        let [t, n] = self.v_in_m_s;
        let v = t.value.hypot(n.value);
        let se = match (t.se, n.se) {
            (Some(a), Some(b)) if v > 0.0 => Some((t.value * a).hypot(n.value * b) / v),
            _ => None,
        };
        Measured { value: v, se }
    }

    /// Impact angle of the incoming velocity from the surface normal, degrees (positive down-slope), with
    /// its standard error: a vertical drop on an incline β arrives at β.
    pub fn impact_angle(&self) -> Measured {
        let [t, n] = self.v_in_m_s;
        let v2 = t.value * t.value + n.value * n.value;
        let value = t.value.atan2(n.value.abs()).to_degrees();
        let se = match (t.se, n.se) {
            (Some(a), Some(b)) if v2 > 0.0 => {
                Some((n.value * a).hypot(t.value * b) / v2 * 180.0 / std::f64::consts::PI)
            }
            _ => None,
        };
        Measured { value, se }
    }
}

/// What the fitted model predicts for one impact (no standard errors: the model's, at its fitted values).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ShotPrediction {
    /// Coefficient of restitution.
    pub cor: f64,
    /// Effective friction.
    pub mu_eff: f64,
    /// Contact time, s.
    pub contact_time_s: f64,
    /// Maximum penetration, m.
    pub delta_max_m: f64,
    /// Spin after the impact, rad/s.
    pub spin_out_rad_s: f64,
    /// Peak normal contact force, N.
    pub peak_force_n: f64,
    /// Peak normal deceleration of the ball's centre, m/s².
    pub peak_deceleration_m_s2: f64,
}

/// The fitted model of one surface at one angle against the impact speed.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelCurve {
    /// Surface name.
    pub surface: String,
    /// Surface incline, degrees (the ball arriving vertically, as in a drop).
    pub angle_deg: f64,
    /// The prediction at each incoming normal speed, ascending.
    pub points: Vec<CurvePoint>,
}

/// The fitted model at one incoming speed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CurvePoint {
    /// Incoming normal speed |v_n,in|, m/s.
    pub v_in_n_m_s: f64,
    /// The prediction there.
    pub prediction: ShotPrediction,
}

/// The contact force over one impact as the fitted model predicts it.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactForce {
    /// The shot whose incoming velocity was used.
    pub clip: String,
    /// Its surface.
    pub surface: String,
    /// Its incline, degrees.
    pub angle_deg: f64,
    /// Its incoming normal speed |v_n,in|, m/s.
    pub v_in_n_m_s: f64,
    /// Why this shot (e.g. "the shot nearest the session's median impact speed").
    pub why: String,
    /// Evenly spaced instants from touch to separation.
    pub samples: Vec<ForceSample>,
}

/// One instant of a contact.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ForceSample {
    /// Time since touch, s.
    pub t_s: f64,
    /// Penetration δ, m.
    pub delta_m: f64,
    /// Normal contact force, N.
    pub force_n: f64,
}

/// One fitted model parameter.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FitParameter {
    /// Name as the fit spells it (`clay:spring.k`, `damping.b`).
    pub name: String,
    /// Fitted value, in `unit`.
    pub value: f64,
    /// Standard error, in `unit`; `None` when the parameter is not determined.
    pub std_error: Option<f64>,
    /// Confidence interval [low, high], in `unit`, at [`FitSummary::confidence`].
    pub interval: Option<[f64; 2]>,
    /// Unit as text ("N/m", "N·s/m", "" for dimensionless).
    pub unit: String,
    /// True if the value ended on a bound of the fit (its interval then means little).
    pub at_bound: bool,
}

/// The paper's mean absolute COR error for one surface.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SurfaceError {
    /// Surface name.
    pub surface: String,
    /// Shots with a measured COR.
    pub shots: usize,
    /// Mean of |e_sim − e_meas| / e_meas over them, %.
    pub mean_abs_error_pct: f64,
}

/// One oblique shot of the validation (the paper's Figure 9): outgoing velocity measured vs predicted.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ObliqueRow {
    /// Clip name.
    pub clip: String,
    /// Surface name.
    pub surface: String,
    /// Surface incline, degrees.
    pub angle_deg: f64,
    /// Measured outgoing velocity (tangential, normal), m/s.
    pub v_out_measured: [f64; 2],
    /// Predicted outgoing velocity (tangential, normal), m/s.
    pub v_out_predicted: [f64; 2],
    /// |predicted − measured| / |measured| per component (tangential, normal), %.
    pub error_pct: [f64; 2],
}

/// The contact model fitted to the measured trajectories.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FitSummary {
    /// The model's name or file (e.g. "paper (spring + damping + coulomb)").
    pub model_name: String,
    /// Fitted parameters, in the fit's order.
    pub parameters: Vec<FitParameter>,
    /// Confidence level of the intervals, 0–1 (e.g. 0.95).
    pub confidence: f64,
    /// Reduced χ² of the whole fit against the tracking σ, χ²/ν, if known: χ² = Σ((model − measured)/σ)²
    /// over both coordinates of every fitted frame, ν = `dof`.
    pub reduced_chi2: Option<f64>,
    /// Degrees of freedom ν of `reduced_chi2`: residuals − fitted parameters (shared ones and one surface
    /// level per shot), if known.
    pub dof: Option<usize>,
    /// RMS of all position residuals (x and y), m, if known.
    pub rms_m: Option<f64>,
    /// Why the solver stopped, as text (e.g. "converged: relative cost change below 1e-10 after 14
    /// iterations"); empty if unknown.
    pub termination: String,
    /// The paper's mean absolute COR error over all shots with a measured COR, %.
    pub mean_abs_error_pct: Option<f64>,
    /// The same per surface.
    pub by_surface: Vec<SurfaceError>,
    /// Oblique validation rows (shots on an incline with measured outputs).
    pub oblique: Vec<ObliqueRow>,
}

/// The diagnosis' conclusion.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VerdictKind {
    /// A candidate effect explains the residual: the top candidate is named.
    MissingEffect,
    /// The model already fits to the tracking noise.
    #[default]
    NoMissingEffect,
    /// No candidate helps; the residual's signature is shown instead of a guess.
    NoCandidateExplains,
    /// Several candidates explain the residual about equally well: all are named, none is picked.
    Ambiguous,
}

impl VerdictKind {
    /// A short heading for the verdict box.
    pub fn label(self) -> &'static str {
        match self {
            VerdictKind::MissingEffect => "Missing effect found",
            VerdictKind::NoMissingEffect => "No missing effect",
            VerdictKind::NoCandidateExplains => "No candidate explains the residual",
            VerdictKind::Ambiguous => "Several effects explain it about equally well",
        }
    }
}

/// One candidate effect added to the current model and fitted.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// Effect name (as in `model.toml`).
    pub effect: String,
    /// Fit error of the current model, in [`DiagnosisSection::error_metric`].
    pub error_before: f64,
    /// Fit error with this effect added, same metric.
    pub error_after: f64,
    /// BIC(with effect) − BIC(current model); negative favours the effect.
    pub delta_bic: f64,
    /// Held-out error of the current model, same metric, if computed.
    pub heldout_before: Option<f64>,
    /// Held-out error with this effect added, same metric, if computed.
    pub heldout_after: Option<f64>,
}

/// Per-shot error before and after a model change.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ShotBeforeAfter {
    /// Clip name (links to the shot's plots when present).
    pub clip: String,
    /// Surface name.
    pub surface: String,
    /// RMS position residual with the earlier model, m.
    pub rms_before_m: f64,
    /// RMS position residual with the new model, m.
    pub rms_after_m: f64,
}

/// One model version of the store's history.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelVersion {
    /// Version number (1 = first).
    pub version: u32,
    /// Model name or effect list.
    pub model: String,
    /// When it was created, as text (shown verbatim).
    pub created: String,
    /// RMS of all position residuals, m, if known.
    pub rms_m: Option<f64>,
    /// Reduced χ², if known.
    pub chi2_red: Option<f64>,
}

/// Which effect is missing.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosisSection {
    /// The conclusion.
    pub verdict_kind: VerdictKind,
    /// The verdict in a few words, for the summary (e.g. "`hunt_crossley` is missing: held-out error
    /// 87.0 → 12.6 µm"); the summary shows `verdict_text` when empty.
    pub headline: String,
    /// The verdict with its evidence in full (names the effect and the error it removes).
    pub verdict_text: String,
    /// Evidence, or the residual's signature when no candidate explains it: plain sentences (e.g. "COR
    /// falls with impact speed, slope −0.04 per m/s, p < 0.001; the model predicts none").
    pub evidence: Vec<String>,
    /// Where the current model's residual sits, largest χ² share first.
    pub signature: Vec<SignatureRow>,
    /// Name of the candidates' error columns (e.g. "position RMS, held-out by cross-validation").
    pub error_metric: String,
    /// Candidates, best first.
    pub candidates: Vec<Candidate>,
    /// Model versions of the store, oldest first.
    pub model_history: Vec<ModelVersion>,
}

/// The residual of one phase and component.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SignatureRow {
    /// The phase.
    pub phase: Phase,
    /// True for the normal component (y), false for the tangential one (x).
    pub normal: bool,
    /// RMS of the residuals, m.
    pub rms_m: f64,
    /// Its part above the noise, √max(0, RMS² − noise²), m.
    pub systematic_m: f64,
    /// Share of the total χ², 0–1.
    pub chi2_share: f64,
}

/// A verdict as it was given.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EarlierVerdict {
    /// The conclusion.
    pub kind: VerdictKind,
    /// Its sentence.
    pub text: String,
}

/// The previous model fitted to this session against the current one.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelChange {
    /// The earlier model (e.g. "built-in paper model (version 1)").
    pub model_before: String,
    /// The current model.
    pub model_after: String,
    /// Effects in the current model that the earlier one lacked (e.g. `hunt_crossley`).
    pub effects_added: Vec<String>,
    /// Effects of the earlier model that the current one dropped.
    pub effects_removed: Vec<String>,
    /// The diagnosis of the earlier model, when it was kept.
    pub verdict_before: Option<EarlierVerdict>,
    /// Where the earlier model's residual sat.
    pub signature_before: Vec<SignatureRow>,
    /// Where the current model's residual sits.
    pub signature_after: Vec<SignatureRow>,
    /// Per shot present in both fits.
    pub shots: Vec<ShotBeforeAfter>,
    /// RMS of all position residuals with the earlier model, m.
    pub total_rms_before_m: f64,
    /// RMS of all position residuals with the current model, m.
    pub total_rms_after_m: f64,
    /// Reduced χ² of the earlier fit.
    pub reduced_chi2_before: f64,
    /// Reduced χ² of the current fit.
    pub reduced_chi2_after: f64,
}
