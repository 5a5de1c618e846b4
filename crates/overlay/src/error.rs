//! The crate's one error type.

/// What went wrong, naming the frame, field or size it is about.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OverlayError {
    /// A key frame the clip does not hold (a trajectory from another version of the clip).
    #[error("frame {frame} is not in the clip")]
    FrameNotInClip {
        /// Frame index.
        frame: u64,
    },
    /// A frame that could not be read back to draw it.
    #[error("reading frame {frame} to draw it: {source}")]
    Read {
        /// Frame index.
        frame: u64,
        /// Why.
        source: Box<bouncelab_frames::FramesError>,
    },
    /// A status name that is none of the tracker's.
    #[error("frame {frame}: unknown status `{name}` (expected ok, occluded, cut_by_border, absent or ambiguous)")]
    UnknownStatus {
        /// Frame index.
        frame: u64,
        /// The name given.
        name: String,
    },
    /// A measured frame whose centre or radius is not a finite number.
    #[error(
        "frame {frame}: {field} is {value}, not a finite number, though the status `{status}` says the ball was measured"
    )]
    NotFinite {
        /// Frame index.
        frame: u64,
        /// `x_px`, `y_px` or `r_px`.
        field: &'static str,
        /// The value given.
        value: f64,
        /// The frame's status name.
        status: &'static str,
    },
    /// A measured frame with a radius that is not positive.
    #[error("frame {frame}: radius {r_px} px must be positive")]
    BadRadius {
        /// Frame index.
        frame: u64,
        /// The radius given, px.
        r_px: f64,
    },
    /// A surface line with a coordinate or slope that is not a finite number.
    #[error("surface line: {field} is {value}, not a finite number")]
    BadLine {
        /// `x0`, `y0` or `slope`.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// A crop asked around a frame where the ball was not measured.
    #[error("frame {frame}: the ball was not measured (status `{status}`), so there is no centre to crop around")]
    NoCentre {
        /// Frame index.
        frame: u64,
        /// The frame's status name.
        status: &'static str,
    },
    /// A style value out of its range.
    #[error("style: {field} = {value} {why}")]
    BadStyle {
        /// The field.
        field: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// An output image larger than the limit (a guard against unbounded allocation).
    #[error("{what} would be {width}×{height} px, over the limit of {limit} pixels")]
    TooLarge {
        /// What was being made.
        what: &'static str,
        /// Width asked for, px.
        width: u64,
        /// Height asked for, px.
        height: u64,
        /// The limit, pixels.
        limit: u64,
    },
    /// A frame with no pixels.
    #[error("frame {frame}: the image is empty ({width}×{height} px)")]
    EmptyFrame {
        /// Frame index.
        frame: u64,
        /// Width, px.
        width: u32,
        /// Height, px.
        height: u32,
    },
    /// A contact sheet or strip with nothing in it.
    #[error("a contact sheet needs at least one tile")]
    EmptySheet,
    /// No frame of the trajectory has a measured ball.
    #[error("no frame of the {frames} given has a measured ball")]
    NoMeasuredFrames {
        /// Frames given.
        frames: usize,
    },
    /// The ball never comes within the margin of the surface line.
    #[error(
        "the ball comes no closer than {clearance_px:.2} px to the surface line (frame {frame}), so no contact is seen (margin {margin_px} px)"
    )]
    NoContact {
        /// Smallest clearance between the ball's lowest point and the line, px.
        clearance_px: f64,
        /// Frame where it is smallest.
        frame: u64,
        /// The contact margin used, px.
        margin_px: f64,
    },
    /// PNG encoding failed.
    #[error("encoding a PNG: {0}")]
    Png(#[from] image::ImageError),
}
