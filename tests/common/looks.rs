//! The tracker and estimator against the renderer's truth on sessions of many looks (`[look]` scenarios):
//! per clip the frames found, the centre error in flight and in contact, the contact level's error, COR and μ
//! errors; per look family the same summarised. Shared by `examples/looks_accuracy.rs` (the full sweep) and
//! `tests/looks.rs` (the small set `cargo test` runs). Nothing inside the pipeline sees the truth.

#![allow(dead_code)]

use bouncelab_estimate::{Conditions, estimate_finding_downslope, estimate_with_frames, fall_se_deg};
use bouncelab_frames::Session;
use bouncelab_track::{ClipTracking, Status, track_clip};
use std::collections::BTreeMap;
use std::path::Path;

/// What one clip gave against its truth.
#[derive(Debug, Clone)]
pub struct ClipResult {
    pub clip: String,
    /// Look family tags of the clip (`truth/looks.csv`).
    pub families: Vec<String>,
    /// Frames with the ball measured `ok`/`occluded` and visible in truth, and frames visible in truth.
    pub frames_found: (usize, usize),
    /// Measured frames whose centre lies more than 1 px from the truth: a rim misread, or another object.
    pub frames_over_1px: usize,
    /// Measured frames whose centre lies more than a quarter of the ball's radius from the truth: another
    /// object taken for the ball (no misread rim moves a centre that far).
    pub frames_off_ball: usize,
    /// Centre RMS error in flight and in contact, px (the clip's constant offset included).
    pub centre_rms_px: (f64, f64),
    /// The clip's constant offset: the mean centre error (x, y) in flight, px. On the `looks` preset's lit
    /// balls it lies along the light's axis (the shaded side's edge found off the silhouette, see
    /// `docs/accuracy.md`). A constant offset moves no velocity; it moves where the ball's bottom
    /// stands against the line.
    pub flight_offset_px: (f64, f64),
    /// Centre RMS error in flight about that offset, px: what the frame-to-frame measurement adds.
    pub flight_rms_about_offset_px: f64,
    /// Why the shot could not be measured, if it could not.
    pub failure: Option<String>,
    /// Contact line used (its cue), its level error at the truth's column, px (measured − truth, + down), and
    /// the line's part of the contact level's standard error as the estimator takes it, px
    /// (`SurfaceLine::level_sigma_px`, times √(1 − the trajectory's share) for a level moved towards the
    /// trajectory's, `Estimate::trajectory_share`, and by `Estimate::level_se_scale` where the two disagree).
    pub level: Option<(String, f64, f64)>,
    /// COR and μ: (estimate, SE, truth).
    pub cor: Option<(f64, f64, f64)>,
    pub mu: Option<(f64, f64, f64)>,
    /// Surface tilt error, degrees (measured − truth), and its stated standard error, when a line was found.
    pub tilt_err_deg: Option<(f64, f64)>,
}

fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt()
}

/// Reads a CSV into rows of (header → value).
fn read_csv(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let h = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            h.iter()
                .zip(rec.iter())
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .collect()
        })
        .collect()
}

fn num(row: &BTreeMap<String, String>, key: &str) -> f64 {
    row.get(key)
        .unwrap_or_else(|| panic!("column {key}"))
        .parse()
        .unwrap_or(f64::NAN)
}

/// Tracks and estimates every clip of the session at `session_dir` against `truth_dir`.
pub fn evaluate(session_dir: &Path, truth_dir: &Path) -> Vec<ClipResult> {
    evaluate_with(session_dir, truth_dir, GivenLine::None)
}

/// Which line, if any, each clip is given as its contact line, as a lab enters a line it measured.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum GivenLine {
    /// None: the tracker finds it, as in `analyze`.
    None,
    /// The truth's surface plane: what the tracker and estimator reach with the line exactly right.
    Plane,
    /// The least-squares line through the band's edge as drawn (`truth/edges.csv`): the best any finder
    /// looking at that edge can do, since a ragged edge's own line is not the plane it was drawn about.
    DrawnEdge,
}

/// [`evaluate`] with each clip given `line` (see [`GivenLine`]).
pub fn evaluate_with(session_dir: &Path, truth_dir: &Path, line: GivenLine) -> Vec<ClipResult> {
    let session = Session::load(session_dir).expect("session");
    let mut shots = read_csv(&truth_dir.join("shots.csv"));
    let looks = read_csv(&truth_dir.join("looks.csv"));
    if line == GivenLine::DrawnEdge {
        let edges = read_csv(&truth_dir.join("edges.csv"));
        for s in &mut shots {
            let e = edges.iter().find(|e| e["clip"] == s["clip"]).expect("edges.csv row");
            s.insert("given_y_px".into(), e["drawn_edge_y_px"].clone());
            s.insert("given_tilt_deg".into(), e["drawn_edge_tilt_deg"].clone());
        }
    } else if line == GivenLine::Plane {
        for s in &mut shots {
            let (y, t) = (s["surface_y_px"].clone(), s["surface_tilt_deg"].clone());
            s.insert("given_y_px".into(), y);
            s.insert("given_tilt_deg".into(), t);
        }
    }
    let mut out = Vec::new();
    for truth in &shots {
        let name = &truth["clip"];
        let families = looks
            .iter()
            .find(|l| &l["clip"] == name)
            .map(|l| {
                l["families"]
                    .split('+')
                    .filter(|s| !s.is_empty())
                    .map(str::to_string)
                    .collect()
            })
            .unwrap_or_default();
        out.push(evaluate_clip(&session, truth, truth_dir, families));
    }
    out
}

fn evaluate_clip(
    session: &Session,
    truth: &BTreeMap<String, String>,
    truth_dir: &Path,
    families: Vec<String>,
) -> ClipResult {
    let name = truth["clip"].clone();
    let mut result = ClipResult {
        clip: name.clone(),
        families,
        frames_found: (0, 0),
        frames_over_1px: 0,
        frames_off_ball: 0,
        centre_rms_px: (f64::NAN, f64::NAN),
        flight_offset_px: (f64::NAN, f64::NAN),
        flight_rms_about_offset_px: f64::NAN,
        failure: None,
        level: None,
        cor: None,
        mu: None,
        tilt_err_deg: None,
    };
    let entry = session.clip(&name).expect("clip listed");
    let clip = match entry.open() {
        Ok(c) => c,
        Err(e) => {
            result.failure = Some(format!("opening: {e}"));
            return result;
        }
    };
    let opts = ClipTracking {
        ball_diameter_m: session.ball.diameter_m,
        downslope_negative_x: entry.downslope == bouncelab_frames::Downslope::MinusX,
        contact_line: truth
            .get("given_y_px")
            .filter(|y| !y.is_empty())
            .map(|_| bouncelab_frames::ContactLine {
                y_px: num(truth, "given_y_px"),
                tilt_deg: num(truth, "given_tilt_deg"),
            }),
        ..ClipTracking::default()
    };
    let track = match track_clip(&clip, &opts, |_, _| {}) {
        Ok(t) => t,
        Err(e) => {
            result.failure = Some(format!("tracking: {e}"));
            return result;
        }
    };
    let frames = read_csv(&truth_dir.join(format!("{name}.csv")));
    let (mut flight_xy, mut contact) = (Vec::new(), Vec::new());
    let mut visible = 0;
    for (f, t) in track.fixes.iter().zip(&frames) {
        if t["visible"] != "full" {
            continue;
        }
        visible += 1;
        if !matches!(f.status, Status::Ok | Status::Occluded) {
            continue;
        }
        let (ex, ey) = (f.x_px - num(t, "x_px"), f.y_px - num(t, "y_px"));
        let e = ex.hypot(ey);
        if e > 1.0 {
            result.frames_over_1px += 1;
        }
        if e > 0.25 * num(t, "r_px") {
            result.frames_off_ball += 1;
        }
        if t["phase"] == "flight" {
            flight_xy.push((ex, ey));
        } else {
            contact.push(e);
        }
    }
    let flight: Vec<f64> = flight_xy.iter().map(|e| e.0.hypot(e.1)).collect();
    result.frames_found = (flight.len() + contact.len(), visible);
    result.centre_rms_px = (rms(&flight), rms(&contact));
    if !flight_xy.is_empty() {
        let n = flight_xy.len() as f64;
        let (mx, my) = flight_xy.iter().fold((0.0, 0.0), |a, e| (a.0 + e.0 / n, a.1 + e.1 / n));
        result.flight_offset_px = (mx, my);
        let about: Vec<f64> = flight_xy.iter().map(|e| (e.0 - mx).hypot(e.1 - my)).collect();
        result.flight_rms_about_offset_px = rms(&about);
    }
    let conditions = Conditions {
        incline_deg: entry.angle_deg,
        gravity: 9.81,
        ball_diameter_m: session.ball.diameter_m,
        surface_tilt_deg: None,
        fall_se_deg: fall_se_deg(entry.settings.dropped_from_rest, entry.settings.incline_se_deg),
    };
    // As `analyze` does: without a down-slope given, the flights' fall is checked against the default.
    let estimate = if entry.downslope_given {
        estimate_with_frames(&track, &clip, &conditions)
    } else {
        estimate_finding_downslope(&track, &clip, &conditions)
    };
    match estimate {
        Ok(e) => {
            if let Some(line) = e.contact_line {
                // The truth's surface line is given at the image's centre column.
                let xc = (clip.dimensions().0 as f64 - 1.0) / 2.0;
                let err = line.y_at(xc) - num(truth, "surface_y_px");
                // A level partly from the trajectory has the line's variance times the line's weight,
                // widened where the two disagree.
                let sigma = line.level_sigma_px() * (1.0 - e.trajectory_share).sqrt() * e.level_se_scale;
                result.level = Some((line.cue.name().to_string(), err, sigma));
            }
            result.cor = Some((e.cor.value, e.cor.se, num(truth, "cor")));
            result.mu = Some((e.mu.value, e.mu.se, num(truth, "mu_eff")));
            result.tilt_err_deg = e
                .surface_tilt_deg
                .map(|t| (t.value - num(truth, "surface_tilt_deg"), t.se));
            if !e.flags.is_empty() {
                result.failure = Some(format!("flagged: {}", e.flags.join("; ")));
            }
        }
        Err(e) => result.failure = Some(format!("estimating: {e}")),
    }
    result
}

/// One Markdown table row per clip.
pub fn clip_table(results: &[ClipResult]) -> String {
    let mut s = String::from(
        "| clip | frames found | over 1 px off | on another object | flight RMS px | flight offset px | about it px | contact RMS px | line | level err px | COR err | μ err | tilt err ° | failure |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in results {
        let f = |v: Option<f64>, d: usize| v.map_or("–".to_string(), |v| format!("{v:+.d$}"));
        s += &format!(
            "| {} | {}/{} | {} | {} | {:.3} | ({:+.2}, {:+.2}) | {:.3} | {:.3} | {} | {} | {} | {} | {} | {} |\n",
            r.clip,
            r.frames_found.0,
            r.frames_found.1,
            r.frames_over_1px,
            r.frames_off_ball,
            r.centre_rms_px.0,
            r.flight_offset_px.0,
            r.flight_offset_px.1,
            r.flight_rms_about_offset_px,
            r.centre_rms_px.1,
            r.level.as_ref().map_or("–".into(), |l| l.0.clone()),
            r.level
                .as_ref()
                .map_or("–".into(), |l| format!("{:+.2} ± {:.2}", l.1, l.2)),
            f(r.cor.map(|c| c.0 - c.2), 4),
            f(r.mu.map(|c| c.0 - c.2), 4),
            r.tilt_err_deg
                .map_or("–".into(), |t| format!("{:+.3} ± {:.3}", t.0, t.1)),
            r.failure.as_deref().unwrap_or("")
        );
    }
    s
}

/// One Markdown table row per look family: clips, shots lost (no estimate), shots flagged (an estimate the
/// estimator says not to trust), frames found, the frames over 1 px off and those on another object (see
/// [`ClipResult::frames_off_ball`]), centre RMS in flight (and
/// about each clip's constant offset, see [`ClipResult::flight_offset_px`]) and in contact, contact level
/// RMS error, and COR and μ RMS and worst error over the shots estimated without a
/// flag.
pub fn family_table(results: &[ClipResult]) -> String {
    let mut fams: BTreeMap<String, Vec<&ClipResult>> = BTreeMap::new();
    for r in results {
        for f in &r.families {
            fams.entry(f.clone()).or_default().push(r);
        }
        fams.entry("(all)".into()).or_default().push(r);
    }
    let mut s = String::from(
        "| family | clips | lost | flagged | frames found | over 1 px off | on another object | flight RMS px | about offsets px | contact RMS px | level RMS px | COR RMS / worst | μ RMS / worst |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (fam, rs) in &fams {
        let flagged = |r: &&&ClipResult| r.failure.as_deref().is_some_and(|f| f.starts_with("flagged"));
        let lost = rs.iter().filter(|r| r.failure.is_some()).count() - rs.iter().filter(flagged).count();
        let trusted = || rs.iter().filter(|r| r.failure.is_none());
        let found: usize = rs.iter().map(|r| r.frames_found.0).sum();
        let vis: usize = rs.iter().map(|r| r.frames_found.1).sum();
        let over_1px: usize = rs.iter().map(|r| r.frames_over_1px).sum();
        let off_ball: usize = rs.iter().map(|r| r.frames_off_ball).sum();
        let all =
            |k: fn(&ClipResult) -> f64| -> Vec<f64> { rs.iter().map(|r| k(r)).filter(|v| v.is_finite()).collect() };
        let cor: Vec<f64> = trusted().filter_map(|r| r.cor.map(|c| c.0 - c.2)).collect();
        let mu: Vec<f64> = trusted().filter_map(|r| r.mu.map(|c| c.0 - c.2)).collect();
        let worst = |v: &[f64]| v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        s += &format!(
            "| {fam} | {} | {lost} | {} | {found}/{vis} | {over_1px} | {off_ball} | {:.3} | {:.3} | {:.3} | {:.2} | {:.4} / {:.4} | {:.4} / {:.4} |\n",
            rs.len(),
            rs.iter().filter(flagged).count(),
            rms(&all(|r| r.centre_rms_px.0)),
            rms(&all(|r| r.flight_rms_about_offset_px)),
            rms(&all(|r| r.centre_rms_px.1)),
            rms(&rs
                .iter()
                .filter_map(|r| r.level.as_ref().map(|l| l.1))
                .collect::<Vec<_>>()),
            rms(&cor),
            worst(&cor),
            rms(&mu),
            worst(&mu),
        );
    }
    s
}

/// One Markdown table row for COR and one for μ over the shots estimated without a flag: shots, RMS error,
/// RMS of error/SE (1 when the stated standard errors are honest) and the shots more than 3 SE off.
pub fn se_table(results: &[ClipResult]) -> String {
    let mut s = String::from("| estimate | shots | RMS error | RMS error/SE | beyond 3 SE |\n|---|---|---|---|---|\n");
    let trusted = || results.iter().filter(|r| r.failure.is_none());
    for (name, values) in [
        ("COR", trusted().filter_map(|r| r.cor).collect::<Vec<_>>()),
        ("μ_eff", trusted().filter_map(|r| r.mu).collect()),
    ] {
        let errs: Vec<f64> = values.iter().map(|(v, _, t)| v - t).collect();
        let z: Vec<f64> = values.iter().map(|(v, se, t)| (v - t) / se).collect();
        s += &format!(
            "| {name} | {} | {:.4} | {:.2} | {} |\n",
            values.len(),
            rms(&errs),
            rms(&z),
            z.iter().filter(|z| z.abs() > 3.0).count()
        );
    }
    s
}

/// One Markdown table row per contact-line cue: how far the contact level stands from the truth's surface
/// against the standard error stated for it (see [`ClipResult::level`]): shots, RMS error, RMS of error/σ
/// (1 when the stated errors are honest), and the shots more than 3 σ off.
pub fn level_table(results: &[ClipResult]) -> String {
    let mut cues: BTreeMap<&str, Vec<(f64, f64)>> = BTreeMap::new();
    for (cue, err, sigma) in results.iter().filter_map(|r| r.level.as_ref()) {
        cues.entry(cue.as_str()).or_default().push((*err, *sigma));
    }
    let mut s = String::from("| line cue | shots | level RMS px | RMS error/σ | beyond 3σ |\n|---|---|---|---|---|\n");
    for (cue, v) in &cues {
        let z: Vec<f64> = v.iter().map(|(e, sd)| e / sd).collect();
        let errs: Vec<f64> = v.iter().map(|(e, _)| *e).collect();
        s += &format!(
            "| {cue} | {} | {:.2} | {:.2} | {} |\n",
            v.len(),
            rms(&errs),
            rms(&z),
            z.iter().filter(|z| z.abs() > 3.0).count()
        );
    }
    s
}
