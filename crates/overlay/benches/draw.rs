//! Drawing cost per frame, one core.
//!
//! Run: `cargo bench -p bouncelab-overlay --bench draw`
//! A synthetic 512×512 8-bit frame of a ball (radius 84 px) just touching a textured surface band (the
//! tracker's test scene, noise σ 2 gray levels). "gray_*": the frame into an RGB canvas. "annotations":
//! line, circle, cross and labels on a ready canvas. "annotate_frame_*": both. "ball_crop_160": one strip
//! tile. "key_frame_strip_5": five tiles and the legend. "png_*": encoding the annotated 512×512 frame.

use bouncelab_frames::GrayPixels;
use bouncelab_overlay::{
    BallMark, Crop, Levels, Phase, PngSpeed, SheetLayout, Status, StripFrame, Style, SurfaceLine, View, annotate_frame,
    ball_crop, draw_annotations, encode_png_with, key_frame_strip, render_gray,
};
use bouncelab_track::testutil::{Scene, render};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let raw = render(&Scene {
        size: (512, 512),
        ball: (250.3, 335.7, 84.0),
        surface: Some((420.0, 0.0)),
        band: (140.0, 25.0),
        backdrop: (60.0, 100.0),
        noise: 2.0,
        seed: 3,
        ..Scene::default()
    });
    let pixels = GrayPixels::U8(image::GrayImage::from_raw(512, 512, raw).expect("512×512"));
    let mark = BallMark {
        frame: 1234,
        x_px: 250.3,
        y_px: 335.7,
        r_px: 84.0,
        status: Status::Occluded,
        phase: Phase::Contact,
    };
    let line = SurfaceLine {
        x0: 256.0,
        y0: 420.0,
        slope: 0.0,
    };
    let style = Style::default();
    let mut g = c.benchmark_group("overlay");
    let full = View::full(512, 512, 1.0).unwrap();
    let zoom2 = View::full(512, 512, 2.0).unwrap();
    g.bench_function("gray_512_zoom1", |b| {
        b.iter(|| black_box(render_gray(&pixels, &full, Levels::FULL).unwrap()))
    });
    g.bench_function("gray_512_zoom2", |b| {
        b.iter(|| black_box(render_gray(&pixels, &zoom2, Levels::FULL).unwrap()))
    });
    let canvas = render_gray(&pixels, &full, Levels::FULL).unwrap();
    g.bench_function("annotations_512", |b| {
        b.iter(|| {
            let mut c = canvas.clone();
            draw_annotations(&mut c, &full, &mark, Some(&line), &style).unwrap();
            black_box(c)
        })
    });
    g.bench_function("canvas_clone_512", |b| b.iter(|| black_box(canvas.clone())));
    g.bench_function("annotate_frame_512_zoom1", |b| {
        b.iter(|| black_box(annotate_frame(&pixels, &mark, Some(&line), 1.0, &style).unwrap()))
    });
    g.bench_function("annotate_frame_512_zoom2", |b| {
        b.iter(|| black_box(annotate_frame(&pixels, &mark, Some(&line), 2.0, &style).unwrap()))
    });
    g.bench_function("ball_crop_160", |b| {
        b.iter(|| black_box(ball_crop(&pixels, &mark, 84.0, Some(&line), &Crop::default(), &style).unwrap()))
    });
    let strip: Vec<StripFrame> = ["APPROACH", "TOUCH", "MAX COMPRESSION", "SEPARATION", "LEAVE"]
        .iter()
        .map(|caption| StripFrame {
            pixels: &pixels,
            mark,
            caption,
        })
        .collect();
    g.bench_function("key_frame_strip_5", |b| {
        b.iter(|| {
            black_box(key_frame_strip(&strip, Some(&line), &Crop::default(), &style, &SheetLayout::default()).unwrap())
        })
    });
    let picture = annotate_frame(&pixels, &mark, Some(&line), 1.0, &style).unwrap();
    for (name, speed) in [("png_512_small", PngSpeed::Small), ("png_512_fast", PngSpeed::Fast)] {
        let bytes = encode_png_with(&picture, speed).unwrap().len();
        eprintln!("{name}: {bytes} bytes");
        g.bench_function(name, |b| {
            b.iter(|| black_box(encode_png_with(&picture, speed).unwrap()))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
