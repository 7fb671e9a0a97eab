//! One error type for the whole engine. Every variant says what is wrong and where, so that the
//! Python layer can pass the message on unchanged.

use thiserror::Error;

/// The engine's one error type; every variant's message names what is wrong and where.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FfError {
    /// A model file (URDF or YAML) could not be read or is malformed.
    #[error("{source_name}{}: {msg}", line.map(|l| format!(", line {l}")).unwrap_or_default())]
    ModelFile {
        /// File name (or `<string>`) the model was read from.
        source_name: String,
        /// Line of the problem, when known.
        line: Option<usize>,
        /// What is wrong.
        msg: String,
    },

    /// A model is structurally wrong (unknown parent, duplicate names, bad joint axis...).
    #[error("invalid model: {0}")]
    Model(String),

    /// Inertial parameters that no rigid body can have.
    #[error("non-physical inertia of body '{body}': {msg}")]
    Inertia {
        /// Name of the body.
        body: String,
        /// What is wrong with its parameters.
        msg: String,
    },

    /// A function argument of the wrong size or with non-finite entries.
    #[error("argument `{name}`: {msg}")]
    Argument {
        /// Name of the argument (as in the function's signature or the Python API).
        name: String,
        /// Expected vs got.
        msg: String,
    },

    /// The numbers themselves defeat the algorithm (singular mass matrix, diverging step...).
    #[error("numerical failure: {0}")]
    Numerical(String),

    /// The caller stopped the run (Ctrl-C, or a progress hook returning false). Not a failure of the
    /// numbers: what was finished before the stop is in `partial` where the routine has one.
    #[error("interrupted: {msg}")]
    Interrupted {
        /// Where the run stopped (`at t = 12.3 s of 100 s`).
        msg: String,
        /// What was finished before the stop.
        partial: Option<Partial>,
    },
}

/// The finished part of an interrupted run.
#[derive(Debug, Clone, PartialEq)]
pub enum Partial {
    /// A simulation's samples up to the interrupt.
    Trajectory(Box<crate::trajectory::Trajectory>),
    /// The first `n` samples of a per-sample output (e.g. the estimates of
    /// `estimation::concurrent::estimate_recorded_interruptible`) are finished.
    Samples(usize),
}

/// `Result` with the engine's error.
pub type Result<T> = std::result::Result<T, FfError>;

impl FfError {
    /// An argument error naming the argument `name`.
    pub fn arg(name: &str, msg: impl Into<String>) -> Self {
        FfError::Argument { name: name.to_string(), msg: msg.into() }
    }

    /// An interruption without a partial result (see [`FfError::Interrupted`]).
    pub fn interrupted(msg: impl Into<String>) -> Self {
        FfError::Interrupted { msg: msg.into(), partial: None }
    }

    /// Whether this error is an interruption rather than a failure.
    pub fn is_interrupted(&self) -> bool {
        matches!(self, FfError::Interrupted { .. })
    }
}
