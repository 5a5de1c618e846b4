// cargo run --release --example looks_accuracy -- [PRESET|SCENARIO.toml|SESSION_DIR TRUTH_DIR]
//
//! The tracker and estimator on many looks (default: the `looks` preset, 64 shots, rendered into a temporary
//! folder): a Markdown table per clip and one per look family (frames found, centre RMS in flight and
//! contact, contact level error, COR and μ errors). The figures in `docs/accuracy.md` ("Many looks") come
//! from this command.

#[path = "../tests/common/looks.rs"]
mod looks;
#[path = "../tests/common/rendered.rs"]
mod rendered;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (session, truth, _tmp) = rendered::session_and_truth(&args, "looks");
    let results = looks::evaluate(&session, &truth);
    println!("{}", looks::clip_table(&results));
    println!("{}", looks::family_table(&results));
}
