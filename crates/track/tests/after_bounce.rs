//! The tracker through a bounce on a clip drawn by `bouncelab-render`'s `looks` preset: where the frames
//! after the bounce are measured again backward, the ball's own fixes stay.

mod common;

use common::{frames_over_1px_off, tracked_looks_shot};

/// `looks --seed 12`'s S038: a 48 px plain ball under 11.9 DN of noise, 16-bit files, on a white tape
/// lying on clay. The pass tracking backward from the outgoing flight lost the pressed ball and fitted
/// what rim it still saw with circles 0.95–2.3 px smaller than the flight's; by the noise, four of them
/// (frames 120 and 122–124, 1.5–3.0 px off the ball) were a little clearer than the forward fixes (within
/// 0.23 px) and replaced them, and three frames ended more than 1 px off. A backward fix clearly further
/// from the ball's size than the forward one no longer replaces it (`bounce::back_replaces`).
#[test]
fn a_backward_fix_smaller_than_the_ball_does_not_replace_the_pressed_ball_s() {
    let (plan, track) = tracked_looks_shot(12, 37, "S038_tape_13.8deg_501mm_r6", |_| {});
    let measured = track.fixes.iter().filter(|f| f.status.measured()).count();
    let off = frames_over_1px_off(&plan, &track);
    println!("{measured} frames measured, {} more than 1 px off: {off:?}", off.len());
    assert_eq!(measured, plan.frames.len());
    assert!(off.is_empty(), "frames more than 1 px off the ball's centre: {off:?}");
}
