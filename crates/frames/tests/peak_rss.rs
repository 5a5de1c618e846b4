//! Streaming a long clip keeps memory bounded (`docs/session.md`): peak RSS of a 20,000-frame clip stays < 200 MB.
//!
//! Its own test binary so that no other test inflates the process's peak. Run with
//! `cargo test -p bouncelab-frames --release --test peak_rss -- --ignored --nocapture`.
//! The 20,000 files are hard links to 16 distinct noisy 512×512 8-bit PNGs (zlib level 6, ≈ 2 MB on disk
//! instead of 2.5 GB);
//! every one is still opened and decoded.

use bouncelab_frames::testutil::{ClipSpec, write_png_with};
use bouncelab_frames::{Clip, ClipOptions};
use image::codecs::png::CompressionType;

fn vm_hwm_kib() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("read /proc/self/status");
    let line = status.lines().find(|l| l.starts_with("VmHWM:")).expect("VmHWM line");
    line.split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .expect("VmHWM value")
}

#[test]
#[ignore = "slow: writes and decodes a 20,000-frame clip"]
fn streaming_20000_frames_keeps_peak_rss_under_200_mb() {
    const FRAMES: u64 = 20_000;
    let tmp = tempfile::tempdir().unwrap();
    let mut spec = ClipSpec::new(16);
    (spec.width, spec.height, spec.noise) = (512, 512, 0.03);
    let sources: Vec<_> = (0..16)
        .map(|k| {
            let p = tmp.path().join(format!("source_{k}.png.src"));
            write_png_with(&p, &spec.image(k), CompressionType::Level(6));
            p
        })
        .collect();
    let dir = tmp.path().join("clip");
    std::fs::create_dir(&dir).unwrap();
    for n in 1..=FRAMES {
        let src = &sources[(n % 16) as usize];
        let dst = dir.join(format!("C001H001S0001{n:06}.png"));
        if std::fs::hard_link(src, &dst).is_err() {
            std::fs::copy(src, &dst).unwrap();
        }
    }
    let before = vm_hwm_kib();
    let start = std::time::Instant::now();
    let clip = Clip::open_with(&dir, &ClipOptions::with_fps(10_000.0)).unwrap();
    assert_eq!(clip.len() as u64, FRAMES);
    let (mut count, mut sum) = (0u64, 0u64);
    for frame in clip.frames() {
        let frame = frame.unwrap();
        assert_eq!(frame.index, count);
        sum += u64::from(frame.pixels.as_u8().unwrap().as_raw()[1000]);
        count += 1;
    }
    let secs = start.elapsed().as_secs_f64();
    let peak = vm_hwm_kib();
    println!(
        "streamed {count} frames of 512×512 in {secs:.1} s ({:.0} frames/s, {} threads); VmHWM before {:.1} MB, after {:.1} MB (checksum {sum})",
        count as f64 / secs,
        rayon::current_num_threads(),
        before as f64 / 1024.0,
        peak as f64 / 1024.0
    );
    assert_eq!(count, FRAMES);
    assert!(peak < 200 * 1024, "peak RSS {peak} KiB ≥ 200 MB");
}
