//! Spin from the texture's rotation, on clips rendered by `bouncelab-render` with known spin.

use bouncelab_estimate::{Conditions, estimate_finding_downslope, estimate_with_frames};
use bouncelab_frames::Clip;
use bouncelab_render::{Rendered, Scenario, ShotTruth, render};
use bouncelab_track::{ClipTracking, Track, track_clip};
use std::path::Path;

fn scenario(camera: &str) -> String {
    format!(
        r#"
seed = 7
pre_contact_ms = 6
post_separation_ms = 6

[camera]
width = 256
height = 256
scale_m_per_px = 8.0e-4
{camera}

[model]
[model.effects.spring]
k = 25650
[model.effects.damping]
b = 14
[model.effects.coulomb]
mu = 0.5

[surfaces.clay]
texture = "clay"
[surfaces.tape]
texture = "white_tape"
coulomb.mu = 0.9

[[shots]]
surface = "clay"
angle_deg = 0
drop_height_m = 0.3

[[shots]]
surface = "tape"
angle_deg = 15
drop_height_m = 0.3

[[shots]]
surface = "clay"
angle_deg = 22.5
drop_height_m = 0.35
"#
    )
}

/// The `spin_in` and `spin_out` columns of `truth/shots.csv` for `clip`.
fn truth_spin(truth_dir: &Path, clip: &str) -> (f64, f64) {
    let text = std::fs::read_to_string(truth_dir.join("shots.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (ci, co) = (col("spin_in"), col("spin_out"));
    // The columns before the JSON `effects` column hold no commas.
    let row: Vec<&str> = lines
        .find(|l| l.starts_with(&format!("{clip},")))
        .unwrap()
        .split(',')
        .collect();
    (row[ci].parse().unwrap(), row[co].parse().unwrap())
}

fn check(camera: &str, minus_x: bool) {
    let dir = tempfile::tempdir().unwrap();
    let s = Scenario::parse(&scenario(camera), "spin test").unwrap();
    let rendered = render(&s, dir.path()).unwrap();
    for shot in &rendered.shots {
        let (truth_in, truth_out) = truth_spin(&rendered.truth_dir, &shot.clip);
        let clip = Clip::open(rendered.session_dir.join(&shot.clip)).unwrap();
        let opts = ClipTracking {
            downslope_negative_x: minus_x,
            ..ClipTracking::default()
        };
        let track = track_clip(&clip, &opts, |_, _| {}).unwrap();
        let c = Conditions {
            incline_deg: shot.angle_deg,
            ..Conditions::default()
        };
        let e = estimate_with_frames(&track, &clip, &c).unwrap();
        let (Some(si), Some(so)) = (e.spin_in, e.spin_out) else {
            panic!("{}: spin not measured: {:?}", shot.clip, e.notes);
        };
        println!(
            "{} ({camera:?}): spin_in truth {truth_in:.3} measured {:.3} ± {:.3}; spin_out truth {truth_out:.3} measured {:.3} ± {:.3} rad/s",
            shot.clip, si.value, si.se, so.value, so.se
        );
        for (name, truth, m) in [("spin_in", truth_in, si), ("spin_out", truth_out, so)] {
            let tol = (0.03 * truth.abs()).max(2.0);
            assert!(
                (m.value - truth).abs() <= tol,
                "{} {name}: truth {truth:.3}, measured {:.3} ± {:.3}",
                shot.clip,
                m.value,
                m.se
            );
            assert!(m.se.is_finite() && m.se < 2.0, "{} {name}: se {}", shot.clip, m.se);
        }
    }
    // The oblique shots leave spinning (a ball rolling toward +x, down-slope, has ω < 0).
    assert!(
        rendered
            .shots
            .iter()
            .filter(|s| s.angle_deg > 0.0)
            .all(|s| s.spin_out < -10.0)
    );
}

#[test]
fn spin_matches_the_rendered_truth() {
    check("", false);
}

#[test]
fn spin_is_in_the_local_frame_when_the_image_is_mirrored_and_16_bit() {
    check("downslope = \"-x\"\nbit_depth = 16", true);
}

/// A shot of a mirrored camera's session: its clip, conditions, and its track as a clip without the
/// `downslope` key gives it (+x) and as one with it (−x).
fn mirrored(rendered: &Rendered, shot: &ShotTruth) -> (Clip, Conditions, Track, Track) {
    let clip = Clip::open(rendered.session_dir.join(&shot.clip)).unwrap();
    let c = Conditions {
        incline_deg: shot.angle_deg,
        ..Conditions::default()
    };
    let unset = track_clip(&clip, &ClipTracking::default(), |_, _| {}).unwrap();
    let set = Track {
        downslope_negative_x: true,
        ..unset.clone()
    };
    (clip, c, unset, set)
}

/// A mirrored camera whose `downslope` nobody gave: the flights, long enough to tell gravity's pull along
/// the incline, set the down-slope, and the shot measures as with the key set; a level shot keeps the default.
#[test]
fn an_unset_down_slope_is_taken_from_the_flights() {
    let text = scenario("downslope = \"-x\"")
        .replace("pre_contact_ms = 6", "pre_contact_ms = 25")
        .replace("post_separation_ms = 6", "post_separation_ms = 25");
    let s = Scenario::parse(&text, "down-slope test").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let rendered = render(&s, dir.path()).unwrap();
    for shot in &rendered.shots {
        let (clip, c, unset, set) = mirrored(&rendered, shot);
        let found = estimate_finding_downslope(&unset, &clip, &c).unwrap();
        let given = estimate_with_frames(&set, &clip, &c).unwrap();
        let taken = found.notes.iter().any(|n| n.contains("so -x is taken as down-slope"));
        if shot.angle_deg == 0.0 {
            let quiet = found.notes.iter().all(|n| !n.contains("down-slope"));
            assert!(!taken && quiet, "{}: {:?}", shot.clip, found.notes);
            continue;
        }
        assert!(taken, "{}: {:?} {:?}", shot.clip, found.gravity, found.notes);
        assert!(found.flags.is_empty(), "{}: {:?}", shot.clip, found.flags);
        assert!((found.mu.value - given.mu.value).abs() < 1e-9, "{}", shot.clip);
        let spin = |e: &bouncelab_estimate::Estimate| e.spin_out.map(|m| m.value);
        assert_eq!(spin(&found), spin(&given), "{}", shot.clip);
        // Without the flip the flights' fits pull μ well away.
        let kept = estimate_with_frames(&unset, &clip, &c).unwrap();
        assert!((kept.mu.value - given.mu.value).abs() > 0.02, "{}", shot.clip);
    }
}

/// The same mirrored camera with short flights (6 ms each side), too short for gravity's pull along the
/// incline to tell the down-slope: a ball dropped from rest meets the surface moving down-slope, which its
/// incoming velocity shows clearly, so the down-slope is taken from that.
#[test]
fn an_unset_down_slope_is_taken_from_the_ball_s_fall() {
    let s = Scenario::parse(&scenario("downslope = \"-x\""), "down-slope test").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let rendered = render(&s, dir.path()).unwrap();
    let mut told = 0;
    for shot in rendered.shots.iter().filter(|s| s.angle_deg != 0.0) {
        let (clip, c, unset, set) = mirrored(&rendered, shot);
        let found = estimate_finding_downslope(&unset, &clip, &c).unwrap();
        let given = estimate_with_frames(&set, &clip, &c).unwrap();
        assert!(
            found.notes.iter().any(|n| n.contains("so -x is taken as down-slope")),
            "{}: {:?}",
            shot.clip,
            found.notes
        );
        told += found
            .notes
            .iter()
            .filter(|n| n.contains("as a ball dropped onto"))
            .count();
        assert!((found.mu.value - given.mu.value).abs() < 1e-9, "{}", shot.clip);
        // Without the fall's evidence (a ball not dropped from rest) the default stays, with a note.
        let thrown = Conditions { fall_se_deg: None, ..c };
        let kept = estimate_finding_downslope(&unset, &clip, &thrown).unwrap();
        assert!(
            kept.notes.iter().any(|n| n.contains("do not tell it")),
            "{}: {:?}",
            shot.clip,
            kept.notes
        );
    }
    assert!(told > 0, "no shot's down-slope was told by its fall");
}
