//! Guards every number of the crate against statsmodels 0.15 / scipy 1.17 on the committed data sets in
//! `fixtures/stats/` (regenerate with `fixtures/stats/make_reference.py`; see its docstring): ANOVA
//! tables, fit and influence, coefficient table, one-way Tukey, estimated marginal means and their
//! Tukey/Holm comparisons, RESET, the quadratic-term test, D'Agostino–Pearson, straight lines (OLS, WLS),
//! Holm, the studentized range.
//!
//! Tolerance: 1e-8 relative everywhere, except
//! * values that can be ~0 (residuals, studentized residuals, confidence limits, normal quantiles,
//!   differences of marginal means and their t): also pass within 1e-12 absolute;
//! * statsmodels' Tukey p-values and scipy's studentized-range CDF: scipy integrates the CDF with
//!   `nquad(epsabs=1e-11)` and returns sf = 1 − cdf, so those are compared within 1e-8 relative + 5e-11
//!   absolute; the same p-values are compared at 1e-8 relative (no absolute slack) with the
//!   independent `*_quadpack` / `*_mpmath` integrals of the upper tail.

use std::cell::RefCell;
use std::fs::File;
use std::path::PathBuf;

use bouncelab_stats::{
    AncovaInference, AnovaTable, AnovaType, Dataset, FTest, PAPER_TERMS, StudentizedRange, TestOutcome, ancova,
    ancova_inference, fit_line, holm, kurtosis, normality_test, quadratic_test, reset_test, skewness,
    tukey_hsd_unadjusted_factor,
};
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
    Dataset::read_csv(f, "cor", &["surface", "angle"], &["v_in_n", "height_m"]).expect("fixture csv parses")
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

/// Checks every number of one data set; returns the inference for further checks.
fn check_data_set(name: &str, file: &str) -> AncovaInference {
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
    let ours = tukey_hsd_unadjusted_factor(&data, "surface", f(&t["alpha"])).expect("tukey");
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
    let inf = check_inference(&c, e, &data);
    c.finish(name);
    inf
}

fn check_f(c: &Checker, label: &str, e: &Value, t: &FTest) {
    c.rel(&format!("{label} F"), f(&e["f"]), t.f);
    c.rel(&format!("{label} p"), f(&e["p"]), t.p);
    c.num(&format!("{label} df_num"), f(&e["df_num"]), t.df_num as f64, 0.0, 0.0);
    c.num(&format!("{label} df_den"), f(&e["df_den"]), t.df_den as f64, 0.0, 0.0);
}

/// Coefficient table, marginal means and their comparisons, residual tests and straight lines.
fn check_inference(c: &Checker, e: &Value, data: &Dataset) -> AncovaInference {
    let inf = ancova_inference(data, &PAPER_TERMS, 0.05).expect("ancova_inference");

    let coefs = e["coefficients"].as_object().expect("coefficients");
    c.num(
        "coefficient count",
        coefs.len() as f64,
        inf.coefficients.rows.len() as f64,
        0.0,
        0.0,
    );
    for (name, ec) in coefs {
        let Some(r) = inf.coefficients.row(name) else {
            c.fail(format!("no coefficient {name}"));
            continue;
        };
        let w = |col: &str| format!("coef {name} {col}");
        c.rel(&w("estimate"), f(&ec["estimate"]), r.estimate);
        c.rel(&w("se"), f(&ec["se"]), r.se);
        c.near0(&w("t"), f(&ec["t"]), r.t);
        c.rel(&w("p"), f(&ec["p"]), r.p);
        c.near0(&w("lower"), f(&ec["lower"]), r.lower);
        c.near0(&w("upper"), f(&ec["upper"]), r.upper);
    }

    for factor in ["surface", "angle"] {
        let em = &e["marginal_means"][factor];
        let Some(ours) = inf.means_of(factor) else {
            c.fail(format!("no marginal means of {factor}"));
            continue;
        };
        let w = |col: &str| format!("emm {factor} {col}");
        c.num(&w("df"), f(&em["df"]), ours.df as f64, 0.0, 0.0);
        c.rel(&w("mse"), f(&em["mse"]), ours.mse);
        c.rel(&w("t_crit (scipy t.ppf)"), f(&em["t_crit"]), ours.t_crit);
        c.rel(&w("q_crit (scipy ppf)"), f(&em["q_crit"]), ours.q_crit);
        match ours.covariates_at.as_slice() {
            [g] if g.name == "v_in_n" => c.rel(&w("grid v_in_n"), f(&em["v_in_n_mean"]), g.value),
            other => c.fail(format!("{}: grid {other:?}", w("covariates_at"))),
        }
        let means = em["means"].as_array().expect("means");
        c.num(&w("level count"), means.len() as f64, ours.means.len() as f64, 0.0, 0.0);
        for (m, o) in means.iter().zip(&ours.means) {
            let w = |col: &str| format!("emm {factor} {} {col}", o.level);
            // pandas reads angles as floats: "7.5", "15.0" as written in the CSV.
            if m["level"].as_str() != Some(o.level.as_str()) {
                c.fail(format!("{}: expected {}", w("level"), m["level"]));
            }
            c.num(&w("n"), f(&m["n"]), o.n as f64, 0.0, 0.0);
            c.rel(&w("raw mean"), f(&m["raw_mean"]), o.raw_mean);
            c.rel(&w("estimate"), f(&m["estimate"]), o.estimate);
            c.rel(&w("se"), f(&m["se"]), o.se);
            c.rel(&w("lower"), f(&m["lower"]), o.lower);
            c.rel(&w("upper"), f(&m["upper"]), o.upper);
        }
        let pairs = em["pairs"].as_array().expect("pairs");
        c.num(&w("pair count"), pairs.len() as f64, ours.pairs.len() as f64, 0.0, 0.0);
        for (p, o) in pairs.iter().zip(&ours.pairs) {
            let w = |col: &str| format!("emm {factor} {} − {} {col}", o.level2, o.level1);
            if p["level1"].as_str() != Some(o.level1.as_str()) || p["level2"].as_str() != Some(o.level2.as_str()) {
                c.fail(format!("{}: expected {} {}", w("order"), p["level1"], p["level2"]));
            }
            c.near0(&w("estimate"), f(&p["estimate"]), o.estimate);
            c.rel(&w("se"), f(&p["se"]), o.se);
            c.near0(&w("t"), f(&p["t"]), o.t);
            c.rel(&w("p (t_test)"), f(&p["p"]), o.p);
            c.num(&w("p tukey vs scipy"), f(&p["p_tukey"]), o.p_tukey, 1e-8, 5e-11);
            c.rel(&w("p tukey vs quadpack"), f(&p["p_tukey_quadpack"]), o.p_tukey);
            c.rel(&w("p holm (multipletests)"), f(&p["p_holm"]), o.p_holm);
            c.near0(&w("lower"), f(&p["lower"]), o.lower);
            c.near0(&w("upper"), f(&p["upper"]), o.upper);
            for (key, ours) in [("reject_tukey", o.reject_tukey), ("reject_holm", o.reject_holm)] {
                if p[key].as_bool() != Some(ours) {
                    c.fail(format!("{}: expected {}, got {ours}", w(key), p[key]));
                }
            }
        }
    }

    let rt = &e["residual_tests"];
    check_f(
        c,
        "RESET power 2",
        &rt["reset_power2"],
        &reset_test(data, &PAPER_TERMS, 2).expect("reset 2"),
    );
    check_f(
        c,
        "RESET power 3",
        &rt["reset_power3"],
        &reset_test(data, &PAPER_TERMS, 3).expect("reset 3"),
    );
    check_f(
        c,
        "quadratic v_in_n",
        &rt["quadratic_v_in_n"],
        &quadratic_test(data, &PAPER_TERMS, "v_in_n").expect("quadratic"),
    );
    let tests = &inf.residual_tests;
    match (&tests.reset, tests.quadratic.as_slice()) {
        (TestOutcome::Ran(r), [q]) if q.covariate == "v_in_n" => {
            check_f(c, "inference RESET", &rt["reset_power2"], r);
            match &q.test {
                TestOutcome::Ran(t) => check_f(c, "inference quadratic", &rt["quadratic_v_in_n"], t),
                other => c.fail(format!("quadratic test not run: {other:?}")),
            }
        }
        other => c.fail(format!("residual tests: {other:?}")),
    }
    let en = &rt["normality"];
    let fit = &ancova(data, &PAPER_TERMS).expect("ancova").fit;
    let n = normality_test(&fit.residuals).expect("normality");
    c.rel("normaltest K2", f(&en["k2"]), n.k2);
    c.rel("normaltest p", f(&en["p"]), n.p);
    c.near0("skewtest z", f(&en["z_skewness"]), n.z_skewness);
    c.rel("skewtest p", f(&en["p_skewness"]), n.p_skewness);
    c.near0("kurtosistest z", f(&en["z_kurtosis"]), n.z_kurtosis);
    c.rel("kurtosistest p", f(&en["p_kurtosis"]), n.p_kurtosis);
    if tests.normality != TestOutcome::Ran(n) {
        c.fail(format!("inference normality differs: {:?}", tests.normality));
    }
    // The caption follows the reference p-values at alpha = 0.05.
    let caption = tests.caption();
    let curved = f(&rt["reset_power2"]["p"]) < 0.05 || f(&rt["quadratic_v_in_n"]["p"]) < 0.05;
    if caption.starts_with("Residuals curve with") != curved
        || caption.starts_with("No curvature detected") == curved
        || caption.contains("residuals are not normal") != (f(&en["p"]) < 0.05)
    {
        c.fail(format!("caption disagrees with the reference p-values: {caption}"));
    }
    println!("caption: {caption}");

    for (surface, el) in e["lines"].as_object().expect("lines") {
        let rows: Vec<usize> = (0..data.len())
            .filter(|&i| data.factor("surface").unwrap().level_of(i) == surface)
            .collect();
        let v = &data.covariate("v_in_n").unwrap().values;
        let h = &data.covariate("height_m").unwrap().values;
        let x: Vec<f64> = rows.iter().map(|&i| v[i]).collect();
        let y: Vec<f64> = rows.iter().map(|&i| data.response()[i]).collect();
        // make_reference.py's line_weights: 1 / (0.005 + 0.02 height)^2.
        let wt: Vec<f64> = rows.iter().map(|&i| (0.005 + 0.02 * h[i]).powi(-2)).collect();
        for (kind, w) in [("unweighted", None), ("weighted", Some(wt.as_slice()))] {
            let r = &el[kind];
            let l = fit_line(&x, &y, w).expect("line");
            let w = |col: &str| format!("line {surface} {kind} {col}");
            c.rel(&w("intercept"), f(&r["intercept"]), l.intercept);
            c.near0(&w("slope"), f(&r["slope"]), l.slope);
            c.rel(&w("intercept_se"), f(&r["intercept_se"]), l.intercept_se);
            c.rel(&w("slope_se"), f(&r["slope_se"]), l.slope_se);
            c.near0(&w("cov"), f(&r["cov_intercept_slope"]), l.cov_intercept_slope);
            c.near0(&w("t"), f(&r["t"]), l.t);
            c.rel(&w("p"), f(&r["p"]), l.p);
            c.rel(&w("residual variance"), f(&r["residual_variance"]), l.residual_variance);
            c.num(&w("df"), f(&r["df"]), l.df as f64, 0.0, 0.0);
        }
    }
    inf
}

#[test]
fn holm_matches_multipletests() {
    let reference = reference();
    let c = Checker::new();
    for case in reference["holm"].as_array().unwrap() {
        let p = arr(&case["p"]);
        for (i, (want, got)) in arr(&case["p_holm"]).iter().zip(holm(&p)).enumerate() {
            c.rel(&format!("holm {p:?}[{i}]"), *want, got);
        }
    }
    c.finish("holm");
}

/// A Hertz-like session: COR falls as |v|^(1/5). The quadratic term in the speed finds the curve the
/// linear ANCOVA misses, and the marginal means separate the tapes where the one-way comparison cannot.
#[test]
fn hertz_curve_is_reported() {
    let inf = check_data_set("hertz", "cor_hertz.csv");
    let caption = inf.residual_tests.caption();
    assert!(
        caption.starts_with("Residuals curve with v_in_n (quadratic term F = "),
        "{caption}"
    );
    assert!(caption.contains("the linear model misses a trend"), "{caption}");
    // The contradiction: raw one-way means cannot tell the tapes apart (the speed spread swamps
    // the pooled variance); the adjusted means, from the same fit as the ANCOVA, can.
    let tapes = |l1: &str, l2: &str| l1 == "tape1" && l2 == "tape2";
    let adjusted = inf.means_of("surface").unwrap();
    let adjusted = adjusted.pairs.iter().find(|p| tapes(&p.level1, &p.level2)).unwrap();
    let one_way = tukey_hsd_unadjusted_factor(&load("cor_hertz.csv"), "surface", 0.05).unwrap();
    let one_way = one_way.pairs.iter().find(|p| tapes(&p.group1, &p.group2)).unwrap();
    assert!(adjusted.reject_tukey && !one_way.reject, "{adjusted:?}\n{one_way:?}");
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
