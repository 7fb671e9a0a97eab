//! Seed 000 post-capture bindings: the scenario simulation (eqs. 39-40, RK4) and the two online
//! estimators (ordinary RLS with forgetting; the paper's modified RLS, eqs. 34-38) as Python objects
//! with `update(...)` for one sample and `run(...)` for many (one call, the loop in Rust).

use crate::errors::{guard, input_err};
use crate::model::PyModel;
use freefloat_core::estimation::{CoupledSample, Coupling, ModifiedRls, Rls};
use freefloat_core::postcapture::{simulate_postcapture, PostcaptureControl};
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
    model, q0, v0, t_final, dt, f_max, k_f, m_max, k_m, k_d, k_p, jet, damping, amp, freq, phase, record_every = 1
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
) -> PyResult<Bound<'py, PyDict>> {
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
    let tr = py.detach(move || guard(|| simulate_postcapture(&m, &q0, &v0, ctl, t_final, dt, record_every, None)))?;
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
    Ok(d)
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

/// Seed 000's modified RLS (Rust `estimation::ModifiedRls`), coupling "spatial" or "planar".
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
