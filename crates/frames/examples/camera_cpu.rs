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
    let clips = camera::speed_files(tmp.path(), SIDE, N, false);
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
