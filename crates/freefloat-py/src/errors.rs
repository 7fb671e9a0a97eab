//! Rust errors become Python exceptions; a Rust panic never crosses into Python.

use freefloat_core::FfError;
use pyo3::create_exception;
use pyo3::exceptions::{PyArithmeticError, PyKeyboardInterrupt, PyRuntimeError, PyValueError};
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

create_exception!(
    _core,
    Interrupted,
    PyKeyboardInterrupt,
    "A long run was stopped (Ctrl-C, or a progress callback returning False); `partial` holds what was \
     finished (a Trajectory for a simulation), or None."
);

/// Whether a Python exception is a Ctrl-C (KeyboardInterrupt, including our `Interrupted`).
pub fn is_ctrl_c(py: Python<'_>, e: &PyErr) -> bool {
    e.is_instance_of::<PyKeyboardInterrupt>(py)
}

/// The `Interrupted` exception with `partial` set (None when there is nothing finished to return).
pub fn interrupted_with(py: Python<'_>, msg: &str, partial: Option<Py<PyAny>>) -> PyErr {
    let e = Interrupted::new_err(msg.to_string());
    let _ = e.value(py).setattr("partial", partial);
    e
}

/// A hook for engine code running with the GIL released: every call re-takes the GIL for the signal check
/// only (the engine calls it at most every 20 ms); a pending Ctrl-C (or any exception a signal handler
/// raises) is kept in `raised` and stops the run.
pub fn signal_hook(raised: &mut Option<PyErr>) -> impl FnMut(f64) -> bool + Send + '_ {
    move |_frac| match Python::attach(|py| py.check_signals()) {
        Ok(()) => true,
        Err(e) => {
            raised.get_or_insert(e);
            false
        }
    }
}

/// After a run stopped by a hook: re-raise a non-Ctrl-C exception from a signal handler unchanged.
pub fn reraise_foreign(py: Python<'_>, raised: Option<PyErr>) -> PyResult<()> {
    match raised {
        Some(e) if !is_ctrl_c(py, &e) => Err(e),
        _ => Ok(()),
    }
}

pub fn to_py(e: FfError) -> PyErr {
    let msg = e.to_string();
    match e {
        FfError::ModelFile { .. } | FfError::Model(_) | FfError::Inertia { .. } => ModelError::new_err(msg),
        FfError::Argument { .. } => InputError::new_err(msg),
        FfError::Numerical(_) => NumericalError::new_err(msg),
        FfError::Interrupted { .. } => {
            let e = Interrupted::new_err(msg);
            Python::attach(|py| {
                let _ = e.value(py).setattr("partial", py.None());
            });
            e
        }
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

/// `guard` that keeps the engine's error as it is (to read an interruption's partial result); a panic is
/// still a RuntimeError.
pub fn guard_raw<T>(f: impl FnOnce() -> Result<T, FfError>) -> PyResult<Result<T, FfError>> {
    guard(|| Ok(f()))
}

pub fn input_err(msg: impl Into<String>) -> PyErr {
    InputError::new_err(msg.into())
}
