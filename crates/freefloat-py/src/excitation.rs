//! Exciting-trajectory design (freefloat_core::excitation): the eq. (32) objective for one or many
//! sampled joint paths, and the minimal-regressor rows along a path (for pruning and figures).

use crate::batch::{array_arg, model_arg};
use crate::errors::{guard, input_err, reraise_foreign, signal_hook};
use freefloat_core::excitation::{evaluate_batch_interruptible, excitation_rows, JointPath, ObjectiveSpec};
use numpy::{IntoPyArray, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Arr<'a, 'py> = &'a Bound<'py, PyAny>;

/// A (B, S, n) or (S, n) array as (B, S, n) data.
fn paths_arg(obj: Arr, name: &str, n: usize) -> PyResult<(Vec<f64>, usize, usize)> {
    let a = array_arg(obj, name)?;
    let shape = a.shape().to_vec();
    let (b, s) = match shape.as_slice() {
        [s, k] if *k == n => (1, *s),
        [b, s, k] if *k == n => (*b, *s),
        _ => return Err(input_err(format!("argument `{name}`: expected (S, {n}) or (B, S, {n}), got {shape:?}"))),
    };
    let data: Vec<f64> = a.as_array().iter().copied().collect();
    Ok((data, b, s))
}

/// Angles and rates of B paths, checked to have the same shape: (q, qd, B, S).
fn path_pair(q: Arr, qd: Arr, n: usize) -> PyResult<(Vec<f64>, Vec<f64>, usize, usize)> {
    let (qa, b, s) = paths_arg(q, "q", n)?;
    let (qda, b2, s2) = paths_arg(qd, "qd", n)?;
    if (b, s) != (b2, s2) {
        return Err(input_err(format!("arguments `q`, `qd`: shapes differ ({b}×{s} and {b2}×{s2} samples)")));
    }
    Ok((qa, qda, b, s))
}

/// Evaluate Naveen, Shah, Misra's eq. (32) for B joint paths at once (worker threads, GIL released; Ctrl-C
/// stops them within ~20 ms and raises `Interrupted`, partial None).
/// q (B, S, n) / qd: driven joints' angles and rates on a grid of `step` seconds; iq, iv: their q and v
/// indices; q0 (nq,): start configuration (base pose, other joints); rows at grid points offset + k·stride;
/// columns: minimal-regressor columns (indices into 10·nbodies); n_signal: how many of the driven joints (the
/// first ones) count in the signal term. Returns a dict of arrays (B,):
/// objective, condition_number, mean_square, and singular_values (B, len(columns)).
#[pyfunction]
#[pyo3(signature = (model, q0, iq, iv, step, q, qd, stride, offset, columns, weight, n_signal, threads = 2))]
#[allow(clippy::too_many_arguments)]
pub fn excitation_objective<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: Vec<f64>,
    iq: Vec<usize>,
    iv: Vec<usize>,
    step: f64,
    q: Arr<'_, 'py>,
    qd: Arr<'_, 'py>,
    stride: usize,
    offset: usize,
    columns: Vec<usize>,
    weight: f64,
    n_signal: usize,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let n = iq.len();
    let (qa, qda, b, s) = path_pair(q, qd, n)?;
    if columns.is_empty() {
        return Err(input_err("argument `columns`: no regressor columns"));
    }
    let w = s * n;
    let paths: Vec<JointPath> = (0..b)
        .map(|k| JointPath { step, iq: &iq, iv: &iv, q: &qa[k * w..(k + 1) * w], qd: &qda[k * w..(k + 1) * w] })
        .collect();
    let spec = ObjectiveSpec { q0: &q0, stride, offset, columns: &columns, weight, n_signal, threads: 1 };
    // Ctrl-C: the calling thread polls the hook (GIL re-taken for the signal check only) while the workers
    // evaluate, and stops them before their next grid point; any other exception from a signal handler comes
    // back unchanged
    let mut raised: Option<PyErr> = None;
    let results = {
        let raised = &mut raised;
        py.detach(move || {
            let mut hook = signal_hook(raised);
            guard(|| evaluate_batch_interruptible(m, &spec, &paths, threads, Some(&mut hook)))
        })
    };
    reraise_foreign(py, raised)?;
    let results = results?;
    let (mut obj, mut kap, mut ms, mut sv) = (vec![], vec![], vec![], vec![]);
    for r in results {
        let e = r.map_err(crate::errors::to_py)?;
        obj.push(e.objective);
        kap.push(e.condition_number);
        ms.push(e.mean_square);
        sv.extend(e.singular_values);
    }
    let d = PyDict::new(py);
    d.set_item("objective", obj.into_pyarray(py))?;
    d.set_item("condition_number", kap.into_pyarray(py))?;
    d.set_item("mean_square", ms.into_pyarray(py))?;
    d.set_item("singular_values", sv.into_pyarray(py).reshape([b, columns.len()])?)?;
    Ok(d)
}

/// Minimal-regressor rows along one joint path: dict with rows (6·points, len(columns)), sumsq, count,
/// q_end (the configuration at the end, base pose integrated).
#[pyfunction]
#[pyo3(name = "excitation_rows", signature = (model, q0, iq, iv, step, q, qd, stride, offset, columns, n_signal))]
#[allow(clippy::too_many_arguments)]
pub fn excitation_rows_py<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: Vec<f64>,
    iq: Vec<usize>,
    iv: Vec<usize>,
    step: f64,
    q: Arr<'_, 'py>,
    qd: Arr<'_, 'py>,
    stride: usize,
    offset: usize,
    columns: Vec<usize>,
    n_signal: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let n = iq.len();
    let (qa, qda, b, _) = path_pair(q, qd, n)?;
    if b != 1 {
        return Err(input_err("arguments `q`, `qd`: expected one path, (S, n) each"));
    }
    let path = JointPath { step, iq: &iq, iv: &iv, q: &qa, qd: &qda };
    let ex = py.detach(|| guard(|| excitation_rows(m, &q0, &path, stride, offset, &columns, n_signal, 2)))?;
    let (r, c) = (ex.rows.nrows(), ex.rows.ncols());
    let rows: Vec<f64> = ex.rows.transpose().as_slice().to_vec(); // column-major -> row-major
    let d = PyDict::new(py);
    d.set_item("rows", rows.into_pyarray(py).reshape([r, c])?)?;
    d.set_item("sumsq", ex.sumsq)?;
    d.set_item("count", ex.count)?;
    d.set_item("q_end", ex.q_end.into_pyarray(py))?;
    Ok(d)
}
