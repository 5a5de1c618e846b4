//! Tracking speed on decoded frames, one core.
//!
//! Run: `cargo bench -p bouncelab-track --bench track`
//! 100 synthetic 512×512 8-bit frames of a ball (radius 84 px) falling onto a textured surface band, decoded
//! in memory beforehand. "track_frame_steady": following the ball once found and the surface line settled
//! (prediction, one edge pass along 128 rays, the robust fit), frames 33–99. "track_first_33_frames": a
//! clip's start, frames 0–32 from a fresh tracker: the cold start, then the frames while the surface line is
//! looked for in the mean of the first 2 (the ball is known from the second frame), 8 and 32 frames. "cold_start_first_frame": the first frame of a
//! clip without a track (Hough, refined candidates). "surface_line": one surface line search.
//! "surface_level_by_mean_gray": the found line's level measured again from the band's mean gray;
//! "surface_level_by_textured_share": the same from the share of each row's pixels the backdrop cannot explain.
//! "detect_full_frame": the Hough transform alone. "limb_learn_frame": one frame's radial profiles added to the
//! limb's mean (128 rays); "limb_offset": the limb model fitted to the mean of 64 frames, once per clip.
//! "rim_evidence": whether one fix's rim stands out of the noise (128 rays), once per accepted fix.

use bouncelab_track::testutil::{Scene, render};
use bouncelab_track::{
    CircleDetection, LimbLearner, Plane, TrackOptions, Tracker, detect_circles, find_surface_lines, mean_gray_level,
    rim_evidence, textured_share_level,
};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

fn frames() -> Vec<Vec<u8>> {
    (0..100)
        .map(|i| {
            let t = i as f64;
            render(&Scene {
                size: (512, 512),
                ball: (150.0 + 1.5 * t, 120.0 + 2.0 * t, 84.0),
                surface: Some((420.0, 0.0)),
                band: (140.0, 25.0),
                backdrop: (60.0, 100.0),
                distractors: vec![(40.0, 440.0, 7.0, 30.0)],
                noise: 2.0,
                seed: i,
                ..Scene::default()
            })
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let frames = frames();
    let opts = TrackOptions {
        radius_px: Some((70.0, 100.0)),
        ..TrackOptions::default()
    };
    // A tracker through the clip's first 33 frames: the ball found on the first, the surface line looked for
    // from the second (once the ball is known) in the mean of 2, 8 and 32 frames.
    const START: usize = 33;
    let mut warm = Tracker::new(opts.clone());
    let first = warm.observe(0, 0.0, &Plane::new(&frames[0], 512, 512));
    for (i, f) in frames.iter().enumerate().take(START).skip(1) {
        warm.observe(i, i as f64 * 1e-4, &Plane::new(f, 512, 512));
    }
    assert!(warm.surface().is_some(), "the bench's surface line is found");
    let mut g = c.benchmark_group("track");
    g.throughput(Throughput::Elements((frames.len() - START) as u64));
    g.bench_function("track_frame_steady", |b| {
        b.iter(|| {
            let mut t = warm.clone();
            for (i, f) in frames.iter().enumerate().skip(START) {
                black_box(t.observe(i, i as f64 * 1e-4, &Plane::new(f, 512, 512)));
            }
        })
    });
    g.throughput(Throughput::Elements(START as u64));
    g.bench_function("track_first_33_frames", |b| {
        b.iter(|| {
            let mut t = Tracker::new(opts.clone());
            for (i, f) in frames.iter().enumerate().take(START) {
                black_box(t.observe(i, i as f64 * 1e-4, &Plane::new(f, 512, 512)));
            }
        })
    });
    g.throughput(Throughput::Elements(1));
    g.bench_function("cold_start_first_frame", |b| {
        b.iter(|| black_box(Tracker::new(opts.clone()).observe(0, 0.0, &Plane::new(&frames[0], 512, 512))))
    });
    let ball = Some((first.x_px, first.y_px, first.r_px));
    g.bench_function("surface_line", |b| {
        b.iter(|| black_box(find_surface_lines(&Plane::new(&frames[1], 512, 512), ball)))
    });
    let plane = Plane::new(&frames[1], 512, 512);
    if let Some(lines) = find_surface_lines(&plane, ball) {
        g.bench_function("surface_level_by_mean_gray", |b| {
            b.iter(|| black_box(mean_gray_level(&plane, &lines.line, None)))
        });
        g.bench_function("surface_level_by_textured_share", |b| {
            b.iter(|| black_box(textured_share_level(&plane, &lines.line, None)))
        });
    }
    let det = CircleDetection {
        min_radius: 70.0,
        max_radius: 100.0,
        ..CircleDetection::default()
    };
    g.bench_function("detect_full_frame", |b| {
        b.iter(|| black_box(detect_circles(&Plane::new(&frames[0], 512, 512), &det)))
    });
    // The scene's own circles: the ball in full flight in every frame.
    let circle = |i: usize| (150.0 + 1.5 * i as f64, 120.0 + 2.0 * i as f64, 84.0);
    g.bench_function("limb_learn_frame", |b| {
        b.iter(|| {
            let mut l = LimbLearner::default();
            l.add(&Plane::new(&frames[10], 512, 512), circle(10), 128, None);
            black_box(l.frames())
        })
    });
    let mut limb = LimbLearner::default();
    for (i, f) in frames.iter().enumerate().take(64) {
        limb.add(&Plane::new(f, 512, 512), circle(i), 128, None);
    }
    g.bench_function("limb_offset", |b| b.iter(|| black_box(limb.offset())));
    let frame = Plane::new(&frames[10], 512, 512);
    g.bench_function("rim_evidence", |b| {
        b.iter(|| black_box(rim_evidence(&frame, circle(10), 128, warm.surface(), 2.0)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
