//! A real recording (a Photron MRAW/CIHX file from outside the project, `fixtures/real/photron/README.md`):
//! a 2.5 mm glass ball in free fall at 30,000 fps with no impact. The chain tracks it in every frame and says
//! plainly that the clip holds no impact, with the fall speed.

use bouncelab_estimate::{Conditions, EstimateError, FALL_SE_DEG, estimate_with_frames};
use bouncelab_frames::{Clip, ClipOptions};
use bouncelab_track::{ClipTracking, track_clip};
use std::path::PathBuf;

fn recording() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/real/photron/ball_12bit.cihx")
}

#[test]
fn a_real_free_fall_is_tracked_in_every_frame_and_has_no_impact() {
    let mut options = ClipOptions::default();
    // The ball's diameter as stated for this recording; the scale is then measured from its radius.
    options.overrides.ball_diameter_m = Some(0.0025);
    let clip = Clip::open_with(recording(), &options).unwrap();
    assert_eq!(clip.fps(), 30_000.0, "the header's record rate");
    let track = track_clip(&clip, &ClipTracking::for_settings(clip.settings(), false), |_, _| {}).unwrap();
    assert_eq!(track.fixes.len(), 15);
    // The header's metadata is carried with the track (README: shutter 1/50,000 s, startFrame 52).
    assert_eq!(track.camera.fps, Some(30_000.0));
    assert!(
        (track.camera.exposure_s.unwrap() - 2e-5).abs() < 1e-9,
        "{:?}",
        track.camera
    );
    assert_eq!(track.camera.start_frame, Some(52));
    assert_eq!(track.camera.trigger_frame, Some(-52));
    assert!(track.fixes.iter().all(|f| f.status.measured()), "{:?}", track.fixes);
    // Hand measurement (README): radius ≈ 63.7 px.
    let scale = track.scale.unwrap();
    assert!((scale.radius_px - 63.7).abs() < 1.0, "{scale:?}");
    // The centres lie on a smooth fall: second differences within a tenth of a pixel.
    let ys: Vec<f64> = track.fixes.iter().map(|f| f.y_px).collect();
    for w in ys.windows(3) {
        assert!((w[2] - 2.0 * w[1] + w[0]).abs() < 0.1, "{ys:?}");
    }
    let conditions = Conditions {
        incline_deg: 0.0,
        gravity: 9.81,
        ball_diameter_m: 0.0025,
        surface_tilt_deg: None,
        fall_se_deg: Some(FALL_SE_DEG),
    };
    match estimate_with_frames(&track, &clip, &conditions) {
        Err(EstimateError::NoImpact {
            frames,
            speed_m_s,
            se_m_s,
        }) => {
            assert_eq!(frames, 15);
            // Hand measurement (README): ≈ 1.56 m/s, falling (negative: toward the surface).
            assert!((speed_m_s + 1.56).abs() < 0.05, "{speed_m_s} ± {se_m_s}");
            assert!(se_m_s > 0.0 && se_m_s < 0.02, "{se_m_s}");
        }
        other => panic!("expected no impact, got {other:?}"),
    }
}

#[test]
fn conditions_no_impact_can_have_are_refused_by_name() {
    use bouncelab_estimate::Conditions;
    let ok = Conditions::default();
    assert!(ok.check().is_ok());
    for (c, field) in [
        (
            Conditions {
                incline_deg: f64::NAN,
                ..ok
            },
            "incline",
        ),
        (
            Conditions {
                incline_deg: 90.0,
                ..ok
            },
            "incline",
        ),
        (Conditions { gravity: 0.0, ..ok }, "gravity"),
        (
            Conditions {
                ball_diameter_m: 1e300 * 1e300,
                surface_tilt_deg: None,
                ..ok
            },
            "ball diameter",
        ),
    ] {
        let err = c.check().unwrap_err();
        assert!(matches!(err, EstimateError::BadCondition { .. }), "{err}");
        assert!(err.to_string().starts_with(field), "{err}");
    }
}
