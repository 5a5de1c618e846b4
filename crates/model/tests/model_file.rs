//! `model.toml`: the shipped paper model, custom formula terms, and a clear error for each bad input.

use bouncelab_model::{ModelError, ModelSpec, SimOptions, State, simulate};

fn parse(text: &str) -> Result<ModelSpec, ModelError> {
    ModelSpec::parse(text, "model.toml")
}

fn err(text: &str) -> String {
    let e = parse(text).and_then(|s| s.build(None).map(|_| s)).unwrap_err();
    e.to_string()
}

#[test]
fn shipped_paper_model_has_three_surfaces_with_the_papers_values() {
    let spec = ModelSpec::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/paper-model.toml"
    )))
    .unwrap();
    assert_eq!(spec.surface_names(), vec!["clay", "tape1", "tape2"]);
    let tape2 = spec.build(Some("tape2")).unwrap();
    assert_eq!(tape2.effect("spring").unwrap().params(), vec![31_825.0]);
    assert_eq!(tape2.effect("damping").unwrap().params(), vec![15.0]);
    let settings = spec.settings(Some("clay")).unwrap();
    let k = settings.iter().find(|(r, _)| r.to_string() == "spring.k").unwrap().1;
    assert!(k.free && k.min == 1000.0 && k.max == 1e6 && k.value == 25_650.0);
    // Friction is fitted per surface.
    let mu = settings.iter().find(|(r, _)| r.to_string() == "coulomb.mu").unwrap().1;
    assert!(mu.free && mu.value == 0.5);
    assert!(
        spec.surfaces
            .iter()
            .all(|(_, v)| v.iter().any(|(r, s)| r.to_string() == "coulomb.mu" && s.free))
    );
    assert!(matches!(
        spec.build(Some("grass")),
        Err(ModelError::UnknownSurface { .. })
    ));
}

const BASE: &str = r#"
[effects.spring]
k = 25650
[effects.damping]
b = 14
[effects.coulomb]
mu = 0.5
"#;

#[test]
fn custom_normal_term_equals_the_built_in_it_imitates() {
    let custom = format!("{BASE}\n[effects.extra]\nkind = \"custom\"\nnormal = \"k2 * delta\"\nk2 = 5000\n");
    let builtin = BASE.replace("k = 25650", "k = 30650");
    let start = State::flying(0.0, 0.034, 0.4, -2.0);
    let o = SimOptions::default();
    let a = simulate(&parse(&custom).unwrap().build(None).unwrap(), 0.0, 0.0, start, &[], &o)
        .unwrap()
        .impact;
    let b = simulate(&parse(&builtin).unwrap().build(None).unwrap(), 0.0, 0.0, start, &[], &o)
        .unwrap()
        .impact;
    assert!((a.restitution - b.restitution).abs() < 1e-9 && (a.contact_time() - b.contact_time()).abs() < 1e-12);
}

#[test]
fn custom_term_sees_the_state_variables_and_unicode_aliases() {
    let text = format!(
        "{BASE}\n[effects.pull]\nkind = \"custom\"\nphase = \"restitution\"\nnormal = \"-f0 * exp(-δ / d0)\"\ntorque = \"-c * P * signum(ω)\"\nf0 = {{ value = 3, free = true, min = 0, max = 10 }}\nd0 = 5e-4\nc = 0.0\n"
    );
    let spec = parse(&text).unwrap();
    let settings = spec.settings(None).unwrap();
    assert!(settings.iter().any(|(r, s)| r.to_string() == "pull.f0" && s.free));
    let start = State::flying(0.0, 0.034, 0.0, -2.0);
    let o = SimOptions::default();
    let pulled = simulate(&spec.build(None).unwrap(), 0.0, 0.0, start, &[], &o)
        .unwrap()
        .impact;
    let plain = simulate(&parse(BASE).unwrap().build(None).unwrap(), 0.0, 0.0, start, &[], &o)
        .unwrap()
        .impact;
    assert!(
        pulled.restitution < plain.restitution - 0.005,
        "{} vs {}",
        pulled.restitution,
        plain.restitution
    );
}

#[test]
fn unknown_effect_lists_the_known_ones() {
    let e = err("[effects.sping]\nk = 1\n");
    assert!(
        e.contains("unknown effect `sping`")
            && e.contains("spring")
            && e.contains("hunt_crossley")
            && e.contains("custom"),
        "{e}"
    );
}

#[test]
fn bad_formula_says_where() {
    let e = err(&format!(
        "{BASE}\n[effects.x]\nkind = \"custom\"\nnormal = \"2 * (delta + \"\n"
    ));
    assert!(e.contains("effects.x.normal") && e.contains("never closed"), "{e}");
    assert!(
        e.contains("\n    2 * (delta + \n        ^"),
        "caret under the `(`:\n{e}"
    );
    let e = err(&format!(
        "{BASE}\n[effects.x]\nkind = \"custom\"\nnormal = \"k * delta + foo(v_n)\"\nk = 1\n"
    ));
    assert!(e.contains("unknown function `foo`"), "{e}");
    let e = err(&format!(
        "{BASE}\n[effects.x]\nkind = \"custom\"\nnormal = \"q * delta\"\n"
    ));
    assert!(
        e.contains("`q` is neither a state variable") && e.contains("\n    ^"),
        "{e}"
    );
    let e = err(&format!("{BASE}\n[effects.x]\nkind = \"custom\"\nnormal = \"P * 2\"\n"));
    assert!(e.contains("cannot use P"), "{e}");
}

#[test]
fn missing_parameter_is_named_with_its_unit() {
    let e = err("[effects.spring]\n[effects.coulomb]\nmu = 0.3\n");
    assert!(e.contains("needs parameter `k` (N/m)"), "{e}");
    let spec = parse("[effects.spring]\n[surfaces.clay]\nspring.k = 100\n[surfaces.tape]\n").unwrap();
    assert!(spec.build(Some("clay")).is_ok());
    let e = spec.build(Some("tape")).unwrap_err().to_string();
    assert!(e.contains("surface `tape` does not set it"), "{e}");
}

#[test]
fn negative_stiffness_is_refused() {
    let e = err("[effects.spring]\nk = -100\n");
    assert!(e.contains("spring.k = -100") && e.contains("negative stiffness"), "{e}");
    let e = err("[effects.spring]\nk = 100\n[surfaces.clay]\nspring.k = -5\n");
    assert!(e.contains("negative stiffness"), "{e}");
}

#[test]
fn other_mistakes_are_reported_not_panicked() {
    for (text, needle) in [
        ("[effects.spring\nk = 1", "model.toml"),
        ("[effects.spring]\nk = \"stiff\"", "must be a number"),
        ("[effects.spring]\nk = 1\nq = 2", "has no parameter `q`"),
        (
            "[effects.spring]\nk = { value = 10, free = true, min = 100, max = 1000 }",
            "outside its fit bounds",
        ),
        ("[effects.spring]\nk = { value = 10, min = 100, max = 1 }", "bounds"),
        ("[ball]\nmass_kg = -1", "must be > 0"),
        ("colour = 3", "unknown key `colour`"),
        (
            "[ball]\nmass_kg = 0.05\ngravity_m_s2 = 9.81",
            "before the first [table]",
        ),
        (
            "[effects.spring]\nk = 1\n[surfaces.clay]\nhertz.k_h = 2",
            "no effect `hertz`",
        ),
        (
            "[effects.x]\nkind = \"custom\"\nphase = \"sometimes\"\nnormal = \"1\"",
            "phase",
        ),
        ("[effects.x]\nkind = \"custom\"\n", "at least one formula"),
        (
            "[effects.spring]\nkind = \"custom\"\nnormal = \"1\"",
            "cannot take the name",
        ),
    ] {
        let e = err(text);
        assert!(e.contains(needle), "{text:?} → {e}");
    }
}

#[test]
fn a_formula_that_yields_nan_stops_the_simulation_with_a_time() {
    let text = format!("{BASE}\n[effects.bad]\nkind = \"custom\"\nnormal = \"ln(delta - 1)\"\n");
    let model = parse(&text).unwrap().build(None).unwrap();
    let e = simulate(
        &model,
        0.0,
        0.0,
        State::flying(0.0, 0.034, 0.0, -2.0),
        &[],
        &SimOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e, ModelError::NonFinite { .. }), "{e}");
}

// Regression tests of issue 19: each is named after what broke.

fn normal_force_of(spec_text: &str, effect: &str, delta: f64) -> f64 {
    use bouncelab_model::{Context, Phase};
    let model = parse(spec_text).unwrap().build(None).unwrap();
    let state = State {
        y: model.ball.radius_m - delta,
        ..State::default()
    };
    let ctx = Context::of(0.0, &state, Phase::Compression, &model.ball, model.gravity, 0.0);
    model.effect(effect).unwrap().normal_force(&ctx)
}

#[test]
fn a_formula_with_33_parameters_no_longer_panics() {
    let names: Vec<String> = (0..33).map(|i| format!("p{i}")).collect();
    let decl: String = names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{n} = {}\n", i + 1))
        .collect();
    let text = format!(
        "{BASE}\n[effects.many]\nkind = \"custom\"\nnormal = \"{} + delta\"\n{decl}",
        names.join(" + ")
    );
    let f = normal_force_of(&text, "many", 2e-3);
    assert!((f - (561.0 + 2e-3)).abs() < 1e-12, "{f}");
    let model = parse(&text).unwrap().build(None).unwrap();
    assert!(
        simulate(
            &model,
            0.0,
            0.0,
            State::flying(0.0, 0.034, 0.3, -2.0),
            &[],
            &SimOptions::default()
        )
        .is_ok()
    );
}

#[test]
fn scientific_notation_in_a_formula_is_a_number() {
    for (formula, factor) in [("1e3*delta", 1e3), ("2.5E-4 * delta", 2.5e-4), ("1E+2*delta", 100.0)] {
        let text = format!("{BASE}\n[effects.sci]\nkind = \"custom\"\nnormal = \"{formula}\"\n");
        let f = normal_force_of(&text, "sci", 2e-3);
        assert!((f / (factor * 2e-3) - 1.0).abs() < 1e-12, "{formula}: {f}");
    }
}

#[test]
fn parser_errors_are_ours_with_the_formula_and_a_caret() {
    for (formula, caret_at, needle) in [
        ("1e3*delta +* 2", 11, "value is missing before `*`"),
        ("2 delta", 2, "operator"),
        ("2delta", 1, "`*`"),
        ("delta ** 2", 7, "value is missing before `*`"),
        ("sin(delta, 2)", 0, "takes 1 argument"),
        ("delta $ 2", 6, "unexpected character `$`"),
    ] {
        let e = err(&format!(
            "{BASE}\n[effects.x]\nkind = \"custom\"\nnormal = \"{formula}\"\n"
        ));
        assert!(e.contains("effects.x.normal") && e.contains(needle), "{formula}: {e}");
        assert!(
            e.contains(&format!("\n    {formula}\n    {}^", " ".repeat(caret_at))),
            "{formula}: caret under character {caret_at}:\n{e}"
        );
        for internal in ["ops", "node", "Operator", "exmex"] {
            assert!(!e.contains(internal), "{formula}: parser internals leak: {e}");
        }
    }
}

#[test]
fn an_empty_model_or_a_zero_spring_says_the_normal_force_is_missing_not_too_stiff() {
    for (text, detail) in [
        ("", "no effects at all"),
        ("[effects.spring]\nk = 0\n", "spring.k = 0"),
        (
            "[effects.damping]\nb = 14\n[effects.coulomb]\nmu = 0.5\n",
            "damping.b = 14",
        ),
        ("[effects.coulomb]\nmu = 0.5\n", "no normal-force effect"),
    ] {
        let e = err(text);
        assert!(
            e.contains("no elastic normal force") && e.contains(detail),
            "{text:?}: {e}"
        );
        assert!(e.contains("[effects.spring]") && !e.contains("too stiff"), "{e}");
    }
    // Per surface: the file's own value is fine, one surface's is not.
    let spec = parse("[effects.spring]\nk = 100\n[surfaces.clay]\nspring.k = 0\n").unwrap();
    assert!(spec.build(None).is_ok());
    let e = spec.build(Some("clay")).unwrap_err().to_string();
    assert!(e.contains("(surface `clay`)") && e.contains("spring.k = 0"), "{e}");
    // A model built in code without any normal force stops with what happened, not a step budget.
    let bare = bouncelab_model::Model::new(bouncelab_model::Ball::TENNIS, 9.81);
    let e = simulate(
        &bare,
        0.0,
        0.0,
        State::flying(0.0, 0.05, 0.0, -2.0),
        &[],
        &SimOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e, ModelError::SankThrough { .. }), "{e}");
}

#[test]
fn huge_gravity_is_refused_with_its_key_and_range() {
    let e = err(&format!("gravity_m_s2 = 1e300\n{BASE}"));
    assert!(
        e.contains("gravity_m_s2 = 1e300 is outside its physical range [0, 100] m/s²"),
        "{e}"
    );
    let e = err(&format!("gravity_m_s2 = -9.81\n{BASE}"));
    assert!(e.contains("gravity_m_s2 = -9.81") && e.contains("[0, 100]"), "{e}");
    assert!(parse(&format!("gravity_m_s2 = 1.62\n{BASE}")).is_ok());
}

#[test]
fn ball_values_are_checked_against_their_physical_ranges() {
    for (line, needle) in [
        (
            "mass_kg = 1000",
            "ball.mass_kg = 1000 is outside its physical range [0.0001, 20] kg",
        ),
        (
            "radius_m = 5",
            "ball.radius_m = 5 is outside its physical range [0.001, 0.5] m",
        ),
        ("diameter_m = 0", "ball.diameter_m = 0 must be > 0"),
        (
            "inertia_factor = 2",
            "ball.inertia_factor = 2 is outside its physical range [0.05, 0.67]",
        ),
        ("mass_kg = nan", "ball.mass_kg = NaN"),
    ] {
        let e = err(&format!("[ball]\n{line}\n{BASE}"));
        assert!(e.contains(needle), "{line}: {e}");
    }
}

#[test]
fn every_effect_parameter_is_checked_with_its_key_and_range() {
    let e = err("[effects.spring]\nk = 1e12\n");
    assert!(
        e.contains("effects.spring.k = 1e12: outside its physical range [0, 1e9] N/m"),
        "{e}"
    );
    let e = err(&format!("{BASE}\n[effects.tangential_spring]\ncompliance = 1\n"));
    assert!(
        e.contains("tangential_spring.compliance = 1") && e.contains("[0, 0.001] m/N"),
        "{e}"
    );
    let e = err(&format!(
        "{BASE}\n[effects.x]\nkind = \"custom\"\nnormal = \"c\"\nc = inf\n"
    ));
    assert!(e.contains("x.c = inf: must be finite"), "{e}");
    // Every library parameter has a finite physical range, so no value from a file goes unchecked.
    for info in bouncelab_model::builtin_effects() {
        for p in info.params {
            assert!(
                p.min.is_finite() && p.max.is_finite() && p.min <= p.neutral && p.neutral <= p.max,
                "{}.{}",
                info.name,
                p.name
            );
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 256, ..Default::default() })]

    /// Whatever is written as a formula, reading the model file returns a model or an error, never a panic.
    #[test]
    fn any_formula_text_gives_a_model_or_an_error(formula in "[ -~δω]{0,40}") {
        let escaped = formula.replace('\\', "\\\\").replace('"', "\\\"");
        let text = format!("{BASE}\n[effects.x]\nkind = \"custom\"\nnormal = \"{escaped}\"\ntangential = \"{escaped}\"\nc = 2\n");
        if let Ok(spec) = parse(&text)
            && let Ok(model) = spec.build(None)
        {
            let _ = simulate(&model, 0.0, 0.0, State::flying(0.0, 0.034, 0.3, -2.0), &[], &SimOptions::default());
        }
    }
}
