//! cargo run --release -p bouncelab-render --example looks_sheet [-- OUT_DIR [PRESET|SCENARIO.toml] [SHOTS]]
//!
//! Contact sheets of the looks of a preset (default `looks`; 12 shots chosen one by one, surfaces in turn,
//! each adding the most family tags and clutter kinds not yet shown): `render-looks.png`, each
//! shot's frame 3 ms before the touch scaled to a 300 × 300 tile, and `render-looks-edges.png`, 1:1 crops
//! of the band's edge under the ball at the touch. Prints each tile's families.

use bouncelab_render::{Pixels, RenderedFrame, Scenario, ShotPlan, encode};
use std::collections::BTreeSet;

/// The frame as 8-bit gray (16-bit and 12-in-16 data scaled down).
fn gray8(f: &RenderedFrame, bit_depth: u8) -> Vec<u8> {
    match &f.pixels {
        Pixels::Gray8(v) => v.clone(),
        Pixels::Gray16(v) if bit_depth == 12 => v
            .iter()
            .map(|&x| ((x >> 4) as f64 * 255.0 / 4095.0).round() as u8)
            .collect(),
        Pixels::Gray16(v) => v.iter().map(|&x| (x as f64 / 257.0).round() as u8).collect(),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = std::path::PathBuf::from(args.first().cloned().unwrap_or_else(|| "docs".into()));
    let preset = args.get(1).cloned().unwrap_or_else(|| "looks".into());
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(12);
    let s = if preset.ends_with(".toml") {
        Scenario::load(std::path::Path::new(&preset)).expect("scenario")
    } else {
        Scenario::preset(&preset).expect("preset")
    };
    let (cols, tile) = (4usize, 300usize);
    let rows = n.div_ceil(cols);
    let (cw, ch) = (240usize, 120usize);
    let mut sheet = vec![24u8; cols * tile * rows * tile];
    let mut edges = vec![24u8; cols * cw * rows * ch];
    let n = n.min(s.shots.len());
    let plans: Vec<ShotPlan> = (0..s.shots.len())
        .map(|i| ShotPlan::new(&s, i).expect("plan"))
        .collect();
    let tags = |p: &ShotPlan| -> BTreeSet<String> {
        let l = p.look.as_ref().expect("a preset with [look]");
        let mut t: BTreeSet<String> = l.families().iter().map(|f| f.to_string()).collect();
        t.extend(l.items.iter().map(|i| i.kind.name().to_string()));
        t
    };
    let (mut chosen, mut shown) = (Vec::new(), BTreeSet::new());
    let surfaces: Vec<&str> = s.surfaces.iter().map(|x| x.name.as_str()).collect();
    for k in 0..n {
        // Surfaces in turn, so the sheet shows clay and tapes alike.
        let surface = surfaces[k % surfaces.len()];
        let best = (0..plans.len())
            .filter(|i| !chosen.contains(i) && plans[*i].truth.surface == surface)
            .max_by_key(|&i| (tags(&plans[i]).difference(&shown).count(), std::cmp::Reverse(i)))
            .expect("enough shots");
        shown.extend(tags(&plans[best]));
        chosen.push(best);
    }
    chosen.sort();
    for (k, &index) in chosen.iter().enumerate() {
        let plan = &plans[index];
        let look = plan.look.as_ref().expect("a preset with [look]");
        let r = plan.renderer();
        let fps = plan.camera().fps;
        let i = ((plan.truth.t_touch_s - 0.003) * fps).round().max(0.0) as usize;
        let f = r.frame(i.min(plan.frames.len() - 1));
        let px = gray8(&f, look.bit_depth);
        let (w, h) = (f.width as usize, f.height as usize);
        let sc = (w.max(h) as f64 / tile as f64).max(1.0);
        let (ox, oy) = ((k % cols) * tile, (k / cols) * tile);
        for ty in 0..tile {
            for tx in 0..tile {
                // Box filter over the source pixels under the tile pixel.
                let (x0, y0) = ((tx as f64 * sc) as usize, (ty as f64 * sc) as usize);
                let (x1, y1) = (
                    (((tx + 1) as f64 * sc) as usize).max(x0 + 1),
                    (((ty + 1) as f64 * sc) as usize).max(y0 + 1),
                );
                if x1 > w || y1 > h {
                    continue;
                }
                let mut acc = 0u32;
                for y in y0..y1 {
                    for x in x0..x1 {
                        acc += px[y * w + x] as u32;
                    }
                }
                sheet[(oy + ty) * cols * tile + ox + tx] = (acc / ((x1 - x0) * (y1 - y0)) as u32) as u8;
            }
        }
        // 1:1 crop around the touch point.
        let it = ((plan.truth.t_touch_s) * fps).round() as usize;
        let ft = &plan.frames[it.min(plan.frames.len() - 1)];
        let f = r.frame(ft.frame);
        let px = gray8(&f, look.bit_depth);
        let cx0 = (ft.x_px as i64 - cw as i64 / 2).clamp(0, (w - cw.min(w)) as i64) as usize;
        let cy0 = ((ft.y_px + ft.r_px) as i64 - 70).clamp(0, (h - ch.min(h)) as i64) as usize;
        let (ex, ey) = ((k % cols) * cw, (k / cols) * ch);
        for y in 0..ch.min(h) {
            for x in 0..cw.min(w) {
                edges[(ey + y) * cols * cw + ex + x] = px[(cy0 + y) * w + cx0 + x];
            }
        }
        println!(
            "tile {} ({}): {} | {}x{}, r {:.0} px, noise {:.1} DN, {}-bit {}",
            k + 1,
            plan.truth.clip,
            look.families().join(" "),
            w,
            h,
            look.ball_radius_px,
            look.read_noise_dn,
            look.bit_depth,
            look.naming
        );
    }
    let save = |name: &str, w: usize, h: usize, v: Vec<u8>| {
        let f = RenderedFrame {
            width: w as u32,
            height: h as u32,
            pixels: Pixels::Gray8(v),
        };
        let path = out.join(name);
        std::fs::write(&path, encode(&f, bouncelab_render::Format::Png).unwrap()).unwrap();
        println!("{}", path.display());
    };
    save("render-looks.png", cols * tile, rows * tile, sheet);
    save("render-looks-edges.png", cols * cw, rows * ch, edges);
    let all: BTreeSet<String> = plans.iter().flat_map(tags).collect();
    println!(
        "the sheet shows {} of the {} tags and item kinds drawn in {preset}; not shown: {:?}",
        shown.len(),
        all.len(),
        all.difference(&shown).collect::<Vec<_>>()
    );
}
