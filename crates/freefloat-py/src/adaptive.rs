//! Bindings of the ch. 4 adaptive pose tracker (`freefloat_core::control::adaptive`): the closed-loop simulation
//! (`adaptive_simulate`), the controller object for a user's own loop (`AdaptivePoseController`) and the
//! realisability test of a dual-inertia parameter vector. Conversion and validation only; every number is
//! computed in freefloat-core.

use crate::dq::PyDualQuaternion;
use crate::errors::{guard, input_err, reraise_foreign, signal_hook};
use freefloat_core::control::adaptive::{
    self as ad, AdaptivePoseController, Gains, Harmonic3, Integrator, LawForm, Learning, Reference, RunOptions,
    Selection, Setup, Table, M7,
};
use freefloat_core::dualquat::{realisability, DualQuat, Realisability, V7, V8};
use freefloat_core::spatial::{M3, V3};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::cell::RefCell;

/// Finite floats of any array-like of shape `shape`, row-major.
fn floats(obj: &Bound<'_, PyAny>, name: &str, shape: &[usize]) -> PyResult<Vec<f64>> {
    let np = obj.py().import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj, "float64"))
        .map_err(|_| input_err(format!("argument `{name}`: cannot be read as numbers")))?;
    let got: Vec<usize> = arr.getattr("shape")?.extract()?;
    if got != shape {
        return Err(input_err(format!("argument `{name}`: expected shape {shape:?}, got {got:?}")));
    }
    let v: Vec<f64> = arr.call_method0("ravel")?.call_method0("tolist")?.extract()?;
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(input_err(format!("argument `{name}`: entry {i} is {} (must be finite)", v[i])));
    }
    Ok(v)
}

/// A DualQuaternion or 8 numbers.
fn dq_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<DualQuat> {
    if let Ok(q) = obj.downcast::<PyDualQuaternion>() {
        return Ok(q.get().inner);
    }
    Ok(DualQuat::from_vec8(&V8::from_column_slice(&floats(obj, name, &[8])?)))
}

fn v7_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<V7> {
    Ok(V7::from_column_slice(&floats(obj, name, &[7])?))
}

/// A 3×3 gain: a number k (k I₃), 3 numbers (a diagonal) or a 3×3 matrix.
fn gain3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<M3> {
    if let Ok(k) = obj.extract::<f64>() {
        return Ok(k * M3::identity());
    }
    let shape: Vec<usize> = obj.py().import("numpy")?.call_method1("shape", (obj,))?.extract()?;
    match shape.as_slice() {
        [3] => Ok(M3::from_diagonal(&V3::from_column_slice(&floats(obj, name, &[3])?))),
        _ => Ok(M3::from_row_slice(&floats(obj, name, &[3, 3])?)),
    }
}

fn gain7(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<M7> {
    if let Ok(k) = obj.extract::<f64>() {
        return Ok(k * M7::identity());
    }
    let shape: Vec<usize> = obj.py().import("numpy")?.call_method1("shape", (obj,))?.extract()?;
    match shape.as_slice() {
        [7] => Ok(M7::from_diagonal(&V7::from_column_slice(&floats(obj, name, &[7])?))),
        _ => Ok(M7::from_row_slice(&floats(obj, name, &[7, 7])?)),
    }
}

fn gains(
    k_r: &Bound<'_, PyAny>,
    k_q: &Bound<'_, PyAny>,
    k_v: &Bound<'_, PyAny>,
    k_w: &Bound<'_, PyAny>,
    k_i: &Bound<'_, PyAny>,
) -> PyResult<Gains> {
    let (kr, kq, kv, kw, ki) =
        (gain3(k_r, "k_r")?, gain3(k_q, "k_q")?, gain3(k_v, "k_v")?, gain3(k_w, "k_w")?, gain7(k_i, "k_i")?);
    guard(|| Gains::new(kr, kq, kv, kw, ki))
}

fn learning(mode: &str, n_s: usize, sigma_stop: f64, selection: &str, seed: u64) -> PyResult<Learning> {
    let rule = match selection {
        "elementwise" | "algorithm3" => Selection::Elementwise,
        "max_min_sv" | "chowdhary" => Selection::MaxMinSingularValue,
        other => {
            return Err(input_err(format!(
                "argument `selection`: must be 'elementwise' (Valverde 2018 ch. 9 Algorithm 3) or 'max_min_sv' (Chowdhary), got '{other}'"
            )))
        }
    };
    match mode {
        "continuous" => Ok(Learning::Continuous),
        "discrete" => Ok(Learning::Discrete { n_s, sigma_stop, rule, seed }),
        other => Err(input_err(format!("argument `learning`: must be 'continuous' or 'discrete', got '{other}'"))),
    }
}

fn law(form: &str) -> PyResult<LawForm> {
    match form {
        "corrected" => Ok(LawForm::Corrected),
        "printed" => Ok(LawForm::Printed),
        other => Err(input_err(format!("argument `law`: must be 'corrected' or 'printed', got '{other}'"))),
    }
}

/// A reference from `(angular, linear)` harmonics (each a (4, 3) array: offset, amplitude, frequency, phase)
/// or a table (`times` (N,), `twists` (N, 6) = [ω̄, v̄]).
fn reference(
    harmonic: Option<(&Bound<'_, PyAny>, &Bound<'_, PyAny>)>,
    table: Option<(&Bound<'_, PyAny>, &Bound<'_, PyAny>)>,
) -> PyResult<Reference> {
    let h3 = |obj: &Bound<'_, PyAny>, name: &str| -> PyResult<Harmonic3> {
        let v = floats(obj, name, &[4, 3])?;
        let row = |k: usize| V3::new(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
        Ok(Harmonic3 { offset: row(0), amplitude: row(1), frequency: row(2), phase: row(3) })
    };
    match (harmonic, table) {
        (Some((a, l)), None) => {
            let (a, l) = (h3(a, "reference_angular")?, h3(l, "reference_linear")?);
            guard(|| Reference::harmonic(a, l))
        }
        (None, Some((t, x))) => {
            let n: usize = t.len().map_err(|_| input_err("argument `reference_times`: must be a sequence"))?;
            let t = floats(t, "reference_times", &[n])?;
            let x = floats(x, "reference_twists", &[n, 6])?;
            let rows = x.chunks(6).map(|c| [c[0], c[1], c[2], c[3], c[4], c[5]]).collect();
            Ok(Reference::Table(guard(|| Table::new(t, rows))?))
        }
        (None, None) => Ok(Reference::constant(V3::zeros(), V3::zeros())),
        _ => Err(input_err("give a harmonic reference or a table, not both")),
    }
}

fn arr2<'py>(py: Python<'py>, v: &[f64], cols: usize) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_slice(py, v).reshape([v.len() / cols.max(1), cols])?.into_any())
}

fn realisability_dict<'py>(py: Python<'py>, r: &Realisability) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("realisable", r.is_realisable())?;
    d.set_item("admissible", r.is_admissible())?;
    d.set_item("finite", r.finite)?;
    d.set_item("mass_positive", r.mass_positive)?;
    d.set_item("positive_definite", r.positive_definite)?;
    d.set_item("triangle_inequality", r.triangle_inequality)?;
    d.set_item("triangle_margin", r.triangle_margin)?;
    d.set_item("principal_moments", r.eigenvalues.to_vec())?;
    d.set_item("failures", r.failures())?;
    Ok(d)
}

/// Whether `v = [I11, I12, I13, I22, I23, I33, m]` is the mass and inertia of a rigid body: a dict with
/// `realisable`, `admissible` (m > 0 and Ī > 0, enough for the dual inertia to be invertible), `mass_positive`,
/// `positive_definite`, `triangle_inequality` (λ_max ≤ sum of the other two principal moments),
/// `triangle_margin`, `principal_moments` (ascending) and `failures` (the failing conditions in words).
#[pyfunction]
pub fn inertia_realisability<'py>(py: Python<'py>, v: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    let n = py.import("numpy")?.call_method1("size", (v,))?.extract::<usize>()?;
    if n != 7 {
        return Err(input_err(format!("argument `v`: expected 7 numbers [I11, I12, I13, I22, I23, I33, m], got {n}")));
    }
    let arr = py.import("numpy")?.call_method1("asarray", (v, "float64"))?.call_method0("ravel")?;
    let x: Vec<f64> = arr.call_method0("tolist")?.extract()?;
    realisability_dict(py, &realisability(&V7::from_column_slice(&x)))
}

/// Simulate the closed loop of Valverde 2018 ch. 4 (relative pose-error dynamics (2.58) of a spacecraft with
/// mass properties `truth`, adaptive law (4.9) corrected, update law (4.13) or (4.29)) in the engine, and
/// return the recorded histories: `t`, `q`, `w`, `estimate`, `force`, `singular_values`, `lyapunov`,
/// `position_error`, `attitude_error`, `stack_len`, `alpha_in_effect` (the CL weight in effect over the step from each
/// recorded time), plus `steps`, `rejected`, `evaluations`, `rank7_time`, `alpha_off_time`, `stack_changes`,
/// `left_admissible_at`, `admissible_since`, `interrupted`. `alpha_off_after` (seconds, ≥ 0; None = never):
/// Valverde 2018 Remark 6, α is set to 0 that long after the CL matrix first has rank 7 (σ_min > `rank_tol`). `progress(t)` is called with the
/// simulated time every 200 steps; returning False (or Ctrl-C) stops the run and keeps what was done.
#[pyfunction]
#[pyo3(signature = (
    truth, q0, w0, estimate0, k_r, k_q, k_v, k_w, k_i, alpha, t_final, learning = "continuous", n_s = 50,
    sigma_stop = f64::INFINITY, selection = "elementwise", seed = 0, law_form = "corrected",
    reference_angular = None, reference_linear = None, reference_times = None, reference_twists = None,
    method = "dopri5", dt = 0.01, rtol = 1e-10, atol = 1e-10, max_step = f64::INFINITY, output_dt = 0.01,
    max_steps = 50_000_000, rank_tol = 1e-8, alpha_off_after = None, progress = None
))]
#[allow(clippy::too_many_arguments)]
pub fn adaptive_simulate<'py>(
    py: Python<'py>,
    truth: &Bound<'_, PyAny>,
    q0: &Bound<'_, PyAny>,
    w0: &Bound<'_, PyAny>,
    estimate0: &Bound<'_, PyAny>,
    k_r: &Bound<'_, PyAny>,
    k_q: &Bound<'_, PyAny>,
    k_v: &Bound<'_, PyAny>,
    k_w: &Bound<'_, PyAny>,
    k_i: &Bound<'_, PyAny>,
    alpha: f64,
    t_final: f64,
    learning: &str,
    n_s: usize,
    sigma_stop: f64,
    selection: &str,
    seed: u64,
    law_form: &str,
    reference_angular: Option<Bound<'_, PyAny>>,
    reference_linear: Option<Bound<'_, PyAny>>,
    reference_times: Option<Bound<'_, PyAny>>,
    reference_twists: Option<Bound<'_, PyAny>>,
    method: &str,
    dt: f64,
    rtol: f64,
    atol: f64,
    max_step: f64,
    output_dt: f64,
    max_steps: usize,
    rank_tol: f64,
    alpha_off_after: Option<f64>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let harmonic = match (&reference_angular, &reference_linear) {
        (Some(a), Some(l)) => Some((a, l)),
        (None, None) => None,
        _ => return Err(input_err("give both `reference_angular` and `reference_linear` (each (4, 3)), or neither")),
    };
    let table = match (&reference_times, &reference_twists) {
        (Some(t), Some(x)) => Some((t, x)),
        (None, None) => None,
        _ => return Err(input_err("give both `reference_times` and `reference_twists`, or neither")),
    };
    let setup = Setup {
        truth: v7_arg(truth, "truth")?,
        gains: gains(k_r, k_q, k_v, k_w, k_i)?,
        alpha,
        alpha_off_after,
        law: law(law_form)?,
        learning: self::learning(learning, n_s, sigma_stop, selection, seed)?,
        q0: dq_arg(q0, "q0")?,
        w0: dq_arg(w0, "w0")?,
        estimate0: v7_arg(estimate0, "estimate0")?,
        reference: reference(harmonic, table)?,
    };
    let integrator = match method {
        "rk4" => Integrator::Rk4 { dt },
        "dopri5" | "rk45" => Integrator::Dopri5 { rtol, atol, max_step },
        other => return Err(input_err(format!("argument `method`: must be 'rk4' or 'dopri5', got '{other}'"))),
    };
    let opts = RunOptions { t_final, integrator, output_dt, max_steps, rank_tol };
    let stash: RefCell<Option<PyErr>> = RefCell::new(None);
    let run = match progress {
        Some(p) => {
            let mut cb = |t: f64| -> bool {
                if let Err(e) = py.check_signals() {
                    // Ctrl-C: stop and keep what was simulated
                    drop(e);
                    return false;
                }
                match p.call1((t,)) {
                    Ok(r) => !matches!(r.extract::<bool>(), Ok(false)),
                    Err(e) => {
                        stash.borrow_mut().get_or_insert(e);
                        false
                    }
                }
            };
            guard(|| ad::simulate(&setup, &opts, Some(&mut cb)))
        }
        None => {
            // no Python runs: the GIL is released and the hook re-takes it only to check for Ctrl-C
            let mut raised: Option<PyErr> = None;
            let r = {
                let raised = &mut raised;
                py.detach(|| {
                    let mut hook = signal_hook(raised);
                    guard(|| ad::simulate(&setup, &opts, Some(&mut hook)))
                })
            };
            reraise_foreign(py, raised)?;
            r
        }
    };
    if let Some(e) = stash.borrow_mut().take() {
        return Err(e);
    }
    let r = run?;
    let d = PyDict::new(py);
    d.set_item("t", PyArray1::from_slice(py, &r.t))?;
    d.set_item("q", arr2(py, &r.q, 8)?)?;
    d.set_item("w", arr2(py, &r.w, 8)?)?;
    d.set_item("estimate", arr2(py, &r.estimate, 7)?)?;
    d.set_item("force", arr2(py, &r.force, 8)?)?;
    d.set_item("singular_values", arr2(py, &r.singular_values, 7)?)?;
    d.set_item("lyapunov", PyArray1::from_slice(py, &r.lyapunov))?;
    d.set_item("position_error", arr2(py, &r.position_error, 3)?)?;
    d.set_item("attitude_error", PyArray1::from_slice(py, &r.attitude_error))?;
    d.set_item("stack_len", PyArray1::from_vec(py, r.stack_len.iter().map(|&n| n as u64).collect()))?;
    d.set_item("steps", r.steps)?;
    d.set_item("rejected", r.rejected)?;
    d.set_item("evaluations", r.evaluations)?;
    d.set_item("rank7_time", r.rank7_time)?;
    d.set_item("alpha_in_effect", PyArray1::from_slice(py, &r.alpha_in_effect))?;
    d.set_item("alpha_off_time", r.alpha_off_time)?;
    d.set_item("stack_changes", r.stack_changes)?;
    d.set_item("left_admissible_at", r.left_admissible_at)?;
    d.set_item("admissible_since", r.admissible_since)?;
    d.set_item("interrupted", r.interrupted)?;
    Ok(d)
}

/// Adaptive dual-quaternion pose tracking with concurrent learning (Valverde 2018, ch. 4), to drive from your
/// own loop: `control(t, q_bd, w_bd)` gives the dual force `f + ετ` (8,), `update(t, dt, q_bd, w_bd, w_bd_dot,
/// force)` records the sample and advances the estimate by dt; `estimate` is `[I11, I12, I13, I22, I23, I33, m]`.
#[pyclass(name = "AdaptivePoseController", module = "freefloat.control")]
pub struct PyAdaptivePoseController {
    inner: AdaptivePoseController,
    reference: Reference,
}

impl PyAdaptivePoseController {
    fn reference_at(
        &self,
        t: f64,
        w_di: Option<&Bound<'_, PyAny>>,
        wdot_di: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<(DualQuat, DualQuat)> {
        let (rw, rwd) = self.reference.eval(t);
        Ok((
            match w_di {
                Some(x) => dq_arg(x, "w_di")?,
                None => rw,
            },
            match wdot_di {
                Some(x) => dq_arg(x, "wdot_di")?,
                None => rwd,
            },
        ))
    }
}

fn out8<'py>(py: Python<'py>, q: &DualQuat) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, q.to_vec8().as_slice())
}

#[pymethods]
impl PyAdaptivePoseController {
    /// Gains as numbers (k I), diagonals or matrices; `learning` 'continuous' (Theorem 1) or 'discrete'
    /// (Theorem 2, with `n_s`, `sigma_stop`, `selection`, `seed`); α = 0 is the baseline. The reference (desired
    /// frame's twist) is harmonic (`reference_angular`, `reference_linear`, each rows offset, amplitude,
    /// frequency, phase) or a table (`reference_times`, `reference_twists` (N, 6) = [ω̄, v̄]); the methods also
    /// take `w_di`, `wdot_di` explicitly.
    #[new]
    #[pyo3(signature = (
        k_r, k_q, k_v, k_w, k_i, alpha, learning = "continuous", n_s = 50, sigma_stop = f64::INFINITY,
        selection = "elementwise", seed = 0, law_form = "corrected", estimate0 = None, reference_angular = None,
        reference_linear = None, reference_times = None, reference_twists = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        k_r: &Bound<'_, PyAny>,
        k_q: &Bound<'_, PyAny>,
        k_v: &Bound<'_, PyAny>,
        k_w: &Bound<'_, PyAny>,
        k_i: &Bound<'_, PyAny>,
        alpha: f64,
        learning: &str,
        n_s: usize,
        sigma_stop: f64,
        selection: &str,
        seed: u64,
        law_form: &str,
        estimate0: Option<Bound<'_, PyAny>>,
        reference_angular: Option<Bound<'_, PyAny>>,
        reference_linear: Option<Bound<'_, PyAny>>,
        reference_times: Option<Bound<'_, PyAny>>,
        reference_twists: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let g = gains(k_r, k_q, k_v, k_w, k_i)?;
        let l = self::learning(learning, n_s, sigma_stop, selection, seed)?;
        let e0 = match estimate0 {
            Some(e) => v7_arg(&e, "estimate0")?,
            None => V7::zeros(),
        };
        let harmonic = match (&reference_angular, &reference_linear) {
            (Some(a), Some(b)) => Some((a, b)),
            (None, None) => None,
            _ => return Err(input_err("give both `reference_angular` and `reference_linear`, or neither")),
        };
        let table = match (&reference_times, &reference_twists) {
            (Some(a), Some(b)) => Some((a, b)),
            (None, None) => None,
            _ => return Err(input_err("give both `reference_times` and `reference_twists`, or neither")),
        };
        let reference = self::reference(harmonic, table)?;
        let lf = law(law_form)?;
        Ok(PyAdaptivePoseController { inner: guard(|| AdaptivePoseController::new(g, alpha, l, lf, e0))?, reference })
    }

    /// The desired frame's twist and its rate at t, `(w_di, wdot_di)`, each (8,) in D axes.
    fn reference<'py>(&self, py: Python<'py>, t: f64) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let (a, b) = self.reference.eval(t);
        (out8(py, &a), out8(py, &b))
    }

    /// The dual control force `f_c^B = f + ετ` (8,) at the pose error `q_bd` (unit) and twist `w_bd`.
    #[pyo3(signature = (t, q_bd, w_bd, w_di = None, wdot_di = None))]
    fn control<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        q_bd: &Bound<'_, PyAny>,
        w_bd: &Bound<'_, PyAny>,
        w_di: Option<Bound<'_, PyAny>>,
        wdot_di: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (a, b) = self.reference_at(t, w_di.as_ref(), wdot_di.as_ref())?;
        let (q, w) = (dq_arg(q_bd, "q_bd")?, dq_arg(w_bd, "w_bd")?);
        Ok(out8(py, &guard(|| self.inner.control(&q, &w, &a, &b))?))
    }

    /// `d v(M̂)/dt` (7,) of the update law at this state with the present memory.
    #[pyo3(signature = (t, q_bd, w_bd, w_di = None, wdot_di = None))]
    fn estimate_rate<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        q_bd: &Bound<'_, PyAny>,
        w_bd: &Bound<'_, PyAny>,
        w_di: Option<Bound<'_, PyAny>>,
        wdot_di: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (a, b) = self.reference_at(t, w_di.as_ref(), wdot_di.as_ref())?;
        let (q, w) = (dq_arg(q_bd, "q_bd")?, dq_arg(w_bd, "w_bd")?);
        Ok(PyArray1::from_slice(py, guard(|| self.inner.estimate_rate(&q, &w, &a, &b))?.as_slice()))
    }

    /// One sample period: when `w_bd_dot` (measured ω̇^B_{B/D}) and `force` (the applied dual force) are given,
    /// record the sample (continuous CL: P += dt RᵀR, Q += dt Rᵀf; discrete CL: offer it to the stack), then
    /// advance the estimate by dt (forward Euler). Returns the new estimate (7,).
    #[pyo3(signature = (t, dt, q_bd, w_bd, w_bd_dot = None, force = None, w_di = None, wdot_di = None))]
    #[allow(clippy::too_many_arguments)]
    fn update<'py>(
        &mut self,
        py: Python<'py>,
        t: f64,
        dt: f64,
        q_bd: &Bound<'_, PyAny>,
        w_bd: &Bound<'_, PyAny>,
        w_bd_dot: Option<Bound<'_, PyAny>>,
        force: Option<Bound<'_, PyAny>>,
        w_di: Option<Bound<'_, PyAny>>,
        wdot_di: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (a, b) = self.reference_at(t, w_di.as_ref(), wdot_di.as_ref())?;
        let (q, w) = (dq_arg(q_bd, "q_bd")?, dq_arg(w_bd, "w_bd")?);
        let sample = match (w_bd_dot, force) {
            (Some(wd), Some(f)) => Some((dq_arg(&wd, "w_bd_dot")?, dq_arg(&f, "force")?)),
            (None, None) => None,
            _ => return Err(input_err("give both `w_bd_dot` and `force` to record a sample, or neither")),
        };
        let v = guard(|| self.inner.update(dt, &q, &w, &a, &b, sample.as_ref().map(|(x, y)| (x, y))))?;
        Ok(PyArray1::from_slice(py, v.as_slice()))
    }

    /// The present estimate `[I11, I12, I13, I22, I23, I33, m]`.
    #[getter]
    fn get_estimate<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.estimate().as_slice())
    }
    #[setter]
    fn set_estimate(&mut self, v: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = v7_arg(v, "estimate")?;
        guard(|| self.inner.set_estimate(v))
    }
    /// Singular values of the CL matrix (P or Σ R_kᵀR_k), descending.
    #[getter]
    fn singular_values(&self) -> Vec<f64> {
        self.inner.singular_values().to_vec()
    }
    /// Samples in the stack (discrete CL) or None (continuous CL).
    #[getter]
    fn stack_len(&self) -> Option<usize> {
        self.inner.stack_len()
    }
    /// The CL matrix (7, 7): P (continuous) or Σ R_kᵀR_k (discrete).
    #[getter]
    fn cl_matrix<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (p, _) = self.inner.memory();
        let rows: Vec<f64> = (0..7).flat_map(|i| (0..7).map(move |j| p[(i, j)])).collect();
        arr2(py, &rows, 7)
    }
    /// The CL vector (7,): Q (continuous) or Σ R_kᵀf_k (discrete).
    #[getter]
    fn cl_vector<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.memory().1.as_slice())
    }
    /// Whether the present estimate is a realisable rigid body (see `inertia_realisability`).
    fn realisability<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        realisability_dict(py, &self.inner.realisability())
    }
}
