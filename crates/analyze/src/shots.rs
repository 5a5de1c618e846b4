//! From stored tracks and estimates to what the fit compares the model with.

use crate::AnalyzeError;
use bouncelab_estimate::{Estimate, MIN_SIGMA_PX};
use bouncelab_fit::{MeasuredFrame, MeasuredOutputs, MeasuredShot, StartState, State};
use bouncelab_store::{ShotStatus, Store, TrackRecord};
use bouncelab_track::TrajectoryRow;

/// One measured shot with everything later stages show: its conditions, its track and its estimate.
#[derive(Debug, Clone)]
pub struct ShotData {
    /// Clip name.
    pub clip: String,
    /// Surface name.
    pub surface: String,
    /// Incline, degrees.
    pub angle_deg: f64,
    /// Drop height from `clips.csv`, m.
    pub drop_height_m: f64,
    /// Extra `clips.csv` columns.
    pub metadata: Vec<(String, String)>,
    /// The stored track: its summary and its trajectory (`docs/outputs.md` columns), one row per frame.
    pub track: TrackRecord,
    /// The estimator's output.
    pub estimate: Estimate,
    /// What the fit uses: the frames from the first fitted incoming frame to the last fitted outgoing one.
    pub measured: MeasuredShot,
}

/// The session's estimated shots among `listed` (the clip names `clips.csv` lists now: a clip removed from
/// it stays in the store but is not analysed), in order of insertion, read back from the store.
///
/// A stored estimate without its detail (written by an older program) is an error naming the shot: re-run
/// with the store removed, or touch the clip's folder, to measure it again.
pub fn load_shots(store: &Store, session_id: i64, listed: &[&str]) -> Result<Vec<ShotData>, AnalyzeError> {
    let mut out = Vec::new();
    for row in store.shots(session_id)? {
        if row.status != ShotStatus::Estimated || !listed.contains(&row.record.clip.as_str()) {
            continue;
        }
        let clip = row.record.clip.clone();
        let (Some(track), Some(est)) = (store.track(row.id)?, store.estimate(row.id)?) else {
            continue;
        };
        let estimate: Estimate = est
            .detail
            .as_deref()
            .and_then(|d| serde_json::from_str(d).ok())
            .ok_or_else(|| AnalyzeError::StaleStore { clip: clip.clone() })?;
        let measured = measured_shot(
            &clip,
            &row.record.surface,
            row.record.angle_deg,
            track.scale_m_per_px,
            &track.rows,
            &estimate,
        );
        out.push(ShotData {
            clip,
            surface: row.record.surface.clone(),
            angle_deg: row.record.angle_deg,
            drop_height_m: row.record.drop_height_m,
            metadata: row.record.metadata.clone().into_iter().collect(),
            track,
            estimate,
            measured,
        });
    }
    Ok(out)
}

/// The stored tracks of the session's shots among `listed` that could not be estimated, with their
/// failure: (clip, track, reason). Shots that failed before a track was made are left out (see
/// [`crate::MeasureSummary::failed`]).
pub fn load_failed_tracks(
    store: &Store,
    session_id: i64,
    listed: &[&str],
) -> Result<Vec<(String, TrackRecord, String)>, AnalyzeError> {
    let mut out = Vec::new();
    for row in store.shots(session_id)? {
        if row.status != ShotStatus::Failed || !listed.contains(&row.record.clip.as_str()) {
            continue;
        }
        if let Some(track) = store.track(row.id)? {
            out.push((row.record.clip.clone(), track, row.error.clone().unwrap_or_default()));
        }
    }
    Ok(out)
}

/// The fit's view of one shot: frames (local frame, m) from the first fitted incoming frame to the last
/// fitted outgoing one that a fit weighs ([`bouncelab_track::Status::fitted`], the estimator's rule), each weighted by the
/// tracker's σ (floored as the estimator floors it) times the scale (m/px; NaN metres when the track has
/// none), and the simulation's start taken from the incoming ballistic arc at the first of those frames.
pub fn measured_shot(
    clip: &str,
    surface: &str,
    angle_deg: f64,
    scale_m_per_px: Option<f64>,
    rows: &[TrajectoryRow],
    e: &Estimate,
) -> MeasuredShot {
    let scale = scale_m_per_px.unwrap_or(f64::NAN);
    let (first, last) = (e.phases.flight_in.0, e.phases.flight_out.1);
    let frames: Vec<MeasuredFrame> = rows
        .iter()
        .filter(|r| r.fix.frame >= first && r.fix.frame <= last)
        .filter(|r| r.fix.status.fitted())
        .filter(|r| r.x_m.is_finite() && r.y_m.is_finite() && r.fix.sigma_px.is_finite())
        .map(|r| MeasuredFrame {
            t_s: r.fix.t_s,
            x_m: r.x_m,
            y_m: r.y_m,
            sigma_m: r.fix.sigma_px.max(MIN_SIGMA_PX) * scale,
        })
        .collect();
    let t0 = frames.first().map_or(e.t_touch.value, |f| f.t_s);
    let p = e.flight_in.position(t0);
    let v = e.flight_in.velocity(t0);
    let state = State {
        x: p[0],
        y: p[1],
        theta: 0.0,
        vx: v[0],
        vy: v[1],
        omega: e.spin_in.map_or(0.0, |s| s.value),
    };
    MeasuredShot {
        name: clip.to_string(),
        surface: surface.to_string(),
        incline_rad: angle_deg.to_radians(),
        frames,
        start: StartState { t_s: t0, state },
        measured: Some(MeasuredOutputs {
            v_out: [e.v_out[0].value, e.v_out[1].value],
            cor: e.cor.value,
            mu: e.mu.value,
        }),
        surface_sigma_m: Some(e.surface_sigma_m).filter(|s| s.is_finite() && *s > 0.0),
        frame_sigma_rad: e
            .surface_tilt_deg
            .map(|t| t.se.to_radians())
            .filter(|s| s.is_finite() && *s > 0.0),
        spin_sigma_rad_s: e.spin_in.map(|s| s.se).filter(|s| s.is_finite() && *s > 0.0),
        rim_change_m: e
            .rim_change_px
            .map(|c| [c.value * scale, c.se * scale])
            .filter(|c| c.iter().all(|v| v.is_finite())),
    }
}
