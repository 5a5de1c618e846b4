// cargo run --release -p bouncelab-frames --example to_camera -- SESSION_DIR OUT_DIR [mraw8|mraw12|cine12|tiff] [--nested]
//
//! Writes every clip of a session (e.g. one `bouncelab render` made) as a camera file, named from its
//! conditions (`clay_15deg_250mm_shot_002.cihx`, or the clip's own name when it says them already) so that `bouncelab init` guesses them back: the input for
//! the camera-file end-to-end figures in `docs/performance.md` and for trying `init` + `analyze`.
//! `--nested` puts each file in a folder of its own (`OUT_DIR/NAME/NAME.cihx`), the layout that
//! `crates/track/examples/end_to_end.rs` reads. 8-bit frames become 12-bit samples as `v << 4`.

#[path = "../tests/common/camera.rs"]
mod camera;

use bouncelab_frames::{ClipOptions, GrayPixels, ReadOptions, Session};
use camera::{Cine, CinePacking, Mraw, TiffCompression, write_tiff_stack};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let nested = args.iter().any(|a| a == "--nested");
    let plain: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    let (Some(session), Some(out)) = (plain.first(), plain.get(1)) else {
        eprintln!("usage: to_camera SESSION_DIR OUT_DIR [mraw8|mraw12|cine12|tiff] [--nested]");
        std::process::exit(2);
    };
    let format = plain.get(2).map_or("mraw12", |s| s.as_str());
    let session = Session::load(session.as_str()).expect("session loads");
    let out = std::path::Path::new(out.as_str());
    std::fs::create_dir_all(out).unwrap();
    for entry in &session.clips {
        let clip = bouncelab_frames::Clip::open_with(&entry.dir, &ClipOptions::with_fps(entry.fps)).unwrap();
        let (w, h) = clip.dimensions();
        let frames: Vec<Vec<u16>> = clip
            .frames_with(&ReadOptions::with_threads(2))
            .unwrap()
            .map(|f| match f.unwrap().pixels {
                GrayPixels::U8(i) => i.as_raw().iter().map(|&v| u16::from(v)).collect(),
                GrayPixels::U16(i) => i.as_raw().iter().map(|&v| v >> 8).collect(),
            })
            .collect();
        let g = bouncelab_frames::init::guess_from_name(&entry.name);
        let name = if g.surface.is_some() && g.angle_deg.is_some() && g.drop_height_m.is_some() {
            entry.name.clone()
        } else {
            format!(
                "{}_{}deg_{}mm_{}",
                entry.surface,
                entry.angle_deg,
                (entry.drop_height_m * 1000.0).round(),
                entry.name
            )
        };
        let dir = if nested { out.join(&name) } else { out.to_path_buf() };
        std::fs::create_dir_all(&dir).unwrap();
        let to12 = |f: &Vec<u16>| f.iter().map(|v| v << 4).collect::<Vec<u16>>();
        let written = match format {
            "mraw8" | "mraw12" => {
                let bits = if format == "mraw8" { 8 } else { 12 };
                let mut spec = Mraw::new(w, h, bits);
                (spec.fps, spec.start_frame) = (entry.fps, 0);
                let frames: Vec<Vec<u16>> = if bits == 12 {
                    frames.iter().map(to12).collect()
                } else {
                    frames
                };
                spec.write(&dir, &name, &frames)
            }
            "cine12" => {
                let mut spec = Cine::new(w, h, CinePacking::P12);
                spec.fps = entry.fps.round() as u32;
                let path = dir.join(format!("{name}.cine"));
                spec.write(&path, &frames.iter().map(to12).collect::<Vec<_>>());
                path
            }
            "tiff" => {
                let path = dir.join(format!("{name}.tif"));
                write_tiff_stack(&path, w, h, 8, &frames, TiffCompression::None);
                path
            }
            other => panic!("unknown format {other}"),
        };
        println!("{} ({} frames) -> {}", entry.name, clip.len(), written.display());
    }
}
