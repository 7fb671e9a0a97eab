//! The engine's rotations, skew matrices, base-pose integration and zero-momentum base twist for Python,
//! stacked over any leading axes (one call per batch).

use crate::algorithms::{run_rows, Arr};
use crate::batch::{array_arg, common_rows, model_arg, output, Batch};
use crate::errors::{guard, input_err};
use freefloat_core::kinematics::{base_twist_for_momentum as base_twist, base_velocity_coordinates};
use freefloat_core::sim::{integrate_base_poses as integrate_free, integrate_planar_base_poses, Steps};
use freefloat_core::spatial::{quat_from_rot, rot_from_quat, skew as skew3, M3, V3};
use freefloat_core::FfError;
use numpy::{IntoPyArray, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// Flat copy of an array whose trailing axes are `inner`, with its leading shape; names the argument.
fn trailing(name: &str, obj: &Bound<'_, PyAny>, inner: &[usize]) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let a = array_arg(obj, name)?;
    let shape = a.shape().to_vec();
    let k = shape.len();
    if k < inner.len() || shape[k - inner.len()..] != *inner {
        let s: Vec<String> = inner.iter().map(|x| x.to_string()).collect();
        return Err(input_err(format!("argument `{name}`: expected shape (…, {}), got {shape:?}", s.join(", "))));
    }
    let data: Vec<f64> = a.as_array().iter().copied().collect();
    let width: usize = inner.iter().product();
    if let Some(j) = data.iter().position(|x| !x.is_finite()) {
        return Err(input_err(format!(
            "argument `{name}`: item {}, entry {} is {} (must be finite)",
            j / width,
            j % width,
            data[j]
        )));
    }
    Ok((shape[..k - inner.len()].to_vec(), data))
}

fn shaped<'py>(py: Python<'py>, lead: &[usize], inner: &[usize], data: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    let shape: Vec<usize> = lead.iter().chain(inner).copied().collect();
    let arr = numpy::ndarray::ArrayD::from_shape_vec(shape, data)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("internal shape error: {e}")))?;
    Ok(arr.into_pyarray(py).into_any())
}

/// Rotation matrices (…, 3, 3) (frame → inertial) of quaternions (…, 4) in x, y, z, w order. Norms within
/// 1e-6 of one are normalised, others rejected (ARCHITECTURE.md quaternion policy).
#[pyfunction]
pub fn quat_to_matrix<'py>(py: Python<'py>, quat: Arr<'_, 'py>) -> PyResult<Bound<'py, PyAny>> {
    let (lead, q) = trailing("quat", quat, &[4])?;
    let mut out = vec![0.0; q.len() / 4 * 9];
    for (k, (qk, o)) in q.chunks_exact(4).zip(out.chunks_exact_mut(9)).enumerate() {
        let n = qk.iter().map(|x| x * x).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-6 {
            return Err(input_err(format!(
                "argument `quat`: item {k} has norm {n:.6}; it must be a unit quaternion (x y z w)"
            )));
        }
        let r = if n == 1.0 { rot_from_quat(qk) } else { rot_from_quat(&[qk[0] / n, qk[1] / n, qk[2] / n, qk[3] / n]) };
        for i in 0..3 {
            for j in 0..3 {
                o[3 * i + j] = r[(i, j)];
            }
        }
    }
    shaped(py, &lead, &[3, 3], out)
}

/// Unit quaternions (…, 4), x, y, z, w with w ≥ 0, of rotation matrices (…, 3, 3) (Shepperd's method).
/// Matrices farther than 1e-6 from a rotation are rejected.
#[pyfunction]
pub fn matrix_to_quat<'py>(py: Python<'py>, rot: Arr<'_, 'py>) -> PyResult<Bound<'py, PyAny>> {
    let (lead, r) = trailing("rot", rot, &[3, 3])?;
    let mut out = vec![0.0; r.len() / 9 * 4];
    for (k, (rk, o)) in r.chunks_exact(9).zip(out.chunks_exact_mut(4)).enumerate() {
        let m = M3::from_row_slice(rk);
        let err = (m.transpose() * m - M3::identity()).amax();
        if err > 1e-6 || m.determinant() < 0.0 {
            return Err(input_err(format!(
                "argument `rot`: item {k} is not a rotation matrix (|RᵀR − 1| = {err:.2e}, det = {:.6})",
                m.determinant()
            )));
        }
        o.copy_from_slice(&quat_from_rot(&m));
    }
    shaped(py, &lead, &[4], out)
}

/// Cross-product matrices (…, 3, 3): `skew(a) @ b == a × b`.
#[pyfunction]
pub fn skew<'py>(py: Python<'py>, v: Arr<'_, 'py>) -> PyResult<Bound<'py, PyAny>> {
    let (lead, x) = trailing("v", v, &[3])?;
    let mut out = vec![0.0; x.len() * 3];
    for (xk, o) in x.chunks_exact(3).zip(out.chunks_exact_mut(9)) {
        let s = skew3(&V3::new(xk[0], xk[1], xk[2]));
        for i in 0..3 {
            for j in 0..3 {
                o[3 * i + j] = s[(i, j)];
            }
        }
    }
    shaped(py, &lead, &[3, 3], out)
}

/// Base poses from sampled base twists by the trapezoidal rule on the group (`sim::integrate_base_poses`).
/// Free base: `twists` (T, 6) = [v; ω] in the base frame, `pose0` (7) = position, quaternion x y z w;
/// returns (T, 7). Planar base: `twists` (T, 3) = [vx, vy, yaw rate], `pose0` (3) = [x, y, yaw]; returns
/// (T, 3). `t` (T,) the increasing sample times. `rates` (the twists' shape): their time derivatives, for the
/// fourth-order (Hermite) correction.
#[pyfunction]
#[pyo3(signature = (t, twists, pose0, rates = None))]
pub fn integrate_base_poses<'py>(
    py: Python<'py>,
    t: Arr<'_, 'py>,
    twists: Arr<'_, 'py>,
    pose0: Arr<'_, 'py>,
    rates: Option<Arr<'_, 'py>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (tl, t) = trailing("t", t, &[])?;
    let tw = array_arg(twists, "twists")?;
    let shape = tw.shape().to_vec();
    let width = match shape.as_slice() {
        [_, 6] => 6,
        [_, 3] => 3,
        _ => return Err(input_err(format!("argument `twists`: expected shape (T, 6) or (T, 3), got {shape:?}"))),
    };
    if tl.len() != 1 {
        return Err(input_err(format!("argument `t`: expected shape (T,), got {tl:?}")));
    }
    let tw: Vec<f64> = tw.as_array().iter().copied().collect();
    let (_, p0) = trailing("pose0", pose0, &[])?;
    let n = shape[0];
    let rates = match rates {
        None => None,
        Some(r) => {
            let r = array_arg(r, "rates")?;
            if r.shape() != shape.as_slice() {
                return Err(input_err(format!(
                    "argument `rates`: expected the twists' shape {shape:?}, got {:?}",
                    r.shape()
                )));
            }
            Some(r.as_array().iter().copied().collect::<Vec<f64>>())
        }
    };
    let mut out = vec![0.0; n * if width == 6 { 7 } else { 3 }];
    py.detach(|| {
        guard(|| {
            if width == 6 {
                integrate_free(Steps::Times(&t), &tw, rates.as_deref(), &p0, &mut out)
            } else {
                integrate_planar_base_poses(Steps::Times(&t), &tw, rates.as_deref(), &p0, &mut out)
            }
        })
    })?;
    shaped(py, &[n], &[if width == 6 { 7 } else { 3 }], out)
}

/// Base velocity (…, nb) — a free base's twist [v; ω] in the base frame, a planar base's [vx, vy, yaw
/// rate] — that gives the total momentum `momentum` (6: [p; L about the inertial origin], inertial frame;
/// default zero) when the other joints move with `joint_rates` (…, nv − nb) at `q` (…, nq).
#[pyfunction]
#[pyo3(signature = (model, q, joint_rates, momentum = None))]
pub fn base_twist_for_momentum<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    joint_rates: Arr<'_, 'py>,
    momentum: Option<Arr<'_, 'py>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let nb = m.nvs[0];
    if nb == 0 {
        return Err(input_err(format!("model '{}' has a fixed base: there is no base twist to solve for", m.name)));
    }
    let qb = Batch::new("q", q, &[m.nq])?;
    let rb = Batch::new("joint_rates", joint_rates, &[m.nv - nb])?;
    let hb = momentum.map(|h| Batch::new("momentum", h, &[6])).transpose()?;
    let mut parts = vec![("q", &qb), ("joint_rates", &rb)];
    if let Some(h) = &hb {
        parts.push(("momentum", h));
    }
    let (rows, st) = common_rows(&parts)?;
    let out = run_rows(py, model, rows, st, nb, |m, d, k, o| {
        let h: [f64; 6] = match &hb {
            Some(h) => std::array::from_fn(|i| h.row(k)[i]),
            None => [0.0; 6],
        };
        let tw = base_twist(m, d, qb.row(k), rb.row(k), &h)?;
        base_velocity_coordinates(m, &tw, o)?;
        Ok::<(), FfError>(())
    })?;
    output(py, out, rows, st, &[nb])
}
