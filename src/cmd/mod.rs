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

/// A progress bar on a terminal; hidden otherwise (logs stay plain).
pub fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg:>10} [{bar:40}] {pos}/{len} ({per_sec}, {eta})")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}
