//! `cargo run --release -p bouncelab-track --example surface_line -- [--ball X,Y,R] FRAME.png [FRAME.png …]`:
//! the surface line each cue finds in each frame (height at the centre column, tilt, σ, roughness), for
//! looking at a clip the line finder has trouble with. With `--ball` (the ball's centre and radius, px, as
//! the tracker would know them) lines the ball is not above are left out, as in the tracker, and when no line
//! is found the faint search the tracker makes in its full stack is shown too. With `--mean`
//! the frames given are averaged first and one result is shown, as the tracker looks for the line.

use bouncelab_frames::{FrameFormat, PngDecoder, decode_bytes};
use bouncelab_track::{
    Plane, ball_columns, find_faint_surface_lines, find_surface_lines, mean_gray_level, texture_line,
};

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut ball = None;
    if let Some(i) = args.iter().position(|a| a == "--ball") {
        let v: Vec<f64> = args[i + 1]
            .split(',')
            .map(|x| x.parse().expect("--ball X,Y,R"))
            .collect();
        ball = Some((v[0], v[1], v[2]));
        args.drain(i..i + 2);
    }
    let mean = args
        .iter()
        .position(|a| a == "--mean")
        .map(|i| args.remove(i))
        .is_some();
    let frames: Vec<(String, Vec<f32>, usize, usize)> = args
        .iter()
        .map(|path| {
            let bytes = std::fs::read(path).expect("read");
            let format = FrameFormat::from_path(path.as_ref()).expect("an image file");
            let img = decode_bytes(&bytes, format, PngDecoder::Image).expect("decode");
            let luma = img.to_luma16();
            let (w, h) = (luma.width() as usize, luma.height() as usize);
            let levels = luma.as_raw().iter().map(|v| *v as f32 / 257.0).collect();
            (path.clone(), levels, w, h)
        })
        .collect();
    let frames = if mean && !frames.is_empty() {
        let (_, first, w, h) = &frames[0];
        let mut sum = vec![0.0f32; first.len()];
        for (_, f, _, _) in &frames {
            sum.iter_mut().zip(f).for_each(|(s, v)| *s += v / frames.len() as f32);
        }
        vec![(format!("mean of {} frames", frames.len()), sum, *w, *h)]
    } else {
        frames
    };
    for (path, levels, w, h) in frames {
        let plane = Plane::new(&levels, w, h);
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
        match find_surface_lines(&plane, ball) {
            Some(l) => {
                println!("  chosen      {}", show(&l.line));
                for a in &l.alternatives {
                    println!("  alternative {}", show(a));
                }
                // As the tracker does, with the ball's columns left out where it comes near the line.
                let skip = ball.and_then(|b| ball_columns(&l.line, b, (b.0, b.0)));
                match mean_gray_level(&plane, &l.line, skip) {
                    Some(s) => println!(
                        "  level by the band's mean gray: {:+.2} ± {:.2} px over {} blocks",
                        s.offset_px, s.sigma_px, s.blocks
                    ),
                    None => println!("  level by the band's mean gray: no clear step"),
                }
            }
            None => {
                println!("  no line");
                // As the tracker does in its full stack when no clear line shows.
                if let Some(l) = ball.and_then(|b| find_faint_surface_lines(&plane, b, (b.0, b.0))) {
                    println!("  faint       {}", show(&l.line));
                }
            }
        }
        if let Some(t) = texture_line(&plane) {
            println!("  texture     {}", show(&t));
        }
    }
}
