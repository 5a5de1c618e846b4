//! Frames decoded per second, per format, PNG decoder and thread count.
//!
//! Run: `cargo bench -p bouncelab-frames --bench decode` (prints a Markdown table).
//! Writes 200 noisy 512×512 8-bit gray frames per format into a temp folder (`FRAMES_BENCH_N` changes the
//! count), then streams each clip through `Clip::frames_with` on 1 and 2 threads; best of 5 runs.

use std::time::Instant;

use bouncelab_frames::testutil::ClipSpec;
use bouncelab_frames::{Clip, ClipOptions, PngDecoder, ReadOptions};
use image::ColorType;
use image::codecs::png::CompressionType;

fn main() {
    let n: u64 = std::env::var("FRAMES_BENCH_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200);
    let tmp = tempfile::tempdir().expect("temp dir");
    let mut rows = Vec::new();
    let clips = [
        ("png", 0.5, None, "±25 % noise, image's default (fast) encoder"),
        (
            "png",
            0.03,
            Some(CompressionType::Level(6)),
            "±1.5 % noise, zlib level 6",
        ),
        ("png", 0.5, Some(CompressionType::Level(6)), "±25 % noise, zlib level 6"),
        ("tif", 0.5, None, "±25 % noise"),
        ("pgm", 0.5, None, "±25 % noise"),
    ];
    for (k, (ext, noise, compression, what)) in clips.into_iter().enumerate() {
        let dir = tmp.path().join(format!("{k}_{ext}"));
        let mut spec = ClipSpec::new(n).ext(ext).colour(ColorType::L8);
        (spec.width, spec.height, spec.noise, spec.png_compression) = (512, 512, noise, compression);
        spec.write(&dir);
        let bytes: u64 = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().metadata().unwrap().len())
            .sum();
        let clip = Clip::open_with(&dir, &ClipOptions::with_fps(10_000.0)).expect("open clip");
        let decoders: &[(PngDecoder, &str)] = if ext == "png" {
            &[(PngDecoder::Image, "png (image)"), (PngDecoder::Zune, "png (zune-png)")]
        } else if ext == "tif" {
            &[(PngDecoder::Image, "tiff (image, uncompressed)")]
        } else {
            &[(PngDecoder::Image, "pgm (image)")]
        };
        for &(png, label) in decoders {
            for threads in [1, 2] {
                let mut options = ReadOptions::with_threads(threads);
                options.png_decoder = png;
                let mut best = f64::INFINITY;
                for _ in 0..5 {
                    let start = Instant::now();
                    let mut count = 0u64;
                    for frame in clip.frames_with(&options).expect("stream") {
                        std::hint::black_box(frame.expect("frame decodes"));
                        count += 1;
                    }
                    assert_eq!(count, n);
                    best = best.min(start.elapsed().as_secs_f64());
                }
                rows.push((
                    label,
                    what,
                    threads,
                    n as f64 / best,
                    1e3 * best / n as f64,
                    bytes / n / 1024,
                ));
            }
        }
    }
    println!("| format (decoder) | frames | threads | frames/s | ms/frame | KiB/frame |");
    println!("|---|---|---:|---:|---:|---:|");
    for (label, what, threads, fps, ms, kib) in rows {
        println!("| {label} | {what} | {threads} | {fps:.0} | {ms:.3} | {kib} |");
    }
}
