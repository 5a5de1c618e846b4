//! `comparison.csv`: one row per shot, phase and component.

use crate::{CompareError, Comparison};
use std::io::Write;

/// The columns of `comparison.csv`, in order (see `docs/compare.md`).
pub const COMPARISON_COLUMNS: [&str; 14] = [
    "clip",
    "surface",
    "angle_deg",
    "phase",
    "component",
    "unit",
    "n",
    "rms_m",
    "chi2_red",
    "v_out_t_err_pct",
    "v_out_n_err_pct",
    "cor_err_pct",
    "cor_err",
    "mu_err",
];

/// Writes `comparison.csv`: a header, then for every shot one row per phase and component that has
/// residuals, the shot's output errors (measured − predicted) repeated on each of its rows and empty when
/// the shot has no measured outputs.
pub fn write_comparison_csv<W: Write>(writer: W, comparison: &Comparison) -> Result<(), CompareError> {
    let mut w = csv::Writer::from_writer(writer);
    w.write_record(COMPARISON_COLUMNS)?;
    let opt = |v: Option<f64>| v.map(|x| format!("{x}")).unwrap_or_default();
    for s in &comparison.shots {
        let e = s.output_errors;
        let tail = [
            opt(e.and_then(|e| e.v_out_t_pct)),
            opt(e.and_then(|e| e.v_out_n_pct)),
            opt(e.map(|e| e.cor_pct)),
            opt(e.map(|e| e.cor_abs)),
            opt(e.map(|e| e.mu_abs)),
        ];
        for p in &s.by_phase {
            let mut row = vec![
                s.shot.clone(),
                s.surface.clone(),
                format!("{}", s.incline_deg),
                p.phase.name().to_string(),
                p.component.name().to_string(),
                p.component.unit().to_string(),
                p.n.to_string(),
                format!("{}", p.rms_m),
                format!("{}", p.chi2_red),
            ];
            row.extend(tail.iter().cloned());
            w.write_record(&row)?;
        }
    }
    w.flush().map_err(|e| CompareError::Csv(e.into()))?;
    Ok(())
}
