//! One error type for the whole engine. Every variant says what is wrong and where, so that the
//! Python layer can pass the message on unchanged.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum FfError {
    /// A model file (URDF or YAML) could not be read or is malformed.
    #[error("{source_name}{}: {msg}", line.map(|l| format!(", line {l}")).unwrap_or_default())]
    ModelFile { source_name: String, line: Option<usize>, msg: String },

    /// A model is structurally wrong (unknown parent, duplicate names, bad joint axis...).
    #[error("invalid model: {0}")]
    Model(String),

    /// Inertial parameters that no rigid body can have.
    #[error("non-physical inertia of body '{body}': {msg}")]
    Inertia { body: String, msg: String },

    /// A function argument of the wrong size or with non-finite entries.
    #[error("argument `{name}`: {msg}")]
    Argument { name: String, msg: String },

    /// The numbers themselves defeat the algorithm (singular mass matrix, diverging step...).
    #[error("numerical failure: {0}")]
    Numerical(String),
}

pub type Result<T> = std::result::Result<T, FfError>;

impl FfError {
    pub fn arg(name: &str, msg: impl Into<String>) -> Self {
        FfError::Argument { name: name.to_string(), msg: msg.into() }
    }
}

pub use crate::check::check_vec;
