//! Spin from the texture's rotation, on clips rendered by `bouncelab-render` with known spin.

use bouncelab_estimate::{Conditions, estimate_with_frames};
use bouncelab_frames::Clip;
use bouncelab_render::{Scenario, render};
use bouncelab_track::{ClipTracking, track_clip};
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
