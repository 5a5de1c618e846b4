//! `cargo run --release -p bouncelab-track --example surface_line -- FRAME.png [FRAME.png …]`: the surface
//! line each cue finds in each frame (height at the centre column, tilt, σ, roughness), for looking at a
//! clip the line finder has trouble with.

use bouncelab_frames::{FrameFormat, PngDecoder, decode_bytes};
use bouncelab_track::{Plane, find_surface_lines, texture_line};

fn main() {
    for path in std::env::args().skip(1) {
        let bytes = std::fs::read(&path).expect("read");
        let format = FrameFormat::from_path(path.as_ref()).expect("an image file");
        let img = decode_bytes(&bytes, format, PngDecoder::Image).expect("decode");
        let luma = img.to_luma16();
        let (w, h) = (luma.width() as usize, luma.height() as usize);
        let plane = Plane::new(luma.as_raw(), w, h);
        let show = |l: &bouncelab_track::SurfaceLine| {
            format!(
                "{:>10} y0 {:8.2} ± {:.2} tilt {:+.3}° ± {:.3} rough {:.2} edge-def {:.2} cols {}",
                l.cue.name(),
                l.y0,
                l.sigma_y0,
                l.tilt_deg(),
                l.sigma_tilt_deg,
                l.roughness_px,
                l.edge_definition_px,
                l.columns
            )
        };
        println!("{path}");
        match find_surface_lines(&plane, None) {
            Some(l) => {
                println!("  chosen      {}", show(&l.line));
                for a in &l.alternatives {
                    println!("  alternative {}", show(a));
                }
            }
            None => println!("  no line"),
        }
        if let Some(t) = texture_line(&plane) {
            println!("  texture     {}", show(&t));
        }
    }
}
