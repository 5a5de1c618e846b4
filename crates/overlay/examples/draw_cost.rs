//! Drawing cost per frame, one core, as the fastest of many batches (the minimum is what other processes'
//! load does not inflate; criterion's means were unusable on a shared machine).
//!
//! Run: `cargo run --release -p bouncelab-overlay --example draw_cost`
//! Same scene as `benches/draw.rs`: a 512×512 8-bit frame, ball radius 84 px touching a textured band.

use bouncelab_frames::GrayPixels;
use bouncelab_overlay::{
    BallMark, Crop, Levels, Phase, PngSpeed, SheetLayout, Status, StripFrame, Style, SurfaceLine, View, annotate_frame,
    ball_crop, draw_annotations, encode_png_with, key_frame_strip, render_gray,
};
use bouncelab_track::testutil::{Scene, render};
use std::hint::black_box;
use std::time::Instant;

/// The fastest of 40 batches of `n` calls, seconds per call.
fn fastest(n: u32, mut f: impl FnMut()) -> f64 {
    (0..40)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..n {
                f();
            }
            start.elapsed().as_secs_f64() / f64::from(n)
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
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
    let full = View::full(512, 512, 1.0).unwrap();
    let zoom2 = View::full(512, 512, 2.0).unwrap();
    let canvas = render_gray(&pixels, &full, Levels::FULL).unwrap();
    let strip: Vec<StripFrame> = ["APPROACH", "TOUCH", "MAX COMPRESSION", "SEPARATION", "LEAVE"]
        .iter()
        .map(|caption| StripFrame {
            pixels: &pixels,
            mark,
            caption,
        })
        .collect();
    let picture = annotate_frame(&pixels, &mark, Some(&line), 1.0, &style).unwrap();
    let clone = fastest(50, || {
        black_box(canvas.clone());
    });
    let rows: Vec<(&str, f64)> = vec![
        (
            "gray canvas, 512×512 at zoom 1 (copy)",
            fastest(20, || {
                black_box(render_gray(&pixels, &full, Levels::FULL).unwrap());
            }),
        ),
        (
            "gray canvas, 512×512 at zoom 2 (bilinear, 1024×1024)",
            fastest(3, || {
                black_box(render_gray(&pixels, &zoom2, Levels::FULL).unwrap());
            }),
        ),
        (
            "annotations on a ready 512×512 canvas (line, dashed circle r 84, cross, 3 labels)",
            fastest(20, || {
                let mut c = canvas.clone();
                draw_annotations(&mut c, &full, &mark, Some(&line), &style).unwrap();
                black_box(c);
            }) - clone,
        ),
        (
            "annotate_frame, 512×512, zoom 1",
            fastest(20, || {
                black_box(annotate_frame(&pixels, &mark, Some(&line), 1.0, &style).unwrap());
            }),
        ),
        (
            "annotate_frame, 512×512, zoom 2",
            fastest(3, || {
                black_box(annotate_frame(&pixels, &mark, Some(&line), 2.0, &style).unwrap());
            }),
        ),
        (
            "ball_crop, 160×160",
            fastest(20, || {
                black_box(ball_crop(&pixels, &mark, 84.0, Some(&line), &Crop::default(), &style).unwrap());
            }),
        ),
        (
            "key_frame_strip, 5 tiles + legend (836×192)",
            fastest(5, || {
                black_box(
                    key_frame_strip(&strip, Some(&line), &Crop::default(), &style, &SheetLayout::default()).unwrap(),
                );
            }),
        ),
        (
            "PNG of an annotated 512×512 frame, fast encoder",
            fastest(5, || {
                black_box(encode_png_with(&picture, PngSpeed::Fast).unwrap());
            }),
        ),
        (
            "PNG of an annotated 512×512 frame, small encoder",
            fastest(1, || {
                black_box(encode_png_with(&picture, PngSpeed::Small).unwrap());
            }),
        ),
    ];
    println!("| operation | time |\n| --- | --- |");
    for (name, s) in rows {
        println!("| {name} | {:.3} ms |", s * 1e3);
    }
    for speed in [PngSpeed::Fast, PngSpeed::Small] {
        println!(
            "PNG {speed:?}: {} bytes",
            encode_png_with(&picture, speed).unwrap().len()
        );
    }
}
