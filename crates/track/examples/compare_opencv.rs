// cargo run --release -p bouncelab-track --features opencv --example compare_opencv -- [SESSION_DIR TRUTH_DIR]
//! Our tracker (`track_clip`) against OpenCV's `HoughCircles` (HOUGH_GRADIENT, HOUGH_GRADIENT_ALT) on the
//! same frames: centre RMS error against the truth in flight and in contact, radius bias, and tracking time
//! per frame (frames decoded on the tracking thread but not counted; one thread, OpenCV's too).
//!
//! Without arguments: ~200 synthetic 512×512 frames from `testutil` (a ball of radius 72 px on a parabola,
//! bouncing into a textured band that hides its bottom; noise; a screw head), the scene's ball as truth.
//! A second table compares the pre-blurs for the OpenCV detectors alone (frames in memory).
//!
//! With arguments: every clip of a rendered session (`SESSION_DIR/clips.csv`, one folder per clip) against
//! `TRUTH_DIR/<clip>.csv` (columns found by name: frame, x_px, y_px, r_px, phase; a clip without frame,
//! x_px or y_px is skipped, a missing r_px or phase leaves that column empty).

use bouncelab_frames::{Clip, ReadOptions, Session};
use bouncelab_track::opencv::{OpencvMethod, OpencvParams, PreBlur, detect_circles_opencv_with, track_clip_opencv};
use bouncelab_track::testutil::{Scene, render};
use bouncelab_track::{CircleDetection, ClipTracking, Plane, Track, TrackError, track_clip};
use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

/// The truth of one frame.
#[derive(Clone, Copy)]
struct Truth {
    x: f64,
    y: f64,
    r: Option<f64>,
    /// `None` when the phase is unknown.
    contact: Option<bool>,
}

/// Sums for one detector.
#[derive(Default)]
struct Acc {
    frames: usize,
    measured: usize,
    sq: [f64; 2],
    n: [usize; 2],
    dr: [f64; 2],
    nr: [usize; 2],
    seconds: f64,
    phases_known: bool,
}

impl Acc {
    fn add(&mut self, track: &Track, truth: &HashMap<usize, Truth>) {
        self.frames += track.fixes.len();
        self.seconds += track.seconds_tracking;
        for f in &track.fixes {
            let Some(t) = truth.get(&f.frame) else { continue };
            if !f.status.measured() {
                continue;
            }
            self.measured += 1;
            let k = match t.contact {
                Some(c) => {
                    self.phases_known = true;
                    c as usize
                }
                None => 0,
            };
            self.sq[k] += (f.x_px - t.x).powi(2) + (f.y_px - t.y).powi(2);
            self.n[k] += 1;
            if let Some(r) = t.r {
                self.dr[k] += f.r_px - r;
                self.nr[k] += 1;
            }
        }
    }

    fn row(&self, name: &str) -> String {
        let rms = |k: usize| match self.n[k] {
            0 => "–".to_string(),
            n => format!("{:.3}", (self.sq[k] / n as f64).sqrt()),
        };
        let bias = |k: usize| match self.nr[k] {
            0 => "–".to_string(),
            n => format!("{:+.3}", self.dr[k] / n as f64),
        };
        let (flight, contact) = if self.phases_known { ("", "") } else { (" (all)", "") };
        format!(
            "| {name} | {}/{} | {}{flight} | {}{contact} | {} | {} | {:.3} |",
            self.measured,
            self.frames,
            rms(0),
            rms(1),
            bias(0),
            bias(1),
            1e3 * self.seconds / self.frames.max(1) as f64
        )
    }
}

const HEADER: &str = "| detector | measured / frames | centre RMS flight (px) | centre RMS contact (px) | radius bias flight (px) | radius bias contact (px) | ms/frame |\n| --- | --- | --- | --- | --- | --- | --- |";

// Synthetic clip: 512×512, surface line at y = 400 px, ball radius 72 px.
const FRAMES: usize = 200;
const SURFACE_Y: f64 = 400.0;
const R: f64 = 72.0;

/// The true centre at frame `i` and whether the ball touches the surface: in at 0.45 px/frame, a 45-frame
/// contact with up to 6 px penetration, out at 0.77 of the speed in; 0.3 px/frame along x; gravity
/// 2.1e-4 px/frame² (9.81 m/s² at 4.65e-4 m/px and 10,000 fps).
fn synthetic_truth(i: usize) -> (f64, f64, bool) {
    let (g, v_in, touch, contact, delta_max) = (2.1e-4, 0.45, 80.0, 45.0, 6.0);
    let t = i as f64;
    let y_touch = SURFACE_Y - R;
    let x = 140.0 + 0.3 * t;
    if t < touch {
        let s = touch - t;
        (x, y_touch - v_in * s + 0.5 * g * s * s, false)
    } else if t <= touch + contact {
        let phase = std::f64::consts::PI * (t - touch) / contact;
        (x, y_touch + delta_max * phase.sin(), true)
    } else {
        let s = t - touch - contact;
        (x, y_touch - 0.77 * v_in * s + 0.5 * g * s * s, false)
    }
}

fn synthetic_scene(i: usize) -> Scene {
    let (x, y, _) = synthetic_truth(i);
    Scene {
        size: (512, 512),
        ball: (x, y, R),
        ball_level: 210.0,
        backdrop: (60.0, 100.0),
        surface: Some((SURFACE_Y, 0.0)),
        band: (120.0, 50.0),
        distractors: vec![(440.0, 120.0, 9.0, 40.0), (60.0, 470.0, 25.0, 190.0)],
        marks: Vec::new(),
        noise: 5.0,
        seed: 1000 + i as u64,
        roughness: 0.0,
    }
}

type Detector = (&'static str, Option<OpencvMethod>);
const DETECTORS: [Detector; 3] = [
    ("ours (track_clip)", None),
    ("OpenCV HOUGH_GRADIENT", Some(OpencvMethod::Gradient)),
    ("OpenCV HOUGH_GRADIENT_ALT", Some(OpencvMethod::GradientAlt)),
];

fn run(clip: &Clip, opts: &ClipTracking, method: Option<OpencvMethod>) -> Result<Track, TrackError> {
    match method {
        None => track_clip(clip, opts, |_, _| {}),
        Some(m) => track_clip_opencv(clip, opts, m, |_, _| {}),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    opencv::core::set_num_threads(1)?;
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [] => synthetic(),
        [session, truth] => session_mode(Path::new(session), Path::new(truth)),
        _ => Err("usage: compare_opencv [SESSION_DIR TRUTH_DIR]".into()),
    }
}

fn synthetic() -> Result<(), Box<dyn std::error::Error>> {
    let dir = tempfile::tempdir()?;
    let mut truth = HashMap::new();
    let mut frames = Vec::new();
    for i in 0..FRAMES {
        let s = synthetic_scene(i);
        let px = render(&s);
        let (x, y, contact) = synthetic_truth(i);
        truth.insert(
            i,
            Truth {
                x,
                y,
                r: Some(R),
                contact: Some(contact),
            },
        );
        image::GrayImage::from_raw(512, 512, px.clone())
            .ok_or("frame size")?
            .save(dir.path().join(format!("img_{i:05}.png")))?;
        frames.push(px);
    }
    let opts = ClipTracking {
        read: ReadOptions::with_threads(1),
        ..ClipTracking::default()
    };
    println!(
        "Synthetic: {FRAMES} frames 512×512, ball r = {R} px, contact frames 80–125 (bottom hidden by a textured band), noise σ = 5, scale found from the ball's motion.\n"
    );
    println!("{HEADER}");
    let clip = Clip::open(dir.path())?;
    for (name, method) in DETECTORS {
        let track = run(&clip, &opts, method)?;
        let mut acc = Acc::default();
        acc.add(&track, &truth);
        println!("{}", acc.row(name));
    }
    blur_table(&frames, &truth);
    Ok(())
}

/// Detection alone on frames in memory, for each pre-blur: the candidate nearest the truth within one
/// radius counts as found.
fn blur_table(frames: &[Vec<u8>], truth: &HashMap<usize, Truth>) {
    println!(
        "\nPre-blur, OpenCV detection alone (radius range {:.0}–{:.0} px, candidate nearest the truth):\n",
        0.85 * R,
        1.15 * R
    );
    println!(
        "| method | pre-blur | found | centre RMS flight (px) | centre RMS contact (px) | false circles / frame | ms/frame |\n| --- | --- | --- | --- | --- | --- | --- |"
    );
    let det = CircleDetection {
        min_radius: 0.85 * R,
        max_radius: 1.15 * R,
        max_candidates: 100,
        ..CircleDetection::default()
    };
    let blurs = [
        ("none", PreBlur::None),
        ("Gaussian 9×9 σ 2", PreBlur::Gaussian { ksize: 9, sigma: 2.0 }),
        ("median 5", PreBlur::Median { ksize: 5 }),
    ];
    for method in [OpencvMethod::Gradient, OpencvMethod::GradientAlt] {
        for (bname, blur) in blurs {
            let params = OpencvParams {
                blur,
                ..OpencvParams::for_method(method)
            };
            let (mut found, mut false_circles, mut seconds) = (0, 0, 0.0);
            let (mut sq, mut n) = ([0.0; 2], [0usize; 2]);
            for (i, px) in frames.iter().enumerate() {
                let t = truth[&i];
                let plane = Plane::new(px, 512, 512);
                let start = Instant::now();
                let cands = detect_circles_opencv_with(&plane, &det, &params).unwrap_or_default();
                seconds += start.elapsed().as_secs_f64();
                let d = |c: &bouncelab_track::Circle| (c.x - t.x).hypot(c.y - t.y);
                let near = cands.iter().filter(|c| d(c) <= R).min_by(|a, b| d(a).total_cmp(&d(b)));
                false_circles += cands.len() - near.is_some() as usize;
                if let Some(c) = near {
                    found += 1;
                    let k = t.contact == Some(true);
                    sq[k as usize] += d(c).powi(2);
                    n[k as usize] += 1;
                }
            }
            let rms = |k: usize| match n[k] {
                0 => "–".to_string(),
                m => format!("{:.3}", (sq[k] / m as f64).sqrt()),
            };
            println!(
                "| {} | {bname} | {found}/{} | {} | {} | {:.2} | {:.2} |",
                method.name(),
                frames.len(),
                rms(0),
                rms(1),
                false_circles as f64 / frames.len() as f64,
                1e3 * seconds / frames.len() as f64
            );
        }
    }
}

/// `TRUTH_DIR/<clip>.csv` by column name; `None` (with a note) when frame, x_px or y_px is missing.
fn read_truth(path: &Path) -> Option<HashMap<usize, Truth>> {
    let mut rdr = match csv::Reader::from_path(path) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("skipping {}: {e}", path.display());
            return None;
        }
    };
    let headers = rdr.headers().ok()?.clone();
    let col = |name: &str| headers.iter().position(|h| h.trim() == name);
    let (Some(cf), Some(cx), Some(cy)) = (col("frame"), col("x_px"), col("y_px")) else {
        eprintln!("skipping {}: needs columns frame, x_px, y_px", path.display());
        return None;
    };
    let (cr, cp) = (col("r_px"), col("phase"));
    let mut out = HashMap::new();
    for rec in rdr.records().flatten() {
        let num = |c: usize| rec.get(c).and_then(|v| v.trim().parse::<f64>().ok());
        let (Some(f), Some(x), Some(y)) = (rec.get(cf).and_then(|v| v.trim().parse().ok()), num(cx), num(cy)) else {
            continue;
        };
        let contact = cp.and_then(|c| rec.get(c)).map(|p| {
            let p = p.trim();
            p == "compression" || p == "restitution" || p == "contact"
        });
        out.insert(
            f,
            Truth {
                x,
                y,
                r: cr.and_then(num),
                contact,
            },
        );
    }
    Some(out)
}

fn session_mode(session: &Path, truth_dir: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let s = Session::load(session)?;
    let mut accs: Vec<Acc> = DETECTORS.iter().map(|_| Acc::default()).collect();
    let mut clips = 0;
    for entry in &s.clips {
        let Some(truth) = read_truth(&truth_dir.join(format!("{}.csv", entry.name))) else {
            continue;
        };
        let opts = ClipTracking {
            ball_diameter_m: s.ball.diameter_m,
            downslope_negative_x: entry.downslope == bouncelab_frames::Downslope::MinusX,
            read: ReadOptions::with_threads(1),
            ..ClipTracking::default()
        };
        let clip = match entry.open() {
            Ok(c) => c,
            Err(e) => {
                eprintln!("skipping {}: {e}", entry.name);
                continue;
            }
        };
        for ((name, method), acc) in DETECTORS.iter().zip(&mut accs) {
            match run(&clip, &opts, *method) {
                Ok(track) => acc.add(&track, &truth),
                Err(e) => eprintln!("{}: {name}: {e}", entry.name),
            }
        }
        clips += 1;
        eprintln!("{} done", entry.name);
    }
    println!("Session {}: {clips} clips\n", session.display());
    println!("{HEADER}");
    for ((name, _), acc) in DETECTORS.iter().zip(&accs) {
        println!("{}", acc.row(name));
    }
    Ok(())
}
