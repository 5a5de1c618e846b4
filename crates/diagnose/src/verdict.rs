//! The decision rule: which candidates explain the residual, their ranking, and the verdict in words.

use crate::diagnosis::{Baseline, Candidate, Floor, PhaseResidual, Signature, Verdict, VerdictKind, WorstShot};
use crate::options::SearchOptions;
use crate::stats;
use bouncelab_compare::Quantity;
use bouncelab_model::builtin;
use bouncelab_stats::p_text;

/// What the decision needs besides the candidates.
pub(crate) struct Inputs<'a> {
    pub options: &'a SearchOptions,
    pub noise_m: f64,
    pub floor: &'a Floor,
    pub baseline: Baseline,
    pub signature: Signature,
    /// Per candidate (in the order given), per shot: held-out χ².
    pub heldout_chi2: Vec<Vec<Option<f64>>>,
    /// Per candidate, per shot: held-out mean square position residual, m².
    pub heldout_ms: Vec<Vec<Option<f64>>>,
}

fn um(m: f64) -> String {
    let v = m * 1e6;
    if v >= 100.0 {
        format!("{v:.0} µm")
    } else {
        format!("{v:.1} µm")
    }
}

/// The floor in words: its value and where it comes from.
fn floor_words(f: &Floor) -> String {
    match f.flight_systematic_m {
        Some(s) => {
            let rim = f.rim_change_m.map_or(String::new(), |r| {
                format!(", the rim's change between the flights {}", um(r))
            });
            let margin = if f.floor_se_m > 0.0 {
                format!(
                    ", plus {} of its standard errors, {}",
                    crate::FLOOR_MARGIN_SE,
                    um(crate::FLOOR_MARGIN_SE * f.floor_se_m)
                )
            } else {
                String::new()
            };
            format!(
                "the {} floor (the flight's own residual structure {}{rim} and {} allowed for tracking in contact, in quadrature{margin})",
                um(f.floor_m),
                um(s),
                um(f.contact_allowance_m)
            )
        }
        None => match f.rim_change_m {
            Some(r) => format!(
                "the {} floor (the rim's change between the flights {} and {} allowed for tracking in contact, in quadrature, plus {} of its standard errors)",
                um(f.floor_m),
                um(r),
                um(f.contact_allowance_m),
                crate::FLOOR_MARGIN_SE
            ),
            None => format!("the {} floor", um(f.floor_m)),
        },
    }
}

/// How far a phase and component may misfit before it alone says the model misfits: the option
/// `phase_tolerance_m`, or three times the floor's estimate (without its margin) when the session's
/// tracking is that much worse (a phase holds a few of the frames, and the tracker's own error differs by
/// phase).
pub(crate) fn phase_tolerance(o: &SearchOptions, f: &Floor) -> f64 {
    let estimate = f.floor_m - crate::FLOOR_MARGIN_SE * f.floor_se_m;
    o.phase_tolerance_m.max(PHASE_FLOORS * estimate)
}

/// Floors a phase's systematic residual may reach (see [`phase_tolerance`]): the default per-phase tolerance
/// is about three times the floor of our clean rendered sessions.
const PHASE_FLOORS: f64 = 3.0;

/// Fewest shots with residuals in a phase for its misfit to be set down to one shot ([`one_shot_s`]): with
/// fewer, one shot is too large a part of the evidence to set aside.
pub const MIN_SHOTS_FOR_ONE_SHOT: usize = 6;

/// The shot a phase's misfit belongs to, when the phase misfits only with it: above `phase_tol` with every
/// shot and within it without the one that weighs most there ([`WorstShot`]). A missing effect acts on
/// every shot of its surface and condition, so it misfits without any one of them; one shot's own misfit
/// (its track off the ball in contact, a frame the tracker mistook) does not, and is not the model's.
fn one_shot_s(ph: &PhaseResidual, phase_tol: f64) -> Option<&WorstShot> {
    ph.worst_shot
        .as_ref()
        .filter(|w| ph.systematic_m > phase_tol && w.systematic_without_m <= phase_tol)
}

/// The shot the whole residual's systematic part belongs to: above the floor `tol` with every shot and
/// within it without the one that weighs most ([`Signature::worst_shot`]), for the reason [`one_shot_s`] gives.
fn whole_one_shot_s<'a>(baseline: &Baseline, signature: &'a Signature, tol: f64) -> Option<&'a WorstShot> {
    signature
        .worst_shot
        .as_ref()
        .filter(|w| baseline.systematic_m > tol && w.systematic_without_m <= tol)
}

/// The sentence for a whole residual whose systematic part is one shot's ([`whole_one_shot_s`]), then one
/// per phase whose misfit is one shot's ([`one_shot_s`]), naming the shot.
fn one_shot_words(baseline: &Baseline, signature: &Signature, tol: f64, phase_tol: f64) -> String {
    let whole = whole_one_shot_s(baseline, signature, tol).map(|w| {
        format!(
            " The whole residual's systematic part, {}, is one shot's: `{}` (RMS {}); without it {}, within the {} floor, so it is not taken for the model's: look at that shot's track.",
            um(baseline.systematic_m),
            w.shot,
            um(w.rms_m),
            um(w.systematic_without_m),
            um(tol)
        )
    });
    let phases = signature
        .phases
        .iter()
        .filter_map(|ph| {
            let w = one_shot_s(ph, phase_tol)?;
            Some(format!(
                " The {} {} residual's systematic part, {}, is one shot's: `{}` (RMS {} there); without it {}, within the {} per-phase tolerance, so it is not taken for the model's: look at that shot's track.",
                ph.component.name(),
                ph.phase.words(),
                um(ph.systematic_m),
                w.shot,
                um(w.rms_m),
                um(w.systematic_without_m),
                um(phase_tol)
            ))
        })
        .collect::<String>();
    whole.unwrap_or_default() + &phases
}

fn num(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.3e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.4}")
    }
}

/// Marks the checks of every candidate, ranks them, and concludes; returns the verdict and the baseline
/// and signature with the misfit filled in.
pub(crate) fn decide(cands: &mut Vec<Candidate>, inp: Inputs<'_>) -> (Verdict, Baseline, Signature) {
    let o = inp.options;
    let noise = inp.noise_m;
    let mut baseline = inp.baseline.clone();
    let signature = inp.signature.clone();

    let reasons = misfit_reasons(&baseline, &signature, &inp);
    baseline.misfit = !reasons.is_empty();
    baseline.misfit_reasons = reasons;

    for c in cands.iter_mut() {
        check(c, o, noise);
    }
    let order = ranking(cands);
    let (named, tie_words) = ties(cands, &order, &inp);

    let ranked: Vec<Candidate> = order
        .iter()
        .enumerate()
        .map(|(r, &i)| {
            let mut c = cands[i].clone();
            c.rank = r + 1;
            c
        })
        .collect();
    let names: Vec<String> = named.iter().map(|&i| cands[i].effect.clone()).collect();
    let best_other = order.first().map(|&i| cands[i].clone());
    *cands = ranked;

    let one_shot = one_shot_words(&baseline, &signature, o.tolerance_m, phase_tolerance(o, inp.floor));
    let mut verdict = match names.len() {
        0 if baseline.misfit => Verdict {
            kind: VerdictKind::NoneExplains,
            effect: None,
            effects: Vec::new(),
            sentence: none_explains(&baseline, &signature, best_other.as_ref(), o),
        },
        0 => Verdict {
            kind: VerdictKind::NoMissingEffect,
            effect: None,
            effects: Vec::new(),
            sentence: no_missing(&baseline, noise, best_other.as_ref(), inp.floor, o.tolerance_m) + &limits(cands),
        },
        1 => Verdict {
            kind: VerdictKind::MissingEffect,
            effect: Some(names[0].clone()),
            effects: names.clone(),
            sentence: missing(&cands[0], cands.get(1), noise),
        },
        _ => Verdict {
            kind: VerdictKind::Ambiguous,
            effect: Some(names[0].clone()),
            effects: names.clone(),
            sentence: ambiguous(cands, &names, &tie_words),
        },
    };
    if matches!(verdict.kind, VerdictKind::NoMissingEffect | VerdictKind::NoneExplains) {
        verdict.sentence += &one_shot;
    }
    (verdict, baseline, signature)
}

/// Why the current model misfits, one sentence per reason (none when it fits): a systematic residual above
/// the floor (in the fit, else held out), a phase and component above the per-phase tolerance, and (with
/// [`SearchOptions::use_trends`]) each significant, material trend of an output error.
fn misfit_reasons(baseline: &Baseline, signature: &Signature, inp: &Inputs<'_>) -> Vec<String> {
    let o = inp.options;
    let noise = inp.noise_m;
    let mut reasons = Vec::new();
    // A systematic part that is one shot's is that shot's, as a phase's is (see `one_shot_s`); the held-out
    // error, which has no shot left out of it, is then not asked either.
    if baseline.systematic_m > o.tolerance_m && whole_one_shot_s(baseline, signature, o.tolerance_m).is_none() {
        reasons.push(format!(
            "residual RMS {} against a noise level of {}: a systematic part of {}, above {}",
            um(baseline.fit.rms_m),
            um(noise),
            um(baseline.systematic_m),
            floor_words(inp.floor)
        ));
    }
    let heldout_systematic = stats::excess(baseline.heldout_error_m.powi(2), noise);
    if baseline.systematic_m <= o.tolerance_m && heldout_systematic > o.tolerance_m {
        reasons.push(format!(
            "held-out error {} against a noise level of {}: a systematic part of {}, above {}",
            um(baseline.heldout_error_m),
            um(noise),
            um(heldout_systematic),
            floor_words(inp.floor)
        ));
    }
    let phase_tol = phase_tolerance(o, inp.floor);
    for ph in &signature.phases {
        if ph.systematic_m > phase_tol && one_shot_s(ph, phase_tol).is_none() {
            reasons.push(format!(
                "{} {}: systematic residual {} (RMS {}), above the {} per-phase tolerance",
                ph.component.name(),
                ph.phase.words(),
                um(ph.systematic_m),
                um(ph.rms_m),
                um(phase_tol)
            ));
        }
    }
    if o.use_trends {
        for t in &signature.trends {
            if t.quantity != Quantity::ResidualRms {
                reasons.push(t.sentence.clone());
            }
        }
    }
    reasons
}

/// The candidates' order (indices): explaining candidates by ΔBIC, then the others by held-out error,
/// failed fits last; ties keep the order given.
fn ranking(cands: &[Candidate]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..cands.len()).collect();
    let key = |c: &Candidate| -> (u8, f64) {
        match (&c.evidence, c.explains) {
            (Some(e), true) => (0, e.delta_bic),
            (Some(e), false) => (1, e.heldout_error_after),
            (None, _) => (2, 0.0),
        }
    };
    order.sort_by(|&a, &b| {
        let (ka, kb) = (key(&cands[a]), key(&cands[b]));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1)).then(a.cmp(&b))
    });
    order
}

/// The candidates named (indices): the best explaining one and every other explaining one that predicts
/// held-out shots not significantly worse, or within the tolerance of it; with a sentence per tie.
fn ties(cands: &[Candidate], order: &[usize], inp: &Inputs<'_>) -> (Vec<usize>, Vec<String>) {
    let o = inp.options;
    let explaining: Vec<usize> = order.iter().copied().filter(|&i| cands[i].explains).collect();
    let mut named: Vec<usize> = Vec::new();
    let mut tie_words: Vec<String> = Vec::new();
    let Some(&best) = explaining.first() else {
        return (named, tie_words);
    };
    named.push(best);
    for &j in &explaining[1..] {
        let d: Vec<f64> = inp.heldout_chi2[j]
            .iter()
            .zip(&inp.heldout_chi2[best])
            .filter_map(|(a, b)| Some((a.as_ref()?.max(f64::MIN_POSITIVE) / b.as_ref()?.max(f64::MIN_POSITIVE)).ln()))
            .collect();
        let (_, p) = stats::one_sided_t(&d);
        // Mean held-out mean square of candidate `k` over the shots both predicted.
        let ms = |k: usize| -> f64 {
            let both = inp.heldout_ms[best].iter().zip(&inp.heldout_ms[j]);
            let (s, n) = inp.heldout_ms[k]
                .iter()
                .zip(both)
                .filter(|(_, (a, b))| a.is_some() && b.is_some())
                .filter_map(|(v, _)| *v)
                .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
            s / n.max(1) as f64
        };
        let gap = (ms(j) - ms(best)).max(0.0).sqrt();
        if p >= o.alpha || gap < o.tolerance_m {
            named.push(j);
            tie_words.push(if p >= o.alpha {
                format!(
                    "`{}` predicts held-out shots not significantly worse ({})",
                    cands[j].effect,
                    p_text(p)
                )
            } else {
                format!(
                    "`{}` leaves a held-out error only {} above it, within the {} tolerance",
                    cands[j].effect,
                    um(gap),
                    um(o.tolerance_m)
                )
            });
        }
    }
    (named, tie_words)
}

fn check(c: &mut Candidate, o: &SearchOptions, noise: f64) {
    let Some(e) = &c.evidence else {
        c.reasons = vec![format!("the fit failed: {}", c.failed.as_deref().unwrap_or("unknown"))];
        return;
    };
    let mut reasons = Vec::new();
    c.checks.bic = e.delta_bic <= -o.min_delta_bic;
    if !c.checks.bic {
        reasons.push(format!("ΔBIC = {:.1}, not below −{}", e.delta_bic, o.min_delta_bic));
    }
    c.checks.heldout =
        e.cross_validated && e.heldout_p_holm < o.alpha && e.heldout_error_after < c.heldout_error_before;
    if !e.cross_validated {
        reasons.push("not cross-validated: its fit to all shots already fails the BIC check".to_string());
    } else if !c.checks.heldout {
        reasons.push(format!(
            "held-out error {} → {} on {} of {} shots better, {} after Holm's correction (needs < {})",
            um(c.heldout_error_before),
            um(e.heldout_error_after),
            e.shots_improved[0],
            e.shots_improved[1],
            p_text(e.heldout_p_holm),
            o.alpha
        ));
    }
    let at_bound = e
        .fit
        .parameters
        .iter()
        .any(|p| p.effect == c.effect && p.param == c.param && p.at_bound);
    let range = builtin(&c.effect)
        .and_then(|i| i.params.iter().find(|p| p.name == c.param))
        .map(|p| (p.min, p.max));
    let unphysical = range.is_some_and(|(lo, hi)| e.param_value < lo || e.param_value > hi);
    c.checks.parameter = e.param_z.is_some_and(|z| z >= o.min_param_z) && !at_bound && !unphysical;
    if !c.checks.parameter {
        reasons.push(match (e.param_z, range) {
            _ if e.kept_at_neutral => format!(
                "no value of {} fitted better than its neutral value {} (the current model), where it is kept",
                c.param,
                num(c.neutral)
            ),
            (_, Some((lo, hi))) if unphysical => format!(
                "{} = {} is outside its physical range [{}, {}]: the data pull it the other way",
                c.param,
                num(e.param_value),
                num(lo),
                num(hi)
            ),
            _ if at_bound => format!("{} = {} ended on a bound of its range", c.param, num(e.param_value)),
            (Some(z), _) => format!(
                "{} = {} is only {z:.1} standard errors from its neutral value {} (needs {})",
                c.param,
                num(e.param_value),
                num(c.neutral),
                o.min_param_z
            ),
            (None, _) => format!("{} = {} is not determined by the shots", c.param, num(e.param_value)),
        });
    }
    // Held-out error removed (in quadrature), and the systematic part the candidate leaves held out.
    let removed = (c.heldout_error_before.powi(2) - e.heldout_error_after.powi(2))
        .max(0.0)
        .sqrt();
    let left = stats::excess(e.heldout_error_after.powi(2), noise);
    let complete = left <= o.tolerance_m || e.explained_fraction >= o.explained_fraction;
    c.checks.material = removed >= o.tolerance_m && complete;
    if !c.checks.material {
        reasons.push(if removed < o.tolerance_m {
            format!(
                "removes only {} of held-out error (in quadrature; needs {})",
                um(removed),
                um(o.tolerance_m)
            )
        } else {
            format!(
                "leaves a systematic held-out error of {} above the {} noise: it removes {:.0} % of the current model's systematic part (needs {:.0} %, or to leave less than {})",
                um(left),
                um(noise),
                e.explained_fraction.max(0.0) * 100.0,
                o.explained_fraction * 100.0,
                um(o.tolerance_m)
            )
        });
    }
    c.explains = c.checks.all();
    // Part of a misfit: the held-out test before Holm's correction (the search then goes on from the model
    // with it, where the next effect must pass every test and this one keep its parameter).
    c.partly_explains = !c.explains
        && e.cross_validated
        && c.checks.bic
        && e.heldout_p < o.alpha
        && e.heldout_error_after < c.heldout_error_before
        && c.checks.parameter
        && removed >= o.tolerance_m
        && !complete;
    c.reasons = reasons;
}

fn doc_of(effect: &str) -> String {
    builtin(effect).map(|i| i.doc.to_string()).unwrap_or_default()
}

fn unit_of(effect: &str, param: &str) -> String {
    builtin(effect)
        .and_then(|i| i.params.iter().find(|p| p.name == param))
        .map(|p| {
            if p.unit == "1" {
                String::new()
            } else {
                format!(" {}", p.unit)
            }
        })
        .unwrap_or_default()
}

fn param_words(c: &Candidate) -> String {
    let Some(e) = &c.evidence else {
        return String::new();
    };
    let unit = unit_of(&c.effect, &c.param);
    match e.param_interval {
        Some([lo, hi]) => format!(
            "{} = {}{unit} (95 % interval {} to {})",
            c.param,
            num(e.param_value),
            num(lo),
            num(hi)
        ),
        None => format!("{} = {}{unit}", c.param, num(e.param_value)),
    }
}

fn missing(c: &Candidate, next: Option<&Candidate>, noise: f64) -> String {
    let e = c.evidence.as_ref().expect("a named candidate has evidence");
    let mut s = format!(
        "The model is missing `{}`: {} Adding it lowers the residual RMS from {} to {} ({:.1}× lower; reduced χ² {:.2} against the tracker's σ, {:.2} against the {} noise estimated from the residuals) and the held-out error from {} to {}, better on {} of {} shots ({} after Holm's correction); ΔBIC = {:.0}. Fitted {}.",
        c.effect,
        doc_of(&c.effect),
        um(c.error_before),
        um(e.error_after),
        e.error_fall,
        e.chi2_red_after,
        e.chi2_red_noise_after,
        um(noise),
        um(c.heldout_error_before),
        um(e.heldout_error_after),
        e.shots_improved[0],
        e.shots_improved[1],
        p_text(e.heldout_p_holm),
        e.delta_bic,
        param_words(c)
    );
    if let Some(n) = next
        && let Some(ne) = &n.evidence
    {
        s += &format!(
            " The next candidate, `{}`, leaves a held-out error of {}.",
            n.effect,
            um(ne.heldout_error_after)
        );
    }
    s += &format!(" Accept it with `bouncelab model add {} --model model.toml`.", c.effect);
    s
}

fn ambiguous(cands: &[Candidate], names: &[String], ties: &[String]) -> String {
    let list = names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(" or ");
    let each = names
        .iter()
        .filter_map(|n| cands.iter().find(|c| &c.effect == n))
        .filter_map(|c| {
            c.evidence.as_ref().map(|e| {
                format!(
                    "`{}` lowers the residual RMS from {} to {} (held-out {}, ΔBIC {:.0}; {})",
                    c.effect,
                    um(c.error_before),
                    um(e.error_after),
                    um(e.heldout_error_after),
                    e.delta_bic,
                    param_words(c)
                )
            })
        })
        .collect::<Vec<_>>()
        .join("; ");
    format!(
        "The model is missing {list}: these explain the residual about equally well and the shots cannot tell them apart, so none is picked. {each}. Against the best, {}. Shots that separate them (a wider range of impact speeds or inclines) would decide.",
        ties.join("; ")
    )
}

fn no_missing(b: &Baseline, noise: f64, best: Option<&Candidate>, floor: &Floor, tol: f64) -> String {
    // Above the floor only with one shot, whose sentence follows (`one_shot_words`).
    let against = if b.systematic_m > tol {
        format!("above {} only with the one shot named below", floor_words(floor))
    } else {
        format!("within {}", floor_words(floor))
    };
    let mut s = format!(
        "No missing effect: the current model fits to the measurement floor (residual RMS {} against a noise level of {} estimated from the residuals; systematic part {}, {against}; reduced χ² {:.2} against the tracker's σ).",
        um(b.fit.rms_m),
        um(noise),
        um(b.systematic_m),
        b.fit.chi2_red
    );
    if let Some(c) = best
        && let Some(e) = &c.evidence
    {
        s += &format!(
            " The best candidate, `{}`, changes the held-out error from {} to {}.",
            c.effect,
            um(c.heldout_error_before),
            um(e.heldout_error_after)
        );
    }
    s
}

/// The detection limits of the candidates, in words: what this session could have shown.
fn limits(cands: &[Candidate]) -> String {
    let each: Vec<String> = cands
        .iter()
        .filter_map(|c| {
            let e = c.evidence.as_ref()?;
            let d = e.detection_limit?;
            let range = builtin(&c.effect).and_then(|i| i.params.iter().find(|p| p.name == c.param))?;
            // The physical side of the neutral value.
            let at = if range.max > range.neutral {
                c.neutral + d
            } else {
                c.neutral - d
            };
            Some(format!(
                "`{}` {} {} {}{}",
                c.effect,
                c.param,
                if at >= c.neutral { "≥" } else { "≤" },
                num(at),
                unit_of(&c.effect, &c.param)
            ))
        })
        .collect();
    if each.is_empty() {
        String::new()
    } else {
        format!(
            " Smaller effects than these would not have been named on this session (detection limits, linearised at the fit): {}.",
            each.join(", ")
        )
    }
}

fn none_explains(b: &Baseline, sig: &Signature, best: Option<&Candidate>, o: &SearchOptions) -> String {
    let mut s = format!(
        "No candidate explains the residual: the current model misfits ({}), but no library effect removes most of it.",
        b.misfit_reasons.first().cloned().unwrap_or_default()
    );
    if let Some(c) = best
        && let Some(e) = &c.evidence
    {
        if c.partly_explains {
            s += &format!(
                " `{}` explains part of it: it passes every test but leaves a systematic held-out error above the floor ({:.0} % of the systematic part removed, {}): it may be one of what is missing, not the whole.",
                c.effect,
                e.explained_fraction.max(0.0) * 100.0,
                param_words(c)
            );
        }
        s += &format!(
            " The closest, `{}`, lowers the held-out error from {} to {} ({:.0} % of the systematic part; {:.0} % needed) and leaves a systematic {}{}.",
            c.effect,
            um(c.heldout_error_before),
            um(e.heldout_error_after),
            e.explained_fraction.max(0.0) * 100.0,
            o.explained_fraction * 100.0,
            um(e.systematic_after_m),
            if c.reasons.is_empty() {
                String::new()
            } else {
                format!(" ({})", c.reasons.join("; "))
            }
        );
    }
    let top: Vec<String> = sig
        .phases
        .iter()
        .take(2)
        .map(|p| {
            format!(
                "{} {} ({:.0} % of χ², systematic {})",
                p.component.name(),
                p.phase.words(),
                p.chi2_share * 100.0,
                um(p.systematic_m)
            )
        })
        .collect();
    if !top.is_empty() {
        s += &format!(" The residual sits in {}.", top.join(" and "));
    }
    for t in sig.trends.iter().take(3) {
        s += " ";
        s += &t.sentence;
    }
    s += " A custom term (`kind = \"custom\"` in model.toml) acting there may be what is missing.";
    s
}
