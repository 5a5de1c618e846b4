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
use camera::{Cine, CinePacking, Mraw, TiffCompression, moving_disc, write_tiff_stack};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const N: usize = 64;
const SIDE: u32 = 512;

fn bench(c: &mut Criterion) {
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
    for (label, bits, compression) in [
        ("tiff_8bit", 8, TiffCompression::None),
        ("tiff_16bit", 16, TiffCompression::None),
        ("tiff_8bit_lzw", 8, TiffCompression::Lzw),
    ] {
        let path = d.join(format!("{label}.tif"));
        let max = if bits == 8 { 255 } else { 65535 };
        write_tiff_stack(&path, SIDE, SIDE, bits, &frames(max), compression);
        clips.push((label.to_string(), path));
    }
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
