//! Escaping and number formatting shared by the HTML and the SVG.

use std::fmt::Write;

/// `s` with `& < > " '` replaced by entities: safe in element content and in quoted attributes, in HTML
/// and in inline SVG.
pub(crate) fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            // Control characters other than tab and newline are not allowed in HTML text.
            c if c.is_control() && c != '\n' && c != '\t' => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

/// [`esc`] of a sentence in which `name` in backticks marks a name to type (an effect, a command): those
/// spans become `<code>`, an unpaired backtick stays as it is; outside them a power written `x^1.5`,
/// `δ^n` or `m^(1+n)` becomes a superscript.
pub(crate) fn esc_code(s: &str) -> String {
    let parts: Vec<&str> = s.split('`').collect();
    if parts.len() < 3 {
        return powers(&esc(s));
    }
    let mut out = String::with_capacity(s.len() + 16);
    let pairs = (parts.len() - 1) / 2;
    for (i, p) in parts.iter().enumerate() {
        if i % 2 == 1 && i < 2 * pairs {
            out.push_str("<code>");
            out.push_str(&esc(p));
            out.push_str("</code>");
        } else {
            if i > 2 * pairs {
                out.push('`');
            }
            out.push_str(&powers(&esc(p)));
        }
    }
    out
}

/// `^(…)` and `^token` (letters, digits, `.`, `+`, `-`) of escaped text as `<sup>`.
fn powers(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find('^') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        let (exp, tail) = if let Some(inner) = after.strip_prefix('(') {
            match inner.find(')') {
                Some(j) => (&inner[..j], &inner[j + 1..]),
                None => ("", after),
            }
        } else {
            let end = after
                .char_indices()
                .find(|(k, c)| !(c.is_alphanumeric() || *c == '.' || ((*c == '+' || *c == '-') && *k == 0)))
                .map_or(after.len(), |(k, _)| k);
            // A trailing full stop ends the sentence, not the exponent.
            let end = if after[..end].ends_with('.') { end - 1 } else { end };
            (&after[..end], &after[end..])
        };
        if exp.is_empty() {
            out.push('^');
            rest = after;
        } else {
            out.push_str("<sup>");
            out.push_str(exp);
            out.push_str("</sup>");
            rest = tail;
        }
    }
    out.push_str(rest);
    out
}

/// A typographic minus sign for negative numbers.
fn minus(s: String) -> String {
    if let Some(rest) = s.strip_prefix('-') {
        format!("\u{2212}{rest}")
    } else {
        s
    }
}

fn non_finite(v: f64) -> Option<String> {
    if v.is_nan() {
        Some("NaN".into())
    } else if v.is_infinite() {
        Some(if v > 0.0 { "∞".into() } else { "\u{2212}∞".into() })
    } else {
        None
    }
}

/// `v` with `sig` significant digits: fixed notation between 1e-3 and 1e6, scientific outside; a NaN
/// or infinity is spelled out.
pub(crate) fn num(v: f64, sig: usize) -> String {
    if let Some(s) = non_finite(v) {
        return s;
    }
    if v == 0.0 {
        return "0".into();
    }
    let sig = sig.clamp(1, 15);
    let mag = v.abs().log10().floor() as i32;
    if (-3..6).contains(&mag) {
        let decimals = (sig as i32 - 1 - mag).max(0) as usize;
        minus(format!("{v:.decimals$}"))
    } else {
        minus(format!("{v:.prec$e}", prec = sig - 1))
    }
}

/// [`num`] without trailing zeros after the decimal point (7.50 → 7.5, 15.0 → 15): for settings such as
/// angles and levels rather than measurements.
pub(crate) fn short(v: f64, sig: usize) -> String {
    let s = num(v, sig);
    if s.contains('e') || !s.contains('.') {
        return s;
    }
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// An optional number, "—" when absent.
pub(crate) fn opt(v: Option<f64>, sig: usize) -> String {
    v.map_or_else(|| "—".into(), |v| num(v, sig))
}

/// `v` with a fixed number of decimals (NaN and infinity spelled out; beyond 1e9 in scientific notation).
pub(crate) fn fixed(v: f64, decimals: usize) -> String {
    if let Some(s) = non_finite(v) {
        return s;
    }
    if v.abs() >= 1e9 {
        return num(v, 4);
    }
    let s = format!("{v:.decimals$}");
    // "-0.00" is zero.
    if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
        s.trim_start_matches('-').into()
    } else {
        minus(s)
    }
}

/// A p-value: three decimals down to 0.001, two significant digits in scientific notation below.
pub(crate) fn p_value(p: f64) -> String {
    if !p.is_finite() {
        return num(p, 2);
    }
    if p >= 0.01 {
        fixed(p, 3)
    } else if p >= 0.001 {
        fixed(p, 4)
    } else {
        num(p, 2)
    }
}

/// A value in metres shown in micrometres (residuals), one decimal below 100 µm.
pub(crate) fn um(v_m: f64) -> String {
    let v = v_m * 1e6;
    if v.is_finite() && v.abs() < 100.0 {
        fixed(v, 1)
    } else {
        num(v, 3)
    }
}

/// A value and its standard error, the error to two significant digits and the value to the same decimal
/// place ("0.7160", "0.0012"; "123.4", "5.6"), so the error is never shown as zero; without a usable error
/// the value to `sig` significant digits and `None`.
pub(crate) fn pm(v: f64, se: Option<f64>, sig: usize) -> (String, Option<String>) {
    match se.filter(|e| e.is_finite() && *e > 0.0) {
        Some(e) if v.is_finite() && v.abs() < 1e9 && e < 1e9 => {
            let decimals = (1 - e.log10().floor() as i32).clamp(0, 12) as usize;
            (fixed(v, decimals), Some(fixed(e, decimals)))
        }
        _ => (num(v, sig), None),
    }
}

/// [`pm`] as one text: "0.7160 ± 0.0012", or the value alone.
pub(crate) fn pm_text(v: f64, se: Option<f64>, sig: usize) -> String {
    match pm(v, se, sig) {
        (v, Some(e)) => format!("{v} ± {e}"),
        (v, None) => v,
    }
}

/// A pixel coordinate for SVG: one decimal, no trailing ".0", clamped to ±1e5 (never NaN).
pub(crate) fn coord(v: f64) -> String {
    let mut s = String::new();
    push_coord(&mut s, v);
    s
}

/// Appends [`coord`] of `v` to `out`.
pub(crate) fn push_coord(out: &mut String, v: f64) {
    let v = if v.is_nan() { 0.0 } else { v.clamp(-1e5, 1e5) };
    let tenths = (v * 10.0).round() as i64;
    if tenths < 0 {
        out.push('-');
    }
    let a = tenths.unsigned_abs();
    let _ = write!(out, "{}", a / 10);
    if !a.is_multiple_of(10) {
        let _ = write!(out, ".{}", a % 10);
    }
}

/// A string usable as an HTML id and URL fragment: ASCII letters, digits, `-`, `_` and `.` kept, anything
/// else replaced by `_`.
pub(crate) fn slug(s: &str) -> String {
    let out: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if out.is_empty() { "_".into() } else { out }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup() {
        assert_eq!(esc(r#"<a href="x">&'"#), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
        assert_eq!(esc("a\u{0}b"), "a\u{FFFD}b");
    }

    #[test]
    fn backticks_become_code() {
        assert_eq!(
            esc_code("add `hertz` & <go>"),
            "add <code>hertz</code> &amp; &lt;go&gt;"
        );
        assert_eq!(esc_code("a `b` c `d"), "a <code>b</code> c `d");
        assert_eq!(esc_code("`<x>`"), "<code>&lt;x&gt;</code>");
        assert_eq!(esc_code("no ticks"), "no ticks");
        assert_eq!(esc_code("P = λ·δ^n·dδ/dt"), "P = λ·δ<sup>n</sup>·dδ/dt");
        assert_eq!(
            esc_code("N·s/m^(1+n) and k·δ^1.5."),
            "N·s/m<sup>1+n</sup> and k·δ<sup>1.5</sup>."
        );
        assert_eq!(esc_code("a ^ b"), "a ^ b");
    }

    #[test]
    fn numbers() {
        assert_eq!(num(0.77012, 4), "0.7701");
        assert_eq!(num(25650.0, 4), "25650");
        assert_eq!(num(-0.04123, 3), "\u{2212}0.0412");
        assert_eq!(num(1.5e-7, 2), "1.5e-7");
        assert_eq!(num(f64::NAN, 3), "NaN");
        assert_eq!(num(f64::NEG_INFINITY, 3), "\u{2212}∞");
        assert_eq!(num(f64::MAX, 3), "1.80e308");
        assert_eq!(num(5e-324, 3), "4.94e-324");
        assert_eq!(fixed(-0.0001, 2), "0.00");
        assert_eq!(fixed(2.5e307, 3), "2.500e307");
        assert_eq!(p_value(0.0432), "0.043");
        assert_eq!(p_value(0.0014), "0.0014");
        assert_eq!(short(7.5, 3), "7.5");
        assert_eq!(short(15.0, 3), "15");
        assert_eq!(short(0.05, 3), "0.05");
        assert_eq!(short(1e-7, 3), "1.00e-7");
        assert_eq!(p_value(2.1e-9), "2.1e-9");
        assert_eq!(um(7.8e-6), "7.8");
        assert_eq!(um(1.234e-4), "123");
    }

    #[test]
    fn errors_set_the_digits_and_are_never_zero() {
        assert_eq!(
            pm(0.68612, Some(0.00031), 3),
            ("0.68612".into(), Some("0.00031".into()))
        );
        assert_eq!(pm_text(0.686, Some(0.0004), 3), "0.68600 ± 0.00040");
        assert_eq!(pm_text(123.44, Some(5.6), 3), "123.4 ± 5.6");
        assert_eq!(pm_text(1234.0, Some(56.0), 3), "1234 ± 56");
        assert_eq!(pm_text(0.5, Some(0.0), 3), "0.500");
        assert_eq!(pm_text(0.5, Some(f64::NAN), 3), "0.500");
        assert_eq!(pm_text(f64::NAN, Some(0.1), 3), "NaN");
    }

    #[test]
    fn coords() {
        assert_eq!(coord(12.34), "12.3");
        assert_eq!(coord(12.0), "12");
        assert_eq!(coord(-0.04), "0");
        assert_eq!(coord(-3.06), "-3.1");
        assert_eq!(coord(f64::NAN), "0");
        assert_eq!(coord(1e300), "100000");
    }

    #[test]
    fn slugs() {
        assert_eq!(slug("a&b\"<x>"), "a_b__x_");
        assert_eq!(slug(""), "_");
        assert_eq!(slug("S001-clay_0.5"), "S001-clay_0.5");
    }
}
