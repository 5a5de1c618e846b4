//! The five frames that show an impact — approach, touch, maximum compression, separation, leave — from a
//! shot's phases, or from its trajectory alone.

use crate::error::OverlayError;
use crate::marks::{BallMark, Phase, Status, SurfaceLine};

/// A shot's phase boundaries as frame indices, as the estimate gives them (`PhaseFrames`: the incoming
/// flight's last frame, the contact's first and last, the outgoing flight's first) plus the deepest frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShotPhases {
    /// Last frame of the incoming flight, if the clip has one.
    pub flight_in_last: Option<u64>,
    /// First frame in contact.
    pub contact_first: u64,
    /// Frame of maximum compression (the lowest centre).
    pub deepest: u64,
    /// Last frame in contact.
    pub contact_last: u64,
    /// First frame of the outgoing flight, if the clip has one.
    pub flight_out_first: Option<u64>,
}

impl ShotPhases {
    /// The phase of `frame`: before the contact's first frame flight in, through its last contact, after
    /// it flight out.
    pub fn phase_of(&self, frame: u64) -> Phase {
        Phase::of_frame(frame, self.contact_first, self.contact_last)
    }

    /// The key frames these phases define.
    pub fn key_frames(&self) -> KeyFrames {
        KeyFrames {
            approach: self.flight_in_last,
            touch: Some(self.contact_first),
            deepest: self.deepest,
            separation: Some(self.contact_last),
            leave: self.flight_out_first,
        }
    }
}

/// Which moment of the impact a key frame shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum KeyRole {
    /// The incoming flight's last frame.
    Approach,
    /// The contact's first frame.
    Touch,
    /// Maximum compression.
    Deepest,
    /// The contact's last frame.
    Separation,
    /// The outgoing flight's first frame.
    Leave,
}

impl KeyRole {
    /// The caption drawn over its tile.
    pub fn label(self) -> &'static str {
        match self {
            KeyRole::Approach => "APPROACH",
            KeyRole::Touch => "TOUCH",
            KeyRole::Deepest => "MAX COMPRESSION",
            KeyRole::Separation => "SEPARATION",
            KeyRole::Leave => "LEAVE",
        }
    }
}

/// The key frames of one shot, as frame indices; a role the data cannot place is `None`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KeyFrames {
    /// The incoming flight's last frame.
    pub approach: Option<u64>,
    /// The contact's first frame.
    pub touch: Option<u64>,
    /// Maximum compression (the lowest centre).
    pub deepest: u64,
    /// The contact's last frame.
    pub separation: Option<u64>,
    /// The outgoing flight's first frame.
    pub leave: Option<u64>,
}

impl KeyFrames {
    /// The roles that are placed, in time order, with their frames.
    pub fn placed(&self) -> Vec<(KeyRole, u64)> {
        [
            (KeyRole::Approach, self.approach),
            (KeyRole::Touch, self.touch),
            (KeyRole::Deepest, Some(self.deepest)),
            (KeyRole::Separation, self.separation),
            (KeyRole::Leave, self.leave),
        ]
        .into_iter()
        .filter_map(|(role, f)| f.map(|f| (role, f)))
        .collect()
    }
}

/// How contact is told from the trajectory (`docs/overlay.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRule {
    /// A frame is in contact when the ball's lowest point (centre + radius) is within this of the surface
    /// line or below it, px. Default 0: the ball reaches the line. (The estimate uses 1 px to keep frames
    /// near the surface out of its flight fits, so its contact phase starts a few frames earlier; on the
    /// rendered `smoke` clips margin 0 puts touch and separation within one frame of the truth.)
    pub margin_px: f64,
    /// The ball's radius, px (the clip's flight radius, e.g. the scale's `radius_px`); `None` takes the
    /// median radius of the frames measured with status `ok`.
    pub radius_px: Option<f64>,
}

impl Default for ContactRule {
    fn default() -> Self {
        ContactRule {
            margin_px: 0.0,
            radius_px: None,
        }
    }
}

/// The frames the phases are found on: centres seen well enough to place the ball against the line (`ok`
/// and `occluded`; a ball cut by the border is left out, as the estimate does).
fn usable(marks: &[BallMark]) -> Vec<&BallMark> {
    marks
        .iter()
        .filter(|m| m.status.fitted())
        .filter(|m| m.x_px.is_finite() && m.y_px.is_finite() && m.r_px.is_finite())
        .collect()
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// The shot's phases from its trajectory and surface line: the contact is the run of frames around the one
/// whose ball comes closest to the line (its clearance `line − (y + R)` smallest) while that clearance stays
/// within `rule.margin_px`; the flights are the frames either side. With the estimate's margin (1 px) this
/// is the estimate's rule.
///
/// Marks need not be sorted; frames not `ok`/`occluded` are skipped. Errors: no usable frame, or the ball
/// never within the margin of the line.
///
/// Cost: O(n log n) in the number of marks.
pub fn phases_from_trajectory(
    marks: &[BallMark],
    line: &SurfaceLine,
    rule: &ContactRule,
) -> Result<ShotPhases, OverlayError> {
    line.check()?;
    let mut pts = usable(marks);
    pts.sort_by_key(|m| m.frame);
    let radius = match rule.radius_px {
        Some(r) => r,
        None => median(pts.iter().filter(|m| m.status == Status::Ok).map(|m| m.r_px).collect())
            .or_else(|| median(pts.iter().map(|m| m.r_px).collect()))
            .ok_or(OverlayError::NoMeasuredFrames { frames: marks.len() })?,
    };
    let clearance: Vec<f64> = pts.iter().map(|m| line.y_at(m.x_px) - m.y_px - radius).collect();
    let low = (0..pts.len())
        .min_by(|&a, &b| clearance[a].total_cmp(&clearance[b]))
        .ok_or(OverlayError::NoMeasuredFrames { frames: marks.len() })?;
    if clearance[low] > rule.margin_px {
        return Err(OverlayError::NoContact {
            clearance_px: clearance[low],
            frame: pts[low].frame,
            margin_px: rule.margin_px,
        });
    }
    let near = |i: usize| clearance[i] <= rule.margin_px;
    let (mut first, mut last) = (low, low);
    while first > 0 && near(first - 1) {
        first -= 1;
    }
    while last + 1 < pts.len() && near(last + 1) {
        last += 1;
    }
    Ok(ShotPhases {
        flight_in_last: first.checked_sub(1).map(|i| pts[i].frame),
        contact_first: pts[first].frame,
        deepest: pts[low].frame,
        contact_last: pts[last].frame,
        flight_out_first: (last + 1 < pts.len()).then(|| pts[last + 1].frame),
    })
}

/// The key frames from the trajectory alone. With a surface line and a contact, those of
/// [`phases_from_trajectory`]. Without a line (or with a line the ball never reaches), no touch or
/// separation can be placed: the deepest frame is the lowest centre (largest y) and approach and leave are
/// the nearest frames before and after it whose centre is one radius higher, so a strip still shows the
/// ball coming in and going out.
///
/// Errors only if no frame has a usable centre.
pub fn key_frames_from_trajectory(
    marks: &[BallMark],
    line: Option<&SurfaceLine>,
    rule: &ContactRule,
) -> Result<KeyFrames, OverlayError> {
    if let Some(line) = line {
        match phases_from_trajectory(marks, line, rule) {
            Ok(p) => return Ok(p.key_frames()),
            Err(OverlayError::NoContact { .. }) => {}
            Err(e) => return Err(e),
        }
    }
    let mut pts = usable(marks);
    pts.sort_by_key(|m| m.frame);
    let low = (0..pts.len())
        .max_by(|&a, &b| pts[a].y_px.total_cmp(&pts[b].y_px))
        .ok_or(OverlayError::NoMeasuredFrames { frames: marks.len() })?;
    let radius = rule
        .radius_px
        .or_else(|| median(pts.iter().map(|m| m.r_px).collect()))
        .unwrap_or(0.0);
    let risen = |i: &usize| pts[*i].y_px <= pts[low].y_px - radius;
    Ok(KeyFrames {
        approach: (0..low).rev().find(risen).map(|i| pts[i].frame),
        touch: None,
        deepest: pts[low].frame,
        separation: None,
        leave: (low + 1..pts.len()).find(risen).map(|i| pts[i].frame),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const R: f64 = 30.0;

    /// A ball falling onto the line y = 200 (slope 0), pressed `depth` px in at frame 20, and rising:
    /// centre y = 170 + depth − 0.4·(f − 20)² (px).
    fn bounce(depth: f64, status_at: impl Fn(u64) -> Status) -> Vec<BallMark> {
        (0..41u64)
            .map(|f| {
                let d = f as f64 - 20.0;
                BallMark {
                    frame: f,
                    x_px: 100.0 + 2.0 * f as f64,
                    y_px: 200.0 - R + depth - 0.4 * d * d,
                    r_px: R,
                    status: status_at(f),
                    phase: Phase::Unknown,
                }
            })
            .collect()
    }

    fn flat(y0: f64) -> SurfaceLine {
        SurfaceLine {
            x0: 0.0,
            y0,
            slope: 0.0,
        }
    }

    #[test]
    fn the_five_frames_of_a_synthetic_bounce() {
        // Clearance = 0.4 d² − 2; ≤ 0 while d² ≤ 5, i.e. frames 18–22.
        let marks = bounce(2.0, |_| Status::Ok);
        let p = phases_from_trajectory(&marks, &flat(200.0), &ContactRule::default()).unwrap();
        assert_eq!(
            p,
            ShotPhases {
                flight_in_last: Some(17),
                contact_first: 18,
                deepest: 20,
                contact_last: 22,
                flight_out_first: Some(23),
            }
        );
        let roles: Vec<_> = p.key_frames().placed();
        assert_eq!(
            roles,
            vec![
                (KeyRole::Approach, 17),
                (KeyRole::Touch, 18),
                (KeyRole::Deepest, 20),
                (KeyRole::Separation, 22),
                (KeyRole::Leave, 23)
            ]
        );
        assert_eq!(
            [0, 17, 18, 22, 23].map(|f| p.phase_of(f)),
            [
                Phase::FlightIn,
                Phase::FlightIn,
                Phase::Contact,
                Phase::Contact,
                Phase::FlightOut
            ]
        );
    }

    #[test]
    fn a_margin_widens_the_contact() {
        // With the estimate's 1 px: 0.4 d² − 2 ≤ 1 while d² ≤ 7.5, still frames 18–22; with 2 px, d² ≤ 10:
        // frames 17–23.
        let marks = bounce(2.0, |_| Status::Ok);
        let rule = |margin_px| ContactRule {
            margin_px,
            radius_px: Some(R),
        };
        let p = phases_from_trajectory(&marks, &flat(200.0), &rule(1.0)).unwrap();
        assert_eq!((p.contact_first, p.contact_last), (18, 22));
        let p = phases_from_trajectory(&marks, &flat(200.0), &rule(2.0)).unwrap();
        assert_eq!((p.contact_first, p.contact_last), (17, 23));
        // A radius given 1 px smaller leaves the ball 1 px further from the line: d² ≤ 2.5.
        let p = phases_from_trajectory(
            &marks,
            &flat(200.0),
            &ContactRule {
                margin_px: 0.0,
                radius_px: Some(R - 1.0),
            },
        )
        .unwrap();
        assert_eq!((p.contact_first, p.contact_last), (19, 21));
    }

    #[test]
    fn unmeasured_frames_and_order_do_not_matter() {
        // The tracker loses the ball at frames 17 and 23: the flights' nearest usable frames are taken.
        let mut marks = bounce(2.0, |f| match f {
            17 | 23 => Status::Absent,
            19 => Status::Occluded,
            _ => Status::Ok,
        });
        marks.reverse();
        let p = phases_from_trajectory(&marks, &flat(200.0), &ContactRule::default()).unwrap();
        assert_eq!(
            (p.flight_in_last, p.contact_first, p.flight_out_first),
            (Some(16), 18, Some(24))
        );
    }

    #[test]
    fn a_ball_that_never_reaches_the_line_has_no_contact() {
        let marks = bounce(-5.0, |_| Status::Ok);
        let e = phases_from_trajectory(&marks, &flat(200.0), &ContactRule::default()).unwrap_err();
        assert!(
            matches!(e, OverlayError::NoContact { frame: 20, clearance_px, .. } if (clearance_px - 5.0).abs() < 1e-9),
            "{e}"
        );
        // The trajectory alone still gives the lowest frame and the frames a radius above it.
        let k = key_frames_from_trajectory(&marks, Some(&flat(200.0)), &ContactRule::default()).unwrap();
        // y rises one radius (30 px) when 0.4 d² ≥ 30: |d| ≥ 9.
        assert_eq!(
            k.placed(),
            vec![(KeyRole::Approach, 11), (KeyRole::Deepest, 20), (KeyRole::Leave, 29)]
        );
        let k2 = key_frames_from_trajectory(&marks, None, &ContactRule::default()).unwrap();
        assert_eq!(k, k2);
    }

    #[test]
    fn nothing_measured_is_an_error() {
        let marks = bounce(2.0, |_| Status::Absent);
        assert!(matches!(
            key_frames_from_trajectory(&marks, Some(&flat(200.0)), &ContactRule::default()),
            Err(OverlayError::NoMeasuredFrames { frames: 41 })
        ));
        assert!(key_frames_from_trajectory(&[], None, &ContactRule::default()).is_err());
    }

    #[test]
    fn a_clip_that_starts_in_contact_has_no_approach() {
        let marks: Vec<_> = bounce(2.0, |_| Status::Ok)
            .into_iter()
            .filter(|m| m.frame >= 19)
            .collect();
        let p = phases_from_trajectory(&marks, &flat(200.0), &ContactRule::default()).unwrap();
        assert_eq!((p.flight_in_last, p.contact_first), (None, 19));
        assert_eq!(p.key_frames().placed()[0].0, KeyRole::Touch);
    }

    proptest! {
        #[test]
        fn key_frames_are_in_time_order_and_phases_agree(
            depth in 0.0f64..8.0, slope in -0.05f64..0.05, lost in proptest::collection::vec(0u64..41, 0..8)
        ) {
            let marks = bounce(depth, |f| if lost.contains(&f) { Status::Absent } else { Status::Ok });
            let line = SurfaceLine { x0: 140.0, y0: 200.0, slope };
            let Ok(p) = phases_from_trajectory(&marks, &line, &ContactRule::default()) else {
                return Ok(());
            };
            // Touch, deepest and separation may coincide (a one-frame contact); the flights are outside it.
            let frames: Vec<u64> = p.key_frames().placed().iter().map(|k| k.1).collect();
            prop_assert!(frames.windows(2).all(|w| w[0] <= w[1]), "{frames:?}");
            prop_assert!(p.flight_in_last.is_none_or(|f| f < p.contact_first));
            prop_assert!(p.flight_out_first.is_none_or(|f| f > p.contact_last));
            prop_assert_eq!(p.phase_of(p.deepest), Phase::Contact);
            if let Some(f) = p.flight_in_last { prop_assert_eq!(p.phase_of(f), Phase::FlightIn); }
            if let Some(f) = p.flight_out_first { prop_assert_eq!(p.phase_of(f), Phase::FlightOut); }
        }
    }
}
