//! `bouncelab`: the command line. It parses arguments, wires the pipeline's crates together and reports;
//! it owns no science. Exit status: 0 on success, 1 on a user error (one line naming the file, frame or
//! field), 2 on a usage error.

mod cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "bouncelab",
    version,
    about = "High-speed video of a ball impact in, physics out."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a small session with a hidden effect, analyse it, accept the verdict, analyse again.
    Demo(cmd::demo::Args),
    /// Simulate one impact with a model file and print its outputs.
    Simulate(cmd::simulate::Args),
    /// List the effects a model can use, with their physics and parameters.
    Effects(cmd::effects::Args),
    /// Render a synthetic session (frames + exact ground truth) from a preset or a scenario file.
    Render(cmd::render::Args),
    /// Measure one shot: velocities in and out, COR, friction, contact time, penetration, with errors.
    Estimate(cmd::estimate::Args),
    /// Track the ball through one clip folder and write its trajectory (CSV).
    Track(cmd::track::Args),
    /// Track one clip and draw the tracking on its frames (PNG) and a sheet of its key frames.
    Overlay(cmd::overlay::Args),
    /// Start a session from a folder of recordings: write session.toml and clips.csv to complete.
    Init(cmd::init::Args),
    /// Everything over a session folder: track, estimate, fit, compare, diagnose, stats, report.
    Analyze(cmd::analyze::Args),
    /// The missing-effect verdict over a session folder (runs `analyze`), with its evidence.
    Diagnose(cmd::analyze::Args),
    /// Edit a model file: `model add EFFECT --model model.toml` accepts a diagnosis.
    Model(cmd::model::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Demo(a) => cmd::demo::run(a),
        Command::Simulate(a) => cmd::simulate::run(a),
        Command::Effects(a) => cmd::effects::run(a),
        Command::Render(a) => cmd::render::run(a),
        Command::Track(a) => cmd::track::run(a),
        Command::Overlay(a) => cmd::overlay::run(a),
        Command::Estimate(a) => cmd::estimate::run(a),
        Command::Init(a) => cmd::init::run(a),
        Command::Analyze(a) => cmd::analyze::run(a),
        Command::Diagnose(a) => cmd::diagnose::run(a),
        Command::Model(a) => cmd::model::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            ExitCode::from(1)
        }
    }
}

/// The error and its causes on one line, each cause once: an error whose message already quotes its cause
/// (`path: No space left on device`) would otherwise print that cause twice.
fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::error_text;

    /// An error that quotes its cause in its own message, as the libraries' file errors do.
    #[derive(Debug)]
    struct Quoting(std::io::Error);

    impl std::fmt::Display for Quoting {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "out/a.csv: {}", self.0)
        }
    }

    impl std::error::Error for Quoting {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.0)
        }
    }

    #[test]
    fn a_cause_the_message_already_quotes_is_printed_once() {
        let io = std::io::Error::other("No space left on device");
        let e = anyhow::Error::new(Quoting(io)).context("analysing session");
        assert_eq!(error_text(&e), "analysing session: out/a.csv: No space left on device");
    }

    #[test]
    fn every_new_cause_is_printed() {
        let e = anyhow::anyhow!("inner").context("middle").context("outer");
        assert_eq!(error_text(&e), "outer: middle: inner");
    }
}
