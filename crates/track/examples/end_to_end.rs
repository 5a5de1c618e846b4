// cargo run --release -p bouncelab-track --example end_to_end -- SESSION_DIR [THREADS]
//
//! End-to-end speed on every clip folder of SESSION_DIR (folders of PNG frames, or folders holding one
//! camera file each, as `bouncelab-frames`' `to_camera --nested` writes them): decoding alone (the frames
//! crate's parallel stream) versus decoding and tracking (`track_clip`), per clip and in total, on THREADS
//! decoding threads (default 2). Each clip is read once before timing so that both runs see the files in the
//! page cache.
//!
//! Besides wall time it prints the process's CPU time (user + system of all threads, from `/proc/self/stat`,
//! Linux), which other work on the machine inflates far less: when decoding alone keeps every core busy, the
//! tracker's CPU time cannot hide behind it, and `(decode CPU + track CPU) / decode CPU` is the least wall
//! ratio the machine can reach.

use bouncelab_frames::{Clip, ReadOptions};
use bouncelab_track::{ClipTracking, track_clip};
use std::time::Instant;

/// Seconds of CPU this process has used, all threads (finished ones included), user + system.
fn process_cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat (Linux)");
    // Fields after the command name (which may hold spaces, hence the last ')'): utime is the 12th, stime
    // the 13th, in clock ticks of 1/100 s (USER_HZ, fixed by the kernel's ABI).
    let rest = &stat[stat.rfind(')').expect("stat's command name") + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f[11].parse::<u64>().expect("utime") + f[12].parse::<u64>().expect("stime");
    ticks as f64 / 100.0
}

fn main() {
    let mut args = std::env::args().skip(1);
    let session = std::path::PathBuf::from(args.next().expect("SESSION_DIR"));
    let threads: usize = args.next().map(|t| t.parse().expect("THREADS")).unwrap_or(2);
    let read = ReadOptions::with_threads(threads);
    let mut clips: Vec<_> = std::fs::read_dir(&session)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .map(|e| e.path())
        .collect();
    clips.sort();
    let load = || std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    eprintln!("load average before: {}", load().trim());
    let (mut decode_total, mut track_total, mut frames_total) = (0.0, 0.0, 0);
    let (mut decode_cpu_total, mut track_cpu_total) = (0.0, 0.0);
    println!("| clip | frames | decode only s | decode + track s | ratio | decode CPU s | decode + track CPU s |");
    println!("|---|---|---|---|---|---|---|");
    for dir in clips {
        let clip = Clip::open(&dir).unwrap();
        for f in clip.frames_with(&read).unwrap() {
            f.unwrap();
        }
        let (t, cpu) = (Instant::now(), process_cpu_s());
        let mut stream = clip.frames_with(&read).unwrap();
        // Given back, as `track_clip` gives each frame back once it has looked at it.
        while let Some(f) = stream.next() {
            stream.recycle(std::hint::black_box(f.unwrap()));
        }
        let (decode, decode_cpu) = (t.elapsed().as_secs_f64(), process_cpu_s() - cpu);
        let (t, cpu) = (Instant::now(), process_cpu_s());
        let opts = ClipTracking {
            read: read.clone(),
            ..ClipTracking::default()
        };
        let track = track_clip(&clip, &opts, |_, _| {}).unwrap();
        let (both, both_cpu) = (t.elapsed().as_secs_f64(), process_cpu_s() - cpu);
        println!(
            "| {} | {} | {decode:.3} | {both:.3} | {:.2} | {decode_cpu:.2} | {both_cpu:.2} |",
            dir.file_name().unwrap().to_string_lossy(),
            track.fixes.len(),
            both / decode
        );
        eprintln!(
            "   waiting {:.3} s, tracking {:.3} s, warnings {:?}",
            track.seconds_waiting, track.seconds_tracking, track.warnings
        );
        decode_total += decode;
        track_total += both;
        decode_cpu_total += decode_cpu;
        track_cpu_total += both_cpu;
        frames_total += track.fixes.len();
    }
    println!(
        "| **all** | {frames_total} | {decode_total:.3} ({:.0} frames/s) | {track_total:.3} ({:.0} frames/s) | **{:.2}** | {decode_cpu_total:.2} ({:.1} µs/frame) | {track_cpu_total:.2} ({:.1} µs/frame) |",
        frames_total as f64 / decode_total,
        frames_total as f64 / track_total,
        track_total / decode_total,
        decode_cpu_total * 1e6 / frames_total as f64,
        track_cpu_total * 1e6 / frames_total as f64,
    );
    eprintln!("load average after: {}", load().trim());
}
