//! Property tests: ANOVA identities, permutation invariance, studentized range CDF shape.

use bouncelab_stats::{
    AnovaType, Dataset, StudentizedRange, ancova_inference, anova, marginal_means, tukey_hsd_unadjusted_factor,
};

use proptest::prelude::*;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// (surface 0..3, angle 0..4, covariate, response) rows.
fn rows() -> impl Strategy<Value = Vec<(usize, usize, f64, f64)>> {
    prop::collection::vec((0usize..3, 0usize..4, -3.0f64..-1.0, 0.6f64..0.9), 12..60)
}

fn dataset(rows: &[(usize, usize, f64, f64)]) -> Dataset {
    let surf: Vec<String> = rows
        .iter()
        .map(|r| ["clay", "tape1", "tape2"][r.0].to_string())
        .collect();
    let ang: Vec<String> = rows
        .iter()
        .map(|r| ["0", "7.5", "15", "22.5"][r.1].to_string())
        .collect();
    Dataset::new("cor", rows.iter().map(|r| r.3).collect())
        .unwrap()
        .with_factor("surface", &surf)
        .unwrap()
        .with_factor("angle", &ang)
        .unwrap()
        .with_covariate("v_in_n", rows.iter().map(|r| r.2).collect())
        .unwrap()
}

const TERMS: [&str; 3] = ["surface", "angle", "v_in_n"];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn type1_ss_add_up_to_total(rows in rows()) {
        let data = dataset(&rows);
        // Designs that miss a level or are rank deficient are legitimately rejected.
        let Ok(t) = anova(&data, &TERMS, AnovaType::TypeI) else { return Ok(()); };
        let sum: f64 = t.terms.iter().map(|r| r.ss).sum::<f64>() + t.error.ss;
        prop_assert!(close(sum, t.total.ss, 1e-9), "{sum} vs {}", t.total.ss);
        let df: usize = t.terms.iter().map(|r| r.df).sum::<usize>() + t.error.df;
        prop_assert_eq!(df, t.total.df);
    }

    #[test]
    fn balanced_without_covariate_type1_equals_type2(
        y in prop::collection::vec(0.6f64..0.9, 24),
    ) {
        // 3 surfaces x 4 angles x 2 replicates.
        let rows: Vec<(usize, usize, f64, f64)> =
            (0..24).map(|i| (i % 3, (i / 3) % 4, -2.0, y[i])).collect();
        let data = dataset(&rows);
        let t1 = anova(&data, &["surface", "angle"], AnovaType::TypeI).unwrap();
        let t2 = anova(&data, &["angle", "surface"], AnovaType::TypeII).unwrap();
        for r in &t1.terms {
            let r2 = t2.row(&r.source).unwrap();
            prop_assert!(close(r.ss, r2.ss, 1e-9), "{}: {} vs {}", r.source, r.ss, r2.ss);
            prop_assert!(close(r.p.unwrap(), r2.p.unwrap(), 1e-8));
        }
    }

    #[test]
    fn permuting_rows_changes_nothing(
        (rows, order) in rows().prop_flat_map(|r| {
            let n = r.len();
            (Just(r), Just((0..n).collect::<Vec<usize>>()).prop_shuffle())
        })
    ) {
        let data = dataset(&rows);
        let shuffled = data.permuted(&order).unwrap();
        for kind in [AnovaType::TypeI, AnovaType::TypeII] {
            match (anova(&data, &TERMS, kind), anova(&shuffled, &TERMS, kind)) {
                (Ok(a), Ok(b)) => {
                    for (ra, rb) in a.rows().zip(b.rows()) {
                        prop_assert_eq!(&ra.source, &rb.source);
                        prop_assert!(close(ra.ss, rb.ss, 1e-9) || ra.ss.abs() < 1e-13,
                            "{} {:?}: {} vs {}", ra.source, kind, ra.ss, rb.ss);
                    }
                }
                (Err(_), Err(_)) => {}
                (a, b) => prop_assert!(false, "one failed: {:?} / {:?}", a.err(), b.err()),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn studentized_range_cdf_is_monotone_in_unit_interval(
        k in 2.0f64..12.0,
        df in prop_oneof![1.0f64..400.0, Just(f64::INFINITY)],
        q1 in 0.0f64..15.0,
        dq in 0.0f64..3.0,
    ) {
        let d = StudentizedRange::new(k, df).unwrap();
        let (c1, c2) = (d.cdf(q1), d.cdf(q1 + dq));
        prop_assert!((0.0..=1.0).contains(&c1) && (0.0..=1.0).contains(&c2));
        prop_assert!(c2 >= c1 - 1e-13, "cdf({q1}) = {c1} > cdf({}) = {c2}", q1 + dq);
        let s1 = d.sf(q1);
        prop_assert!((0.0..=1.0).contains(&s1));
        prop_assert!((c1 + s1 - 1.0).abs() < 1e-9, "cdf + sf = {}", c1 + s1);
    }
}

/// Tukey–Kramer on a shuffled copy gives the same comparisons (one fixed unbalanced case: the
/// studentized range quantile makes each call too slow for many proptest cases).
#[test]
fn tukey_is_permutation_invariant() {
    let rows: Vec<(usize, usize, f64, f64)> = (0..23)
        .map(|i| {
            (
                i % 3,
                i % 4,
                -2.0,
                0.7 + 0.01 * ((i * 7919) % 13) as f64 + 0.02 * (i % 3) as f64,
            )
        })
        .collect();
    let data = dataset(&rows);
    let order: Vec<usize> = (0..23).map(|i| (i * 5) % 23).collect();
    let shuffled = data.permuted(&order).unwrap();
    let a = tukey_hsd_unadjusted_factor(&data, "surface", 0.05).unwrap();
    let b = tukey_hsd_unadjusted_factor(&shuffled, "surface", 0.05).unwrap();
    assert_eq!(a.pairs.len(), 3);
    for (pa, pb) in a.pairs.iter().zip(&b.pairs) {
        assert_eq!((&pa.group1, &pa.group2), (&pb.group1, &pb.group2));
        assert!(close(pa.mean_diff, pb.mean_diff, 1e-9), "{pa:?} vs {pb:?}");
        assert!(close(pa.p_adj, pb.p_adj, 1e-8), "{pa:?} vs {pb:?}");
    }
}

/// With two levels the studentized range at |t|·√2 is the two-sided t test, so Tukey adjusts nothing and
/// its interval is the t interval; with three, Tukey's p is the larger. One case each: a studentized range
/// quantile is too slow for many proptest cases.
#[test]
fn tukey_on_two_levels_is_the_t_test() {
    let rows: Vec<(usize, usize, f64, f64)> = (0..20)
        .map(|i| {
            (
                i % 2,
                (i / 2) % 4,
                -1.5 - 0.05 * ((i * 7) % 9) as f64,
                0.7 + 0.004 * ((i * 5) % 7) as f64,
            )
        })
        .collect();
    let m = marginal_means(&dataset(&rows), &TERMS, "surface", 0.05).unwrap();
    let p = &m.pairs[0];
    assert!(close(p.p_tukey, p.p, 1e-9), "{p:?}");
    assert!(close(m.q_crit / std::f64::consts::SQRT_2, m.t_crit, 1e-9), "{m:?}");
    assert!(close(p.upper - p.estimate, m.t_crit * p.se, 1e-9), "{p:?}");
    let rows3: Vec<(usize, usize, f64, f64)> = (0..24)
        .map(|i| {
            (
                i % 3,
                (i / 3) % 4,
                -1.5 - 0.05 * ((i * 7) % 9) as f64,
                0.7 + 0.004 * ((i * 5) % 7) as f64,
            )
        })
        .collect();
    let m = marginal_means(&dataset(&rows3), &TERMS, "surface", 0.05).unwrap();
    for p in &m.pairs {
        assert!(p.p_tukey > p.p && p.p_tukey <= 1.0, "{p:?}");
    }
}

/// The inference on a shuffled copy is the same.
#[test]
fn inference_is_permutation_invariant() {
    let rows: Vec<(usize, usize, f64, f64)> = (0..23)
        .map(|i| {
            (
                i % 3,
                i % 4,
                -1.5 - 0.07 * ((i * 3) % 8) as f64,
                0.7 + 0.01 * ((i * 7919) % 13) as f64,
            )
        })
        .collect();
    let data = dataset(&rows);
    let order: Vec<usize> = (0..23).map(|i| (i * 5) % 23).collect();
    let a = ancova_inference(&data, &TERMS, 0.05).unwrap();
    let b = ancova_inference(&data.permuted(&order).unwrap(), &TERMS, 0.05).unwrap();
    for (x, y) in a.coefficients.rows.iter().zip(&b.coefficients.rows) {
        assert_eq!(x.name, y.name);
        assert!(
            close(x.estimate, y.estimate, 1e-9) && close(x.p, y.p, 1e-8),
            "{x:?} {y:?}"
        );
    }
    for (ma, mb) in a.marginal_means.iter().zip(&b.marginal_means) {
        for (x, y) in ma.pairs.iter().zip(&mb.pairs) {
            assert!(
                close(x.estimate, y.estimate, 1e-9) && close(x.p_tukey, y.p_tukey, 1e-8),
                "{x:?} {y:?}"
            );
            assert!(close(x.p_holm, y.p_holm, 1e-8), "{x:?} {y:?}");
        }
    }
    let (ra, rb) = (
        a.residual_tests.reset.ran().unwrap(),
        b.residual_tests.reset.ran().unwrap(),
    );
    assert!(close(ra.f, rb.f, 1e-7), "{ra:?} {rb:?}");
    let (na, nb) = (
        a.residual_tests.normality.ran().unwrap(),
        b.residual_tests.normality.ran().unwrap(),
    );
    assert!(close(na.k2, nb.k2, 1e-8), "{na:?} {nb:?}");
}
