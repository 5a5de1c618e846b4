//! cargo run --release -p bouncelab-render --example docs_frames [-- OUT_DIR]
//!
//! Writes the example frames of docs/renderer.md: one flight frame per surface texture of the `paper`
//! preset (render-clay.png, render-white_tape.png, render-green_tape.png) and a 2× close-up of the clay
//! contact at maximum compression (render-contact.png).

use bouncelab_render::{Pixels, RenderedFrame, Scenario, ShotPlan, encode};

fn save(frame: &RenderedFrame, path: &std::path::Path) {
    std::fs::write(path, encode(frame, bouncelab_render::Format::Png).unwrap()).unwrap();
    println!("{}", path.display());
}

fn main() {
    let out = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "docs".into()));
    let s = Scenario::preset("paper").unwrap();
    let pick = |surface: &str, angle: f64, h: f64| {
        s.shots
            .iter()
            .position(|x| x.surface == surface && x.angle_deg == angle && x.drop_height_m == h && x.repeat == 1)
            .unwrap()
    };
    for (surface, texture, angle) in [
        ("clay", "clay", 15.0),
        ("tape1", "white_tape", 7.5),
        ("tape2", "green_tape", 22.5),
    ] {
        let plan = ShotPlan::new(&s, pick(surface, angle, 0.33)).unwrap();
        let i = ((plan.truth.t_touch_s - 0.006) * s.camera.fps).round() as usize;
        save(&plan.renderer().frame(i), &out.join(format!("render-{texture}.png")));
    }
    let plan = ShotPlan::new(&s, pick("clay", 22.5, 0.4)).unwrap();
    let i = (plan.truth.t_max_s * s.camera.fps).round() as usize;
    let f = plan.renderer().frame(i);
    let ft = &plan.frames[i];
    let (cw, ch) = (220u32, 130u32);
    let x0 = (ft.x_px as i64 - cw as i64 / 2).clamp(0, (f.width - cw) as i64) as u32;
    let y0 = ((ft.y_px + ft.r_px) as i64 - 80).clamp(0, (f.height - ch) as i64) as u32;
    let Pixels::Gray8(px) = &f.pixels else { unreachable!() };
    let mut crop = Vec::with_capacity((4 * cw * ch) as usize);
    for y in 0..2 * ch {
        for x in 0..2 * cw {
            crop.push(px[((y0 + y / 2) * f.width + x0 + x / 2) as usize]);
        }
    }
    let close = RenderedFrame {
        width: 2 * cw,
        height: 2 * ch,
        pixels: Pixels::Gray8(crop),
    };
    save(&close, &out.join("render-contact.png"));
    println!(
        "contact: frame {i}, delta = {:.2} mm ({:.1} px), crop at ({x0}, {y0})",
        ft.delta_m * 1e3,
        ft.delta_m / s.camera.scale_m_per_px
    );
}
