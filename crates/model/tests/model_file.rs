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
    let mu = settings.iter().find(|(r, _)| r.to_string() == "coulomb.mu").unwrap().1;
    assert!(!mu.free);
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
