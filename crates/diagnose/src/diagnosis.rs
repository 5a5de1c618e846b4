//! `diagnosis.json`: the verdict, the ranked candidates with their evidence, the current model's fit and
//! the signature of its residual.

use crate::FitSummary;
use bouncelab_compare::{Component, ImpactPhase, Trend};
use serde::{Deserialize, Serialize};

/// What the search concluded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VerdictKind {
    /// One candidate explains the residual and no other comes close: it is named.
    MissingEffect,
    /// Several candidates explain the residual about equally well: all are named, none is picked.
    Ambiguous,
    /// The current model fits to the noise (within the tolerance): nothing is missing.
    NoMissingEffect,
    /// The current model misfits but no candidate removes most of the misfit: the residual's signature
    /// is shown instead of a name.
    NoneExplains,
}

impl VerdictKind {
    /// Snake-case name, as in `diagnosis.json`.
    pub fn name(self) -> &'static str {
        match self {
            VerdictKind::MissingEffect => "missing_effect",
            VerdictKind::Ambiguous => "ambiguous",
            VerdictKind::NoMissingEffect => "no_missing_effect",
            VerdictKind::NoneExplains => "none_explains",
        }
    }
}

/// The verdict.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Verdict {
    /// What was concluded.
    pub kind: VerdictKind,
    /// The named effect (`missing_effect`), or the best of the tied ones (`ambiguous`); `None` otherwise.
    pub effect: Option<String>,
    /// Every named effect, best first (one for `missing_effect`, several for `ambiguous`, none otherwise).
    pub effects: Vec<String>,
    /// One paragraph in plain language: the conclusion and its evidence.
    pub sentence: String,
}

/// Which tests a candidate passed (all four for it to be named).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Checks {
    /// ΔBIC ≤ −`min_delta_bic`.
    pub bic: bool,
    /// Held-out error lower, paired test across shots significant after Holm's correction.
    pub heldout: bool,
    /// Switch parameter at least `min_param_z` standard errors from its neutral value, not on a bound.
    pub parameter: bool,
    /// Removes at least `tolerance_m` of held-out error (in quadrature), and leaves less than `tolerance_m`
    /// of systematic held-out error or removes at least `explained_fraction` of the current model's.
    pub material: bool,
}

impl Checks {
    /// True when every check passed.
    pub fn all(&self) -> bool {
        self.bic && self.heldout && self.parameter && self.material
    }
}

/// One candidate effect, added to the current model and fitted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// The effect's name.
    pub effect: String,
    /// Rank, 1 = best (explaining candidates first, by ΔBIC; then the others by held-out error; failed
    /// fits last).
    pub rank: usize,
    /// True if it passed every check.
    pub explains: bool,
    /// True if it passed every check but completeness (its held-out test before Holm's correction):
    /// significant, with a clear parameter, removing at least the floor of held-out error, but leaving more
    /// than the floor (and more than `1 − explained_fraction` of the systematic part): part of what is
    /// missing, not all.
    #[serde(default)]
    pub partly_explains: bool,
    /// The checks.
    pub checks: Checks,
    /// Why it did not pass, one phrase per failed check (empty when it explains).
    pub reasons: Vec<String>,
    /// Position RMS of the current model (x and y, all frames), m.
    pub error_before: f64,
    /// Held-out position RMS of the current model (cross-validation across shots), m.
    pub heldout_error_before: f64,
    /// The candidate's switch parameter.
    pub param: String,
    /// Its neutral value (the effect does nothing there).
    pub neutral: f64,
    /// The evidence, when the fit succeeded (its fields appear at this level in the JSON).
    #[serde(flatten)]
    pub evidence: Option<Evidence>,
    /// Why the fit failed (names the shot), if it did.
    pub failed: Option<String>,
    /// Wall time of its fit and cross-validation, s.
    pub seconds: f64,
}

/// What a candidate's fit showed, against the current model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evidence {
    /// Position RMS with the candidate, m.
    pub error_after: f64,
    /// `error_before / error_after`.
    pub error_fall: f64,
    /// BIC(with candidate) − BIC(current), with the noise variance estimated from the residuals
    /// (`n·ln(RSS/n) + p·ln n`, σ-weighted RSS); negative favours the candidate.
    pub delta_bic: f64,
    /// Held-out position RMS with the candidate, m; without cross-validation (`cross_validated` false),
    /// the fit's own RMS, a lower bound of it.
    pub heldout_error_after: f64,
    /// Mean over shots of ln(held-out χ² before / after): > 0 when the candidate predicts unseen shots
    /// better; σ cancels in the ratio.
    pub heldout_log_ratio: f64,
    /// One-sided p of the paired t test of those log ratios across shots.
    pub heldout_p: f64,
    /// `heldout_p` adjusted by Holm's method over the candidates.
    pub heldout_p_holm: f64,
    /// Shots predicted better held out, and shots compared.
    pub shots_improved: [usize; 2],
    /// Fraction of the current model's systematic held-out mean square (above the noise, and at least the
    /// tolerance squared) that the candidate removes (≤ 1).
    pub explained_fraction: f64,
    /// Systematic part of the residual left with the candidate, `√max(0, RMS² − noise²)`, m.
    pub systematic_after_m: f64,
    /// χ² / dof with the candidate, against the tracker's σ.
    pub chi2_red_after: f64,
    /// Mean square residual with the candidate over the noise variance (a reduced χ² that does not trust
    /// the stated σ).
    pub chi2_red_noise_after: f64,
    /// The switch parameter's fitted value, in its unit.
    pub param_value: f64,
    /// Its 95 % interval, when determined.
    pub param_interval: Option<[f64; 2]>,
    /// Its distance from the neutral value in standard errors (`None` when not determined).
    pub param_z: Option<f64>,
    /// The detection limit: the smallest distance of the switch parameter from its neutral value (in its
    /// unit) at which this session would have named the effect, linearised at the fit: the larger of
    /// `min_param_z` standard errors and the size whose change of the trajectories, after the other
    /// parameters are refitted, has an RMS equal to the floor. `None` when the parameter is not determined
    /// or the candidate frees more than one parameter of its own.
    #[serde(default)]
    pub detection_limit: Option<f64>,
    /// False when the candidate was not cross-validated: its fit to all shots already failed the BIC check,
    /// so it could be neither named nor said to explain part (the folds would cost six fits and decide
    /// nothing); its held-out test then counts as failed.
    #[serde(default = "yes")]
    pub cross_validated: bool,
    /// True when the candidate is reported at its switch's neutral value, i.e. as the current model: no
    /// value on the scan of its start fitted better, or its fit ended above the neutral value's χ² (a
    /// response that rings as the parameter moves has local minima the fit can stop in).
    #[serde(default)]
    pub kept_at_neutral: bool,
    /// The fit with the candidate (every parameter, base ones refitted too, with intervals).
    pub fit: FitSummary,
}

/// The shot with the largest share of a residual's squares (one phase and component's, or the whole
/// position residual's), and that residual without it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorstShot {
    /// The shot (clip) name.
    pub shot: String,
    /// Its RMS there, m.
    pub rms_m: f64,
    /// The residual's systematic part over the other shots, m.
    pub systematic_without_m: f64,
}

/// The systematic residual of one phase and component of the current model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseResidual {
    /// The phase.
    pub phase: ImpactPhase,
    /// The component.
    pub component: Component,
    /// Residuals.
    pub n: usize,
    /// RMS, m.
    pub rms_m: f64,
    /// Systematic part `√max(0, RMS² − noise²)`, m.
    pub systematic_m: f64,
    /// Share of the total χ² (0–1).
    pub chi2_share: f64,
    /// χ² / n against the tracker's σ.
    pub chi2_red: f64,
    /// The shot that weighs most here, with the systematic part without it; `None` with fewer than
    /// [`crate::MIN_SHOTS_FOR_ONE_SHOT`] shots in the phase.
    #[serde(default)]
    pub worst_shot: Option<WorstShot>,
}

/// Where the current model's residual sits: what a person looks at when no candidate explains it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Signature {
    /// Per phase and component, largest χ² share first.
    pub phases: Vec<PhaseResidual>,
    /// The shot that weighs most in the whole position residual, with the systematic part without it;
    /// `None` with fewer than [`crate::MIN_SHOTS_FOR_ONE_SHOT`] shots.
    #[serde(default)]
    pub worst_shot: Option<WorstShot>,
    /// Significant trends across conditions (Holm-corrected), smallest p first.
    pub trends: Vec<Trend>,
    /// The compare crate's sentences: where χ² sits, then one per significant trend.
    pub sentences: Vec<String>,
}

/// The current model fitted to all shots.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Baseline {
    /// The fit.
    pub fit: FitSummary,
    /// Held-out position RMS (cross-validation across shots), m.
    pub heldout_error_m: f64,
    /// Systematic part of the residual, `√max(0, RMS² − noise²)`, m.
    pub systematic_m: f64,
    /// True if it misfits: systematic part above the floor, a phase above the per-phase tolerance (both in
    /// [`Thresholds`]), or a significant trend of an output error.
    pub misfit: bool,
    /// Why it misfits, one phrase each.
    pub misfit_reasons: Vec<String>,
    /// Wall time of its fit and cross-validation, s.
    pub seconds: f64,
}

/// The noise the decisions are measured against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Noise {
    /// White-noise level of the positions used by the decisions, m.
    pub noise_m: f64,
    /// How it was obtained: "residual third differences" or "given".
    pub source: NoiseSource,
    /// RMS of the σ the tracker stated, m.
    pub stated_sigma_m: f64,
    /// `noise_m / stated_sigma_m`: how far the stated σ is off.
    pub ratio: f64,
}

/// Where the noise level came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// Estimated from the current model's residuals (median absolute third difference).
    ThirdDifferences,
    /// Given in [`SearchOptions::noise_m`](crate::SearchOptions::noise_m).
    Given,
    /// The stated σ (too few equally spaced frames to estimate it).
    Stated,
}

/// The thresholds the verdict used: those of [`SearchOptions`](crate::SearchOptions), the per-phase
/// tolerance as the learned floor raises it (the floor itself is [`Floor::floor_m`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Thresholds {
    /// Significance level.
    pub alpha: f64,
    /// Least BIC fall.
    pub min_delta_bic: f64,
    /// Least parameter distance from neutral, standard errors.
    pub min_param_z: f64,
    /// Systematic residual tolerated, m: the session's floor ([`Diagnosis::floor`]).
    pub tolerance_m: f64,
    /// Systematic residual tolerated per phase and component, m.
    pub phase_tolerance_m: f64,
    /// Least fraction of the systematic error a named candidate removes.
    pub explained_fraction: f64,
}

fn yes() -> bool {
    true
}

/// The measurement floor: the systematic residual below which a misfit is "no missing effect", learned
/// from the session's free flight (see `docs/diagnosis.md`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Floor {
    /// The floor the decisions use, m: `flight_systematic_m`, `rim_change_m` and `contact_allowance_m` in
    /// quadrature, plus [`FLOOR_MARGIN_SE`](crate::FLOOR_MARGIN_SE) of its standard errors (`floor_se_m`).
    pub floor_m: f64,
    /// Systematic part of the flight residuals after each arc's own fit (exact physics), pooled over every
    /// shot, m: the tracker's own structure; `None` when no arc was long enough or the floor was given.
    pub flight_systematic_m: Option<f64>,
    /// The tracker's error that changes between a shot's two flights, which each arc's own fit hides, m:
    /// from the change of the ball's measured radius between them (see `floor.rs`); `None` when no shot's
    /// was measured or the floor was given.
    #[serde(default)]
    pub rim_change_m: Option<f64>,
    /// Standard error of the learned parts of the floor, m (`floor_m` holds three of it).
    #[serde(default)]
    pub floor_se_m: f64,
    /// The tracker's extra error in contact, which the flight cannot show (the option `tolerance_m`), m.
    pub contact_allowance_m: f64,
    /// Per shot (input order): the systematic part of its flight residuals, m (`None`: no arc long enough).
    pub per_shot_m: Vec<Option<f64>>,
    /// Flight frames measured.
    pub flight_frames: usize,
}

/// Everything the search found; `diagnosis.json` is its serde serialisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diagnosis {
    /// The conclusion.
    pub verdict: Verdict,
    /// Every candidate tried, ranked.
    pub candidates: Vec<Candidate>,
    /// The current model.
    pub baseline: Baseline,
    /// Where the current model's residual sits.
    pub signature: Signature,
    /// The noise level.
    pub noise: Noise,
    /// The measurement floor the decisions used.
    #[serde(default)]
    pub floor: Floor,
    /// Shots used.
    pub shots: usize,
    /// Folds of the cross-validation.
    pub folds: usize,
    /// The thresholds.
    pub thresholds: Thresholds,
    /// A formula term proposed when no library effect explains the misfit (`none_explains` only, and only
    /// when one removes a material part of it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub proposal: Option<crate::TermProposal>,
    /// The search continued from the model with the first effect added (at its fitted values), when that
    /// effect left a systematic misfit above the floor or explained only part of it: the second search's
    /// diagnosis. The verdict's `effects` then lists both (`[a, b]`), each with its evidence in its own
    /// search's candidates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub then: Option<Box<Diagnosis>>,
    /// Wall time of the search, s.
    pub seconds: f64,
}

impl Diagnosis {
    /// `diagnosis.json` text (pretty-printed).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a diagnosis serialises")
    }

    /// The candidate for `effect`.
    pub fn candidate(&self, effect: &str) -> Option<&Candidate> {
        self.candidates.iter().find(|c| c.effect == effect)
    }
}
