//! Looks and random physics: determinism, every family reachable, ranges respected in the truth, the
//! truth agreeing with the pixels (ball centre, surface line = mean of the ragged edge), 12-bit files, the
//! session's per-clip camera files, errors naming the field.

mod testutil;

use bouncelab_model::{Phase, SimOptions, simulate_drop};
use bouncelab_render::*;
use std::collections::BTreeSet;
use testutil::*;

#[test]
fn looks_are_byte_identical_for_a_seed_and_parallel_equals_sequential() {
    let text = tiny_look(11, "");
    let s = Scenario::parse(&text, "tiny-look").unwrap();
    let n = assert_renders_identically(&s);
    assert!(n > 60, "{n} files");
    // Another seed draws other looks.
    let mut s2 = s.clone();
    s2.seed = 12;
    let (l1, l2) = (ShotPlan::new(&s, 0).unwrap().look, ShotPlan::new(&s2, 0).unwrap().look);
    assert_ne!(l1.unwrap().band_dn, l2.unwrap().band_dn);
}

/// Every shot of the `looks` preset planned (look drawn and placed, no images), once per test process.
fn looks_preset() -> &'static (Scenario, Vec<ShotPlan>) {
    static PLANS: std::sync::OnceLock<(Scenario, Vec<ShotPlan>)> = std::sync::OnceLock::new();
    PLANS.get_or_init(|| {
        let s = Scenario::preset("looks").unwrap();
        let plans = (0..s.shots.len()).map(|i| ShotPlan::new(&s, i).unwrap()).collect();
        (s, plans)
    })
}

#[test]
fn every_family_is_reachable_in_the_looks_preset() {
    let (_, plans) = looks_preset();
    let mut seen = BTreeSet::new();
    let (mut kinds, mut names, mut formats, mut surfaces) =
        (BTreeSet::new(), BTreeSet::new(), BTreeSet::new(), BTreeSet::new());
    for p in plans {
        let l = p.look.as_ref().unwrap();
        seen.extend(l.families());
        kinds.extend(l.items.iter().map(|i| i.kind.name()));
        names.insert(l.naming.clone());
        formats.insert(format!("{:?}", l.format));
        surfaces.insert(p.truth.surface.clone());
    }
    let all: BTreeSet<&str> = LOOK_FAMILIES.iter().map(|f| f.0).collect();
    let missing: Vec<_> = all.difference(&seen).collect();
    assert!(missing.is_empty(), "families never drawn in `looks`: {missing:?}");
    for k in ["ruler", "fixture", "screw", "resting_ball", "ring", "lamp", "hand"] {
        assert!(kinds.contains(k), "no {k} in `looks` (placed: {kinds:?})");
    }
    assert_eq!(names.len(), 8, "naming patterns × extensions: {names:?}");
    assert_eq!(formats.len(), 2);
    assert_eq!(surfaces.len(), 2);
}

#[test]
fn the_looks_presets_keep_the_ball_in_view_within_their_ranges() {
    let smoke = Scenario::preset("looks-smoke").unwrap();
    let smoke_plans: Vec<ShotPlan> = (0..smoke.shots.len())
        .map(|i| ShotPlan::new(&smoke, i).unwrap())
        .collect();
    let (looks, looks_plans) = looks_preset();
    for (name, s, plans) in [("looks", looks, looks_plans), ("looks-smoke", &smoke, &smoke_plans)] {
        let spec = s.look.clone().unwrap();
        for p in plans {
            let l = p.look.as_ref().unwrap();
            assert!(
                p.frames.iter().all(|f| f.visible == Visibility::Full),
                "{name} {}: ball cut by the border",
                p.truth.clip
            );
            assert!(spec.width_px.contains(l.width_px as f64) && spec.height_px.contains(l.height_px as f64));
            assert!(
                spec.ball_radius_px.contains(p.truth.r_px),
                "{}: r {}",
                p.truth.clip,
                p.truth.r_px
            );
            assert_eq!(p.camera().width, l.width_px);
            // The band is in view below the line over the whole width.
            assert!(p.truth.surface_y_px < l.height_px as f64 - 10.0);
        }
    }
}

/// The value of every numeric column of `truth/looks.csv` with the `[look]` key it is drawn from.
type KeyOf = fn(&LookSpec) -> Range;
const RANGED: &[(&str, KeyOf)] = &[
    ("texture_dn", |l| l.texture_dn),
    ("lip_dn", |l| l.lip_dn),
    ("edge_roughness_px", |l| l.edge_roughness_px),
    ("edge_scale_px", |l| l.edge_scale_px),
    ("grain_px", |l| l.grain_px),
    ("tape_edge_roughness_px", |l| l.tape_edge_roughness_px),
    ("weave_period_px", |l| l.weave_period_px),
    ("tape_thickness_px", |l| l.tape_thickness_px),
    ("gradient", |l| l.gradient),
    ("vignetting", |l| l.vignetting),
    ("hot_spots", |l| l.hot_spots),
    ("fixtures", |l| l.fixtures),
    ("screws", |l| l.screws),
    ("light_elevation_deg", |l| l.light_elevation_deg),
    ("read_noise_dn", |l| l.read_noise_dn),
    ("look_roll_deg", |l| l.roll_deg),
    ("ball_radius_px", |l| l.ball_radius_px),
    ("width_px", |l| l.width_px),
    ("height_px", |l| l.height_px),
];

#[test]
fn look_ranges_are_respected_in_the_truth() {
    let extra = r#"
band_offset_dn = [-6, 6]
backdrop_dn = [90, 110]
backlit_backdrop_dn = [180, 200]
texture_dn = [7, 9]
lip_dn = 0
edge_roughness_px = [2, 3]
edge_scale_px = [3, 5]
grain_px = [2, 3]
tape_edge_roughness_px = [0.2, 0.4]
weave_period_px = [4, 5]
tape_thickness_px = [1, 2]
gradient = [0.1, 0.2]
vignetting = [0.3, 0.4]
light_elevation_deg = [30, 40]
read_noise_dn = [9, 11]
roll_deg = [1, 1.5]
bit_depths = [12]
formats = ["tiff"]
naming = ["img_{}"]
downslopes = ["-x"]
tape_looks = ["tape_on_clay", "woven_tape"]
"#;
    let s = Scenario::parse(&tiny_look(21, extra), "ranges").unwrap();
    let spec = s.look.clone().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = render_to(&s, dir.path(), true);
    let (h, rows) = read_csv(&out.truth_dir.join("looks.csv"));
    assert_eq!(h, LOOK_COLUMNS);
    assert_eq!(rows.len(), 3);
    let (sh, shots) = read_csv(&out.truth_dir.join("shots.csv"));
    for (row, shot) in rows.iter().zip(&shots) {
        let v = |c: &str| col(&h, row, c);
        for (c, range) in RANGED {
            let cell = v(c);
            if cell.is_empty() {
                continue; // not used by this surface
            }
            let x: f64 = cell.parse().unwrap();
            assert!(
                range(&spec).contains(x),
                "{}: {c} = {x} outside {}",
                row[0],
                range(&spec)
            );
        }
        let offset: f64 = v("band_offset_dn").parse().unwrap();
        assert!(spec.band_offset_dn.contains(offset), "band offset {offset}");
        let backdrop: f64 = v("backdrop_dn").parse().unwrap();
        let want = if v("ball_look") == "backlit" {
            spec.backlit_backdrop_dn
        } else {
            spec.backdrop_dn
        };
        assert!(
            want.contains(backdrop),
            "backdrop {backdrop} for a {} ball",
            v("ball_look")
        );
        assert_eq!(v("bit_depth"), "12");
        assert_eq!(v("format"), "tiff");
        assert_eq!(v("naming"), "img_{}.tif");
        assert_eq!(v("downslope"), "-x");
        assert!(v("families").contains("low_contrast") && v("families").contains("12in16"));
        // The shot's truth carries the look's camera: total roll, down-slope, scale from the radius.
        let roll: f64 = col(&sh, shot, "roll_deg").parse().unwrap();
        assert_eq!(roll, v("look_roll_deg").parse::<f64>().unwrap());
        assert_eq!(col(&sh, shot, "downslope"), "-x");
        let r: f64 = col(&sh, shot, "r_px").parse().unwrap();
        assert!((r - v("ball_radius_px").parse::<f64>().unwrap()).abs() < 1e-9);
        // The frames are the look's files.
        let clip_dir = out.session_dir.join(&row[0]);
        assert!(clip_dir.join("img_0.tif").is_file());
        let n = std::fs::read_dir(&clip_dir).unwrap().count();
        assert_eq!(
            n,
            col(&sh, shot, "frames").parse::<usize>().unwrap() + 1,
            "frames + clip.toml"
        );
        // Items lie where the truth says, inside the frame.
        let items: serde_json::Value = serde_json::from_str(v("items")).unwrap();
        assert!(items.as_array().unwrap().iter().all(|i| i["x_px"].is_number()));
    }
    // Clay looks only on clay, the tape looks listed on the tapes.
    assert_eq!(col(&h, &rows[0], "surface_look"), "clay_speckle");
    for row in &rows[1..] {
        assert!(["tape_on_clay", "woven_tape"].contains(&col(&h, row, "surface_look")));
    }
}

#[test]
fn the_looks_preset_respects_its_default_ranges() {
    let (s, plans) = looks_preset();
    let spec = s.look.clone().unwrap();
    for p in plans {
        let l = p.look.as_ref().unwrap();
        let row = l.row(&p.truth.clip);
        for (c, range) in RANGED {
            let i = LOOK_COLUMNS.iter().position(|x| x == c).unwrap();
            if let Ok(x) = row[i].parse::<f64>() {
                assert!(
                    range(&spec).contains(x),
                    "{}: {c} = {x} outside {}",
                    p.truth.clip,
                    range(&spec)
                );
            }
        }
        assert!(spec.band_offset_dn.contains(l.band_dn - l.backdrop_dn));
        for it in &l.items {
            if matches!(it.kind, ItemKind::Screw) {
                assert!(spec.screw_radius_px.contains(it.r_px));
            }
        }
    }
}

#[test]
fn twelve_bit_files_have_their_low_four_bits_zero() {
    // From the camera key, without a look, and from a look.
    let camera12 = tiny(3).replace("[camera]\n", "[camera]\nbit_depth = 12\n");
    let look12 = tiny_look(3, "bit_depths = [12]\nformats = [\"png\"]\n");
    for (text, name) in [(camera12, "camera"), (look12, "look")] {
        let s = Scenario::parse(&text, name).unwrap();
        let plan = ShotPlan::new(&s, 0).unwrap();
        let f = plan.renderer().frame(2);
        let Pixels::Gray16(v) = &f.pixels else {
            panic!("{name}: 12-bit data comes in 16-bit frames")
        };
        assert!(v.iter().all(|x| x & 0xF == 0), "{name}: low bits set");
        let distinct: BTreeSet<u16> = v.iter().copied().collect();
        assert!(
            distinct.len() > 256,
            "{name}: only {} levels: not 12-bit data",
            distinct.len()
        );
        // The file holds the same words.
        let bytes = encode(&f, plan.camera().format).unwrap();
        let img = image::load_from_memory(&bytes).unwrap().into_luma16();
        assert_eq!(img.as_raw(), v);
        // 16-bit data uses the low bits.
        let s16 = Scenario::parse(&tiny(3).replace("[camera]\n", "[camera]\nbit_depth = 16\n"), "16").unwrap();
        let Pixels::Gray16(w) = ShotPlan::new(&s16, 0).unwrap().renderer().frame(2).pixels else {
            panic!()
        };
        assert!(w.iter().filter(|x| *x & 0xF != 0).count() > w.len() / 2);
    }
}

/// Keys giving the ball's rim a clear contrast: a dark backdrop and a felt ball lit from near the camera.
const CONTRAST: &str = "backdrop_dn = [40, 60]\nlight_elevation_deg = [60, 80]\nball_albedo_dn = [200, 240]\n";

#[test]
fn a_looks_ball_is_where_the_truth_says() {
    // Mirrored, rolled, at its own scale: the brute-force fit of the render tests. An unshaded backlit
    // silhouette pins the absolute position; on a shaded felt ball the strongest gradient along a ray sits
    // inside a dim limb (by up to a few tenths of a pixel, the same in every frame), so there the fit must
    // follow the truth from frame to frame about a constant offset.
    for (ball, seed, absolute) in [("backlit", 2, 0.1), ("plain", 1, 0.4), ("felt_seam", 3, 0.4)] {
        let extra = format!(
            "ruler = 0\nfixtures = 0\nscrews = 0\nsecond_circle = 0\nhand = 0\nhot_spots = 0\nread_noise_dn = 1.5\nballs = [\"{ball}\"]\ndownslopes = [\"-x\"]\nroll_deg = [1, 2]\nball_radius_px = [30, 34]\nwidth_px = 240\nheight_px = 240\n{CONTRAST}"
        );
        let text = tiny_look(seed, &extra).replace("pre_contact_ms = 1", "pre_contact_ms = 6");
        let s = Scenario::parse(&text, "ball").unwrap();
        let (mut worst, mut scatter, mut n) = (0.0f64, Vec::new(), 0);
        for shot in 0..s.shots.len() {
            let plan = ShotPlan::new(&s, shot).unwrap();
            let r = plan.renderer();
            let l = plan.look.as_ref().unwrap();
            assert_eq!(l.ball.name(), ball);
            // Far enough above the band that its grains stay out of the fit's annulus.
            let clear = 6.0 + l.edge_roughness_px.unwrap_or(0.0) * 3.0;
            let mut errors = Vec::new();
            for ft in plan.frames.iter().step_by(3) {
                if ft.phase != Phase::Flight || ft.y_px + ft.r_px > plan.truth.surface_y_px - clear {
                    continue;
                }
                let f = r.frame(ft.frame);
                let (x, y, rr) = fit_circle(&f, ft.x_px, ft.y_px, ft.r_px);
                assert!(
                    (rr - ft.r_px).abs() < 0.6,
                    "{ball} frame {}: radius {rr} vs {}",
                    ft.frame,
                    ft.r_px
                );
                worst = worst.max((x - ft.x_px).hypot(y - ft.y_px));
                errors.push((x - ft.x_px, y - ft.y_px));
            }
            let m = errors.len().max(1) as f64;
            let (mx, my) = errors.iter().fold((0.0, 0.0), |a, e| (a.0 + e.0 / m, a.1 + e.1 / m));
            scatter.extend(errors.iter().map(|e| (e.0 - mx).hypot(e.1 - my)));
            n += errors.len();
        }
        let rms = (scatter.iter().map(|d| d * d).sum::<f64>() / scatter.len() as f64).sqrt();
        eprintln!(
            "{ball}: worst centre error {worst:.3} px, scatter about each shot's offset {rms:.3} px RMS, {n} frames"
        );
        assert!(n >= 8, "{ball}: only {n} frames checked");
        assert!(worst < absolute, "{ball}: worst centre error {worst} px");
        assert!(rms < 0.1, "{ball}: the fit scatters {rms} px RMS about its offset");
    }
}

/// A level clay band 80 DN above a 40 DN backdrop, no lip, no clutter, 320 × 240 px, a 20 px ball: the edge
/// is the half-way crossing (80 DN) in every column. `heights` are the drop heights, `look` the `[look]`
/// keys that differ between the tests (roughness, texture, noise, bit depth, roll).
fn edge_scenario(heights: &str, look: &str) -> Scenario {
    let text = format!(
        r#"
seed = 4
pre_contact_ms = 25
post_separation_ms = 3
[camera]
fixed_pattern_noise = 0
hot_pixel_fraction = 0
flicker_amplitude = 0
[surfaces.clay]
texture = "clay"
[grid]
surfaces = ["clay"]
drop_heights_m = {heights}
angles_deg = [0]
[look]
balls = ["felt_seam"]
backdrop_dn = 40
band_offset_dn = 80
lip_dn = 0
edge_scale_px = [3, 8]
gradient = 0
vignetting = 0
hot_spots = 0
ruler = 0
fixtures = 0
screws = 0
second_circle = 0
hand = 0
width_px = 320
height_px = 240
ball_radius_px = 20
{look}
"#
    );
    Scenario::parse(&text, "edge").unwrap()
}

#[test]
fn the_surface_line_in_truth_is_the_mean_of_the_ragged_edge() {
    // A faint texture: the edge is found in every column as the half-way crossing; the truth's line must
    // be its mean and its RMS the look's roughness.
    let s = edge_scenario(
        "[0.25, 0.3, 0.35]",
        "texture_dn = 2\nedge_roughness_px = 3\nread_noise_dn = 1\nbit_depths = [8]",
    );
    for shot in 0..s.shots.len() {
        let plan = ShotPlan::new(&s, shot).unwrap();
        let t = &plan.truth;
        let f = plan.renderer().frame(0);
        let (w, h) = (f.width as usize, f.height as usize);
        let ball = &plan.frames[0];
        let tan = t.surface_tilt_deg.to_radians().tan();
        let xc = (w as f64 - 1.0) / 2.0;
        let mut heights = Vec::new();
        for x in 0..w {
            let line = t.surface_y_px - tan * (x as f64 - xc);
            let (y0, y1) = ((line - 16.0).max(1.0) as usize, ((line + 16.0) as usize).min(h - 1));
            if (x as f64 - ball.x_px).abs() < ball.r_px + 4.0 && ball.y_px + ball.r_px + 2.0 > y0 as f64 {
                panic!("{}: the ball reaches the edge's window in frame 0", t.clip);
            }
            let v = |y: usize| f.get(x as u32, y as u32);
            let Some(y) = (y0..=y1).find(|&y| v(y) >= 80.0 && v(y - 1) < 80.0) else {
                let col: Vec<f64> = (y0..=y1).map(v).collect();
                panic!(
                    "{}: no edge in column {x} (line {line}, rows {y0}..={y1}: {col:?})",
                    t.clip
                )
            };
            let ye = y as f64 - 1.0 + (80.0 - v(y - 1)) / (v(y) - v(y - 1));
            heights.push(line - ye);
        }
        let n = heights.len() as f64;
        let mean = heights.iter().sum::<f64>() / n;
        let rms = (heights.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n).sqrt();
        eprintln!("{}: edge mean {mean:+.3} px, RMS {rms:.3} px over {n} columns", t.clip);
        assert!(
            mean.abs() < 0.3,
            "{}: mean edge height {mean} px from the truth's line",
            t.clip
        );
        assert!((rms - 3.0).abs() < 0.3, "{}: edge RMS {rms} px, look says 3", t.clip);
    }
}

/// The drawn edge's own line (`ShotRenderer::drawn_edge_line`, written to `truth/edges.csv`) is the
/// least-squares line through the edge a frame shows: on a smooth edge it is the truth's plane; on a ragged
/// one it is the line through the half-way crossings found in the frame's columns, and leans off the plane.
#[test]
fn the_drawn_edge_line_is_the_line_through_the_edge_the_frame_shows() {
    for roughness in [0.0, 3.0] {
        let s = edge_scenario(
            "[0.25, 0.3]",
            &format!(
                "texture_dn = 0.5\nedge_roughness_px = {roughness}\nread_noise_dn = 0.5\nbit_depths = [16]\nroll_deg = [1.5, 1.5]"
            ),
        );
        for shot in 0..s.shots.len() {
            let plan = ShotPlan::new(&s, shot).unwrap();
            let t = &plan.truth;
            let r = plan.renderer();
            let (y_drawn, tilt_drawn) = r.drawn_edge_line().expect("a band in view");
            let f = r.frame(0);
            let (w, h) = (f.width as usize, f.height as usize);
            let ball = &plan.frames[0];
            let xc = (w as f64 - 1.0) / 2.0;
            // The half-way crossing (80 DN between 40 and 120) down each column clear of the ball.
            let v = |x: usize, y: usize| f.get(x as u32, y as u32);
            let pts: Vec<(f64, f64)> = (0..w)
                .filter(|&x| (x as f64 - ball.x_px).abs() > ball.r_px + 4.0)
                .filter_map(|x| {
                    (1..h).find(|&y| v(x, y) >= 80.0).map(|y| {
                        (
                            x as f64 - xc,
                            y as f64 - 1.0 + (80.0 - v(x, y - 1)) / (v(x, y) - v(x, y - 1)),
                        )
                    })
                })
                .collect();
            let n = pts.len() as f64;
            let (mx, my) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
            let m = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
                / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
            let (y_seen, tilt_seen) = (my - m * mx, (-m).atan().to_degrees());
            eprintln!(
                "{} roughness {roughness}: drawn ({y_drawn:.3}, {tilt_drawn:.4}°), seen ({y_seen:.3}, {tilt_seen:.4}°), plane ({:.3}, {:.4}°)",
                t.clip, t.surface_y_px, t.surface_tilt_deg
            );
            // The frame's columns behind the ball are left out, so the two fits see slightly different columns.
            assert!((y_drawn - y_seen).abs() < 0.2 && (tilt_drawn - tilt_seen).abs() < 0.02);
            if roughness == 0.0 {
                assert!(
                    (y_drawn - t.surface_y_px).abs() < 0.05,
                    "{y_drawn} against {}",
                    t.surface_y_px
                );
                assert!((tilt_drawn - t.surface_tilt_deg).abs() < 0.01);
            } else {
                assert!(
                    (tilt_drawn - t.surface_tilt_deg).abs() > 1e-3,
                    "a ragged edge leans off its plane"
                );
            }
        }
    }
}

#[test]
fn a_look_session_gives_each_clip_its_camera_and_no_truth() {
    let text = tiny_look(6, "");
    let s = Scenario::parse(&text, "tiny-look").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = render_to(&s, dir.path(), true);
    let session = std::fs::read_to_string(out.session_dir.join("session.toml")).unwrap();
    let st: toml::Table = session.parse().unwrap();
    assert!(st["camera"].get("downslope").is_none() && st["camera"].get("width_px").is_none());
    for p in &out.shots {
        let ct: toml::Table = std::fs::read_to_string(out.session_dir.join(&p.clip).join("clip.toml"))
            .unwrap()
            .parse()
            .unwrap();
        let cam = &ct["camera"];
        assert_eq!(cam["downslope"].as_str(), Some(p.downslope.as_str()));
        assert!([8, 16].contains(&cam["bit_depth"].as_integer().unwrap()));
        assert_eq!(cam["width_px"].as_integer(), Some(176));
    }
    for f in files(&out.session_dir) {
        let text = std::fs::read(out.session_dir.join(&f)).unwrap();
        if f.extension().is_some_and(|e| e == "toml" || e == "csv") {
            let text = String::from_utf8(text).unwrap();
            for leak in ["rough", "famil", "scale", "roll", "band_", "texture", "noise", "cor ="] {
                assert!(!text.contains(leak), "{} leaks `{leak}`", f.display());
            }
        }
    }
    let (h, rows) = read_csv(&out.truth_dir.join("looks.csv"));
    assert_eq!(h, LOOK_COLUMNS);
    assert_eq!(rows.len(), 3);
}

#[test]
fn random_physics_is_drawn_in_range_and_is_the_models_truth() {
    let text = tiny(8).replacen(
        "[[shots]]",
        "[random_physics]\ndrop_height_m = [0.2, 0.5]\nangle_deg = [5, 20]\nk = [20000, 30000]\nb = [10, 18]\nmu = [0.3, 0.6]\n\n[[shots]]",
        1,
    );
    let s = Scenario::parse(&text, "random").unwrap();
    let rp = s.random_physics.unwrap();
    for i in 0..s.shots.len() {
        let p = ShotPlan::new(&s, i).unwrap();
        let t = &p.truth;
        assert!(rp.drop_height_m.unwrap().contains(t.drop_height_m) && rp.angle_deg.unwrap().contains(t.angle_deg));
        assert!(rp.k.unwrap().contains(t.k.unwrap()) && rp.b.unwrap().contains(t.b.unwrap()));
        assert!(rp.mu.unwrap().contains(t.mu.unwrap()));
        assert_eq!(t.k.unwrap() % 10.0, 0.0, "k rounded to 10 N/m");
        assert_eq!(
            (t.drop_height_m * 1000.0).round() / 1000.0,
            t.drop_height_m,
            "height rounded to mm"
        );
        assert_eq!(
            (t.angle_deg * 10.0).round() / 10.0,
            t.angle_deg,
            "incline rounded to 0.1°"
        );
        assert_eq!(s.shot(i).drop_height_m, t.drop_height_m);
        assert!(t.clip.contains(&format!("{}deg", t.angle_deg)));
        // The truth is the model's output with the drawn values.
        let effects: serde_json::Value = serde_json::from_str(&t.effects_json).unwrap();
        assert_eq!(effects["spring"]["k"].as_f64(), t.k);
        assert_eq!(effects["coulomb"]["mu"].as_f64(), t.mu);
        if !t.extra_effects.is_empty() {
            continue; // its hidden Hertz term is checked with the scenario's model below
        }
        // An independent model file with the drawn values.
        let model = bouncelab_model::ModelSpec::parse(
            &format!(
                "gravity_m_s2 = 9.81\n[ball]\nmass_kg = 0.0567\nradius_m = 0.0335\ninertia_factor = {}\n[effects.spring]\nk = {}\n[effects.damping]\nb = {}\n[effects.coulomb]\nmu = {}\n",
                2.0 / 3.0,
                t.k.unwrap(),
                t.b.unwrap(),
                t.mu.unwrap()
            ),
            "test",
        )
        .unwrap()
        .build(None)
        .unwrap();
        let imp = simulate_drop(
            &model,
            t.angle_deg.to_radians(),
            t.drop_height_m,
            &[],
            &SimOptions::default(),
        )
        .unwrap()
        .impact;
        assert_eq!(t.cor, imp.restitution);
        assert_eq!(t.contact_ms, imp.contact_time() * 1e3);
    }
    // The draws follow the seed.
    let mut s2 = s.clone();
    s2.seed = 9;
    assert_ne!(s.shot(0).drop_height_m, s2.shot(0).drop_height_m);
}

fn err(text: &str) -> String {
    Scenario::parse(text, "bad.toml").unwrap_err().to_string()
}

#[test]
fn look_and_random_physics_errors_name_the_field() {
    let look = |extra: &str| err(&tiny_look(1, extra));
    let e = look("read_noise_dn = [5, 1]");
    assert!(
        e.contains("bad.toml") && e.contains("look.read_noise_dn = [5, 1]") && e.contains("low ≤ high"),
        "{e}"
    );
    let e = look("vignetting = 2");
    assert!(e.contains("look.vignetting") && e.contains("0.9"), "{e}");
    let e = look("noise = 3");
    assert!(e.contains("noise"), "{e}");
    let e = look("balls = [\"shiny\"]");
    assert!(e.contains("shiny") && e.contains("felt_seam"), "{e}");
    let e = look("bit_depths = [10]");
    assert!(e.contains("look.bit_depths") && e.contains("10"), "{e}");
    let e = look("naming = [\"frame\"]");
    assert!(e.contains("look.naming") && e.contains("placeholder"), "{e}");
    let e = look("width_px = [300.2, 300.8]");
    assert!(e.contains("look.width_px") && e.contains("whole number"), "{e}");
    let e = look("hand = 1.5");
    assert!(e.contains("look.hand") && e.contains("probability"), "{e}");
    let e = look("balls = []");
    assert!(e.contains("look.balls") && e.contains("at least one"), "{e}");
    let e = look("width_px = \"wide\"");
    assert!(
        e.contains("line ") && e.contains("width_px") && e.contains("[low, high]"),
        "{e}"
    );
    let rp = |table: &str| err(&tiny(1).replacen("[[shots]]", &format!("[random_physics]\n{table}\n\n[[shots]]"), 1));
    let e = rp("angle_deg = [0, 80]");
    assert!(e.contains("random_physics.angle_deg") && e.contains("±60"), "{e}");
    let e = rp("k = [-5, 10]");
    assert!(e.contains("random_physics") && e.contains("low"), "{e}");
    let e = rp("mu = [0.2, 9]");
    assert!(e.contains("random_physics") && e.contains("high"), "{e}");
    let e = rp("spin = [0, 1]");
    assert!(e.contains("spin"), "{e}");
    let no_friction = tiny(1).replacen("[[shots]]", "[random_physics]\nmu = [0.3, 0.5]\n\n[[shots]]", 1)
        + "[model]\n[model.effects.spring]\nk = 25650\n[model.effects.damping]\nb = 14\n";
    let e = err(&no_friction);
    assert!(e.contains("random_physics.mu") && e.contains("coulomb"), "{e}");
}

#[test]
fn the_example_scenarios_look_and_random_physics_blocks_parse_with_the_defaults() {
    let text = include_str!("../examples/scenario.toml");
    // Uncomment the two blocks: every line from `#[look]` / `#[random_physics]` to the next blank line.
    let mut out = String::new();
    let mut inside = false;
    for line in text.lines() {
        if line.starts_with("#[look]") || line.starts_with("#[random_physics]") {
            inside = true;
        } else if line.trim().is_empty() {
            inside = false;
        }
        out += if inside { &line[1..] } else { line };
        out.push('\n');
    }
    let s = Scenario::parse(&out, "examples/scenario.toml (uncommented)").unwrap();
    assert_eq!(
        s.look.as_ref(),
        Some(&LookSpec::default()),
        "the example shows the defaults"
    );
    let rp = s.random_physics.unwrap();
    assert_eq!(rp.k, Some(Range::new(20000.0, 36000.0)));
    assert!(ShotPlan::new(&s, 0).unwrap().look.is_some());
}
