//! Time of the session statistics on the 144-row paper design (`fixtures/stats/cor_paper_design.csv`: 3
//! surfaces × 4 angles × 12 shots, covariate v_in_n), the calls `analyze` makes for its stats stage.
//!
//! Run: `cargo bench -p bouncelab-stats --bench inference` (prints a Markdown table; best of 5 runs each).

use std::fs::File;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use bouncelab_stats::{
    Dataset, PAPER_TERMS, StudentizedRange, ancova, ancova_inference, residual_tests, tukey_hsd_unadjusted_factor,
};

/// A row of the table: what is timed, and the call.
type Timed<'a> = (&'static str, Box<dyn FnMut() -> bool + 'a>);

fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> Duration {
    (0..runs)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed()
        })
        .min()
        .unwrap_or_default()
}

fn main() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/stats/cor_paper_design.csv");
    let data = Dataset::read_csv(
        File::open(&path).expect("fixture"),
        "cor",
        &["surface", "angle"],
        &["v_in_n"],
    )
    .expect("fixture parses");
    let srange = StudentizedRange::new(4.0, 137.0).expect("k, df");
    let rows: [Timed; 6] = [
        (
            "`ancova` (Type I + II tables, fit, diagnostics)",
            Box::new(|| ancova(&data, &PAPER_TERMS).is_ok()),
        ),
        (
            "`ancova_inference` (coefficients, marginal means of surface and angle, residual tests)",
            Box::new(|| ancova_inference(&data, &PAPER_TERMS, 0.05).is_ok()),
        ),
        (
            "`residual_tests` alone",
            Box::new(|| residual_tests(&data, &PAPER_TERMS, 0.05).is_ok()),
        ),
        (
            "`tukey_hsd_unadjusted_factor` (surface)",
            Box::new(|| tukey_hsd_unadjusted_factor(&data, "surface", 0.05).is_ok()),
        ),
        (
            "`StudentizedRange::quantile(0.95)`, k 4, df 137",
            Box::new(|| srange.quantile(0.95) > 0.0),
        ),
        (
            "`StudentizedRange::sf(3.0)`, k 4, df 137",
            Box::new(|| srange.sf(3.0) > 0.0),
        ),
    ];
    println!("| call | best of 5 |\n| --- | --- |");
    for (what, mut f) in rows {
        println!("| {what} | {:.1} ms |", best_of(5, &mut f).as_secs_f64() * 1e3);
    }
}
