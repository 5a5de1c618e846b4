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
        "Coefficient of restitution against impact speed",
        "Contact time against impact speed",
        "COR against surface incline",
        "Differences of adjusted mean COR by surface",
        "Contact force over time",
        "Systematic residual per phase and component",
    ] {
        assert!(html.contains(fig), "{fig}");
    }
    assert!(!html.contains("not available"), "the sample has every section");

    let empty = render_html(&Report::default());
    assert_sections(&empty);
    check_html(&empty).unwrap();
    // Missing parts say so in one line each: ancova, comparisons, fit, diagnosis, model change, residual
    // diagnostics.
    assert_eq!(
        empty.matches("<p class=\"na\">not available: not computed</p>").count(),
        6,
        "{empty}"
    );
    assert!(empty.contains("not available: no shot was tracked"));
    assert!(empty.contains("not available: no shot was measured"));
}

#[test]
fn the_comparisons_are_the_ancovas_adjusted_ones() {
    let report = sample_report();
    let html = render_html(&report);
    let inf = report.inference.get().unwrap();
    let m = inf.means_of("surface").unwrap();
    // Every pair's Tukey and Holm p and every adjusted mean come from the ANCOVA's inference.
    for p in &m.pairs {
        let row = format!("<td>{} − {}</td>", p.level2, p.level1);
        let at = html.find(&row).unwrap_or_else(|| panic!("no row {row}"));
        let tail = &html[at..at + 800];
        assert!(
            tail.contains(&format!("<td class=\"n\">{}</td>", p_text_of(p.p_tukey))),
            "{tail}"
        );
        assert!(
            tail.contains(&format!("<td class=\"n\">{}</td>", p_text_of(p.p_holm))),
            "{tail}"
        );
    }
    // The coefficients carry SE, t, p and an interval: six cells in the v_in_n row.
    let c = inf.coefficients.row("v_in_n").unwrap();
    let at = html.find("<td><code>v_in_n</code></td>").expect("no v_in_n row");
    let row = &html[at..at + html[at..].find("</tr>").unwrap()];
    assert_eq!(row.matches("<td").count(), 6, "{row}");
    assert!(
        row.contains(&format!("<td class=\"n\">{}</td>", p_text_of(c.p))),
        "{row}"
    );
    // The residual caption says what the tests found.
    let caption = inf.residual_tests.caption();
    assert!(
        html.contains(&caption.replace('\'', "&#39;")),
        "caption missing: {caption}"
    );
    assert!(!html.contains("no pattern"), "an expectation instead of a finding");
    // No unadjusted one-way table pretending to be the comparison.
    assert!(!html.contains("pooled MSE"));
}

/// The report's p-value format (three decimals down to 0.01, four to 0.001, two significant digits below).
fn p_text_of(p: f64) -> String {
    if p >= 0.01 {
        format!("{p:.3}")
    } else if p >= 0.001 {
        format!("{p:.4}")
    } else {
        format!("{p:.1e}")
    }
}

#[test]
fn every_quantity_is_shown_per_surface_and_per_shot() {
    let report = sample_report();
    let html = render_html(&report);
    for q in [
        "Impact speed |v<sub>in</sub>| (m/s)",
        "Impact angle from the normal (°)",
        "COR e",
        "μ<sub>eff</sub>",
        "Contact time (ms)",
        "δ<sub>max</sub> (mm)",
        "Spin in ω<sub>in</sub> (rad/s)",
        "Spin out ω<sub>out</sub> (rad/s)",
        "Peak deceleration, track (m/s²)",
        "Peak contact force, track (N)",
        "Peak contact force, model (N)",
        "Peak deceleration, model (m/s²)",
    ] {
        assert!(html.contains(&format!("<td>{q}</td>")), "per-surface row {q}");
    }
    // The per-surface mean ± SD of the COR of clay, from the measurements.
    let cors: Vec<f64> = report
        .measurements
        .iter()
        .filter(|m| m.surface == "clay")
        .map(|m| m.cor.value)
        .collect();
    let n = cors.len() as f64;
    let mean = cors.iter().sum::<f64>() / n;
    let sd = (cors.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let decimals = (1 - sd.log10().floor() as i32) as usize;
    let cell = format!(
        "{mean:.decimals$}<span class=\"se\">±{sd:.decimals$}</span> <span class=\"se\">(n = {})</span>",
        cors.len()
    );
    assert!(html.contains(&cell), "no cell {cell}");
    // Per shot, the COR with an error that is not shown as zero.
    let m = &report.measurements[0];
    let se = m.cor.se.unwrap();
    let decimals = (1 - se.log10().floor() as i32) as usize;
    assert!(html.contains(&format!(
        "{:.decimals$}<span class=\"se\">±{se:.decimals$}</span>",
        m.cor.value
    )));
    assert!(!html.contains("±0.000<"), "an error shown as zero");
    // The model's curve values are listed under the figure.
    let p = &report.model_curves[0].points[0];
    assert!(
        html.contains(&format!("<td class=\"n\">{:.4}</td>", p.prediction.cor)),
        "curve value"
    );
}

#[test]
fn a_note_every_shot_carries_is_said_once() {
    let html = render_html(&sample_report());
    assert_eq!(html.matches("the surface level is fitted per surface").count(), 1);
    assert!(html.contains("2 frames without the ball (311–312)"));
}

#[test]
fn a_strip_of_annotated_frames_is_embedded_when_given() {
    let mut report = sample_report_with(1, 3);
    // A 1×1 PNG.
    let png: Vec<u8> = vec![
        0x89, 0x50, 0x4E, 0x47, 0x0D, 0x0A, 0x1A, 0x0A, 0, 0, 0, 0x0D, 0x49, 0x48, 0x44, 0x52, 0, 0, 0, 1, 0, 0, 0, 1,
        8, 0, 0, 0, 0, 0x3A, 0x7E, 0x9B, 0x55, 0, 0, 0, 0x0A, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9C, 0x63, 0x60, 0, 0, 0,
        0x02, 0, 0x01, 0xE2, 0x21, 0xBC, 0x33, 0, 0, 0, 0, 0x49, 0x45, 0x4E, 0x44, 0xAE, 0x42, 0x60, 0x82,
    ];
    report.shots[0].frames = vec![
        FrameImage {
            caption: "touch, frame <312>".into(),
            png: png.clone(),
        },
        FrameImage {
            caption: "maximum compression".into(),
            png,
        },
    ];
    let html = render_html(&report);
    check_html(&html).unwrap();
    assert_eq!(html.matches("<img alt=").count(), 2);
    assert!(
        html.contains("src=\"data:image/png;base64,iVBORw0KGgo"),
        "the PNG as a data URI"
    );
    assert!(html.contains("touch, frame &lt;312&gt;"));
    // Without frames there is no strip.
    assert!(!render_html(&sample_report_with(1, 3)).contains("class=\"strip\""));
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
            frames: vec![],
        })
        .collect();
    let measurements: Vec<ShotMeasurement> = (0..n)
        .map(|i| {
            let mut q = || Measured {
                value: next(),
                se: Some(next()),
            };
            ShotMeasurement {
                clip: format!("c{}", i % 3),
                surface: format!("s{}", i % 2),
                angle_deg: q().value,
                drop_height_m: Some(q().value),
                v_in_m_s: [q(), q()],
                v_out_m_s: [q(), q()],
                cor: q(),
                mu_eff: q(),
                contact_time_s: q(),
                delta_max_m: q(),
                spin_in_rad_s: Some(q()),
                spin_out_rad_s: Some(q()),
                peak_deceleration_track_m_s2: Some(q()),
                peak_force_track_n: Some(q()),
                model: Some(ShotPrediction {
                    cor: q().value,
                    peak_force_n: q().value,
                    peak_deceleration_m_s2: q().value,
                    contact_time_s: q().value,
                    ..Default::default()
                }),
            }
        })
        .collect();
    let model_curves = vec![ModelCurve {
        surface: "s0".into(),
        angle_deg: next(),
        points: (0..n)
            .map(|_| CurvePoint {
                v_in_n_m_s: next(),
                prediction: ShotPrediction {
                    cor: next(),
                    contact_time_s: next(),
                    delta_max_m: next(),
                    peak_deceleration_m_s2: next(),
                    ..Default::default()
                },
            })
            .collect(),
    }];
    let contact_force = ContactForce {
        samples: (0..n)
            .map(|_| ForceSample {
                t_s: next(),
                delta_m: next(),
                force_n: next(),
            })
            .collect(),
        ..Default::default()
    };
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
        dof: Some(n),
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
    let change = ModelChange {
        shots: (0..n)
            .map(|i| ShotBeforeAfter {
                clip: format!("c{i}"),
                surface: "s0".into(),
                rms_before_m: next(),
                rms_after_m: next(),
            })
            .collect(),
        signature_before: vec![SignatureRow {
            phase: Phase::Compression,
            normal: true,
            rms_m: next(),
            systematic_m: next(),
            chi2_share: next(),
        }],
        total_rms_before_m: next(),
        total_rms_after_m: next(),
        ..Default::default()
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
        ..Default::default()
    };
    Report {
        shots,
        measurements,
        model_curves,
        contact_force: contact_force.into(),
        fit: fit.into(),
        diagnosis: diagnosis.into(),
        model_change: change.into(),
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
