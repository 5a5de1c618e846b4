//! The output files (their columns are documented in `docs/outputs.md`), each written to a temporary name and
//! renamed, so a reader never sees half a file.

use crate::{AnalyzeError, ShotData};
use bouncelab_fit::FitResult;
use bouncelab_report as r;
use bouncelab_store::ESTIMATE_QUANTITIES as Q;
use bouncelab_track::{TRAJECTORY_COLUMNS, TrajectoryCell, TrajectoryRow};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The columns of `estimates.csv`, in order. Every name ends in its unit (`_m_s`, `_ms`, `_mm`, `_deg`,
/// `_rad_s`, `_m_s2`, `_s`, `_m`); `cor`, `mu_eff`, their `_se`, `chi2_red_flight`, `trajectory_share` and
/// `level_se_scale` are dimensionless. A standard error is `<quantity>_se_<unit>` (see `docs/outputs.md`).
/// The measured quantities' columns are the store's `estimates` columns ([`Q`],
/// `bouncelab_store::ESTIMATE_QUANTITIES`), so the file and the table name them alike.
pub const ESTIMATE_COLUMNS: [&str; 49] = [
    "clip",
    "surface",
    "angle_deg",
    "drop_height_m",
    Q[0][0],
    Q[0][1],
    Q[1][0],
    Q[1][1],
    Q[2][0],
    Q[2][1],
    Q[3][0],
    Q[3][1],
    "impact_speed_m_s",
    "impact_speed_se_m_s",
    "impact_angle_deg",
    "impact_angle_se_deg",
    Q[4][0],
    Q[4][1],
    Q[5][0],
    Q[5][1],
    Q[6][0],
    Q[6][1],
    Q[7][0],
    Q[7][1],
    Q[8][0],
    Q[8][1],
    Q[9][0],
    Q[9][1],
    "peak_decel_track_m_s2",
    "peak_decel_track_se_m_s2",
    "peak_force_track_n",
    "peak_force_track_se_n",
    "t_touch_s",
    "t_touch_se_s",
    "t_sep_s",
    "t_sep_se_s",
    "chi2_red_flight",
    "contact_line",
    "trajectory_share",
    "level_se_scale",
    "surface_tilt_deg",
    "surface_tilt_se_deg",
    "line_tilt_deg",
    "line_tilt_se_deg",
    "fall_tilt_deg",
    "fall_tilt_se_deg",
    "flags",
    "notes",
    "trajectory_file",
];

/// The columns of `comparison.csv`: one row per shot, phase and component. `rms` is in `unit` (µm for the
/// tangential and normal positions, rad/s for spin); the output errors are measured − predicted.
pub const COMPARISON_COLUMNS: [&str; 15] = [
    "clip",
    "surface",
    "angle_deg",
    "phase",
    "component",
    "unit",
    "n",
    "rms",
    "chi2_red",
    "v_out_t_err_pct",
    "v_out_n_err_pct",
    "cor_err_pct",
    "cor_err",
    "mu_eff_err",
    "contact_err_ms",
];

/// The columns of `model_predictions.csv`: per fitted shot, the fitted model hit at the shot's measured
/// incoming velocity, and the fit's error on the shot.
pub const PREDICTION_COLUMNS: [&str; 14] = [
    "clip",
    "surface",
    "angle_deg",
    "cor",
    "mu_eff",
    "contact_ms",
    "delta_max_mm",
    "spin_out_rad_s",
    "peak_force_n",
    "peak_decel_m_s2",
    "frames",
    "rms_um",
    "chi2_red",
    "notes",
];

/// The columns of `model_curves.csv`: the fitted model against the incoming normal speed, per surface and
/// incline (the ball arriving vertically).
pub const CURVE_COLUMNS: [&str; 10] = [
    "surface",
    "angle_deg",
    "v_in_n_m_s",
    "cor",
    "mu_eff",
    "contact_ms",
    "delta_max_mm",
    "spin_out_rad_s",
    "peak_force_n",
    "peak_decel_m_s2",
];

/// The columns of `contact_force.csv`: the contact force over one impact (the report's Figure 2 panel).
pub const FORCE_COLUMNS: [&str; 5] = ["clip", "surface", "t_ms", "delta_mm", "force_n"];

/// The columns of `surfaces.csv`: per surface and quantity, mean, sample SD and count over the shots; the
/// rows mix quantities, so the unit is a column.
pub const SURFACE_COLUMNS: [&str; 6] = ["surface", "quantity", "unit", "n", "mean", "sd"];

/// Writes `path` through a temporary file in the same folder and a rename.
pub(crate) fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), AnalyzeError> {
    let io = |source| AnalyzeError::Io {
        path: path.to_path_buf(),
        source,
    };
    // A short name of its own in the same folder: `<name>.partial` would pass the file system's name limit
    // for a long legal name.
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = path.with_file_name(format!(".partial-{}-{n}", std::process::id()));
    let written = std::fs::File::create(&tmp).and_then(|file| {
        let mut file = std::io::BufWriter::new(file);
        write(&mut file)?;
        file.flush()
    });
    // A failed write (a full disk, say) leaves no temporary file behind; the previous `path` is untouched.
    match written.and_then(|()| std::fs::rename(&tmp, path)) {
        Ok(()) => Ok(()),
        Err(source) => {
            let _ = std::fs::remove_file(&tmp);
            Err(io(source))
        }
    }
}

fn num(v: f64) -> String {
    if v.is_finite() { format!("{v}") } else { String::new() }
}

/// `estimates.csv`: one row per measured shot with every estimate and its standard error; the ball's mass
/// (kg) and gravity (m/s²) turn the track's peak deceleration into a force; `files` maps each clip to its
/// file under `trajectories/` ([`trajectory_files`]).
pub fn write_estimates_csv(
    out: &mut dyn Write,
    shots: &[ShotData],
    ball_mass_kg: f64,
    gravity: f64,
    files: &TrajectoryFiles,
) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(ESTIMATE_COLUMNS)?;
    for s in shots {
        w.write_record(estimate_cells(s, ball_mass_kg, gravity, files))?;
    }
    w.flush()?;
    Ok(())
}

/// A value and its standard error as two cells; two empty cells when not measured.
fn value_se_cells(v: Option<(f64, Option<f64>)>) -> [String; 2] {
    v.map_or([String::new(), String::new()], |(value, se)| {
        [num(value), se.map_or(String::new(), num)]
    })
}

/// One shot's `estimates.csv` row, in the order of [`ESTIMATE_COLUMNS`]: its conditions, the measured
/// quantities as the store holds them ([`crate::measure::estimate_quantities`]) with the impact's speed and
/// angle after the velocities, then what is derived from the track and the estimate's own account.
fn estimate_cells(s: &ShotData, ball_mass_kg: f64, gravity: f64, files: &TrajectoryFiles) -> Vec<String> {
    let e = &s.estimate;
    let m = crate::report::measurement(s, None, ball_mass_kg, gravity);
    let stored = crate::measure::estimate_quantities(e).map(|q| value_se_cells(q.map(|v| (v.value, Some(v.se)))));
    let pair = |v: Option<r::Measured>| value_se_cells(v.map(|a| (a.value, a.se)));
    let (speed, angle) = (m.impact_speed(), m.impact_angle());
    let worst_chi2 = e.chi2_red.iter().cloned().fold(f64::NAN, f64::max);
    let mut cells = vec![
        s.clip.clone(),
        s.surface.clone(),
        num(s.angle_deg),
        num(s.drop_height_m),
    ];
    cells.extend(stored[..4].iter().flatten().cloned());
    cells.extend(pair(Some(speed)));
    cells.extend(pair(Some(angle)));
    cells.extend(stored[4..].iter().flatten().cloned());
    cells.extend(pair(m.peak_deceleration_track_m_s2));
    cells.extend(pair(m.peak_force_track_n));
    cells.extend([
        num(e.t_touch.value),
        num(e.t_touch.se),
        num(e.t_sep.value),
        num(e.t_sep.se),
    ]);
    cells.push(num(worst_chi2));
    cells.push(e.contact_line.map_or(String::new(), |l| l.cue.name().to_string()));
    cells.push(num(e.trajectory_share));
    cells.push(num(e.level_se_scale));
    for tilt in [e.surface_tilt_deg, e.line_tilt_deg, e.fall_tilt_deg] {
        cells.extend(value_se_cells(tilt.map(|t| (t.value, Some(t.se)))));
    }
    cells.push(e.flags.join("; "));
    cells.push(e.notes.join("; "));
    cells.push(
        files
            .get(&s.clip)
            .map_or_else(String::new, |f| format!("trajectories/{f}")),
    );
    cells
}

/// `trajectories/<clip>.csv`: the `docs/outputs.md` columns of every frame.
fn write_trajectory(out: &mut dyn Write, s: &ShotData) -> Result<(), csv::Error> {
    write_track_rows(out, &s.track.rows)
}

/// Writes `trajectories/<clip>.csv` for tracks whose shots could not be estimated (what was measured of them
/// is still a person's to look at).
pub(crate) fn write_failed_trajectories(
    dir: &Path,
    tracks: &[(String, bouncelab_store::TrackRecord)],
    files: &TrajectoryFiles,
) -> Result<Vec<PathBuf>, AnalyzeError> {
    let traj = dir.join("trajectories");
    std::fs::create_dir_all(&traj).map_err(|source| AnalyzeError::Io {
        path: traj.clone(),
        source,
    })?;
    let mut written = Vec::new();
    for (clip, track) in tracks {
        let path = traj.join(file_for(files, clip));
        write_atomic(&path, |w| write_track_rows(w, &track.rows).map_err(csv_io))?;
        written.push(path);
    }
    Ok(written)
}

/// `estimates.csv` with no fit behind it: the rows of `shots` (possibly none); `spec` gives the ball's mass
/// and gravity.
pub(crate) fn write_estimates_only(
    dir: &Path,
    shots: &[ShotData],
    spec: &bouncelab_model::ModelSpec,
    files: &TrajectoryFiles,
) -> Result<PathBuf, AnalyzeError> {
    let path = dir.join("estimates.csv");
    write_atomic(&path, |w| {
        write_estimates_csv(w, shots, spec.ball.mass_kg, spec.gravity, files).map_err(csv_io)
    })?;
    Ok(path)
}

/// A trajectory's rows under [`TRAJECTORY_COLUMNS`]; a NaN (not measured) is an empty cell.
fn write_track_rows(out: &mut dyn Write, rows: &[TrajectoryRow]) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(TRAJECTORY_COLUMNS)?;
    for r in rows {
        w.write_record(r.cells().map(|cell| match cell {
            TrajectoryCell::Frame(f) => f.to_string(),
            TrajectoryCell::Number(x) => num(x),
            TrajectoryCell::Status(s) => s.name().to_string(),
        }))?;
    }
    w.flush()?;
    Ok(())
}

fn csv_io(e: csv::Error) -> std::io::Error {
    std::io::Error::other(e)
}

/// Removes the temporary files ([`write_atomic`]'s `.partial-*`) a killed run left in `dir` and
/// `dir/trajectories`.
pub(crate) fn clear_partials(dir: &Path) {
    for d in [dir.to_path_buf(), dir.join("trajectories")] {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let Some(pid) = name.strip_prefix(".partial-").and_then(|r| r.split('-').next()) else {
                continue;
            };
            // Only a dead writer's (known where /proc lists the living): a live run renames its own.
            let proc = Path::new("/proc");
            if proc.is_dir() && !proc.join(pid).exists() {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// Removes the `.csv` files of `dir/trajectories` that are no clip's file in `files` (clips no longer listed
/// in `clips.csv`), so that the folder shows exactly the session's clips.
pub(crate) fn remove_stale_trajectories(dir: &Path, files: &TrajectoryFiles) -> Result<(), AnalyzeError> {
    let traj = dir.join("trajectories");
    let Ok(entries) = std::fs::read_dir(&traj) else {
        return Ok(());
    };
    let current: std::collections::HashSet<&str> = files.values().map(String::as_str).collect();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        if name.ends_with(".csv") && !current.contains(name) {
            let path = entry.path();
            std::fs::remove_file(&path).map_err(|source| AnalyzeError::Io { path, source })?;
        }
    }
    Ok(())
}

/// Each clip's file name under `trajectories/` (see [`trajectory_files`]).
pub type TrajectoryFiles = std::collections::HashMap<String, String>;

/// The file of `clip`: from the map, or (a clip the map was not given, which the pipeline never does) its
/// own bounded name.
fn file_for(files: &TrajectoryFiles, clip: &str) -> String {
    files
        .get(clip)
        .cloned()
        .unwrap_or_else(|| trajectory_files([clip]).remove(clip).unwrap_or_default())
}

/// Longest clip-derived part of an output file name, in bytes: with the hash suffix and `.csv` the name stays
/// far below the 255-byte limit of common file systems, with room for a temporary suffix.
const MAX_STEM_BYTES: usize = 96;

/// The file name under `trajectories/` of each clip, unique and bounded, decided from the names alone (so
/// the same clips always get the same files, whatever else the session holds). A name that is already a
/// safe, short file name (letters, digits, `-`, `_`, `.`, not starting with `.`) is kept as it is plus
/// `.csv`; any other is cleaned, cut to `MAX_STEM_BYTES` (96) and given 8 hex digits of a hash of the
/// original, so `shot 1` and `shot_1` never share a file. Names equal but for case (one file on
/// case-insensitive file systems) get `-2`, `-3` … in the order given.
pub fn trajectory_files<'a>(clips: impl IntoIterator<Item = &'a str>) -> TrajectoryFiles {
    let mut out = std::collections::HashMap::new();
    let mut taken = std::collections::HashSet::new();
    for clip in clips {
        if out.contains_key(clip) {
            continue;
        }
        let clean: String = clip
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let kept = clean == clip && !clip.is_empty() && !clip.starts_with('.') && clip.len() <= MAX_STEM_BYTES;
        let mut stem = if kept {
            clean
        } else {
            let mut cut = clean.trim_start_matches('.').to_string();
            cut.truncate(MAX_STEM_BYTES);
            let hash = bouncelab_store::Fingerprint::new().str(clip).finish();
            format!("{cut}-{}", &hash[..8])
        };
        let base = stem.clone();
        let mut n = 1;
        while !taken.insert(stem.to_ascii_lowercase()) {
            n += 1;
            stem = format!("{base}-{n}");
        }
        out.insert(clip.to_string(), format!("{stem}.csv"));
    }
    out
}

/// Writes `estimates.csv`, `trajectories/`, `fit.json` and returns their paths.
pub(crate) fn write_all(
    dir: &Path,
    shots: &[ShotData],
    fit: &FitResult,
    spec: &bouncelab_model::ModelSpec,
    files: &TrajectoryFiles,
) -> Result<Vec<PathBuf>, AnalyzeError> {
    let mut written = Vec::new();
    let path = dir.join("estimates.csv");
    write_atomic(&path, |w| {
        write_estimates_csv(w, shots, spec.ball.mass_kg, spec.gravity, files).map_err(csv_io)
    })?;
    written.push(path);
    let traj = dir.join("trajectories");
    std::fs::create_dir_all(&traj).map_err(|source| AnalyzeError::Io {
        path: traj.clone(),
        source,
    })?;
    for s in shots {
        let path = traj.join(file_for(files, &s.clip));
        write_atomic(&path, |w| write_trajectory(w, s).map_err(csv_io))?;
    }
    written.push(traj);
    let path = dir.join("fit.json");
    write_atomic(&path, |w| w.write_all(fit.to_json().as_bytes()))?;
    written.push(path);
    Ok(written)
}

/// `comparison.csv` (see [`COMPARISON_COLUMNS`]).
pub(crate) fn write_comparison(
    dir: &Path,
    comparison: &bouncelab_compare::Comparison,
) -> Result<PathBuf, AnalyzeError> {
    let path = dir.join("comparison.csv");
    write_atomic(&path, |w| write_comparison_csv(w, comparison).map_err(csv_io))?;
    Ok(path)
}

/// Writes [`COMPARISON_COLUMNS`] rows of `comparison`.
pub fn write_comparison_csv(out: &mut dyn Write, comparison: &bouncelab_compare::Comparison) -> Result<(), csv::Error> {
    use bouncelab_compare::Component;
    let mut w = csv::Writer::from_writer(out);
    w.write_record(COMPARISON_COLUMNS)?;
    let opt = |v: Option<f64>| v.map_or(String::new(), num);
    for s in &comparison.shots {
        let e = s.output_errors;
        let tail = [
            opt(e.and_then(|e| e.v_out_t_pct)),
            opt(e.and_then(|e| e.v_out_n_pct)),
            opt(e.map(|e| e.cor_pct)),
            opt(e.map(|e| e.cor_abs)),
            opt(e.map(|e| e.mu_abs)),
            opt(s.contact_time_error_ms),
        ];
        for p in &s.by_phase {
            let (unit, rms) = match p.component {
                Component::Spin => ("rad/s", p.rms_m),
                _ => ("um", p.rms_m * 1e6),
            };
            let mut row = vec![
                s.shot.clone(),
                s.surface.clone(),
                num(s.incline_deg),
                p.phase.name().to_string(),
                p.component.name().to_string(),
                unit.to_string(),
                p.n.to_string(),
                num(rms),
                num(p.chi2_red),
            ];
            row.extend(tail.iter().cloned());
            w.write_record(&row)?;
        }
    }
    w.flush()?;
    Ok(())
}

/// One quantity of `surfaces.csv`: its name there, its unit, the factor from SI, the value of a shot.
type SurfaceQuantity = (&'static str, &'static str, f64, fn(&r::ShotMeasurement) -> Option<f64>);

/// The quantities of `surfaces.csv`, measured first, then the model's.
const SURFACE_QUANTITIES: [SurfaceQuantity; 16] = [
    ("impact_speed", "m/s", 1.0, |m| Some(m.impact_speed().value)),
    ("impact_angle", "deg", 1.0, |m| Some(m.impact_angle().value)),
    ("v_in_n", "m/s", 1.0, |m| Some(m.v_in_m_s[1].value.abs())),
    ("cor", "1", 1.0, |m| Some(m.cor.value)),
    ("mu_eff", "1", 1.0, |m| Some(m.mu_eff.value)),
    ("contact", "ms", 1e3, |m| Some(m.contact_time_s.value)),
    ("delta_max", "mm", 1e3, |m| Some(m.delta_max_m.value)),
    ("spin_in", "rad/s", 1.0, |m| m.spin_in_rad_s.map(|v| v.value)),
    ("spin_out", "rad/s", 1.0, |m| m.spin_out_rad_s.map(|v| v.value)),
    ("peak_decel_track", "m/s2", 1.0, |m| {
        m.peak_deceleration_track_m_s2.map(|v| v.value)
    }),
    ("peak_force_track", "N", 1.0, |m| m.peak_force_track_n.map(|v| v.value)),
    ("cor_model", "1", 1.0, |m| m.model.map(|p| p.cor)),
    ("contact_model", "ms", 1e3, |m| m.model.map(|p| p.contact_time_s)),
    ("delta_max_model", "mm", 1e3, |m| m.model.map(|p| p.delta_max_m)),
    ("peak_force_model", "N", 1.0, |m| m.model.map(|p| p.peak_force_n)),
    ("peak_decel_model", "m/s2", 1.0, |m| {
        m.model.map(|p| p.peak_deceleration_m_s2)
    }),
];

/// The files holding the numbers the report draws: `model_predictions.csv`, `model_curves.csv`,
/// `contact_force.csv` (when the report has a contact) and `surfaces.csv`; returns their paths.
pub(crate) fn write_figure_data(dir: &Path, report: &r::Report) -> Result<Vec<PathBuf>, AnalyzeError> {
    let mut written = Vec::new();
    let mut write = |name: &str, rows: &dyn Fn(&mut csv::Writer<&mut dyn Write>) -> csv::Result<()>| {
        let path = dir.join(name);
        write_atomic(&path, |out| {
            let mut w = csv::Writer::from_writer(out);
            rows(&mut w).map_err(csv_io)?;
            w.flush()
        })?;
        written.push(path);
        Ok::<(), AnalyzeError>(())
    };
    write("model_predictions.csv", &|w| write_predictions(w, report))?;
    write("model_curves.csv", &|w| write_curves(w, report))?;
    if let Some(f) = report.contact_force.get() {
        write("contact_force.csv", &|w| write_contact_force(w, f))?;
    }
    write("surfaces.csv", &|w| write_surfaces(w, report))?;
    Ok(written)
}

/// `model_predictions.csv`: per shot, the fitted model at its measured incoming velocity and the fit's error.
fn write_predictions(w: &mut csv::Writer<&mut dyn Write>, report: &r::Report) -> csv::Result<()> {
    w.write_record(PREDICTION_COLUMNS)?;
    for sh in &report.shots {
        let p = report
            .measurements
            .iter()
            .find(|m| m.clip == sh.clip)
            .and_then(|m| m.model);
        let f = |g: fn(&r::ShotPrediction) -> f64, scale: f64| p.as_ref().map_or(String::new(), |p| num(g(p) * scale));
        w.write_record([
            sh.clip.clone(),
            sh.surface.clone(),
            num(sh.angle_deg),
            f(|p| p.cor, 1.0),
            f(|p| p.mu_eff, 1.0),
            f(|p| p.contact_time_s, 1e3),
            f(|p| p.delta_max_m, 1e3),
            f(|p| p.spin_out_rad_s, 1.0),
            f(|p| p.peak_force_n, 1.0),
            f(|p| p.peak_deceleration_m_s2, 1.0),
            sh.measured.len().to_string(),
            sh.rms_m.map_or(String::new(), |v| num(v * 1e6)),
            sh.chi2_red.map_or(String::new(), num),
            sh.notes.join("; "),
        ])?;
    }
    Ok(())
}

/// `model_curves.csv`: the fitted model against the incoming normal speed, per surface and incline.
fn write_curves(w: &mut csv::Writer<&mut dyn Write>, report: &r::Report) -> csv::Result<()> {
    w.write_record(CURVE_COLUMNS)?;
    for c in &report.model_curves {
        for p in &c.points {
            let q = &p.prediction;
            w.write_record([
                c.surface.clone(),
                num(c.angle_deg),
                num(p.v_in_n_m_s),
                num(q.cor),
                num(q.mu_eff),
                num(q.contact_time_s * 1e3),
                num(q.delta_max_m * 1e3),
                num(q.spin_out_rad_s),
                num(q.peak_force_n),
                num(q.peak_deceleration_m_s2),
            ])?;
        }
    }
    Ok(())
}

/// `contact_force.csv`: one contact's force against time and penetration.
fn write_contact_force(w: &mut csv::Writer<&mut dyn Write>, f: &r::ContactForce) -> csv::Result<()> {
    w.write_record(FORCE_COLUMNS)?;
    for s in &f.samples {
        w.write_record([
            f.clip.clone(),
            f.surface.clone(),
            num(s.t_s * 1e3),
            num(s.delta_m * 1e3),
            num(s.force_n),
        ])?;
    }
    Ok(())
}

/// `surfaces.csv`: per surface (in the order first measured) and quantity, mean, sample SD and count.
fn write_surfaces(w: &mut csv::Writer<&mut dyn Write>, report: &r::Report) -> csv::Result<()> {
    w.write_record(SURFACE_COLUMNS)?;
    let mut surfaces: Vec<&str> = Vec::new();
    for m in &report.measurements {
        if !surfaces.contains(&m.surface.as_str()) {
            surfaces.push(&m.surface);
        }
    }
    for s in surfaces {
        for (name, unit, scale, get) in SURFACE_QUANTITIES {
            let v: Vec<f64> = report
                .measurements
                .iter()
                .filter(|m| m.surface == s)
                .filter_map(get)
                .map(|v| v * scale)
                .filter(|v| v.is_finite())
                .collect();
            if v.is_empty() {
                continue;
            }
            let n = v.len() as f64;
            let mean = v.iter().sum::<f64>() / n;
            let sd = if v.len() > 1 {
                (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
            } else {
                f64::NAN
            };
            w.write_record([s, name, unit, &v.len().to_string(), &num(mean), &num(sd)])?;
        }
    }
    Ok(())
}

/// Where the diagnosis of model version `version` is kept in an output folder.
fn kept_path(dir: &Path, version: i64) -> PathBuf {
    dir.join("diagnoses").join(format!("model-v{version}.json"))
}

/// Keeps `d`, the diagnosis of model version `version`, in `dir/diagnoses/`.
pub(crate) fn keep_diagnosis(dir: &Path, version: i64, d: &bouncelab_diagnose::Diagnosis) -> Result<(), AnalyzeError> {
    let path = kept_path(dir, version);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|source| AnalyzeError::Io {
            path: parent.to_path_buf(),
            source,
        })?;
    }
    write_atomic(&path, |w| w.write_all(d.to_json().as_bytes()))
}

/// The kept diagnosis of model version `version`, if this output folder has a readable one.
pub(crate) fn kept_diagnosis(dir: &Path, version: i64) -> Option<bouncelab_diagnose::Diagnosis> {
    let text = std::fs::read_to_string(kept_path(dir, version)).ok()?;
    serde_json::from_str(&text).ok()
}

/// `anova.csv`: the Type I table (the paper's Table 1), then the Type II table.
pub(crate) fn write_anova(dir: &Path, a: &bouncelab_stats::Ancova) -> Result<PathBuf, AnalyzeError> {
    let path = dir.join("anova.csv");
    write_atomic(&path, |w| {
        bouncelab_stats::write_anova_csv(w, &[&a.type1, &a.type2]).map_err(std::io::Error::other)
    })?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `trajectories/<clip>.csv` spells numbers with `Display` and a value not measured as an empty cell.
    #[test]
    fn a_trajectory_file_writes_every_column_and_leaves_unmeasured_cells_empty() {
        use bouncelab_track::{BallFix, Status};
        let fix = |frame, x_px: f64, status| BallFix {
            frame,
            t_s: frame as f64 * 1e-4,
            x_px,
            y_px: 200.25,
            r_px: 40.5,
            sigma_px: 0.03,
            sigma_r_px: 0.04,
            quality: if x_px.is_nan() { 0.0 } else { 0.97 },
            status,
        };
        let rows = [
            TrajectoryRow {
                fix: fix(7, 101.125, Status::Occluded),
                x_m: -0.0125,
                y_m: 0.5,
            },
            TrajectoryRow {
                fix: fix(8, f64::NAN, Status::Absent),
                x_m: f64::NAN,
                y_m: f64::NAN,
            },
        ];
        let mut out = Vec::new();
        write_track_rows(&mut out, &rows).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "frame,t_s,x_px,y_px,r_px,sigma_px,quality,status,x_m,y_m\n\
             7,0.0007,101.125,200.25,40.5,0.03,0.97,occluded,-0.0125,0.5\n\
             8,0.0008,,200.25,40.5,0.03,0,absent,,\n"
        );
    }

    /// Every CSV's header, one file a line: the contract users read (refresh with BOUNCELAB_BLESS=1).
    #[test]
    fn csv_headers_match_the_golden_file() {
        let actual: String = [
            ("estimates.csv", &ESTIMATE_COLUMNS[..]),
            ("comparison.csv", &COMPARISON_COLUMNS[..]),
            ("model_predictions.csv", &PREDICTION_COLUMNS[..]),
            ("model_curves.csv", &CURVE_COLUMNS[..]),
            ("contact_force.csv", &FORCE_COLUMNS[..]),
            ("surfaces.csv", &SURFACE_COLUMNS[..]),
        ]
        .iter()
        .map(|(f, c)| format!("{f}: {}\n", c.join(",")))
        .collect();
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/csv_headers.txt");
        if std::env::var_os("BOUNCELAB_BLESS").is_some() {
            std::fs::write(path, &actual).unwrap();
        }
        let expected = std::fs::read_to_string(path).expect("golden file (refresh with BOUNCELAB_BLESS=1)");
        assert!(
            expected == actual,
            "CSV headers changed (refresh with BOUNCELAB_BLESS=1)\n--- expected\n{expected}\n--- actual\n{actual}"
        );
    }

    /// `docs/outputs.md` names every column of `estimates.csv` (a standard error either by name or as the
    /// `(+ `_se_`)` of its quantity's line) and the trajectory columns in order.
    #[test]
    fn the_outputs_doc_names_every_estimate_and_trajectory_column() {
        let doc = include_str!("../../../docs/outputs.md");
        let section = |title: &str| {
            let start = doc
                .find(title)
                .unwrap_or_else(|| panic!("{title} not in docs/outputs.md"));
            let rest = &doc[start + title.len()..];
            &rest[..rest.find("\n## ").unwrap_or(rest.len())]
        };
        let estimates = section("## `estimates.csv`");
        for c in ESTIMATE_COLUMNS {
            let named = estimates.contains(&format!("`{c}`"));
            let by_quantity = c.contains("_se_") && {
                let value = format!("`{}`", c.replacen("_se_", "_", 1));
                estimates
                    .lines()
                    .any(|l| l.contains(&value) && l.contains("(+ `_se_`)"))
            };
            assert!(
                named || by_quantity,
                "estimates.csv column {c} is not in docs/outputs.md"
            );
        }
        let words: Vec<&str> = section("## The rest").split_whitespace().collect();
        assert!(
            words
                .join(" ")
                .contains(&format!("(`{}`)", TRAJECTORY_COLUMNS.join(", "))),
            "docs/outputs.md does not list the trajectory columns {TRAJECTORY_COLUMNS:?}"
        );
    }

    /// `shot 1` and `shot_1` wrote the same file; a 250-character name passed the name limit.
    #[test]
    fn trajectory_files_are_unique_bounded_and_stable() {
        let long = "é".repeat(200);
        let clips = [
            "shot 1",
            "shot_1",
            "Shot_1",
            "../up",
            ".hidden",
            "a/b",
            long.as_str(),
            "ok-1.2",
        ];
        let files = trajectory_files(clips);
        let mut names: Vec<&String> = files.values().collect();
        names.sort();
        names.dedup_by(|a, b| a.eq_ignore_ascii_case(b));
        assert_eq!(names.len(), clips.len(), "{files:?}");
        for (clip, f) in &files {
            assert!(f.len() <= MAX_STEM_BYTES + 20, "{clip}: {f}");
            assert!(f.ends_with(".csv") && !f.starts_with('.'), "{f}");
            assert!(f.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)), "{f}");
        }
        assert_eq!(files["shot_1"], "shot_1.csv");
        assert_eq!(files["ok-1.2"], "ok-1.2.csv");
        assert_ne!(files["shot 1"], files["shot_1"]);
        // The same names give the same files, whatever else is listed.
        assert_eq!(trajectory_files(["shot 1"])["shot 1"], files["shot 1"]);
    }

    /// Every column name but the text and dimensionless ones ends in a unit.
    #[test]
    fn every_column_names_its_unit() {
        let units = ["_m_s", "_ms", "_mm", "_deg", "_rad_s", "_m_s2", "_s", "_m", "_n", "_um"];
        let unitless = [
            "clip",
            "surface",
            "notes",
            "cor",
            "cor_se",
            "mu_eff",
            "mu_eff_se",
            "chi2_red_flight",
            "contact_line",
            "trajectory_share",
            "level_se_scale",
            "flags",
            "trajectory_file",
            "phase",
            "component",
            "unit",
            "n",
            "rms",
            "chi2_red",
            "cor_err",
            "mu_eff_err",
            "quantity",
            "mean",
            "sd",
            "frames",
            "v_out_t_err_pct",
            "v_out_n_err_pct",
            "cor_err_pct",
        ];
        for c in ESTIMATE_COLUMNS
            .iter()
            .chain(&COMPARISON_COLUMNS)
            .chain(&PREDICTION_COLUMNS)
            .chain(&CURVE_COLUMNS)
            .chain(&FORCE_COLUMNS)
            .chain(&SURFACE_COLUMNS)
        {
            assert!(
                unitless.contains(c) || units.iter().any(|u| c.ends_with(u)),
                "column {c} names no unit"
            );
        }
    }
}
