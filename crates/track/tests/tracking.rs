//! The tracker on synthetic sequences: a bounce into the surface band, a second ball, a ball leaving the
//! frame, an empty and a saturated frame.

use bouncelab_track::testutil::{Scene, render};
use bouncelab_track::{Plane, Status, TrackOptions, Tracker};

/// Ball centre at frame i: down to 3 px below touching the surface at frame 20, then back up.
fn path(i: usize) -> (f64, f64) {
    let t = i as f64 - 20.0;
    (70.0 + 1.7 * i as f64, 200.0 - 40.0 + 3.0 - 2.6 * t.abs() + 0.02 * t * t)
}

fn scene(i: usize) -> Scene {
    let (x, y) = path(i);
    Scene {
        size: (256, 256),
        ball: (x, y, 40.0),
        surface: Some((200.0, 0.0)),
        band: (150.0, 20.0),
        seed: i as u64,
        ..Scene::default()
    }
}

#[test]
fn follows_a_bounce_into_the_surface_to_a_tenth_of_a_pixel() {
    let mut tracker = Tracker::new(TrackOptions {
        radius_px: Some((30.0, 50.0)),
        ..TrackOptions::default()
    });
    let mut worst: f64 = 0.0;
    for i in 0..40 {
        let s = scene(i);
        let px = render(&s);
        let fix = tracker.observe(i, i as f64 * 1e-4, &Plane::new(&px, 256, 256));
        assert_eq!(fix.status, Status::Ok, "frame {i}: {fix:?}");
        let (x, y) = path(i);
        worst = worst.max((fix.x_px - x).abs()).max((fix.y_px - y).abs());
    }
    assert!(worst < 0.1, "worst centre error {worst} px");
    let line = tracker.surface().unwrap();
    assert!((line.y0 - 200.0).abs() < 0.1);
    assert!((tracker.flight_radius().unwrap() - 40.0).abs() < 0.1);
}

#[test]
fn a_second_ball_is_named_and_the_track_continues_on_the_first() {
    let mut tracker = Tracker::new(TrackOptions {
        radius_px: Some((30.0, 50.0)),
        ..TrackOptions::default()
    });
    for i in 0..10 {
        let mut s = scene(i);
        s.distractors.push((215.0, 60.0, 40.0, 200.0));
        let px = render(&s);
        let fix = tracker.observe(i, i as f64 * 1e-4, &Plane::new(&px, 256, 256));
        if i == 0 {
            // No track yet: two equally good balls.
            assert_eq!(fix.status, Status::Ambiguous);
        } else {
            let (x, y) = path(i);
            let on_first = (fix.x_px - x).abs() < 0.2 && (fix.y_px - y).abs() < 0.2;
            let on_second = (fix.x_px - 215.0).abs() < 0.2;
            assert!(on_first || on_second, "frame {i}: {fix:?}");
        }
    }
    assert!(
        tracker.warnings().iter().any(|w| w.contains("ball-like circles")),
        "{:?}",
        tracker.warnings()
    );
}

#[test]
fn a_ball_leaving_the_frame_is_flagged_then_absent() {
    let mut tracker = Tracker::new(TrackOptions {
        radius_px: Some((30.0, 50.0)),
        ..TrackOptions::default()
    });
    let mut statuses = Vec::new();
    for i in 0..30 {
        let s = Scene {
            ball: (150.0 + 6.0 * i as f64, 100.0, 40.0),
            seed: i as u64,
            ..Scene::default()
        };
        let px = render(&s);
        statuses.push(tracker.observe(i, i as f64 * 1e-4, &Plane::new(&px, 256, 256)).status);
    }
    assert_eq!(statuses[0], Status::Ok);
    assert!(statuses.contains(&Status::CutByBorder), "{statuses:?}");
    assert_eq!(*statuses.last().unwrap(), Status::Absent, "{statuses:?}");
    // Once gone it is never invented.
    let first_absent = statuses.iter().position(|s| *s == Status::Absent).unwrap();
    assert!(
        statuses[first_absent..].iter().all(|s| *s == Status::Absent),
        "{statuses:?}"
    );
}

#[test]
fn black_and_saturated_frames_are_absent_not_a_panic() {
    let mut tracker = Tracker::new(TrackOptions::default());
    for (i, v) in [0u8, 255, 0].into_iter().enumerate() {
        let px = vec![v; 256 * 256];
        assert_eq!(
            tracker.observe(i, 0.0, &Plane::new(&px, 256, 256)).status,
            Status::Absent
        );
    }
}
