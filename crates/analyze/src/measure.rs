//! The measuring stage: every clip of a session tracked and estimated, in parallel, through the store.
//!
//! A shot whose fingerprint (its frame files and every setting that shapes its track and estimate) is
//! unchanged and whose estimate is stored is not touched. The others are tracked on worker threads; each
//! result is written by the calling thread in one transaction (track, trajectory and estimate together), so a
//! run killed at any instant leaves each shot complete or absent and the next run resumes.

use crate::{AnalyzeError, Progress, Stage};
use bouncelab_estimate::{
    Conditions, Estimate, estimate_finding_downslope, estimate_with_frames, fall_se_deg, saturation_flag,
};
use bouncelab_frames::{ClipEntry, Downslope, ReadOptions, Session};
use bouncelab_store::{
    ClipFingerprint, EstimateRecord, Fingerprint, SessionRecord, ShotRecord, Store, TrackRecord, ValueSe,
    fingerprint_clip_dir,
};
use bouncelab_track::{ClipTracking, Track, track_clip};
use rayon::prelude::*;
use std::sync::mpsc;

/// What the measuring stage did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeasureSummary {
    /// The session's row id in the store.
    pub session_id: i64,
    /// Shots tracked and estimated in this run.
    pub measured: Vec<String>,
    /// Shots whose stored results were reused.
    pub reused: Vec<String>,
    /// Shots that could not be measured, with the reason (clip, message).
    pub failed: Vec<(String, String)>,
}

/// One clip to measure.
struct Job<'a> {
    shot_id: i64,
    entry: &'a ClipEntry,
}

/// The session's settings fingerprint: `session.toml` and `clips.csv` as read.
fn session_record(session: &Session) -> Result<SessionRecord, AnalyzeError> {
    let read = |name: &str| {
        let path = session.dir.join(name);
        std::fs::read_to_string(&path).map_err(|source| AnalyzeError::Io { path, source })
    };
    let (toml, csv) = (read("session.toml")?, read("clips.csv")?);
    let description = session
        .metadata
        .get("session")
        .and_then(|t| t.get("description"))
        .and_then(|d| d.as_str())
        .map(str::to_string);
    Ok(SessionRecord {
        path: session_key(session),
        description,
        settings_hash: Fingerprint::new().str(&toml).str(&csv).finish(),
        session_toml: toml,
    })
}

/// The session's natural key in the store: its canonical path.
pub(crate) fn session_key(session: &Session) -> String {
    session
        .dir
        .canonicalize()
        .unwrap_or_else(|_| session.dir.clone())
        .display()
        .to_string()
}

/// Raised whenever the tracker or the estimator changes what they record for a shot, so that shots
/// measured by an earlier build are measured again (2: estimates carry the surface line's σ; 3: the contact
/// line's source, the local frame along the measured tilt, the gravity check; 4: a rejected line lends no
/// tilt, an unmeasured tilt is in the errors, the surface's tilt setting; 5: the surface line from the mean
/// of the first frames, its tilt error counting the edge's roughness, flight bounding the prediction; 6: a
/// band's outer side looked for beyond the search window while a track settles, a reversed down-slope named;
/// 7: a ball first sighted late followed back from its sighting, a doubtful circle giving way to a clearer one
/// inside it; 8: the flights' and the onset's errors counting the residuals' correlation, an onset at the
/// edge of its window only bounded, the radius's change between the flights; 9: a track that left the ball
/// taken over by a pass tracked back from the clip's end; 10: the frames after a bounce measured again
/// backward, a found line's level measured again from the band's mean gray; 11: the trajectory's level from
/// the touch alone, a found line's level moved towards it by their weights; 12: the limb's silhouette in the
/// errors of the radius and of the centres' common offset; 13: a faint texture line looked for when no clear
/// line is found, the frames from a step no pass explained marked ambiguous; 14: a circle taken for the
/// ball only when its rim stands out of the noise, the frames before a lost rim taken from the pass from the
/// clip's end; 15: a circle acquired only when its rim stands out of the noise, a circle detected before
/// the ball's flight radius is known only within the radius range it was acquired with, the frames after a
/// step kept when the frames from the bounce measured again remove it; 16: a frame off the path its
/// neighbours give, further than the ball can stray, marked ambiguous; 17: the forward track starts from
/// the radius measured before the first sighting; 18: the sensor noise measured without the blocks that
/// hold none, and a border padded by repeating the frame's edge taken off; 19: dark letterbox bars that keep
/// one level through the clip taken off too; 20: a shot whose flights scatter beyond a tenth of the ball's
/// radius flagged, and a track that turns back above the contact line told from one with no impact; 21: the
/// gravity check's fall measured beyond what the rim's change explains; 22: a texture line's tilt measured
/// again on every column's edge in a 3 × 3 box's map of both gradients; 23: a flight whose measured radius
/// wanders beyond a hundredth of the ball's about a steady change flagged; 24: every circle measured again
/// against its neighbouring frames' mean rim, and moved onto the limb's silhouette; 25: a lost ball looked
/// for again frame by frame after a seed, not by its sightings' gap; 26: in noisy frames, a lost ball looked
/// for by its rim's strength around the prediction; 27: the surface's tilt weighed with the one the ball's
/// fall from rest implies; 28: a found line the ball passes in front of given up for the next line below,
/// and the limb learned over the whole flight, before and after the bounce; 29: a line's level measured
/// again, on a ragged edge, from the share of each row's pixels the backdrop cannot explain where the band's
/// mean gray does not tell it; 30: a ball that moves too little in one sighting gap sighted over two or
/// four, and a line's tilt the ball's fall contradicts kept with an error that covers the fall's; 31: the
/// limb's centre fitted again over its last 3 px, and taken where the deeper fit disagrees, else the two
/// averaged; 32: no level from the band's mean gray where a strip along its top lies beyond the backdrop's
/// gray; 33: a pressed ball's rim at its prediction kept however less clear than in flight; 34: the contact
/// level's error widened where the line and the ball's trajectory lie further apart than their errors allow;
/// 35: a backward fix after the bounce clearly further from the ball's size than the forward one does not
/// replace it).
const MEASUREMENT_REVISION: u32 = 35;

/// Everything besides the frame files that changes a shot's track or estimate.
fn settings_text(entry: &ClipEntry, gravity: f64) -> String {
    format!(
        "bouncelab {} rev {MEASUREMENT_REVISION} | fps {} ({:?}) | downslope {:?} (given {}) | diameter {} | scale {:?} | roi {:?} | line {:?} | tilt {:?} | incline se {:?} | dropped {:?} | angle {} | gravity {} | tracker {:?}",
        env!("CARGO_PKG_VERSION"),
        entry.fps,
        entry.fps_source,
        entry.downslope,
        entry.downslope_given,
        entry.settings.ball_diameter_m,
        entry.settings.scale_m_per_px,
        entry.settings.roi,
        entry.settings.contact_line,
        entry.settings.surface_tilt_deg,
        entry.settings.incline_se_deg,
        entry.settings.dropped_from_rest,
        entry.angle_deg,
        gravity,
        bouncelab_track::TrackOptions::default(),
    )
}

/// Tracks and estimates the shots of `session` that need it and records everything in `store`.
///
/// Shots that fail (no ball, ball leaving the frame, a flight too short …) are recorded as failed with their
/// reason and listed in the summary; the others go on. Errors are only those of the store itself.
pub fn measure_session(
    session: &Session,
    store: &mut Store,
    gravity: f64,
    fingerprint: ClipFingerprint,
    progress: &dyn Progress,
) -> Result<MeasureSummary, AnalyzeError> {
    let session_id = store.upsert_session(&session_record(session)?)?;
    let mut summary = MeasureSummary {
        session_id,
        ..MeasureSummary::default()
    };
    // Held from choosing the shots to the last one written: a second run on this store waits here, then
    // finds the shots measured instead of tracking them again.
    let _lock = store.lock_measuring(|holder| {
        progress.note(&format!(
            "waiting for another run on {} ({}) to finish measuring",
            store.path().display(),
            holder.map_or_else(|| "process unknown".to_string(), |p| format!("process {p}"))
        ))
    })?;
    record_unusable(session, store, session_id, progress, &mut summary)?;
    let jobs = shots_to_measure(session, store, session_id, gravity, fingerprint, &mut summary)?;
    progress.start(Stage::Track, jobs.len() as u64);
    measure_and_store(&jobs, store, gravity, progress, &mut summary)?;
    // Shots reused from the store may have failed before: list them too (those still listed).
    let listed = session.listed();
    for row in store.shots(session_id)? {
        if row.status == bouncelab_store::ShotStatus::Failed
            && listed.contains(&row.record.clip.as_str())
            && !summary.failed.iter().any(|(c, _)| *c == row.record.clip)
        {
            summary
                .failed
                .push((row.record.clip.clone(), row.error.clone().unwrap_or_default()));
        }
    }
    progress.finish(
        Stage::Track,
        &format!(
            "{} shot(s) tracked, {} reused, {} failed",
            summary.measured.len(),
            summary.reused.len(),
            summary.failed.len()
        ),
    );
    Ok(summary)
}

/// Records each row of `clips.csv` whose clip cannot be opened as a failed shot, with its reason: the
/// session goes on without it.
fn record_unusable(
    session: &Session,
    store: &mut Store,
    session_id: i64,
    progress: &dyn Progress,
    summary: &mut MeasureSummary,
) -> Result<(), AnalyzeError> {
    for u in &session.unusable {
        let record = ShotRecord {
            clip: u.name.clone(),
            surface: u.surface.clone(),
            angle_deg: u.angle_deg,
            drop_height_m: u.drop_height_m,
            fps: f64::NAN,
            metadata: u.metadata.iter().cloned().collect(),
            frames_hash: Fingerprint::new().str("unusable").str(&u.reason).finish(),
        };
        store.transaction(|tx| {
            let up = tx.upsert_shot(session_id, &record)?;
            tx.mark_failed(up.id, &u.reason)
        })?;
        progress.note(&format!("{}: {}", u.name, u.reason));
        summary.failed.push((u.name.clone(), u.reason.clone()));
    }
    Ok(())
}

/// Stores every clip's shot with its fingerprint and returns those that must be tracked; the others are
/// listed as reused.
fn shots_to_measure<'a>(
    session: &'a Session,
    store: &mut Store,
    session_id: i64,
    gravity: f64,
    fingerprint: ClipFingerprint,
    summary: &mut MeasureSummary,
) -> Result<Vec<Job<'a>>, AnalyzeError> {
    let mut jobs = Vec::new();
    for entry in &session.clips {
        let hash = fingerprint_clip_dir(&entry.dir, &settings_text(entry, gravity), fingerprint)?;
        let record = ShotRecord {
            clip: entry.name.clone(),
            surface: entry.surface.clone(),
            angle_deg: entry.angle_deg,
            drop_height_m: entry.drop_height_m,
            fps: entry.fps,
            metadata: entry.metadata.iter().cloned().collect(),
            frames_hash: hash,
        };
        let up = store.upsert_shot(session_id, &record)?;
        if up.needs_tracking {
            jobs.push(Job { shot_id: up.id, entry });
        } else {
            summary.reused.push(entry.name.clone());
        }
    }
    Ok(jobs)
}

/// Measures the `jobs` on rayon's threads while this thread writes each result in one transaction (track,
/// trajectory and estimate together), as it arrives. After a store error the remaining shots stay pending
/// and the error is returned.
fn measure_and_store(
    jobs: &[Job<'_>],
    store: &mut Store,
    gravity: f64,
    progress: &dyn Progress,
    summary: &mut MeasureSummary,
) -> Result<(), AnalyzeError> {
    let (tx, rx) = mpsc::channel();
    let mut store_error = None;
    std::thread::scope(|scope| {
        scope.spawn(move || {
            jobs.par_iter().for_each_with(tx, |tx, job| {
                let result = measure_clip(job.entry, gravity);
                // The receiver only goes away after a store error; the remaining shots then stay pending.
                let _ = tx.send((job.shot_id, job.entry.name.clone(), result));
            });
        });
        for (shot_id, clip, result) in rx {
            if store_error.is_some() {
                continue;
            }
            let written = store.transaction(|tx| match &result {
                Ok((track, Ok(estimate))) => {
                    tx.put_track(shot_id, track)?;
                    tx.put_estimate(shot_id, estimate)
                }
                Ok((track, Err(message))) => {
                    tx.put_track(shot_id, track)?;
                    tx.mark_failed(shot_id, message)
                }
                Err(message) => tx.mark_failed(shot_id, message),
            });
            match (written, result) {
                (Err(e), _) => store_error = Some(e),
                (Ok(()), Ok((_, Ok(_)))) => summary.measured.push(clip),
                (Ok(()), Ok((_, Err(m))) | Err(m)) => {
                    progress.note(&format!("{clip}: {m}"));
                    summary.failed.push((clip, m));
                }
            }
            progress.advance(Stage::Track, 1);
        }
    });
    match store_error {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}

type Measured = Result<(TrackRecord, Result<EstimateRecord, String>), String>;

/// Tracks and estimates one clip on the calling thread.
fn measure_clip(entry: &ClipEntry, gravity: f64) -> Measured {
    let clip = entry.open().map_err(|e| e.to_string())?;
    let settings = &entry.settings;
    let opts = ClipTracking {
        read: ReadOptions::with_threads(1),
        ..ClipTracking::for_settings(settings, entry.downslope == Downslope::MinusX)
    };
    let started = std::time::Instant::now();
    let track = track_clip(&clip, &opts, |_, _| {}).map_err(|e| format!("tracking: {e}"))?;
    let conditions = Conditions {
        incline_deg: entry.angle_deg,
        gravity,
        ball_diameter_m: settings.ball_diameter_m,
        surface_tilt_deg: settings.surface_tilt_deg,
        fall_se_deg: fall_se_deg(settings.dropped_from_rest, settings.incline_se_deg),
    };
    // Without a down-slope direction given, the flights' fall is checked against the default.
    let estimate = if entry.downslope_given {
        estimate_with_frames(&track, &clip, &conditions)
    } else {
        estimate_finding_downslope(&track, &clip, &conditions)
    };
    // The trajectory in the estimate's local frame (on the contact line it chose, along its tilt), else in
    // the frame of the line the tracker found.
    let frame = estimate.as_ref().ok().and_then(|e| e.frame);
    let line = estimate.as_ref().ok().and_then(|e| e.contact_line).or(track.surface);
    let mut record = track_record(&track, frame.as_ref(), line.as_ref(), started.elapsed().as_secs_f64());
    record.camera = camera_record(clip.camera());
    Ok((
        record,
        estimate
            .map(|e| estimate_record(&e))
            .map_err(|e| match saturation_flag(&track) {
                Some(why) => format!("estimating: {e}; {why}"),
                None => format!("estimating: {e}"),
            }),
    ))
}

/// What a camera file's header says, as stored with the track; `None` for a folder of images, whose files say
/// none of it.
fn camera_record(info: &bouncelab_frames::CameraInfo) -> Option<bouncelab_store::CameraRecord> {
    (info.format != bouncelab_frames::SourceFormat::Folder).then(|| bouncelab_store::CameraRecord {
        format: info.format.label().to_string(),
        model: info.camera_model.clone(),
        fps: info.fps,
        exposure_s: info.exposure_s,
        bit_depth: info.effective_bit_depth.or(info.bit_depth),
        trigger_frame: info.trigger_frame,
    })
}

fn track_record(
    track: &Track,
    frame: Option<&bouncelab_track::SurfaceFrame>,
    line: Option<&bouncelab_track::SurfaceLine>,
    seconds: f64,
) -> TrackRecord {
    let rows = match frame {
        Some(f) => track.rows_in(Some(f)),
        None => track.rows(),
    };
    TrackRecord {
        frames: track.fixes.len() as u64,
        measured: track.fixes.iter().filter(|f| f.status.measured()).count() as u64,
        scale_m_per_px: track.scale.map(|s| s.m_per_px),
        scale_se: track.scale.map(|s| s.sigma_m_per_px),
        surface_y_px: line.map(|l| l.y0),
        surface_tilt_deg: line.map(|l| l.tilt_deg()),
        warnings: track.warnings.clone(),
        seconds,
        camera: None,
        rows,
    }
}

/// An estimate's measured quantities in the order of [`bouncelab_store::ESTIMATE_QUANTITIES`], in the units
/// their column names give: what the store's `estimates` table and `estimates.csv` both hold.
pub(crate) fn estimate_quantities(e: &Estimate) -> [Option<ValueSe>; 10] {
    let v = |m: bouncelab_estimate::Measured| Some(ValueSe::new(m.value, m.se));
    [
        v(e.v_in[0]),
        v(e.v_in[1]),
        v(e.v_out[0]),
        v(e.v_out[1]),
        v(e.cor),
        // + 0.0: a friction of zero is written 0, not −0.
        Some(ValueSe::new(e.mu.value + 0.0, e.mu.se)),
        v(e.contact_ms),
        Some(ValueSe::new(e.delta_max_m.value * 1e3, e.delta_max_m.se * 1e3)),
        e.spin_in.and_then(v),
        e.spin_out.and_then(v),
    ]
}

fn estimate_record(e: &Estimate) -> EstimateRecord {
    EstimateRecord::from_quantities(estimate_quantities(e), e.notes.clone(), serde_json::to_string(e).ok())
}
