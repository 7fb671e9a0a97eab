//! `freefloat.dq.DualQuaternion`: the dual-quaternion algebra of `freefloat_core::dualquat` as a Python
//! object (8 coefficients `[real w x y z, dual w x y z]`), plus the chapter 3 kinematics and constraints.
//! Every argument is validated here, and errors name it; all arithmetic is in freefloat-core.

use crate::errors::{guard, input_err};
use freefloat_core::dualquat::constraints::{self, ConstraintValue};
use freefloat_core::dualquat::kinematics::{dh, dh_chain};
use freefloat_core::dualquat::pose::checked_pose;
use freefloat_core::dualquat::regressor::params;
use freefloat_core::dualquat::{
    body_regressor, exp, h_vector, log, r_matrix, relative_regressor, screw_exp, screw_log, DualInertia, DualQuat, M8,
    M87,
};
use freefloat_core::spatial::{M3, V3};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// Read `n` finite floats from any sequence or numpy array, naming the argument on failure.
fn floats(obj: &Bound<'_, PyAny>, name: &str, n: usize) -> PyResult<Vec<f64>> {
    let np = obj.py().import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj, "float64"))
        .map_err(|_| input_err(format!("argument `{name}`: cannot be read as numbers")))?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape != [n] {
        return Err(input_err(format!("argument `{name}`: expected shape ({n},), got {shape:?}")));
    }
    let v: Vec<f64> = arr.call_method0("tolist")?.extract()?;
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(input_err(format!("argument `{name}`: entry {i} is {} (must be finite)", v[i])));
    }
    Ok(v)
}

fn v3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<V3> {
    let v = floats(obj, name, 3)?;
    Ok(V3::new(v[0], v[1], v[2]))
}

fn finite(x: f64, name: &str) -> PyResult<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(input_err(format!("argument `{name}`: must be finite, got {x}")))
    }
}

/// A dual quaternion `r + ε d`; poses are unit (`q q* = 1`), twists `ω + εv`, wrenches `f + ετ`.
#[pyclass(name = "DualQuaternion", module = "freefloat.dq", frozen)]
#[derive(Clone, Copy)]
pub struct PyDualQuaternion {
    pub inner: DualQuat,
}

fn wrap(q: DualQuat) -> PyDualQuaternion {
    PyDualQuaternion { inner: q }
}

/// Another DualQuaternion, or anything with 8 coefficients.
fn operand(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<DualQuat> {
    if let Ok(q) = obj.downcast::<PyDualQuaternion>() {
        return Ok(q.get().inner);
    }
    let v = floats(obj, name, 8)?;
    Ok(DualQuat::from_slice(&[v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]]))
}

fn arr1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

fn arr2<'py>(py: Python<'py>, v: Vec<f64>, rows: usize, cols: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    PyArray1::from_vec(py, v).reshape([rows, cols])
}

fn m8<'py>(py: Python<'py>, m: &M8) -> PyResult<Bound<'py, PyArray2<f64>>> {
    arr2(py, (0..8).flat_map(|i| (0..8).map(move |j| m[(i, j)])).collect(), 8, 8)
}

#[pymethods]
impl PyDualQuaternion {
    /// `DualQuaternion(coeffs)`: 8 numbers `[real w, x, y, z, dual w, x, y, z]`.
    #[new]
    fn py_new(coeffs: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(wrap(operand(coeffs, "coeffs")?))
    }
    /// numpy must not treat `array * q` elementwise: deferring makes it call `q.__rmul__(array)`.
    #[classattr]
    fn __array_ufunc__(py: Python<'_>) -> Py<PyAny> {
        py.None()
    }
    /// The 8 coefficients as a list (`numpy.asarray(q)` also works).
    fn tolist(&self) -> Vec<f64> {
        self.inner.to_array().to_vec()
    }
    #[pyo3(signature = (dtype = None, copy = None))]
    fn __array__<'py>(
        &self,
        py: Python<'py>,
        dtype: Option<&Bound<'py, PyAny>>,
        copy: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let _ = copy;
        let np = py.import("numpy")?;
        let a = np.call_method1("array", (self.tolist(),))?;
        match dtype {
            Some(d) if !d.is_none() => a.call_method1("astype", (d,)),
            _ => Ok(a),
        }
    }
    /// Real part `(w, x, y, z)`.
    #[getter]
    fn real<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        arr1(py, self.inner.r.to_vec4().iter().copied().collect())
    }
    /// Dual part `(w, x, y, z)`.
    #[getter]
    fn dual<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        arr1(py, self.inner.d.to_vec4().iter().copied().collect())
    }
    /// Pose in the engine convention: `(quat_xyzw, t)`. Raises InputError if not unit (`q q* = 1`).
    #[allow(clippy::wrong_self_convention, clippy::type_complexity)]
    fn to_pose<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
        let q = guard(|| checked_pose("self", &self.inner))?;
        let (qx, t) = q.to_pose_xyzw();
        Ok((arr1(py, qx.to_vec()), arr1(py, vec![t.x, t.y, t.z])))
    }
    /// `r^A = 2 q_d q_r*` (position of the frame in the reference frame).
    fn translation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let t = self.inner.translation();
        arr1(py, vec![t.x, t.y, t.z])
    }
    /// 3×3 rotation matrix `C(q_r)` (active: `C v = vec(q v q*)`).
    fn rotation_matrix<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let c = self.inner.r.rotation_matrix();
        arr2(py, (0..3).flat_map(|i| (0..3).map(move |j| c[(i, j)])).collect(), 3, 3)
    }
    fn conj(&self) -> Self {
        wrap(self.inner.conj())
    }
    fn swap(&self) -> Self {
        wrap(self.inner.swap())
    }
    fn dot(&self, other: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(wrap(self.inner.dot(&operand(other, "other")?)))
    }
    fn cross(&self, other: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(wrap(self.inner.cross(&operand(other, "other")?)))
    }
    /// Circle product (Table 2.4), the real number `a∘b`.
    fn circle(&self, other: &Bound<'_, PyAny>) -> PyResult<f64> {
        Ok(self.inner.circle_scalar(&operand(other, "other")?))
    }
    fn norm(&self) -> f64 {
        self.inner.norm()
    }
    fn sc(&self) -> Self {
        wrap(self.inner.sc())
    }
    fn vec(&self) -> Self {
        wrap(self.inner.vec())
    }
    /// General inverse; raises InputError when the real part is zero.
    fn inverse(&self) -> PyResult<Self> {
        self.inner.inverse().map(wrap).ok_or_else(|| input_err("argument `self`: real part is zero, no inverse"))
    }
    fn is_unit(&self) -> bool {
        self.inner.is_unit()
    }
    /// `max |q q* − 1|`.
    fn unit_defect(&self) -> f64 {
        self.inner.unit_defect()
    }
    /// Normalisation (2.30).
    fn normalized(&self) -> PyResult<Self> {
        self.inner.normalized().map(wrap).ok_or_else(|| input_err("argument `self`: real part is zero"))
    }
    /// Properisation (2.31).
    fn properized(&self) -> Self {
        wrap(self.inner.properized())
    }
    /// Principal logarithm of a unit dual quaternion.
    fn log(&self) -> PyResult<Self> {
        guard(|| log(&self.inner).map_err(|e| rename(e, "self"))).map(wrap)
    }
    /// Screw parameters `(theta, d, l, m)` of a unit dual quaternion.
    #[allow(clippy::type_complexity)]
    fn screw<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(f64, f64, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
        let s = guard(|| screw_log(&self.inner).map_err(|e| rename(e, "self")))?;
        Ok((s.theta, s.d, arr1(py, s.l.iter().copied().collect()), arr1(py, s.m.iter().copied().collect())))
    }
    /// `q* x q` (2.41)/(2.43): a wrench or twist in this pose's reference frame, seen in its own frame.
    fn shift_in(&self, x: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(wrap(self.inner.shift_in(&operand(x, "x")?)))
    }
    /// `q x q*` (2.42)/(2.44).
    fn shift_out(&self, x: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(wrap(self.inner.shift_out(&operand(x, "x")?)))
    }
    /// 8×8 left product matrix (2.28): `q.left_matrix() @ b == (q * b)`.
    fn left_matrix<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        m8(py, &self.inner.left_matrix())
    }
    /// 8×8 right product matrix (2.28): `b.right_matrix() @ a == (a * b)`.
    fn right_matrix<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        m8(py, &self.inner.right_matrix())
    }
    fn __mul__(&self, other: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let py = other.py();
        if let Ok(s) = other.extract::<f64>() {
            return Ok(Py::new(py, wrap(self.inner.scale(s)))?.into_any());
        }
        match operand(other, "other") {
            Ok(b) => Ok(Py::new(py, wrap(self.inner.mul(&b)))?.into_any()),
            Err(_) => Ok(py.NotImplemented()),
        }
    }
    fn __rmul__(&self, other: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let py = other.py();
        if let Ok(s) = other.extract::<f64>() {
            return Ok(Py::new(py, wrap(self.inner.scale(s)))?.into_any());
        }
        match operand(other, "other") {
            Ok(a) => Ok(Py::new(py, wrap(a.mul(&self.inner)))?.into_any()),
            Err(_) => Ok(py.NotImplemented()),
        }
    }
    fn __add__(&self, other: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(wrap(self.inner + operand(other, "other")?))
    }
    fn __sub__(&self, other: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(wrap(self.inner - operand(other, "other")?))
    }
    fn __neg__(&self) -> Self {
        wrap(-self.inner)
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.downcast::<PyDualQuaternion>().map(|o| o.get().inner == self.inner).unwrap_or(false)
    }
    fn __len__(&self) -> usize {
        8
    }
    fn __getitem__(&self, k: isize) -> PyResult<f64> {
        let i = if k < 0 { k + 8 } else { k };
        if !(0..8).contains(&i) {
            return Err(pyo3::exceptions::PyIndexError::new_err("DualQuaternion index out of range"));
        }
        Ok(self.inner.to_array()[i as usize])
    }
    /// `DualQuaternion([rw, rx, ry, rz, dw, dx, dy, dz])`: the constructor's own order, every digit kept, so
    /// the text evaluates back to the same value.
    fn __repr__(&self) -> String {
        let a: Vec<String> = self.inner.to_array().iter().map(|x| format!("{x:?}")).collect();
        format!("DualQuaternion([{}])", a.join(", "))
    }
    /// `[rw, rx, ry, rz] + ε[dw, dx, dy, dz]`: real and dual parts, each `(w, x, y, z)`.
    fn __str__(&self) -> String {
        let a: Vec<String> = self.inner.to_array().iter().map(|x| format!("{x:.9}")).collect();
        format!("[{}] + ε[{}]", a[..4].join(", "), a[4..].join(", "))
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let cls = slf.get_type().into_any();
        Ok((cls, PyTuple::new(py, [slf.get().tolist()])?))
    }
}

fn rename(e: freefloat_core::FfError, name: &str) -> freefloat_core::FfError {
    match e {
        freefloat_core::FfError::Argument { msg, .. } => freefloat_core::FfError::arg(name, msg),
        other => other,
    }
}

/// Pose from the engine convention: unit quaternion `(x, y, z, w)` (normalised if within 1e-6 of unit,
/// rejected otherwise, as everywhere in freefloat) and translation `t`.
#[pyfunction]
pub fn dq_from_pose(quat_xyzw: &Bound<'_, PyAny>, t: &Bound<'_, PyAny>) -> PyResult<PyDualQuaternion> {
    let q = floats(quat_xyzw, "quat_xyzw", 4)?;
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (n - 1.0).abs() > 1e-6 {
        return Err(input_err(format!("argument `quat_xyzw`: not a unit quaternion (norm {n}); order is x, y, z, w")));
    }
    let t = v3(t, "t")?;
    Ok(wrap(DualQuat::from_pose_xyzw(&[q[0] / n, q[1] / n, q[2] / n, q[3] / n], &t)))
}

/// `exp(x)` of a vector dual quaternion.
#[pyfunction]
pub fn dq_exp(x: &Bound<'_, PyAny>) -> PyResult<PyDualQuaternion> {
    let x = operand(x, "x")?;
    if !x.is_vector(1e-12) {
        return Err(input_err("argument `x`: exp is defined here for vector dual quaternions (zero scalar parts)"));
    }
    Ok(wrap(exp(&x)))
}

/// Screw exponential (3.10) `exp(½(θ + εd)(ℓ + εm))`.
#[pyfunction]
pub fn dq_screw(theta: f64, d: f64, l: &Bound<'_, PyAny>, m: &Bound<'_, PyAny>) -> PyResult<PyDualQuaternion> {
    let (theta, d) = (finite(theta, "theta")?, finite(d, "d")?);
    let l = v3(l, "l")?;
    let m = v3(m, "m")?;
    let n = l.norm();
    if (n - 1.0).abs() > 1e-9 {
        return Err(input_err(format!("argument `l`: the screw axis must be a unit vector (norm {n})")));
    }
    if l.dot(&m).abs() > 1e-9 * (1.0 + m.norm()) {
        return Err(input_err("argument `m`: the moment must be orthogonal to the axis (m = p × l)"));
    }
    Ok(wrap(screw_exp(theta, d, &l, &m)))
}

/// Standard DH transform (3.26); with `rows` (n × 4 of d, θ, a, α) the chain product.
#[pyfunction]
pub fn dq_dh(d: f64, theta: f64, a: f64, alpha: f64) -> PyResult<PyDualQuaternion> {
    Ok(wrap(dh(finite(d, "d")?, finite(theta, "theta")?, finite(a, "a")?, finite(alpha, "alpha")?)))
}

#[pyfunction]
pub fn dq_dh_chain(rows: Vec<Vec<f64>>) -> PyResult<PyDualQuaternion> {
    let mut rr = Vec::with_capacity(rows.len());
    for (k, r) in rows.iter().enumerate() {
        if r.len() != 4 || r.iter().any(|x| !x.is_finite()) {
            return Err(input_err(format!("argument `rows`: row {k} must be 4 finite numbers (d, theta, a, alpha)")));
        }
        rr.push([r[0], r[1], r[2], r[3]]);
    }
    Ok(wrap(dh_chain(&rr)))
}

fn cv(c: ConstraintValue) -> (f64, Vec<f64>) {
    (c.value, c.gradient.iter().copied().collect())
}

fn pose_arg(q: &Bound<'_, PyAny>, name: &str) -> PyResult<DualQuat> {
    let q = operand(q, name)?;
    guard(|| checked_pose(name, &q))
}

/// Constraint `(value, gradient)`; `value ≤ 0` is feasible. See `freefloat.dq.line_of_sight`.
#[pyfunction]
pub fn dq_line_of_sight(q_ga: &Bound<'_, PyAny>, y_g: &Bound<'_, PyAny>, half_angle: f64) -> PyResult<(f64, Vec<f64>)> {
    let q = pose_arg(q_ga, "q_ga")?;
    let y = v3(y_g, "y_g")?;
    guard(|| constraints::line_of_sight(&q, &y, half_angle)).map(cv)
}

#[pyfunction]
pub fn dq_approach_slope(
    q_ga: &Bound<'_, PyAny>,
    z_a: &Bound<'_, PyAny>,
    half_angle: f64,
) -> PyResult<(f64, Vec<f64>)> {
    let q = pose_arg(q_ga, "q_ga")?;
    let z = v3(z_a, "z_a")?;
    guard(|| constraints::approach_slope(&q, &z, half_angle)).map(cv)
}

#[pyfunction]
pub fn dq_attitude(
    q_bi: &Bound<'_, PyAny>,
    n_i: &Bound<'_, PyAny>,
    n_b: &Bound<'_, PyAny>,
    max_angle: f64,
) -> PyResult<(f64, Vec<f64>)> {
    let q = pose_arg(q_bi, "q_bi")?;
    let (ni, nb) = (v3(n_i, "n_i")?, v3(n_b, "n_b")?);
    guard(|| constraints::attitude(&q, &ni, &nb, max_angle)).map(cv)
}

#[pyfunction]
pub fn dq_distance_bound(q: &Bound<'_, PyAny>, delta: f64) -> PyResult<(f64, Vec<f64>)> {
    let q = pose_arg(q, "q")?;
    guard(|| constraints::distance_bound(&q, delta)).map(cv)
}

/// Body poses of a model as dual quaternions, (nbodies, 8): `method` "chain" (the product of relative poses
/// (3.43)) or "poe" (product of exponentials (3.19)).
#[pyfunction]
#[pyo3(signature = (model, q, method = "chain"))]
pub fn dq_body_poses<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    method: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mb = crate::batch::model_arg(model)?;
    let m = &mb.get().inner;
    let qv = floats(q, "q", m.nq)?;
    let poses = guard(|| match method {
        "chain" => freefloat_core::dualquat::kinematics::body_poses(m, &qv),
        "poe" => freefloat_core::dualquat::kinematics::ProductOfExponentials::new(m)?.body_poses(m, &qv),
        other => Err(freefloat_core::FfError::arg("method", format!("must be 'chain' or 'poe', got '{other}'"))),
    })?;
    let n = poses.len();
    arr2(py, poses.iter().flat_map(|p| p.to_array()).collect(), n, 8)
}

// ---- the dual-inertia regressor (Valverde 2018, §4.1 and §9.1) ----

/// A vector dual quaternion argument (twist, wrench or their rates): 8 coefficients with zero scalar parts.
fn vector_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<DualQuat> {
    let q = operand(obj, name)?;
    if !q.is_vector(1e-12 * q.norm().max(1.0)) {
        return Err(input_err(format!(
            "argument `{name}`: must be a vector dual quaternion (scalar parts zero: [0, x, y, z, 0, x, y, z]), got \
             scalar parts {} and {}",
            q.r.w, q.d.w
        )));
    }
    Ok(q)
}

fn m87<'py>(py: Python<'py>, m: &M87) -> PyResult<Bound<'py, PyArray2<f64>>> {
    arr2(py, (0..8).flat_map(|i| (0..7).map(move |j| m[(i, j)])).collect(), 8, 7)
}

/// `r(b)` (8×7), eq. (4.2): `r(b) @ v(M) = M ⋆ b` for a vector dual quaternion `b`.
#[pyfunction]
pub fn dq_r_matrix<'py>(py: Python<'py>, b: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    m87(py, &r_matrix(&vector_arg(b, "b")?))
}

/// `h(a, b)` (7,), §4.2: `a ∘ (M ⋆ b) = h(a, b) @ v(M)`.
#[pyfunction]
pub fn dq_h_vector<'py>(
    py: Python<'py>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let h = h_vector(&vector_arg(a, "a")?, &vector_arg(b, "b")?);
    Ok(arr1(py, h.iter().copied().collect()))
}

/// `R̂(ω̇, ω)` (8×7), eq. (9.7).
#[pyfunction]
pub fn dq_body_regressor<'py>(
    py: Python<'py>,
    twist: &Bound<'_, PyAny>,
    twist_dot: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    m87(py, &body_regressor(&vector_arg(twist, "twist")?, &vector_arg(twist_dot, "twist_dot")?))
}

/// `R(ω̇_B/D, ω_B/D, ω̇_D/I, ω_D/I, q_B/D)` (8×7), eq. (4.3).
#[pyfunction]
pub fn dq_relative_regressor<'py>(
    py: Python<'py>,
    w_bd_dot: &Bound<'_, PyAny>,
    w_bd: &Bound<'_, PyAny>,
    w_di_dot: &Bound<'_, PyAny>,
    w_di: &Bound<'_, PyAny>,
    q_bd: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = relative_regressor(
        &vector_arg(w_bd_dot, "w_bd_dot")?,
        &vector_arg(w_bd, "w_bd")?,
        &vector_arg(w_di_dot, "w_di_dot")?,
        &vector_arg(w_di, "w_di")?,
        &pose_arg(q_bd, "q_bd")?,
    );
    m87(py, &r)
}

/// `v(M) = [I11, I12, I13, I22, I23, I33, m]` of a rigid body (mass, 3×3 inertia about the CoM).
#[pyfunction]
pub fn dq_inertia_params<'py>(
    py: Python<'py>,
    mass: f64,
    inertia: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let np = inertia.py().import("numpy")?;
    let arr = np
        .call_method1("asarray", (inertia, "float64"))
        .map_err(|_| input_err("argument `inertia`: cannot be read as numbers"))?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape != [3, 3] {
        return Err(input_err(format!("argument `inertia`: expected a 3×3 matrix, got shape {shape:?}")));
    }
    let i = floats(&arr.call_method0("flatten")?, "inertia", 9)?;
    let m = guard(|| DualInertia::new(mass, M3::from_row_slice(&i)))?;
    Ok(arr1(py, params(&m).iter().copied().collect()))
}
