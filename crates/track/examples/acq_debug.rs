use bouncelab_frames::{Clip, GrayPixels, PngDecoder};
use bouncelab_track::*;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let clip = Clip::open(&a[1]).unwrap();
    let k: usize = a[2].parse().unwrap();
    let f = clip.read(k, PngDecoder::Image).unwrap().unwrap();
    let (w, h) = f.pixels.dimensions();
    let raw = std::env::args().nth(3).is_some();
    let run = |p: &dyn Fn(&CircleDetection) -> Vec<(Circle, Refined)>| {
        for (lo, hi) in radius_bands(8.0, w.min(h) as f64 / 2.0) {
            let det = CircleDetection {
                min_radius: lo,
                max_radius: hi,
                max_candidates: 24,
                ..CircleDetection::default()
            };
            for (c, r) in p(&det) {
                println!(
                    "band {lo:.0}-{hi:.0}: ({:.1},{:.1}) r {:.1} q {:.3} kept {}/{} contrast {:.1} hidden {} outside {}",
                    r.fit.x,
                    r.fit.y,
                    r.fit.r,
                    c.support,
                    r.fit.inliers,
                    r.rays,
                    r.contrast,
                    r.rays_hidden,
                    r.rays_outside
                );
            }
        }
    };
    match &f.pixels {
        GrayPixels::U8(img) => {
            let p = Plane::new(img.as_raw(), w as usize, h as usize);
            if raw {
                for (lo, hi) in radius_bands(8.0, w.min(h) as f64 / 2.0) {
                    for c in detect_circles(
                        &p,
                        &CircleDetection {
                            min_radius: lo,
                            max_radius: hi,
                            max_candidates: 24,
                            noise_sigma: std::env::var("NOISE").ok().map(|v| v.parse().unwrap()),
                            ..Default::default()
                        },
                    ) {
                        println!("raw {lo:.0}-{hi:.0} {c:?}")
                    }
                }
            } else {
                run(&|d| {
                    refined_candidates(
                        &p,
                        d,
                        &EdgeSearch {
                            smooth: std::env::var("SMOOTH").is_ok(),
                            ..EdgeSearch::default()
                        },
                        None,
                        0.3,
                    )
                })
            }
        }
        GrayPixels::U16(img) => {
            let p = Plane::new(img.as_raw(), w as usize, h as usize);
            if raw {
                for (lo, hi) in radius_bands(8.0, w.min(h) as f64 / 2.0) {
                    for c in detect_circles(
                        &p,
                        &CircleDetection {
                            min_radius: lo,
                            max_radius: hi,
                            max_candidates: 24,
                            noise_sigma: std::env::var("NOISE").ok().map(|v| v.parse().unwrap()),
                            ..Default::default()
                        },
                    ) {
                        println!("raw {lo:.0}-{hi:.0} {c:?}")
                    }
                }
            } else {
                run(&|d| {
                    refined_candidates(
                        &p,
                        d,
                        &EdgeSearch {
                            smooth: std::env::var("SMOOTH").is_ok(),
                            ..EdgeSearch::default()
                        },
                        None,
                        0.3,
                    )
                })
            }
        }
    }
}
