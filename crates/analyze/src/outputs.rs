//! The files of SPEC §5, each written to a temporary name and renamed, so a reader never sees half a file.

use crate::{AnalyzeError, ShotData};
use bouncelab_fit::FitResult;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The columns of `estimates.csv` (SPEC §5), in order.
pub const ESTIMATE_COLUMNS: [&str; 30] = [
    "clip",
    "surface",
    "angle_deg",
    "drop_height_m",
    "v_in_t",
    "v_in_t_se",
    "v_in_n",
    "v_in_n_se",
    "v_out_t",
    "v_out_t_se",
    "v_out_n",
    "v_out_n_se",
    "cor",
    "cor_se",
    "mu",
    "mu_se",
    "contact_ms",
    "contact_ms_se",
    "spin_in",
    "spin_in_se",
    "spin_out",
    "spin_out_se",
    "delta_max_mm",
    "delta_max_mm_se",
    "t_touch_s",
    "t_touch_s_se",
    "t_sep_s",
    "t_sep_s_se",
    "chi2_red_flight",
    "notes",
];

/// Writes `path` through a temporary file in the same folder and a rename.
pub(crate) fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), AnalyzeError> {
    let io = |source| AnalyzeError::Io {
        path: path.to_path_buf(),
        source,
    };
    let tmp = path.with_extension("partial");
    {
        let mut file = std::io::BufWriter::new(std::fs::File::create(&tmp).map_err(io)?);
        write(&mut file).map_err(io)?;
        file.flush().map_err(io)?;
    }
    std::fs::rename(&tmp, path).map_err(io)
}

/// `estimates.csv`: one row per measured shot with every estimate and its standard error.
pub fn write_estimates_csv(out: &mut dyn Write, shots: &[ShotData]) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(ESTIMATE_COLUMNS)?;
    let num = |v: f64| if v.is_finite() { format!("{v}") } else { String::new() };
    for s in shots {
        let e = &s.estimate;
        let opt = |m: Option<bouncelab_estimate::Measured>| {
            m.map_or((String::new(), String::new()), |m| (num(m.value), num(m.se)))
        };
        let (si, si_se) = opt(e.spin_in);
        let (so, so_se) = opt(e.spin_out);
        let worst_chi2 = e.chi2_red.iter().cloned().fold(f64::NAN, f64::max);
        w.write_record([
            s.clip.clone(),
            s.surface.clone(),
            num(s.angle_deg),
            num(s.drop_height_m),
            num(e.v_in[0].value),
            num(e.v_in[0].se),
            num(e.v_in[1].value),
            num(e.v_in[1].se),
            num(e.v_out[0].value),
            num(e.v_out[0].se),
            num(e.v_out[1].value),
            num(e.v_out[1].se),
            num(e.cor.value),
            num(e.cor.se),
            num(e.mu.value + 0.0),
            num(e.mu.se),
            num(e.contact_ms.value),
            num(e.contact_ms.se),
            si,
            si_se,
            so,
            so_se,
            num(e.delta_max_m.value * 1e3),
            num(e.delta_max_m.se * 1e3),
            num(e.t_touch.value),
            num(e.t_touch.se),
            num(e.t_sep.value),
            num(e.t_sep.se),
            num(worst_chi2),
            e.notes.join("; "),
        ])?;
    }
    w.flush()?;
    Ok(())
}

/// `trajectories/<clip>.csv`: the SPEC §5 columns of every frame.
fn write_trajectory(out: &mut dyn Write, s: &ShotData) -> Result<(), csv::Error> {
    write_track_rows(out, &s.track)
}

/// Writes `trajectories/<clip>.csv` for tracks whose shots could not be estimated (what was measured of them
/// is still a person's to look at).
pub(crate) fn write_failed_trajectories(
    dir: &Path,
    tracks: &[(String, bouncelab_store::TrackRecord)],
) -> Result<Vec<PathBuf>, AnalyzeError> {
    let traj = dir.join("trajectories");
    std::fs::create_dir_all(&traj).map_err(|source| AnalyzeError::Io {
        path: traj.clone(),
        source,
    })?;
    let mut written = Vec::new();
    for (clip, track) in tracks {
        let path = traj.join(format!("{}.csv", safe_name(clip)));
        write_atomic(&path, |w| write_track_rows(w, track).map_err(csv_io))?;
        written.push(path);
    }
    Ok(written)
}

/// `estimates.csv` with no fit behind it: the rows of `shots` (possibly none).
pub(crate) fn write_estimates_only(dir: &Path, shots: &[ShotData]) -> Result<PathBuf, AnalyzeError> {
    let path = dir.join("estimates.csv");
    write_atomic(&path, |w| write_estimates_csv(w, shots).map_err(csv_io))?;
    Ok(path)
}

fn write_track_rows(out: &mut dyn Write, track: &bouncelab_store::TrackRecord) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record([
        "frame", "t_s", "x_px", "y_px", "r_px", "sigma_px", "quality", "status", "x_m", "y_m",
    ])?;
    let num = |v: f64| if v.is_finite() { format!("{v}") } else { String::new() };
    for r in &track.rows {
        w.write_record([
            r.frame.to_string(),
            num(r.t_s),
            num(r.x_px),
            num(r.y_px),
            num(r.r_px),
            num(r.sigma_px),
            num(r.quality),
            r.status.clone(),
            num(r.x_m),
            num(r.y_m),
        ])?;
    }
    w.flush()?;
    Ok(())
}

fn csv_io(e: csv::Error) -> std::io::Error {
    std::io::Error::other(e)
}

/// A file name for a clip that cannot escape the trajectories folder.
fn safe_name(clip: &str) -> String {
    clip.chars()
        .map(|c| {
            if c.is_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Writes `estimates.csv`, `trajectories/`, `fit.json` and returns their paths.
pub(crate) fn write_all(dir: &Path, shots: &[ShotData], fit: &FitResult) -> Result<Vec<PathBuf>, AnalyzeError> {
    let mut written = Vec::new();
    let path = dir.join("estimates.csv");
    write_atomic(&path, |w| write_estimates_csv(w, shots).map_err(csv_io))?;
    written.push(path);
    let traj = dir.join("trajectories");
    std::fs::create_dir_all(&traj).map_err(|source| AnalyzeError::Io {
        path: traj.clone(),
        source,
    })?;
    for s in shots {
        let path = traj.join(format!("{}.csv", safe_name(&s.clip)));
        write_atomic(&path, |w| write_trajectory(w, s).map_err(csv_io))?;
    }
    written.push(traj);
    let path = dir.join("fit.json");
    write_atomic(&path, |w| w.write_all(fit.to_json().as_bytes()))?;
    written.push(path);
    Ok(written)
}

/// `comparison.csv` (see `bouncelab_compare::COMPARISON_COLUMNS`).
pub(crate) fn write_comparison(
    dir: &Path,
    comparison: &bouncelab_compare::Comparison,
) -> Result<PathBuf, AnalyzeError> {
    let path = dir.join("comparison.csv");
    write_atomic(&path, |w| {
        bouncelab_compare::write_comparison_csv(w, comparison).map_err(std::io::Error::other)
    })?;
    Ok(path)
}

/// `anova.csv`: the Type I table (the paper's Table 1), then the Type II table.
pub(crate) fn write_anova(dir: &Path, a: &bouncelab_stats::Ancova) -> Result<PathBuf, AnalyzeError> {
    let path = dir.join("anova.csv");
    write_atomic(&path, |w| {
        bouncelab_stats::write_anova_csv(w, &[&a.type1, &a.type2]).map_err(std::io::Error::other)
    })?;
    Ok(path)
}
