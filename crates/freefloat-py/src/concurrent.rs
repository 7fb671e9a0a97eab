//! Concurrent-learning mass estimation of Valverde 2018 ch. 9 (freefloat_core::estimation::concurrent): the
//! whole coupled run, one data point from a multibody state, and the estimator a user drives sample by
//! sample. Conversion only; every number is computed in the engine.

use crate::batch::model_arg;
use crate::errors::{guard, guard_raw, input_err, interrupted_with, reraise_foreign, signal_hook, to_py};
use freefloat_core::dqdynamics::dq_dynamics;
use freefloat_core::error::{FfError, Partial};
use freefloat_core::estimation::concurrent::{
    estimate_recorded_interruptible, run_cl, ClParams, ClScenario, ConcurrentEstimator, Excitation, Gain, Noise, Offer,
    SampleBuilder, SplitMix, M87, NP, V8,
};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[allow(clippy::too_many_arguments)]
fn params(
    ns: usize,
    sigma_th: f64,
    t_th: f64,
    aggressive: bool,
    t_th2: f64,
    sigma_th2: f64,
    sigma_new: f64,
    gain: &str,
    kappa: f64,
    seed: u64,
) -> PyResult<ClParams> {
    let gain = Gain::parse(gain).map_err(to_py)?;
    Ok(ClParams { ns, sigma_th, t_th, aggressive, t_th2, sigma_th2, sigma_new, gain, kappa, seed })
}

fn offer_name(o: Option<Offer>) -> &'static str {
    match o {
        None => "ignored",
        Some(Offer::Appended) => "appended",
        Some(Offer::Replaced(_)) => "replaced",
        Some(Offer::Rejected) => "rejected",
        Some(Offer::Full) => "full",
    }
}

/// Run Valverde 2018 ch. 9 on `model` (free base, no gravity) from (q0, v0): the robot under the joint
/// actuation `amplitude·sin(frequency·t + phase)` on every joint DOF for t_start ≤ t ≤ t_end, integrated with
/// RK4 at `dt` to `t_final`, and the concurrent-learning estimator (Algorithms 3-4, law (9.15), SVD gain
/// (9.22-9.27)) fed one data point per step. `m0`: initial estimate, 7 per body ([I11, I12, I13, I22, I23, I33,
/// m], model order). `gain`: "thesis" (9.27, the default) or "truncated" (a direction is accelerated only when
/// the current estimate's residual along it is at least `kappa` times the stored data's noise estimate).
/// `wrench_noise`, `rate_noise`: standard deviations of the joint force/torque sensors and of the measured body
/// twists and twist rates. `progress(t)` is called with the simulated time; returning False
/// (or Ctrl-C) stops the run, which then returns what it has with `interrupted = True`. Returns a dict of numpy
/// arrays: t, estimates (n, 7B), singular_values (n, 7B, descending), block_singular_values (n, B, 7), offers
/// (n,), truth, final_estimate, realisable (B,), max_residual, noise_sigma (B,), gain_withheld (B,),
/// stack_changes, stack_trials, interrupted.
#[pyfunction]
#[pyo3(signature = (model, q0, v0, m0, *, ns = 10, sigma_th = 0.001, t_th = 5.0, aggressive = true, t_th2 = 4.9,
    sigma_th2 = 0.5, sigma_new = 100.0, gain = "thesis", kappa = 6.0, seed = 1, dt = 0.01, t_final = 10.0,
    amplitude = 0.5, frequency = 1.0, phase = 0.0, t_start = 2.0, t_end = 3.0, wrench_noise = 0.0, rate_noise = 0.0,
    noise_seed = 7, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn cl_run<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: PyReadonlyArray1<'py, f64>,
    v0: PyReadonlyArray1<'py, f64>,
    m0: PyReadonlyArray1<'py, f64>,
    ns: usize,
    sigma_th: f64,
    t_th: f64,
    aggressive: bool,
    t_th2: f64,
    sigma_th2: f64,
    sigma_new: f64,
    gain: &str,
    kappa: f64,
    seed: u64,
    dt: f64,
    t_final: f64,
    amplitude: f64,
    frequency: f64,
    phase: f64,
    t_start: f64,
    t_end: f64,
    wrench_noise: f64,
    rate_noise: f64,
    noise_seed: u64,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = model.inner.clone();
    let sc = ClScenario {
        q0: q0.as_array().to_vec(),
        v0: v0.as_array().to_vec(),
        excitation: Excitation { amplitude, frequency, phase, t_start, t_end },
        params: params(ns, sigma_th, t_th, aggressive, t_th2, sigma_th2, sigma_new, gain, kappa, seed)?,
        m0: m0.as_array().to_vec(),
        dt,
        t_final,
        noise: Noise { wrench: wrench_noise, rate: rate_noise },
        noise_seed,
    };
    // The callback and Ctrl-C: Python runs only here (GIL held); an exception other than KeyboardInterrupt
    // is re-raised after the run stops.
    let mut raised: Option<PyErr> = None;
    let mut cb = |t: f64| -> bool {
        if let Err(e) = py.check_signals() {
            raised = Some(e);
            return false;
        }
        if let Some(p) = &progress {
            match p.call1((t,)) {
                Ok(r) => return !matches!(r.extract::<bool>(), Ok(false)),
                Err(e) => {
                    raised = Some(e);
                    return false;
                }
            }
        }
        true
    };
    let res = guard(|| run_cl(&m, &sc, Some(&mut cb)))?;
    if let Some(e) = raised {
        if !e.is_instance_of::<PyKeyboardInterrupt>(py) {
            return Err(e);
        }
    }
    let n = res.times.len();
    let nb = m.nbodies();
    let np = NP * nb;
    let d = PyDict::new(py);
    d.set_item("t", PyArray1::from_slice(py, &res.times))?;
    d.set_item("estimates", PyArray1::from_slice(py, &res.estimates).reshape([n, np])?)?;
    d.set_item("singular_values", PyArray1::from_slice(py, &res.singular_values).reshape([n, np])?)?;
    d.set_item("block_singular_values", PyArray1::from_slice(py, &res.block_singular_values).reshape([n, nb, NP])?)?;
    d.set_item("offers", PyArray1::from_slice(py, &res.offers))?;
    d.set_item("truth", PyArray1::from_slice(py, &res.truth))?;
    d.set_item("final_estimate", PyArray1::from_slice(py, &res.final_estimate))?;
    d.set_item("realisable", res.realisable.clone())?;
    d.set_item("max_residual", res.max_residual)?;
    d.set_item("noise_sigma", PyArray1::from_slice(py, &res.noise_sigma))?;
    d.set_item("gain_withheld", res.gain_withheld.clone())?;
    d.set_item("stack_changes", res.stack_changes)?;
    d.set_item("stack_trials", res.stack_trials)?;
    d.set_item("interrupted", res.interrupted)?;
    Ok(d)
}

/// The ch. 9 estimator alone over recorded data points: R (n, B, 8, 7), F (n, B, 8) taken every `dt` from
/// t = 0; the same sequence as `cl_run` (offer, record, step) without the robot (`gain`, `kappa` as there).
/// Returns the estimates (n, 7B).
/// Ctrl-C stops it within ~20 ms: `Interrupted.partial` holds the estimates finished, (k, 7B), equal to the
/// first k rows of an uninterrupted call.
#[pyfunction]
#[pyo3(signature = (r, f, dt, m0, *, ns = 10, sigma_th = 0.001, t_th = 5.0, aggressive = true, t_th2 = 4.9,
    sigma_th2 = 0.5, sigma_new = 100.0, gain = "thesis", kappa = 6.0, seed = 1))]
#[allow(clippy::too_many_arguments)]
pub fn cl_estimate<'py>(
    py: Python<'py>,
    r: PyReadonlyArrayDyn<'py, f64>,
    f: PyReadonlyArrayDyn<'py, f64>,
    dt: f64,
    m0: PyReadonlyArray1<'py, f64>,
    ns: usize,
    sigma_th: f64,
    t_th: f64,
    aggressive: bool,
    t_th2: f64,
    sigma_th2: f64,
    sigma_new: f64,
    gain: &str,
    kappa: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyAny>> {
    let sh = r.shape().to_vec();
    if sh.len() != 4 || sh[2] != 8 || sh[3] != NP {
        return Err(input_err(format!("argument `R`: expected shape (n, B, 8, 7), got {sh:?}")));
    }
    let (n, nb) = (sh[0], sh[1]);
    if f.shape() != [n, nb, 8] {
        return Err(input_err(format!("argument `F`: expected shape ({n}, {nb}, 8), got {:?}", f.shape())));
    }
    let (Ok(rs), Ok(fs)) = (r.as_slice(), f.as_slice()) else {
        return Err(input_err("arguments `R`, `F`: must be C-contiguous float64 arrays (numpy.ascontiguousarray)"));
    };
    // row-major (…, 8, 7) blocks into nalgebra's column-major 8×7
    let rb: Vec<M87> = rs.chunks_exact(56).map(M87::from_row_slice).collect();
    let fb: Vec<V8> = fs.chunks_exact(8).map(V8::from_column_slice).collect();
    let p = params(ns, sigma_th, t_th, aggressive, t_th2, sigma_th2, sigma_new, gain, kappa, seed)?;
    let m0 = m0.as_array().to_vec();
    let mut out = vec![0.0; n * NP * nb];
    // Ctrl-C: the engine polls the hook after each sample (GIL re-taken for the signal check only); the
    // estimates up to the stop become `Interrupted.partial`, (k, 7B)
    let mut raised: Option<PyErr> = None;
    let r = {
        let (raised, out) = (&mut raised, &mut out);
        py.detach(move || {
            let mut hook = signal_hook(raised);
            guard_raw(|| estimate_recorded_interruptible(nb, p, &m0, dt, &rb, &fb, out, Some(&mut hook)))
        })
    };
    reraise_foreign(py, raised)?;
    match r? {
        Ok(()) => Ok(PyArray1::from_vec(py, out).reshape([n, NP * nb])?.into_any()),
        Err(FfError::Interrupted { msg, partial }) => {
            let k = match partial {
                Some(Partial::Samples(k)) => k,
                _ => 0,
            };
            out.truncate(k * NP * nb);
            let done = PyArray1::from_vec(py, out).reshape([k, NP * nb])?.into_any().unbind();
            Err(interrupted_with(py, &msg, Some(done)))
        }
        Err(e) => Err(to_py(e)),
    }
}

/// One data point of ch. 9 from a multibody state: the dual-quaternion dynamics at (q, v, tau) give every
/// body's CoM twist and twist rate and every joint's transmitted wrench; returns (R, F, twists, rates) with
/// R (B, 8, 7) the per-body regressors R̂ (9.7), F (B, 8) the wrenches on the bodies about their CoMs (from the
/// joint wrenches, not from the mass properties), twists and rates (B, 8) as dual quaternions (ω + ε v).
/// `wrench_noise`, `rate_noise` as in `cl_run`, drawn with `noise_seed`.
#[pyfunction]
#[pyo3(signature = (model, q, v, tau, wrench_noise = 0.0, rate_noise = 0.0, noise_seed = 7))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub fn cl_sample<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: PyReadonlyArray1<'py, f64>,
    v: PyReadonlyArray1<'py, f64>,
    tau: PyReadonlyArray1<'py, f64>,
    wrench_noise: f64,
    rate_noise: f64,
    noise_seed: u64,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = model.inner.clone();
    let ok = |x: f64| x.is_finite() && x >= 0.0;
    if !ok(wrench_noise) || !ok(rate_noise) {
        return Err(input_err("arguments `wrench_noise`, `rate_noise`: must be finite and ≥ 0"));
    }
    let (q, v, tau) = (q.as_array().to_vec(), v.as_array().to_vec(), tau.as_array().to_vec());
    let mut sb = SampleBuilder::new(&m);
    model.with_data(|m, d| {
        guard(|| {
            dq_dynamics(m, d, &q, &v, &tau, None, None)?;
            let mut rng = SplitMix::new(noise_seed);
            sb.build(m, d, None, &Noise { wrench: wrench_noise, rate: rate_noise }, &mut rng)
        })
    })?;
    let nb = m.nbodies();
    let mut r = Vec::with_capacity(nb * 56);
    for b in &sb.r {
        for i in 0..8 {
            for j in 0..NP {
                r.push(b[(i, j)]);
            }
        }
    }
    let f: Vec<f64> = sb.f.iter().flat_map(|x| x.iter().copied()).collect();
    let tw: Vec<f64> = sb.twists().iter().flat_map(|x| x.to_array()).collect();
    let rt: Vec<f64> = sb.rates().iter().flat_map(|x| x.to_array()).collect();
    Ok((
        PyArray1::from_slice(py, &r).reshape([nb, 8, NP])?.into_any(),
        PyArray1::from_slice(py, &f).reshape([nb, 8])?.into_any(),
        PyArray1::from_slice(py, &tw).reshape([nb, 8])?.into_any(),
        PyArray1::from_slice(py, &rt).reshape([nb, 8])?.into_any(),
    ))
}

/// The concurrent-learning estimator of Valverde 2018 ch. 9 for `nbodies` bodies, driven from the caller's own
/// loop: `add_sample(R, F)` offers a data point (Algorithm 3 while the time is below t_th), `step(dt)` advances
/// the estimate by one RK4 step of (9.15), or of (9.23) with the SVD gain once the time reaches t_th2.
/// `m0` is the initial estimate (7 per body: [I11, I12, I13, I22, I23, I33, m]); `gain`, `kappa` as in `cl_run`.
#[pyclass(name = "ConcurrentEstimator", module = "freefloat._core")]
pub struct PyConcurrentEstimator {
    inner: ConcurrentEstimator,
    r: Vec<M87>,
    f: Vec<V8>,
}

#[pymethods]
impl PyConcurrentEstimator {
    #[new]
    #[pyo3(signature = (nbodies, m0, *, ns = 10, sigma_th = 0.001, t_th = 5.0, aggressive = true, t_th2 = 4.9,
        sigma_th2 = 0.5, sigma_new = 100.0, gain = "thesis", kappa = 6.0, seed = 1))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        nbodies: usize,
        m0: PyReadonlyArray1<f64>,
        ns: usize,
        sigma_th: f64,
        t_th: f64,
        aggressive: bool,
        t_th2: f64,
        sigma_th2: f64,
        sigma_new: f64,
        gain: &str,
        kappa: f64,
        seed: u64,
    ) -> PyResult<Self> {
        let p = params(ns, sigma_th, t_th, aggressive, t_th2, sigma_th2, sigma_new, gain, kappa, seed)?;
        let m0 = m0.as_array().to_vec();
        let inner = guard(|| ConcurrentEstimator::new(nbodies, p, &m0))?;
        Ok(PyConcurrentEstimator { inner, r: vec![M87::zeros(); nbodies], f: vec![V8::zeros(); nbodies] })
    }

    /// Offer the data point (R, F): R as (B, 8, 7) per-body blocks or the (8B, 7B) block-diagonal matrix 𝐑 of
    /// (9.9), F as (B, 8) or (8B,). Returns what Algorithm 3 did: "appended", "replaced", "rejected", "full"
    /// (the stack is good enough: σ_min ≥ σ_th), or "ignored" (time ≥ t_th).
    fn add_sample(&mut self, r: PyReadonlyArrayDyn<f64>, f: PyReadonlyArrayDyn<f64>) -> PyResult<&'static str> {
        let nb = self.r.len();
        let ra = r.as_array();
        let shape = r.shape().to_vec();
        if shape == [nb, 8, NP] {
            for b in 0..nb {
                self.r[b] = M87::from_fn(|i, j| ra[[b, i, j]]);
            }
        } else if shape == [8 * nb, NP * nb] {
            for b in 0..nb {
                self.r[b] = M87::from_fn(|i, j| ra[[8 * b + i, NP * b + j]]);
            }
            let off = ra.indexed_iter().any(|(ix, x)| ix[0] / 8 != ix[1] / NP && *x != 0.0);
            if off {
                return Err(input_err(
                    "argument `R`: the stacked regressor (9.9) must be block diagonal (one 8×7 block per body)",
                ));
            }
        } else {
            return Err(input_err(format!(
                "argument `R`: expected shape ({nb}, 8, 7) or ({}, {}), got {shape:?}",
                8 * nb,
                NP * nb
            )));
        }
        let fa = f.as_array();
        if f.len() != 8 * nb || !(f.shape() == [nb, 8] || f.shape() == [8 * nb]) {
            return Err(input_err(format!(
                "argument `F`: expected shape ({nb}, 8) or ({},), got {:?}",
                8 * nb,
                f.shape()
            )));
        }
        for (k, x) in fa.iter().enumerate() {
            self.f[k / 8][k % 8] = *x;
        }
        let o = guard(|| self.inner.add_sample(&self.r, &self.f))?;
        Ok(offer_name(o))
    }

    /// Advance by one RK4 step of length dt (RR, Rf and the gain held over the step).
    fn step(&mut self, dt: f64) -> PyResult<()> {
        guard(|| self.inner.step(dt))
    }

    /// The current estimate, 7 per body.
    #[getter]
    fn estimate<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let mut out = vec![0.0; NP * self.r.len()];
        self.inner.estimate_into(&mut out);
        PyArray1::from_vec(py, out)
    }

    /// The 7B singular values of ΣRᵀR, descending (the union of the per-body blocks' ones).
    #[getter]
    fn singular_values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.stack().singular_values())
    }

    /// Per body, its block's 7 singular values (descending), shape (B, 7).
    #[getter]
    fn block_singular_values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(PyArray1::from_slice(py, self.inner.stack().block_singular_values()).reshape([self.r.len(), NP])?.into_any())
    }

    /// RR = Σ𝐑_kᵀ𝐑_k as its diagonal blocks, shape (B, 7, 7).
    #[getter]
    fn rr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<f64> =
            self.inner.stack().rr().iter().flat_map(|b| (0..49).map(move |k| b[(k / 7, k % 7)])).collect();
        Ok(PyArray1::from_vec(py, v).reshape([self.r.len(), NP, NP])?.into_any())
    }

    /// Rf = Σ𝐑_kᵀ𝐅_k per body, shape (B, 7).
    #[getter]
    fn rf<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<f64> = self.inner.stack().rf().iter().flat_map(|b| b.iter().copied().collect::<Vec<_>>()).collect();
        Ok(PyArray1::from_vec(py, v).reshape([self.r.len(), NP])?.into_any())
    }

    /// The gain K per body, shape (B, 7, 7) (identity until t_th2).
    #[getter]
    fn gain<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<f64> = self.inner.gain().iter().flat_map(|b| (0..49).map(move |k| b[(k / 7, k % 7)])).collect();
        Ok(PyArray1::from_vec(py, v).reshape([self.r.len(), NP, NP])?.into_any())
    }

    /// Number of stored data points N_c.
    #[getter]
    fn stack_size(&self) -> usize {
        self.inner.stack().len()
    }

    /// Current time (advanced by `step`; settable).
    #[getter]
    fn get_time(&self) -> f64 {
        self.inner.time()
    }

    #[setter]
    fn set_time(&mut self, t: f64) -> PyResult<()> {
        if !t.is_finite() {
            return Err(input_err("argument `time`: must be finite"));
        }
        self.inner.set_time(t);
        Ok(())
    }

    /// Per body, the noise estimate σ̂ = ρ/√(n − r) of the stored data (least-squares residual norm ρ over the
    /// n stored rows that are not identically zero, r the block's rank); infinite without redundancy.
    #[getter]
    fn noise_sigma<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let st = self.inner.stack();
        let v: Vec<f64> = (0..self.r.len()).map(|i| st.noise_sigma(i).unwrap_or(f64::NAN)).collect();
        PyArray1::from_vec(py, v)
    }

    /// Per body, the directions the truncated gain withheld (left at the plain law's rate although the thesis'
    /// (9.27) would accelerate them) when the gain was last formed; zeros with gain="thesis".
    #[getter]
    fn gain_withheld(&self) -> Vec<usize> {
        self.inner.withheld().to_vec()
    }

    /// Whether the SVD gain K is in use (time ≥ t_th2 at the last step, aggressive mode).
    #[getter]
    fn gain_active(&self) -> bool {
        self.inner.gain_active()
    }

    /// Number of bodies.
    #[getter]
    fn nbodies(&self) -> usize {
        self.r.len()
    }
}
