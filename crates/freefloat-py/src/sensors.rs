//! Sensor models (freefloat_core::sensors): `measure` a recorded run with a sensor set.

use crate::batch::{array_arg, model_arg};
use crate::errors::{guard, input_err};
use freefloat_core::sensors::{measure as core_measure, parse_sensors, Samples};
use numpy::{IntoPyArray, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// A (T, n) array argument as a row-major copy.
fn rows(obj: &Bound<'_, PyAny>, name: &str, t: usize, n: usize) -> PyResult<Vec<f64>> {
    let a = array_arg(obj, name)?;
    if a.shape() != [t, n] {
        return Err(input_err(format!("argument `{name}`: expected shape ({t}, {n}), got {:?}", a.shape())));
    }
    Ok(contiguous(&a))
}

/// A row-major copy (one memcpy when the array is already C-contiguous).
fn contiguous(a: &numpy::PyReadonlyArrayDyn<'_, f64>) -> Vec<f64> {
    match a.as_slice() {
        Ok(s) => s.to_vec(),
        Err(_) => a.as_array().iter().copied().collect(),
    }
}

/// Sample a recorded run with a sensor set (`sensors`: YAML or JSON text of a `sensors:` list) from the
/// random streams of `seed`. t (T,), q (T, nq), v (T, nv), ddq (T, nv) or None. Returns one dict per
/// sensor: sensor, columns (list of names), t (N,), values (N, len(columns)), white_sigma (per-column
/// standard deviation of the white part of a rate sensor's errors; empty otherwise), period [s].
#[pyfunction]
#[pyo3(signature = (model, sensors, t, q, v, ddq = None, seed = 0))]
#[allow(clippy::too_many_arguments)]
pub fn measure<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    sensors: &str,
    t: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    ddq: Option<&Bound<'py, PyAny>>,
    seed: u64,
) -> PyResult<Bound<'py, PyList>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let ta = array_arg(t, "t")?;
    if ta.ndim() != 1 {
        return Err(input_err(format!("argument `t`: expected a 1-D array, got shape {:?}", ta.shape())));
    }
    let tv = contiguous(&ta);
    let n = tv.len();
    let qv = rows(q, "q", n, m.nq)?;
    let vv = rows(v, "v", n, m.nv)?;
    let av = match ddq {
        Some(a) if !a.is_none() => Some(rows(a, "ddq", n, m.nv)?),
        _ => None,
    };
    let spec = guard(|| parse_sensors(sensors))?;
    let streams = py.detach(|| {
        guard(|| {
            let s = Samples { t: &tv, q: &qv, v: &vv, ddq: av.as_deref(), nq: m.nq, nv: m.nv };
            core_measure(m, &s, &spec, seed)
        })
    })?;
    let out = PyList::empty(py);
    for st in streams {
        let d = PyDict::new(py);
        let (len, w) = (st.t.len(), st.columns.len());
        d.set_item("sensor", st.sensor)?;
        d.set_item("columns", st.columns)?;
        d.set_item("t", st.t.into_pyarray(py))?;
        d.set_item("values", st.values.into_pyarray(py).reshape([len, w])?)?;
        d.set_item("white_sigma", st.white_sigma.into_pyarray(py))?;
        d.set_item("period", st.period)?;
        out.append(d)?;
    }
    Ok(out)
}

/// Check a sensor set (YAML or JSON text) without running it; returns the sensors' names in order.
#[pyfunction]
pub fn check_sensors(sensors: &str) -> PyResult<Vec<String>> {
    Ok(guard(|| parse_sensors(sensors))?.into_iter().map(|s| s.name).collect())
}

/// Accelerations from noisy rates (`freefloat_core::sensors::smooth_rates`): the Rauch-Tung-Striebel smoother
/// of the white-jerk rate model, per column of `y` (N, k) sampled every `h` seconds. `log_ratio`:
/// log10(q h³ / r) for every column, or None for each column's ratio by generalised cross-validation. Returns a dict: rate
/// and accel (N, k), log_ratio and sigma (k,) (the estimated white rate noise per sample).
#[pyfunction]
#[pyo3(signature = (y, h, log_ratio = None))]
pub fn smooth_rates<'py>(
    py: Python<'py>,
    y: &Bound<'py, PyAny>,
    h: f64,
    log_ratio: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = array_arg(y, "y")?;
    let shape = a.shape().to_vec();
    if shape.len() != 2 {
        return Err(input_err(format!("argument `y`: expected shape (samples, channels), got {shape:?}")));
    }
    let data = contiguous(&a);
    let (n, k) = (shape[0], shape[1]);
    let r = py.detach(|| guard(|| freefloat_core::sensors::smooth_rates(&data, k, h, log_ratio)))?;
    let d = PyDict::new(py);
    let as2 = |v: Vec<f64>| -> PyResult<Bound<'py, PyAny>> { Ok(v.into_pyarray(py).reshape([n, k])?.into_any()) };
    d.set_item("rate", as2(r.rate)?)?;
    d.set_item("accel", as2(r.accel)?)?;
    d.set_item("log_ratio", r.log_ratio.into_pyarray(py))?;
    d.set_item("sigma", r.sigma.into_pyarray(py))?;
    Ok(d)
}
