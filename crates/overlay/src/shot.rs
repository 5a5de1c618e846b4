//! A shot's key frames chosen from its trajectory and drawn from its clip: what the `overlay` command's sheet
//! and the report's strip above each shot show.

use crate::{
    BallMark, ContactRule, Crop, KeyFrames, OverlayError, SheetLayout, ShotPhases, StripFrame, Style, SurfaceLine,
    key_frame_strip, key_frames_from_trajectory, phases_from_trajectory,
};
use bouncelab_frames::{Clip, PngDecoder};
use image::RgbImage;

/// The phases (when a contact is seen) and the key frames of a trajectory, with a sentence on where they came
/// from: with a line the ball reaches, the contact is where it is within the rule's margin of it; otherwise
/// the key frames lie around the lowest centre and the phases are unknown. Errors only if no frame has a
/// usable centre, or the line or a mark is malformed.
pub fn choose_key_frames(
    marks: &[BallMark],
    line: Option<&SurfaceLine>,
    rule: &ContactRule,
) -> Result<(Option<ShotPhases>, KeyFrames, String), OverlayError> {
    let why = match line {
        Some(l) => match phases_from_trajectory(marks, l, rule) {
            Ok(p) => {
                let how = "phases from the trajectory: contact while the ball reaches the surface line".to_string();
                return Ok((Some(p), p.key_frames(), how));
            }
            Err(e @ OverlayError::NoContact { .. }) => e.to_string(),
            Err(e) => return Err(e),
        },
        None => "no surface line was found".to_string(),
    };
    let k = key_frames_from_trajectory(marks, line, rule)?;
    Ok((
        None,
        k,
        format!("{why}: phases unknown; key frames around the lowest centre"),
    ))
}

/// A shot's key-frame strip drawn from its clip: the key frames of [`choose_key_frames`], each read from the
/// clip (only those: a handful of decodes), cropped around the ball and annotated, with a caption listing
/// them ("approach 96, touch 99, …"). Marks carry their phase when the phases are known.
///
/// Errors: no usable centre, a key frame missing from the clip or unreadable (naming it), a malformed mark.
/// Cost: ~5 frame decodes and ~3 ms of drawing.
pub fn shot_strip(
    clip: &Clip,
    marks: &[BallMark],
    line: Option<&SurfaceLine>,
    rule: &ContactRule,
    style: &Style,
) -> Result<(RgbImage, String), OverlayError> {
    let (phases, keys, _) = choose_key_frames(marks, line, rule)?;
    let placed = keys.placed();
    let mut read = Vec::with_capacity(placed.len());
    for (role, frame) in &placed {
        let pos = clip
            .files()
            .iter()
            .position(|f| f.index == *frame)
            .ok_or(OverlayError::FrameNotInClip { frame: *frame })?;
        let pixels = clip
            .read(pos, PngDecoder::default())
            .ok_or(OverlayError::FrameNotInClip { frame: *frame })?
            .map_err(|source| OverlayError::Read {
                frame: *frame,
                source: Box::new(source),
            })?
            .pixels;
        let mut mark = *marks
            .iter()
            .find(|m| m.frame == *frame)
            .ok_or(OverlayError::FrameNotInClip { frame: *frame })?;
        if let Some(p) = &phases {
            mark.phase = p.phase_of(mark.frame);
        }
        read.push((role.label(), pixels, mark));
    }
    let strip: Vec<StripFrame<'_>> = read
        .iter()
        .map(|(caption, pixels, mark)| StripFrame {
            pixels,
            mark: *mark,
            caption,
        })
        .collect();
    let image = key_frame_strip(&strip, line, &Crop::default(), style, &SheetLayout::default())?;
    let caption = placed
        .iter()
        .map(|(role, f)| format!("{} {f}", role.label().to_lowercase()))
        .collect::<Vec<_>>()
        .join(", ");
    Ok((image, caption))
}
