// cargo run --release --example looks_accuracy -- [--line plane|drawn-edge] [PRESET|SCENARIO.toml|SESSION_DIR TRUTH_DIR]
//
//! The tracker and estimator on many looks (default: the `looks` preset, 64 shots, rendered into a temporary
//! folder): a Markdown table per clip and one per look family (frames found, centre RMS in flight and
//! contact, the clip's constant offset in flight and the RMS about it, contact level error, COR and μ
//! errors), one per contact-line cue (the level against its stated standard error), and one for COR and μ
//! against their stated standard errors. The figures in `docs/accuracy.md` ("Many looks") come
//! from this command. `--line plane` gives each clip the truth's surface plane as its contact line (as a lab
//! gives a line it measured): the errors left are the tracker's and the estimator's alone. `--line
//! drawn-edge` gives it the least-squares line through the band's edge as drawn (`truth/edges.csv`): the
//! best a line finder can do, since a ragged edge's own line is not the plane it was drawn about.

#[path = "../tests/common/looks.rs"]
mod looks;
#[path = "../tests/common/rendered.rs"]
mod rendered;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut line = looks::GivenLine::None;
    if let Some(i) = args.iter().position(|a| a == "--line") {
        line = match args.get(i + 1).map(String::as_str) {
            Some("plane") => looks::GivenLine::Plane,
            Some("drawn-edge") => looks::GivenLine::DrawnEdge,
            other => panic!("--line takes `plane` or `drawn-edge`, not {other:?}"),
        };
        args.drain(i..i + 2);
    }
    let (session, truth, _tmp) = rendered::session_and_truth(&args, "looks");
    let results = looks::evaluate_with(&session, &truth, line);
    println!("{}", looks::clip_table(&results));
    println!("{}", looks::family_table(&results));
    println!("{}", looks::level_table(&results));
    println!("{}", looks::se_table(&results));
}
