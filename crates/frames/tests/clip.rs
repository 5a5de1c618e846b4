//! Reading clip folders: formats, order, gaps, fps precedence, bad input (`docs/session.md`).

use std::path::Path;

use bouncelab_frames::testutil::{ClipSpec, SESSION_TOML, noisy_gradient, write_frame};
use bouncelab_frames::{
    Clip, ClipOptions, FpsSource, Frame, FramesError, GrayPixels, PngDecoder, ReadOptions, Warning,
};
use image::{ColorType, DynamicImage};
use proptest::prelude::*;

fn read_all(clip: &Clip, options: &ReadOptions) -> Vec<Frame> {
    clip.frames_with(options).unwrap().map(|f| f.unwrap()).collect()
}

fn expected_gray(img: &DynamicImage) -> GrayPixels {
    match img.color() {
        ColorType::L8 => GrayPixels::U8(img.to_luma8()),
        ColorType::L16 => GrayPixels::U16(img.to_luma16()),
        c if c.bytes_per_pixel() / c.channel_count() == 1 => GrayPixels::U8(img.to_luma8()),
        _ => GrayPixels::U16(img.to_luma16()),
    }
}

#[test]
fn every_lossless_format_and_depth_round_trips_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        ("png", ColorType::L8),
        ("png", ColorType::L16),
        ("png", ColorType::Rgb8),
        ("png", ColorType::Rgba16),
        ("tif", ColorType::L8),
        ("tiff", ColorType::L16),
        ("tif", ColorType::Rgb8),
        ("bmp", ColorType::L8),
        ("bmp", ColorType::Rgb8),
        ("pgm", ColorType::L8),
        ("pgm", ColorType::L16),
        ("ppm", ColorType::Rgb8),
    ];
    for (i, (ext, colour)) in cases.into_iter().enumerate() {
        let spec = ClipSpec::new(3).ext(ext).colour(colour);
        let dir = tmp.path().join(format!("c{i}"));
        spec.write(&dir);
        let clip = Clip::open_with(&dir, &ClipOptions::with_fps(1000.0)).unwrap();
        assert_eq!(clip.dimensions(), (32, 24));
        let frames = read_all(&clip, &ReadOptions::default());
        assert_eq!(frames.len(), 3, "{ext} {colour:?}");
        for f in &frames {
            let want = expected_gray(&spec.image(f.number));
            assert_eq!(f.pixels.bit_depth(), want.bit_depth(), "{ext} {colour:?}");
            assert_eq!(f.pixels, want, "{ext} {colour:?} frame {}", f.number);
        }
    }
}

#[test]
fn colour_becomes_luma_and_sixteen_bit_keeps_precision() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = ClipSpec::new(1).colour(ColorType::L16);
    spec.write(tmp.path());
    let f = Clip::open(tmp.path()).unwrap().frames().next().unwrap().unwrap();
    let px = f.pixels.as_u16().expect("16-bit stays 16-bit");
    assert!(px.as_raw().iter().any(|v| v % 257 != 0), "low byte kept");

    let rgb = tempfile::tempdir().unwrap();
    let spec = ClipSpec::new(1).colour(ColorType::Rgb8);
    spec.write(rgb.path());
    let f = Clip::open(rgb.path()).unwrap().frames().next().unwrap().unwrap();
    let src = spec.image(1).to_rgb8();
    let (p, g) = (src.get_pixel(5, 7).0, f.pixels.as_u8().unwrap().get_pixel(5, 7).0[0]);
    let luma = 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
    assert!((f64::from(g) - luma).abs() <= 1.0, "{g} vs {luma}");
}

#[test]
fn jpeg_reads_back_approximately() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = ClipSpec::new(2).ext("jpg");
    spec.write(tmp.path());
    let clip = Clip::open(tmp.path()).unwrap();
    for f in read_all(&clip, &ReadOptions::default()) {
        let want = spec.image(f.number).to_luma8();
        let got = f.pixels.as_u8().unwrap();
        assert_eq!(got.dimensions(), want.dimensions());
        let mean_err = got
            .as_raw()
            .iter()
            .zip(want.as_raw())
            .map(|(&a, &b)| f64::from(a.abs_diff(b)))
            .sum::<f64>()
            / want.as_raw().len() as f64;
        assert!(mean_err < 25.0, "mean abs error {mean_err}");
    }
}

#[test]
fn mixed_formats_other_files_and_hidden_files() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    for (n, ext) in [(1, "png"), (2, "tif"), (3, "pgm"), (4, "bmp")] {
        write_frame(&d.join(format!("f{n}.{ext}")), &noisy_gradient(8, 8, n, ColorType::L8));
    }
    std::fs::write(d.join("notes.txt"), "hello 99").unwrap();
    std::fs::write(d.join("._f5.png"), "resource fork").unwrap();
    std::fs::write(d.join("clip.toml"), "[camera]\nfps = 2000\n").unwrap();
    std::fs::create_dir(d.join("thumbs")).unwrap();
    let clip = Clip::open(d).unwrap();
    assert_eq!(
        clip.files().iter().map(|f| f.number).collect::<Vec<_>>(),
        vec![1, 2, 3, 4]
    );
    assert_eq!(clip.fps(), 2000.0);
    assert!(matches!(clip.fps_source(), FpsSource::ClipToml(_)));
    assert!(!clip.warnings().iter().any(|w| matches!(w, Warning::DefaultFps { .. })));
}

#[test]
fn lab_names_sort_by_their_last_number() {
    let tmp = tempfile::tempdir().unwrap();
    let names = [
        "C001H001S0001000123.png",
        "C001H001S0001000124.png",
        "img_2.png",
        "img_10.png",
        "7.png",
    ];
    for (i, n) in names.iter().enumerate() {
        write_frame(&tmp.path().join(n), &noisy_gradient(4, 4, i as u64, ColorType::L8));
    }
    let clip = Clip::open(tmp.path()).unwrap();
    let order: Vec<_> = clip
        .files()
        .iter()
        .map(|f| f.path.file_name().unwrap().to_str().unwrap().to_string())
        .collect();
    assert_eq!(
        order,
        [
            "img_2.png",
            "7.png",
            "img_10.png",
            "C001H001S0001000123.png",
            "C001H001S0001000124.png"
        ]
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]
    #[test]
    fn shuffled_padded_names_sort_by_number(
        numbers in proptest::collection::btree_set(0u64..100_000, 1..12),
        pads in proptest::collection::vec(0usize..9, 12),
        seed in any::<u64>(),
    ) {
        let tmp = tempfile::tempdir().unwrap();
        let mut order: Vec<u64> = numbers.iter().copied().collect();
        // Write in a shuffled order with random padding and prefixes.
        let mut s = seed;
        for i in (1..order.len()).rev() {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            order.swap(i, (s >> 33) as usize % (i + 1));
        }
        for (k, n) in order.iter().enumerate() {
            let name = format!("{}{:0pad$}.pgm", ["img_", "C001H001S", "", "x9_"][k % 4], n, pad = pads[k]);
            write_frame(&tmp.path().join(name), &noisy_gradient(2, 2, *n, ColorType::L8));
        }
        let clip = Clip::open_with(tmp.path(), &ClipOptions::with_fps(100.0)).unwrap();
        let got: Vec<u64> = clip.files().iter().map(|f| f.number).collect();
        let want: Vec<u64> = numbers.iter().copied().collect();
        prop_assert_eq!(got, want);
    }
}

#[test]
fn a_gap_is_reported_and_timestamps_follow_numbers() {
    let tmp = tempfile::tempdir().unwrap();
    ClipSpec::new(0)
        .numbers([100, 101, 102, 105, 106, 108])
        .write(tmp.path());
    let clip = Clip::open_with(tmp.path(), &ClipOptions::with_fps(1000.0)).unwrap();
    assert_eq!(clip.len(), 6);
    assert_eq!(clip.span(), 9);
    assert_eq!(clip.dropped(), 3);
    let gaps: Vec<_> = clip.gaps().iter().map(|g| (g.first, g.last, g.len())).collect();
    assert_eq!(gaps, vec![(103, 104, 2), (107, 107, 1)]);
    let frames = read_all(&clip, &ReadOptions::default());
    let idx: Vec<_> = frames.iter().map(|f| f.index).collect();
    assert_eq!(idx, vec![0, 1, 2, 5, 6, 8]);
    for f in &frames {
        assert!((f.t_s - f.index as f64 / 1000.0).abs() < 1e-15);
    }
    assert!((frames[3].t_s - 0.005).abs() < 1e-15);
}

#[test]
fn parallel_and_sequential_decoding_agree_for_both_png_decoders() {
    let tmp = tempfile::tempdir().unwrap();
    ClipSpec::new(23)
        .numbers((1..=25).filter(|n| n % 11 != 0))
        .write(tmp.path());
    let clip = Clip::open(tmp.path()).unwrap();
    let mut reference = ReadOptions::with_threads(1);
    reference.png_decoder = PngDecoder::Image;
    let seq = read_all(&clip, &reference);
    assert_eq!(seq.len(), 23);
    for threads in [None, Some(1), Some(2), Some(3)] {
        for window in [None, Some(1), Some(5), Some(100)] {
            for png in [PngDecoder::Zune, PngDecoder::Image] {
                let mut o = ReadOptions::default();
                (o.threads, o.window, o.png_decoder) = (threads, window, png);
                let stream = clip.frames_with(&o).unwrap();
                assert_eq!(stream.len(), 23);
                assert_eq!(
                    stream.map(|f| f.unwrap()).collect::<Vec<_>>(),
                    seq,
                    "{threads:?} {window:?} {png:?}"
                );
            }
        }
    }
    assert_eq!(clip.read(3, PngDecoder::Zune).unwrap().unwrap(), seq[3]);
    assert!(clip.read(23, PngDecoder::Zune).is_none());
}

// ---- fps precedence --------------------------------------------------------------------------------------

#[test]
fn fps_precedence_override_then_clip_then_session_then_default() {
    let tmp = tempfile::tempdir().unwrap();
    let clip_dir = tmp.path().join("shot");
    ClipSpec::new(2).write(&clip_dir);

    let clip = Clip::open(&clip_dir).unwrap();
    assert_eq!((clip.fps(), clip.fps_source()), (10_000.0, &FpsSource::Default));
    assert!(matches!(
        clip.warnings(),
        [Warning::DefaultFps { .. }, Warning::DefaultDiameter { .. }]
    ));
    assert!(clip.warnings()[0].to_string().contains("10000"));

    std::fs::write(tmp.path().join("session.toml"), SESSION_TOML.replace("10000", "4000")).unwrap();
    let clip = Clip::open(&clip_dir).unwrap();
    assert_eq!(clip.fps(), 4000.0);
    // session.toml gives the fps and the ball: no default is taken.
    assert!(matches!(clip.fps_source(), FpsSource::SessionToml(_)) && clip.warnings().is_empty());

    std::fs::write(clip_dir.join("clip.toml"), "[camera]\nfps = 5000.0\n").unwrap();
    let clip = Clip::open(&clip_dir).unwrap();
    assert_eq!(clip.fps(), 5000.0);
    assert!(matches!(clip.fps_source(), FpsSource::ClipToml(_)));

    let clip = Clip::open_with(&clip_dir, &ClipOptions::with_fps(20_000.0)).unwrap();
    assert_eq!((clip.fps(), clip.fps_source()), (20_000.0, &FpsSource::Override));
    assert_eq!(clip.time_of(2), 1e-4);
}

#[test]
fn nonsense_fps_is_an_error_naming_file_and_field() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path().join("shot");
    ClipSpec::new(1).write(&d);
    for bad in ["0", "-10000", "nan", "\"ten thousand\"", "1e9"] {
        std::fs::write(d.join("clip.toml"), format!("[camera]\nfps = {bad}\n")).unwrap();
        let err = Clip::open(&d).unwrap_err();
        assert!(matches!(err, FramesError::BadFps { .. }), "{bad}: {err:?}");
        let msg = err.to_string();
        assert!(msg.contains("clip.toml") && msg.contains("[camera] fps"), "{msg}");
    }
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 2e7] {
        let err = Clip::open_with(&d, &ClipOptions::with_fps(bad)).unwrap_err();
        assert!(matches!(err, FramesError::BadFps { .. }), "{bad}");
        assert!(err.to_string().contains("command line"));
    }
    std::fs::write(d.join("clip.toml"), "[camera\nfps = 3").unwrap();
    let err = Clip::open(&d).unwrap_err();
    assert!(
        matches!(err, FramesError::Toml { .. }) && err.to_string().contains("clip.toml"),
        "{err}"
    );
}

// ---- bad input -------------------------------------------------------------------------------------------

fn message_names(err: &FramesError, what: &str) {
    assert!(err.to_string().contains(what), "`{err}` should name `{what}`");
}

#[test]
fn empty_or_missing_folder_is_an_error_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("readme.txt"), "no frames here 1").unwrap();
    let err = Clip::open(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::NoFrames { .. }));
    message_names(&err, &tmp.path().display().to_string());

    let missing = tmp.path().join("nope");
    let err = Clip::open(&missing).unwrap_err();
    assert!(matches!(err, FramesError::NotAFolder { .. }));
    message_names(&err, "nope");
}

#[test]
fn names_without_numbers_and_duplicate_numbers_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let img = noisy_gradient(4, 4, 0, ColorType::L8);
    write_frame(&tmp.path().join("img_001.png"), &img);
    write_frame(&tmp.path().join("background.png"), &img);
    let err = Clip::open(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::NoNumber { .. }));
    message_names(&err, "background.png");

    std::fs::remove_file(tmp.path().join("background.png")).unwrap();
    write_frame(&tmp.path().join("img_1.tif"), &img);
    let err = Clip::open(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::DuplicateNumber { number: 1, .. }));
    message_names(&err, "img_001.png");
    message_names(&err, "img_1.tif");
}

#[test]
fn truncated_and_garbage_frames_are_errors_naming_file_and_index() {
    for ext in ["png", "tif", "pgm", "bmp", "jpg"] {
        let tmp = tempfile::tempdir().unwrap();
        let paths = ClipSpec::new(5).ext(ext).write(tmp.path());
        let bytes = std::fs::read(&paths[2]).unwrap();
        std::fs::write(&paths[2], &bytes[..bytes.len() / 2]).unwrap();
        std::fs::write(&paths[3], b"this is not an image").unwrap();
        let clip = Clip::open(tmp.path()).unwrap();
        for threads in [1, 2] {
            let results: Vec<_> = clip.frames_with(&ReadOptions::with_threads(threads)).unwrap().collect();
            assert_eq!(results.len(), 5);
            assert!(results[0].is_ok() && results[1].is_ok() && results[4].is_ok(), "{ext}");
            for (k, name) in [(2usize, "img_0003"), (3, "img_0004")] {
                let err = results[k].as_ref().unwrap_err();
                assert!(
                    matches!(err, FramesError::Decode { index, .. } if *index == k as u64),
                    "{ext}: {err:?}"
                );
                message_names(err, name);
                message_names(err, &format!("frame {k}"));
            }
        }
    }
}

#[test]
fn a_frame_of_another_size_is_an_error_naming_file_and_both_sizes() {
    let tmp = tempfile::tempdir().unwrap();
    ClipSpec::new(3).write(tmp.path());
    write_frame(
        &tmp.path().join("img_0004.png"),
        &noisy_gradient(16, 24, 4, ColorType::L8),
    );
    let clip = Clip::open(tmp.path()).unwrap();
    let results: Vec<_> = clip.frames().collect();
    let err = results[3].as_ref().unwrap_err();
    assert!(
        matches!(
            err,
            FramesError::SizeMismatch {
                found: (16, 24),
                expected: (32, 24),
                ..
            }
        ),
        "{err:?}"
    );
    message_names(err, "img_0004.png");
    message_names(err, "16×24");
    message_names(err, "32×24");
}

#[test]
fn unreadable_first_frame_fails_at_open_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("f_1.png"), b"").unwrap();
    let err = Clip::open(tmp.path()).unwrap_err();
    assert!(matches!(err, FramesError::Decode { index: 0, .. }));
    message_names(&err, "f_1.png");
    let _ = Path::new("");
}
