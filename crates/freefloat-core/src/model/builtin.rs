//! Built-in robots: the YAML files of `models/`, embedded at build time (see build.rs).

use super::Model;
use crate::error::{FfError, Result};

include!(concat!(env!("OUT_DIR"), "/builtin_models.rs"));

/// Names of the built-in robots, sorted.
pub fn names() -> Vec<&'static str> {
    MODELS.iter().map(|(n, _)| *n).collect()
}

/// The YAML text of a built-in robot.
pub fn source(name: &str) -> Result<&'static str> {
    MODELS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| *s)
        .ok_or_else(|| FfError::arg("name", format!("no built-in model '{name}'; available: {}", names().join(", "))))
}

/// Load a built-in robot by name (the YAML files embedded at build time).
pub fn load(name: &str) -> Result<Model> {
    super::yaml::from_yaml_str(source(name)?, &format!("built-in model '{name}'"))
}
