// cargo run -p bouncelab-report --example sample_report -- /tmp/sample_report.html
//! Writes the synthetic sample report (3 surfaces, 24 shots) to the path given on the command line, so the
//! page can be looked at in a browser.

use std::process::ExitCode;

fn main() -> ExitCode {
    let Some(path) = std::env::args_os().nth(1) else {
        eprintln!("usage: sample_report OUT.html");
        return ExitCode::from(2);
    };
    let report = bouncelab_report::testutil::sample_report();
    match bouncelab_report::write_report(&path, &report) {
        Ok(()) => {
            let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
            println!("wrote {} ({} KB)", path.to_string_lossy(), size / 1024);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
