//! Camera files as clips: the real Photron recording against its independent decode, written MRAW, CINE
//! and TIFF stacks round-tripped at every depth, and bad headers refused with the file and field named.

mod common;

use std::path::{Path, PathBuf};

use bouncelab_frames::{
    BitSide, Clip, ClipOptions, FpsSource, Frame, FramesError, GrayPixels, ReadOptions, SourceFormat, Warning,
};
use common::camera::{Cine, CinePacking, Mraw, PhotronHeader, TiffCompression, moving_disc, write_tiff_stack};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/real/photron")
}

fn read_all(clip: &Clip, threads: usize) -> Vec<Frame> {
    clip.frames_with(&ReadOptions::with_threads(threads))
        .unwrap()
        .map(|f| f.unwrap())
        .collect()
}

fn u16s(p: &GrayPixels) -> Vec<u16> {
    match p {
        GrayPixels::U8(i) => i.as_raw().iter().map(|&v| u16::from(v)).collect(),
        GrayPixels::U16(i) => i.as_raw().clone(),
    }
}

fn names(err: &FramesError, parts: &[&str]) {
    let msg = err.to_string();
    for p in parts {
        assert!(msg.contains(p), "`{msg}` should name `{p}`");
    }
}

#[test]
fn the_real_photron_recording_decodes_pixel_exact() {
    let dir = fixture();
    let clip = Clip::open(dir.join("ball_12bit.cihx")).unwrap();
    assert_eq!((clip.len(), clip.dimensions()), (15, (384, 384)));
    assert_eq!(
        (clip.fps(), clip.fps_source()),
        (30_000.0, &FpsSource::Header(dir.join("ball_12bit.cihx")))
    );
    let info = clip.camera();
    assert_eq!(info.format, SourceFormat::PhotronMraw);
    assert_eq!(info.fps, Some(30_000.0));
    assert!((info.exposure_s.unwrap() - 2e-5).abs() < 1e-15, "{:?}", info.exposure_s);
    assert_eq!((info.bit_depth, info.effective_bit_depth), (Some(12), Some(12)));
    assert_eq!(info.effective_bit_side, Some(BitSide::Lower));
    assert_eq!((info.start_frame, info.trigger_frame), (Some(52), Some(-52)));
    assert!(info.camera_model.as_deref().unwrap().starts_with("FASTCAM Nova S16"));
    // No fps warning (the header gives it); the ball diameter is the only default taken.
    assert!(
        matches!(clip.warnings(), [Warning::DefaultDiameter { .. }]),
        "{:?}",
        clip.warnings()
    );
    for threads in [1, 2] {
        let frames = read_all(&clip, threads);
        assert_eq!(frames.len(), 15);
        for f in &frames {
            let reference = image::open(dir.join(format!("frames16/frame_{:05}.png", f.index)))
                .unwrap()
                .into_luma16();
            let got = f.pixels.as_u16().expect("12-bit frames decode to 16-bit");
            assert_eq!(got.dimensions(), reference.dimensions());
            let diff = got
                .as_raw()
                .iter()
                .zip(reference.as_raw())
                .filter(|(a, b)| a != b)
                .count();
            assert_eq!(diff, 0, "frame {}: {diff} pixels differ", f.index);
            assert!((f.t_s - f.index as f64 / 30_000.0).abs() < 1e-15);
        }
    }
    // The .mraw names the same clip.
    let by_data = Clip::open(dir.join("ball_12bit.mraw")).unwrap();
    assert_eq!(
        by_data.read(7, Default::default()).unwrap().unwrap().pixels,
        read_all(&clip, 1)[7].pixels
    );
    assert_eq!(by_data.source_files().len(), 2);
}

#[test]
fn written_mraw_round_trips_at_8_12_and_16_bits_with_both_headers() {
    let tmp = tempfile::tempdir().unwrap();
    for (bits, effective, max, shift) in [
        (8, 8, 255u16, 0u32),
        (12, 12, 4095, 4),
        (16, 12, 4095, 4),
        (16, 16, 65535, 0),
    ] {
        for header in [PhotronHeader::Cihx, PhotronHeader::Cih] {
            let mut spec = Mraw::new(24, 10, bits);
            (spec.effective, spec.header, spec.start_frame) = (effective, header, -7);
            let frames = moving_disc(24, 10, 5, max, u64::from(bits));
            let stem = format!("s{bits}_{effective}_{header:?}");
            let path = spec.write(tmp.path(), &stem, &frames);
            let clip = Clip::open(&path).unwrap();
            assert_eq!((clip.len(), clip.dimensions()), (5, (24, 10)), "{stem}");
            assert_eq!(clip.fps(), 30_000.0);
            assert_eq!(
                (clip.camera().start_frame, clip.camera().trigger_frame),
                (Some(-7), Some(7))
            );
            assert!((clip.camera().exposure_s.unwrap() - 2e-5).abs() < 1e-15);
            assert_eq!(clip.camera().camera_model.as_deref(), Some("FASTCAM test"));
            for f in read_all(&clip, 2) {
                let want: Vec<u16> = frames[f.index as usize].iter().map(|v| v << shift).collect();
                assert_eq!(u16s(&f.pixels), want, "{stem} frame {}", f.index);
                assert_eq!(f.pixels.bit_depth(), if bits == 8 { 8 } else { 16 });
            }
        }
    }
}

#[test]
fn frames_given_back_while_streaming_do_not_change_the_frames_that_follow() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = moving_disc(40, 12, 24, 4095, 3);
    let path = packed_cine(tmp.path(), &frames);
    let mraw = Mraw::new(40, 12, 12).write(tmp.path(), "given_back", &frames);
    for path in [path, mraw] {
        let clip = Clip::open(&path).unwrap();
        let mut stream = clip.frames_with(&ReadOptions::with_threads(2)).unwrap();
        let mut seen = 0;
        while let Some(f) = stream.next() {
            let f = f.unwrap();
            let want: Vec<u16> = frames[f.index as usize].iter().map(|v| v << 4).collect();
            assert_eq!(u16s(&f.pixels), want, "{} frame {}", path.display(), f.index);
            stream.recycle(f);
            seen += 1;
        }
        assert_eq!(seen, 24);
    }
}

/// A 12-bit packed CINE of these frames.
fn packed_cine(dir: &Path, frames: &[Vec<u16>]) -> PathBuf {
    let path = dir.join("given_back.cine");
    Cine::new(40, 12, CinePacking::P12).write(&path, frames);
    path
}

#[test]
fn written_cine_round_trips_at_every_depth_with_its_metadata() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (CinePacking::U8, 255u16, 0u32),
        (CinePacking::U16 { real_bpp: 12 }, 4095, 4),
        (CinePacking::U16 { real_bpp: 16 }, 65535, 0),
        (CinePacking::P10, 1023, 6),
        (CinePacking::P12, 4095, 4),
    ];
    for (packing, max, shift) in cases {
        for annotation in [8, 36] {
            let mut spec = Cine::new(20, 12, packing);
            spec.annotation = annotation;
            let frames = moving_disc(20, 12, 6, max, u64::from(max));
            let path = tmp
                .path()
                .join(format!("{packing:?}_{annotation}.cine").replace(['{', '}', ' ', ':'], ""));
            spec.write(&path, &frames);
            let clip = Clip::open(&path).unwrap();
            assert_eq!((clip.len(), clip.dimensions(), clip.fps()), (6, (20, 12), 25_000.0));
            assert!(matches!(clip.fps_source(), FpsSource::Header(_)));
            let info = clip.camera();
            assert_eq!(info.format, SourceFormat::PhantomCine);
            assert!((info.exposure_s.unwrap() - 38e-6).abs() < 1e-15);
            assert_eq!((info.start_frame, info.trigger_frame), (Some(-120), Some(120)));
            assert_eq!(info.camera_model.as_deref(), Some("Phantom v2512"));
            assert_eq!(info.camera_serial.as_deref(), Some("31337"));
            assert_eq!(
                clip.warnings()
                    .iter()
                    .any(|w| matches!(w, Warning::NonLinearPixels { .. })),
                packing == CinePacking::P10
            );
            for f in read_all(&clip, 2) {
                let want: Vec<u16> = frames[f.index as usize].iter().map(|v| v << shift).collect();
                assert_eq!(u16s(&f.pixels), want, "{packing:?} frame {}", f.index);
            }
        }
    }
}

#[test]
fn tiff_stacks_read_every_page_with_any_compression() {
    let tmp = tempfile::tempdir().unwrap();
    for bits in [8u32, 16] {
        for c in [
            TiffCompression::None,
            TiffCompression::Lzw,
            TiffCompression::Deflate,
            TiffCompression::PackBits,
        ] {
            let max = if bits == 8 { 255 } else { 65535 };
            let frames = moving_disc(30, 14, 7, max, 3);
            let path = tmp.path().join(format!("stack_{bits}_{c:?}.tif"));
            write_tiff_stack(&path, 30, 14, bits, &frames, c);
            let clip = Clip::open_with(&path, &ClipOptions::with_fps(5000.0)).unwrap();
            assert_eq!((clip.len(), clip.dimensions()), (7, (30, 14)), "{bits} {c:?}");
            assert_eq!(clip.camera().format, SourceFormat::TiffStack);
            for threads in [1, 2] {
                for f in read_all(&clip, threads) {
                    assert_eq!(
                        u16s(&f.pixels),
                        frames[f.index as usize],
                        "{bits} {c:?} page {}",
                        f.index
                    );
                }
            }
        }
    }
}

#[test]
fn a_folder_holding_only_a_stack_is_that_stack_and_a_stack_among_frames_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = moving_disc(16, 8, 4, 255, 1);
    let only = tmp.path().join("only");
    std::fs::create_dir(&only).unwrap();
    write_tiff_stack(&only.join("stack_001.tif"), 16, 8, 8, &frames, TiffCompression::None);
    let clip = Clip::open_with(&only, &ClipOptions::with_fps(100.0)).unwrap();
    assert_eq!(clip.len(), 4);
    assert_eq!(u16s(&read_all(&clip, 1)[3].pixels), frames[3]);

    let mixed = tmp.path().join("mixed");
    std::fs::create_dir(&mixed).unwrap();
    write_tiff_stack(
        &mixed.join("img_001.tif"),
        16,
        8,
        8,
        &frames[..1],
        TiffCompression::None,
    );
    write_tiff_stack(&mixed.join("img_002.tif"), 16, 8, 8, &frames, TiffCompression::None);
    let clip = Clip::open_with(&mixed, &ClipOptions::with_fps(100.0)).unwrap();
    let results: Vec<_> = clip.frames().collect();
    assert!(results[0].is_ok());
    let err = results[1].as_ref().unwrap_err();
    assert!(matches!(err, FramesError::MultiPageInFolder { .. }), "{err:?}");
    names(err, &["img_002.tif", "multi-page"]);
}

#[test]
fn a_folder_holding_one_camera_file_is_that_file() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = moving_disc(16, 8, 3, 4095, 1);
    let dir = tmp.path().join("shot");
    Mraw::new(16, 8, 12).write(&dir, "take", &frames);
    let clip = Clip::open(&dir).unwrap();
    assert_eq!((clip.len(), clip.camera().format), (3, SourceFormat::PhotronMraw));
    assert_eq!(
        u16s(&read_all(&clip, 1)[2].pixels),
        frames[2].iter().map(|v| v << 4).collect::<Vec<_>>()
    );
    Cine::new(16, 8, CinePacking::U8).write(&dir.join("other.cine"), &moving_disc(16, 8, 2, 255, 1));
    let err = Clip::open(&dir).unwrap_err();
    assert!(matches!(err, FramesError::NoFrames { .. }), "two camera files: {err:?}");
}

#[test]
fn header_fps_beats_session_toml_and_loses_to_clip_toml_and_the_command_line() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = Cine::new(8, 8, CinePacking::U8);
    let path = tmp.path().join("shot1.cine");
    spec.write(&path, &moving_disc(8, 8, 2, 255, 0));
    std::fs::write(
        tmp.path().join("session.toml"),
        "[ball]\ndiameter_m = 0.067\nmass_kg = 0.05\n[camera]\nfps = 4000\n",
    )
    .unwrap();
    assert_eq!(Clip::open(&path).unwrap().fps(), 25_000.0);
    std::fs::write(tmp.path().join("shot1.clip.toml"), "[camera]\nfps = 5000\n").unwrap();
    let clip = Clip::open(&path).unwrap();
    assert_eq!(clip.fps(), 5000.0);
    assert_eq!(
        clip.fps_source(),
        &FpsSource::ClipToml(tmp.path().join("shot1.clip.toml"))
    );
    let clip = Clip::open_with(&path, &ClipOptions::with_fps(1000.0)).unwrap();
    assert_eq!((clip.fps(), clip.fps_source()), (1000.0, &FpsSource::Override));
    // Without an fps in the header, session.toml applies.
    let stack = tmp.path().join("stack.tif");
    write_tiff_stack(&stack, 8, 8, 8, &moving_disc(8, 8, 2, 255, 0), TiffCompression::None);
    let clip = Clip::open(&stack).unwrap();
    assert_eq!(clip.fps(), 4000.0);
    assert!(matches!(clip.fps_source(), FpsSource::SessionToml(_)));
}

// ---- bad input -------------------------------------------------------------------------------------------

#[test]
fn a_truncated_or_padded_mraw_is_refused_naming_the_file_and_the_frame_count() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = moving_disc(16, 8, 4, 4095, 1);
    let header = Mraw::new(16, 8, 12).write(tmp.path(), "cut", &frames);
    let data = tmp.path().join("cut.mraw");
    let bytes = std::fs::read(&data).unwrap();
    std::fs::write(&data, &bytes[..bytes.len() - 100]).unwrap();
    let err = Clip::open(&header).unwrap_err();
    assert!(matches!(err, FramesError::CameraHeader { .. }), "{err:?}");
    names(
        &err,
        &["cut.mraw", "<frameInfo><totalFrame>", "truncated", "3 whole frames"],
    );
    let mut longer = bytes.clone();
    longer.extend([0u8; 192]);
    std::fs::write(&data, longer).unwrap();
    names(&Clip::open(&header).unwrap_err(), &["cut.mraw", "disagrees"]);
}

#[test]
fn unknown_bit_depths_huge_sizes_and_missing_data_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = moving_disc(8, 8, 1, 255, 1);
    for header in [PhotronHeader::Cihx, PhotronHeader::Cih] {
        let mut spec = Mraw::new(8, 8, 8);
        spec.header = header;
        let path = spec.write(tmp.path(), "odd", &frames);
        spec.bits = 14;
        std::fs::write(&path, spec.header_text(1)).unwrap();
        let err = Clip::open(&path).unwrap_err();
        let field = if header == PhotronHeader::Cihx {
            "<imageDataInfo><colorInfo><bit>"
        } else {
            "Color Bit"
        };
        names(&err, &["odd.ci", field, "unknown bit depth 14"]);
        spec.bits = 8;
        (spec.width, spec.height) = (1_000_000, 1_000_000);
        std::fs::write(&path, spec.header_text(1)).unwrap();
        let err = Clip::open(&path).unwrap_err();
        assert!(matches!(err, FramesError::FrameTooLarge { .. }), "{err:?}");
        names(&err, &["1000000×1000000"]);
    }
    let lonely = tmp.path().join("lonely.cihx");
    std::fs::write(&lonely, Mraw::new(8, 8, 8).header_text(1)).unwrap();
    let err = Clip::open(&lonely).unwrap_err();
    assert!(matches!(err, FramesError::MissingCompanion { .. }), "{err:?}");
    names(&err, &["lonely.cihx", "lonely.mraw"]);
    let mut small = ClipOptions::default();
    small.max_frame_pixels = 63;
    let path = Mraw::new(8, 8, 8).write(tmp.path(), "limit", &frames);
    assert!(matches!(
        Clip::open_with(&path, &small),
        Err(FramesError::FrameTooLarge { limit: 63, .. })
    ));
}

#[test]
fn a_cine_with_a_bad_offset_table_or_header_is_refused_naming_the_field() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = moving_disc(16, 8, 3, 255, 2);
    let path = tmp.path().join("bad.cine");
    let layout = Cine::new(16, 8, CinePacking::U8).write(&path, &frames);
    let good = std::fs::read(&path).unwrap();
    let patch = |at: usize, bytes: &[u8]| {
        let mut b = good.clone();
        b[at..at + bytes.len()].copy_from_slice(bytes);
        std::fs::write(&path, b).unwrap();
        Clip::open(&path).unwrap_err()
    };
    let err = patch(layout.off_offsets + 8, &(good.len() as u64 + 5).to_le_bytes());
    assert!(matches!(err, FramesError::CameraHeader { .. }), "{err:?}");
    names(&err, &["bad.cine", "pImage[1]", "leaves no room"]);
    names(
        &patch(32, &(good.len() as u32 - 4).to_le_bytes()),
        &["OffImageOffsets", "runs past the end"],
    );
    names(
        &patch(44 + 16, &7u32.to_le_bytes()),
        &["biCompression", "unknown image packing 7"],
    );
    names(
        &patch(44 + 14, &12u16.to_le_bytes()),
        &["biBitCount", "unknown bit depth 12"],
    );
    names(&patch(0, b"XX"), &["CINEFILEHEADER.Type"]);
    names(
        &patch(24, &(good.len() as u32).to_le_bytes()),
        &["OffImageHeader", "BITMAPINFOHEADER"],
    );
    // An annotation that claims the wrong image size fails that frame only, naming it.
    let mut b = good.clone();
    let at = layout.images[2] + 4;
    b[at..at + 4].copy_from_slice(&5u32.to_le_bytes());
    std::fs::write(&path, b).unwrap();
    let clip = Clip::open(&path).unwrap();
    let results: Vec<_> = clip.frames_with(&ReadOptions::with_threads(2)).unwrap().collect();
    assert!(results[0].is_ok() && results[1].is_ok());
    let err = results[2].as_ref().unwrap_err();
    assert!(matches!(err, FramesError::Decode { index: 2, .. }), "{err:?}");
    names(err, &["bad.cine", "frame 2", "image size 5 bytes"]);
    // A file cut in the last image.
    std::fs::write(&path, &good[..good.len() - 10]).unwrap();
    names(&Clip::open(&path).unwrap_err(), &["pImage[2]"]);
}

#[test]
fn video_and_other_files_say_what_reads_them() {
    let tmp = tempfile::tempdir().unwrap();
    let video = tmp.path().join("shot.mp4");
    std::fs::write(&video, b"not really").unwrap();
    let err = Clip::open(&video).unwrap_err();
    #[cfg(not(feature = "opencv"))]
    {
        assert!(matches!(err, FramesError::VideoNeedsFeature { .. }), "{err:?}");
        names(&err, &["shot.mp4", "--features opencv", "ffmpeg"]);
    }
    #[cfg(feature = "opencv")]
    names(&err, &["shot.mp4", "VideoClip"]);
    let other = tmp.path().join("notes.txt");
    std::fs::write(&other, b"x").unwrap();
    let err = Clip::open(&other).unwrap_err();
    assert!(matches!(err, FramesError::NotAClip { .. }));
    names(&err, &["notes.txt", ".cihx", ".cine"]);
    names(
        &Clip::open(tmp.path().join("nope")).unwrap_err(),
        &["nope", "no such clip folder or camera file"],
    );
}

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Corrupted headers never panic: each byte flip gives a clip that decodes or a clean error.
        #[test]
        fn corrupted_camera_files_fail_cleanly(flips in proptest::collection::vec((0usize..7000, any::<u8>()), 1..8), which in 0usize..3) {
            let tmp = tempfile::tempdir().unwrap();
            let frames = moving_disc(8, 6, 2, 255, 9);
            let path = match which {
                0 => { let p = tmp.path().join("f.cine"); Cine::new(8, 6, CinePacking::P12).write(&p, &moving_disc(8, 6, 2, 4095, 9)); p }
                1 => Mraw::new(8, 6, 8).write(tmp.path(), "f", &frames),
                _ => { let p = tmp.path().join("f.tif"); write_tiff_stack(&p, 8, 6, 8, &frames, TiffCompression::Lzw); p }
            };
            let mut bytes = std::fs::read(&path).unwrap();
            for (at, v) in flips {
                let n = bytes.len();
                bytes[at % n] ^= v;
            }
            std::fs::write(&path, bytes).unwrap();
            if let Ok(clip) = Clip::open(&path) {
                for f in clip.frames_with(&ReadOptions::with_threads(1)).unwrap() {
                    let _ = f;
                }
            }
        }
    }
}
