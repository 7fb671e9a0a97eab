//! `simulate`: the engine's integrators driven from Python. Python callables (torque function,
//! controller, prescribed motion, progress) are called with the GIL held; without them the whole
//! run happens with the GIL released.

use crate::algorithms::prescribed_bodies;
use crate::environment::PyEnvironment;
use crate::errors::{guard, input_err};
use crate::model::PyModel;
use freefloat_core::environment::Environment;
use freefloat_core::sim::{self, Controller, Hold, Inputs, Method, Prescription, SimOptions, TorqueSource};
use freefloat_core::FfError;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::cell::RefCell;
use std::rc::Rc;

/// The first Python exception raised inside a callback; re-raised when the run stops.
type Stash = Rc<RefCell<Option<PyErr>>>;

fn stash_err(stash: &Stash, e: PyErr, what: &str) -> FfError {
    let mut s = stash.borrow_mut();
    if s.is_none() {
        *s = Some(e);
    }
    FfError::Numerical(format!("{what} raised an exception"))
}

/// Copy a callback's return value (anything array-like) into `out`, checking its length.
fn fill(obj: &Bound<'_, PyAny>, out: &mut [f64], what: &str) -> PyResult<()> {
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj, "float64"))?;
    let arr: PyReadonlyArrayDyn<f64> = arr.extract()?;
    if arr.len() != out.len() {
        return Err(input_err(format!("{what} must return {} numbers, returned shape {:?}", out.len(), arr.shape())));
    }
    for (o, x) in out.iter_mut().zip(arr.as_array().iter()) {
        *o = *x;
    }
    Ok(())
}

fn state_fn<'py>(py: Python<'py>, f: Bound<'py, PyAny>, stash: Stash, what: &'static str) -> sim::TorqueFn<'py> {
    Box::new(move |t, q, v, out| {
        let r =
            f.call1((t, PyArray1::from_slice(py, q), PyArray1::from_slice(py, v))).and_then(|r| fill(&r, out, what));
        r.map_err(|e| stash_err(&stash, e, what))
    })
}

#[pyfunction]
#[pyo3(signature = (
    model, q0, v0, t_final, dt, method = "rk4", rtol = 1e-9, atol = 1e-12, max_step = None, record_every = 1,
    torques = None, torque_times = None, hold = "zoh", controller = None, controller_period = None,
    prescribed = None, prescription = None, max_steps = 50_000_000, progress = None, formulation = "aba",
    environment = None
))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    model: &PyModel,
    q0: PyReadonlyArray1<'py, f64>,
    v0: PyReadonlyArray1<'py, f64>,
    t_final: f64,
    dt: f64,
    method: &str,
    rtol: f64,
    atol: f64,
    max_step: Option<f64>,
    record_every: usize,
    torques: Option<Bound<'py, PyAny>>,
    torque_times: Option<PyReadonlyArray1<'py, f64>>,
    hold: &str,
    controller: Option<Bound<'py, PyAny>>,
    controller_period: Option<f64>,
    prescribed: Option<Vec<String>>,
    prescription: Option<Bound<'py, PyAny>>,
    max_steps: usize,
    progress: Option<Bound<'py, PyAny>>,
    formulation: &str,
    environment: Option<PyRef<'py, PyEnvironment>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = model.inner.clone();
    let env: Option<Environment> = environment.map(|e| e.inner);
    if let Some(e) = &env {
        guard(|| e.check(&m))?;
    }
    let formulation = match formulation {
        "aba" => sim::Formulation::Aba,
        "dq" => sim::Formulation::DualQuaternion,
        other => return Err(input_err(format!("argument `formulation`: must be 'aba' or 'dq', got '{other}'"))),
    };
    let method = match method {
        "rk4" => Method::Rk4,
        "rk45" | "dopri5" => Method::Rk45 { rtol, atol, max_step: max_step.unwrap_or(f64::INFINITY) },
        other => return Err(input_err(format!("method must be 'rk4' or 'rk45', got '{other}'"))),
    };
    let opts = SimOptions { t_final, dt, method, record_every, max_steps };
    let stash: Stash = Rc::new(RefCell::new(None));

    let hold = match hold {
        "zoh" => Hold::Zoh,
        "linear" => Hold::Linear,
        other => return Err(input_err(format!("hold must be 'zoh' or 'linear', got '{other}'"))),
    };
    // Parse the torques into plain data first: without Python callbacks the run moves to a thread
    // that does not hold the GIL, and only plain data may go there.
    let torque_spec = match torques {
        None => TorqueSpec::Zero,
        Some(t) if t.is_callable() => TorqueSpec::Callable(t),
        Some(t) => {
            let arr: PyReadonlyArrayDyn<f64> =
                py.import("numpy")?.call_method1("asarray", (t, "float64"))?.extract()?;
            let shape = arr.shape().to_vec();
            let rows = match shape.as_slice() {
                [r, c] if *c == m.nv => *r,
                [c] if *c == m.nv => 1,
                _ => {
                    return Err(input_err(format!(
                        "argument `torques`: expected a callable or an array of shape (T, {}), got {:?}",
                        m.nv, shape
                    )))
                }
            };
            let times: Vec<f64> = match &torque_times {
                Some(tt) => tt.as_array().to_vec(),
                None => (0..rows).map(|k| k as f64 * dt).collect(),
            };
            if times.len() != rows {
                return Err(input_err(format!(
                    "argument `torque_times`: {} times for {rows} torque rows",
                    times.len()
                )));
            }
            let values: Vec<f64> = arr.as_array().iter().copied().collect();
            // Validate now (clear errors before any work), build again where it runs.
            guard(|| TorqueSource::table(times.clone(), values.clone(), m.nv, hold))?;
            TorqueSpec::Table(times, values)
        }
    };
    let ctrl = match (controller, controller_period) {
        (None, _) => None,
        (Some(c), Some(p)) if c.is_callable() => {
            Some(Controller { period: p, f: state_fn(py, c, stash.clone(), "the controller") })
        }
        (Some(_), None) => {
            return Err(input_err("a controller needs `controller_period` (its sample time in seconds)"))
        }
        (Some(_), Some(_)) => {
            return Err(input_err(
                "argument `controller` must be callable as controller(t, q, v) -> generalized forces (nv,)",
            ))
        }
    };
    let presc = match (prescribed, prescription) {
        (None, None) => None,
        (Some(names), Some(f)) if f.is_callable() => {
            let bodies = prescribed_bodies(&m, &names)?;
            let st = stash.clone();
            let f = f.clone();
            let pf: sim::PrescriptionFn = Box::new(move |t, q, v, a| {
                let r = f.call1((t,)).and_then(|r| {
                    let (rq, rv, ra): (Bound<PyAny>, Bound<PyAny>, Bound<PyAny>) = r.extract().map_err(|_| {
                        input_err(
                            "prescription(t) must return a tuple (q, v, a) of full-length arrays (nq,), (nv,), (nv,)",
                        )
                    })?;
                    fill(&rq, q, "prescription q")?;
                    fill(&rv, v, "prescription v")?;
                    fill(&ra, a, "prescription a")
                });
                r.map_err(|e| stash_err(&st, e, "the prescription"))
            });
            Some(Prescription { bodies, f: pf })
        }
        (Some(_), Some(_)) => {
            return Err(input_err("argument `prescription` must be callable as prescription(t) -> (q, v, a)"))
        }
        _ => {
            return Err(input_err(
                "give both `prescribed` (joint names) and `prescription` (a function of t), or neither",
            ))
        }
    };
    let has_callbacks =
        matches!(torque_spec, TorqueSpec::Callable(_)) || ctrl.is_some() || presc.is_some() || progress.is_some();
    let q0 = q0.as_array().to_vec();
    let v0 = v0.as_array().to_vec();
    let nv = m.nv;

    let m_after = m.clone();
    let result = if has_callbacks {
        let torque_src = match torque_spec {
            TorqueSpec::Zero => TorqueSource::Zero,
            TorqueSpec::Table(times, values) => guard(|| TorqueSource::table(times, values, nv, hold))?,
            TorqueSpec::Callable(f) => TorqueSource::Function(state_fn(py, f, stash.clone(), "the torque function")),
        };
        let inputs = Inputs { torques: torque_src, controller: ctrl, prescription: presc, environment: env.as_ref() };
        let st = stash.clone();
        let mut prog = progress.map(|p| {
            move |frac: f64| -> bool {
                match p.call1((frac,)) {
                    Ok(r) => !matches!(r.extract::<bool>(), Ok(false)), // only an explicit False aborts
                    Err(e) => {
                        stash_err(&st, e, "the progress callback");
                        false
                    }
                }
            }
        });
        let pr: Option<sim::Progress> = prog.as_mut().map(|p| p as &mut dyn FnMut(f64) -> bool);
        guard(|| sim::simulate_with(&m, &q0, &v0, &opts, inputs, formulation, pr))
    } else {
        // No Python code runs during the simulation: release the GIL; the inputs are built from
        // plain data on the detached side.
        let table = match torque_spec {
            TorqueSpec::Table(times, values) => Some((times, values)),
            _ => None,
        };
        let (q0, v0) = (&q0, &v0);
        py.detach(move || {
            guard(|| {
                let torques = match table {
                    Some((times, values)) => TorqueSource::table(times, values, nv, hold)?,
                    None => TorqueSource::Zero,
                };
                let inputs = Inputs { torques, environment: env.as_ref(), ..Default::default() };
                sim::simulate_with(&m, q0, v0, &opts, inputs, formulation, None)
            })
        })
    };
    if let Some(e) = stash.borrow_mut().take() {
        return Err(e);
    }
    let tr = result?;
    let d = PyDict::new(py);
    let n = tr.len();
    d.set_item("t", PyArray1::from_slice(py, &tr.t))?;
    d.set_item("q", PyArray1::from_slice(py, &tr.q).reshape([n, tr.nq])?)?;
    d.set_item("v", PyArray1::from_slice(py, &tr.v).reshape([n, tr.nv])?)?;
    d.set_item("ddq", PyArray1::from_slice(py, &tr.ddq).reshape([n, tr.nv])?)?;
    d.set_item("tau", PyArray1::from_slice(py, &tr.tau).reshape([n, tr.nv])?)?;
    d.set_item("momentum", PyArray1::from_slice(py, &tr.momentum).reshape([n, 6])?)?;
    d.set_item("kinetic_energy", PyArray1::from_slice(py, &tr.kinetic_energy))?;
    d.set_item("work", PyArray1::from_slice(py, &tr.work))?;
    d.set_item("steps", tr.steps)?;
    d.set_item("rejected", tr.rejected)?;
    d.set_item("evaluations", tr.evaluations)?;
    if let Some(e) = env.as_ref().filter(|e| e.orbit.is_some()) {
        // the frame origin's inertial orbit at the recorded times (the propagation the run used)
        let orbit = guard(|| freefloat_core::environment::reference_orbit(e, &m_after, &q0, &v0, &tr.t))?;
        d.set_item("orbit", PyArray1::from_vec(py, orbit).reshape([n, 6])?)?;
    }
    Ok(d)
}

/// What the caller gave as torques, before it becomes an engine `TorqueSource`.
enum TorqueSpec<'py> {
    Zero,
    Table(Vec<f64>, Vec<f64>),
    Callable(Bound<'py, PyAny>),
}
