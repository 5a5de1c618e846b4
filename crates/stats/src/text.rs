//! How a p-value is written in a sentence.

/// A p-value for a sentence: `"p < 0.001"` below 0.001, else `"p = "` with three decimals (`"p = 0.023"`,
/// `"p = 0.500"`, `"p = 1.000"`); `"p = n/a"` for NaN. Three decimals are what a reader compares
/// against 0.05 or 0.01; below 0.001 the exact value carries no decision a sentence needs (tables keep the
/// number itself).
pub fn p_text(p: f64) -> String {
    if p.is_nan() {
        "p = n/a".into()
    } else if p < 0.001 {
        "p < 0.001".into()
    } else {
        format!("p = {p:.3}")
    }
}

/// A test statistic for a sentence: three significant digits for ordinary sizes (`0.412`, `3.08`, `12.3`,
/// `255`), scientific outside 0.001…10⁵.
pub(crate) fn stat_text(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        format!("{v}")
    } else if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.2e}")
    } else {
        // Decimals from the value rounded to three significant digits, so 9.996 gives "10.0", not "10.00".
        let r = format!("{a:.2e}").parse::<f64>().unwrap_or(a);
        let decimals = (2 - r.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn convention() {
        assert_eq!(p_text(0.0234), "p = 0.023");
        assert_eq!(p_text(0.001), "p = 0.001");
        assert_eq!(p_text(0.000_999), "p < 0.001");
        assert_eq!(p_text(0.0), "p < 0.001");
        assert_eq!(p_text(0.5), "p = 0.500");
        assert_eq!(p_text(1.0), "p = 1.000");
        assert_eq!(p_text(f64::NAN), "p = n/a");
        assert_eq!(stat_text(255.3), "255");
        assert_eq!(stat_text(12.34), "12.3");
        assert_eq!(stat_text(3.084), "3.08");
        assert_eq!(stat_text(0.4123), "0.412");
        assert_eq!(stat_text(0.0856), "0.0856");
        assert_eq!(stat_text(2.5e-5), "2.50e-5");
        assert_eq!(stat_text(0.0), "0");
        assert_eq!(stat_text(9.996), "10.0");
        assert_eq!(stat_text(-1.5), "-1.50");
    }
}
