//! `bouncelab model add EFFECT --model model.toml`: accept a diagnosis by adding the named effect to a model
//! file (comments and layout kept), so the next `analyze --model` fits it and shows the error falling.

use anyhow::Context;
use bouncelab_diagnose::{Diagnosis, add_effect_to_model_toml};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: ModelCommand,
}

#[derive(clap::Subcommand)]
pub enum ModelCommand {
    /// Add a library effect to a model file (created from the paper's model if it does not exist).
    Add(AddArgs),
}

#[derive(clap::Args)]
pub struct AddArgs {
    /// The effect's name (see `bouncelab effects`).
    pub effect: String,
    /// The model file to edit.
    #[arg(long)]
    pub model: PathBuf,
    /// A diagnosis.json whose fitted values for the effect are used as starting values [default: the
    /// effect's defaults].
    #[arg(long)]
    pub diagnosis: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    match a.command {
        ModelCommand::Add(a) => {
            let (path, values) = add(&a.effect, &a.model, a.diagnosis.as_deref())?;
            let shown: Vec<String> = values.iter().map(|(n, v)| format!("{n} = {v:.6}")).collect();
            println!(
                "added `{}` to {}{}; re-run `bouncelab analyze SESSION_DIR --model {}` to see the error before and after",
                a.effect,
                path.display(),
                if shown.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", shown.join(", "))
                },
                path.display()
            );
            Ok(())
        }
    }
}

/// The effect's fitted values in a diagnosis (`<effect>.<param>` parameters of its candidate's fit).
pub fn fitted_values(d: &Diagnosis, effect: &str) -> Vec<(String, f64)> {
    let prefix = format!("{effect}.");
    d.candidate(effect)
        .and_then(|c| c.evidence.as_ref())
        .map(|e| {
            e.fit
                .parameters
                .iter()
                .filter_map(|p| p.name.strip_prefix(&prefix).map(|n| (n.to_string(), p.value)))
                .collect()
        })
        .unwrap_or_default()
}

/// Adds `effect` to the model file at `path` (created from the paper's model when absent); the previous
/// text is kept beside it as `<name>.before-<effect>.toml`. Returns the path and the values written.
pub fn add(effect: &str, path: &Path, diagnosis: Option<&Path>) -> anyhow::Result<(PathBuf, Vec<(String, f64)>)> {
    let text = if path.exists() {
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?
    } else {
        bouncelab_model::PAPER_MODEL_TOML.to_string()
    };
    let values = match diagnosis {
        Some(d) => {
            let json = std::fs::read_to_string(d).with_context(|| format!("reading {}", d.display()))?;
            let d: Diagnosis =
                serde_json::from_str(&json).with_context(|| format!("{}: not a diagnosis.json", d.display()))?;
            fitted_values(&d, effect)
        }
        None => Vec::new(),
    };
    let new =
        add_effect_to_model_toml(&text, effect, &values).with_context(|| format!("editing {}", path.display()))?;
    if path.exists() {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let backup = path.with_file_name(format!("{stem}.before-{effect}.toml"));
        std::fs::write(&backup, &text).with_context(|| format!("writing {}", backup.display()))?;
    }
    let tmp = path.with_extension("toml.partial");
    std::fs::write(&tmp, new).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("writing {}", path.display()))?;
    Ok((path.to_path_buf(), values))
}
