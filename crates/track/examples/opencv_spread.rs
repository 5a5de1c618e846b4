// cargo run --release -p bouncelab-track --features opencv --example opencv_spread -- [SEEDS]
//! How far OpenCV's `HoughCircles` (both methods, this crate's default parameters) lands from the ball on
//! the frames of `tests/opencv.rs`: the test's three balls, each rendered with noise seeds 0..SEEDS
//! (default 100), centre and radius errors against the drawn ball, per ball and over all three, as RMS,
//! percentiles and the largest. The test's limits are set from this spread (`docs/accuracy.md`), not from
//! one frame.

use bouncelab_track::opencv::{OpencvMethod, detect_circles_opencv};
use bouncelab_track::testutil::{opencv_scene, render};
use bouncelab_track::{CircleDetection, Plane};

/// The balls of `tests/opencv.rs` (x, y, r), px.
const BALLS: [(f64, f64, f64); 3] = [(201.3, 240.6, 60.0), (260.8, 300.2, 72.5), (300.4, 190.9, 84.0)];

/// Noise seeds per ball in the test.
const TEST_SEEDS: usize = 4;

/// Errors of one method on a set of frames, px.
#[derive(Default, Clone)]
struct Spread {
    /// Centre errors in seed order (NaN where nothing was found).
    block: Vec<f64>,
    centre: Vec<f64>,
    radius: Vec<f64>,
    missed: usize,
}

impl Spread {
    fn row(&mut self, name: &str) -> String {
        let (c, r) = (&mut self.centre, &mut self.radius);
        c.sort_by(f64::total_cmp);
        r.sort_by(f64::total_cmp);
        let at = |v: &[f64], p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
        let rms = (c.iter().map(|d| d * d).sum::<f64>() / c.len() as f64).sqrt();
        format!(
            "| {name} | {} | {rms:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            self.missed,
            at(c, 0.5),
            at(c, 0.95),
            at(c, 0.99),
            c[c.len() - 1],
            at(r, 0.99),
            r[r.len() - 1],
        )
    }
}

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .map_or(100, |s| s.parse().expect("SEEDS: a count"));
    let methods = [OpencvMethod::Gradient, OpencvMethod::GradientAlt];
    // [method][ball]
    let mut spread = vec![vec![Spread::default(); BALLS.len()]; methods.len()];
    for seed in 0..seeds {
        for (b, ball) in BALLS.into_iter().enumerate() {
            let px = render(&opencv_scene(ball, seed));
            let plane = Plane::new(&px, 512, 512);
            let det = CircleDetection {
                min_radius: 0.85 * ball.2,
                max_radius: 1.15 * ball.2,
                ..CircleDetection::default()
            };
            for (m, method) in methods.into_iter().enumerate() {
                let s = &mut spread[m][b];
                match detect_circles_opencv(&plane, &det, method)
                    .expect("valid options")
                    .first()
                {
                    Some(best) => {
                        s.block.push((best.x - ball.0).hypot(best.y - ball.1));
                        s.centre.push((best.x - ball.0).hypot(best.y - ball.1));
                        s.radius.push((best.r - ball.2).abs());
                    }
                    None => {
                        s.block.push(f64::NAN);
                        s.missed += 1;
                    }
                }
            }
        }
    }
    println!("noise seeds 0..{seeds}, one frame per ball and seed\n");
    println!("| method, ball | missed | centre RMS px | p50 | p95 | p99 | max | radius |err| p99 | max |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for (m, method) in methods.into_iter().enumerate() {
        let mut all = Spread::default();
        for (b, s) in spread[m].iter_mut().enumerate() {
            println!("{}", s.row(&format!("{method:?}, {:?}", BALLS[b])));
            all.centre.extend(&s.centre);
            all.radius.extend(&s.radius);
            all.missed += s.missed;
        }
        println!("{}", all.row(&format!("{method:?}, all three")));
    }
    // The test's RMS is over the three balls with TEST_SEEDS noise seeds each: its spread over disjoint
    // blocks of seeds.
    println!("\ncentre RMS over the three balls × {TEST_SEEDS} seeds, blocks of seeds 0..{seeds}:");
    for (m, method) in methods.into_iter().enumerate() {
        let mut rms: Vec<f64> = (0..seeds as usize / TEST_SEEDS)
            .map(|k| {
                let block = |s: &Spread| s.block[k * TEST_SEEDS..(k + 1) * TEST_SEEDS].to_vec();
                let d: Vec<f64> = spread[m].iter().flat_map(block).collect();
                (d.iter().map(|d| d * d).sum::<f64>() / d.len() as f64).sqrt()
            })
            .collect();
        rms.sort_by(f64::total_cmp);
        println!(
            "{method:?}: {} blocks, median {:.3}, max {:.3}",
            rms.len(),
            rms[rms.len() / 2],
            rms[rms.len() - 1]
        );
    }
}
