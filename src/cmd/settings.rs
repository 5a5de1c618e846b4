//! The clip-setting flags shared by `track`, `estimate`, `overlay` and `analyze` (`docs/session.md`): each
//! beats `clip.toml`, the camera header and `session.toml`.

use bouncelab_frames::{ClipOptions, ContactLine, Roi};

#[derive(clap::Args, Clone, Debug, Default)]
pub struct Overrides {
    /// Frame rate, frames/s [default: clip.toml, the camera header, session.toml, else 10000 with a warning].
    #[arg(long, allow_negative_numbers = true)]
    pub fps: Option<f64>,
    /// Ball diameter, m [default: clip.toml, session.toml's [ball] diameter_m, else 0.067 with a warning].
    #[arg(long, allow_negative_numbers = true)]
    pub diameter: Option<f64>,
    /// Image scale, m/px [default: clip.toml, session.toml, else measured from the ball's radius].
    #[arg(long, allow_negative_numbers = true)]
    pub scale: Option<f64>,
    /// Region of interest X,Y,WIDTH,HEIGHT in pixels (left, top, size): only that part of each frame is
    /// searched [default: the whole frame].
    #[arg(long, value_parser = parse_roi, value_name = "X,Y,W,H")]
    pub roi: Option<Roi>,
    /// Contact line Y[,TILT]: its y in pixels at the frame's centre column and its tilt in degrees
    /// (counter-clockwise in the image) [default: found in the image, else from the ball's trajectory].
    #[arg(long, value_parser = parse_line, value_name = "Y[,TILT]", allow_negative_numbers = true)]
    pub line: Option<ContactLine>,
}

impl Overrides {
    /// These flags as options for opening a clip or loading a session.
    pub fn clip_options(&self) -> ClipOptions {
        let mut o = ClipOptions::default();
        o.fps = self.fps;
        o.overrides.ball_diameter_m = self.diameter;
        o.overrides.scale_m_per_px = self.scale;
        o.overrides.roi = self.roi;
        o.overrides.contact_line = self.line;
        o
    }
}

/// Comma-separated numbers, each named in the error.
fn numbers(text: &str, names: &[&str]) -> Result<Vec<f64>, String> {
    text.split(',')
        .zip(names)
        .map(|(part, name)| {
            part.trim()
                .parse::<f64>()
                .map_err(|_| format!("{name} {:?} is not a number", part.trim()))
        })
        .collect()
}

fn parse_roi(text: &str) -> Result<Roi, String> {
    let names = ["X", "Y", "WIDTH", "HEIGHT"];
    if text.split(',').count() != 4 {
        return Err("expected four numbers X,Y,WIDTH,HEIGHT in pixels, e.g. 0,100,512,400".into());
    }
    let v = numbers(text, &names)?;
    let mut px = [0u32; 4];
    for ((p, value), name) in px.iter_mut().zip(&v).zip(names) {
        if value.fract() != 0.0 || *value < 0.0 || *value > f64::from(u32::MAX) {
            return Err(format!("{name} {value} is not a whole number of pixels ≥ 0"));
        }
        *p = *value as u32;
    }
    if px[2] == 0 || px[3] == 0 {
        return Err("WIDTH and HEIGHT must be at least 1 pixel".into());
    }
    Ok(Roi {
        x: px[0],
        y: px[1],
        width: px[2],
        height: px[3],
    })
}

fn parse_line(text: &str) -> Result<ContactLine, String> {
    let parts = text.split(',').count();
    if !(1..=2).contains(&parts) {
        return Err("expected Y or Y,TILT (pixels, degrees), e.g. 431.5 or 431.5,-1.2".into());
    }
    let v = numbers(text, &["Y", "TILT"])?;
    Ok(ContactLine {
        y_px: v[0],
        tilt_deg: v.get(1).copied().unwrap_or(0.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_region_needs_four_whole_pixel_numbers() {
        assert_eq!(
            parse_roi("10, 20,300,200"),
            Ok(Roi {
                x: 10,
                y: 20,
                width: 300,
                height: 200
            })
        );
        assert!(parse_roi("10,20,300").unwrap_err().contains("four numbers"));
        assert!(parse_roi("10,20,300.5,200").unwrap_err().contains("WIDTH"));
        assert!(parse_roi("-1,20,300,200").unwrap_err().contains("X"));
        assert!(parse_roi("1,2,0,5").unwrap_err().contains("at least 1"));
        assert!(parse_roi("a,2,3,5").unwrap_err().contains("X \"a\""));
    }

    #[test]
    fn a_line_is_y_with_an_optional_tilt() {
        assert_eq!(
            parse_line("431.5"),
            Ok(ContactLine {
                y_px: 431.5,
                tilt_deg: 0.0
            })
        );
        assert_eq!(
            parse_line("431.5,-1.25"),
            Ok(ContactLine {
                y_px: 431.5,
                tilt_deg: -1.25
            })
        );
        assert!(parse_line("1,2,3").is_err());
        assert!(parse_line("x").unwrap_err().contains("Y \"x\""));
    }
}
