//! The results store: an embedded SQLite database (one file, WAL journal, foreign keys on) in which sessions,
//! shots, tracks with their trajectories, estimates, model versions and fits accumulate across sessions.
//!
//! The design choice is that the database is the unit of crash safety: every write runs inside an immediate
//! transaction, and a caller groups the writes that belong together (a shot, its track and its estimate) in
//! one [`Store::transaction`], so a run killed at any instant leaves each shot either complete or absent, and
//! re-running resumes. Incremental analysis rests on each shot's fingerprint ([`fingerprint_clip_dir`]):
//! [`Tx::upsert_shot`] says whether a shot must be tracked again. The crate takes plain records defined here,
//! and the tracker's own trajectory row (`bouncelab_track::TrajectoryRow`, status stored by its name); every
//! table exports to CSV. See `docs/store.md`.

mod error;
mod export;
mod fingerprint;
mod records;
mod schema;
mod store;

pub use error::{Result, StoreError};
pub use fingerprint::{ClipFingerprint, Fingerprint, fingerprint_clip_dir};
pub use records::{
    CameraRecord, EstimateRecord, EstimateRow, FitRecord, FitRow, ModelHistoryRow, ModelVersionRecord, ModelVersionRow,
    SessionRecord, SessionRow, ShotRecord, ShotRow, ShotStatus, ShotUpsert, TrackRecord, ValueSe,
};
pub use schema::{ESTIMATE_QUANTITIES, MIGRATIONS, Migration, Table, latest_version};
pub use store::{Store, StoreLock, Tx};
