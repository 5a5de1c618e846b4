//! The model versions fitted to a session, from the store: this run's version recorded, and the previous
//! version's errors against this one's (before/after a model change).

use crate::{AnalyzeError, AnalyzeOptions};
use bouncelab_diagnose::Diagnosis;
use bouncelab_fit::FitResult;
use bouncelab_store::{FitRecord, ModelHistoryRow, ModelVersionRecord, Store};
use std::path::Path;

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

/// What the store holds about this run's model version once its fit is recorded.
pub(crate) struct Recorded {
    /// The store's id of the model version fitted.
    pub version: i64,
    /// This model's errors against the previous model version fitted to the session, if any.
    pub before: Option<BeforeAfter>,
    /// The previous version's diagnosis, when the output folder kept it.
    pub previous_diagnosis: Option<Diagnosis>,
    /// Every model version with its latest fit on this session.
    pub history: Vec<ModelHistoryRow>,
    /// The model version's text as stored (the diagnosis cache's key).
    pub model_text: String,
}

/// The model file's text, or the paper model's when none is given.
pub(crate) fn model_toml(options: &AnalyzeOptions) -> Result<String, AnalyzeError> {
    match &options.model_path {
        Some(p) => std::fs::read_to_string(p).map_err(|source| AnalyzeError::Io {
            path: p.clone(),
            source,
        }),
        None => Ok(bouncelab_model::PAPER_MODEL_TOML.to_string()),
    }
}

/// Stores the model version (the file's text, or the paper model's) and its fit on session `session_id`,
/// after reading the previous version's fit to compare against.
pub(crate) fn record_fit(
    store: &mut Store,
    session_id: i64,
    options: &AnalyzeOptions,
    fit: &FitResult,
) -> Result<Recorded, AnalyzeError> {
    let model_toml = model_toml(options)?;
    let version = store.add_model_version(&ModelVersionRecord {
        name: model_name(options.model_path.as_deref()),
        toml: model_toml,
        parent_id: None,
    })?;
    let before = before_after(store, session_id, version, fit)?;
    let previous_diagnosis = before
        .as_ref()
        .and_then(|b| crate::outputs::kept_diagnosis(&options.out_dir, b.before_version));
    store.add_fit(&FitRecord {
        session_id: Some(session_id),
        model_version_id: version,
        json: fit.to_json(),
        reduced_chi2: fit.reduced_chi2,
        rms_m: fit.rms_m,
        mae_pct: fit.mean_abs_cor_error_pct,
    })?;
    let history = store.model_history(Some(session_id))?;
    let model_text = store
        .model_versions()?
        .into_iter()
        .find(|v| v.id == version)
        .map(|v| v.record.toml)
        .unwrap_or_default();
    Ok(Recorded {
        version,
        before,
        previous_diagnosis,
        history,
        model_text,
    })
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

/// The name a model version is stored under: the file's name, or the built-in model's.
fn model_name(path: Option<&Path>) -> String {
    path.and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "built-in paper model".into())
}
