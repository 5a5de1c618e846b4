//! The contact force over one impact as the fitted model predicts it (the paper's Figure 2): against time
//! from touch, and against the penetration (the loading and unloading paths, whose enclosed area is the
//! energy the contact dissipates).

use crate::data::ContactForce;
use crate::fmt::{esc, num, short};
use crate::html::Ctx;
use crate::svg::{Chart, Item, Key};

/// The figure.
pub(crate) fn render(ctx: &mut Ctx, f: &ContactForce) -> String {
    let (color, _) = ctx.style(&f.surface);
    let (n, id) = ctx.next_figure();
    let mut a = Chart::new(format!("{id}a"), 540.0, 330.0);
    a.title = "Contact force over time".into();
    a.x_label = "time since touch (ms)".into();
    a.y_label = "normal contact force P (N)".into();
    a.y_include.push(0.0);
    a.items.push(Item::Line {
        pts: f.samples.iter().map(|s| (s.t_s * 1e3, s.force_n)).collect(),
        color,
        width: 2.0,
        dash: false,
    });
    let mut b = Chart::new(format!("{id}b"), 540.0, 330.0);
    b.title = "Contact force against penetration".into();
    b.x_label = "penetration δ (mm)".into();
    b.y_label = "normal contact force P (N)".into();
    b.y_include.push(0.0);
    b.x_include.push(0.0);
    b.items.push(Item::Line {
        pts: f.samples.iter().map(|s| (s.delta_m * 1e3, s.force_n)).collect(),
        color,
        width: 2.0,
        dash: false,
    });
    b.legend.push((f.surface.clone(), Key::Line { color, dash: false }));
    let peak = f.samples.iter().map(|s| s.force_n).fold(f64::NEG_INFINITY, f64::max);
    let duration = f.samples.last().map_or(f64::NAN, |s| s.t_s);
    let caption = format!(
        "The normal contact force the fitted model predicts for shot {} on {} at {}° (|v<sub>n,in</sub>| = {} m/s; \
         {}), the paper's Figure 2: peak {} N, contact {} ms. Right: the same against the penetration; loading \
         runs up the upper path, unloading down the lower one, and the area between them is the energy the \
         contact dissipates.",
        esc(&f.clip),
        esc(&f.surface),
        short(f.angle_deg, 3),
        num(f.v_in_n_m_s, 4),
        esc(&f.why),
        num(peak, 4),
        num(duration * 1e3, 4)
    );
    ctx.figure(n, &[a, b], &caption)
}
