//! Plain records: what callers write (`*Record`) and what queries return (`*Row`).
//!
//! The caller converts from the pipeline's types (`frames::Session`, `track::Track`, `estimate::Estimate`,
//! `fit::FitResult`) except the trajectory, whose row is the tracker's own [`TrajectoryRow`] (the store comes
//! after the tracker in the pipeline). Numbers that are NaN are stored as SQL `NULL` and read back as NaN;
//! −0 is read back as 0 (SQLite keeps an integral real as an integer).

use std::collections::BTreeMap;
use std::fmt;

use bouncelab_track::TrajectoryRow;
use serde::{Deserialize, Serialize};

/// A session folder as loaded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SessionRecord {
    /// The session folder (canonical path as text); the natural key.
    pub path: String,
    /// `[session] description` of `session.toml`, if any.
    pub description: Option<String>,
    /// Fingerprint of `session.toml` and `clips.csv` (see [`crate::Fingerprint`]).
    pub settings_hash: String,
    /// The text of `session.toml`.
    pub session_toml: String,
}

/// A stored session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SessionRow {
    /// Row id.
    pub id: i64,
    /// What was written.
    pub record: SessionRecord,
    /// When first stored (ISO 8601, UTC).
    pub loaded_at: String,
    /// When last upserted (ISO 8601, UTC).
    pub updated_at: String,
}

/// One shot (a clip of a session) with its conditions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShotRecord {
    /// Clip name, as in `clips.csv`; unique within a session.
    pub clip: String,
    /// Surface name.
    pub surface: String,
    /// Surface inclination, degrees.
    pub angle_deg: f64,
    /// Drop height, m.
    pub drop_height_m: f64,
    /// Frame rate used, frames per second.
    pub fps: f64,
    /// Extra `clips.csv` columns.
    pub metadata: BTreeMap<String, String>,
    /// Fingerprint of the clip's frames and the settings that shape its track (see
    /// [`crate::fingerprint_clip_dir`]). When it changes, the shot's track and estimate are dropped.
    pub frames_hash: String,
}

/// Where a shot is in the analysis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShotStatus {
    /// Stored, not tracked yet (or its frames changed).
    Pending,
    /// Track stored, no estimate.
    Tracked,
    /// Track and estimate stored.
    Estimated,
    /// Tracking or estimation failed; the message is in `error`.
    Failed,
}

impl ShotStatus {
    /// The name stored in `shots.status`.
    pub fn as_str(self) -> &'static str {
        match self {
            ShotStatus::Pending => "pending",
            ShotStatus::Tracked => "tracked",
            ShotStatus::Estimated => "estimated",
            ShotStatus::Failed => "failed",
        }
    }

    pub(crate) fn parse(s: &str) -> Option<Self> {
        [
            ShotStatus::Pending,
            ShotStatus::Tracked,
            ShotStatus::Estimated,
            ShotStatus::Failed,
        ]
        .into_iter()
        .find(|v| v.as_str() == s)
    }
}

impl fmt::Display for ShotStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A stored shot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShotRow {
    /// Row id.
    pub id: i64,
    /// Its session.
    pub session_id: i64,
    /// What was written.
    pub record: ShotRecord,
    /// Where it is in the analysis.
    pub status: ShotStatus,
    /// Why it failed, when `status` is `Failed`.
    pub error: Option<String>,
    /// When last written (ISO 8601, UTC).
    pub updated_at: String,
}

/// What [`crate::Tx::upsert_shot`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShotUpsert {
    /// The shot's id.
    pub id: i64,
    /// The shot was not stored before.
    pub inserted: bool,
    /// It was stored with another fingerprint (its track and estimate were dropped).
    pub frames_changed: bool,
    /// It must be tracked: new, changed, never finished (`pending`, `tracked`) or `failed`. A shot whose
    /// fingerprint is unchanged and whose status is `estimated` needs nothing.
    pub needs_tracking: bool,
}

/// A shot's track: summary and per-frame rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrackRecord {
    /// Frames in the clip (dropped frames counted).
    pub frames: u64,
    /// Frames with a measured ball.
    pub measured: u64,
    /// Scale, metres per pixel, if found.
    pub scale_m_per_px: Option<f64>,
    /// Standard error of the scale, metres per pixel.
    pub scale_se: Option<f64>,
    /// Surface line height at the image centre, px (y down), if found.
    pub surface_y_px: Option<f64>,
    /// Surface line tilt in the image, degrees, if found.
    pub surface_tilt_deg: Option<f64>,
    /// Tracker warnings.
    pub warnings: Vec<String>,
    /// Wall time spent tracking, seconds.
    pub seconds: f64,
    /// Per-frame trajectory (`docs/outputs.md` columns); frames unique. Read back, each fix's `sigma_r_px`
    /// (not a column) is NaN.
    pub rows: Vec<TrajectoryRow>,
    /// What the camera file's header says (model, rate, exposure, bit depth, trigger), when the clip is a
    /// camera file; `None` for a folder of images or a track stored before it was kept.
    #[serde(default)]
    pub camera: Option<CameraRecord>,
}

/// A camera file's header as stored with its track.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CameraRecord {
    /// The file format (e.g. "Photron MRAW", "Phantom CINE").
    pub format: String,
    /// Camera model, as the header names it.
    pub model: Option<String>,
    /// Record rate from the header, frames/s.
    pub fps: Option<f64>,
    /// Exposure (shutter) time of one frame, s.
    pub exposure_s: Option<f64>,
    /// Bits per pixel the sensor filled (the effective depth, else the stored one).
    pub bit_depth: Option<u8>,
    /// Position in the file (0-based) of the trigger frame; may lie outside the stored frames.
    pub trigger_frame: Option<i64>,
}

/// A value with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ValueSe {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub se: f64,
}

impl ValueSe {
    /// A value and its standard error.
    pub fn new(value: f64, se: f64) -> Self {
        Self { value, se }
    }
}

/// A shot's estimates (`docs/outputs.md` `estimates.csv`), each with its standard error.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct EstimateRecord {
    /// Incoming tangential velocity, m/s.
    pub v_in_t: ValueSe,
    /// Incoming normal velocity, m/s (negative).
    pub v_in_n: ValueSe,
    /// Outgoing tangential velocity, m/s.
    pub v_out_t: ValueSe,
    /// Outgoing normal velocity, m/s (positive).
    pub v_out_n: ValueSe,
    /// Coefficient of restitution.
    pub cor: ValueSe,
    /// Effective friction coefficient.
    pub mu: ValueSe,
    /// Contact time, ms.
    pub contact_ms: ValueSe,
    /// Spin before impact, rad/s, if measured.
    pub spin_in: Option<ValueSe>,
    /// Spin after impact, rad/s, if measured.
    pub spin_out: Option<ValueSe>,
    /// Maximum penetration, mm (the unit of `estimates.csv`).
    pub delta_max_mm: ValueSe,
    /// Estimator notes.
    pub notes: Vec<String>,
    /// The estimator's full output as JSON (phases, flight arcs …) for later stages, if the caller keeps it.
    pub detail: Option<String>,
}

impl EstimateRecord {
    /// The measured quantities in the order of [`crate::ESTIMATE_QUANTITIES`] (their columns); `None` for a
    /// spin not measured.
    pub fn quantities(&self) -> [Option<ValueSe>; 10] {
        [
            Some(self.v_in_t),
            Some(self.v_in_n),
            Some(self.v_out_t),
            Some(self.v_out_n),
            Some(self.cor),
            Some(self.mu),
            Some(self.contact_ms),
            Some(self.delta_max_mm),
            self.spin_in,
            self.spin_out,
        ]
    }

    /// The record with these quantities (in [`EstimateRecord::quantities`]'s order), notes and detail; a
    /// quantity other than a spin that is `None` is NaN.
    pub fn from_quantities(q: [Option<ValueSe>; 10], notes: Vec<String>, detail: Option<String>) -> Self {
        let v = |x: Option<ValueSe>| x.unwrap_or(ValueSe::new(f64::NAN, f64::NAN));
        EstimateRecord {
            v_in_t: v(q[0]),
            v_in_n: v(q[1]),
            v_out_t: v(q[2]),
            v_out_n: v(q[3]),
            cor: v(q[4]),
            mu: v(q[5]),
            contact_ms: v(q[6]),
            delta_max_mm: v(q[7]),
            spin_in: q[8],
            spin_out: q[9],
            notes,
            detail,
        }
    }
}

/// An estimate joined with its shot's conditions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EstimateRow {
    /// The shot.
    pub shot_id: i64,
    /// Clip name.
    pub clip: String,
    /// Surface name.
    pub surface: String,
    /// Inclination, degrees.
    pub angle_deg: f64,
    /// Drop height, m.
    pub drop_height_m: f64,
    /// The estimate.
    pub estimate: EstimateRecord,
}

/// A model file version.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelVersionRecord {
    /// A name (the file's name or the model's).
    pub name: String,
    /// The text of `model.toml`.
    pub toml: String,
    /// The version it was derived from (e.g. before adding a suggested effect).
    pub parent_id: Option<i64>,
}

/// A stored model version.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelVersionRow {
    /// Row id (versions are numbered in the order they were first stored).
    pub id: i64,
    /// What was written.
    pub record: ModelVersionRecord,
    /// When first stored (ISO 8601, UTC).
    pub created_at: String,
}

/// A fit of a model version.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    /// The session fitted; `None` for a fit across sessions.
    pub session_id: Option<i64>,
    /// The model version fitted.
    pub model_version_id: i64,
    /// `fit.json` (must be valid JSON).
    pub json: String,
    /// χ² / (n − p).
    pub reduced_chi2: f64,
    /// RMS of the position residuals, m.
    pub rms_m: f64,
    /// The paper's mean absolute COR error, %, when any shot has a measured COR.
    pub mae_pct: Option<f64>,
}

/// A stored fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRow {
    /// Row id (increasing: the latest fit has the largest id).
    pub id: i64,
    /// What was written.
    pub record: FitRecord,
    /// When stored (ISO 8601, UTC).
    pub created_at: String,
}

/// A model version with the errors of its latest fit: the "did the error fall" history.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelHistoryRow {
    /// The version.
    pub version: ModelVersionRow,
    /// How many fits it has (in the session asked for, or in all).
    pub fits: u64,
    /// Its latest fit, without the JSON (`record.json` is empty).
    pub latest: Option<FitRow>,
}
