//! Bad input gives a named error, never a panic; the CSV form has the agreed columns.

use bouncelab_stats::{
    AncovaInference, AnovaType, CorObservation, Dataset, Observation, PAPER_TERMS, StatsError, TestOutcome, ancova,
    ancova_inference, anova, marginal_means, normality_test, quadratic_test, reset_test, residual_tests,
    tukey_hsd_unadjusted, write_anova_csv,
};

fn cor_rows() -> Vec<CorObservation> {
    (0..24)
        .map(|i| CorObservation {
            surface: ["clay", "tape1", "tape2"][i % 3].into(),
            angle: [0.0, 7.5, 15.0, 22.5][(i / 3) % 4],
            v_in_n: -2.0 - 0.01 * i as f64,
            cor: 0.72 + 0.003 * ((i * 37) % 11) as f64,
        })
        .collect()
}

#[test]
fn paper_terms_on_cor_rows() {
    let data = Dataset::from_cor(&cor_rows()).unwrap();
    assert_eq!(data.factor("angle").unwrap().levels, ["0", "7.5", "15", "22.5"]);
    let a = ancova(&data, &bouncelab_stats::PAPER_TERMS).unwrap();
    assert_eq!(a.type1.terms.len(), 3);
    assert_eq!(a.type1.total.df, 23);
    assert_eq!(a.type1.error.df, 24 - 7);
}

#[test]
fn single_level_factor_is_named() {
    let mut rows = cor_rows();
    rows.iter_mut().for_each(|r| r.surface = "clay".into());
    let data = Dataset::from_cor(&rows).unwrap();
    match anova(&data, &["surface", "angle"], AnovaType::TypeI) {
        Err(StatsError::SingleLevel { factor, level }) => {
            assert_eq!((factor.as_str(), level.as_str()), ("surface", "clay"))
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn collinear_covariate_is_singular() {
    let rows = cor_rows();
    let dummy: Vec<f64> = rows
        .iter()
        .map(|r| if r.surface == "tape1" { 1.0 } else { 0.0 })
        .collect();
    let data = Dataset::from_cor(&rows).unwrap().with_covariate("copy", dummy).unwrap();
    match anova(&data, &["surface", "copy"], AnovaType::TypeII) {
        Err(StatsError::SingularDesign { term }) => assert_eq!(term, "copy"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn nan_unknown_short_and_mismatched_inputs_are_errors() {
    let mut rows = cor_rows();
    rows[5].cor = f64::NAN;
    assert!(matches!(
        Dataset::from_cor(&rows),
        Err(StatsError::NonFinite { row: 5, .. })
    ));
    let data = Dataset::from_cor(&cor_rows()).unwrap();
    assert!(matches!(
        anova(&data, &["height"], AnovaType::TypeI),
        Err(StatsError::UnknownVariable { .. })
    ));
    assert!(matches!(
        anova(&data, &["surface", "surface"], AnovaType::TypeI),
        Err(StatsError::UnknownVariable { .. })
    ));
    let tiny = Dataset::from_cor(&cor_rows()[..4]).unwrap();
    assert!(matches!(
        anova(&tiny, &["surface", "angle", "v_in_n"], AnovaType::TypeI),
        Err(StatsError::TooFewObservations { .. })
    ));
    assert!(matches!(
        Dataset::new("y", vec![1.0, 2.0]).unwrap().with_factor("g", &["a"]),
        Err(StatsError::LengthMismatch { .. })
    ));
    assert!(matches!(
        tukey_hsd_unadjusted(&[1.0, 2.0], &["a", "b"], 0.05),
        Err(StatsError::TooFewObservations { .. })
    ));
    assert!(matches!(
        tukey_hsd_unadjusted(&[1.0, 2.0, 3.0], &["a", "b", "b"], 1.5),
        Err(StatsError::InvalidParameter { .. })
    ));
    let obs = vec![Observation::default(), {
        let mut o = Observation::default();
        o.factors.insert("g".into(), "x".into());
        o
    }];
    assert!(matches!(
        Dataset::from_observations("y", &obs),
        Err(StatsError::MissingValue { row: 1, .. })
    ));
}

#[test]
fn anova_csv_has_agreed_columns() {
    let data = Dataset::from_cor(&cor_rows()).unwrap();
    let a = ancova(&data, &bouncelab_stats::PAPER_TERMS).unwrap();
    let mut out = Vec::new();
    write_anova_csv(&mut out, &[&a.type1, &a.type2]).unwrap();
    let text = String::from_utf8(out).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "source,ss,df,ms,f,p,type");
    assert_eq!(lines.len(), 1 + 2 * 5);
    assert!(lines[1].starts_with("surface,") && lines[1].ends_with(",I"));
    assert!(
        lines[4].starts_with("Error,") && lines[4].ends_with(",,,I"),
        "{}",
        lines[4]
    );
    assert!(lines[10].starts_with("Total,") && lines[10].ends_with(",II"));
}

#[test]
fn inference_names_what_it_cannot_do() {
    let data = Dataset::from_cor(&cor_rows()).unwrap();
    match marginal_means(&data, &["surface", "v_in_n"], "angle", 0.05) {
        Err(StatsError::NotATerm { name, kind }) => assert_eq!((name.as_str(), kind), ("angle", "factor")),
        other => panic!("{other:?}"),
    }
    match quadratic_test(&data, &PAPER_TERMS, "surface") {
        Err(StatsError::NotATerm { name, kind }) => assert_eq!((name.as_str(), kind), ("surface", "covariate")),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        reset_test(&data, &PAPER_TERMS, 1),
        Err(StatsError::InvalidParameter { name: "max_power", .. })
    ));
    // Two groups with equal means: the fitted values are constant but for rounding, which must not be
    // standardised into a column.
    let two = Dataset::new("y", (0..10).map(|i| (i * 7 % 5) as f64).collect())
        .unwrap()
        .with_factor("g", &["a", "b", "a", "b", "a", "b", "a", "b", "a", "b"])
        .unwrap();
    let r = reset_test(&two, &["g"], 2);
    assert!(matches!(r, Err(StatsError::SingularDesign { .. })), "{r:?}");
    // Two groups with different means: the fitted values take two values, so their square is a
    // combination of the intercept and the group column.
    let two = Dataset::new(
        "y",
        (0..10).map(|i| (i % 2) as f64 + 0.1 * (i * 7 % 5) as f64).collect(),
    )
    .unwrap()
    .with_factor("g", &["a", "b", "a", "b", "a", "b", "a", "b", "a", "b"])
    .unwrap();
    let r = reset_test(&two, &["g"], 2);
    assert!(matches!(r, Err(StatsError::SingularDesign { .. })), "{r:?}");
    assert!(matches!(
        normality_test(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]),
        Err(StatsError::TooFewObservations { have: 7, need: 8, .. })
    ));
    assert!(matches!(normality_test(&[0.5; 12]), Err(StatsError::Degenerate { .. })));
    let mut rows = cor_rows();
    rows.iter_mut().for_each(|r| r.angle = 15.0);
    let flat = Dataset::from_cor(&rows).unwrap();
    assert!(matches!(
        ancova_inference(&flat, &PAPER_TERMS, 0.05),
        Err(StatsError::SingleLevel { .. })
    ));
    assert!(matches!(
        ancova_inference(&data, &PAPER_TERMS, 1.0),
        Err(StatsError::InvalidParameter { name: "alpha", .. })
    ));
}

/// Data a main-effects model fits exactly: every test would test rounding noise, so none runs.
#[test]
fn exact_fit_is_not_tested() {
    let rows: Vec<CorObservation> = (0..24)
        .map(|i| {
            let v = -2.0 - 0.01 * ((i * 7) % 11) as f64;
            CorObservation {
                surface: ["clay", "tape1", "tape2"][i % 3].into(),
                angle: [0.0, 7.5, 15.0, 22.5][(i / 3) % 4],
                v_in_n: v,
                cor: 0.7 + 0.01 * (i % 3) as f64 - 0.002 * ((i / 3) % 4) as f64 + 0.03 * v,
            }
        })
        .collect();
    let t = residual_tests(&Dataset::from_cor(&rows).unwrap(), &PAPER_TERMS, 0.05).unwrap();
    fn reason<T>(o: &TestOutcome<T>) -> Option<&str> {
        match o {
            TestOutcome::NotRun { reason } => Some(reason),
            TestOutcome::Ran(_) => None,
        }
    }
    let reasons = [reason(&t.reset), reason(&t.quadratic[0].test), reason(&t.normality)];
    for r in reasons {
        assert!(r.is_some_and(|r| r.contains("the fit is exact")), "{t:?}");
    }
    assert!(
        t.caption().starts_with("Curvature not tested (cannot compute"),
        "{}",
        t.caption()
    );
}

/// A small session: the curvature tests run, the normality test says why it cannot, and the caption
/// says so instead of claiming anything.
#[test]
fn small_session_caption_says_what_was_not_tested() {
    let rows: Vec<CorObservation> = (0..7)
        .map(|i| CorObservation {
            surface: ["clay", "tape1"][i % 2].into(),
            angle: 0.0,
            v_in_n: -1.5 - 0.2 * i as f64,
            cor: 0.72 + 0.01 * ((i * 5) % 3) as f64,
        })
        .collect();
    let data = Dataset::from_cor(&rows).unwrap();
    let t = residual_tests(&data, &["surface", "v_in_n"], 0.05).unwrap();
    assert!(t.reset.ran().is_some() && t.quadratic[0].test.ran().is_some(), "{t:?}");
    match &t.normality {
        TestOutcome::NotRun { reason } => assert!(reason.contains("have 7, need at least 8"), "{reason}"),
        other => panic!("{other:?}"),
    }
    let caption = t.caption();
    assert!(caption.ends_with("normality not tested (too few observations for the D'Agostino–Pearson normality test: have 7, need at least 8)."), "{caption}");
}

#[test]
fn inference_round_trips_through_json() {
    let data = Dataset::from_cor(&cor_rows()).unwrap();
    let inf = ancova_inference(&data, &PAPER_TERMS, 0.05).unwrap();
    assert_eq!(inf.marginal_means.len(), 2);
    assert_eq!(inf.means_of("angle").unwrap().pairs.len(), 6);
    let json = serde_json::to_string(&inf).unwrap();
    assert!(json.contains(r#""status":"ran""#), "{json}");
    let back: AncovaInference = serde_json::from_str(&json).unwrap();
    // serde_json's float parsing may be off by an ulp: compare the trees with a tolerance.
    fn same(a: &serde_json::Value, b: &serde_json::Value) -> bool {
        use serde_json::Value::*;
        match (a, b) {
            (Number(x), Number(y)) => {
                let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
                (x - y).abs() <= 1e-15 * x.abs().max(y.abs())
            }
            (Array(x), Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same(x, y)),
            (Object(x), Object(y)) => x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same(v, w))),
            _ => a == b,
        }
    }
    let (a, b) = (
        serde_json::to_value(&inf).unwrap(),
        serde_json::to_value(&back).unwrap(),
    );
    assert!(same(&a, &b), "{a}\n{b}");
    assert_eq!(back.residual_tests.caption(), inf.residual_tests.caption());
}
