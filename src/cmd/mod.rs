//! One module per subcommand.

pub mod analyze;
pub mod demo;
pub mod diagnose;
pub mod effects;
pub mod estimate;
pub mod init;
pub mod model;
pub mod overlay;
pub mod render;
pub mod settings;
pub mod simulate;
pub mod track;

use anyhow::Context;
use bouncelab_model::ModelSpec;
use std::path::Path;

/// The model file at `path`, or the built-in paper model.
pub fn load_model(path: Option<&Path>) -> anyhow::Result<ModelSpec> {
    match path {
        Some(p) => ModelSpec::load(p).with_context(|| format!("reading the model {}", p.display())),
        None => Ok(ModelSpec::paper()),
    }
}

/// A progress bar on a terminal counting `unit`s (e.g. "frames", "shots"), with its rate in that unit per
/// second; hidden otherwise (logs stay plain).
pub fn progress_bar(len: u64, what: &str, unit: &'static str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!(
            "{{prefix:>9}} [{{bar:40}}] {{pos}}/{{len}} {unit} ({{rate}}, eta {{eta}}) {{msg}}"
        ))
        .expect("valid template")
        .with_key(
            "rate",
            move |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{}", rate(s.per_sec(), unit));
            },
        )
        .progress_chars("=> "),
    );
    bar.set_prefix(what.to_string());
    bar
}

/// A rate for people: "254.9 frames/s", "3.2 shots/s", "0.21 shots/s" (three significant digits).
pub fn rate(per_sec: f64, unit: &str) -> String {
    if !per_sec.is_finite() || per_sec <= 0.0 {
        return format!("— {unit}/s");
    }
    let digits = (2 - per_sec.log10().floor() as i32).max(0) as usize;
    format!("{per_sec:.digits$} {unit}/s")
}

/// A value with its standard error for a terminal: the error to two significant digits, the value to the
/// same decimal place, so the error never reads as zero ("0.6860 ± 0.0004"); a negative zero as zero.
pub fn pm(v: f64, se: f64) -> String {
    if !(se.is_finite() && se > 0.0 && v.is_finite()) {
        return no_minus_zero(&format!("{v:.4}"));
    }
    let d = (1 - se.log10().floor() as i32).clamp(0, 12) as usize;
    format!("{} ± {se:.d$}", no_minus_zero(&format!("{v:.d$}")))
}

/// "-0.000" (a rounded tiny negative) as "0.000".
pub fn no_minus_zero(s: &str) -> String {
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_and_errors_read_well() {
        assert_eq!(rate(254.9181, "frames"), "255 frames/s");
        assert_eq!(rate(3.21, "shots"), "3.21 shots/s");
        assert_eq!(rate(0.0, "shots"), "— shots/s");
        assert_eq!(pm(0.686, 0.0004), "0.68600 ± 0.00040");
        assert_eq!(pm(-0.00001, 0.0031), "0.0000 ± 0.0031");
        assert_eq!(pm(1.5, f64::NAN), "1.5000");
        assert_eq!(no_minus_zero("-0.0000"), "0.0000");
        assert_eq!(no_minus_zero("-0.0010"), "-0.0010");
    }
}
