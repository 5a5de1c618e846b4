//! The picture inside a border that holds no image: a frame padded by repeating its edge, as a converter
//! or an editor pads a picture to a larger size.
//!
//! Such a border is not the scene: its repeated rows and columns are straight, noiseless copies of the
//! picture's edge, so the surface band's edge runs on through them as a perfect step whose height is the
//! edge column's (a line fitted there takes that column's tilt), and their blocks tell no sensor noise. A
//! sensor's noise never repeats a row or a column of a picture exactly, so an outer row or column that is
//! the same as the next one in is border; the picture is what is left. A row or column whose every pixel
//! is at the frame's lowest or highest level is kept: it may be a letterbox, but it may as well be a
//! clipped band or a backlit field the ball will cross, and it puts no false step or tilt in the picture.

use crate::plane::{Pixel, Plane};

/// The picture inside `img`'s border: `(x, y, width, height)` px, the whole frame when it has no border.
/// Outer columns are taken off while each equals the next one in and holds a pixel between the frame's
/// lowest and highest levels, then outer rows likewise (over the columns left). Only meaningful on a frame
/// with sensor noise: a noiseless render's smooth margins could be taken for a border. Cost: at most three
/// reads of the frame.
pub fn picture_box<P: Pixel>(img: &Plane<P>) -> (usize, usize, usize, usize) {
    let (w, h) = (img.width, img.height);
    let px = |x: usize, y: usize| img.data[y * w + x].level();
    let (lo, hi) = img.data.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
        let v = p.level();
        (lo.min(v), hi.max(v))
    });
    let unclipped = |v: f32| v > lo && v < hi;
    let column_is_border = |x: usize, inner: usize, ys: (usize, usize)| {
        (ys.0..ys.1).all(|y| px(x, y) == px(inner, y)) && (ys.0..ys.1).any(|y| unclipped(px(x, y)))
    };
    let row_is_border = |y: usize, inner: usize, xs: (usize, usize)| {
        (xs.0..xs.1).all(|x| px(x, y) == px(x, inner)) && (xs.0..xs.1).any(|x| unclipped(px(x, y)))
    };
    let (mut x0, mut x1) = (0, w);
    while x1 - x0 > 2 && column_is_border(x0, x0 + 1, (0, h)) {
        x0 += 1;
    }
    while x1 - x0 > 2 && column_is_border(x1 - 1, x1 - 2, (0, h)) {
        x1 -= 1;
    }
    let (mut y0, mut y1) = (0, h);
    while y1 - y0 > 2 && row_is_border(y0, y0 + 1, (x0, x1)) {
        y0 += 1;
    }
    while y1 - y0 > 2 && row_is_border(y1 - 1, y1 - 2, (x0, x1)) {
        y1 -= 1;
    }
    (x0, y0, x1 - x0, y1 - y0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_testkit::Rng;

    /// A `w` × `h` picture of noise about 100 DN with a brighter band in its lower third.
    fn picture(w: usize, h: usize, seed: u64) -> Vec<u8> {
        let mut rng = Rng::new(seed);
        (0..w * h)
            .map(|i| {
                let base = if i / w > 2 * h / 3 { 160.0 } else { 100.0 };
                (base + 3.0 * rng.normal()).round() as u8
            })
            .collect()
    }

    #[test]
    fn a_picture_without_a_border_is_whole() {
        let img = picture(40, 30, 1);
        assert_eq!(picture_box(&Plane::new(&img, 40, 30)), (0, 0, 40, 30));
    }

    /// Padded by its edge on every side: the picture is found to the pixel.
    #[test]
    fn a_padded_border_is_taken_off() {
        let (w, h) = (40, 30);
        let inner = picture(w, h, 2);
        let (left, top, right, bottom) = (7, 5, 4, 3);
        let (pw, ph) = (w + left + right, h + top + bottom);
        let frame: Vec<u8> = (0..pw * ph)
            .map(|i| {
                let (x, y) = ((i % pw).clamp(left, left + w - 1), (i / pw).clamp(top, top + h - 1));
                inner[(y - top) * w + x - left]
            })
            .collect();
        assert_eq!(picture_box(&Plane::new(&frame, pw, ph)), (left, top, w, h));
    }

    /// A black letterbox on the left and rows clipped white at the bottom (a band overexposed) are kept:
    /// nothing tells them from the scene.
    #[test]
    fn letterboxes_and_clipped_rows_are_kept() {
        let (w, h) = (40, 30);
        let mut frame = picture(w, h, 3);
        for (i, v) in frame.iter_mut().enumerate() {
            if i % w < 6 {
                *v = 0;
            } else if i / w >= 26 {
                *v = 255;
            }
        }
        assert_eq!(picture_box(&Plane::new(&frame, w, h)), (0, 0, w, h));
    }
}
