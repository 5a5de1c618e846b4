//! One module per subcommand.

pub mod demo;
pub mod effects;
pub mod simulate;

use anyhow::Context;
use bouncelab_model::ModelSpec;
use std::path::Path;

/// The model file at `path`, or the built-in paper model.
pub fn load_model(path: Option<&Path>) -> anyhow::Result<ModelSpec> {
    match path {
        Some(p) => ModelSpec::load(p).with_context(|| format!("reading the model {}", p.display())),
        None => Ok(ModelSpec::paper()),
    }
}
