//! The page's exact bytes for fixed inputs: a refactor of the renderer (moving code, splitting functions)
//! must not change one byte. Each report's FNV-1a digest and length are kept in `tests/data/html_digests.txt`;
//! an intended change of the page is taken in with `BOUNCELAB_BLESS=1`. On a mismatch the page is written
//! under the target folder so it can be compared with the previous one.

use bouncelab_report::testutil::{hostile_report, sample_report, sample_report_with};
use bouncelab_report::{Report, render_html};

/// FNV-1a, 64 bit: a fixed, dependency-free digest (std's hasher may change between Rust releases).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn pages() -> Vec<(&'static str, String)> {
    vec![
        ("sample_report", render_html(&sample_report())),
        ("sample_report_with(3, 1)", render_html(&sample_report_with(3, 1))),
        ("hostile_report", render_html(&hostile_report())),
        ("empty", render_html(&Report::default())),
    ]
}

#[test]
fn the_pages_of_the_fixtures_keep_their_bytes() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/html_digests.txt");
    let actual: String = pages()
        .iter()
        .map(|(name, html)| format!("{name}\t{:016x}\t{}\n", fnv1a(html.as_bytes()), html.len()))
        .collect();
    if std::env::var_os("BOUNCELAB_BLESS").is_some() {
        std::fs::write(path, &actual).expect("write the digests");
    }
    let expected = std::fs::read_to_string(path).expect("digest file (refresh with BOUNCELAB_BLESS=1)");
    if expected != actual {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
        for (name, html) in pages() {
            let file = dir.join(format!("{}.html", name.replace(|c: char| !c.is_alphanumeric(), "_")));
            let _ = std::fs::write(&file, html);
        }
        panic!(
            "the page's bytes changed (pages written to {}; refresh with BOUNCELAB_BLESS=1 if intended)\n\
             --- expected\n{expected}--- actual\n{actual}",
            dir.display()
        );
    }
}
