//! Least-squares identification from momentum (freefloat_core::estimation), streamed over samples
//! in Rust with the GIL released; the tall regressor is never formed.

use crate::batch::{array_arg, model_arg, Batch};
use crate::errors::{guard, input_err, reraise_foreign, signal_hook};
use freefloat_core::estimation::{identify_momentum_interruptible, momentum_regressor_pass, Method, MomentumProblem};
use freefloat_core::FfError;
use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Arr<'a, 'py> = &'a Bound<'py, PyAny>;

/// Identify the parameters in `columns` (indices into the 10·nbodies standard parameters) from
/// measured momenta H (T, 6), states Q (T, nq), V (T, nv). `known_params` (10·nbodies,): the known
/// bodies' momentum K·P over the other columns is subtracted from H. `weights` (6,): inverse
/// variances of [p; L]. method: "auto" (normal equations + refinement when well conditioned, else
/// streaming QR) or "qr". Returns a dict: x, std, covariance, rss, dof, condition_number, rank,
/// rows, method. Raises NumericalError naming the unexcited combinations if rank deficient.
#[pyfunction]
#[pyo3(signature = (model, q, v, h, columns, known_params, weights = None, method = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn identify_momentum<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    h: Arr<'_, 'py>,
    columns: Vec<usize>,
    known_params: Arr<'_, 'py>,
    weights: Option<Arr<'_, 'py>>,
    method: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let force_qr = match method {
        "auto" => false,
        "qr" => true,
        _ => return Err(input_err(format!("argument `method`: expected 'auto' or 'qr', got {method:?}"))),
    };
    let a = Args::new(m, q, v, h, known_params, weights)?;
    let problem = a.problem(&columns);
    // Ctrl-C stops the passes over the samples (the hook re-takes the GIL only to check for signals) and raises
    // `Interrupted`; any other exception a signal handler raises comes back unchanged.
    let mut raised: Option<PyErr> = None;
    let res = {
        let raised = &mut raised;
        let problem = &problem;
        py.detach(move || {
            let mut hook = signal_hook(raised);
            guard(|| identify_momentum_interruptible(m, problem, force_qr, Some(&mut hook)).map_err(python_names))
        })
    };
    reraise_foreign(py, raised)?;
    let res = res?;
    let n = res.x.len();
    let d = PyDict::new(py);
    d.set_item("x", res.x.as_slice().to_vec().into_pyarray(py))?;
    d.set_item("std", res.std.as_slice().to_vec().into_pyarray(py))?;
    // nalgebra is column-major; the covariance is symmetric, but transpose to be exact
    let cov: Vec<f64> = res.covariance.transpose().as_slice().to_vec();
    d.set_item("covariance", cov.into_pyarray(py).reshape([n, n])?)?;
    d.set_item("rss", res.rss)?;
    d.set_item("dof", res.dof)?;
    d.set_item("condition_number", res.condition_number)?;
    d.set_item("rank", res.rank)?;
    d.set_item("rows", res.rows)?;
    d.set_item(
        "method",
        match res.method {
            Method::GramRefined => "normal equations + refinement",
            Method::Gram => "normal equations",
            Method::StreamingQr => "streaming QR",
        },
    )?;
    Ok(d)
}

/// The arguments of a momentum identification: the time series Q, V, H borrowed from numpy as they are (see
/// [`Series`]), the known parameters and weights copied.
struct Args<'py> {
    q: Series<'py>,
    v: Series<'py>,
    h: Series<'py>,
    known: Batch,
    weights: Option<[f64; 6]>,
}

impl<'py> Args<'py> {
    fn new(
        m: &freefloat_core::Model,
        q: Arr<'_, 'py>,
        v: Arr<'_, 'py>,
        h: Arr<'_, 'py>,
        known_params: Arr,
        weights: Option<Arr>,
    ) -> PyResult<Args<'py>> {
        let (q, v, h) = (Series::new("Q", q, m.nq)?, Series::new("V", v, m.nv)?, Series::new("H", h, 6)?);
        if q.rows != h.rows || v.rows != h.rows {
            return Err(input_err(format!(
                "arguments `Q`, `V`, `H` must be stacked over the same samples: got {}, {}, {} rows",
                q.rows, v.rows, h.rows
            )));
        }
        let known = Batch::new("known_params", known_params, &[10 * m.nbodies()])?;
        let w = weights.map(|w| Batch::new("weights", w, &[6])).transpose()?;
        let weights = w.map(|w| std::array::from_fn(|k| w.data[k]));
        Ok(Args { q, v, h, known, weights })
    }

    fn problem<'a>(&'a self, columns: &'a [usize]) -> MomentumProblem<'a> {
        MomentumProblem {
            q: self.q.slice(),
            v: self.v.slice(),
            h: self.h.slice(),
            unknown_cols: columns,
            known_params: &self.known.data,
            weights: self.weights,
        }
    }
}

/// The engine names the per-sample arrays q, v, h; the Python functions call them Q, V, H.
fn python_names(e: FfError) -> FfError {
    match e {
        FfError::Argument { name, msg } if matches!(name.as_str(), "q" | "v" | "h") => {
            FfError::Argument { name: name.to_uppercase(), msg }
        }
        other => other,
    }
}

/// A (T, width) time series read where numpy keeps it, without a copy: a C-contiguous float64 array as given
/// (anything else converted once by numpy), registered with numpy's borrow checker as read-only while the call
/// lasts. Copying 67 000 samples (20 MB) took about a fifth of the whole identification's wall time, most of it
/// page faults of the fresh copy on the calling thread, and doubled the memory of a large data set. Finiteness is
/// the engine's per-sample check (on the worker threads, naming the sample). Like numpy's own functions that
/// release the GIL, this asks that no other thread writes to the arrays during the call.
struct Series<'py> {
    arr: PyReadonlyArrayDyn<'py, f64>,
    rows: usize,
}

impl<'py> Series<'py> {
    fn new(name: &str, obj: Arr<'_, 'py>, width: usize) -> PyResult<Series<'py>> {
        let mut arr = array_arg(obj, name)?;
        if !arr.is_c_contiguous() {
            let np = obj.py().import("numpy")?;
            arr = np.call_method1("ascontiguousarray", (arr.as_any(),))?.extract()?;
        }
        let shape = arr.shape();
        if shape.len() != 2 || shape[1] != width {
            return Err(input_err(format!(
                "argument `{name}`: expected shape (T, {width}), one row per sample, got {shape:?}"
            )));
        }
        arr.as_slice().map_err(|e| input_err(format!("argument `{name}`: {e}")))?;
        let rows = shape[0];
        Ok(Series { arr, rows })
    }

    /// The samples, row-major (`new` checked that the array is contiguous; were it not, the empty slice would
    /// fail the engine's size check with the argument's name).
    fn slice(&self) -> &[f64] {
        self.arr.as_slice().unwrap_or(&[])
    }
}

/// For benchmarks: one streaming pass of `identify_momentum` that builds every block of the
/// regressor and right-hand side and discards it (no solve). Returns the sum of the right-hand
/// sides. Same arguments as `identify_momentum`.
#[pyfunction]
#[pyo3(signature = (model, q, v, h, columns, known_params, weights = None))]
#[allow(clippy::too_many_arguments)]
pub fn momentum_regressor_stream<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    h: Arr<'_, 'py>,
    columns: Vec<usize>,
    known_params: Arr<'_, 'py>,
    weights: Option<Arr<'_, 'py>>,
) -> PyResult<f64> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let a = Args::new(m, q, v, h, known_params, weights)?;
    let problem = a.problem(&columns);
    py.detach(|| guard(|| momentum_regressor_pass(m, &problem).map_err(python_names)))
}
