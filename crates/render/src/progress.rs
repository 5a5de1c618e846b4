//! A terminal progress bar (indicatif) as a [`RenderObserver`], hidden when stderr is not a terminal.

use crate::RenderObserver;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// Shows frames written out of the total on stderr, on a terminal only.
#[derive(Debug)]
pub struct ProgressBarObserver {
    bar: ProgressBar,
}

impl ProgressBarObserver {
    /// A bar drawn on stderr if it is a terminal, hidden otherwise.
    pub fn new() -> ProgressBarObserver {
        let bar = ProgressBar::hidden();
        if std::io::stderr().is_terminal() {
            bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        bar.set_style(
            ProgressStyle::with_template("{spinner} rendering [{bar:40}] {pos}/{len} frames ({rate}, eta {eta})")
                .expect("valid template")
                // indicatif's own {per_sec} prints "254.9181/s": the rate with its unit and no false digits.
                .with_key("rate", |s: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{:.0} frames/s", s.per_sec());
                })
                .progress_chars("=> "),
        );
        ProgressBarObserver { bar }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Default for ProgressBarObserver {
    fn default() -> Self {
        Self::new()
    }
}

impl RenderObserver for ProgressBarObserver {
    fn planned(&self, _shots: usize, frames: usize) {
        self.bar.set_length(frames as u64);
    }
    fn frame_written(&self) {
        self.bar.inc(1);
    }
}
