//! The `Model` class: an immutable robot description, plus a cached `Data` so single calls do not
//! allocate their work buffers each time.

use crate::errors::{guard, input_err};
use freefloat_core::model::{builtin, mjcf, urdf, yaml, JointType};
use freefloat_core::spatial::quat_from_rot;
use freefloat_core::{Data, Model};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Arc, Mutex};

#[pyclass(name = "Model", module = "freefloat._core", frozen)]
pub struct PyModel {
    pub inner: Arc<Model>,
    data: Mutex<Data>,
}

impl PyModel {
    pub fn wrap(m: Model) -> PyModel {
        let data = Mutex::new(Data::new(&m));
        PyModel { inner: Arc::new(m), data }
    }

    /// Run `f` with a Data for this model: the cached one, or a fresh one if another thread holds it.
    pub fn with_data<T>(&self, f: impl FnOnce(&Model, &mut Data) -> T) -> T {
        match self.data.try_lock() {
            Ok(mut d) => f(&self.inner, &mut d),
            Err(_) => f(&self.inner, &mut Data::new(&self.inner)),
        }
    }
}

fn base_type(base: &str) -> PyResult<JointType> {
    JointType::base_from_name(base)
        .ok_or_else(|| input_err(format!("base must be 'free', 'planar' or 'fixed', got '{base}'")))
}

#[pymethods]
impl PyModel {
    /// Parse URDF text. `source` names it in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, base = "free", source = "<string>", allow_nonphysical = false))]
    fn from_urdf_string(text: &str, base: &str, source: &str, allow_nonphysical: bool) -> PyResult<PyModel> {
        let b = base_type(base)?;
        guard(|| urdf::from_urdf_str(text, source, b, allow_nonphysical)).map(PyModel::wrap)
    }

    /// Parse the YAML model format (docs/model_format.md).
    #[staticmethod]
    #[pyo3(signature = (text, source = "<string>"))]
    fn from_yaml_string(text: &str, source: &str) -> PyResult<PyModel> {
        guard(|| yaml::from_yaml_str(text, source)).map(PyModel::wrap)
    }

    #[staticmethod]
    fn builtin(name: &str) -> PyResult<PyModel> {
        guard(|| builtin::load(name)).map(PyModel::wrap)
    }

    #[staticmethod]
    fn builtin_names() -> Vec<&'static str> {
        builtin::names()
    }

    #[staticmethod]
    fn builtin_source(name: &str) -> PyResult<&'static str> {
        guard(|| builtin::source(name))
    }

    fn to_urdf_string(&self) -> PyResult<String> {
        guard(|| urdf::to_urdf_string(&self.inner))
    }

    /// The model as MJCF (MuJoCo XML): free joint on the base, inertias at full precision, no fusing
    /// of static bodies, zero gravity unless `with_gravity`.
    #[pyo3(signature = (with_gravity = false))]
    fn to_mjcf_string(&self, with_gravity: bool) -> PyResult<String> {
        guard(|| mjcf::to_mjcf_string(&self.inner, with_gravity))
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }
    #[getter]
    fn nq(&self) -> usize {
        self.inner.nq
    }
    #[getter]
    fn nv(&self) -> usize {
        self.inner.nv
    }
    #[getter]
    fn nbodies(&self) -> usize {
        self.inner.nbodies()
    }
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.inner.body_names.clone()
    }
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joint_names.clone()
    }
    /// Parent body index of each body (-1 for the base).
    #[getter]
    fn parents(&self) -> Vec<i64> {
        self.inner.parents.iter().map(|p| p.map(|x| x as i64).unwrap_or(-1)).collect()
    }
    #[getter]
    fn joint_types(&self) -> Vec<&'static str> {
        self.inner.joint_types.iter().map(|j| j.name()).collect()
    }
    #[getter]
    fn idx_q(&self) -> Vec<usize> {
        self.inner.idx_q.clone()
    }
    #[getter]
    fn idx_v(&self) -> Vec<usize> {
        self.inner.idx_v.clone()
    }
    #[getter]
    fn nqs(&self) -> Vec<usize> {
        self.inner.nqs.clone()
    }
    #[getter]
    fn nvs(&self) -> Vec<usize> {
        self.inner.nvs.clone()
    }
    #[getter]
    fn tags(&self) -> Vec<Vec<String>> {
        self.inner.tags.clone()
    }
    #[getter]
    fn total_mass(&self) -> f64 {
        self.inner.total_mass()
    }
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.gravity.as_slice())
    }
    /// Unit joint axes (nbodies, 3), joint frame.
    #[getter]
    fn joint_axes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v: Vec<f64> = self.inner.axes.iter().flat_map(|a| a.iter().copied().collect::<Vec<_>>()).collect();
        PyArray1::from_vec(py, v).reshape([self.inner.nbodies(), 3])
    }
    /// Second axes of universal joints (nbodies, 3; intermediate frame); z for every other joint.
    #[getter]
    fn joint_axes2<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v: Vec<f64> = self.inner.axes2.iter().flat_map(|a| a.iter().copied().collect::<Vec<_>>()).collect();
        PyArray1::from_vec(py, v).reshape([self.inner.nbodies(), 3])
    }
    /// Rest placement of each joint frame in its parent body, as (nbodies, 4, 4) homogeneous matrices.
    #[getter]
    fn placements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mut v = Vec::with_capacity(16 * self.inner.nbodies());
        for p in &self.inner.placements {
            for r in 0..3 {
                for c in 0..3 {
                    v.push(p.rot[(r, c)]);
                }
                v.push(p.trans[r]);
            }
            v.extend_from_slice(&[0.0, 0.0, 0.0, 1.0]);
        }
        Ok(PyArray1::from_vec(py, v).reshape([self.inner.nbodies(), 4, 4])?.into_any())
    }
    /// Joint limits as a dict of arrays (lower, upper, velocity, effort), NaN where not given.
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let l = &self.inner.limits;
        let col = |f: &dyn Fn(&freefloat_core::model::JointLimits) -> Option<f64>| -> Vec<f64> {
            l.iter().map(|x| f(x).unwrap_or(f64::NAN)).collect()
        };
        d.set_item("lower", PyArray1::from_vec(py, col(&|x| x.lower)))?;
        d.set_item("upper", PyArray1::from_vec(py, col(&|x| x.upper)))?;
        d.set_item("velocity", PyArray1::from_vec(py, col(&|x| x.velocity)))?;
        d.set_item("effort", PyArray1::from_vec(py, col(&|x| x.effort)))?;
        Ok(d)
    }
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.inner.frames.iter().map(|f| f.name.clone()).collect()
    }
    /// Frames as a list of (name, body name, position (3,), quaternion xyzw (4,)).
    #[getter]
    fn frames(&self) -> Vec<(String, String, [f64; 3], [f64; 4])> {
        self.inner
            .frames
            .iter()
            .map(|f| {
                let t = f.placement.trans;
                (
                    f.name.clone(),
                    self.inner.body_names[f.body].clone(),
                    [t.x, t.y, t.z],
                    quat_from_rot(&f.placement.rot),
                )
            })
            .collect()
    }

    /// Standard inertial parameters, (nbodies, 10): [m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]
    /// about each body-frame origin, body axes.
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v: Vec<f64> = self.inner.parameters().iter().flatten().copied().collect();
        PyArray1::from_vec(py, v).reshape([self.inner.nbodies(), 10])
    }

    /// A new Model with other standard parameters (nbodies, 10); checked for physical consistency.
    fn with_parameters(&self, params: PyReadonlyArray2<f64>) -> PyResult<PyModel> {
        let shape = params.shape();
        if shape != [self.inner.nbodies(), 10] {
            return Err(input_err(format!(
                "argument `P`: expected shape ({}, 10), got {:?}",
                self.inner.nbodies(),
                shape
            )));
        }
        let flat: Vec<f64> = params.as_array().iter().copied().collect();
        guard(|| self.inner.with_parameters(&flat)).map(PyModel::wrap)
    }

    /// A new Model with every welded (fixed-joint) leaf merged into its parent, a frame of the leaf's name left
    /// in its place: the same dynamics with fewer bodies.
    fn with_fixed_leaves_merged(&self) -> PyResult<PyModel> {
        guard(|| self.inner.with_fixed_leaves_merged()).map(PyModel::wrap)
    }

    /// A new Model of the first `n` bodies (the last ones, and the frames on them, dropped): the dynamics of the
    /// rest when the dropped tail is massless (the rate-driven wrist of the chapter 8 DDP robot).
    fn leading_bodies(&self, n: usize) -> PyResult<PyModel> {
        guard(|| self.inner.leading_bodies(n)).map(PyModel::wrap)
    }

    fn with_gravity(&self, g: [f64; 3]) -> PyResult<PyModel> {
        guard(|| self.inner.with_gravity(g.into())).map(PyModel::wrap)
    }

    fn neutral<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.neutral())
    }

    fn __repr__(&self) -> String {
        let m = &self.inner;
        format!(
            "Model('{}': {} bodies, base {}, nq={}, nv={}, mass={} kg)",
            m.name,
            m.nbodies(),
            m.joint_types[0].name(),
            m.nq,
            m.nv,
            m.total_mass()
        )
    }
}
