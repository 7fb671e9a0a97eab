//! Built-in robots: the YAML files of `models/`, embedded at build time (see build.rs).

use super::Model;
use crate::error::{FfError, Result};

include!(concat!(env!("OUT_DIR"), "/builtin_models.rs"));

/// Earlier names of the built-in robots, still accepted by `source` and `load`: (old name, current name).
/// Listings show only the current names.
pub static ALIASES: &[(&str, &str)] = &[
    ("seed000_2d_large", "zhang2020_2d_large"),
    ("seed000_2d_medium", "zhang2020_2d_medium"),
    ("seed000_2d_small", "zhang2020_2d_small"),
    ("seed000_3d", "zhang2020_3d"),
    ("seed001_dual_arm", "naveen_dual_arm"),
    ("seed001_dual_arm_consistent", "naveen_dual_arm_consistent"),
    ("seed001_dual_arm_offset", "naveen_dual_arm_offset"),
    ("thesis_ch5_single_arm", "valverde_ch5_single_arm"),
    ("thesis_ch7_two_arm", "valverde_ch7_two_arm"),
];

/// Names of the built-in robots, sorted (current names only; see `ALIASES`).
pub fn names() -> Vec<&'static str> {
    MODELS.iter().map(|(n, _)| *n).collect()
}

/// The current name for `name`: itself, or the robot an alias stands for.
pub fn resolve(name: &str) -> &str {
    ALIASES.iter().find(|(old, _)| *old == name).map(|(_, new)| *new).unwrap_or(name)
}

/// The YAML text of a built-in robot (by current name or alias).
pub fn source(name: &str) -> Result<&'static str> {
    let name = resolve(name);
    MODELS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| *s)
        .ok_or_else(|| FfError::arg("name", format!("no built-in model '{name}'; available: {}", names().join(", "))))
}

/// Load a built-in robot by current name or alias (the YAML files embedded at build time).
pub fn load(name: &str) -> Result<Model> {
    super::yaml::from_yaml_str(source(name)?, &format!("built-in model '{}'", resolve(name)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_alias_names_a_current_robot_and_loads_it() {
        let current = names();
        for (old, new) in ALIASES {
            assert!(current.contains(new), "alias {old} -> {new}: no such built-in");
            assert!(!current.contains(old), "alias {old} is also a current name");
            assert_eq!(source(old).unwrap(), source(new).unwrap());
            assert_eq!(resolve(old), *new);
        }
        assert_eq!(resolve("naveen_dual_arm"), "naveen_dual_arm");
        assert!(source("no_such_robot").is_err());
    }
}
