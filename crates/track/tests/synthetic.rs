//! Detection, refinement and the surface line on synthetic frames with known geometry.

use bouncelab_track::testutil::{Scene, render};
use bouncelab_track::{CircleDetection, EdgeSearch, Plane, detect_circles, find_surface_line, refine_circle};

fn plane<'a>(data: &'a [u8], s: &Scene) -> Plane<'a, u8> {
    Plane::new(data, s.size.0, s.size.1)
}

/// Hough candidates of radius 25–60 px (the scene's ball is 40 px).
fn detect_ball_sized(px: &[u8], s: &Scene) -> Vec<bouncelab_track::Circle> {
    let det = CircleDetection {
        min_radius: 25.0,
        max_radius: 60.0,
        ..Default::default()
    };
    detect_circles(&plane(px, s), &det)
}

#[test]
fn hough_finds_the_ball_and_not_the_small_distractor() {
    let s = Scene {
        distractors: vec![(40.0, 200.0, 8.0, 30.0)],
        ..Scene::default()
    };
    let px = render(&s);
    let c = detect_ball_sized(&px, &s);
    let best = c.first().expect("a circle");
    assert!(
        (best.x - s.ball.0).abs() < 1.5 && (best.y - s.ball.1).abs() < 1.5,
        "{best:?}"
    );
    assert!((best.r - s.ball.2).abs() < 2.0, "{best:?}");
    assert!(best.support > 0.5, "{best:?}");
}

#[test]
fn hough_ranks_two_balls_by_support() {
    let s = Scene {
        distractors: vec![(200.0, 190.0, 38.0, 190.0)],
        ..Scene::default()
    };
    let px = render(&s);
    let c = detect_ball_sized(&px, &s);
    assert!(c.len() >= 2);
    let near = |x: f64, y: f64| {
        c.iter()
            .any(|k| (k.x - x).abs() < 2.0 && (k.y - y).abs() < 2.0 && k.support > 0.5)
    };
    assert!(near(s.ball.0, s.ball.1) && near(200.0, 190.0), "{c:?}");
}

#[test]
fn refinement_is_sub_pixel_in_flight() {
    for (i, &(x, y)) in [(120.3, 90.7), (101.77, 130.21), (140.5, 111.5)].iter().enumerate() {
        let s = Scene {
            ball: (x, y, 40.0),
            seed: i as u64,
            ..Scene::default()
        };
        let px = render(&s);
        let r = refine_circle(&plane(&px, &s), x + 1.2, y - 0.8, 41.0, &EdgeSearch::default(), None).unwrap();
        let (ex, ey) = (r.fit.x - x, r.fit.y - y);
        assert!(ex.abs() < 0.05 && ey.abs() < 0.05, "centre error ({ex:.3}, {ey:.3})");
        assert!((r.fit.r - 40.0).abs() < 0.1, "radius {}", r.fit.r);
        assert!(r.fit.sigma_x < 0.05 && r.quality() > 0.8, "{r:?}");
    }
}

#[test]
fn refinement_ignores_the_rim_below_the_surface() {
    // The ball sinks 4 px into the band: its bottom is hidden.
    let s = Scene {
        ball: (128.4, 150.2, 40.0),
        surface: Some((186.2, 0.0)),
        ..Scene::default()
    };
    let px = render(&s);
    let p = plane(&px, &s);
    let line = find_surface_line(&p).expect("surface");
    let r = refine_circle(&p, 129.0, 149.0, 40.0, &EdgeSearch::default(), Some(&line)).unwrap();
    assert!(r.rays_hidden > 5, "{r:?}");
    assert!(
        (r.fit.x - 128.4).abs() < 0.08 && (r.fit.y - 150.2).abs() < 0.08,
        "{:?}",
        r.fit
    );
}

#[test]
fn surface_line_height_and_tilt() {
    // (height, tilt, band brightness, texture, noise, tolerance on the height): a bright or dark band, a band
    // barely different from the backdrop behind a strong texture, and a noise-free 8-bit frame whose smooth
    // backdrop has quantisation steps that must not pass for the surface.
    for (y0, deg, band, tex, noise, tol) in [
        (200.3, 0.0f64, 150.0, 25.0, 2.0, 0.1),
        (180.7, 2.0, 40.0, 25.0, 2.0, 0.1),
        (190.0, -3.5, 150.0, 25.0, 2.0, 0.1),
        (200.3, 0.0, 90.0, 25.0, 2.0, 0.3),
        (200.3, 1.0, 90.0, 0.0, 0.0, 0.05),
    ] {
        let slope = -deg.to_radians().tan();
        let s = Scene {
            surface: Some((y0, slope)),
            band: (band, tex),
            noise,
            ..Scene::default()
        };
        let px = render(&s);
        let line = find_surface_line(&plane(&px, &s)).expect("surface");
        assert!((line.y0 - y0).abs() < tol, "y0 {} vs {y0} (band {band})", line.y0);
        assert!(
            (line.tilt_deg() - deg).abs() < 0.05,
            "tilt {} vs {deg} (band {band})",
            line.tilt_deg()
        );
    }
}

#[test]
fn no_ball_and_flat_frames_give_nothing_not_a_panic() {
    let black = vec![0u8; 128 * 128];
    let p = Plane::new(&black, 128, 128);
    assert!(detect_circles(&p, &CircleDetection::default()).is_empty());
    assert!(find_surface_line(&p).is_none());
    assert!(refine_circle(&p, 64.0, 64.0, 30.0, &EdgeSearch::default(), None).is_none());
    let white = vec![255u8; 128 * 128];
    assert!(detect_circles(&Plane::new(&white, 128, 128), &CircleDetection::default()).is_empty());
}

/// Over the full acquisition range (8 px to half the frame), a lone ball of any size is the best candidate:
/// the octave bands each search their own radii, and the many small circles of the band's noise do not
/// push the ball out.
#[test]
fn the_full_radius_range_finds_balls_of_every_size() {
    for r in [9.0, 21.0, 47.0, 90.0, 180.0] {
        let s = Scene {
            size: (512, 512),
            ball: (251.3, 262.6, r),
            noise: 4.0,
            distractors: vec![(40.0, 40.0, 6.0, 30.0)],
            ..Scene::default()
        };
        let px = render(&s);
        let det = CircleDetection {
            min_radius: 8.0,
            max_radius: 256.0,
            max_candidates: 24,
            ..Default::default()
        };
        let found = detect_circles(&plane(&px, &s), &det);
        let best = found.first().unwrap_or_else(|| panic!("r {r}: no circle"));
        let tol = 1.5 + 0.03 * r;
        assert!(
            (best.x - s.ball.0).abs() < tol && (best.y - s.ball.1).abs() < tol && (best.r - r).abs() < tol,
            "r {r}: {best:?}"
        );
        // A circle seen in two overlapping bands is reported once.
        let copies = found
            .iter()
            .filter(|c| (c.x - s.ball.0).hypot(c.y - s.ball.1) < 0.1 * r && (c.r - r).abs() < 0.1 * r)
            .count();
        assert_eq!(copies, 1, "r {r}: {found:?}");
    }
}
