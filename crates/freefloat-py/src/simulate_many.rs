//! `simulate_many`: B simulations (initial states, inertial parameters or torque tables) in one call, run on all
//! cores with the GIL released (`freefloat_core::sim::simulate_many`).

use crate::batch::{array_arg, model_arg};
use crate::errors::{guard, input_err, interrupted_with, reraise_foreign, signal_hook, to_py};
use freefloat_core::error::{FfError, Partial};
use freefloat_core::sim::{self, BatchSpec, Hold, Method, SimOptions, Stacked};
use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

/// A stacked argument: (data, rows) for an array of shape (width,) [shared] or (B, width...) [one row per member].
fn stacked(obj: &Bound<'_, PyAny>, name: &str, inner: usize) -> PyResult<(Vec<f64>, usize)> {
    let a = array_arg(obj, name)?;
    let shape = a.shape().to_vec();
    let data: Vec<f64> = a.as_array().iter().copied().collect();
    let rows = match shape.as_slice() {
        [w] if *w == inner => 1,
        [b, rest @ ..] if !rest.is_empty() && rest.iter().product::<usize>() == inner => *b,
        _ => {
            return Err(input_err(format!(
            "argument `{name}`: expected shape ({inner},) for all members or (B, {inner}) for B members, got {shape:?}"
        )))
        }
    };
    if let Some(k) = data.iter().position(|x| !x.is_finite()) {
        return Err(input_err(format!("argument `{name}`: entry {k} is {} (must be finite)", data[k])));
    }
    Ok((data, rows))
}

/// Simulate B members at once (RK4 or RK45, table torques): returns (list of B trajectory dicts or None, list of
/// (index, exception) for the members that failed).
#[pyfunction]
#[pyo3(signature = (
    model, q0, v0, t_final, dt, method = "rk4", rtol = 1e-9, atol = 1e-12, max_step = None, record_every = 1,
    torques = None, torque_times = None, hold = "zoh", params = None, threads = 0, max_steps = 50_000_000
))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_many<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: &Bound<'py, PyAny>,
    v0: &Bound<'py, PyAny>,
    t_final: f64,
    dt: f64,
    method: &str,
    rtol: f64,
    atol: f64,
    max_step: Option<f64>,
    record_every: usize,
    torques: Option<&Bound<'py, PyAny>>,
    torque_times: Option<&Bound<'py, PyAny>>,
    hold: &str,
    params: Option<&Bound<'py, PyAny>>,
    threads: usize,
    max_steps: usize,
) -> PyResult<(Bound<'py, PyList>, Bound<'py, PyList>)> {
    let mb = model_arg(model)?;
    let m = mb.get().inner.clone();
    let method = match method {
        "rk4" => Method::Rk4,
        "rk45" | "dopri5" => Method::Rk45 { rtol, atol, max_step: max_step.unwrap_or(f64::INFINITY) },
        other => return Err(input_err(format!("argument `method`: must be 'rk4' or 'rk45', got '{other}'"))),
    };
    let hold = match hold {
        "zoh" => Hold::Zoh,
        "linear" => Hold::Linear,
        other => return Err(input_err(format!("argument `hold`: must be 'zoh' or 'linear', got '{other}'"))),
    };
    let opts = SimOptions { t_final, dt, method, record_every, max_steps };
    let (qd, qr) = stacked(q0, "q0", m.nq)?;
    let (vd, vr) = stacked(v0, "v0", m.nv)?;
    let pp = params.map(|p| stacked(p, "params", 10 * m.nbodies())).transpose()?;
    // torques: (T, nv) shared or (B, T, nv) per member; times default k·dt as in `simulate`
    let (tq, times) = match torques {
        None => (None, None),
        Some(t) => {
            let a = array_arg(t, "torques")?;
            let shape = a.shape().to_vec();
            let (rows, nt) = match shape.as_slice() {
                [nt, c] if *c == m.nv => (1, *nt),
                [b, nt, c] if *c == m.nv => (*b, *nt),
                _ => {
                    return Err(input_err(format!(
                        "argument `torques`: expected shape (T, {nv}) for all members or (B, T, {nv}), got {shape:?}",
                        nv = m.nv
                    )))
                }
            };
            let data: Vec<f64> = a.as_array().iter().copied().collect();
            let times: Vec<f64> = match torque_times {
                Some(tt) => array_arg(tt, "torque_times")?.as_array().iter().copied().collect(),
                None => (0..nt).map(|k| k as f64 * dt).collect(),
            };
            if times.len() != nt {
                return Err(input_err(format!("argument `torque_times`: {} times for {nt} torque rows", times.len())));
            }
            (Some((data, rows)), Some(times))
        }
    };
    let spec = BatchSpec {
        q0: Stacked { data: &qd, rows: qr },
        v0: Stacked { data: &vd, rows: vr },
        params: pp.as_ref().map(|(d, r)| Stacked { data: d, rows: *r }),
        torques: tq.as_ref().map(|(d, r)| Stacked { data: d, rows: *r }),
        torque_times: times.as_deref(),
        hold,
    };
    // Ctrl-C: the calling thread polls the hook (GIL re-taken for the signal check only) and stops every member
    let mut raised: Option<PyErr> = None;
    let r = {
        let raised = &mut raised;
        py.detach(move || {
            let mut hook = signal_hook(raised);
            guard(|| sim::simulate_many_interruptible(&m, &spec, &opts, threads, Some(&mut hook)))
        })
    };
    reraise_foreign(py, raised)?;
    let (results, stopped) = r?;
    let out = PyList::empty(py);
    let failures = PyList::empty(py);
    let mut finished = 0;
    for (k, r) in results.into_iter().enumerate() {
        match r {
            Ok(tr) => {
                finished += 1;
                out.append(crate::simulate::traj_dict(py, tr)?)?;
            }
            // stopped by Ctrl-C: the member's samples so far, marked as such
            Err(FfError::Interrupted { msg, partial: Some(Partial::Trajectory(tr)) }) if stopped => {
                let d = crate::simulate::traj_dict(py, *tr)?;
                d.set_item("interrupted", msg)?;
                out.append(d)?;
            }
            Err(e) => {
                out.append(py.None())?;
                failures.append((k, to_py(e).into_value(py)))?;
            }
        }
    }
    if stopped {
        // `partial` is (members, failures) as the normal return: finished members whole, running ones cut
        let n = out.len();
        let msg = format!("simulate_many stopped by Ctrl-C: {finished} of {n} members finished");
        let partial = PyTuple::new(py, [out.into_any(), failures.into_any()])?.into_any().unbind();
        return Err(interrupted_with(py, &msg, Some(partial)));
    }
    Ok((out, failures))
}
