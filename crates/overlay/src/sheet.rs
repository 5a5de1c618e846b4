//! Contact sheets: pictures in a grid, each under its caption, with a legend of the colours; and the
//! key-frame strip of one shot.

use crate::annotate::{Crop, Style, crop_at};
use crate::error::OverlayError;
use crate::font::{GLYPH_H, draw_text, text_size};
use crate::marks::{BallMark, Phase, Status, SurfaceLine, phase_colour, status_colour, status_label};
use crate::view::MAX_CANVAS_PIXELS;
use bouncelab_frames::GrayPixels;
use image::{Rgb, RgbImage};
use imageproc::drawing::draw_filled_rect_mut;
use imageproc::rect::Rect;

/// One picture of a sheet and the caption above it.
#[derive(Debug, Clone, PartialEq)]
pub struct Tile {
    /// The picture.
    pub image: RgbImage,
    /// Drawn above it (upper case; other characters as `?`).
    pub caption: String,
}

/// How a sheet is laid out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetLayout {
    /// Tiles per row (at least 1).
    pub columns: u32,
    /// Space between and around tiles, px.
    pub gap_px: u32,
    /// Px per font cell of captions and legend (at least 1).
    pub font_scale: u32,
    /// Whether a legend of the colours is drawn under the tiles.
    pub legend: bool,
}

impl Default for SheetLayout {
    fn default() -> Self {
        SheetLayout {
            columns: 5,
            gap_px: 6,
            font_scale: 1,
            legend: true,
        }
    }
}

const SHEET_BG: Rgb<u8> = Rgb([24, 24, 24]);
const CAPTION: Rgb<u8> = Rgb([235, 235, 235]);

/// A legend entry: a colour swatch (or none) and its meaning.
type LegendItem = (Option<Rgb<u8>>, String);

/// A placed legend entry: its position in the legend, px, and the entry.
type PlacedItem = (i32, i32, Option<Rgb<u8>>, String);

/// The legend's entries.
fn legend_items() -> Vec<LegendItem> {
    let mut items: Vec<LegendItem> = vec![(None, "CIRCLE:".into())];
    for p in [Phase::FlightIn, Phase::Contact, Phase::FlightOut] {
        items.push((Some(phase_colour(p)), p.name().replace('_', " ")));
    }
    items.push((None, "(DASHED: FIT TO PART OF THE RIM)".into()));
    items.push((Some(SurfaceLine::colour()), "SURFACE LINE".into()));
    items.push((None, "STATUS:".into()));
    for s in Status::ALL {
        items.push((Some(status_colour(s)), status_label(s).into()));
    }
    items
}

/// Lays the legend out in lines no wider than `width`; returns each item's position and the height used.
fn legend_layout(width: u32, scale: u32) -> (Vec<PlacedItem>, u32) {
    let line_h = (GLYPH_H + 3) * scale;
    let gap = 6 * scale;
    let (mut x, mut y) = (0u32, 0u32);
    let mut placed = Vec::new();
    for (swatch, text) in legend_items() {
        let sw = if swatch.is_some() { GLYPH_H * scale + scale } else { 0 };
        let w = sw + text_size(&text, scale).0;
        if x > 0 && x + w > width {
            x = 0;
            y += line_h;
        }
        placed.push((x as i32, y as i32, swatch, text));
        x += w + gap;
    }
    (placed, y + line_h)
}

/// Tiles in a grid of `layout.columns` columns, each under its caption, on a dark background, with an
/// optional legend of the colours under them. Tiles of different sizes get cells of the largest size.
///
/// Errors: no tiles, a zero column count or font scale, or a sheet over the size limit.
///
/// Cost: one copy of every tile plus the captions and legend, small beside making the tiles.
pub fn contact_sheet(tiles: &[Tile], layout: &SheetLayout) -> Result<RgbImage, OverlayError> {
    if tiles.is_empty() {
        return Err(OverlayError::EmptySheet);
    }
    for (field, v) in [("columns", layout.columns), ("font_scale", layout.font_scale)] {
        if v == 0 {
            return Err(OverlayError::BadStyle {
                field,
                value: 0.0,
                why: "must be at least 1",
            });
        }
    }
    let scale = layout.font_scale.min(16);
    let gap = u64::from(layout.gap_px);
    let cell_w = tiles.iter().map(|t| t.image.width()).max().unwrap_or(0);
    let cell_h = tiles.iter().map(|t| t.image.height()).max().unwrap_or(0);
    let caption_h = u64::from((GLYPH_H + 2) * scale);
    let cols = u64::from(layout.columns).min(tiles.len() as u64);
    let rows = (tiles.len() as u64).div_ceil(cols);
    let width = gap + cols * (u64::from(cell_w) + gap);
    let grid_h = gap + rows * (caption_h + u64::from(cell_h) + gap);
    let too_large = |height: u64| OverlayError::TooLarge {
        what: "a contact sheet",
        width,
        height,
        limit: MAX_CANVAS_PIXELS,
    };
    if width * grid_h > MAX_CANVAS_PIXELS || width > u64::from(u32::MAX) {
        return Err(too_large(grid_h));
    }
    let legend = layout
        .legend
        .then(|| legend_layout(width.saturating_sub(2 * gap) as u32, scale));
    let height = grid_h + legend.as_ref().map_or(0, |(_, h)| u64::from(*h) + gap);
    if width * height > MAX_CANVAS_PIXELS {
        return Err(too_large(height));
    }
    let mut sheet = RgbImage::from_pixel(width as u32, height as u32, SHEET_BG);
    for (k, tile) in tiles.iter().enumerate() {
        let (c, r) = (k as u64 % cols, k as u64 / cols);
        let x = gap + c * (u64::from(cell_w) + gap);
        let y = gap + r * (caption_h + u64::from(cell_h) + gap);
        draw_text(&mut sheet, x as i32, y as i32, &tile.caption, scale, CAPTION);
        image::imageops::replace(&mut sheet, &tile.image, x as i64, (y + caption_h) as i64);
    }
    if let Some((items, _)) = legend {
        let (x0, y0) = (gap as i32, grid_h as i32);
        for (x, y, swatch, text) in items {
            let mut tx = x0 + x;
            if let Some(colour) = swatch {
                let side = GLYPH_H * scale;
                draw_filled_rect_mut(&mut sheet, Rect::at(tx, y0 + y).of_size(side, side), colour);
                tx += (side + scale) as i32;
            }
            draw_text(&mut sheet, tx, y0 + y, &text, scale, CAPTION);
        }
    }
    Ok(sheet)
}

/// One frame of a strip: its pixels, its ball and the caption over its tile.
#[derive(Debug, Clone, Copy)]
pub struct StripFrame<'a> {
    /// The frame's pixels.
    pub pixels: &'a GrayPixels,
    /// Its ball and phase.
    pub mark: BallMark,
    /// Drawn over its tile (e.g. a [`KeyRole`](crate::KeyRole) label).
    pub caption: &'a str,
}

/// A row of crops around the ball, one per frame, at one magnification (the median radius of the measured
/// frames, `crop.radii` radii on a side), each annotated and captioned; the colours' legend under them.
/// A frame where the ball was not measured is cropped where the nearest frame of the strip saw it, so the
/// tile shows the empty place and its red status.
///
/// Errors: no frames, or no frame with a measured ball; a mark or style that the crop refuses.
///
/// Cost: one crop per frame plus the sheet: ~3 ms for five 160 px tiles.
pub fn key_frame_strip(
    frames: &[StripFrame<'_>],
    line: Option<&SurfaceLine>,
    crop: &Crop,
    style: &Style,
    layout: &SheetLayout,
) -> Result<RgbImage, OverlayError> {
    if frames.is_empty() {
        return Err(OverlayError::EmptySheet);
    }
    let mut circles = Vec::with_capacity(frames.len());
    for f in frames {
        circles.push(f.mark.circle()?);
    }
    let mut radii: Vec<f64> = circles.iter().flatten().map(|c| c.2).collect();
    if radii.is_empty() {
        return Err(OverlayError::NoMeasuredFrames { frames: frames.len() });
    }
    radii.sort_by(f64::total_cmp);
    let radius = radii[radii.len() / 2];
    let mut tiles = Vec::with_capacity(frames.len());
    for (k, f) in frames.iter().enumerate() {
        let (cx, cy) = match circles[k] {
            Some((x, y, _)) => (x, y),
            // At least one circle exists (checked above), so `nearest` finds one.
            None => (0..circles.len())
                .filter_map(|j| circles[j].map(|c| (k.abs_diff(j), c)))
                .min_by_key(|(d, _)| *d)
                .map_or((f64::NAN, f64::NAN), |(_, c)| (c.0, c.1)),
        };
        let image = crop_at(f.pixels, cx, cy, radius, &f.mark, line, crop, style)?;
        tiles.push(Tile {
            image,
            caption: f.caption.to_string(),
        });
    }
    let layout = SheetLayout {
        columns: layout.columns.max(1).min(frames.len() as u32),
        ..*layout
    };
    contact_sheet(&tiles, &layout)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{GrayImage, Luma};

    fn tile(w: u32, h: u32, v: u8, caption: &str) -> Tile {
        Tile {
            image: RgbImage::from_pixel(w, h, Rgb([v, v, v])),
            caption: caption.into(),
        }
    }

    #[test]
    fn tiles_land_in_their_cells_under_their_captions() {
        let tiles: Vec<_> = (0..7).map(|k| tile(20, 10, 100 + k as u8, "T")).collect();
        let layout = SheetLayout {
            columns: 3,
            gap_px: 2,
            font_scale: 1,
            legend: false,
        };
        let s = contact_sheet(&tiles, &layout).unwrap();
        // 3 columns × (20 + 2) + 2; 3 rows × (caption 9 + 10 + 2) + 2.
        assert_eq!(s.dimensions(), (68, 65));
        for k in 0..7u32 {
            let (c, r) = (k % 3, k / 3);
            let (x, y) = (2 + c * 22, 2 + r * 21 + 9);
            assert_eq!(s.get_pixel(x, y).0[0], 100 + k as u8, "tile {k}");
            assert_eq!(s.get_pixel(x + 19, y + 9).0[0], 100 + k as u8, "tile {k}");
        }
        assert_eq!(*s.get_pixel(2 + 2 * 22, 2 + 2 * 21 + 9), SHEET_BG, "no eighth tile");
    }

    #[test]
    fn the_legend_wraps_inside_the_sheet() {
        let narrow = contact_sheet(&[tile(60, 60, 0, "X")], &SheetLayout::default()).unwrap();
        let wide = contact_sheet(&vec![tile(160, 60, 0, "X"); 5], &SheetLayout::default()).unwrap();
        let plain = contact_sheet(
            &[tile(60, 60, 0, "X")],
            &SheetLayout {
                legend: false,
                ..SheetLayout::default()
            },
        )
        .unwrap();
        assert!(narrow.height() > plain.height() + 3 * (GLYPH_H + 3));
        // The whole legend fits on one line under five 160 px tiles.
        assert_eq!(wide.height(), plain.height() + GLYPH_H + 3 + 6);
        // Every phase colour appears as a swatch.
        for p in [Phase::FlightIn, Phase::Contact, Phase::FlightOut] {
            assert!(narrow.pixels().any(|px| *px == phase_colour(p)), "{p:?}");
        }
    }

    #[test]
    fn empty_or_huge_sheets_are_errors() {
        assert!(matches!(
            contact_sheet(&[], &SheetLayout::default()),
            Err(OverlayError::EmptySheet)
        ));
        let zero = SheetLayout {
            columns: 0,
            ..SheetLayout::default()
        };
        assert!(contact_sheet(&[tile(4, 4, 0, "")], &zero).is_err());
        let many = vec![tile(4000, 4000, 0, ""); 5];
        assert!(matches!(
            contact_sheet(&many, &SheetLayout::default()),
            Err(OverlayError::TooLarge { .. })
        ));
    }

    #[test]
    fn a_strip_crops_every_frame_at_one_magnification() {
        let img = GrayPixels::U8(GrayImage::from_fn(120, 80, |x, y| {
            let d = (f64::from(x) - 60.0).hypot(f64::from(y) - 40.0);
            Luma([if d < 15.0 { 220 } else { 40 }])
        }));
        let m = |frame, r, status| BallMark {
            frame,
            x_px: 60.0,
            y_px: 40.0,
            r_px: r,
            status,
            phase: Phase::Contact,
        };
        let absent = BallMark {
            x_px: f64::NAN,
            ..m(3, f64::NAN, Status::Absent)
        };
        let frames = [
            StripFrame {
                pixels: &img,
                mark: m(1, 15.0, Status::Ok),
                caption: "A",
            },
            StripFrame {
                pixels: &img,
                mark: m(2, 14.0, Status::Occluded),
                caption: "B",
            },
            StripFrame {
                pixels: &img,
                mark: absent,
                caption: "C",
            },
        ];
        let crop = Crop {
            size_px: 90,
            radii: 3.0,
        };
        let style = Style {
            font_scale: Some(0),
            ..Style::default()
        };
        let layout = SheetLayout {
            legend: false,
            ..SheetLayout::default()
        };
        let s = key_frame_strip(&frames, None, &crop, &style, &layout).unwrap();
        assert_eq!(s.width(), 6 + 3 * (90 + 6));
        // The absent frame's tile is centred where its neighbour saw the ball, and bordered in red.
        let (x, y) = (6 + 2 * 96, 6 + 9);
        assert_eq!(*s.get_pixel(x + 45, y + 45), Rgb([220, 220, 220]));
        assert_eq!(*s.get_pixel(x + 45, y + 1), status_colour(Status::Absent));
        let none = [StripFrame {
            pixels: &img,
            mark: absent,
            caption: "C",
        }];
        assert!(matches!(
            key_frame_strip(&none, None, &crop, &style, &layout),
            Err(OverlayError::NoMeasuredFrames { frames: 1 })
        ));
    }
}
