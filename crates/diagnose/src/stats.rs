//! Small statistics: the white-noise level of residual series, the systematic part of a mean square, RMS
//! over shots, a paired test across shots, folds (Holm's correction is the stats crate's).

use crate::evaluate::ShotSums;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Sum of the squared coefficients of the third difference (1, −3, 3, −1).
const THIRD_DIFF_GAIN: f64 = 20.0;
/// Median of |N(0, 1)|.
const MEDIAN_ABS_NORMAL: f64 = 0.674_489_750_196_081_7;

/// White-noise standard deviation of residual series, m: the median absolute third difference of each
/// series (over runs of four equally spaced samples), divided by `0.6745·√20`.
///
/// A smooth misfit (a missing force changes the trajectory over milliseconds) hardly enters third
/// differences at 10 kHz, so this measures the tracking noise from the data, whatever σ the tracker
/// stated; the median ignores the few frames where the misfit has a kink (touch, separation). Returns
/// `None` with fewer than 8 differences.
pub(crate) fn white_noise(series: &[(Vec<f64>, Vec<f64>)]) -> Option<f64> {
    let mut d = Vec::new();
    for (t, r) in series {
        for k in 3..r.len().min(t.len()) {
            let (h1, h2, h3) = (t[k - 2] - t[k - 3], t[k - 1] - t[k - 2], t[k] - t[k - 1]);
            let equal = |a: f64, b: f64| (a - b).abs() <= 1e-3 * a.abs().max(b.abs());
            if !(h1 > 0.0 && equal(h1, h2) && equal(h2, h3)) {
                continue;
            }
            d.push((r[k] - 3.0 * r[k - 1] + 3.0 * r[k - 2] - r[k - 3]).abs());
        }
    }
    if d.len() < 8 {
        return None;
    }
    let mid = d.len() / 2;
    let (_, m, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*m / (MEDIAN_ABS_NORMAL * THIRD_DIFF_GAIN.sqrt()))
}

/// `√max(0, ms − noise²)`: the systematic part of a mean square, m.
pub(crate) fn excess(ms: f64, noise_m: f64) -> f64 {
    (ms - noise_m * noise_m).max(0.0).sqrt()
}

/// RMS over the residuals of the given shots, m (0 when there are none).
pub(crate) fn rms_of<'a>(sums: impl Iterator<Item = &'a ShotSums>) -> f64 {
    let (sq, n) = sums.fold((0.0, 0usize), |(a, n), s| (a + s.sq_m2, n + s.n));
    if n == 0 { 0.0 } else { (sq / n as f64).sqrt() }
}

/// One-sided paired test that the values `d` (e.g. per-shot log ratios of held-out errors) have a positive
/// mean: Student t with n − 1 degrees of freedom. Returns (mean, p); p = 1 with fewer than 2 values, 0
/// when every value is equal and positive.
pub(crate) fn one_sided_t(d: &[f64]) -> (f64, f64) {
    let n = d.len();
    if n < 2 {
        return (d.first().copied().unwrap_or(0.0), 1.0);
    }
    let mean = d.iter().sum::<f64>() / n as f64;
    let var = d.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1) as f64;
    let se = (var / n as f64).sqrt();
    if se.is_nan() || se <= 0.0 {
        return (mean, if mean > 0.0 { 0.0 } else { 1.0 });
    }
    let t = mean / se;
    let p = StudentsT::new(0.0, 1.0, (n - 1) as f64)
        .map(|dist| dist.sf(t))
        .unwrap_or(1.0);
    (mean, p)
}

/// Assigns shots to `k` folds, round-robin within each surface (in the order the shots are given), so
/// every fold holds some shots of every surface that has at least `k` shots.
pub(crate) fn folds(surfaces: &[&str], k: usize) -> Vec<usize> {
    let mut seen: Vec<(&str, usize)> = Vec::new();
    let mut next_start = 0usize;
    surfaces
        .iter()
        .map(|s| match seen.iter_mut().find(|(n, _)| n == s) {
            Some((_, c)) => {
                *c += 1;
                *c % k
            }
            None => {
                // Each surface starts where the previous left off, so small surfaces spread over folds.
                let start = next_start % k;
                next_start += 1;
                seen.push((s, start));
                start
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sided_t_of_a_clear_shift_is_small_and_of_noise_is_not() {
        let (m, p) = one_sided_t(&[1.0, 1.2, 0.9, 1.1, 1.05]);
        assert!(m > 1.0 && p < 1e-4, "{m} {p}");
        let (_, p) = one_sided_t(&[-0.1, 0.1, 0.05, -0.05]);
        assert!(p > 0.3, "{p}");
        assert_eq!(one_sided_t(&[1.0]).1, 1.0);
    }

    #[test]
    fn white_noise_sees_the_noise_and_not_a_smooth_curve() {
        let mut rng = bouncelab_fit::testutil::Rng::new(5);
        let t: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-4).collect();
        // A smooth misfit 100 times the noise.
        let r: Vec<f64> = t
            .iter()
            .map(|t| 1e-3 * (t * 300.0).sin() + 1e-5 * rng.normal())
            .collect();
        let s = white_noise(&[(t, r)]).unwrap();
        assert!((s / 1e-5 - 1.0).abs() < 0.1, "{s}");
        assert!(white_noise(&[(vec![0.0, 1.0], vec![0.0, 1.0])]).is_none());
    }

    #[test]
    fn folds_spread_every_surface() {
        let s = ["a", "a", "a", "b", "b", "a", "b", "c"];
        let f = folds(&s, 3);
        assert_eq!(f, vec![0, 1, 2, 1, 2, 0, 0, 2]);
    }
}
