//! Camera-file frames decoded per second on one thread: Photron MRAW, Phantom CINE and TIFF stacks of
//! 512×512 frames, streamed through `Clip::frames_with` on the calling thread (`ReadOptions::with_threads(1)`).
//!
//! Run: `cargo bench -p bouncelab-frames --bench camera` (criterion's `thrpt` is frames/s). The files are
//! written to a temp folder first (64 frames each, a moving disc on a gradient with noise) and read through
//! the page cache, as a clip is on its second read.

#[path = "../tests/common/camera.rs"]
mod camera;

use std::hint::black_box;

use bouncelab_frames::{Clip, ClipOptions, ReadOptions};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const N: usize = 64;
const SIDE: u32 = 512;

fn bench(c: &mut Criterion) {
    let tmp = tempfile::tempdir().expect("temp dir");
    let clips = camera::speed_files(tmp.path(), SIDE, N, true);
    let mut g = c.benchmark_group("decode_512x512_one_thread");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(20);
    g.measurement_time(std::time::Duration::from_secs(3));
    let read = ReadOptions::with_threads(1);
    for (label, path) in &clips {
        let clip = Clip::open_with(path, &ClipOptions::with_fps(10_000.0)).expect("open");
        assert_eq!(clip.len(), N);
        g.bench_function(label.as_str(), |b| {
            b.iter(|| {
                for f in clip.frames_with(&read).expect("stream") {
                    black_box(f.expect("frame"));
                }
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
