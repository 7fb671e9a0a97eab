//! Post-capture bindings (Zhang, Yue, Yuan 2020): the scenario simulation (eqs. 39-40, RK4) and the two online
//! estimators (ordinary RLS with forgetting; the paper's modified RLS, eqs. 34-38) as Python objects
//! with `update(...)` for one sample and `run(...)` for many (one call, the loop in Rust).

use crate::environment::PyEnvironment;
use crate::errors::{guard, guard_raw, input_err, interrupted_with, reraise_foreign, signal_hook, to_py};
use crate::model::PyModel;
use freefloat_core::environment::Environment;
use freefloat_core::error::{FfError, Partial};
use freefloat_core::estimation::{CoupledSample, Coupling, ModifiedRls, Rls};
use freefloat_core::postcapture::{simulate_postcapture_with, thruster_base_wrench, PostcaptureControl};
use freefloat_core::spatial::V3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A float64 array of the given shape (None = any length for that axis), as a flat row-major Vec.
fn shaped(name: &str, a: &PyReadonlyArrayDyn<f64>, shape: &[Option<usize>]) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let s = a.shape().to_vec();
    let ok = s.len() == shape.len() && s.iter().zip(shape).all(|(x, want)| want.is_none_or(|w| w == *x));
    if !ok {
        let want: Vec<String> = shape.iter().map(|x| x.map_or("N".to_string(), |v| v.to_string())).collect();
        return Err(input_err(format!("argument `{name}`: expected shape ({}), got {s:?}", want.join(", "))));
    }
    Ok((s, a.as_array().iter().copied().collect()))
}

/// Simulate the post-capture scenario. Returns a dict like `simulate` (t, q, v, ddq, tau, momentum,
/// kinetic_energy, work) recorded every `record_every` RK4 steps.
#[pyfunction]
#[pyo3(signature = (
    model, q0, v0, t_final, dt, f_max, k_f, m_max, k_m, k_d, k_p, jet, damping, amp, freq, phase, record_every = 1,
    max_memory = None, actuators = None, environment = None
))]
#[allow(clippy::too_many_arguments)]
pub fn postcapture_simulate<'py>(
    py: Python<'py>,
    model: &PyModel,
    q0: PyReadonlyArray1<'py, f64>,
    v0: PyReadonlyArray1<'py, f64>,
    t_final: f64,
    dt: f64,
    f_max: f64,
    k_f: f64,
    m_max: f64,
    k_m: f64,
    k_d: Vec<f64>,
    k_p: Vec<f64>,
    jet: Vec<f64>,
    damping: f64,
    amp: Vec<f64>,
    freq: Vec<f64>,
    phase: Vec<f64>,
    record_every: usize,
    max_memory: Option<f64>,
    actuators: Option<Bound<'py, PyAny>>,
    environment: Option<PyRef<'py, PyEnvironment>>,
) -> PyResult<Bound<'py, PyDict>> {
    let env: Option<Environment> = environment.map(|e| e.inner);
    let acts = match &actuators {
        None => None,
        Some(a) if a.is_none() => None,
        Some(a) => Some(crate::simulate::parse_actuators(&model.inner, a)?),
    };
    // the recording must fit in `max_memory` bytes, checked before any work (the run records every step)
    if let (Some(limit), true) = (max_memory, t_final.is_finite() && dt.is_finite() && dt > 0.0 && t_final > 0.0) {
        let samples = (t_final / dt).round() / record_every.max(1) as f64 + 2.0;
        let bytes = samples * freefloat_core::sim::Trajectory::bytes_per_sample(&model.inner) as f64;
        if bytes > limit {
            return Err(input_err(format!(
                "duration {t_final} s at dt = {dt} s records {samples:.3e} samples = {:.3} GB, more than the memory \
                 limit of {:.3} GB; shorten the duration",
                bytes / 1e9,
                limit / 1e9
            )));
        }
    }
    if jet.len() != 3 {
        return Err(input_err(format!("argument `jet`: expected 3 entries, got {}", jet.len())));
    }
    let gain = |name: &str, g: &[f64]| -> PyResult<V3> {
        match g {
            [x] => Ok(V3::repeat(*x)),
            [x, y, z] => Ok(V3::new(*x, *y, *z)),
            _ => Err(input_err(format!("argument `{name}`: expected 1 or 3 entries, got {}", g.len()))),
        }
    };
    let (k_d, k_p) = (gain("k_d", &k_d)?, gain("k_p", &k_p)?);
    let m = model.inner.clone();
    let ctl = PostcaptureControl {
        f_max,
        k_f,
        m_max,
        k_m,
        k_d,
        k_p,
        jet: V3::new(jet[0], jet[1], jet[2]),
        damping,
        amp,
        freq,
        phase,
    };
    let (q0, v0) = (q0.as_array().to_vec(), v0.as_array().to_vec());
    // Ctrl-C: the engine polls the hook (GIL re-taken for the signal check only) and stops with `Interrupted`
    let mut raised: Option<PyErr> = None;
    let r = {
        let raised = &mut raised;
        py.detach(move || {
            let mut hook = signal_hook(raised);
            guard_raw(|| {
                simulate_postcapture_with(
                    &m,
                    &q0,
                    &v0,
                    ctl,
                    t_final,
                    dt,
                    record_every,
                    acts,
                    env.as_ref(),
                    Some(&mut hook),
                )
            })
        })
    };
    reraise_foreign(py, raised)?;
    match r? {
        Ok(tr) => crate::simulate::traj_dict(py, tr),
        // the samples recorded up to the stop become `Interrupted.partial` (a dict like the full result's)
        Err(FfError::Interrupted { msg, partial }) => {
            let partial = match partial {
                Some(Partial::Trajectory(tr)) => Some(crate::simulate::traj_dict(py, *tr)?.into_any().unbind()),
                _ => None,
            };
            Err(interrupted_with(py, &msg, partial))
        }
        Err(e) => Err(to_py(e)),
    }
}

/// The thrusters' wrench on the base (T × 6, body frame about the base origin, the base entries of the
/// generalized force) and each tank's propellant flow (T × tanks, kg/s) at the samples `t` of a run with
/// `propellant` (T × tanks) left: the engine's thruster model, as the stepper evaluates it.
#[pyfunction]
pub fn postcapture_thruster_wrench<'py>(
    py: Python<'py>,
    model: &PyModel,
    actuators: Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    propellant: PyReadonlyArrayDyn<'py, f64>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let acts = crate::simulate::parse_actuators(&model.inner, &actuators)?;
    let tv = t.as_array().to_vec();
    let mp: Vec<f64> = propellant.as_array().iter().copied().collect();
    let nt = acts.tanks.len();
    let (w, f) = guard(|| thruster_base_wrench(&model.inner, &acts, &tv, &mp))?;
    Ok((
        PyArray1::from_vec(py, w).reshape([tv.len(), 6])?.into_any(),
        PyArray1::from_vec(py, f).reshape([tv.len(), nt])?.into_any(),
    ))
}

/// Ordinary recursive least squares with forgetting factor (Rust `estimation::Rls`).
#[pyclass(name = "RecursiveLS", module = "freefloat._core")]
pub struct PyRls {
    inner: Rls,
}

#[pymethods]
impl PyRls {
    #[new]
    #[pyo3(signature = (theta0, p0, forgetting = 1.0))]
    fn new(theta0: PyReadonlyArray1<f64>, p0: PyReadonlyArrayDyn<f64>, forgetting: f64) -> PyResult<Self> {
        let th = theta0.as_array().to_vec();
        let p: Vec<f64> = p0.as_array().iter().copied().collect();
        Ok(PyRls { inner: guard(|| Rls::new(&th, &p, forgetting))? })
    }

    /// One sample: phi (r, n), y (r,).
    fn update(&mut self, t: f64, phi: PyReadonlyArrayDyn<f64>, y: PyReadonlyArrayDyn<f64>) -> PyResult<()> {
        let n = self.inner.n();
        let (_, yv) = shaped("y", &y, &[None])?;
        let (_, pv) = shaped("phi", &phi, &[Some(yv.len()), Some(n)])?;
        guard(|| self.inner.update(t, &pv, &yv))
    }

    /// Many samples: t (N,), phi (N, r, n), y (N, r). Returns the estimate after each sample (N, n).
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        t: PyReadonlyArray1<f64>,
        phi: PyReadonlyArrayDyn<f64>,
        y: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.inner.n();
        let tv = t.as_array().to_vec();
        let (ys, yv) = shaped("y", &y, &[Some(tv.len()), None])?;
        let r = ys[1];
        let (_, pv) = shaped("phi", &phi, &[Some(tv.len()), Some(r), Some(n)])?;
        let est = &mut self.inner;
        let hist = py.detach(|| {
            guard(|| {
                let mut hist = Vec::with_capacity(tv.len() * n);
                for (k, &tk) in tv.iter().enumerate() {
                    est.update(tk, &pv[k * r * n..(k + 1) * r * n], &yv[k * r..(k + 1) * r])?;
                    hist.extend_from_slice(est.estimate());
                }
                Ok(hist)
            })
        })?;
        Ok(PyArray1::from_vec(py, hist).reshape([tv.len(), n])?.into_any())
    }

    #[getter]
    fn estimate<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.estimate())
    }

    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.inner.n();
        Ok(PyArray1::from_slice(py, self.inner.covariance()).reshape([n, n])?.into_any())
    }

    #[getter]
    fn samples(&self) -> usize {
        self.inner.samples()
    }
}

/// The modified RLS of Zhang, Yue, Yuan 2020 (Rust `estimation::ModifiedRls`), coupling "spatial" or "planar".
#[pyclass(name = "ModifiedRLS", module = "freefloat._core")]
pub struct PyModifiedRls {
    inner: ModifiedRls,
}

#[pymethods]
impl PyModifiedRls {
    #[new]
    fn new(
        coupling: &str,
        mu0: PyReadonlyArray1<f64>,
        p_mu0: PyReadonlyArrayDyn<f64>,
        theta0: PyReadonlyArray1<f64>,
        p_theta0: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Self> {
        let c = match coupling {
            "spatial" => Coupling::Spatial,
            "planar" => Coupling::Planar,
            o => return Err(input_err(format!("argument `coupling`: expected 'spatial' or 'planar', got {o:?}"))),
        };
        let (mu, th) = (mu0.as_array().to_vec(), theta0.as_array().to_vec());
        let pm: Vec<f64> = p_mu0.as_array().iter().copied().collect();
        let pt: Vec<f64> = p_theta0.as_array().iter().copied().collect();
        Ok(PyModifiedRls { inner: guard(|| ModifiedRls::new(c, &mu, &pm, &th, &pt))? })
    }

    /// One sample: a (rμ, nμ), b (rμ,), phi (rθ, nθ), y (rθ,), psi (rθ, nD).
    #[allow(clippy::too_many_arguments)]
    fn update(
        &mut self,
        t: f64,
        a: PyReadonlyArrayDyn<f64>,
        b: PyReadonlyArrayDyn<f64>,
        phi: PyReadonlyArrayDyn<f64>,
        y: PyReadonlyArrayDyn<f64>,
        psi: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<()> {
        let (nm, nt, nd) = self.inner.sizes();
        let (_, bv) = shaped("b", &b, &[None])?;
        let (_, yv) = shaped("y", &y, &[None])?;
        let (_, av) = shaped("a", &a, &[Some(bv.len()), Some(nm)])?;
        let (_, pv) = shaped("phi", &phi, &[Some(yv.len()), Some(nt)])?;
        let (_, sv) = shaped("psi", &psi, &[Some(yv.len()), Some(nd)])?;
        guard(|| self.inner.update(&CoupledSample { t, a: &av, b: &bv, phi: &pv, y: &yv, psi: &sv }))
    }

    /// Many samples (leading axis N). Returns (mu history (N, nμ), theta history (N, nθ)).
    #[allow(clippy::too_many_arguments)]
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        t: PyReadonlyArray1<f64>,
        a: PyReadonlyArrayDyn<f64>,
        b: PyReadonlyArrayDyn<f64>,
        phi: PyReadonlyArrayDyn<f64>,
        y: PyReadonlyArrayDyn<f64>,
        psi: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (nm, nt, nd) = self.inner.sizes();
        let tv = t.as_array().to_vec();
        let n = tv.len();
        let (bs, bv) = shaped("b", &b, &[Some(n), None])?;
        let (ys, yv) = shaped("y", &y, &[Some(n), None])?;
        let (rm, rt) = (bs[1], ys[1]);
        let (_, av) = shaped("a", &a, &[Some(n), Some(rm), Some(nm)])?;
        let (_, pv) = shaped("phi", &phi, &[Some(n), Some(rt), Some(nt)])?;
        let (_, sv) = shaped("psi", &psi, &[Some(n), Some(rt), Some(nd)])?;
        let est = &mut self.inner;
        let (hm, ht) = py.detach(|| {
            guard(|| {
                let (mut hm, mut ht) = (Vec::with_capacity(n * nm), Vec::with_capacity(n * nt));
                for k in 0..n {
                    est.update(&CoupledSample {
                        t: tv[k],
                        a: &av[k * rm * nm..(k + 1) * rm * nm],
                        b: &bv[k * rm..(k + 1) * rm],
                        phi: &pv[k * rt * nt..(k + 1) * rt * nt],
                        y: &yv[k * rt..(k + 1) * rt],
                        psi: &sv[k * rt * nd..(k + 1) * rt * nd],
                    })?;
                    hm.extend_from_slice(est.mu());
                    ht.extend_from_slice(est.theta());
                }
                Ok((hm, ht))
            })
        })?;
        Ok((
            PyArray1::from_vec(py, hm).reshape([n, nm])?.into_any(),
            PyArray1::from_vec(py, ht).reshape([n, nt])?.into_any(),
        ))
    }

    #[getter]
    fn mu<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.mu())
    }

    #[getter]
    fn theta<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.theta())
    }

    #[getter]
    fn samples(&self) -> usize {
        self.inner.samples()
    }
}

// -- Zhang 2020's identification equations (postcapture::equations), one call per batch -------------------

fn flat(name: &str, obj: &Bound<'_, PyAny>, width: usize) -> PyResult<Vec<f64>> {
    let a = crate::batch::array_arg(obj, name)?;
    let s = a.shape().to_vec();
    let ok = match s.as_slice() {
        [_, w] => *w == width,
        [_] => width == 1,
        _ => false,
    };
    if !ok {
        return Err(input_err(format!("argument `{name}`: expected shape (T, {width}), got {s:?}")));
    }
    Ok(a.as_array().iter().copied().collect())
}

fn array3<'py>(py: Python<'py>, data: Vec<f64>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    let arr = numpy::ndarray::ArrayD::from_shape_vec(shape.to_vec(), data)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("internal shape error: {e}")))?;
    Ok(numpy::IntoPyArray::into_pyarray(arr, py).into_any())
}

/// Regression rows of Zhang, Yue, Yuan 2020 over a whole measurement record, computed by the
/// engine (`postcapture::equations`). `form`: "momentum" (eqs. 11-19; cumulative differences from the first
/// sample, so one block fewer) or "force" (eqs. 26-33, about the base sensor). `solver`: "paper" (dict with
/// t, A, b, Phi, y, Psi: `A μ = b`, `Φ θ = y + Ψ D(μ)`) or "standard" (dict with t, Phi, y, standard
/// parameters about the reference points). Arrays have a leading sample axis. `transport` (T, 3, 10·nbodies,
/// from `postcapture_momentum_transport`): the momentum rows' angular balance about the moving base point,
/// `impulse_m` then being ∫ M_B dτ about it.
#[pyfunction]
#[pyo3(signature = (model, form, solver, t, q, v, ddq, base_wrench, impulse_f, impulse_m, base, target, transport=None))]
#[allow(clippy::too_many_arguments)]
pub fn postcapture_rows<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    form: &str,
    solver: &str,
    t: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    ddq: &Bound<'py, PyAny>,
    base_wrench: &Bound<'py, PyAny>,
    impulse_f: &Bound<'py, PyAny>,
    impulse_m: &Bound<'py, PyAny>,
    base: usize,
    target: usize,
    transport: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    use freefloat_core::postcapture::equations as eq;
    let mb = crate::batch::model_arg(model)?;
    let m = mb.get().inner.clone();
    let (nq, nv, nb) = (m.nq, m.nv, m.nvs[0]);
    let t = flat("t", t, 1)?;
    let (q, v, ddq) = (flat("q", q, nq)?, flat("v", v, nv)?, flat("ddq", ddq, nv)?);
    let wrench = flat("base_wrench", base_wrench, nb)?;
    let (imp_f, imp_m) = (flat("impulse_F", impulse_f, 3)?, flat("impulse_M", impulse_m, 3)?);
    let transport = match transport {
        None => None,
        Some(x) if x.is_none() => None,
        Some(x) => {
            let a = crate::batch::array_arg(x, "transport")?;
            let want = [t.len(), 3, 10 * m.nbodies()];
            if a.shape() != want {
                return Err(input_err(format!(
                    "argument `transport`: expected shape {want:?} (samples, 3, 10 · bodies), got {:?}",
                    a.shape()
                )));
            }
            Some(a.as_array().iter().copied().collect::<Vec<f64>>())
        }
    };
    let paper = match solver {
        "paper" => true,
        "standard" => false,
        other => return Err(input_err(format!("argument `solver`: expected 'paper' or 'standard', got '{other}'"))),
    };
    let momentum = match form {
        "momentum" => true,
        "force" => false,
        other => return Err(input_err(format!("argument `form`: expected 'momentum' or 'force', got '{other}'"))),
    };
    enum Rows {
        Paper(eq::PaperRows),
        Standard(eq::StandardRows),
    }
    let rows = py.detach(|| {
        guard(|| {
            let meas = eq::Measurements {
                t: &t,
                q: &q,
                v: &v,
                ddq: &ddq,
                base_wrench: &wrench,
                impulse_f: &imp_f,
                impulse_m: &imp_m,
                transport: transport.as_deref(),
            };
            Ok(match (paper, momentum) {
                (true, true) => Rows::Paper(eq::paper_momentum_rows(&m, &meas, base, target)?),
                (true, false) => Rows::Paper(eq::paper_force_rows(&m, &meas, base, target)?),
                (false, true) => Rows::Standard(eq::standard_momentum_rows(&m, &meas, base, target)?),
                (false, false) => Rows::Standard(eq::standard_force_rows(&m, &meas, base, target)?),
            })
        })
    })?;
    let d = PyDict::new(py);
    match rows {
        Rows::Paper(r) => {
            let n = r.t.len();
            let [nl, nmu, na, nth, nd] = r.dims;
            d.set_item("t", PyArray1::from_vec(py, r.t))?;
            d.set_item("A", array3(py, r.a, &[n, nl, nmu])?)?;
            d.set_item("b", array3(py, r.b, &[n, nl])?)?;
            d.set_item("Phi", array3(py, r.phi, &[n, na, nth])?)?;
            d.set_item("y", array3(py, r.y, &[n, na])?)?;
            d.set_item("Psi", array3(py, r.psi, &[n, na, nd])?)?;
        }
        Rows::Standard(r) => {
            let n = r.t.len();
            let [nr, nx] = r.dims;
            d.set_item("t", PyArray1::from_vec(py, r.t))?;
            d.set_item("Phi", array3(py, r.phi, &[n, nr, nx])?)?;
            d.set_item("y", array3(py, r.y, &[n, nr])?)?;
        }
    }
    Ok(d)
}

/// The transport term `∫ [v_B]× K_lin dτ` of the base-point momentum balance (`postcapture::momentum_point`)
/// from the dense record `t` (N), `q` (N, nq), `v` (N, nv) at the frame indices `at` (T): an array
/// (T, 3, 10·nbodies), integrated from `t[at[0]]` (Simpson's rule on an even grid, else trapezoid). B is the
/// frame origin of body `point`.
#[pyfunction]
#[pyo3(signature = (model, t, q, v, at, point=0))]
pub fn postcapture_momentum_transport<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    at: Vec<usize>,
    point: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = crate::batch::model_arg(model)?;
    let m = mb.get().inner.clone();
    let t = flat("t", t, 1)?;
    let (q, v) = (flat("q", q, m.nq)?, flat("v", v, m.nv)?);
    let w = 10 * m.nbodies();
    let out = py.detach(|| guard(|| freefloat_core::postcapture::momentum_transport(&m, &t, &q, &v, &at, point)))?;
    array3(py, out, &[at.len(), 3, w])
}

/// `(m, b', I'_c)` from standard parameters (…, 10) about a reference point: masses (…), centres of mass
/// (…, 3), inertias about the centre of mass (…, 3, 3) (parallel axes; `postcapture::equations::com_form`).
#[pyfunction]
pub fn inertia_com_form<'py>(
    py: Python<'py>,
    params: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    use freefloat_core::postcapture::equations as eq;
    let a = crate::batch::array_arg(params, "params")?;
    let s = a.shape().to_vec();
    if s.last() != Some(&10) {
        return Err(input_err(format!("argument `params`: expected shape (…, 10), got {s:?}")));
    }
    let lead = &s[..s.len() - 1];
    let x: Vec<f64> = a.as_array().iter().copied().collect();
    let n = x.len() / 10;
    let (mut ms, mut bs, mut is) = (Vec::with_capacity(n), Vec::with_capacity(3 * n), Vec::with_capacity(9 * n));
    for (k, p) in x.chunks_exact(10).enumerate() {
        let (m, b, i) = match eq::com_form(p) {
            Ok(x) => x,
            Err(freefloat_core::FfError::Argument { name, msg }) => {
                return Err(input_err(format!("argument `{name}`: item {k}: {msg}")))
            }
            Err(e) => return Err(crate::errors::to_py(e)),
        };
        ms.push(m);
        bs.extend_from_slice(b.as_slice());
        for r in 0..3 {
            for c in 0..3 {
                is.push(i[(r, c)]);
            }
        }
    }
    let with = |inner: &[usize]| lead.iter().chain(inner).copied().collect::<Vec<usize>>();
    Ok((array3(py, ms, &with(&[]))?, array3(py, bs, &with(&[3]))?, array3(py, is, &with(&[3, 3]))?))
}

/// Standard parameters (…, 10) about the reference point from masses (…), centres of mass (…, 3) and
/// inertias about the centre of mass (…, 3, 3) (`postcapture::equations::standard_form`).
#[pyfunction]
pub fn inertia_standard_form<'py>(
    py: Python<'py>,
    mass: &Bound<'py, PyAny>,
    com: &Bound<'py, PyAny>,
    inertia: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    use freefloat_core::postcapture::equations as eq;
    use freefloat_core::spatial::{M3, V3};
    let (m, c, i) = (
        crate::batch::array_arg(mass, "mass")?,
        crate::batch::array_arg(com, "com")?,
        crate::batch::array_arg(inertia, "inertia")?,
    );
    let lead = m.shape().to_vec();
    let want = |inner: &[usize]| lead.iter().chain(inner).copied().collect::<Vec<usize>>();
    if c.shape() != want(&[3]).as_slice() || i.shape() != want(&[3, 3]).as_slice() {
        return Err(input_err(format!(
            "arguments `mass`, `com`, `inertia`: expected shapes {lead:?}, {:?}, {:?}; got {:?}, {:?}",
            want(&[3]),
            want(&[3, 3]),
            c.shape(),
            i.shape()
        )));
    }
    let (m, c, i): (Vec<f64>, Vec<f64>, Vec<f64>) = (
        m.as_array().iter().copied().collect(),
        c.as_array().iter().copied().collect(),
        i.as_array().iter().copied().collect(),
    );
    if m.iter().chain(&c).chain(&i).any(|x| !x.is_finite()) {
        return Err(input_err("arguments `mass`, `com`, `inertia`: entries must be finite"));
    }
    let mut out = Vec::with_capacity(10 * m.len());
    for k in 0..m.len() {
        let b = V3::new(c[3 * k], c[3 * k + 1], c[3 * k + 2]);
        out.extend_from_slice(&eq::standard_form(m[k], &b, &M3::from_row_slice(&i[9 * k..9 * k + 9])));
    }
    array3(py, out, &want(&[10]))
}

/// Nearest physically consistent standard parameters (…, 10) (pseudo-inertia eigenvalues clipped at
/// `eps`·max; `postcapture::equations::project_consistent`).
#[pyfunction]
#[pyo3(signature = (params, eps = 1e-9))]
pub fn inertia_project_consistent<'py>(
    py: Python<'py>,
    params: &Bound<'py, PyAny>,
    eps: f64,
) -> PyResult<Bound<'py, PyAny>> {
    use freefloat_core::postcapture::equations as eq;
    let a = crate::batch::array_arg(params, "params")?;
    let s = a.shape().to_vec();
    if s.last() != Some(&10) {
        return Err(input_err(format!("argument `params`: expected shape (…, 10), got {s:?}")));
    }
    let x: Vec<f64> = a.as_array().iter().copied().collect();
    let mut out = Vec::with_capacity(x.len());
    for p in x.chunks_exact(10) {
        out.extend_from_slice(&guard(|| eq::project_consistent(p, eps))?);
    }
    array3(py, out, &s)
}

/// `m J(b')` (10) = [m, m b', m mono(b')] (Zhang 2020, eq. (23)).
#[pyfunction]
pub fn postcapture_m_j<'py>(py: Python<'py>, mass: f64, com: [f64; 3]) -> Bound<'py, PyArray1<f64>> {
    let b = freefloat_core::spatial::V3::new(com[0], com[1], com[2]);
    PyArray1::from_vec(py, freefloat_core::postcapture::equations::m_j(mass, &b).to_vec())
}

/// The grasp of a drifting target as an inelastic impact (`postcapture::capture_impact`): `model` is the combined
/// model whose leaf body `target` (a fixed joint) is the target, `q` the configuration at contact, `v` the
/// servicer's velocity just before, `target_twist` the target's twist just before (its own axes, [v; ω]).
/// Returns a dict: v_post (nv), impulse_local / impulse_world (6, [linear; angular], about the target frame origin),
/// momentum_before / momentum_after (6, inertial, about the origin), energy_before / energy_after.
#[pyfunction]
pub fn capture_impact<'py>(
    py: Python<'py>,
    model: &PyModel,
    target: usize,
    q: Vec<f64>,
    v: Vec<f64>,
    target_twist: Vec<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let tw: [f64; 6] = target_twist
        .as_slice()
        .try_into()
        .map_err(|_| input_err(format!("argument `target_twist`: expected 6 entries, got {}", target_twist.len())))?;
    let c = model.with_data(|m, d| guard(|| freefloat_core::postcapture::capture_impact(m, d, target, &q, &v, &tw)))?;
    let six = |f: &freefloat_core::spatial::Force| [f.lin.x, f.lin.y, f.lin.z, f.ang.x, f.ang.y, f.ang.z].to_vec();
    let out = PyDict::new(py);
    out.set_item("v_post", PyArray1::from_vec(py, c.v_post))?;
    out.set_item("impulse_local", PyArray1::from_vec(py, six(&c.impulse_local)))?;
    out.set_item("impulse_world", PyArray1::from_vec(py, six(&c.impulse_world)))?;
    out.set_item("momentum_before", PyArray1::from_vec(py, six(&c.momentum_before)))?;
    out.set_item("momentum_after", PyArray1::from_vec(py, six(&c.momentum_after)))?;
    out.set_item("energy_before", c.energy_before)?;
    out.set_item("energy_after", c.energy_after)?;
    Ok(out)
}
