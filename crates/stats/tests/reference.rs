//! Guards every number of the crate against statsmodels 0.15 / scipy 1.17 on the committed data sets in
//! `fixtures/stats/` (regenerate with `fixtures/stats/make_reference.py`; see its docstring).
//!
//! Tolerance: 1e-8 relative everywhere, except
//! * values that can be ~0 (residuals, studentized residuals, confidence limits, normal quantiles):
//!   also pass within 1e-12 absolute;
//! * statsmodels' Tukey p-values and scipy's studentized-range CDF: scipy integrates the CDF with
//!   `nquad(epsabs=1e-11)` and returns sf = 1 − cdf, so those are compared within 1e-8 relative + 5e-11
//!   absolute; the same p-values are compared at 1e-8 relative (no absolute slack) with the
//!   independent `*_quadpack` / `*_mpmath` integrals of the upper tail.

use std::cell::RefCell;
use std::fs::File;
use std::path::PathBuf;

use bouncelab_stats::{AnovaTable, AnovaType, Dataset, StudentizedRange, ancova, kurtosis, skewness};
use serde_json::Value;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/stats")
}

struct Checker {
    failures: RefCell<Vec<String>>,
    max_rel: RefCell<(f64, String)>,
    count: RefCell<usize>,
}

impl Checker {
    fn new() -> Self {
        Checker {
            failures: RefCell::new(Vec::new()),
            max_rel: RefCell::new((0.0, String::new())),
            count: RefCell::new(0),
        }
    }

    /// |actual − expected| ≤ rel·|expected| + abs.
    fn num(&self, what: &str, expected: f64, actual: f64, rel: f64, abs: f64) {
        *self.count.borrow_mut() += 1;
        let diff = (actual - expected).abs();
        let r = if expected != 0.0 { diff / expected.abs() } else { diff };
        if diff > abs && r > self.max_rel.borrow().0 {
            *self.max_rel.borrow_mut() = (r, what.to_string());
        }
        if diff.is_nan() || diff > rel * expected.abs() + abs {
            self.failures.borrow_mut().push(format!(
                "{what}: expected {expected:.17e}, actual {actual:.17e} (rel {r:.2e})"
            ));
        }
    }

    fn rel(&self, what: &str, expected: f64, actual: f64) {
        self.num(what, expected, actual, 1e-8, 0.0);
    }

    fn near0(&self, what: &str, expected: f64, actual: f64) {
        self.num(what, expected, actual, 1e-8, 1e-12);
    }

    fn fail(&self, msg: String) {
        self.failures.borrow_mut().push(msg);
    }

    fn finish(&self, name: &str) {
        let (r, w) = self.max_rel.borrow().clone();
        println!(
            "{name}: {} numbers checked, max relative error {r:.2e} ({w})",
            self.count.borrow()
        );
        let f = self.failures.borrow();
        assert!(f.is_empty(), "{} mismatches:\n{}", f.len(), f.join("\n"));
    }
}

fn reference() -> Value {
    let text = std::fs::read_to_string(fixtures().join("reference.json")).expect("reference.json");
    serde_json::from_str(&text).expect("reference.json parses")
}

fn load(file: &str) -> Dataset {
    let f = File::open(fixtures().join(file)).expect("fixture csv");
    Dataset::read_csv(f, "cor", &["surface", "angle"], &["v_in_n"]).expect("fixture csv parses")
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

fn arr(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(f).collect()
}

fn check_table(c: &Checker, label: &str, table: &AnovaTable, expected: &Value, total_ss: f64) {
    let rows = expected.as_array().expect("anova rows");
    for e in rows {
        let src = e["source"].as_str().unwrap();
        let Some(r) = table.row(src) else {
            c.fail(format!("{label}: no row {src}"));
            continue;
        };
        let w = |col: &str| format!("{label} {src} {col}");
        c.rel(&w("ss"), f(&e["ss"]), r.ss);
        c.num(&w("df"), f(&e["df"]), r.df as f64, 0.0, 0.0);
        if !e["ms"].is_null() {
            c.rel(&w("ms"), f(&e["ms"]), r.ms);
        }
        if !e["f"].is_null() {
            c.rel(&w("F"), f(&e["f"]), r.f.unwrap_or(f64::NAN));
            c.rel(&w("p"), f(&e["p"]), r.p.unwrap_or(f64::NAN));
        }
    }
    c.num(
        &format!("{label} row count"),
        rows.len() as f64,
        (table.terms.len() + 1) as f64,
        0.0,
        0.0,
    );
    c.rel(&format!("{label} Total ss"), total_ss, table.total.ss);
}

fn check_data_set(name: &str, file: &str) {
    let reference = reference();
    let e = &reference[name];
    let data = load(file);
    let c = Checker::new();
    c.num("n", f(&e["n"]), data.len() as f64, 0.0, 0.0);
    let a = ancova(&data, &["surface", "angle", "v_in_n"]).expect("ancova");
    let total_ss = f(&e["total_ss"]);
    check_table(&c, "type I", &a.type1, &e["anova_type1"], total_ss);
    check_table(&c, "type II", &a.type2, &e["anova_type2"], total_ss);
    assert_eq!(a.type1.kind, AnovaType::TypeI);

    for (sm_name, v) in e["params"].as_object().unwrap() {
        let ours = sm_name.replace("C(surface)", "surface").replace("C(angle)", "angle");
        match a.fit.coefficient_names.iter().position(|n| *n == ours) {
            Some(i) => c.rel(&format!("coef {ours}"), f(v), a.fit.coefficients[i]),
            None => c.fail(format!("no coefficient {ours} in {:?}", a.fit.coefficient_names)),
        }
    }
    let d = &a.diagnostics;
    for (key, ours, near0) in [
        ("fitted", &d.fitted, false),
        ("residuals", &d.residuals, true),
        ("leverage", &d.leverage, false),
        ("studentized_internal", &d.studentized_internal, true),
        ("studentized_external", &d.studentized_external, true),
    ] {
        let exp = arr(&e[key]);
        c.num(&format!("{key} length"), exp.len() as f64, ours.len() as f64, 0.0, 0.0);
        for (i, (x, y)) in exp.iter().zip(ours).enumerate() {
            if near0 {
                c.near0(&format!("{key}[{i}]"), *x, *y);
            } else {
                c.rel(&format!("{key}[{i}]"), *x, *y);
            }
        }
    }
    for (i, (x, p)) in arr(&e["normal_plot_quantiles"]).iter().zip(&d.normal_plot).enumerate() {
        c.near0(&format!("normal quantile[{i}]"), *x, p.normal_quantile);
    }
    let mut sorted = d.residuals.clone();
    sorted.sort_by(f64::total_cmp);
    for (s, p) in sorted.iter().zip(&d.normal_plot) {
        c.num("normal plot order", *s, p.residual, 0.0, 0.0);
    }
    c.rel("residual skewness", f(&e["residual_skewness"]), d.residual_skewness);
    c.rel("residual kurtosis", f(&e["residual_kurtosis"]), d.residual_kurtosis);
    c.rel(
        "cor skewness",
        f(&e["cor_skewness"]),
        skewness(data.response()).unwrap(),
    );
    c.rel(
        "cor kurtosis",
        f(&e["cor_kurtosis"]),
        kurtosis(data.response()).unwrap(),
    );

    let t = &e["tukey"];
    let ours = bouncelab_stats::tukey_hsd_factor(&data, "surface", f(&t["alpha"])).expect("tukey");
    c.num("tukey df", f(&t["df"]), ours.df as f64, 0.0, 0.0);
    c.rel("tukey q_crit (scipy ppf)", f(&t["q_crit"]), ours.q_crit);
    for g in &ours.groups {
        c.rel(&format!("mean {}", g.name), f(&t["group_means"][&g.name]), g.mean);
    }
    let pairs = t["pairs"].as_array().unwrap();
    c.num(
        "tukey pair count",
        pairs.len() as f64,
        ours.pairs.len() as f64,
        0.0,
        0.0,
    );
    for (ep, op) in pairs.iter().zip(&ours.pairs) {
        let w = |col: &str| format!("tukey {}-{} {col}", op.group1, op.group2);
        if ep["group1"] != op.group1.as_str() || ep["group2"] != op.group2.as_str() {
            c.fail(format!(
                "pair order: expected {} {}, got {} {}",
                ep["group1"], ep["group2"], op.group1, op.group2
            ));
        }
        c.rel(&w("meandiff"), f(&ep["meandiff"]), op.mean_diff);
        c.rel(&w("std"), f(&ep["std_pair"]), op.std_err);
        c.rel(&w("q"), f(&ep["q"]), op.q);
        c.num(&w("p-adj vs statsmodels/scipy"), f(&ep["p_adj"]), op.p_adj, 1e-8, 5e-11);
        c.rel(&w("p-adj vs quadpack"), f(&ep["p_adj_quadpack"]), op.p_adj);
        c.near0(&w("lower"), f(&ep["lower"]), op.lower);
        c.near0(&w("upper"), f(&ep["upper"]), op.upper);
        if ep["reject"].as_bool() != Some(op.reject) {
            c.fail(format!("{}: expected {}, got {}", w("reject"), ep["reject"], op.reject));
        }
    }
    c.finish(name);
}

#[test]
fn paper_design_matches_statsmodels() {
    check_data_set("paper_design", "cor_paper_design.csv");
}

#[test]
fn unbalanced_matches_statsmodels() {
    check_data_set("unbalanced", "cor_unbalanced.csv");
    // The point of this data set: sequential and Type II sums of squares differ.
    let a = ancova(&load("cor_unbalanced.csv"), &["surface", "angle", "v_in_n"]).unwrap();
    let (s1, s2) = (a.type1.row("surface").unwrap().ss, a.type2.row("surface").unwrap().ss);
    assert!((s1 - s2).abs() > 1e-6 * s1, "type I {s1} == type II {s2}");
}

#[test]
fn studentized_range_matches_reference_integrals() {
    let reference = reference();
    let c = Checker::new();
    for case in reference["studentized_range"].as_array().unwrap() {
        let (q, k) = (f(&case["q"]), f(&case["k"]));
        let df = if case["df"] == "inf" {
            f64::INFINITY
        } else {
            f(&case["df"])
        };
        let d = StudentizedRange::new(k, df).unwrap();
        let w = |col: &str| format!("srange q {q} k {k} df {df} {col}");
        c.rel(&w("sf vs quadpack"), f(&case["sf_quadpack"]), d.sf(q));
        c.num(&w("cdf vs scipy"), f(&case["cdf_scipy"]), d.cdf(q), 1e-8, 5e-11);
        if !case["cdf_mpmath"].is_null() {
            c.rel(&w("cdf vs mpmath"), f(&case["cdf_mpmath"]), d.cdf(q));
            c.rel(&w("sf vs mpmath"), f(&case["sf_mpmath"]), d.sf(q));
        }
    }
    // 20-digit mpmath double integral, recorded in make_reference.py's note.
    let d = StudentizedRange::new(3.0, 141.0).unwrap();
    c.rel("srange sf(3.5, 3, 141) vs mpmath", 0.038_341_746_795_273_42, d.sf(3.5));
    c.finish("studentized range");
}
