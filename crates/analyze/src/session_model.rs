//! The model a session is fitted with.

use crate::{AnalyzeError, Progress};
use bouncelab_frames::Session;
use bouncelab_model::ModelSpec;
use std::path::Path;

/// The model for a session: `path` or the paper's, with the session's ball, the surface level nuisance
/// ([`bouncelab_fit::add_surface_level`]), and a surface table for every surface of the session that the
/// file does not list (copying the file's own values, so each surface gets its own fitted parameters when
/// any are free).
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
    bouncelab_fit::add_surface_level(&mut spec);
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
