//! Rust errors become Python exceptions; a Rust panic never crosses into Python.

use freefloat_core::FfError;
use pyo3::create_exception;
use pyo3::exceptions::{PyArithmeticError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

create_exception!(_core, ModelError, PyValueError, "A model file or model description is malformed or non-physical.");
create_exception!(
    _core,
    InputError,
    PyValueError,
    "An argument has the wrong shape, non-finite entries or an invalid value."
);
create_exception!(
    _core,
    NumericalError,
    PyArithmeticError,
    "The numbers defeat the algorithm (singular matrix, diverging step...)."
);

pub fn to_py(e: FfError) -> PyErr {
    let msg = e.to_string();
    match e {
        FfError::ModelFile { .. } | FfError::Model(_) | FfError::Inertia { .. } => ModelError::new_err(msg),
        FfError::Argument { .. } => InputError::new_err(msg),
        FfError::Numerical(_) => NumericalError::new_err(msg),
    }
}

/// Run engine code, turning its errors into exceptions and any panic into a RuntimeError.
pub fn guard<T>(f: impl FnOnce() -> Result<T, FfError>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(x)) => Ok(x),
        Ok(Err(e)) => Err(to_py(e)),
        Err(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(PyRuntimeError::new_err(format!("internal error in freefloat (please report it): {what}")))
        }
    }
}

pub fn input_err(msg: impl Into<String>) -> PyErr {
    InputError::new_err(msg.into())
}
