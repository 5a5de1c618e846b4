//! Shared test helper: small records in a line.
#![allow(dead_code)]

use bouncelab_store::*;
pub use bouncelab_track::{BallFix, Status, TrajectoryRow};

pub fn session(path: &str) -> SessionRecord {
    SessionRecord {
        path: path.to_string(),
        description: Some("clay vs tape".into()),
        settings_hash: "s1".into(),
        session_toml: "[ball]\ndiameter_m = 0.067\n".into(),
    }
}

pub fn shot(clip: &str, hash: &str) -> ShotRecord {
    ShotRecord {
        clip: clip.to_string(),
        surface: "clay".into(),
        angle_deg: 20.0,
        drop_height_m: 0.25,
        fps: 10_000.0,
        metadata: [("operator".to_string(), "ana".to_string())].into_iter().collect(),
        frames_hash: hash.to_string(),
    }
}

pub fn track(frames: u64) -> TrackRecord {
    TrackRecord {
        frames,
        measured: frames.saturating_sub(1),
        scale_m_per_px: Some(2.5e-4),
        scale_se: Some(1e-7),
        surface_y_px: Some(400.5),
        surface_tilt_deg: None,
        warnings: vec!["frame 3: ball cut by the border".into()],
        seconds: 0.125,
        camera: Some(CameraRecord {
            format: "Photron MRAW".into(),
            model: Some("FASTCAM SA-Z".into()),
            fps: Some(20_000.0),
            exposure_s: Some(2e-5),
            bit_depth: Some(12),
            trigger_frame: Some(-52),
        }),
        rows: (0..frames)
            .map(|i| TrajectoryRow {
                fix: BallFix {
                    frame: i as usize,
                    t_s: i as f64 * 1e-4,
                    x_px: 100.0 + i as f64,
                    y_px: 200.0 - 0.5 * i as f64,
                    r_px: 134.0,
                    sigma_px: 0.05,
                    sigma_r_px: 0.07,
                    quality: 0.9,
                    status: Status::Ok,
                },
                x_m: 0.001 * i as f64,
                y_m: 0.03,
            })
            .collect(),
    }
}

pub fn estimate(k: f64) -> EstimateRecord {
    let v = |x: f64| ValueSe::new(x + k, 0.01 * (x.abs() + 1.0));
    EstimateRecord {
        v_in_t: v(0.7),
        v_in_n: v(-2.1),
        v_out_t: v(0.5),
        v_out_n: v(1.6),
        cor: v(0.77),
        mu: v(0.31),
        contact_ms: v(4.46),
        spin_in: None,
        spin_out: Some(v(-15.0)),
        delta_max_mm: v(4.0),
        notes: vec!["spin in: seam not visible".into()],
        detail: Some(format!("{{\"k\": {k}}}")),
    }
}
