//! Bad input gives a named error, never a panic; the CSV form has the agreed columns.

use bouncelab_stats::{
    AnovaType, CorObservation, Dataset, Observation, StatsError, ancova, anova, tukey_hsd, write_anova_csv,
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
        tukey_hsd(&[1.0, 2.0], &["a", "b"], 0.05),
        Err(StatsError::TooFewObservations { .. })
    ));
    assert!(matches!(
        tukey_hsd(&[1.0, 2.0, 3.0], &["a", "b", "b"], 1.5),
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
