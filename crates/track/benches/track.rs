//! Tracking speed on decoded frames, one core.
//!
//! Run: `cargo bench -p bouncelab-track --bench track`
//! 100 synthetic 512×512 8-bit frames of a ball (radius 84 px) falling onto a textured surface band, decoded
//! in memory beforehand; "track_frame" is the per-frame cost of following the ball (prediction, edge search
//! along 128 rays, two robust fits); "detect_full_frame" is the Hough search used on the first frame and
//! after a loss.

use bouncelab_track::testutil::{Scene, render};
use bouncelab_track::{CircleDetection, Plane, TrackOptions, Tracker, detect_circles};
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
    let mut g = c.benchmark_group("track");
    g.throughput(Throughput::Elements(frames.len() as u64));
    g.bench_function("track_frame", |b| {
        b.iter(|| {
            let mut t = Tracker::new(TrackOptions {
                radius_px: Some((70.0, 100.0)),
                ..TrackOptions::default()
            });
            for (i, f) in frames.iter().enumerate() {
                black_box(t.observe(i, i as f64 * 1e-4, &Plane::new(f, 512, 512)));
            }
        })
    });
    g.throughput(Throughput::Elements(1));
    let det = CircleDetection {
        min_radius: 70.0,
        max_radius: 100.0,
        ..CircleDetection::default()
    };
    g.bench_function("detect_full_frame", |b| {
        b.iter(|| black_box(detect_circles(&Plane::new(&frames[0], 512, 512), &det)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
