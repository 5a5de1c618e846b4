//! The tracker on clips drawn by `bouncelab-render`'s `looks` preset whose lighting shades the ball unevenly:
//! its centres are the silhouette's, not the shading's, in flight and pressed into the surface.

mod common;

use bouncelab_render::{Pixels, Visibility};
use bouncelab_testkit::Rng;
use bouncelab_track::Status;
use common::{frames_over_1px_off, tracked_looks_shot};

/// `looks --seed 11`'s S045: a 27.2 px plain ball lit from 59.5° above, 8-bit, 4 DN of noise. Its lower
/// limb's terminator lies ≈ 3.6 px inside the silhouette and its rim-brightened edge meets the backdrop at
/// about its gray, so the circles fitted to the rim sit 0.5 px high; with the limb model fitted over the
/// last 4 px inside the rim alone, the terminator's step bent the lower rays' fit and every flight centre
/// stayed 0.52 px high (flight RMS 0.524 px). The fit over the last 3 px disagrees with it (χ² 41 on 2
/// degrees of freedom) and is taken: 0.05 px.
#[test]
fn a_ball_lit_from_high_above_is_centred_on_its_silhouette() {
    let (plan, track) = tracked_looks_shot(11, 44, "S045_tape_8.1deg_547mm_r13", |_| {});
    let (touch, separation) = (plan.truth.t_touch_s, plan.truth.t_sep_s);
    let errors: Vec<f64> = track
        .fixes
        .iter()
        .zip(&plan.frames)
        .filter(|(_, t)| t.visible == Visibility::Full && (t.t_s < touch || t.t_s > separation))
        .filter(|(f, _)| f.status == Status::Ok)
        .map(|(f, t)| (f.x_px - t.x_px).hypot(f.y_px - t.y_px))
        .collect();
    assert!(errors.len() > 120, "{} flight frames tracked", errors.len());
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    println!("flight RMS {rms:.3} px over {} frames", errors.len());
    assert!(rms < 0.15, "flight RMS {rms:.3} px");
}

/// `looks --seed 17`'s S014: a 99 px felt-seamed ball lit from 64° above, dropped onto clay, 16-bit files.
/// With 4 DN more noise (as `perturb.py --noise 4` gives), its pressed rim's visible quality fell below
/// the 0.6 of its flight's median that a continuing track asks (`Tracker::same_rim`) from the deepest
/// compression on; the frame was then searched whole, and the lit cap's edge, a circle 4.4 px smaller and
/// 6.6 px lower, was followed through the restitution: 17 frames more than 1 px off here (38 in the copy
/// `perturb.py --noise 4 --seed 3` makes), all `ok`.
#[test]
fn a_pressed_rim_less_clear_than_in_flight_stays_the_ball_s() {
    let mut rng = Rng::new(3);
    // 4 DN of the 8-bit scale.
    let (plan, track) = tracked_looks_shot(17, 13, "S014_clay_21deg_509mm_r14", |frame| match &mut frame.pixels {
        Pixels::Gray8(v) => v
            .iter_mut()
            .for_each(|p| *p = (*p as f64 + 4.0 * rng.normal()).round().clamp(0.0, 255.0) as u8),
        Pixels::Gray16(v) => v
            .iter_mut()
            .for_each(|p| *p = (*p as f64 + 4.0 * 257.0 * rng.normal()).round().clamp(0.0, 65535.0) as u16),
    });
    let off = frames_over_1px_off(&plan, &track);
    let measured = track.fixes.iter().filter(|f| f.status.measured()).count();
    println!("{measured} frames measured, {} more than 1 px off: {off:?}", off.len());
    assert!(
        measured + 5 >= plan.frames.len(),
        "{measured} of {} frames measured",
        plan.frames.len()
    );
    assert!(off.is_empty(), "frames more than 1 px off the ball's centre: {off:?}");
}
