//! The paper's statistics of one session of shots: the ANCOVA of COR on the terms the session can support,
//! Tukey–Kramer comparisons of its surfaces, and the inference of the same fit (`docs/stats.md`).

use crate::{
    Ancova, AncovaInference, CorObservation, Dataset, PAPER_TERMS, StatsError, TukeyHsd, ancova, ancova_inference,
    tukey_hsd_factor,
};

/// Family-wise level of a session's comparisons and one minus the level of its intervals (the paper's 0.05).
pub const SESSION_ALPHA: f64 = 0.05;

/// The paper's statistics of a session.
#[derive(Debug, Clone)]
pub struct SessionStats {
    /// The terms fitted, in order (those with a single level are left out).
    pub terms: Vec<&'static str>,
    /// ANCOVA of COR (Type I and II), its fit and diagnostics.
    pub ancova: Ancova,
    /// Tukey–Kramer comparisons of the surfaces' raw means at α = [`SESSION_ALPHA`], when there are two or
    /// more (one-way: the impact speed is not accounted for; `inference` holds the comparisons that agree
    /// with the ANCOVA).
    pub tukey: Option<TukeyHsd>,
    /// The same fit's coefficients with SE, t and p, adjusted means of every factor with Tukey–Kramer and
    /// Holm comparisons, and its residual tests (α = [`SESSION_ALPHA`]), or why they could not be computed.
    pub inference: Result<AncovaInference, String>,
}

/// The paper's terms ([`PAPER_TERMS`]) that `rows` can support: a factor with a single level (one surface,
/// one angle) has no contrast and is left out; the covariate always stays.
pub fn session_terms(rows: &[CorObservation]) -> Vec<&'static str> {
    let distinct = |f: &dyn Fn(&CorObservation) -> String| {
        let mut v: Vec<String> = rows.iter().map(f).collect();
        v.sort();
        v.dedup();
        v.len()
    };
    let surfaces = distinct(&|r| r.surface.clone());
    let angles = distinct(&|r| format!("{}", r.angle));
    PAPER_TERMS
        .into_iter()
        .filter(|t| match *t {
            "surface" => surfaces > 1,
            "angle" => angles > 1,
            _ => true,
        })
        .collect()
}

/// ANCOVA of COR on surface and angle with the incoming normal speed as covariate (the terms of
/// [`session_terms`]), and Tukey–Kramer pairwise comparisons of the surfaces when there are two or more.
/// An error says why nothing could be fitted; the ANCOVA's own failure is [`StatsError::Session`].
pub fn session_stats(rows: &[CorObservation]) -> Result<SessionStats, StatsError> {
    let terms = session_terms(rows);
    let data = Dataset::from_cor(rows)?;
    let ancova = ancova(&data, &terms).map_err(|e| StatsError::Session {
        shots: rows.len(),
        error: Box::new(e),
    })?;
    let tukey = if terms.contains(&"surface") {
        Some(tukey_hsd_factor(&data, "surface", SESSION_ALPHA)?)
    } else {
        None
    };
    let inference = ancova_inference(&data, &terms, SESSION_ALPHA).map_err(|e| e.to_string());
    Ok(SessionStats {
        terms,
        ancova,
        tukey,
        inference,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(surface: &str, angle: f64, v_in_n: f64, cor: f64) -> CorObservation {
        CorObservation {
            surface: surface.into(),
            angle,
            v_in_n,
            cor,
        }
    }

    #[test]
    fn a_factor_with_one_level_is_left_out() {
        let one = [row("clay", 0.0, 2.0, 0.5), row("clay", 0.0, 3.0, 0.45)];
        assert_eq!(session_terms(&one), ["v_in_n"]);
        let two = [row("clay", 0.0, 2.0, 0.5), row("tape", 7.5, 3.0, 0.45)];
        assert_eq!(session_terms(&two), ["surface", "angle", "v_in_n"]);
        let angles = [row("clay", 0.0, 2.0, 0.5), row("clay", 15.0, 3.0, 0.45)];
        assert_eq!(session_terms(&angles), ["angle", "v_in_n"]);
    }

    #[test]
    fn two_surfaces_give_the_ancova_and_tukey_and_too_few_shots_an_error_naming_them() {
        let rows: Vec<CorObservation> = (0..12)
            .map(|i| {
                let v = 1.5 + 0.1 * i as f64;
                let (surface, base) = if i % 2 == 0 { ("clay", 0.6) } else { ("tape", 0.7) };
                row(surface, 0.0, v, base - 0.03 * v + 0.002 * ((i * 7 % 5) as f64))
            })
            .collect();
        let s = session_stats(&rows).unwrap();
        assert_eq!(s.terms, ["surface", "v_in_n"]);
        assert!(s.tukey.is_some() && s.inference.is_ok());
        let err = session_stats(&rows[..2]).unwrap_err();
        assert!(err.to_string().starts_with("2 shot(s): "), "{err}");
    }
}
