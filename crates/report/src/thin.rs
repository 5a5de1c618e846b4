//! Thinning long series so the page stays small: markers keep every frame of interest and a regular
//! stride of the rest; lines are simplified in pixel space (Ramer–Douglas–Peucker), which keeps a smooth
//! model curve to within a fraction of a pixel with a few dozen vertices.

/// Indices of `n` points to draw, at most about `budget` of them: every index where `keep(i)` is true (up
/// to `budget`), then a regular stride of the others; sorted, first and last always included.
pub(crate) fn thin_indices(n: usize, budget: usize, keep: impl Fn(usize) -> bool) -> Vec<usize> {
    let budget = budget.max(2);
    if n <= budget {
        return (0..n).collect();
    }
    let kept: Vec<usize> = (0..n).filter(|&i| keep(i)).collect();
    let rest = n - kept.len();
    // At least a third of the budget goes to the other points, so the flight phases stay visible.
    let for_kept = kept.len().min(budget - budget / 3);
    let kept_stride = kept.len().div_ceil(for_kept.max(1)).max(1);
    let for_rest = budget.saturating_sub(for_kept).max(1);
    let rest_stride = rest.div_ceil(for_rest).max(1);
    let mut out = Vec::with_capacity(budget + 2);
    let (mut k, mut r) = (0usize, 0usize);
    for i in 0..n {
        let take = if keep(i) {
            k += 1;
            (k - 1) % kept_stride == 0
        } else {
            r += 1;
            (r - 1) % rest_stride == 0
        };
        if take || i == 0 || i == n - 1 {
            out.push(i);
        }
    }
    out
}

/// Ramer–Douglas–Peucker simplification of a polyline of finite pixel points: the vertices to keep so that
/// no dropped vertex lies farther than `tol` pixels from the simplified line. Iterative (no recursion),
/// first and last kept.
pub(crate) fn simplify(pts: &[(f64, f64)], tol: f64) -> Vec<(f64, f64)> {
    let n = pts.len();
    if n <= 2 {
        return pts.to_vec();
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let mut stack = vec![(0usize, n - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (ax, ay) = pts[a];
        let (bx, by) = pts[b];
        let (dx, dy) = (bx - ax, by - ay);
        let len = (dx * dx + dy * dy).sqrt();
        let mut worst = (0.0f64, a);
        for (i, &(px, py)) in pts.iter().enumerate().take(b).skip(a + 1) {
            let d = if len > 0.0 {
                ((px - ax) * dy - (py - ay) * dx).abs() / len
            } else {
                ((px - ax).powi(2) + (py - ay).powi(2)).sqrt()
            };
            if d > worst.0 {
                worst = (d, i);
            }
        }
        if worst.0 > tol {
            keep[worst.1] = true;
            stack.push((a, worst.1));
            stack.push((worst.1, b));
        }
    }
    pts.iter().zip(keep).filter(|(_, k)| *k).map(|(p, _)| *p).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinning_keeps_marked_points_and_ends() {
        let idx = thin_indices(1000, 100, |i| (500..540).contains(&i));
        assert!(idx.len() <= 110, "{}", idx.len());
        assert!((500..540).all(|i| idx.contains(&i)));
        assert_eq!(idx[0], 0);
        assert_eq!(*idx.last().unwrap(), 999);
        assert!(idx.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(thin_indices(5, 100, |_| false), vec![0, 1, 2, 3, 4]);
        assert!(thin_indices(100_000, 100, |_| true).len() <= 102);
    }

    #[test]
    fn simplification_of_a_parabola_is_within_tolerance() {
        let pts: Vec<(f64, f64)> = (0..=1000)
            .map(|i| (i as f64 * 0.6, (i as f64 - 500.0).powi(2) / 2000.0))
            .collect();
        let s = simplify(&pts, 0.25);
        assert!(s.len() < 60, "{}", s.len());
        assert_eq!(s[0], pts[0]);
        assert_eq!(*s.last().unwrap(), pts[1000]);
        // Straight line: two vertices.
        let line: Vec<(f64, f64)> = (0..100).map(|i| (i as f64, 2.0 * i as f64)).collect();
        assert_eq!(simplify(&line, 0.1).len(), 2);
    }
}
