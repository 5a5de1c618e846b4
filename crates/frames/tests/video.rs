//! Video files through OpenCV (feature `opencv`): a small MJPG .avi written by OpenCV reads back.
#![cfg(feature = "opencv")]

use bouncelab_frames::video::{VideoClip, is_video};
use bouncelab_frames::{ClipOptions, FpsSource, FramesError};
use opencv::core::{Mat, Size};
use opencv::prelude::*;
use opencv::{imgproc, videoio};

const W: i32 = 64;
const H: i32 = 48;

/// Frame k: a horizontal gradient plus 30·k, gray.
fn level(k: i32, x: i32) -> u8 {
    (20 + 30 * k + 2 * x).clamp(0, 255) as u8
}

fn write_avi(path: &std::path::Path, frames: i32, fps: f64) {
    let fourcc = videoio::VideoWriter::fourcc('M', 'J', 'P', 'G').unwrap();
    let mut writer = videoio::VideoWriter::new(path.to_str().unwrap(), fourcc, fps, Size::new(W, H), true).unwrap();
    assert!(writer.is_opened().unwrap(), "VideoWriter opens");
    for k in 0..frames {
        let mut gray = Mat::new_rows_cols_with_default(H, W, opencv::core::CV_8UC1, 0.into()).unwrap();
        for (i, px) in gray.data_bytes_mut().unwrap().iter_mut().enumerate() {
            *px = level(k, i as i32 % W);
        }
        let mut bgr = Mat::default();
        imgproc::cvt_color_def(&gray, &mut bgr, imgproc::COLOR_GRAY2BGR).unwrap();
        writer.write(&bgr).unwrap();
    }
    writer.release().unwrap();
}

#[test]
fn an_mjpg_avi_reads_back_as_gray_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("shot.avi");
    write_avi(&path, 5, 25.0);
    assert!(is_video(&path));
    let video = VideoClip::open(&path, &ClipOptions::default()).unwrap();
    assert_eq!(video.dimensions(), (W as u32, H as u32));
    assert_eq!(video.frame_count(), Some(5));
    assert_eq!(video.fps(), 25.0);
    assert!(matches!(video.fps_source(), FpsSource::Container(_)));
    let frames: Vec<_> = video.map(|f| f.unwrap()).collect();
    assert_eq!(frames.len(), 5);
    for (k, f) in frames.iter().enumerate() {
        assert_eq!((f.index, f.t_s), (k as u64, k as f64 / 25.0));
        let img = f.pixels.as_u8().expect("8-bit gray");
        assert_eq!(img.dimensions(), (W as u32, H as u32));
        let err: f64 = img
            .enumerate_pixels()
            .map(|(x, _, p)| f64::from(p.0[0].abs_diff(level(k as i32, x as i32))))
            .sum::<f64>()
            / f64::from(W * H);
        assert!(err < 6.0, "frame {k}: mean abs error {err}");
    }
}

#[test]
fn fps_override_and_bad_files() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("shot.avi");
    write_avi(&path, 2, 30.0);
    let video = VideoClip::open(&path, &ClipOptions::with_fps(10_000.0)).unwrap();
    assert_eq!((video.fps(), video.fps_source()), (10_000.0, &FpsSource::Override));
    assert_eq!(video.last().unwrap().unwrap().t_s, 1e-4);

    let missing = VideoClip::open(tmp.path().join("none.mp4"), &ClipOptions::default())
        .err()
        .unwrap();
    assert!(matches!(missing, FramesError::Video { .. }) && missing.to_string().contains("none.mp4"));
    let junk = tmp.path().join("junk.mov");
    std::fs::write(&junk, b"not a video at all").unwrap();
    let err = VideoClip::open(&junk, &ClipOptions::default()).err().unwrap();
    assert!(err.to_string().contains("junk.mov"), "{err}");
}
