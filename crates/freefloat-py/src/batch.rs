//! Stacked (time-series) arguments: every function takes one sample or a leading time axis.

use crate::errors::input_err;
use crate::model::PyModel;
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

/// A `freefloat.Model` (the Python facade, which holds the engine model in `_core`) or the engine
/// model itself.
pub fn model_arg<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyModel>> {
    if let Ok(m) = obj.downcast::<PyModel>() {
        return Ok(m.clone());
    }
    // interned: the attribute name is made once, not on every call (binding overhead, issue 16)
    obj.getattr(pyo3::intern!(obj.py(), "_core")).ok().and_then(|c| c.downcast_into::<PyModel>().ok()).ok_or_else(
        || {
            PyTypeError::new_err(format!(
                "expected a freefloat.Model, got {}",
                obj.get_type().name().map(|n| n.to_string()).unwrap_or_default()
            ))
        },
    )
}

/// Any array-like as a float64 numpy array (no copy when it already is one), naming the argument
/// when it cannot be read as numbers.
pub fn array_arg<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'py, f64>>() {
        return Ok(a);
    }
    let np = obj.py().import("numpy")?;
    // numpy would drop an imaginary part with only a ComplexWarning
    if np.call_method1("iscomplexobj", (obj,))?.is_truthy()? {
        return Err(input_err(format!("argument `{name}`: complex numbers are not accepted; give real numbers")));
    }
    let converted = np
        .call_method1("ascontiguousarray", (obj, "float64"))
        .map_err(|e| input_err(format!("argument `{name}`: cannot be read as an array of numbers ({e})")))?;
    converted.extract().map_err(|e| input_err(format!("argument `{name}`: {e}")))
}

/// Entries from which [`copy_out`] copies on several threads.
const PARALLEL_COPY_MIN: usize = 1 << 18;

/// `src.to_vec()`, on up to four threads for a long array. The copy of a long batch is work the calling thread does
/// alone before the engine's threads start (and its fresh pages fault in one by one): numpy's own copy of 20 MB
/// takes about 5 ms on one thread here. (The identification's time series are not copied at all: see
/// `estimation::Series`.) The caller holds the GIL throughout, so no Python code can write to `src` meanwhile.
fn copy_out(src: &[f64]) -> Vec<f64> {
    if src.len() < PARALLEL_COPY_MIN {
        return src.to_vec();
    }
    let threads = freefloat_core::threads::available_cores().min(4);
    if threads < 2 {
        return src.to_vec();
    }
    let mut out: Vec<f64> = Vec::with_capacity(src.len());
    let part = src.len().div_ceil(threads);
    let mut all_started = true;
    std::thread::scope(|sc| {
        let mut parts = out.spare_capacity_mut().chunks_mut(part).zip(src.chunks(part));
        let first = parts.next();
        for (dst, from) in parts {
            // a thread that cannot be started (a process at its thread limit): copy the plain way below, no panic
            if std::thread::Builder::new().spawn_scoped(sc, move || copy_into(dst, from)).is_err() {
                all_started = false;
                break;
            }
        }
        if let Some((dst, from)) = first {
            copy_into(dst, from);
        }
    });
    if !all_started {
        return src.to_vec();
    }
    // SAFETY: the chunks above cover the first src.len() entries of the spare capacity, each written once, and
    // every thread has joined (end of the scope).
    unsafe { out.set_len(src.len()) };
    out
}

fn copy_into(dst: &mut [std::mem::MaybeUninit<f64>], from: &[f64]) {
    for (d, x) in dst.iter_mut().zip(from) {
        d.write(*x);
    }
}

/// A validated, contiguous copy of an argument with `rows` samples of `width` numbers each.
pub struct Batch {
    pub data: Vec<f64>,
    pub rows: usize,
    pub width: usize,
    pub stacked: bool,
}

impl Batch {
    /// `inner` is the shape of one sample, e.g. [nq] or [nbodies, 6]. Checks the shape and that every
    /// entry is finite (for arguments the engine does not check itself).
    pub fn new(name: &str, obj: &Bound<'_, PyAny>, inner: &[usize]) -> PyResult<Batch> {
        let b = Batch::shape(name, obj, inner)?;
        // the engine's branch-free, vectorised check first; the position only on failure (the scan it replaced,
        // `position(!is_finite)`, took about 6 instructions per entry on the calling thread, callgrind)
        if freefloat_core::check::check_finite(name, &b.data).is_ok() {
            return Ok(b);
        }
        if let Some(k) = b.data.iter().position(|x| !x.is_finite()) {
            let width = b.width.max(1);
            let where_ =
                if b.stacked { format!("sample {}, entry {}", k / width, k % width) } else { format!("entry {k}") };
            return Err(input_err(format!("argument `{name}`: {where_} is {} (must be finite)", b.data[k])));
        }
        Ok(b)
    }

    /// Shape only (one sample or a leading time axis): for the arguments the engine's own check
    /// (`freefloat_core::check`) validates per sample — finiteness, quaternions, sizes.
    pub fn shape(name: &str, obj: &Bound<'_, PyAny>, inner: &[usize]) -> PyResult<Batch> {
        // Fast path (binding overhead, issue 16): a C-contiguous float64 array is copied straight out, without
        // registering a borrow with numpy's borrow checker (the copy happens now, with the GIL held, before any
        // Python code can run, so nothing can write to the array meanwhile).
        if let Ok(a) = obj.downcast::<PyArrayDyn<f64>>() {
            if a.is_c_contiguous() {
                let shape = a.shape();
                let stacked = if shape == inner {
                    false
                } else if shape.len() == inner.len() + 1 && &shape[1..] == inner {
                    true
                } else {
                    return Err(Batch::shape_error(name, inner, shape));
                };
                // SAFETY: contiguous float64 data of this array, read once under the GIL (see above).
                let data = copy_out(unsafe { a.as_slice() }.map_err(|e| input_err(format!("argument `{name}`: {e}")))?);
                let rows = if stacked { shape[0] } else { 1 };
                return Ok(Batch { data, rows, width: inner.iter().product(), stacked });
            }
        }
        let a = array_arg(obj, name)?;
        let shape = a.shape().to_vec();
        let stacked = if shape.as_slice() == inner {
            false
        } else if shape.len() == inner.len() + 1 && &shape[1..] == inner {
            true
        } else {
            return Err(Batch::shape_error(name, inner, &shape));
        };
        let data: Vec<f64> = match a.as_slice() {
            Ok(s) => s.to_vec(),
            Err(_) => a.as_array().iter().copied().collect(),
        };
        let width: usize = inner.iter().product();
        let rows = if stacked { shape[0] } else { 1 };
        Ok(Batch { data, rows, width, stacked })
    }

    fn shape_error(name: &str, inner: &[usize], shape: &[usize]) -> PyErr {
        let s: Vec<String> = inner.iter().map(|x| x.to_string()).collect();
        let expect = format!("({}) or (T, {})", s.join(", "), s.join(", "));
        input_err(format!("argument `{name}`: expected shape {expect}, got {shape:?}"))
    }

    #[inline]
    pub fn row(&self, k: usize) -> &[f64] {
        let k = if self.stacked { k } else { 0 };
        &self.data[k * self.width..(k + 1) * self.width]
    }
}

/// Number of samples of a set of arguments: single samples broadcast, stacked ones must agree.
pub fn common_rows(batches: &[(&str, &Batch)]) -> PyResult<(usize, bool)> {
    let mut rows: Option<(usize, &str)> = None;
    for (name, b) in batches {
        if b.stacked {
            match rows {
                None => rows = Some((b.rows, name)),
                Some((r, first)) if r != b.rows => {
                    return Err(input_err(format!(
                        "argument `{name}` has {} samples but `{first}` has {r}: stacked arguments must share the time axis",
                        b.rows
                    )))
                }
                _ => {}
            }
        }
    }
    if let Some((0, first)) = rows {
        // an empty stack is almost always a filter or slice that selected nothing upstream: say so rather than
        // return an empty result that fails later, far from its cause
        return Err(input_err(format!(
            "argument `{first}` has 0 samples (an empty stack): give at least one sample, as a 1-D array or as rows"
        )));
    }
    Ok(rows.map(|(r, _)| (r, true)).unwrap_or((1, false)))
}

/// A fresh numpy array of `shape` (non-empty) holding a copy of `data` (C order).
pub fn array_copy<'py>(py: Python<'py>, shape: &[usize], data: &[f64]) -> PyResult<Bound<'py, PyAny>> {
    let arr = PyArrayDyn::<f64>::zeros(py, shape, false);
    // SAFETY: the array was just created here, is C-contiguous and no one else holds it yet.
    unsafe { arr.as_slice_mut() }
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("internal array error: {e}")))?
        .copy_from_slice(data);
    Ok(arr.into_any())
}

/// Build the output array: `inner` is the shape of one sample's result.
pub fn output<'py>(
    py: Python<'py>,
    data: Vec<f64>,
    rows: usize,
    stacked: bool,
    inner: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let mut shape = vec![];
    if stacked {
        shape.push(rows);
    }
    shape.extend_from_slice(inner);
    if shape.is_empty() {
        return Ok(data[0].into_pyobject(py)?.into_any());
    }
    // Small results are copied into a fresh numpy array: cheaper than handing numpy the Vec, which needs a
    // Python object to own it (binding overhead of single calls, issue 16). Large ones are handed over uncopied.
    if data.len() <= 4096 {
        return array_copy(py, &shape, &data);
    }
    // Build the array with its final shape directly (a reshape would be a second numpy call).
    let arr = numpy::ndarray::ArrayD::from_shape_vec(shape, data)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("internal shape error: {e}")))?;
    let arr: Bound<'py, PyArrayDyn<f64>> = arr.into_pyarray(py);
    Ok(arr.into_any())
}
