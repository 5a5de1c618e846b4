//! The picture inside a border that holds no image: a frame padded by repeating its edge, as a converter
//! or an editor pads a picture to a larger size, or letterboxed by dark bars.
//!
//! Such a border is not the scene. Repeated rows and columns are straight, noiseless copies of the
//! picture's edge, so the surface band's edge runs on through them as a perfect step whose height is the
//! edge column's (a line fitted there takes that column's tilt), and their blocks tell no sensor noise. A
//! letterbox bar's edge is a perfectly straight step across the frame, stronger than most surface bands'
//! tops, which the line finder takes for the surface. A sensor's noise never repeats a row or a column of
//! a picture exactly, so an outer row or column that is the same as the next one in is border. A row or
//! column of one level throughout may be a bar, but it may as well be a clipped band or a backlit field
//! the ball will cross: it is border only when it keeps that level in every frame looked at through the
//! clip ([`SteadyLines`]), that level is below the frame's highest (a saturated backlit field stays
//! picture however still it is: the ball may enter it), and a bar as wide faces it across the frame (a
//! dark tape clipped black lies on one side, and its top edge must stay in the picture).
//! `docs/accuracy.md` ("Letterbox bars") has the clips behind each rule. The picture is what is left.

use crate::plane::{Pixel, Plane};

/// The rows and columns of a clip's frames that are one level throughout, each with that level, in every
/// frame looked at: what a letterbox or pillarbox bar is, as nothing in the clip crosses it.
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyLines {
    rows: Vec<Option<f32>>,
    columns: Vec<Option<f32>>,
}

impl SteadyLines {
    /// The rows and columns of `img` that are one level throughout. Cost: two reads of the frame.
    pub fn of<P: Pixel>(img: &Plane<P>) -> SteadyLines {
        let (w, h) = (img.width, img.height);
        let px = |x: usize, y: usize| img.data[y * w + x].level();
        SteadyLines {
            rows: (0..h).map(|y| one_level((0..w).map(|x| px(x, y)))).collect(),
            columns: (0..w).map(|x| one_level((0..h).map(|y| px(x, y)))).collect(),
        }
    }

    /// Keeps only the rows and columns that `other` (a later frame) has at the same level; none when its
    /// size differs.
    pub fn and(&mut self, other: &SteadyLines) {
        let keep = |a: &mut Vec<Option<f32>>, b: &[Option<f32>]| {
            if a.len() != b.len() {
                a.fill(None);
            }
            for (a, b) in a.iter_mut().zip(b) {
                if *a != *b {
                    *a = None;
                }
            }
        };
        keep(&mut self.rows, &other.rows);
        keep(&mut self.columns, &other.columns);
    }

    /// Whether the first and the last row, or the first and the last column, are each one level
    /// throughout: only then can the frame have a pair of bars ([`picture_box`]).
    pub fn may_have_bars(&self) -> bool {
        let ends = |v: &[Option<f32>]| v.first().is_some_and(Option::is_some) && v.last().is_some_and(Option::is_some);
        ends(&self.rows) || ends(&self.columns)
    }

    /// Whether row `y` is one level throughout, below `highest`, in every frame looked at.
    fn dark_row(&self, y: usize, highest: f32) -> bool {
        self.rows.get(y).copied().flatten().is_some_and(|v| v < highest)
    }

    /// Whether column `x` is one level throughout, below `highest`, in every frame looked at.
    fn dark_column(&self, x: usize, highest: f32) -> bool {
        self.columns.get(x).copied().flatten().is_some_and(|v| v < highest)
    }
}

/// The one level of `levels`, if they are all the same.
fn one_level(mut levels: impl Iterator<Item = f32>) -> Option<f32> {
    let first = levels.next()?;
    levels.all(|v| v == first).then_some(first)
}

/// The picture inside `img`'s border: `(x, y, width, height)` px, the whole frame when it has no border.
/// First a pair of dark bars is taken off each way: bars on opposite sides, as wide as each other to a
/// pixel, of rows (columns) each one level below the frame's highest throughout in every frame of
/// `steady` (the lines of frames looked at through the clip; `None` when only this frame is known). A
/// converter centres the picture between its bars; a band or a shadow clipped black lies on one side,
/// and its edge must stay in the picture. Then outer columns are taken off while each equals the next
/// one in and holds a pixel between the frame's lowest and highest levels, and outer rows likewise (over
/// the columns left). Only meaningful on a frame with sensor noise: a noiseless render's smooth margins
/// could be taken for a border. Cost: at most three reads of the frame.
pub fn picture_box<P: Pixel>(img: &Plane<P>, steady: Option<&SteadyLines>) -> (usize, usize, usize, usize) {
    let (w, h) = (img.width, img.height);
    let px = |x: usize, y: usize| img.data[y * w + x].level();
    let (lo, hi) = img.data.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
        let v = p.level();
        (lo.min(v), hi.max(v))
    });
    let (left, right) = steady.map_or((0, 0), |s| paired_bars(w, |x| s.dark_column(x, hi)));
    let (top, bottom) = steady.map_or((0, 0), |s| paired_bars(h, |y| s.dark_row(y, hi)));
    let unclipped = |v: f32| v > lo && v < hi;
    let column_repeats = |x: usize, inner: usize, ys: (usize, usize)| {
        (ys.0..ys.1).all(|y| px(x, y) == px(inner, y)) && (ys.0..ys.1).any(|y| unclipped(px(x, y)))
    };
    let row_repeats = |y: usize, inner: usize, xs: (usize, usize)| {
        (xs.0..xs.1).all(|x| px(x, y) == px(x, inner)) && (xs.0..xs.1).any(|x| unclipped(px(x, y)))
    };
    let (mut x0, mut x1) = (left, w - right);
    while x1 - x0 > 2 && column_repeats(x0, x0 + 1, (0, h)) {
        x0 += 1;
    }
    while x1 - x0 > 2 && column_repeats(x1 - 1, x1 - 2, (0, h)) {
        x1 -= 1;
    }
    let (mut y0, mut y1) = (top, h - bottom);
    while y1 - y0 > 2 && row_repeats(y0, y0 + 1, (x0, x1)) {
        y0 += 1;
    }
    while y1 - y0 > 2 && row_repeats(y1 - 1, y1 - 2, (x0, x1)) {
        y1 -= 1;
    }
    (x0, y0, x1 - x0, y1 - y0)
}

/// The widths of the bars at the two ends of `n` lines (`bar(i)` whether line `i` is a bar's), when both
/// ends have one, within a line of each other, and they leave more than two lines between them; (0, 0)
/// otherwise.
fn paired_bars(n: usize, bar: impl Fn(usize) -> bool) -> (usize, usize) {
    let first = (0..n).take_while(|&i| bar(i)).count();
    let last = (0..n).rev().take_while(|&i| bar(i)).count();
    if first > 0 && last > 0 && first.abs_diff(last) <= 1 && first + last + 2 < n {
        (first, last)
    } else {
        (0, 0)
    }
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
        assert_eq!(picture_box(&Plane::new(&img, 40, 30), None), (0, 0, 40, 30));
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
        assert_eq!(picture_box(&Plane::new(&frame, pw, ph), None), (left, top, w, h));
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
        assert_eq!(picture_box(&Plane::new(&frame, w, h), None), (0, 0, w, h));
    }

    /// `picture(w, h, seed)` with rows `top` and `bottom` from the top and bottom edges set to `bar`.
    fn barred(w: usize, h: usize, seed: u64, (top, bottom): (usize, usize), bar: u8) -> Vec<u8> {
        let mut frame = picture(w, h, seed);
        for (i, v) in frame.iter_mut().enumerate() {
            if i / w < top || i / w >= h - bottom {
                *v = bar;
            }
        }
        frame
    }

    /// Paired bars (4 and 5 rows) of one level below the highest that keep it in every frame looked at are
    /// taken off; rows saturated in every frame (a backlit field) are kept.
    #[test]
    fn steady_dark_bars_are_taken_off() {
        let (w, h) = (40, 30);
        for bar in [0, 16, 128, 255] {
            let frames: Vec<Vec<u8>> = (0..3).map(|k| barred(w, h, 10 + k, (4, 5), bar)).collect();
            let steady = steady_of(&frames, w, h);
            assert!(steady.may_have_bars());
            let first = Plane::new(&frames[0], w, h);
            let picture = if bar == 255 { (0, 0, w, h) } else { (0, 4, w, h - 9) };
            assert_eq!(picture_box(&first, Some(&steady)), picture, "bar at {bar}");
            if bar == 0 || bar == 255 {
                assert_eq!(
                    picture_box(&first, None),
                    (0, 0, w, h),
                    "one frame cannot tell a bar (at {bar})"
                );
            }
        }
    }

    /// `frames`' steady lines.
    fn steady_of(frames: &[Vec<u8>], w: usize, h: usize) -> SteadyLines {
        let mut steady = SteadyLines::of(&Plane::new(&frames[0], w, h));
        for f in &frames[1..] {
            steady.and(&SteadyLines::of(&Plane::new(f, w, h)));
        }
        steady
    }

    /// A dark band clipped black on one side (a tape below the picture's middle), or facing a bar of
    /// another width, is kept; pillarbox bars (3 and 3 columns) are taken off.
    #[test]
    fn only_paired_dark_bars_are_border() {
        let (w, h) = (40, 30);
        for (top, bottom) in [(0, 6), (2, 6), (6, 0)] {
            let frames: Vec<Vec<u8>> = (0..3).map(|k| barred(w, h, 30 + k, (top, bottom), 0)).collect();
            let steady = steady_of(&frames, w, h);
            assert_eq!(
                picture_box(&Plane::new(&frames[0], w, h), Some(&steady)),
                (0, 0, w, h),
                "bars of {top} and {bottom} rows"
            );
        }
        let pillarboxed: Vec<Vec<u8>> = (0..3)
            .map(|k| {
                let mut f = picture(w, h, 40 + k);
                for (i, v) in f.iter_mut().enumerate() {
                    if i % w < 3 || i % w >= w - 3 {
                        *v = 0;
                    }
                }
                f
            })
            .collect();
        let steady = steady_of(&pillarboxed, w, h);
        assert_eq!(
            picture_box(&Plane::new(&pillarboxed[0], w, h), Some(&steady)),
            (3, 0, w - 6, h)
        );
    }

    /// Rows clipped black in the first frame that something brighter crosses later (a shadow the ball
    /// falls through) are kept, as is a bar whose level changes.
    #[test]
    fn clipped_rows_something_crosses_are_kept() {
        let (w, h) = (40, 30);
        let first = barred(w, h, 20, (6, 6), 0);
        let mut crossed = barred(w, h, 21, (6, 6), 0);
        for y in h - 6..h {
            for x in 10..16 {
                crossed[y * w + x] = 140;
            }
        }
        let steady = steady_of(&[first.clone(), crossed], w, h);
        assert_eq!(picture_box(&Plane::new(&first, w, h), Some(&steady)), (0, 0, w, h));

        let mut steady = steady_of(&[first.clone(), barred(w, h, 22, (6, 6), 1)], w, h);
        assert_eq!(picture_box(&Plane::new(&first, w, h), Some(&steady)), (0, 0, w, h));
        steady.and(&SteadyLines::of(&Plane::new(&picture(w + 1, h, 23), w + 1, h)));
        assert!(!steady.may_have_bars(), "a frame of another size keeps nothing");
    }
}
