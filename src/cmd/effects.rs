//! `bouncelab effects`: the effect library, for people writing `model.toml`.

use bouncelab_model::builtin_effects;
use bouncelab_model::effects::FORMULA_VARIABLES;

#[derive(clap::Args)]
pub struct Args {
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if a.json {
        let out: Vec<_> = builtin_effects()
            .iter()
            .map(|e| {
                serde_json::json!({
                    "name": e.name, "group": e.group, "base": e.base, "doc": e.doc,
                    "params": e.params.iter().map(|p| serde_json::json!({
                        "name": p.name, "unit": p.unit, "doc": p.doc, "default": p.default,
                        "neutral": p.neutral, "min": finite(p.min), "max": finite(p.max),
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    for e in builtin_effects() {
        let tag = match (e.base, e.group) {
            (true, "nuisance") => " (fitted with the base model; never a candidate)",
            (true, _) => " (base model)",
            _ => "",
        };
        println!("{} [{}]{tag}\n    {}", e.name, e.group, e.doc);
        for p in e.params {
            let default = p
                .default
                .map(|d| format!("default {d}"))
                .unwrap_or_else(|| "required".into());
            println!(
                "    {:<9} {:<12} {} ({default}; range {} to {})",
                p.name, p.unit, p.doc, p.min, p.max
            );
        }
        println!();
    }
    println!(
        "custom [kind = \"custom\"]\n    A force law written as formulas (normal, tangential, force_x, force_y, torque) over the state"
    );
    println!("    and the term's own parameters; phase = contact | compression | restitution | flight | always.");
    println!("    Variables:");
    for (v, doc) in FORMULA_VARIABLES {
        println!("    {v:<9} {doc}");
    }
    Ok(())
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}
