//! The clip-setting flags shared by `track`, `estimate`, `overlay` and `analyze` (`docs/session.md`): each
//! beats `clip.toml`, the camera header and `session.toml`.

use bouncelab_frames::{
    ClipOptions, ContactLine, DIAMETER_RANGE_M, MAX_FPS, MAX_LINE_TILT_DEG, MIN_FPS, Roi, SCALE_RANGE_M_PER_PX,
};

/// A number within [lo, hi] (in `unit`): the text parsed, or why not, for clap to print with the flag's name.
pub fn number_in(text: &str, (lo, hi): (f64, f64), unit: &str) -> Result<f64, String> {
    let x: f64 = text.trim().parse().map_err(|_| format!("`{text}` is not a number"))?;
    if x.is_finite() && x >= lo && x <= hi {
        Ok(x)
    } else {
        Err(format!("{} is outside the accepted range {lo}–{hi}{unit}", text.trim()))
    }
}

fn parse_fps(text: &str) -> Result<f64, String> {
    number_in(text, (MIN_FPS, MAX_FPS), " frames/s")
}

fn parse_diameter(text: &str) -> Result<f64, String> {
    number_in(text, DIAMETER_RANGE_M, " m")
}

fn parse_tilt(text: &str) -> Result<f64, String> {
    number_in(text, (-MAX_LINE_TILT_DEG, MAX_LINE_TILT_DEG), " degrees")
}

fn parse_scale(text: &str) -> Result<f64, String> {
    number_in(text, SCALE_RANGE_M_PER_PX, " m/px")
}

/// An incline, degrees: strictly between −90 and 90 (90 is a wall, not a surface to bounce on).
pub fn parse_angle(text: &str) -> Result<f64, String> {
    let x = number_in(text, (-90.0, 90.0), " degrees")?;
    if x.abs() < 90.0 {
        Ok(x)
    } else {
        Err(format!(
            "{} is not an incline: it must lie strictly between -90 and 90 degrees",
            text.trim()
        ))
    }
}

/// Gravitational acceleration, m/s² (the Moon's 1.6 to well above Jupiter's 24.8, with margin).
pub fn parse_gravity(text: &str) -> Result<f64, String> {
    number_in(text, (0.1, 100.0), " m/s²")
}

#[derive(clap::Args, Clone, Debug, Default)]
pub struct Overrides {
    /// Frame rate, frames/s [default: clip.toml, the camera header, session.toml, else 10000 with a warning].
    #[arg(long, allow_negative_numbers = true, value_parser = parse_fps)]
    pub fps: Option<f64>,
    /// Ball diameter, m [default: clip.toml, session.toml's [ball] diameter_m, else 0.067 with a warning].
    #[arg(long, allow_negative_numbers = true, value_parser = parse_diameter)]
    pub diameter: Option<f64>,
    /// Image scale, m/px [default: clip.toml, session.toml, else measured from the ball's radius].
    #[arg(long, allow_negative_numbers = true, value_parser = parse_scale)]
    pub scale: Option<f64>,
    /// Region of interest X,Y,WIDTH,HEIGHT in pixels (left, top, size): only that part of each frame is
    /// searched [default: the whole frame].
    #[arg(long, value_parser = parse_roi, value_name = "X,Y,W,H")]
    pub roi: Option<Roi>,
    /// Contact line Y[,TILT]: its y in pixels at the frame's centre column and its tilt in degrees
    /// (counter-clockwise in the image) [default: found in the image, else from the ball's trajectory].
    #[arg(long, value_parser = parse_line, value_name = "Y[,TILT]", allow_negative_numbers = true)]
    pub line: Option<ContactLine>,
    /// The surface's tilt in the image, degrees counter-clockwise as seen, for shots whose level no line
    /// shows (a known camera roll) [default: session.toml / clip.toml `[surface] tilt_deg`, else the image's
    /// axes, taken as level to within 2°].
    #[arg(long, allow_negative_numbers = true, value_parser = parse_tilt, value_name = "DEGREES")]
    pub tilt: Option<f64>,
    /// Largest frame accepted, in pixels, checked from each file's header before decoding (a corrupt or
    /// hostile header is refused) [default: 67108864 = 8192×8192].
    #[arg(long, value_name = "PIXELS", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_frame_pixels: Option<u64>,
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
        o.overrides.surface_tilt_deg = self.tilt;
        if let Some(max) = self.max_frame_pixels {
            o.max_frame_pixels = max;
        }
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
    if !(v[0].is_finite() && v[0] >= 0.0) {
        return Err(format!("Y {} is not a pixel row (a number ≥ 0)", v[0]));
    }
    if let Some(t) = v.get(1)
        && !(t.is_finite() && t.abs() <= MAX_LINE_TILT_DEG)
    {
        return Err(format!(
            "TILT {t} is outside -{MAX_LINE_TILT_DEG}–{MAX_LINE_TILT_DEG} degrees"
        ));
    }
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
        assert!(
            parse_line("nan").unwrap_err().contains("Y NaN"),
            "{:?}",
            parse_line("nan")
        );
        assert!(parse_line("10,90").unwrap_err().contains("TILT 90"));
    }

    #[test]
    fn nonsense_numbers_are_refused_with_the_range() {
        for bad in ["0", "1e-12", "1e-300", "-1", "nan", "inf", "1e300"] {
            assert!(
                parse_scale(bad).unwrap_err().contains(&format!("{bad} is outside")),
                "{bad}"
            );
            assert!(parse_diameter(bad).is_err(), "{bad}");
            assert!(parse_fps(bad).is_err(), "{bad}");
        }
        assert!(parse_fps("1e-300").unwrap_err().contains("frames/s"));
        assert_eq!(parse_fps("20000"), Ok(20000.0));
        for bad in ["nan", "90", "95", "-90", "1e300", "inf"] {
            assert!(parse_angle(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_angle("-30"), Ok(-30.0));
        assert!(parse_gravity("1e300").is_err() && parse_gravity("0").is_err());
        assert_eq!(parse_gravity("9.81"), Ok(9.81));
    }
}
