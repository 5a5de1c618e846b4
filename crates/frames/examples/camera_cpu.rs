// cargo run --release -p bouncelab-frames --example camera_cpu -- [PASSES] [REPEATS]
//
//! CPU time per decoded camera-file frame, next to wall time: the same files as
//! `benches/camera.rs` (64 frames of 512×512 each, streamed on the calling thread with
//! `ReadOptions::with_threads(1)`), each read PASSES times (default 40) in a row, best of REPEATS (default 3).
//!
//! CPU time is this thread's time on a core (user + system, from `/proc/thread-self/schedstat`, in ns):
//! on a machine shared with other work it grows far less than wall time, which also counts the time the
//! thread waited for a core. Linux only.

#[path = "../tests/common/camera.rs"]
mod camera;

use std::hint::black_box;
use std::time::Instant;

use bouncelab_frames::{Clip, ClipOptions, ReadOptions};
use camera::{Cine, CinePacking, Mraw, TiffCompression, moving_disc, write_tiff_stack};

const N: usize = 64;
const SIDE: u32 = 512;

/// Nanoseconds this thread has run on a core (user + system).
fn thread_cpu_ns() -> u64 {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").expect("/proc/thread-self/schedstat (Linux)");
    s.split_whitespace()
        .next()
        .and_then(|v| v.parse().ok())
        .expect("schedstat's first field")
}

fn main() {
    let mut args = std::env::args().skip(1);
    let passes: usize = args.next().map_or(40, |a| a.parse().expect("PASSES"));
    let repeats: usize = args.next().map_or(3, |a| a.parse().expect("REPEATS"));
    let tmp = tempfile::tempdir().expect("temp dir");
    let d = tmp.path();
    let frames = |max| moving_disc(SIDE, SIDE, N, max, 7);
    let mut clips = Vec::new();
    for bits in [8u32, 12, 16] {
        let max = if bits == 8 { 255 } else { 4095 };
        let header = Mraw::new(SIDE, SIDE, bits).write(d, &format!("m{bits}"), &frames(max));
        clips.push((format!("mraw_{bits}bit"), header));
    }
    for (label, packing, max) in [
        ("cine_8bit", CinePacking::U8, 255),
        ("cine_10bit_packed", CinePacking::P10, 1023),
        ("cine_12bit_packed", CinePacking::P12, 4095),
        ("cine_16bit", CinePacking::U16 { real_bpp: 12 }, 4095),
    ] {
        let path = d.join(format!("{label}.cine"));
        Cine::new(SIDE, SIDE, packing).write(&path, &frames(max));
        clips.push((label.to_string(), path));
    }
    for (label, bits) in [("tiff_8bit", 8), ("tiff_16bit", 16)] {
        let path = d.join(format!("{label}.tif"));
        let max = if bits == 8 { 255 } else { 65535 };
        write_tiff_stack(&path, SIDE, SIDE, bits, &frames(max), TiffCompression::None);
        clips.push((label.to_string(), path));
    }
    let read = ReadOptions::with_threads(1);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "{passes} passes × {N} frames of {SIDE}×{SIDE}, best of {repeats}; load average before: {}",
        load.split_whitespace().take(3).collect::<Vec<_>>().join(" ")
    );
    println!("| file | CPU µs/frame | wall µs/frame | frames/s of CPU | frames/s of wall |");
    println!("| --- | --- | --- | --- | --- |");
    for (label, path) in &clips {
        let clip = Clip::open_with(path, &ClipOptions::with_fps(10_000.0)).expect("open");
        for f in clip.frames_with(&read).expect("stream") {
            black_box(f.expect("frame"));
        }
        let (mut cpu, mut wall) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..repeats {
            let (c0, t0) = (thread_cpu_ns(), Instant::now());
            for _ in 0..passes {
                for f in clip.frames_with(&read).expect("stream") {
                    black_box(f.expect("frame"));
                }
            }
            let n = (passes * N) as f64;
            wall = wall.min(t0.elapsed().as_secs_f64() * 1e6 / n);
            cpu = cpu.min((thread_cpu_ns() - c0) as f64 / 1e3 / n);
        }
        println!(
            "| {label} | {cpu:.1} | {wall:.1} | {:.0} | {:.0} |",
            1e6 / cpu,
            1e6 / wall
        );
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "load average after: {}",
        load.split_whitespace().take(3).collect::<Vec<_>>().join(" ")
    );
}
