//! What the tests on the `looks` preset's clips share.

use bouncelab_frames::Clip;
use bouncelab_render::{RenderedFrame, Scenario, ShotPlan, encode};
use bouncelab_track::{ClipTracking, Track, track_clip};

/// Shot `index` of `looks --seed seed` (named `clip`, checked), rendered in memory, each frame passed
/// through `alter`, written to a temporary folder in the camera's format and tracked as `analyze` would.
pub fn tracked_looks_shot(
    seed: u64,
    index: usize,
    clip: &str,
    mut alter: impl FnMut(&mut RenderedFrame),
) -> (ShotPlan, Track) {
    let mut scenario = Scenario::preset("looks").unwrap();
    scenario.seed = seed;
    let plan = ShotPlan::new(&scenario, index).unwrap();
    assert_eq!(plan.truth.clip, clip, "the preset's draws changed");
    let dir = tempfile::tempdir().unwrap();
    let (renderer, camera) = (plan.renderer(), plan.camera());
    for i in 0..plan.frames.len() {
        let mut frame = renderer.frame(i);
        alter(&mut frame);
        let bytes = encode(&frame, camera.format).unwrap();
        std::fs::write(dir.path().join(camera.frame_name(i)), bytes).unwrap();
    }
    let clip = Clip::open(dir.path()).unwrap();
    let track = track_clip(&clip, &ClipTracking::default(), |_, _| {}).unwrap();
    (plan, track)
}

/// The frames `track` measured more than 1 px from the centre `plan` drew.
pub fn frames_over_1px_off(plan: &ShotPlan, track: &Track) -> Vec<usize> {
    track
        .fixes
        .iter()
        .zip(&plan.frames)
        .filter(|(f, _)| f.status.measured())
        .filter(|(f, t)| (f.x_px - t.x_px).hypot(f.y_px - t.y_px) > 1.0)
        .map(|(f, _)| f.frame)
        .collect()
}
