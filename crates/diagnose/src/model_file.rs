//! Accepting a diagnosis: the model file with the named effect added, the user's comments and layout kept.

use crate::DiagnoseError;
use crate::candidates::library_effect;
use bouncelab_model::ModelSpec;
use toml_edit::{DocumentMut, InlineTable, Item, Table, value};

/// The name model files are reported under in errors of [`add_effect_to_model_toml`].
const ORIGIN: &str = "model.toml";

/// `v` to six significant digits (far below any fitted interval), as the file shows it.
fn round6(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    format!("{v:.5e}").parse().unwrap_or(v)
}

/// The text of a model file with `[effects.<effect>]` added after its last effect.
///
/// Each parameter in `values` (name, value in the parameter's unit; e.g. the fitted values of a
/// diagnosis) is written free within the effect's physical range, `{ value = …, free = true, min = …,
/// max = … }` (an unbounded end is left out); the effect's other parameters are written at their defaults,
/// fixed. Everything else in the file (comments, order, spacing) is kept as it was. The result parses with
/// [`ModelSpec::parse`].
///
/// Errors: the text is not a valid model file; `effect` is not a library effect (the error lists them);
/// the model already has it; a value names a parameter the effect does not have or lies outside its
/// physical range; a parameter without a default is not given.
pub fn add_effect_to_model_toml(text: &str, effect: &str, values: &[(String, f64)]) -> Result<String, DiagnoseError> {
    let info = library_effect(effect)?;
    let file_error = |message: String| DiagnoseError::ModelFile {
        origin: ORIGIN.into(),
        message,
    };
    let spec = ModelSpec::parse(text, ORIGIN).map_err(|e| file_error(e.to_string()))?;
    if spec.has_effect(effect) {
        return Err(DiagnoseError::AlreadyPresent {
            origin: ORIGIN.into(),
            effect: effect.into(),
        });
    }
    for (name, v) in values {
        let Some(p) = info.params.iter().find(|p| p.name == name) else {
            return Err(DiagnoseError::BadValue {
                effect: effect.into(),
                param: name.clone(),
                value: *v,
                reason: format!(
                    "`{effect}` has no such parameter (its parameters: {})",
                    info.params.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
                ),
            });
        };
        if !(v.is_finite() && *v >= p.min && *v <= p.max) {
            return Err(DiagnoseError::BadValue {
                effect: effect.into(),
                param: name.clone(),
                value: *v,
                reason: format!("outside the physical range [{}, {}]", p.min, p.max),
            });
        }
    }

    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| file_error(e.to_string()))?;
    let mut table = Table::new();
    for p in info.params {
        match values.iter().find(|(n, _)| n == p.name) {
            Some((_, v)) => {
                let mut t = InlineTable::new();
                t.insert("value", round6(*v).clamp(p.min, p.max).into());
                t.insert("free", true.into());
                if p.min.is_finite() {
                    t.insert("min", p.min.into());
                }
                if p.max.is_finite() {
                    t.insert("max", p.max.into());
                }
                t.fmt();
                table.insert(p.name, value(t));
            }
            None => {
                let d = p.default.ok_or_else(|| DiagnoseError::BadValue {
                    effect: effect.into(),
                    param: p.name.into(),
                    value: f64::NAN,
                    reason: format!("has no default: give its value ({})", p.unit),
                })?;
                table.insert(p.name, value(d));
            }
        }
    }
    table.decor_mut().set_prefix(format!(
        "\n# {}\n# Added by `bouncelab model add {effect}`.\n",
        info.doc
    ));

    let root = doc.as_table_mut();
    match root.get_mut("effects") {
        None => {
            let mut effects = Table::new();
            effects.set_implicit(true);
            effects.insert(effect, Item::Table(table));
            root.insert("effects", Item::Table(effects));
        }
        Some(Item::Table(effects)) => {
            // A table without a position takes the position of the table before it in the tree, so it is
            // written right after the model's last effect.
            effects.insert(effect, Item::Table(table));
        }
        Some(Item::Value(toml_edit::Value::InlineTable(effects))) => {
            let mut inline = table.into_inline_table();
            inline.fmt();
            effects.insert(effect, toml_edit::Value::InlineTable(inline));
        }
        Some(_) => return Err(file_error("`effects` must be a table of [effects.NAME]".into())),
    }
    let out = doc.to_string();
    ModelSpec::parse(&out, ORIGIN)
        .map_err(|e| file_error(format!("the edited file does not parse ({e}); please report this")))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bouncelab_model::PAPER_MODEL_TOML;

    #[test]
    fn adds_the_effect_after_the_last_one_keeping_comments() {
        let out = add_effect_to_model_toml(
            PAPER_MODEL_TOML,
            "hunt_crossley",
            &[("lambda".into(), 2003.456789), ("n".into(), 1.02)],
        )
        .unwrap();
        // Every line of the original is still there, in order.
        let mut rest = out.as_str();
        for line in PAPER_MODEL_TOML.lines() {
            let at = rest
                .find(line)
                .unwrap_or_else(|| panic!("lost line {line:?} in\n{out}"));
            rest = &rest[at + line.len()..];
        }
        assert!(out.contains("# Friction differs between surfaces"), "{out}");
        let hc = out.find("[effects.hunt_crossley]").unwrap();
        assert!(
            hc > out.find("[effects.coulomb]").unwrap() && hc < out.find("[surfaces.clay]").unwrap(),
            "{out}"
        );
        assert!(
            out.contains("lambda = { value = 2003.46, free = true, min = 0.0, max = "),
            "{out}"
        );
        assert!(
            out.contains("n = { value = 1.02, free = true, min = 0.0, max = 3.0 }"),
            "{out}"
        );
        let spec = ModelSpec::parse(&out, "out").unwrap();
        let s = spec.settings(Some("clay")).unwrap();
        let l = s
            .iter()
            .find(|(r, _)| r.to_string() == "hunt_crossley.lambda")
            .unwrap()
            .1;
        assert!(l.free && (l.value - 2003.46).abs() < 1e-9);
    }

    #[test]
    fn parameters_not_given_are_written_at_their_defaults() {
        let out = add_effect_to_model_toml(PAPER_MODEL_TOML, "drag", &[("cd".into(), 0.61)]).unwrap();
        assert!(out.contains("rho = 1.204"), "{out}");
        let spec = ModelSpec::parse(&out, "out").unwrap();
        assert!(spec.has_effect("drag"));
    }

    #[test]
    fn unknown_effect_lists_the_library() {
        let e = add_effect_to_model_toml(PAPER_MODEL_TOML, "magnus", &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("unknown effect `magnus`") && e.contains("hunt_crossley") && e.contains("camera_roll"),
            "{e}"
        );
    }

    #[test]
    fn an_effect_already_present_is_refused() {
        let e = add_effect_to_model_toml(PAPER_MODEL_TOML, "damping", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("already has effect `damping`"), "{e}");
        let once = add_effect_to_model_toml(PAPER_MODEL_TOML, "hertz", &[("k_h".into(), 4e5)]).unwrap();
        let e = add_effect_to_model_toml(&once, "hertz", &[("k_h".into(), 4e5)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("already has effect `hertz`"), "{e}");
    }

    #[test]
    fn bad_values_are_refused_naming_the_parameter() {
        let e = add_effect_to_model_toml(PAPER_MODEL_TOML, "plastic_dent", &[("phi".into(), 1.5)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("phi") && e.contains("physical range"), "{e}");
        let e = add_effect_to_model_toml(PAPER_MODEL_TOML, "plastic_dent", &[("psi".into(), 0.1)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("no such parameter") && e.contains("phi"), "{e}");
        let e = add_effect_to_model_toml("not = [toml", "hertz", &[])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("model.toml:"), "{e}");
    }

    #[test]
    fn a_file_without_effects_gets_an_effects_table() {
        let text = "# just a ball\n[ball]\nmass_kg = 0.0567\n";
        let out = add_effect_to_model_toml(text, "camera_roll", &[("roll_deg".into(), -2.5)]).unwrap();
        assert!(out.starts_with("# just a ball\n[ball]\nmass_kg = 0.0567\n"), "{out}");
        assert!(
            out.contains("[effects.camera_roll]\nroll_deg = { value = -2.5, free = true, min = -45.0, max = 45.0 }"),
            "{out}"
        );
        let inline = "[effects]\nspring = { k = 100 }\n";
        let out = add_effect_to_model_toml(inline, "hertz", &[("k_h".into(), 1e5)]).unwrap();
        assert!(ModelSpec::parse(&out, "x").unwrap().has_effect("hertz"), "{out}");
    }
}
