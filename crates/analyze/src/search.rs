//! The missing-effect search as a stage: run, or read back from the output folder when nothing it depends
//! on changed (it is the slowest stage after tracking).

use crate::{AnalyzeError, AnalyzeOptions, Progress, ShotData, Stage, outputs};
use bouncelab_compare::ShotExtras;
use bouncelab_diagnose::{Diagnosis, FittedBaseline, SearchOptions, SearchProgress, find_missing_effect_from};
use bouncelab_model::ModelSpec;
use bouncelab_store::Fingerprint;

/// The search's options: the defaults, with each shot's surface level fitted within its line's σ.
fn search_options() -> SearchOptions {
    SearchOptions {
        surface_levels: true,
        ..SearchOptions::default()
    }
}

/// The missing-effect search from the current model as the fit stage fitted and compared it (`baseline`),
/// or its stored result when neither the shots, their measurements, the model nor the program changed
/// since it ran; `Ok(Err(why))` when it was not asked for or there are too few shots.
pub(crate) fn search_stage(
    spec: &ModelSpec,
    model_text: &str,
    shots: &[&ShotData],
    extras: &[ShotExtras],
    baseline: FittedBaseline<'_>,
    analyze: &AnalyzeOptions,
    progress: &dyn Progress,
) -> Result<Result<Diagnosis, String>, AnalyzeError> {
    let options = search_options();
    if !analyze.diagnose {
        return Ok(Err(
            "the missing-effect search was not asked for (--no-diagnose)".to_string()
        ));
    }
    if shots.len() < options.min_shots {
        let why = format!(
            "{} shot(s) fitted; the missing-effect search needs at least {} (held-out errors are compared across shots)",
            shots.len(),
            options.min_shots
        );
        progress.finish(Stage::Diagnose, &format!("not run: {why}"));
        return Ok(Err(why));
    }
    let out_dir = analyze.out_dir.as_path();
    crate::create_dir(out_dir)?;
    let key = inputs_key(model_text, &options, shots);
    let path = out_dir.join("diagnosis.json");
    let key_path = out_dir.join(".diagnosis-inputs");
    if let Some(d) = crate::reuse::read_back::<Diagnosis>(&path, &key_path, &key) {
        progress.finish(
            Stage::Diagnose,
            &format!(
                "unchanged since the last run ({} candidate(s) in diagnosis.json)",
                d.candidates.len()
            ),
        );
        return Ok(Ok(d));
    }
    crate::reuse::forget(&key_path)?;
    let measured: Vec<_> = shots.iter().map(|s| s.measured.clone()).collect();
    // The current model plus every library effect it lacks.
    let total = 1 + bouncelab_model::builtin_effects()
        .iter()
        .filter(|e| !e.base && !spec.has_effect(e.name))
        .count();
    progress.start(Stage::Diagnose, total as u64);
    let last = std::sync::atomic::AtomicUsize::new(0);
    let report = |p: SearchProgress| {
        if let Some(i) = p.iteration {
            // A solver iteration of the model being fitted.
            progress.iteration(Stage::Diagnose, i, p.chi2_red.unwrap_or(f64::NAN));
            return;
        }
        let before = last.swap(p.done, std::sync::atomic::Ordering::Relaxed);
        progress.advance(Stage::Diagnose, p.done.saturating_sub(before) as u64);
        progress.doing(Stage::Diagnose, &p.what);
    };
    let d = find_missing_effect_from(spec, &measured, extras, baseline, &options, &report)?;
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
    Ok(Ok(d))
}

/// The search's own revision: raised whenever the search or its verdict concludes otherwise from the same
/// inputs, so that a diagnosis kept in an output folder is made again by a program that would conclude
/// otherwise (the package's version alone changes only at a release). 2: a whole residual above the floor
/// only with one shot is that shot's, not the model's.
const DIAGNOSIS_REVISION: u32 = 2;

/// The key of what the search depends on: the program's version and the search's revision, the model, the
/// options and every shot's measurement.
fn inputs_key(model_text: &str, options: &SearchOptions, shots: &[&ShotData]) -> String {
    let mut key = Fingerprint::new();
    key.str(env!("CARGO_PKG_VERSION"))
        .str(&format!("diagnosis rev {DIAGNOSIS_REVISION}"))
        .str(model_text)
        .str(&format!("{options:?}"));
    crate::reuse::add_shots(&mut key, shots);
    key.finish()
}
