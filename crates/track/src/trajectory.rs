//! The trajectory row: one frame of a track in pixels and in the local frame, as `trajectories/<clip>.csv`,
//! `bouncelab track` and the store's `trajectory` table hold it (`docs/outputs.md`).

use crate::tracker::Status;
use serde::{Deserialize, Serialize};

/// The columns of a trajectory, in order: the header of `trajectories/<clip>.csv` and of `bouncelab track`'s
/// output, and the store's `trajectory` table after its `shot_id`. Each name is a field of [`TrajectoryRow`].
pub const TRAJECTORY_COLUMNS: [&str; 10] = [
    "frame", "t_s", "x_px", "y_px", "r_px", "sigma_px", "quality", "status", "x_m", "y_m",
];

/// One frame of a trajectory in pixels and in the local frame (the `trajectories/<clip>.csv` row).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryRow {
    /// Frame index (position in the clip, dropped frames counted).
    pub frame: usize,
    /// Time, s.
    pub t_s: f64,
    /// Centre x, px.
    pub x_px: f64,
    /// Centre y, px (down).
    pub y_px: f64,
    /// Radius, px.
    pub r_px: f64,
    /// Standard error of each centre coordinate, px.
    pub sigma_px: f64,
    /// Quality 0–1.
    pub quality: f64,
    /// What the tracker said (written as [`Status::name`]).
    pub status: Status,
    /// Along the surface, down-slope, m (origin at the contact column).
    pub x_m: f64,
    /// Above the surface line, m.
    pub y_m: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_serde_header_is_the_column_list_and_statuses_keep_their_names() {
        let row = |status| TrajectoryRow {
            frame: 3,
            t_s: 0.5,
            x_px: 1.0,
            y_px: 2.0,
            r_px: 3.0,
            sigma_px: 0.1,
            quality: 0.9,
            status,
            x_m: 0.01,
            y_m: 0.02,
        };
        let mut w = csv::Writer::from_writer(Vec::new());
        for s in Status::ALL {
            w.serialize(row(s)).unwrap();
        }
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next().unwrap(), TRAJECTORY_COLUMNS.join(","));
        for (s, line) in Status::ALL.into_iter().zip(lines) {
            assert_eq!(line.split(',').nth(7), Some(s.name()), "{line}");
            assert_eq!(Status::from_name(s.name()), Ok(s));
        }
        assert_eq!(
            Status::from_name("lost").unwrap_err().to_string(),
            "unknown status `lost` (known: ok, occluded, cut_by_border, absent, ambiguous)"
        );
    }
}
