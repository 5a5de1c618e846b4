//! Where the model fails: χ² shares by phase and component, and per-shot errors against the conditions.

use crate::{Comparison, Component, ImpactPhase, ShotComparison};
use bouncelab_stats::{LineFit, fit_line, holm, p_text};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF, FisherSnedecor, StudentsT};

/// A per-shot quantity whose trend is tested. Errors are measured − predicted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// COR, measured − predicted.
    CorError,
    /// Effective friction μ, measured − predicted.
    MuError,
    /// Outgoing tangential velocity, (measured − predicted)/|measured|, %.
    VOutTError,
    /// Outgoing normal velocity, (measured − predicted)/|measured|, %.
    VOutNError,
    /// Contact time, measured − predicted, ms.
    ContactTimeError,
    /// RMS of the shot's position residuals, µm.
    ResidualRms,
}

impl Quantity {
    /// Every quantity.
    pub const ALL: [Quantity; 6] = [
        Quantity::CorError,
        Quantity::MuError,
        Quantity::VOutTError,
        Quantity::VOutNError,
        Quantity::ContactTimeError,
        Quantity::ResidualRms,
    ];

    /// Snake-case name.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::CorError => "cor_error",
            Quantity::MuError => "mu_error",
            Quantity::VOutTError => "v_out_t_error_pct",
            Quantity::VOutNError => "v_out_n_error_pct",
            Quantity::ContactTimeError => "contact_time_error_ms",
            Quantity::ResidualRms => "residual_rms_um",
        }
    }

    /// The shot's value, if it has one.
    pub fn of(self, s: &ShotComparison) -> Option<f64> {
        let e = s.output_errors;
        match self {
            Quantity::CorError => e.map(|e| e.cor_abs),
            Quantity::MuError => e.map(|e| e.mu_abs),
            Quantity::VOutTError => e.and_then(|e| e.v_out_t_pct),
            Quantity::VOutNError => e.and_then(|e| e.v_out_n_pct),
            Quantity::ContactTimeError => s.contact_time_error_ms,
            Quantity::ResidualRms => Some(s.rms_m * 1e6),
        }
    }

    /// The model's own prediction of the quantity, for the quantities the model predicts (COR, μ).
    fn predicted(self, s: &ShotComparison) -> Option<f64> {
        match self {
            Quantity::CorError => s.output_errors.map(|e| e.cor_predicted),
            Quantity::MuError => s.output_errors.map(|e| e.mu_predicted),
            _ => None,
        }
    }

    /// (subject, unit, decimals) for sentences.
    fn words(self) -> (&'static str, &'static str, usize) {
        match self {
            Quantity::CorError => ("COR", "", 3),
            Quantity::MuError => ("μ", "", 3),
            Quantity::VOutTError => ("the outgoing tangential speed", " %", 2),
            Quantity::VOutNError => ("the outgoing normal speed", " %", 2),
            Quantity::ContactTimeError => ("the contact time", " ms", 3),
            Quantity::ResidualRms => ("the residual RMS", " µm", 2),
        }
    }

    /// The smallest effect worth a sentence, in the quantity's unit: the instrument's resolution (the
    /// estimator's accuracy targets: COR 0.002, μ 0.005, speeds 0.3 %, contact time 0.05 ms; 2 µm of
    /// residual RMS). Smaller trends stay in the table with their p-values but are not called failures: with
    /// a hundred shots a bias far below what the lab can measure is "significant".
    pub fn material(self) -> f64 {
        match self {
            Quantity::CorError => 0.002,
            Quantity::MuError => 0.005,
            Quantity::VOutTError | Quantity::VOutNError => 0.3,
            Quantity::ContactTimeError => 0.05,
            Quantity::ResidualRms => 2.0,
        }
    }

    /// Spread below which the quantity is taken as constant (numerical noise), in its unit.
    fn tiny(self) -> f64 {
        match self {
            Quantity::VOutTError | Quantity::VOutNError => 1e-4,
            _ => 1e-6,
        }
    }
}

/// A condition a quantity is tested against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Against {
    /// Nothing: is the mean error zero? (one-sample t test; `slope` is the mean).
    Mean,
    /// Impact speed |v_n,in|, m/s.
    ImpactSpeed,
    /// Incline, degrees.
    Incline,
    /// Drop height, m.
    DropHeight,
    /// Camera roll from the surface line's tilt, degrees.
    CameraRoll,
    /// Test surface, as a factor (one-way ANOVA; `slope` is the highest minus the lowest group mean).
    Surface,
}

impl Against {
    /// Every condition.
    pub const ALL: [Against; 6] = [
        Against::Mean,
        Against::ImpactSpeed,
        Against::Incline,
        Against::DropHeight,
        Against::CameraRoll,
        Against::Surface,
    ];

    /// Snake-case name.
    pub fn name(self) -> &'static str {
        match self {
            Against::Mean => "mean",
            Against::ImpactSpeed => "impact_speed",
            Against::Incline => "incline",
            Against::DropHeight => "drop_height",
            Against::CameraRoll => "camera_roll",
            Against::Surface => "surface",
        }
    }

    fn x(self, s: &ShotComparison) -> Option<f64> {
        match self {
            Against::ImpactSpeed => Some(s.impact_speed_m_s),
            Against::Incline => Some(s.incline_deg),
            Against::DropHeight => s.drop_height_m,
            Against::CameraRoll => s.camera_roll_deg,
            Against::Mean | Against::Surface => None,
        }
    }

    /// (words, unit) for sentences.
    fn words(self) -> (&'static str, &'static str) {
        match self {
            Against::ImpactSpeed => ("impact speed", "m/s"),
            Against::Incline => ("incline", "°"),
            Against::DropHeight => ("drop height", "m"),
            Against::CameraRoll => ("camera roll", "°"),
            Against::Mean => ("", ""),
            Against::Surface => ("surface", ""),
        }
    }
}

/// One trend test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trend {
    /// The per-shot quantity.
    pub quantity: Quantity,
    /// What it is tested against.
    pub against: Against,
    /// Slope of the least-squares line, quantity unit per condition unit; the mean for
    /// [`Against::Mean`]; highest − lowest surface mean for [`Against::Surface`].
    pub slope: f64,
    /// Standard error of `slope`.
    pub slope_se: f64,
    /// `slope / slope_se`.
    pub t: f64,
    /// Two-sided p-value (Student t with n − 2, n − 1 d.o.f.; the ANOVA F test for the surface).
    pub p: f64,
    /// `p` adjusted by Holm's method over every test of the report.
    pub p_holm: f64,
    /// The F statistic of the surface ANOVA.
    pub f: Option<f64>,
    /// Shots in the test.
    pub n: usize,
    /// `p_holm < alpha`.
    pub significant: bool,
    /// Size of the effect in the quantity's unit: |mean|, |slope| × the condition's range, or the spread of
    /// the surface means.
    #[serde(default)]
    pub size: f64,
    /// `size` ≥ the quantity's [`Quantity::material`] resolution.
    #[serde(default)]
    pub material: bool,
    /// The finding in one plain sentence.
    pub sentence: String,
}

/// The share of the total χ² held by one phase and component (all shots).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PhaseShare {
    /// The phase.
    pub phase: ImpactPhase,
    /// The component.
    pub component: Component,
    /// Its χ².
    pub chi2: f64,
    /// χ² / total χ² (0–1).
    pub share: f64,
    /// χ² / n.
    pub chi2_red: f64,
    /// Number of residuals.
    pub n: usize,
}

/// Where the model fails.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailureReport {
    /// χ² shares, largest first.
    pub phase_shares: Vec<PhaseShare>,
    /// Every test made, smallest p first.
    pub trends: Vec<Trend>,
    /// The findings in plain language: the χ² location, then one sentence per significant trend, or one
    /// saying there is none.
    pub sentences: Vec<String>,
}

/// Settings of [`diagnose`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiagnoseOptions {
    /// Significance level after Holm's correction (default 0.01).
    pub alpha: f64,
    /// Fewest shots for a test (default 4).
    pub min_shots: usize,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            alpha: 0.01,
            min_shots: 4,
        }
    }
}

/// `+0.012`, `−0.050` (a true minus sign).
fn signed(v: f64, decimals: usize) -> String {
    let s = format!("{:+.*}", decimals, v);
    s.replacen('-', "−", 1)
}

/// The least-squares line `y = a + b·x` (the stats crate's); `None` when x does not vary, n < 3 or a value
/// is not finite.
fn regress(x: &[f64], y: &[f64]) -> Option<LineFit> {
    fit_line(x, y, None).ok()
}

fn mean_sd(y: &[f64]) -> (f64, f64) {
    let n = y.len() as f64;
    let m = y.iter().sum::<f64>() / n;
    let var = if y.len() > 1 {
        y.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, var.sqrt())
}

/// Whether the shots' camera rolls differ by no more than their standard errors say (χ² of their scatter
/// about the weighted mean, p ≥ 0.01), all of them having one. Then the rolls are one roll measured many
/// times, and a trend of an output against them is the tilt's own error carried into the outputs measured
/// in the frame it sets (a tilt 0.01° off turns the outgoing velocity by as much), not anything the model
/// misses: on the clean 144-shot `paper` session, rolls of −0.042° to +0.033° (standard errors ≈ 0.009°)
/// gave the outgoing tangential speed a slope of +20 % per degree, p = 3·10⁻²¹.
fn rolls_within_their_errors(shots: &[&ShotComparison]) -> bool {
    let rolls: Option<Vec<(f64, f64)>> = shots
        .iter()
        .map(|s| Some((s.camera_roll_deg?, s.camera_roll_se_deg.filter(|se| *se > 0.0)?)))
        .collect();
    let Some(rolls) = rolls.filter(|r| r.len() >= 2) else {
        return false;
    };
    let w: f64 = rolls.iter().map(|(_, se)| se.powi(-2)).sum();
    let mean = rolls.iter().map(|(x, se)| x / (se * se)).sum::<f64>() / w;
    let chi2: f64 = rolls.iter().map(|(x, se)| ((x - mean) / se).powi(2)).sum();
    ChiSquared::new((rolls.len() - 1) as f64).is_ok_and(|d| d.sf(chi2) >= ROLLS_DIFFER_P)
}

/// Below this p-value the shots' camera rolls differ (see [`rolls_within_their_errors`]).
const ROLLS_DIFFER_P: f64 = 0.01;

/// One test of quantity `q` against condition `a` over the shots that have `q`; `None` when the shots
/// cannot test it (too few, no spread, one surface …).
fn trend_of(q: Quantity, a: Against, shots: &[ShotComparison], opts: &DiagnoseOptions) -> Option<Trend> {
    let t = TrendTest {
        q,
        a,
        have: shots.iter().filter(|s| q.of(s).is_some()).collect(),
        min_shots: opts.min_shots,
    };
    if a == Against::CameraRoll && rolls_within_their_errors(&t.have) {
        return None;
    }
    match a {
        Against::Mean => t.mean_offset(),
        Against::Surface => t.between_surfaces(),
        _ => t.slope(),
    }
}

/// A quantity tested against a condition over the shots that have it.
struct TrendTest<'a> {
    q: Quantity,
    a: Against,
    have: Vec<&'a ShotComparison>,
    min_shots: usize,
}

impl TrendTest<'_> {
    /// The trend's record from its figures (Holm's adjustment and significance come later).
    #[allow(clippy::too_many_arguments)]
    fn trend(&self, slope: f64, se: f64, p: f64, f: Option<f64>, n: usize, size: f64, sentence: String) -> Trend {
        Trend {
            quantity: self.q,
            against: self.a,
            slope,
            slope_se: se,
            t: slope / se,
            p,
            p_holm: p,
            f,
            n,
            significant: false,
            size,
            material: size >= self.q.material(),
            sentence,
        }
    }

    /// Does the model miss the quantity on average? A one-sample t test of its mean.
    fn mean_offset(&self) -> Option<Trend> {
        let q = self.q;
        let (subject, unit, dec) = q.words();
        if q == Quantity::ResidualRms {
            return None;
        }
        let y: Vec<f64> = self.have.iter().filter_map(|s| q.of(s)).collect();
        if y.len() < self.min_shots {
            return None;
        }
        let (m, sd) = mean_sd(&y);
        if sd < q.tiny() {
            return None;
        }
        let se = sd / (y.len() as f64).sqrt();
        let p = StudentsT::new(0.0, 1.0, (y.len() - 1) as f64)
            .map(|d| 2.0 * d.sf((m / se).abs()))
            .unwrap_or(f64::NAN);
        let verb = if m < 0.0 { "over-predicts" } else { "under-predicts" };
        let sentence = format!(
            "The model {verb} {subject} by {:.*}{unit} on average ({}, n = {}).",
            dec,
            m.abs(),
            p_text(p),
            y.len()
        );
        Some(self.trend(m, se, p, None, y.len(), m.abs(), sentence))
    }

    /// Does the quantity differ between surfaces? One-way ANOVA, the slope being the highest surface's
    /// mean minus the lowest's.
    fn between_surfaces(&self) -> Option<Trend> {
        let q = self.q;
        let (subject, unit, dec) = q.words();
        let mut groups: Vec<(String, Vec<f64>)> = Vec::new();
        for s in &self.have {
            let v = q.of(s).expect("filtered");
            match groups.iter_mut().find(|(g, _)| *g == s.surface) {
                Some((_, vs)) => vs.push(v),
                None => groups.push((s.surface.clone(), vec![v])),
            }
        }
        let n: usize = groups.iter().map(|(_, v)| v.len()).sum();
        let k = groups.len();
        if k < 2 || n <= k || n < self.min_shots {
            return None;
        }
        let all: Vec<f64> = groups.iter().flat_map(|(_, v)| v.iter().copied()).collect();
        let (grand, sd) = mean_sd(&all);
        if sd < q.tiny() {
            return None;
        }
        let means: Vec<f64> = groups.iter().map(|(_, v)| mean_sd(v).0).collect();
        let ssb: f64 = groups
            .iter()
            .zip(&means)
            .map(|((_, v), m)| v.len() as f64 * (m - grand).powi(2))
            .sum();
        let ssw: f64 = groups
            .iter()
            .zip(&means)
            .map(|((_, v), m)| v.iter().map(|x| (x - m).powi(2)).sum::<f64>())
            .sum();
        let (d1, d2) = ((k - 1) as f64, (n - k) as f64);
        let msw = ssw / d2;
        let f = (ssb / d1) / msw;
        let p = if msw > 0.0 {
            FisherSnedecor::new(d1, d2).map(|d| d.sf(f)).unwrap_or(f64::NAN)
        } else {
            0.0
        };
        let hi = (0..k).max_by(|&i, &j| means[i].total_cmp(&means[j])).expect("k ≥ 2");
        let lo = (0..k).min_by(|&i, &j| means[i].total_cmp(&means[j])).expect("k ≥ 2");
        let slope = means[hi] - means[lo];
        let se = (msw * (1.0 / groups[hi].1.len() as f64 + 1.0 / groups[lo].1.len() as f64)).sqrt();
        let what = if q == Quantity::ResidualRms {
            subject.to_string()
        } else {
            format!("{subject} relative to the model (measured − predicted)")
        };
        let sentence = format!(
            "{} differs between surfaces (F = {f:.1}, {}): highest on {} ({}{unit}), lowest on {} ({}{unit}).",
            capitalise(&what),
            p_text(p),
            groups[hi].0,
            signed(means[hi], dec),
            groups[lo].0,
            signed(means[lo], dec)
        );
        Some(self.trend(slope, se, p, Some(f), n, slope.abs(), sentence))
    }

    /// Does the quantity move with the condition? The least-squares line's slope, with the model's own
    /// slope in the sentence.
    fn slope(&self) -> Option<Trend> {
        let (q, a) = (self.q, self.a);
        let (subject, unit, dec) = q.words();
        let (xw, xu) = a.words();
        let pairs: Vec<(f64, f64, Option<f64>)> = self
            .have
            .iter()
            .filter_map(|s| Some((a.x(s)?, q.of(s)?, q.predicted(s))))
            .collect();
        if pairs.len() < self.min_shots {
            return None;
        }
        let x: Vec<f64> = pairs.iter().map(|p| p.0).collect();
        let y: Vec<f64> = pairs.iter().map(|p| p.1).collect();
        if mean_sd(&y).1 < q.tiny() {
            return None;
        }
        let line = regress(&x, &y)?;
        let dir = if line.slope < 0.0 { "falls" } else { "rises" };
        let per = format!("{}{unit} per {xu}", signed(line.slope, dec));
        let mut sentence = if q == Quantity::ResidualRms {
            format!("{} {dir} with {xw}, {per} ({}).", capitalise(subject), p_text(line.p))
        } else {
            format!(
                "{} {dir} with {xw} relative to the model, {per} (measured − predicted; {})",
                capitalise(subject),
                p_text(line.p)
            )
        };
        if q != Quantity::ResidualRms {
            let pred: Vec<f64> = pairs.iter().filter_map(|p| p.2).collect();
            if pred.len() == x.len() {
                match regress(&x, &pred) {
                    Some(pl) if pl.slope.abs() >= 0.1 * line.slope.abs() => {
                        sentence.push_str(&format!("; the model predicts {} per {xu}.", signed(pl.slope, dec)))
                    }
                    _ => sentence.push_str("; the model predicts a constant."),
                }
            } else {
                sentence.push('.');
            }
        }
        let range =
            x.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - x.iter().cloned().fold(f64::INFINITY, f64::min);
        Some(self.trend(
            line.slope,
            line.slope_se,
            line.p,
            None,
            pairs.len(),
            (line.slope * range).abs(),
            sentence,
        ))
    }
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        // Symbols keep their case: "μ" is not "Μ".
        Some(f) if !f.is_ascii() => s.to_string(),
        Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
        None => String::new(),
    }
}

/// Locates where the model fails: the χ² share of every phase and component, and every per-shot quantity
/// tested against every condition the shots carry (see `docs/compare.md` for the rules).
pub fn diagnose(comparison: &Comparison, opts: &DiagnoseOptions) -> FailureReport {
    let total: f64 = comparison.overall.iter().map(|s| s.chi2).sum();
    let mut phase_shares: Vec<PhaseShare> = comparison
        .overall
        .iter()
        .map(|s| PhaseShare {
            phase: s.phase,
            component: s.component,
            chi2: s.chi2,
            share: if total > 0.0 { s.chi2 / total } else { 0.0 },
            chi2_red: s.chi2_red,
            n: s.n,
        })
        .collect();
    phase_shares.sort_by(|a, b| b.chi2.total_cmp(&a.chi2));

    let mut trends: Vec<Trend> = Quantity::ALL
        .iter()
        .flat_map(|q| Against::ALL.iter().map(move |a| (*q, *a)))
        .filter_map(|(q, a)| trend_of(q, a, &comparison.shots, opts))
        .collect();
    trends.sort_by(|a, b| a.p.total_cmp(&b.p));
    // Holm's step-down adjustment over the whole family.
    let m = trends.len();
    let ps: Vec<f64> = trends.iter().map(|t| t.p).collect();
    for (t, p) in trends.iter_mut().zip(holm(&ps)) {
        t.p_holm = p;
        t.significant = p < opts.alpha;
    }

    let mut sentences = Vec::new();
    let dof = comparison.n_residuals.saturating_sub(comparison.n_params).max(1) as f64;
    let chi2_red = comparison.chi2_red_total;
    if chi2_red <= 1.0 + 3.0 * (2.0 / dof).sqrt() {
        sentences.push(format!(
            "The trajectories fit to the tracking noise (reduced χ² = {chi2_red:.2})."
        ));
    } else if let Some(top) = phase_shares.first() {
        sentences.push(format!(
            "Reduced χ² = {chi2_red:.2}; most of χ² is in the {} component during {}: {:.0} % (its reduced χ² = {:.1}).",
            top.component.name(),
            top.phase.words(),
            top.share * 100.0,
            top.chi2_red
        ));
    }
    let significant: Vec<&Trend> = trends.iter().filter(|t| t.significant && t.material).collect();
    let immaterial = trends.iter().filter(|t| t.significant && !t.material).count();
    if significant.is_empty() && immaterial > 0 {
        sentences.push(format!(
            "No material trend across conditions: {immaterial} test(s) are significant but below the measurement's resolution (COR 0.002, μ 0.005, speeds 0.3 %, contact time 0.05 ms)."
        ));
    } else if significant.is_empty() {
        match trends.first() {
            Some(t) => sentences.push(format!(
                "No trend across conditions (smallest {} over {m} tests, {:.3} after Holm's correction).",
                p_text(t.p),
                t.p_holm
            )),
            None => sentences.push("No trend could be tested (too few shots or conditions).".into()),
        }
    } else {
        sentences.extend(significant.iter().map(|t| t.sentence.clone()));
    }
    FailureReport {
        phase_shares,
        trends,
        sentences,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{OutputErrors, ShotComparison};

    fn shot(surface: &str, speed: f64, cor_err: f64) -> ShotComparison {
        ShotComparison {
            shot: format!("{surface}-{speed}"),
            surface: surface.into(),
            incline_deg: 0.0,
            impact_speed_m_s: speed,
            drop_height_m: None,
            camera_roll_deg: None,
            camera_roll_se_deg: None,
            contact_time_error_ms: None,
            residuals: Vec::new(),
            by_phase: Vec::new(),
            output_errors: Some(OutputErrors {
                v_out_t_pct: None,
                v_out_n_pct: None,
                cor_pct: 0.0,
                cor_abs: cor_err,
                mu_abs: 0.0,
                cor_measured: 0.7 + cor_err,
                cor_predicted: 0.7,
                mu_measured: 0.0,
                mu_predicted: 0.0,
                v_out_measured: [0.0, 1.0],
                v_out_predicted: [0.0, 1.0],
            }),
            rms_m: 0.0,
            chi2: 0.0,
            n: 0,
        }
    }

    /// A trend far below the instrument's resolution is significant with enough shots but is not called a
    /// failure: it stays in the table, marked immaterial, and the sentence says so.
    #[test]
    fn significant_but_immaterial_trends_are_not_failures() {
        // 40 shots, COR error 0.0003 on average with scatter 0.0001: p ≪ 0.001, size 0.0003 < 0.002.
        let shots: Vec<ShotComparison> = (0..40)
            .map(|i| shot("clay", 1.0 + 0.05 * i as f64, 0.0003 + 0.0001 * ((i % 3) as f64 - 1.0)))
            .collect();
        let comparison = Comparison {
            shots,
            overall: Vec::new(),
            chi2: 0.0,
            n_residuals: 100,
            n_params: 2,
            chi2_red_total: 1.0,
        };
        let r = diagnose(&comparison, &DiagnoseOptions::default());
        let mean = r
            .trends
            .iter()
            .find(|t| t.quantity == Quantity::CorError && t.against == Against::Mean)
            .unwrap();
        assert!(mean.significant && !mean.material, "{mean:?}");
        assert!(
            r.sentences.iter().any(|s| s.starts_with("No material trend")),
            "{:?}",
            r.sentences
        );
        assert!(
            !r.sentences.iter().any(|s| s.contains("over-predicts")),
            "{:?}",
            r.sentences
        );
        assert_eq!(capitalise("μ rises"), "μ rises");
    }

    /// A COR error that follows each shot's measured roll: no trend when the rolls are one roll measured
    /// with its error (that is the error carried into the outputs), a trend when the camera did turn.
    #[test]
    fn a_trend_against_camera_roll_needs_rolls_that_differ_beyond_their_errors() {
        let trend = |spread: f64| {
            let shots: Vec<ShotComparison> = (0..24)
                .map(|i| {
                    let roll = spread * ((i * 7 % 5) as f64 - 2.0) + 0.01 * ((i * 3 % 4) as f64 - 1.5);
                    ShotComparison {
                        camera_roll_deg: Some(roll),
                        camera_roll_se_deg: Some(0.01),
                        ..shot("clay", 2.0, 0.2 * roll + 0.0002 * ((i % 3) as f64 - 1.0))
                    }
                })
                .collect();
            trend_of(
                Quantity::CorError,
                Against::CameraRoll,
                &shots,
                &DiagnoseOptions::default(),
            )
        };
        assert!(trend(0.0).is_none());
        let t = trend(0.5).unwrap();
        assert!((t.slope - 0.2).abs() < 0.01 && t.p < 1e-6, "{t:?}");
    }

    /// The slope, its standard error and p against a hand computation (R: `summary(lm(y ~ x))`).
    #[test]
    fn regression_matches_hand_computation() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        let y = [1.1, 1.9, 3.2, 3.8, 5.1];
        let l = regress(&x, &y).unwrap();
        // Sxx = 10, Sxy = 9.9, slope 0.99, SSE = 0.107, se = sqrt(0.107/3/10).
        assert!((l.slope - 0.99).abs() < 1e-12);
        assert!((l.slope_se - (0.107f64 / 30.0).sqrt()).abs() < 1e-12);
        // t = 16.577 with 3 d.o.f.: two-sided p = 4.8e-4.
        assert!((l.p - 4.8e-4).abs() < 0.2e-4, "{}", l.p);
        assert!(regress(&[2.0; 5], &y).is_none());
    }

    /// Reference test: with two surfaces, the ANOVA F equals the square of the pooled two-sample t, and
    /// the p-values agree.
    #[test]
    fn anova_of_two_groups_is_the_t_test() {
        let vals_a = [0.01, 0.02, -0.01, 0.015];
        let vals_b = [-0.02, -0.01, -0.03, 0.0, -0.015];
        let mut shots: Vec<ShotComparison> = vals_a.iter().map(|v| shot("clay", 2.0, *v)).collect();
        shots.extend(vals_b.iter().map(|v| shot("tape", 2.0, *v)));
        let t = trend_of(
            Quantity::CorError,
            Against::Surface,
            &shots,
            &DiagnoseOptions::default(),
        )
        .unwrap();
        let f = t.f.unwrap();
        assert!((f - t.t * t.t).abs() < 1e-9 * f, "F {f} t² {}", t.t * t.t);
        let st = StudentsT::new(0.0, 1.0, 7.0).unwrap();
        assert!((t.p - 2.0 * st.sf(t.t.abs())).abs() < 1e-9);
        assert!(t.sentence.contains("highest on clay"), "{}", t.sentence);
    }

    /// Holm: the adjusted p-values are monotone, ≥ the raw ones and ≤ 1; an exact linear trend is found.
    #[test]
    fn holm_adjustment_and_sentences() {
        let shots: Vec<ShotComparison> = (0..8)
            .map(|i| {
                shot(
                    "clay",
                    1.0 + i as f64 * 0.5,
                    -0.05 * (1.0 + i as f64 * 0.5) + 0.001 * ((i * 7 % 5) as f64),
                )
            })
            .collect();
        let comparison = Comparison {
            shots,
            overall: Vec::new(),
            chi2: 0.0,
            n_residuals: 0,
            n_params: 0,
            chi2_red_total: f64::NAN,
        };
        let r = diagnose(&comparison, &DiagnoseOptions::default());
        let mut last = 0.0;
        for t in &r.trends {
            assert!(t.p_holm >= t.p && t.p_holm <= 1.0 && t.p_holm >= last);
            last = t.p_holm;
        }
        let top = &r.trends[0];
        assert_eq!((top.quantity, top.against), (Quantity::CorError, Against::ImpactSpeed));
        assert!(
            top.sentence
                .starts_with("COR falls with impact speed relative to the model, −0.050 per m/s")
        );
        assert!(r.sentences.contains(&top.sentence));
    }
}
