//! From stored tracks and estimates to what the fit compares the model with.

use crate::AnalyzeError;
use bouncelab_estimate::{Estimate, MIN_SIGMA_PX};
use bouncelab_fit::{MeasuredFrame, MeasuredOutputs, MeasuredShot, StartState, State};
use bouncelab_store::{ShotStatus, Store, TrackRecord, TrajectoryRecord};
use bouncelab_track::{Status, TrajectoryRow};

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
    /// The stored track's summary; its per-frame rows are taken out into [`ShotData::rows`] (typed), so
    /// `track.rows` is empty.
    pub track: TrackRecord,
    /// The trajectory read back from the store (`docs/outputs.md` columns), one row per frame.
    pub rows: Vec<TrajectoryRow>,
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
        let (Some(mut track), Some(est)) = (store.track(row.id)?, store.estimate(row.id)?) else {
            continue;
        };
        let rows = trajectory_rows(&clip, &std::mem::take(&mut track.rows))?;
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
            &rows,
            &estimate,
        );
        out.push(ShotData {
            clip,
            surface: row.record.surface.clone(),
            angle_deg: row.record.angle_deg,
            drop_height_m: row.record.drop_height_m,
            metadata: row.record.metadata.clone().into_iter().collect(),
            track,
            rows,
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
/// fitted outgoing one that a fit weighs ([`Status::fitted`], the estimator's rule), each weighted by the
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
        .filter(|r| r.frame >= first && r.frame <= last)
        .filter(|r| r.status.fitted())
        .filter(|r| r.x_m.is_finite() && r.y_m.is_finite() && r.sigma_px.is_finite())
        .map(|r| MeasuredFrame {
            t_s: r.t_s,
            x_m: r.x_m,
            y_m: r.y_m,
            sigma_m: r.sigma_px.max(MIN_SIGMA_PX) * scale,
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
    }
}

/// The store's plain row for a trajectory row: the same fields, the status by [`Status::name`].
pub(crate) fn trajectory_record(r: &TrajectoryRow) -> TrajectoryRecord {
    TrajectoryRecord {
        frame: r.frame as u64,
        t_s: r.t_s,
        x_px: r.x_px,
        y_px: r.y_px,
        r_px: r.r_px,
        sigma_px: r.sigma_px,
        quality: r.quality,
        status: r.status.name().to_string(),
        x_m: r.x_m,
        y_m: r.y_m,
    }
}

/// A stored row back as the tracker's: the status read by [`Status::from_name`], so a status this build does
/// not know is an error naming the shot and the frame, never a frame silently left out.
pub(crate) fn trajectory_row(clip: &str, r: &TrajectoryRecord) -> Result<TrajectoryRow, AnalyzeError> {
    let bad = |why: String| AnalyzeError::BadTrajectoryRow {
        clip: clip.to_string(),
        frame: r.frame,
        why,
    };
    Ok(TrajectoryRow {
        frame: usize::try_from(r.frame).map_err(|e| bad(e.to_string()))?,
        t_s: r.t_s,
        x_px: r.x_px,
        y_px: r.y_px,
        r_px: r.r_px,
        sigma_px: r.sigma_px,
        quality: r.quality,
        status: Status::from_name(&r.status).map_err(|e| bad(e.to_string()))?,
        x_m: r.x_m,
        y_m: r.y_m,
    })
}

/// Every stored row of a shot's trajectory as [`trajectory_row`] reads it.
pub(crate) fn trajectory_rows(clip: &str, rows: &[TrajectoryRecord]) -> Result<Vec<TrajectoryRow>, AnalyzeError> {
    rows.iter().map(|r| trajectory_row(clip, r)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every field compared by its bits, so NaN (the tracker's "not measured") must survive too.
    fn same(a: &TrajectoryRow, b: &TrajectoryRow) -> bool {
        let bits =
            |r: &TrajectoryRow| [r.t_s, r.x_px, r.y_px, r.r_px, r.sigma_px, r.quality, r.x_m, r.y_m].map(f64::to_bits);
        a.frame == b.frame && a.status == b.status && bits(a) == bits(b)
    }

    fn any_f64() -> impl Strategy<Value = f64> {
        prop_oneof![
            any::<f64>(),
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(-0.0),
            -1e4..1e4f64
        ]
    }

    prop_compose! {
        fn any_row()(
            frame in 0..=(i64::MAX as usize),
            v in proptest::collection::vec(any_f64(), 8),
            status in proptest::sample::select(Status::ALL.to_vec()),
        ) -> TrajectoryRow {
            TrajectoryRow {
                frame, t_s: v[0], x_px: v[1], y_px: v[2], r_px: v[3], sigma_px: v[4], quality: v[5],
                status, x_m: v[6], y_m: v[7],
            }
        }
    }

    proptest! {
        /// The store keeps its own plain row (it depends on no other bouncelab crate): through it and back,
        /// every field of the tracker's row survives bit for bit.
        #[test]
        fn a_row_survives_the_store_record(row in any_row()) {
            let back = trajectory_row("c", &trajectory_record(&row)).unwrap();
            prop_assert!(same(&row, &back), "{row:?} -> {back:?}");
        }
    }

    /// The store cannot see the tracker's column list, so its `trajectory` table is checked against it here.
    #[test]
    fn the_store_trajectory_table_has_the_trajectory_columns() {
        let columns = bouncelab_store::Table::Trajectory.columns();
        assert_eq!(columns[0], "shot_id");
        assert_eq!(&columns[1..], &bouncelab_track::TRAJECTORY_COLUMNS[..]);
    }

    #[test]
    fn an_unknown_stored_status_names_the_shot_and_frame() {
        let mut record = trajectory_record(&TrajectoryRow {
            frame: 41,
            t_s: 0.0,
            x_px: 1.0,
            y_px: 2.0,
            r_px: 3.0,
            sigma_px: 0.1,
            quality: 1.0,
            status: Status::Ok,
            x_m: 0.0,
            y_m: 0.0,
        });
        record.status = "lost".into();
        let e = trajectory_rows("S007", &[record]).unwrap_err().to_string();
        assert!(
            e.contains("S007") && e.contains("frame 41") && e.contains("`lost`"),
            "{e}"
        );
    }
}
