//! The report page: every section present, input text escaped, odd numbers survived, deterministic bytes,
//! well-formed HTML, a reasonable size, atomic writing.

mod common;

use bouncelab_report::testutil::{
    AMP_CLIP, CONSOLE_SURFACE, SCRIPT_SURFACE, hostile_report, sample_report, sample_report_with,
};
use bouncelab_report::*;
use common::{check_html, outline};
use proptest::prelude::*;

fn assert_sections(html: &str) {
    for (id, heading) in SECTIONS {
        let tag = format!("<section id=\"{id}\">\n<h2>{heading}</h2>");
        assert!(html.contains(&tag), "missing section {id} ({heading})");
    }
}

#[test]
fn every_section_is_present_in_a_full_and_an_empty_report() {
    let html = render_html(&sample_report());
    assert_sections(&html);
    check_html(&html).unwrap();
    for fig in [
        "Figure 1.",
        "COR against impact speed",
        "COR against surface angle",
        "Pairwise differences of mean COR",
    ] {
        assert!(html.contains(fig), "{fig}");
    }
    assert!(!html.contains("not available"), "the sample has every section");

    let empty = render_html(&Report::default());
    assert_sections(&empty);
    check_html(&empty).unwrap();
    // Missing parts say so in one line each.
    assert_eq!(
        empty.matches("<p class=\"na\">not available: not computed</p>").count(),
        5,
        "{empty}"
    );
    assert!(empty.contains("not available: no shot was tracked"));
    assert!(empty.contains("not available: no shot has a measured COR"));
}

#[test]
fn a_stage_error_becomes_the_reason() {
    let err: Result<FitSummary, std::io::Error> =
        Err(std::io::Error::other("fit did not converge <after 200 iterations>"));
    let report = Report {
        fit: err.into(),
        ..Default::default()
    };
    let html = render_html(&report);
    assert!(html.contains("not available: fit did not converge &lt;after 200 iterations&gt;"));
}

#[test]
fn text_from_input_is_escaped_in_html_and_svg() {
    let html = render_html(&hostile_report());
    assert!(!html.contains("<script>alert"), "unescaped script");
    assert!(!html.contains("<img"), "unescaped img");
    assert!(!html.contains("<b>title") && !html.contains("<i>desc") && !html.contains("<verdict>"));
    assert_eq!(html.matches("<script").count(), 1, "only the page's own script");
    assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(html.contains("a&amp;b&quot;&lt;x&gt;"));
    // Inside SVG too: tooltips and legends carry the names.
    let svg_part: String = html.split("<svg").skip(1).collect::<Vec<_>>().join("<svg");
    assert!(
        svg_part.contains("&lt;script&gt;alert(1)&lt;/script&gt;"),
        "surface name in a legend or tooltip"
    );
    assert!(svg_part.contains("a&amp;b&quot;&lt;x&gt;"), "clip name in a tooltip");
    assert!(
        html.contains(
            &CONSOLE_SURFACE
                .replace('<', "&lt;")
                .replace('>', "&gt;")
                .replace('"', "&quot;")
                .replace('\'', "&#39;")
        )
    );
    check_html(&html).unwrap();
    let _ = (AMP_CLIP, SCRIPT_SURFACE);
}

#[test]
fn odd_numbers_give_sensible_html() {
    let html = render_html(&hostile_report());
    assert_sections(&html);
    check_html(&html).unwrap();
    // Non-finite values are spelled out in tables and never reach SVG coordinates.
    assert!(html.contains("NaN") && html.contains("∞"));
    for svg in html.split("<svg").skip(1) {
        let svg = &svg[..svg.find("</svg>").unwrap()];
        assert!(
            !svg.contains("NaN") && !svg.contains("inf"),
            "non-finite number in SVG: {svg}"
        );
    }
    assert!(html.contains("non-finite values not drawn"));
    // A repeated clip name gets its own anchor; links go to the first.
    assert!(html.contains("id=\"shot-a_b__x_\"") && html.contains("id=\"shot-a_b__x_-2\""));
}

#[test]
fn the_same_report_gives_the_same_bytes() {
    let a = render_html(&sample_report());
    let b = render_html(&sample_report());
    assert!(a == b, "two renders differ");
    assert_eq!(render_html(&hostile_report()), render_html(&hostile_report()));
}

#[test]
fn the_page_loads_nothing_from_outside() {
    let html = render_html(&sample_report());
    let without_ns = html.replace("xmlns=\"http://www.w3.org/2000/svg\"", "");
    for needle in ["http:", "https:", "src=", "@import", "url(http", "<link", "@font-face"] {
        assert!(!without_ns.contains(needle), "{needle}");
    }
}

#[test]
fn outline_matches_the_golden_file() {
    let actual = outline(&render_html(&sample_report()));
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/sample_outline.txt");
    if std::env::var_os("BOUNCELAB_BLESS").is_some() {
        std::fs::write(path, &actual).unwrap();
    }
    let expected = std::fs::read_to_string(path).expect("golden file (refresh with BOUNCELAB_BLESS=1)");
    assert!(
        expected == actual,
        "outline changed (refresh with BOUNCELAB_BLESS=1)\n--- expected\n{expected}\n--- actual\n{actual}"
    );
}

#[test]
fn file_size_stays_reasonable() {
    let small = render_html(&sample_report()).len();
    assert!(small < 900_000, "24 shots: {small} bytes");
    let large = render_html(&sample_report_with(48, 1)).len();
    assert!(large < 3_000_000, "144 shots: {large} bytes");
    eprintln!("24 shots: {} KB, 144 shots: {} KB", small / 1024, large / 1024);
}

#[test]
fn write_report_replaces_the_file_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("report.html");
    std::fs::write(&path, "old").unwrap();
    write_report(&path, &sample_report()).unwrap();
    let written = std::fs::read_to_string(&path).unwrap();
    assert_eq!(written, render_html(&sample_report()));
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        names,
        vec![std::ffi::OsString::from("report.html")],
        "no temporary file left"
    );

    let missing = dir.path().join("no/such/folder/report.html");
    let err = write_report(&missing, &Report::default()).unwrap_err();
    assert!(matches!(err, ReportError::Write { .. }));
    assert!(err.to_string().contains("no/such/folder/report.html"), "{err}");
    let err = write_report("/", &Report::default()).unwrap_err();
    assert!(matches!(err, ReportError::NoFileName { .. }), "{err}");
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        proptest::num::f64::ANY,
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(0.0),
        Just(f64::MAX),
        Just(f64::MIN_POSITIVE),
        -1.0..1.0f64,
    ]
}

/// A report whose every plotted number comes from `v` (cycled).
fn report_from(v: &[f64], n: usize) -> Report {
    let mut k = 0usize;
    let mut next = || {
        k += 1;
        if v.is_empty() { f64::NAN } else { v[k % v.len()] }
    };
    let shots: Vec<ShotPlot> = (0..2)
        .map(|s| ShotPlot {
            clip: format!("c{s}"),
            surface: format!("s{}", s % 2),
            angle_deg: next(),
            drop_height_m: Some(next()),
            measured: (0..n)
                .map(|_| MeasuredPoint {
                    t_s: next(),
                    x_m: next(),
                    y_m: next(),
                    sigma_m: next(),
                })
                .collect(),
            model: (0..n)
                .map(|_| ModelPoint {
                    t_s: next(),
                    x_m: next(),
                    y_m: next(),
                })
                .collect(),
            phases: Phase::ALL
                .iter()
                .map(|&phase| PhaseSpan {
                    phase,
                    t0_s: next(),
                    t1_s: next(),
                })
                .collect(),
            residuals: (0..n)
                .map(|_| Residual {
                    t_s: next(),
                    dx_m: next(),
                    dy_m: next(),
                })
                .collect(),
            rms_m: if s == 0 { None } else { Some(next()) },
            chi2_red: Some(next()),
            notes: vec![],
        })
        .collect();
    let cor_points = (0..n)
        .map(|i| CorPoint {
            clip: format!("c{}", i % 3),
            surface: format!("s{}", i % 2),
            angle_deg: next(),
            v_in_n: next(),
            v_in_n_se: Some(next()),
            cor: next(),
            cor_se: Some(next()),
        })
        .collect();
    let fit = FitSummary {
        model_name: "m".into(),
        parameters: vec![FitParameter {
            name: "k".into(),
            value: next(),
            std_error: Some(next()),
            interval: Some([next(), next()]),
            unit: "N/m".into(),
            at_bound: false,
        }],
        confidence: next(),
        reduced_chi2: Some(next()),
        rms_m: Some(next()),
        termination: String::new(),
        mean_abs_error_pct: Some(next()),
        by_surface: vec![SurfaceError {
            surface: "s0".into(),
            shots: 1,
            mean_abs_error_pct: next(),
        }],
        oblique: (0..n)
            .map(|i| ObliqueRow {
                clip: format!("c{i}"),
                surface: "s1".into(),
                angle_deg: next(),
                v_out_measured: [next(), next()],
                v_out_predicted: [next(), next()],
                error_pct: [next(), next()],
            })
            .collect(),
    };
    let diagnosis = DiagnosisSection {
        candidates: vec![Candidate {
            effect: "e".into(),
            error_before: next(),
            error_after: next(),
            delta_bic: next(),
            heldout_before: Some(next()),
            heldout_after: Some(next()),
        }],
        before_after: (0..n)
            .map(|i| ShotBeforeAfter {
                clip: format!("c{i}"),
                surface: "s0".into(),
                rms_before_m: next(),
                rms_after_m: next(),
            })
            .collect(),
        total_rms_before_m: if n % 2 == 0 { None } else { Some(next()) },
        total_rms_after_m: Some(next()),
        ..Default::default()
    };
    Report {
        shots,
        cor_points,
        fit: fit.into(),
        diagnosis: diagnosis.into(),
        timings: vec![("a".into(), next()), ("b".into(), next())],
        ..Default::default()
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any numbers at all in the plots and tables: no panic, and the page stays well-formed.
    #[test]
    fn render_never_panics_on_arbitrary_numbers(v in proptest::collection::vec(any_f64(), 0..40), n in 0usize..12) {
        let html = render_html(&report_from(&v, n));
        prop_assert!(html.ends_with("</html>\n"));
        check_html(&html).map_err(TestCaseError::fail)?;
    }
}
