//! Property tests (a bounded fuzz run: a fixed number of cases per property, seeded by proptest): frame
//! decoding, `session.toml`/`clips.csv` and `model.toml` parsing, and the formula evaluator never panic,
//! hang or allocate without bound, whatever the bytes; whatever they accept holds only finite, in-range
//! numbers.

use bouncelab_frames::{FrameFormat, PngDecoder, Session, decode_bytes};
use bouncelab_model::{ModelSpec, SimOptions, State, simulate};
use proptest::prelude::*;

/// Cases per property: `PROPTEST_CASES` overrides it (CI's bounded run uses the default).
fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|c| c.parse().ok())
            .unwrap_or(cases),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// One small valid frame of each format, to mutate.
fn seeds() -> Vec<(FrameFormat, Vec<u8>)> {
    let img = image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(24, 16, |x, y| {
        image::Luma([(x * 9 + y * 5) as u8])
    }));
    [
        (FrameFormat::Png, image::ImageFormat::Png),
        (FrameFormat::Bmp, image::ImageFormat::Bmp),
        (FrameFormat::Pnm, image::ImageFormat::Pnm),
        (FrameFormat::Tiff, image::ImageFormat::Tiff),
        (FrameFormat::Jpeg, image::ImageFormat::Jpeg),
    ]
    .into_iter()
    .map(|(f, i)| {
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, i).unwrap();
        (f, bytes.into_inner())
    })
    .collect()
}

proptest! {
    #![proptest_config(config(300))]

    /// A valid frame with bytes overwritten, cut or extended decodes or fails; it never panics, and what
    /// decodes is no larger than the limit the header can claim with these few bytes.
    #[test]
    fn decoding_mutated_frames_never_panics(
        which in 0usize..5,
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..12),
        cut in any::<prop::sample::Index>(),
        zune in any::<bool>(),
    ) {
        let (format, mut bytes) = seeds().swap_remove(which);
        for (at, b) in edits {
            let i = at.index(bytes.len());
            bytes[i] = b;
        }
        let keep = cut.index(bytes.len() + 1);
        bytes.truncate(keep.max(bytes.len() / 2));
        let png = if zune { PngDecoder::Zune } else { PngDecoder::Image };
        if let Ok(img) = decode_bytes(&bytes, format, png) {
            prop_assert!(u64::from(img.width()) * u64::from(img.height()) <= 1 << 26);
        }
    }

    /// Arbitrary bytes as any format: an error, never a panic.
    #[test]
    fn decoding_noise_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..600), which in 0usize..5) {
        let format = [FrameFormat::Png, FrameFormat::Bmp, FrameFormat::Pnm, FrameFormat::Tiff, FrameFormat::Jpeg][which];
        let _ = decode_bytes(&bytes, format, PngDecoder::Image);
    }
}

/// Text built from the pieces a settings file is made of, so the parser gets deep, not just rejected at
/// the first byte.
fn settings_text() -> impl Strategy<Value = String> {
    let key = prop::sample::select(vec![
        "fps",
        "diameter_m",
        "mass_kg",
        "scale_m_per_px",
        "roi",
        "downslope",
        "line_y_px",
        "line_tilt_deg",
        "tilt_deg",
    ]);
    let table = prop::sample::select(vec!["[ball]", "[camera]", "[surface]", "[session]", "[ball", "x"]);
    let value = prop::sample::select(vec![
        "0",
        "-1",
        "1e300",
        "-1e300",
        "nan",
        "inf",
        "0.067",
        "0.0567",
        "10000",
        "0.5",
        "\"+x\"",
        "\"-x\"",
        "[0, 0, 10, 10]",
        "[1, 2, 3]",
        "[-1, 0, 5, 5]",
        "true",
        "\"",
        "1e-300",
        "9223372036854775807",
    ]);
    prop::collection::vec((table, key, value), 0..8)
        .prop_map(|lines| lines.into_iter().map(|(t, k, v)| format!("{t}\n{k} = {v}\n")).collect())
}

fn csv_text() -> impl Strategy<Value = String> {
    let cell = prop::sample::select(vec![
        "shot", "../x", "/etc", "a b", "\"q", "\"\"", "0", "90", "-90", "1e300", "nan", "", "0.3", "-1", "#c", "clay",
    ]);
    let header = prop::sample::select(vec![
        "clip,surface,angle_deg,drop_height_m",
        "surface,clip,drop_height_m,angle_deg,notes",
        "clip,surface,angle_deg",
        "\"clip,surface,angle_deg,drop_height_m",
    ]);
    (header, prop::collection::vec(prop::collection::vec(cell, 0..6), 0..5)).prop_map(|(h, rows)| {
        let mut t = format!("{h}\n");
        for r in rows {
            t.push_str(&r.join(","));
            t.push('\n');
        }
        t
    })
}

proptest! {
    #![proptest_config(config(200))]

    /// Any `session.toml` and `clips.csv`: the session loads or fails with our error; what loads holds
    /// numbers inside their documented ranges and clips inside the folder.
    #[test]
    fn session_parsing_never_panics_and_accepts_only_sense(toml in settings_text(), csv in csv_text()) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("session.toml"), &toml).unwrap();
        std::fs::write(dir.path().join("clips.csv"), &csv).unwrap();
        std::fs::create_dir_all(dir.path().join("shot")).unwrap();
        if let Ok(s) = Session::load(dir.path()) {
            prop_assert!(s.ball.diameter_m > 0.0 && s.ball.diameter_m <= 1.0);
            prop_assert!(s.ball.mass_kg > 0.0 && s.ball.mass_kg <= 100.0);
            for c in &s.clips {
                prop_assert!(c.angle_deg.abs() < 90.0 && c.drop_height_m.is_finite());
                prop_assert!(c.fps >= 100.0 && c.fps <= 1e7);
                prop_assert!(c.dir.starts_with(dir.path()));
            }
            prop_assert!(!s.listed().is_empty());
        }
    }
}

/// Formulas from a small grammar over the documented variables, numbers in every notation, and any number
/// of parameter names.
fn formula() -> impl Strategy<Value = (String, Vec<String>)> {
    let leaf = prop_oneof![
        prop::sample::select(vec!["delta", "δ", "v_n", "v_t", "omega", "t", "P", "u_t"]).prop_map(str::to_string),
        prop::sample::select(vec!["1e3", "2.5E-4", "0", "1e308", "-1", "0.5", "1e-300", "3"]).prop_map(str::to_string),
        (0usize..40).prop_map(|i| format!("p{i}")),
    ];
    leaf.prop_recursive(4, 24, 3, |inner| {
        prop_oneof![
            (
                inner.clone(),
                prop::sample::select(vec!["+", "-", "*", "/", "^"]),
                inner.clone()
            )
                .prop_map(|(a, op, b)| format!("({a} {op} {b})")),
            (
                prop::sample::select(vec!["exp", "abs", "sqrt", "signum", "ln", "sin"]),
                inner.clone()
            )
                .prop_map(|(f, a)| format!("{f}({a})")),
            inner.prop_map(|a| format!("-{a}")),
        ]
    })
    .prop_map(|f| {
        let mut names: Vec<String> = (0..40)
            .map(|i| format!("p{i}"))
            .filter(|n| f.contains(n.as_str()))
            .collect();
        names.sort();
        names.dedup();
        (f, names)
    })
}

proptest! {
    #![proptest_config(config(120))]

    /// Any formula: `model.toml` parses or gives our error (never the parser's internals); a model that
    /// builds simulates one impact to an end or an error — no panic, no hang.
    #[test]
    fn formulas_parse_and_evaluate_without_panic((f, names) in formula(), value in prop::sample::select(vec![0.0, 1.0, 1e-3, 1e6])) {
        let params: String = names.iter().map(|n| format!("{n} = {value}\n")).collect();
        let text = format!(
            "{}\n[effects.x]\nkind = \"custom\"\nphase = \"contact\"\nnormal = \"{f}\"\n{params}",
            bouncelab_model::PAPER_MODEL_TOML
        );
        match ModelSpec::parse(&text, "fuzz.toml") {
            Err(e) => {
                let msg = e.to_string();
                prop_assert!(msg.contains("fuzz.toml"), "{msg}");
                prop_assert!(!msg.contains(" ops and ") && !msg.contains(" node"), "{msg}");
            }
            Ok(spec) => {
                if let Ok(model) = spec.build(Some("clay")) {
                    let start = State::flying(0.0, model.ball.radius_m, 0.0, -2.0);
                    let mut opts = SimOptions::default();
                    opts.max_steps = opts.max_steps.min(20_000);
                    let _ = simulate(&model, 0.0, 0.0, start, &[], &opts);
                }
            }
        }
    }

    /// Random text as `model.toml`: our error naming the file, or a model.
    #[test]
    fn model_files_of_noise_never_panic(text in "[\\[\\]a-z_.=\"{},0-9e+\\- \n]{0,300}") {
        if let Err(e) = ModelSpec::parse(&text, "noise.toml") {
            prop_assert!(e.to_string().contains("noise.toml"));
        }
    }
}
