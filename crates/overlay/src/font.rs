//! A built-in 5×7 bitmap font for frame numbers, phase and status words, so no font file ships and no font
//! rasteriser is built. Upper-case letters, digits and a little punctuation; lower case is drawn as upper
//! case and anything else as `?`.

use image::{Rgb, RgbImage};
use imageproc::drawing::draw_filled_rect_mut;
use imageproc::rect::Rect;

/// Glyph width and height in font cells; one blank cell separates glyphs and lines.
pub const GLYPH_W: u32 = 5;
/// Glyph height in font cells.
pub const GLYPH_H: u32 = 7;

/// Each glyph: 7 rows of 5 cells, `#` on.
const GLYPHS: &[(char, [&str; 7])] = &[
    ('0', [" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### "]),
    ('1', ["  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "]),
    ('2', [" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####"]),
    ('3', ["#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### "]),
    ('4', ["   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # "]),
    ('5', ["#####", "#    ", "#### ", "    #", "    #", "#   #", " ### "]),
    ('6', ["  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### "]),
    ('7', ["#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   "]),
    ('8', [" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### "]),
    ('9', [" ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  "]),
    ('A', [" ### ", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"]),
    ('B', ["#### ", "#   #", "#   #", "#### ", "#   #", "#   #", "#### "]),
    ('C', [" ### ", "#   #", "#    ", "#    ", "#    ", "#   #", " ### "]),
    ('D', ["#### ", "#   #", "#   #", "#   #", "#   #", "#   #", "#### "]),
    ('E', ["#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#####"]),
    ('F', ["#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#    "]),
    ('G', [" ### ", "#   #", "#    ", "# ###", "#   #", "#   #", " ####"]),
    ('H', ["#   #", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"]),
    ('I', [" ### ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "]),
    ('J', ["  ###", "   # ", "   # ", "   # ", "   # ", "#  # ", " ##  "]),
    ('K', ["#   #", "#  # ", "# #  ", "##   ", "# #  ", "#  # ", "#   #"]),
    ('L', ["#    ", "#    ", "#    ", "#    ", "#    ", "#    ", "#####"]),
    ('M', ["#   #", "## ##", "# # #", "# # #", "#   #", "#   #", "#   #"]),
    ('N', ["#   #", "#   #", "##  #", "# # #", "#  ##", "#   #", "#   #"]),
    ('O', [" ### ", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "]),
    ('P', ["#### ", "#   #", "#   #", "#### ", "#    ", "#    ", "#    "]),
    ('Q', [" ### ", "#   #", "#   #", "#   #", "# # #", "#  # ", " ## #"]),
    ('R', ["#### ", "#   #", "#   #", "#### ", "# #  ", "#  # ", "#   #"]),
    ('S', [" ####", "#    ", "#    ", " ### ", "    #", "    #", "#### "]),
    ('T', ["#####", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  "]),
    ('U', ["#   #", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "]),
    ('V', ["#   #", "#   #", "#   #", "#   #", "#   #", " # # ", "  #  "]),
    ('W', ["#   #", "#   #", "#   #", "# # #", "# # #", "# # #", " # # "]),
    ('X', ["#   #", "#   #", " # # ", "  #  ", " # # ", "#   #", "#   #"]),
    ('Y', ["#   #", "#   #", " # # ", "  #  ", "  #  ", "  #  ", "  #  "]),
    ('Z', ["#####", "    #", "   # ", "  #  ", " #   ", "#    ", "#####"]),
    (' ', ["     ", "     ", "     ", "     ", "     ", "     ", "     "]),
    ('#', [" # # ", " # # ", "#####", " # # ", "#####", " # # ", " # # "]),
    ('-', ["     ", "     ", "     ", "#####", "     ", "     ", "     "]),
    ('_', ["     ", "     ", "     ", "     ", "     ", "     ", "#####"]),
    ('.', ["     ", "     ", "     ", "     ", "     ", " ##  ", " ##  "]),
    (',', ["     ", "     ", "     ", "     ", " ##  ", "  #  ", " #   "]),
    (':', ["     ", " ##  ", " ##  ", "     ", " ##  ", " ##  ", "     "]),
    ('/', ["    #", "    #", "   # ", "  #  ", " #   ", "#    ", "#    "]),
    ('(', ["   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # "]),
    (')', [" #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   "]),
    ('+', ["     ", "  #  ", "  #  ", "#####", "  #  ", "  #  ", "     "]),
    ('=', ["     ", "     ", "#####", "     ", "#####", "     ", "     "]),
    ('%', ["##   ", "##  #", "   # ", "  #  ", " #   ", "#  ##", "   ##"]),
    ('?', [" ### ", "#   #", "    #", "   # ", "  #  ", "     ", "  #  "]),
];

/// The rows of `c`'s glyph, as 5-bit masks (bit 4 = leftmost cell).
fn glyph(c: char) -> [u8; 7] {
    let c = c.to_ascii_uppercase();
    let rows = GLYPHS
        .iter()
        .find(|(g, _)| *g == c)
        .or_else(|| GLYPHS.iter().find(|(g, _)| *g == '?'))
        .map(|(_, rows)| rows)
        .expect("the font has `?`");
    rows.map(|row| row.bytes().fold(0u8, |acc, b| (acc << 1) | u8::from(b == b'#')))
}

/// Width and height in pixels of `text` drawn at `scale` pixels per font cell (one line; no trailing gap).
pub fn text_size(text: &str, scale: u32) -> (u32, u32) {
    let n = text.chars().count() as u32;
    let w = if n == 0 { 0 } else { n * (GLYPH_W + 1) - 1 };
    (w * scale, GLYPH_H * scale)
}

/// Draws `text` with its top-left corner at (x, y), each font cell a `scale`×`scale` square of `colour`
/// (drawn with imageproc's `draw_filled_rect_mut`), clipped to the image.
///
/// Cost: one rectangle per lit cell, about 15 per glyph: ~0.2 µs per character at scale 2.
pub fn draw_text(img: &mut RgbImage, x: i32, y: i32, text: &str, scale: u32, colour: Rgb<u8>) {
    let scale = scale.max(1);
    let step = ((GLYPH_W + 1) * scale) as i32;
    for (k, c) in text.chars().enumerate() {
        let gx = x + k as i32 * step;
        if gx >= img.width() as i32 {
            break;
        }
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..GLYPH_W {
                if bits & (1 << (GLYPH_W - 1 - col)) != 0 {
                    let rect = Rect::at(gx + (col * scale) as i32, y + row as i32 * scale as i32).of_size(scale, scale);
                    draw_filled_rect_mut(img, rect, colour);
                }
            }
        }
    }
}

/// Draws `text` on a filled box of `background` with a margin of one font cell, top-left corner at
/// (x, y); returns the box's size in pixels.
pub fn draw_label(
    img: &mut RgbImage,
    x: i32,
    y: i32,
    text: &str,
    scale: u32,
    colour: Rgb<u8>,
    background: Rgb<u8>,
) -> (u32, u32) {
    let scale = scale.max(1);
    let (w, h) = text_size(text, scale);
    let (bw, bh) = (w + 2 * scale, h + 2 * scale);
    draw_filled_rect_mut(img, Rect::at(x, y).of_size(bw, bh), background);
    draw_text(img, x + scale as i32, y + scale as i32, text, scale, colour);
    (bw, bh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_glyph_is_five_by_seven_and_distinct() {
        for (c, rows) in GLYPHS {
            assert!(rows.iter().all(|r| r.len() == 5), "{c}");
        }
        for (i, (a, ra)) in GLYPHS.iter().enumerate() {
            for (b, rb) in &GLYPHS[i + 1..] {
                assert_ne!(a, b, "duplicate entry");
                assert_ne!(ra, rb, "{a} and {b} look the same");
            }
        }
    }

    #[test]
    fn lower_case_is_upper_case_and_unknown_is_a_question_mark() {
        assert_eq!(glyph('k'), glyph('K'));
        assert_eq!(glyph('é'), glyph('?'));
        assert_ne!(glyph('1'), glyph('?'));
    }

    #[test]
    fn text_lights_exactly_the_glyph_cells_and_stays_in_its_box() {
        let bg = Rgb([0, 0, 0]);
        let fg = Rgb([255, 255, 255]);
        let mut img = RgbImage::from_pixel(40, 20, bg);
        draw_text(&mut img, 2, 3, "10", 2, fg);
        let (w, h) = text_size("10", 2);
        assert_eq!((w, h), (22, 14));
        let lit = img.pixels().filter(|p| **p == fg).count();
        let cells: u32 = ['1', '0']
            .iter()
            .map(|&c| glyph(c).iter().map(|r| r.count_ones()).sum::<u32>())
            .sum();
        assert_eq!(lit as u32, cells * 4);
        for (x, y, p) in img.enumerate_pixels() {
            if *p == fg {
                assert!((2..2 + w).contains(&x) && (3..3 + h).contains(&y), "({x}, {y}) outside");
            }
        }
        // The top row of `1` is its single centre cell.
        assert_eq!(*img.get_pixel(2 + 2 * 2, 3), fg);
        assert_eq!(*img.get_pixel(2, 3), bg);
    }

    #[test]
    fn text_past_the_border_is_clipped_not_a_panic() {
        let mut img = RgbImage::new(8, 8);
        draw_text(&mut img, -20, -3, "ABSENT 123", 3, Rgb([9, 9, 9]));
        draw_text(&mut img, 6, 6, "AMBIGUOUS", 1, Rgb([9, 9, 9]));
        assert_eq!(text_size("", 4), (0, 28));
    }
}
