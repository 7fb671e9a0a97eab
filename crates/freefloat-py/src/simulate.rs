//! `simulate`: the engine's integrators driven from Python. Python callables (torque function,
//! controller, prescribed motion, progress) are called with the GIL held; without them the whole
//! run happens with the GIL released.

use crate::algorithms::prescribed_bodies;
use crate::environment::PyEnvironment;
use crate::errors::{guard, guard_raw, input_err, interrupted_with, is_ctrl_c, reraise_foreign, signal_hook};
use crate::model::PyModel;
use freefloat_core::environment::Environment;
use freefloat_core::model::Model;
use freefloat_core::sim::{
    self, Actuators, Controller, Hold, InputTiming, Inputs, JointLimit, Method, Prescription, SimOptions, Tank,
    Thruster, TorqueSource, Wheel,
};
use freefloat_core::spatial::V3;
use freefloat_core::FfError;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::cell::RefCell;
use std::rc::Rc;

/// The first Python exception raised inside a callback; re-raised when the run stops.
type Stash = Rc<RefCell<Option<PyErr>>>;

fn stash_err(stash: &Stash, e: PyErr, what: &str) -> FfError {
    let ctrl_c = Python::attach(|py| is_ctrl_c(py, &e));
    let mut s = stash.borrow_mut();
    if s.is_none() {
        *s = Some(e);
    }
    if ctrl_c {
        // Ctrl-C seen while Python code ran in a callback: an interruption, with the samples so far
        return FfError::interrupted("stopped by Ctrl-C");
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
    actuators = None, input_timing = "step", max_memory = None, environment = None
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
    actuators: Option<Bound<'py, PyAny>>,
    input_timing: &str,
    max_memory: Option<f64>,
    environment: Option<PyRef<'py, PyEnvironment>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = model.inner.clone();
    let env: Option<Environment> = environment.map(|e| e.inner);
    if let Some(e) = &env {
        guard(|| e.check(&m))?;
    }
    let timing = match input_timing {
        "step" => InputTiming::PerStep,
        "stage" => InputTiming::Stage,
        other => return Err(input_err(format!("argument `input_timing`: must be 'step' or 'stage', got '{other}'"))),
    };
    let acts = match &actuators {
        None => None,
        Some(a) if a.is_none() => None,
        Some(a) => Some(parse_actuators(&m, a)?),
    };
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
    // Work sized up front: the recording must fit in `max_memory` bytes (the Python layer's default is a
    // fraction of the memory available), checked before any work.
    if let Some(limit) = max_memory {
        if t_final.is_finite() && t_final > 0.0 && dt.is_finite() && dt > 0.0 && record_every > 0 {
            let samples = sim::planned_samples(&opts);
            let bytes = sim::planned_bytes(&m, &opts);
            if bytes > limit {
                return Err(input_err(format!(
                    "argument `t_final`: this run would record {samples:.3e} samples of {} bytes = {} GB, more \
                     than the memory limit of {} GB (max_memory); record fewer samples (a larger record_every \
                     or dt, a shorter t_final) or raise max_memory",
                    sim::Trajectory::bytes_per_sample(&m),
                    sig3(bytes / 1e9),
                    sig3(limit / 1e9)
                )));
            }
        }
    }
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
            // A C-contiguous array is copied in one block (the element iterator cost more than the run's first
            // steps on a 10 s table at dt/2).
            let values: Vec<f64> = match arr.as_slice() {
                Ok(x) => x.to_vec(),
                Err(_) => arr.as_array().iter().copied().collect(),
            };
            // Validated now (clear errors before any work); the checked vectors come back out, to be moved (not
            // copied and checked again) into the source where the run happens.
            match guard(|| TorqueSource::table(times, values, m.nv, hold))? {
                TorqueSource::Table { times, values, .. } => TorqueSpec::Table(times, values),
                _ => unreachable!("TorqueSource::table makes a table"),
            }
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
            // the entries the prescription drives: a NaN or an infinity there is named, with the time
            let used: Vec<(String, Vec<usize>, Vec<usize>)> = bodies
                .iter()
                .map(|&b| {
                    let (iq, iv) = (m.idx_q[b], m.idx_v[b]);
                    (m.joint_names[b].clone(), (iq..iq + m.nqs[b]).collect(), (iv..iv + m.nvs[b]).collect())
                })
                .collect();
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
                    fill(&ra, a, "prescription a")?;
                    for (joint, qi, vi) in &used {
                        for (what, x, idx) in [("q", &*q, qi), ("v", &*v, vi), ("a", &*a, vi)] {
                            if let Some(&k) = idx.iter().find(|&&k| !x[k].is_finite()) {
                                return Err(input_err(format!(
                                    "argument `prescription`: at t = {t} its {what}[{k}] (joint '{joint}') is {}; a \
                                     prescribed motion must be finite",
                                    x[k]
                                )));
                            }
                        }
                    }
                    Ok(())
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

    let mut raised: Option<PyErr> = None;
    let mut returned_false = false;
    let m_after = m.clone();
    let result = if has_callbacks {
        let torque_src = match torque_spec {
            TorqueSpec::Zero => TorqueSource::Zero,
            TorqueSpec::Table(times, values) => TorqueSource::Table { times, values, hold },
            TorqueSpec::Callable(f) => TorqueSource::Function(state_fn(py, f, stash.clone(), "the torque function")),
        };
        let inputs = Inputs {
            torques: torque_src,
            controller: ctrl,
            prescription: presc,
            actuators: acts,
            timing,
            environment: env.as_ref(),
        };
        let st = stash.clone();
        // Python code runs in the callbacks (GIL held): the hook checks for Ctrl-C itself (at most every
        // 20 ms), then calls the progress callback, whose explicit False stops the run.
        let rf = &mut returned_false;
        let mut prog = move |frac: f64| -> bool {
            if let Err(e) = py.check_signals() {
                stash_err(&st, e, "Ctrl-C");
                return false;
            }
            match &progress {
                None => true,
                Some(p) => match p.call1((frac,)) {
                    Ok(r) => {
                        let go = !matches!(r.extract::<bool>(), Ok(false));
                        *rf = !go;
                        go
                    }
                    Err(e) => {
                        stash_err(&st, e, "the progress callback");
                        false
                    }
                },
            }
        };
        let pr: Option<sim::Progress> = Some(&mut prog);
        guard_raw(|| sim::simulate_with(&m, &q0, &v0, &opts, inputs, formulation, pr))?
    } else {
        // No Python code runs during the simulation: release the GIL; the inputs are built from
        // plain data on the detached side. The hook re-takes the GIL only to check for Ctrl-C.
        let table = match torque_spec {
            TorqueSpec::Table(times, values) => Some((times, values)),
            _ => None,
        };
        let raised = &mut raised;
        let (q0, v0, env) = (&q0, &v0, &env);
        py.detach(move || {
            let mut hook = signal_hook(raised);
            guard_raw(|| {
                let torques = match table {
                    Some((times, values)) => TorqueSource::Table { times, values, hold },
                    None => TorqueSource::Zero,
                };
                let inputs =
                    Inputs { torques, actuators: acts, timing, environment: env.as_ref(), ..Default::default() };
                sim::simulate_with(&m, q0, v0, &opts, inputs, formulation, Some(&mut hook))
            })
        })?
    };
    reraise_foreign(py, raised)?;
    let stashed = stash.borrow_mut().take();
    match (stashed, result) {
        // Ctrl-C or a stop by the progress callback: raise `Interrupted` (a KeyboardInterrupt) with the samples
        // recorded so far as `partial`.
        (s, Err(FfError::Interrupted { msg, partial })) if s.as_ref().is_none_or(|e| is_ctrl_c(py, e)) => {
            let msg = if returned_false { format!("{msg} (the progress callback returned False)") } else { msg };
            let partial = match partial {
                Some(freefloat_core::error::Partial::Trajectory(tr)) => Some(traj_dict(py, *tr)?.into_any().unbind()),
                _ => None,
            };
            Err(interrupted_with(py, &msg, partial))
        }
        (Some(e), _) => Err(e),
        (None, Err(e)) => Err(crate::errors::to_py(e)),
        (None, Ok(tr)) => {
            // the frame origin's inertial orbit at the recorded times (the propagation the run used)
            let orbit = match env.as_ref().filter(|e| e.orbit.is_some()) {
                Some(e) => Some(guard(|| freefloat_core::environment::reference_orbit(e, &m_after, &q0, &v0, &tr.t))?),
                None => None,
            };
            let n = tr.len();
            let d = traj_dict(py, tr)?;
            if let Some(orbit) = orbit {
                d.set_item("orbit", PyArray1::from_vec(py, orbit).reshape([n, 6])?)?;
            }
            Ok(d)
        }
    }
}

/// The trajectory as the dict of arrays the Python layer turns into a `Trajectory` (also `simulate_many`'s).
pub(crate) fn traj_dict<'py>(py: Python<'py>, tr: sim::Trajectory) -> PyResult<Bound<'py, PyDict>> {
    // The recorded vectors move into numpy (no copy): a long run's record is not held twice at the end.
    let d = PyDict::new(py);
    let n = tr.len();
    let nt = tr.propellant.len().checked_div(n).unwrap_or(0);
    let nb = if tr.base_parameters.is_empty() { 0 } else { 10 };
    let sim::Trajectory {
        nq, nv, t, q, v, ddq, tau, momentum, kinetic_energy, work, propellant, base_parameters, ..
    } = tr;
    d.set_item("t", recycled_array(py, t)?)?;
    d.set_item("q", recycled_array(py, q)?.reshape([n, nq])?)?;
    d.set_item("v", recycled_array(py, v)?.reshape([n, nv])?)?;
    d.set_item("ddq", recycled_array(py, ddq)?.reshape([n, nv])?)?;
    d.set_item("tau", recycled_array(py, tau)?.reshape([n, nv])?)?;
    d.set_item("momentum", recycled_array(py, momentum)?.reshape([n, 6])?)?;
    d.set_item("kinetic_energy", recycled_array(py, kinetic_energy)?)?;
    d.set_item("work", recycled_array(py, work)?)?;
    d.set_item("propellant", PyArray1::from_vec(py, propellant).reshape([n, nt])?)?;
    d.set_item("base_parameters", PyArray1::from_vec(py, base_parameters).reshape([n, nb])?)?;
    d.set_item("steps", tr.steps)?;
    d.set_item("rejected", tr.rejected)?;
    d.set_item("evaluations", tr.evaluations)?;
    Ok(d)
}

/// The owner of a recorded vector that numpy arrays view: when the last of them is freed, the vector goes back to the
/// engine's spare record buffers (`sim::recycle`), so that the next run writes into pages that are already mapped
/// instead of faulting fresh ones in (about a tenth of a 10-s benchmark run, see `sim::SPARE_BYTES`).
#[pyclass(frozen)]
struct RecordBuffer(Vec<f64>);

impl Drop for RecordBuffer {
    fn drop(&mut self) {
        sim::recycle(std::mem::take(&mut self.0));
    }
}

/// A 1-d array of `x` without a copy (as `PyArray1::from_vec`), its memory recycled when numpy frees it.
fn recycled_array(py: Python<'_>, x: Vec<f64>) -> PyResult<Bound<'_, PyArray1<f64>>> {
    if x.is_empty() {
        return Ok(PyArray1::from_vec(py, x));
    }
    // the vector's heap buffer stays where it is when the vector moves into its owner
    let (ptr, len) = (x.as_ptr(), x.len());
    let owner = Bound::new(py, RecordBuffer(x))?;
    // SAFETY: `ptr` points to the `len` initialised entries of the vector that `owner` now holds; the owner never
    // touches the vector before it is dropped, so it is not reallocated, and the array keeps the owner alive as its
    // base object (borrow_from_array's contract).
    unsafe {
        let view = numpy::ndarray::ArrayView1::from_shape_ptr(len, ptr);
        Ok(PyArray1::borrow_from_array(&view, owner.into_any()))
    }
}

/// `x` with three significant digits, in plain notation (`0.000100`, `6.90`, `69000`).
fn sig3(x: f64) -> String {
    if !(x.is_finite()) || x == 0.0 {
        return format!("{x}");
    }
    let p = 2 - x.abs().log10().floor() as i32;
    if p <= 0 {
        format!("{x:.0}")
    } else {
        format!("{:.*}", p as usize, x)
    }
}

/// What the caller gave as torques, before it becomes an engine `TorqueSource`.
enum TorqueSpec<'py> {
    Zero,
    /// Times and values already checked by `TorqueSource::table`.
    Table(Vec<f64>, Vec<f64>),
    Callable(Bound<'py, PyAny>),
}

/// The keys `parse_actuators` reads: of the `actuators` mapping and of each entry of its lists. The
/// Python classes (`freefloat.Actuators` and its entries) and the scenario schema read them, with the
/// wheel defaults, from `actuator_fields`, and a test checks that they agree.
const ACTUATOR_KEYS: &[&str] = &["limits", "wheels", "thrusters", "tanks"];
const LIMIT_KEYS: &[&str] = &["joint", "effort", "velocity"];
const WHEEL_KEYS: &[&str] = &[
    "joint",
    "max_torque",
    "max_speed",
    "max_power",
    "coulomb",
    "static_friction",
    "stribeck_speed",
    "viscous",
    "limit_cycle_speed",
    "static_imbalance",
    "dynamic_imbalance",
];
const THRUSTER_KEYS: &[&str] = &[
    "name",
    "body",
    "position",
    "direction",
    "max_thrust",
    "min_on_time",
    "ramp_on",
    "ramp_off",
    "isp",
    "tank",
    "firings",
];
const TANK_KEYS: &[&str] = &["name", "body", "position", "mass", "radius"];

/// `actuator_fields()`: `{"actuators": [keys], "limits"/"wheels"/"thrusters"/"tanks": {"keys": [...],
/// "defaults": {...}}}`: the keys `parse_actuators` accepts and, for wheels, the engine's defaults
/// (`Wheel::new`; `None`: no limit). The one source the Python classes and the scenario schema read.
#[pyfunction]
pub fn actuator_fields(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("actuators", ACTUATOR_KEYS.to_vec())?;
    let w = Wheel::new(0);
    let wd = PyDict::new(py);
    wd.set_item("max_torque", w.max_torque)?;
    wd.set_item("max_speed", w.max_speed)?;
    wd.set_item("max_power", w.max_power)?;
    wd.set_item("coulomb", w.coulomb)?;
    wd.set_item("static_friction", w.static_friction)?;
    wd.set_item("stribeck_speed", w.stribeck_speed)?;
    wd.set_item("viscous", w.viscous)?;
    wd.set_item("limit_cycle_speed", w.limit_cycle_speed)?;
    wd.set_item("static_imbalance", w.static_imbalance)?;
    wd.set_item("dynamic_imbalance", w.dynamic_imbalance)?;
    for (key, keys, defaults) in [
        ("limits", LIMIT_KEYS, None),
        ("wheels", WHEEL_KEYS, Some(wd)),
        ("thrusters", THRUSTER_KEYS, None),
        ("tanks", TANK_KEYS, None),
    ] {
        let e = PyDict::new(py);
        e.set_item("keys", keys.to_vec())?;
        e.set_item("defaults", defaults.unwrap_or_else(|| PyDict::new(py)))?;
        d.set_item(key, e)?;
    }
    Ok(d)
}

/// Read the `actuators` argument: a dict `{"limits": [...], "wheels": [...], "thrusters": [...], "tanks": [...]}` of
/// dicts (what `freefloat.Actuators.to_dict()` writes); joints and bodies by name. Every key is
/// checked; errors name the entry (`actuators.wheels[1].max_torque`).
pub(crate) fn parse_actuators(m: &Model, a: &Bound<'_, PyAny>) -> PyResult<Actuators> {
    let d = a.downcast::<PyDict>().map_err(|_| {
        input_err(
            "argument `actuators`: expected a freefloat.Actuators or a dict with limits/wheels/thrusters/tanks lists",
        )
    })?;
    check_keys(d, ACTUATOR_KEYS, "actuators")?;
    let list = |key: &str| -> PyResult<Vec<Bound<'_, PyDict>>> {
        match d.get_item(key)? {
            None => Ok(vec![]),
            Some(x) if x.is_none() => Ok(vec![]),
            Some(x) => {
                let items: Vec<Bound<PyAny>> =
                    x.extract().map_err(|_| input_err(format!("actuators.{key}: expected a list")))?;
                items
                    .into_iter()
                    .enumerate()
                    .map(|(j, it)| {
                        it.downcast_into::<PyDict>()
                            .map_err(|_| input_err(format!("actuators.{key}[{j}]: expected a mapping of settings")))
                    })
                    .collect()
            }
        }
    };
    let mut out = Actuators::default();
    let joint = |name: &str, at: &str| -> PyResult<usize> {
        m.joint_names.iter().position(|n| *n == name).ok_or_else(|| {
            input_err(format!(
                "{at}.joint: the model has no joint '{name}' (joints: {})",
                m.joint_names[1..].join(", ")
            ))
        })
    };
    for (j, l) in list("limits")?.iter().enumerate() {
        let at = format!("actuators.limits[{j}]");
        check_keys(l, LIMIT_KEYS, &at)?;
        let name = get_str(l, "joint", &at)?;
        // NaN, zero, negative and duplicate joints: the engine's check names the entry
        out.limits.push(JointLimit {
            joint: joint(&name, &at)?,
            effort: get_f_any(l, "effort", &at)?,
            velocity: get_f_any(l, "velocity", &at)?,
        });
    }
    for (j, w) in list("wheels")?.iter().enumerate() {
        let at = format!("actuators.wheels[{j}]");
        check_keys(w, WHEEL_KEYS, &at)?;
        let name = get_str(w, "joint", &at)?;
        // the engine's `Wheel::new` holds every default (the Python classes and the schema read them from
        // `actuator_fields`)
        let mut wh = Wheel::new(joint(&name, &at)?);
        wh.max_torque = get_f(w, "max_torque", &at)?.or(wh.max_torque);
        wh.max_speed = get_f(w, "max_speed", &at)?.or(wh.max_speed);
        wh.max_power = get_f(w, "max_power", &at)?.or(wh.max_power);
        wh.coulomb = get_f(w, "coulomb", &at)?.unwrap_or(wh.coulomb);
        wh.static_friction = get_f(w, "static_friction", &at)?.unwrap_or(wh.static_friction);
        wh.stribeck_speed = get_f(w, "stribeck_speed", &at)?.or(wh.stribeck_speed);
        wh.viscous = get_f(w, "viscous", &at)?.unwrap_or(wh.viscous);
        wh.limit_cycle_speed = get_f(w, "limit_cycle_speed", &at)?.unwrap_or(wh.limit_cycle_speed);
        wh.static_imbalance = get_f(w, "static_imbalance", &at)?.unwrap_or(wh.static_imbalance);
        wh.dynamic_imbalance = get_f(w, "dynamic_imbalance", &at)?.unwrap_or(wh.dynamic_imbalance);
        out.wheels.push(wh);
    }
    let body = |d: &Bound<PyDict>, at: &str| -> PyResult<usize> {
        match d.get_item("body")? {
            None => Ok(0),
            Some(x) if x.is_none() => Ok(0),
            Some(_) => {
                let name = get_str(d, "body", at)?;
                m.body_names
                    .iter()
                    .position(|n| *n == name)
                    .ok_or_else(|| input_err(format!("{at}.body: the model has no body '{name}'")))
            }
        }
    };
    let tanks = list("tanks")?;
    let mut tank_names = Vec::new();
    for (j, t) in tanks.iter().enumerate() {
        let at = format!("actuators.tanks[{j}]");
        check_keys(t, TANK_KEYS, &at)?;
        tank_names.push(match t.get_item("name")? {
            Some(x) if !x.is_none() => get_str(t, "name", &at)?,
            _ => format!("tank{j}"),
        });
        out.tanks.push(Tank {
            body: body(t, &at)?,
            position: get_v3(t, "position", &at)?.unwrap_or_else(V3::zeros),
            mass: get_f(t, "mass", &at)?.ok_or_else(|| input_err(format!("{at}.mass: required (kg of propellant)")))?,
            radius: get_f(t, "radius", &at)?.unwrap_or(0.0),
        });
    }
    for (j, t) in list("thrusters")?.iter().enumerate() {
        let at = format!("actuators.thrusters[{j}]");
        check_keys(t, THRUSTER_KEYS, &at)?;
        let tank = match t.get_item("tank")? {
            None => None,
            Some(x) if x.is_none() => None,
            Some(x) => {
                if let Ok(k) = x.extract::<usize>() {
                    Some(k)
                } else {
                    let name: String =
                        x.extract().map_err(|_| input_err(format!("{at}.tank: expected a tank name or index")))?;
                    Some(tank_names.iter().position(|n| *n == name).ok_or_else(|| {
                        input_err(format!("{at}.tank: no tank named '{name}' (tanks: {tank_names:?})"))
                    })?)
                }
            }
        };
        let firings: Vec<(f64, f64)> = match t.get_item("firings")? {
            None => vec![],
            Some(x) if x.is_none() => vec![],
            Some(x) => x.extract().map_err(|_| {
                input_err(format!("{at}.firings: expected a list of (start, duration) pairs in seconds"))
            })?,
        };
        out.thrusters.push(Thruster {
            body: body(t, &at)?,
            position: get_v3(t, "position", &at)?.unwrap_or_else(V3::zeros),
            direction: get_v3(t, "direction", &at)?
                .ok_or_else(|| input_err(format!("{at}.direction: required (unit vector, body frame)")))?,
            max_thrust: get_f(t, "max_thrust", &at)?
                .ok_or_else(|| input_err(format!("{at}.max_thrust: required (N)")))?,
            min_on_time: get_f(t, "min_on_time", &at)?.unwrap_or(0.0),
            ramp_on: get_f(t, "ramp_on", &at)?.unwrap_or(0.0),
            ramp_off: get_f(t, "ramp_off", &at)?.unwrap_or(0.0),
            isp: get_f(t, "isp", &at)?,
            tank,
            firings,
        });
    }
    // The engine checks every value against the model (ranges, Isp, tank masses) and names the entry.
    Ok(out)
}

fn check_keys(d: &Bound<'_, PyDict>, allowed: &[&str], at: &str) -> PyResult<()> {
    for k in d.keys() {
        let k: String = k.extract().map_err(|_| input_err(format!("{at}: keys must be strings")))?;
        if !allowed.contains(&k.as_str()) {
            return Err(input_err(format!("{at}: unknown key '{k}' (allowed: {})", allowed.join(", "))));
        }
    }
    Ok(())
}

fn get_f(d: &Bound<'_, PyDict>, key: &str, at: &str) -> PyResult<Option<f64>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(x) if x.is_none() => Ok(None),
        Some(x) => {
            let v: f64 = x.extract().map_err(|_| input_err(format!("{at}.{key}: expected a number")))?;
            if !v.is_finite() {
                return Err(input_err(format!("{at}.{key}: must be finite, got {v}")));
            }
            Ok(Some(v))
        }
    }
}

/// A number that may be anything (NaN, negative): the engine's check says what is wrong with it.
fn get_f_any(d: &Bound<'_, PyDict>, key: &str, at: &str) -> PyResult<Option<f64>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(x) if x.is_none() => Ok(None),
        Some(x) => Ok(Some(x.extract().map_err(|_| input_err(format!("{at}.{key}: expected a number")))?)),
    }
}

fn get_str(d: &Bound<'_, PyDict>, key: &str, at: &str) -> PyResult<String> {
    d.get_item(key)?
        .ok_or_else(|| input_err(format!("{at}.{key}: required")))?
        .extract()
        .map_err(|_| input_err(format!("{at}.{key}: expected a name (string)")))
}

fn get_v3(d: &Bound<'_, PyDict>, key: &str, at: &str) -> PyResult<Option<V3>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(x) if x.is_none() => Ok(None),
        Some(x) => {
            let v: [f64; 3] = x.extract().map_err(|_| input_err(format!("{at}.{key}: expected three numbers")))?;
            if !v.iter().all(|x| x.is_finite()) {
                return Err(input_err(format!("{at}.{key}: must be finite")));
            }
            Ok(Some(V3::new(v[0], v[1], v[2])))
        }
    }
}
