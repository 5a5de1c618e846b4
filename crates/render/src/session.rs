//! Writing a session (`docs/session.md`) and its truth beside it.

use crate::scene::{Pixels, RenderedFrame};
use crate::shot::{ShotPlan, ShotTruth};
use crate::{Format, RenderError, Scenario};
use image::ExtendedColorType;
use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Receives progress while a session renders (a progress bar, a log, a test). Methods are called from
/// worker threads.
pub trait RenderObserver: Sync {
    /// Every shot is planned: `shots` clips with `frames` frames in total will be written.
    fn planned(&self, _shots: usize, _frames: usize) {}
    /// One more frame is written.
    fn frame_written(&self) {}
    /// A clip is complete.
    fn shot_done(&self, _truth: &ShotTruth) {}
}

/// An observer that does nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoRenderProgress;
impl RenderObserver for NoRenderProgress {}

/// How to render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RenderOptions {
    /// Render shots and frames in parallel (rayon); the output is byte-identical either way.
    pub parallel: bool,
    /// Replace existing `session/` and `truth/` folders in the output folder instead of refusing.
    pub overwrite: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            parallel: true,
            overwrite: false,
        }
    }
}

/// What a render wrote.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The session folder (`out_dir/session`).
    pub session_dir: PathBuf,
    /// The truth folder (`out_dir/truth`).
    pub truth_dir: PathBuf,
    /// Per-shot truth, in shot order.
    pub shots: Vec<ShotTruth>,
    /// Frames written.
    pub frames: usize,
}

/// Renders `scenario` into `out_dir/session` (the session) and `out_dir/truth` (its ground truth), in
/// parallel, refusing to overwrite.
pub fn render(scenario: &Scenario, out_dir: &Path) -> Result<Rendered, RenderError> {
    render_with(scenario, out_dir, &RenderOptions::default(), &NoRenderProgress)
}

fn non_empty(p: &Path) -> bool {
    std::fs::read_dir(p).map(|mut d| d.next().is_some()).unwrap_or(false) || (p.exists() && !p.is_dir())
}

/// Renders `scenario` into `out_dir` with options and a progress observer.
pub fn render_with(
    scenario: &Scenario,
    out_dir: &Path,
    opts: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Result<Rendered, RenderError> {
    let session_dir = out_dir.join("session");
    let truth_dir = out_dir.join("truth");
    for d in [&session_dir, &truth_dir] {
        if non_empty(d) {
            if !opts.overwrite {
                return Err(RenderError::OutputExists { path: d.clone() });
            }
            std::fs::remove_dir_all(d).map_err(|e| RenderError::write(d, e))?;
        }
    }
    for d in [&session_dir, &truth_dir] {
        std::fs::create_dir_all(d).map_err(|e| RenderError::write(d, e))?;
    }
    let n = scenario.shots.len();
    let plans: Vec<ShotPlan> = if opts.parallel {
        (0..n)
            .into_par_iter()
            .map(|i| ShotPlan::new(scenario, i))
            .collect::<Result<_, _>>()?
    } else {
        (0..n).map(|i| ShotPlan::new(scenario, i)).collect::<Result<_, _>>()?
    };
    let total: usize = plans.iter().map(|p| p.frames.len()).sum();
    observer.planned(n, total);
    write_session_files(scenario, &session_dir, &plans)?;
    write_truth_files(scenario, &truth_dir, &plans)?;
    let one = |p: &ShotPlan| -> Result<Option<(f64, f64)>, RenderError> {
        let dir = session_dir.join(&p.truth.clip);
        std::fs::create_dir_all(&dir).map_err(|e| RenderError::write(&dir, e))?;
        let r = p.renderer();
        let cam = p.camera();
        let write = |i: usize| -> Result<(), RenderError> {
            let path = dir.join(cam.frame_name(i));
            let bytes = encode(&r.frame(i), cam.format).map_err(|e| RenderError::write(&path, e))?;
            std::fs::write(&path, bytes).map_err(|e| RenderError::write(&path, e))?;
            observer.frame_written();
            Ok(())
        };
        if opts.parallel {
            (0..p.frames.len()).into_par_iter().try_for_each(write)?;
        } else {
            (0..p.frames.len()).try_for_each(write)?;
        }
        observer.shot_done(&p.truth);
        Ok(r.drawn_edge_line())
    };
    let edges: Vec<Option<(f64, f64)>> = if opts.parallel {
        plans.par_iter().map(one).collect::<Result<_, _>>()?
    } else {
        plans.iter().map(one).collect::<Result<_, _>>()?
    };
    write_csv(
        &truth_dir.join("edges.csv"),
        EDGE_COLUMNS,
        plans.iter().zip(&edges),
        |(p, e)| {
            let (y, tilt) = e.map_or((String::new(), String::new()), |(y, t)| (num(y), num(t)));
            vec![p.truth.clip.clone(), y, tilt]
        },
    )?;
    Ok(Rendered {
        session_dir,
        truth_dir,
        shots: plans.iter().map(|p| p.truth.clone()).collect(),
        frames: total,
    })
}

/// Encodes a frame as PNG (fast compression) or uncompressed TIFF.
pub fn encode(frame: &RenderedFrame, format: Format) -> Result<Vec<u8>, image::ImageError> {
    let (w, h) = (frame.width, frame.height);
    let (bytes, color): (std::borrow::Cow<[u8]>, _) = match &frame.pixels {
        Pixels::Gray8(v) => (v.as_slice().into(), ExtendedColorType::L8),
        Pixels::Gray16(v) => (
            v.iter().flat_map(|x| x.to_ne_bytes()).collect::<Vec<u8>>().into(),
            ExtendedColorType::L16,
        ),
    };
    let mut out = Vec::with_capacity(bytes.len() / 2 + 1024);
    match format {
        Format::Png => PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Sub)
            .write_image(&bytes, w, h, color)?,
        Format::Tiff => {
            let mut cur = std::io::Cursor::new(&mut out);
            image::codecs::tiff::TiffEncoder::new(&mut cur).write_image(&bytes, w, h, color)?
        }
    }
    Ok(out)
}

fn write_csv<T>(
    path: &Path,
    header: &[&str],
    rows: impl Iterator<Item = T>,
    f: impl Fn(T) -> Vec<String>,
) -> Result<(), RenderError> {
    let mut wr = csv::Writer::from_path(path).map_err(|e| RenderError::write(path, e))?;
    wr.write_record(header).map_err(|e| RenderError::write(path, e))?;
    for r in rows {
        wr.write_record(f(r)).map_err(|e| RenderError::write(path, e))?;
    }
    wr.flush().map_err(|e| RenderError::write(path, e))
}

/// A number as written in CSV files: shortest round-trip form, never `-0`.
fn num(x: f64) -> String {
    (x + 0.0).to_string()
}

fn format_name(f: Format) -> &'static str {
    match f {
        Format::Png => "png",
        Format::Tiff => "tiff",
    }
}

/// The bits of the files a camera writes (12-bit data comes in 16-bit files).
fn file_bits(c: &crate::Camera) -> u8 {
    if c.bit_depth == 8 { 8 } else { 16 }
}

fn write_session_files(scenario: &Scenario, dir: &Path, plans: &[ShotPlan]) -> Result<(), RenderError> {
    let c = &scenario.camera;
    let desc = if scenario.description.is_empty() {
        scenario.name.clone()
    } else {
        scenario.description.clone()
    };
    if scenario.look.is_some() {
        return write_look_session_files(scenario, dir, plans, &desc);
    }
    let text = format!(
        "# Rendered by bouncelab-render {}: a synthetic session. Its ground truth is beside it (../truth), never here.\n\n[session]\ndescription = {}\nsynthetic = true\n\n[ball]\ndiameter_m = {}\nmass_kg = {}\n\n[camera]\nfps = {}\ndownslope = \"{}\"\nexposure_s = {}\nbit_depth = {}\nwidth_px = {}\nheight_px = {}\nformat = \"{}\"\n",
        env!("CARGO_PKG_VERSION"),
        toml::Value::String(desc),
        scenario.ball.diameter_m,
        scenario.ball.mass_kg,
        c.fps,
        c.downslope.as_str(),
        c.exposure_s,
        file_bits(c),
        c.width,
        c.height,
        match c.format {
            Format::Png => "png",
            Format::Tiff => "tiff",
        },
    );
    let p = dir.join("session.toml");
    std::fs::write(&p, text).map_err(|e| RenderError::write(&p, e))?;
    write_clips_csv(dir, plans)
}

fn write_clips_csv(dir: &Path, plans: &[ShotPlan]) -> Result<(), RenderError> {
    write_csv(
        &dir.join("clips.csv"),
        &["clip", "surface", "angle_deg", "drop_height_m", "repeat"],
        plans.iter(),
        |p| {
            let t = &p.truth;
            vec![
                t.clip.clone(),
                t.surface.clone(),
                num(t.angle_deg),
                num(t.drop_height_m),
                t.repeat.to_string(),
            ]
        },
    )
}

/// Columns of `truth/edges.csv`: the least-squares line through each shot's band edge as drawn
/// ([`crate::ShotRenderer::drawn_edge_line`]; empty where the frame shows no band), at the centre column as the
/// surface line of `shots.csv` is.
pub const EDGE_COLUMNS: &[&str] = &["clip", "drawn_edge_y_px", "drawn_edge_tilt_deg"];

/// Columns of `truth/shots.csv`.
pub const SHOTS_COLUMNS: &[&str] = &[
    "clip",
    "surface",
    "angle_deg",
    "drop_height_m",
    "repeat",
    "seed",
    "frames",
    "v_in_t",
    "v_in_n",
    "v_out_t",
    "v_out_n",
    "cor",
    "mu_eff",
    "t_touch_s",
    "t_max_s",
    "t_sep_s",
    "contact_ms",
    "delta_max_m",
    "spin_in",
    "spin_out",
    "rolling_at_separation",
    "scale_m_per_px",
    "r_px",
    "surface_y_px",
    "surface_tilt_deg",
    "roll_deg",
    "downslope",
    "k",
    "b",
    "mu",
    "extra_effects",
    "effects",
];

/// Columns of `truth/<clip>.csv`.
pub const FRAME_COLUMNS: &[&str] = &[
    "frame",
    "t_s",
    "x_px",
    "y_px",
    "r_px",
    "x_m",
    "y_m",
    "theta_rad",
    "phase",
    "visible",
    "delta_m",
];

/// `session.toml` with what all clips share, and each clip's own camera in its `clip.toml` (as a lab writes
/// one per camera set-up): frame size, file bits and format, and the down-slope direction the pipeline needs.
fn write_look_session_files(
    scenario: &Scenario,
    dir: &Path,
    plans: &[ShotPlan],
    desc: &str,
) -> Result<(), RenderError> {
    let c = &scenario.camera;
    let text = format!(
        "# Rendered by bouncelab-render {}: a synthetic session. Its ground truth is beside it (../truth), never here.\n# Each clip's camera (frame size, bits, format, down-slope) is in its clip.toml.\n\n[session]\ndescription = {}\nsynthetic = true\n\n[ball]\ndiameter_m = {}\nmass_kg = {}\n\n[camera]\nfps = {}\nexposure_s = {}\n",
        env!("CARGO_PKG_VERSION"),
        toml::Value::String(desc.to_string()),
        scenario.ball.diameter_m,
        scenario.ball.mass_kg,
        c.fps,
        c.exposure_s,
    );
    let p = dir.join("session.toml");
    std::fs::write(&p, text).map_err(|e| RenderError::write(&p, e))?;
    for plan in plans {
        let c = plan.camera();
        let clip_dir = dir.join(&plan.truth.clip);
        std::fs::create_dir_all(&clip_dir).map_err(|e| RenderError::write(&clip_dir, e))?;
        let text = format!(
            "[camera]\ndownslope = \"{}\"\nbit_depth = {}\nwidth_px = {}\nheight_px = {}\nformat = \"{}\"\n",
            c.downslope.as_str(),
            file_bits(c),
            c.width,
            c.height,
            format_name(c.format),
        );
        let p = clip_dir.join("clip.toml");
        std::fs::write(&p, text).map_err(|e| RenderError::write(&p, e))?;
    }
    write_clips_csv(dir, plans)
}

fn write_truth_files(scenario: &Scenario, dir: &Path, plans: &[ShotPlan]) -> Result<(), RenderError> {
    let opt = |v: Option<f64>| v.map(num).unwrap_or_default();
    write_csv(&dir.join("shots.csv"), SHOTS_COLUMNS, plans.iter(), |p| {
        let t = &p.truth;
        vec![
            t.clip.clone(),
            t.surface.clone(),
            num(t.angle_deg),
            num(t.drop_height_m),
            t.repeat.to_string(),
            t.seed.to_string(),
            t.frames.to_string(),
            num(t.v_in_t),
            num(t.v_in_n),
            num(t.v_out_t),
            num(t.v_out_n),
            num(t.cor),
            num(t.mu_eff),
            num(t.t_touch_s),
            num(t.t_max_s),
            num(t.t_sep_s),
            num(t.contact_ms),
            num(t.delta_max_m),
            num(t.spin_in),
            num(t.spin_out),
            t.rolling_at_separation.to_string(),
            num(t.scale_m_per_px),
            num(t.r_px),
            num(t.surface_y_px),
            num(t.surface_tilt_deg),
            num(t.roll_deg),
            t.downslope.clone(),
            opt(t.k),
            opt(t.b),
            opt(t.mu),
            if t.extra_effects.is_empty() {
                "none".into()
            } else {
                t.extra_effects.join("+")
            },
            t.effects_json.clone(),
        ]
    })?;
    for p in plans {
        write_csv(
            &dir.join(format!("{}.csv", p.truth.clip)),
            FRAME_COLUMNS,
            p.frames.iter(),
            |f| {
                vec![
                    f.frame.to_string(),
                    num(f.t_s),
                    num(f.x_px),
                    num(f.y_px),
                    num(f.r_px),
                    num(f.x_m),
                    num(f.y_m),
                    num(f.theta_rad),
                    f.phase.name().to_string(),
                    f.visible.name().to_string(),
                    num(f.delta_m),
                ]
            },
        )?;
    }
    if scenario.look.is_some() {
        write_csv(
            &dir.join("looks.csv"),
            crate::LOOK_COLUMNS,
            plans.iter().filter_map(|p| p.look.as_ref().map(|l| (p, l))),
            |(p, l)| l.row(&p.truth.clip),
        )?;
    }
    let p = dir.join("scenario.toml");
    let text = format!(
        "# The scenario this session was rendered from ({}), rendered with seed = {}.\n{}",
        scenario.origin, scenario.seed, scenario.source
    );
    std::fs::write(&p, text).map_err(|e| RenderError::write(&p, e))
}
