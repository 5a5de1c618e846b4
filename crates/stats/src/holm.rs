//! Holm's step-down adjustment of a family of p-values.

/// Holm's step-down adjusted p-values, in the order given: sort ascending, multiply the i-th smallest
/// (i = 0, 1, …) by m − i, carry the running maximum forward and cap at 1. The result is ≥ the raw p,
/// ≤ 1, and monotone in the raw p; reject a hypothesis at family-wise level α when its adjusted p ≤ α
/// (R's `p.adjust(p, "holm")`, statsmodels' `multipletests(p, method="holm")`).
///
/// A NaN p stays NaN and counts in m (as R's default), sorted last so the others are unaffected. Ties
/// get equal adjusted values whatever their order.
pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    // NaN last, then ascending; the index breaks ties so the result does not depend on the sort.
    order.sort_by(|&a, &b| {
        p[a].is_nan()
            .cmp(&p[b].is_nan())
            .then(p[a].total_cmp(&p[b]))
            .then(a.cmp(&b))
    });
    let mut out = vec![f64::NAN; m];
    let mut running = 0.0f64;
    for (rank, &i) in order.iter().enumerate() {
        if p[i].is_nan() {
            break;
        }
        running = running.max(((m - rank) as f64 * p[i]).min(1.0));
        out[i] = running;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn hand_computed_case() {
        // Sorted: 0.005·4 = 0.02, 0.01·3 = 0.03, 0.03·2 = 0.06, 0.04·1 = 0.04 → running max 0.06.
        let adj = holm(&[0.01, 0.04, 0.03, 0.005]);
        for (a, w) in adj.iter().zip([0.03, 0.06, 0.06, 0.02]) {
            assert!((a - w).abs() < 1e-15, "{adj:?}");
        }
        assert!(holm(&[]).is_empty());
        assert_eq!(holm(&[0.7]), vec![0.7]);
        let with_nan = holm(&[0.01, f64::NAN, 0.02]);
        assert!(with_nan[1].is_nan());
        assert!(
            (with_nan[0] - 0.03).abs() < 1e-15 && (with_nan[2] - 0.04).abs() < 1e-15,
            "{with_nan:?}"
        );
    }

    proptest! {
        #[test]
        fn adjusted_is_bounded_monotone_and_order_free(p in prop::collection::vec(0.0f64..=1.0, 0..30)) {
            let adj = holm(&p);
            prop_assert_eq!(adj.len(), p.len());
            for i in 0..p.len() {
                prop_assert!(adj[i] >= p[i] && adj[i] <= 1.0, "{} -> {}", p[i], adj[i]);
                for j in 0..p.len() {
                    if p[i] <= p[j] {
                        prop_assert!(adj[i] <= adj[j], "p {} <= {} but adj {} > {}", p[i], p[j], adj[i], adj[j]);
                    }
                }
            }
            let rev: Vec<f64> = p.iter().rev().copied().collect();
            let adj_rev = holm(&rev);
            for (a, b) in adj.iter().zip(adj_rev.iter().rev()) {
                prop_assert_eq!(a, b);
            }
        }
    }
}
