// cargo run --release -p bouncelab-track --example end_to_end -- SESSION_DIR [THREADS]
//
//! End-to-end speed on a folder of PNG frames: decoding alone (the frames crate's parallel stream) versus
//! decoding and tracking (`track_clip`), per clip and in total, on THREADS decoding threads (default 2).
//! Each clip is read once before timing so that both runs see the files in the page cache.

use bouncelab_frames::{Clip, ReadOptions};
use bouncelab_track::{ClipTracking, track_clip};
use std::time::Instant;

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
    let (mut decode_total, mut track_total, mut frames_total) = (0.0, 0.0, 0);
    println!("| clip | frames | decode only s | decode + track s | ratio |");
    println!("|---|---|---|---|---|");
    for dir in clips {
        let clip = Clip::open(&dir).unwrap();
        for f in clip.frames_with(&read).unwrap() {
            f.unwrap();
        }
        let t = Instant::now();
        for f in clip.frames_with(&read).unwrap() {
            std::hint::black_box(f.unwrap());
        }
        let decode = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let opts = ClipTracking {
            read: read.clone(),
            ..ClipTracking::default()
        };
        let track = track_clip(&clip, &opts, |_, _| {}).unwrap();
        let both = t.elapsed().as_secs_f64();
        println!(
            "| {} | {} | {decode:.3} | {both:.3} | {:.2} |",
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
        frames_total += track.fixes.len();
    }
    println!(
        "| **all** | {frames_total} | {decode_total:.3} ({:.0} frames/s) | {track_total:.3} ({:.0} frames/s) | **{:.2}** |",
        frames_total as f64 / decode_total,
        frames_total as f64 / track_total,
        track_total / decode_total
    );
}
