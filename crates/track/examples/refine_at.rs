use bouncelab_frames::{Clip, GrayPixels, PngDecoder};
use bouncelab_track::*;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let clip = Clip::open(&a[1]).unwrap();
    let k: usize = a[2].parse().unwrap();
    let (x, y, r): (f64, f64, f64) = (a[3].parse().unwrap(), a[4].parse().unwrap(), a[5].parse().unwrap());
    let f = clip.read(k, PngDecoder::Image).unwrap().unwrap();
    let (w, h) = f.pixels.dimensions();
    for smooth in [false, true] {
        for hw in [2.0, 4.0, 6.0] {
            let s = EdgeSearch {
                smooth,
                half_width: hw,
                ..EdgeSearch::default()
            };
            let r = match &f.pixels {
                GrayPixels::U8(i) => refine_circle(&Plane::new(i.as_raw(), w as usize, h as usize), x, y, r, &s, None),
                GrayPixels::U16(i) => refine_circle(&Plane::new(i.as_raw(), w as usize, h as usize), x, y, r, &s, None),
            };
            if let Some(r) = r {
                println!(
                    "smooth {smooth} hw {hw}: ({:.2},{:.2}) r {:.2} q {:.3} kept {}/{} edges {} contrast {:.1}",
                    r.fit.x,
                    r.fit.y,
                    r.fit.r,
                    r.quality(),
                    r.fit.inliers,
                    r.rays,
                    r.rays_with_edge,
                    r.contrast
                );
            } else {
                println!("smooth {smooth} hw {hw}: none");
            }
        }
    }
}
