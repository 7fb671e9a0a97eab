//! The engine's algorithms as Python functions. Each accepts one sample or a leading time axis and
//! loops over samples in Rust with the GIL released.

use crate::batch::{common_rows, model_arg, output, Batch};
use crate::errors::{guard, input_err};
use crate::model::PyModel;
use freefloat_core::dynamics::{self, Prescribed};
use freefloat_core::kinematics::{self as kin, Reference};
use freefloat_core::regressors;
use freefloat_core::spatial::quat_from_rot;
use freefloat_core::{Data, FfError, Model};
use nalgebra::{Dyn, MatrixViewMut};
use pyo3::prelude::*;

/// An argument that is read as an array of float64 (anything numpy can convert).
pub(crate) type Arr<'a, 'py> = &'a Bound<'py, PyAny>;

pub(crate) fn at_row(e: FfError, k: usize, stacked: bool) -> FfError {
    if !stacked {
        return e;
    }
    match e {
        FfError::Argument { name, msg } => FfError::Argument { name, msg: format!("sample {k}, {msg}") },
        FfError::Numerical(msg) => FfError::Numerical(format!("sample {k}: {msg}")),
        other => other,
    }
}

/// Evaluate `f` on every sample, each writing `width` numbers. Stacked inputs run with the GIL
/// released; a single sample does not, since releasing and retaking it costs more than most
/// single evaluations.
pub(crate) fn run_rows<F>(
    py: Python<'_>,
    model: &PyModel,
    rows: usize,
    stacked: bool,
    width: usize,
    f: F,
) -> PyResult<Vec<f64>>
where
    F: Fn(&Model, &mut Data, usize, &mut [f64]) -> Result<(), FfError> + Send + Sync,
{
    let work = || {
        model.with_data(|m, d| {
            guard(|| {
                let mut out = vec![0.0; rows * width];
                for k in 0..rows {
                    f(m, d, k, &mut out[k * width..(k + 1) * width]).map_err(|e| at_row(e, k, stacked))?;
                }
                Ok(out)
            })
        })
    };
    if stacked {
        py.detach(work)
    } else {
        work()
    }
}

pub(crate) fn fext_batch(m: &Model, fext: Option<Arr>) -> PyResult<Option<Batch>> {
    fext.map(|f| Batch::shape("fext", f, &[m.nbodies(), 6])).transpose()
}

fn name_to_frame(m: &Model, name: &str) -> PyResult<(usize, freefloat_core::spatial::Se3)> {
    guard(|| m.frame_or_body(name))
}

/// Placement of every body in the inertial frame: (nbodies, 7) = position, quaternion x y z w.
#[pyfunction]
pub fn forward_kinematics<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let nb = m.nbodies();
    let out = run_rows(py, model, rows, st, nb * 7, |m, d, k, o| {
        let q = qb.row(k);
        kin::forward_kinematics(m, d, q)?;
        for i in 0..nb {
            let p = &d.o_mi[i];
            o[7 * i..7 * i + 3].copy_from_slice(p.trans.as_slice());
            o[7 * i + 3..7 * i + 7].copy_from_slice(&quat_from_rot(&p.rot));
        }
        Ok(())
    })?;
    output(py, out, rows, st, &[nb, 7])
}

/// Placement of a body or frame in the inertial frame: (7,) = position, quaternion x y z w.
#[pyfunction]
pub fn frame_placement<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    name: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (body, pl) = name_to_frame(m, name)?;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let out = run_rows(py, model, rows, st, 7, |m, d, k, o| {
        let q = qb.row(k);
        kin::forward_kinematics(m, d, q)?;
        let p = kin::frame_placement(m, d, body, &pl)?;
        o[..3].copy_from_slice(p.trans.as_slice());
        o[3..].copy_from_slice(&quat_from_rot(&p.rot));
        Ok(())
    })?;
    output(py, out, rows, st, &[7])
}

#[pyfunction]
pub fn center_of_mass<'py>(py: Python<'py>, model: &Bound<'py, PyAny>, q: Arr<'_, 'py>) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let out = run_rows(py, model, rows, st, 3, |m, d, k, o| {
        let q = qb.row(k);
        o.copy_from_slice(kin::center_of_mass(m, d, q)?.as_slice());
        Ok(())
    })?;
    output(py, out, rows, st, &[3])
}

/// Total momentum [linear; angular about the inertial origin], inertial frame.
#[pyfunction]
pub fn momentum<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("v", &vb)])?;
    let out = run_rows(py, model, rows, st, 6, |m, d, k, o| {
        let q = qb.row(k);
        kin::momentum(m, d, q, vb.row(k))?.write(o);
        Ok(())
    })?;
    output(py, out, rows, st, &[6])
}

#[pyfunction]
pub fn kinetic_energy<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("v", &vb)])?;
    let out = run_rows(py, model, rows, st, 1, |m, d, k, o| {
        let q = qb.row(k);
        o[0] = kin::kinetic_energy(m, d, q, vb.row(k))?;
        Ok(())
    })?;
    output(py, out, rows, st, &[])
}

/// Body twists (nbodies, 6) [linear; angular], each in its own body frame (Pinocchio LOCAL).
#[pyfunction]
pub fn body_velocities<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("v", &vb)])?;
    let nb = m.nbodies();
    let out = run_rows(py, model, rows, st, 6 * nb, |m, d, k, o| {
        let q = qb.row(k);
        kin::forward_velocities(m, d, q, vb.row(k))?;
        for i in 0..nb {
            d.v[i].write(&mut o[6 * i..6 * i + 6]);
        }
        Ok(())
    })?;
    output(py, out, rows, st, &[nb, 6])
}

/// Body accelerations (nbodies, 6) in body frames: spatial (d/dt of the body-frame twist
/// components, Pinocchio LOCAL) or, with `classical`, the acceleration of each body origin.
/// Gravity is not included.
#[pyfunction]
#[pyo3(signature = (model, q, v, a, classical = false))]
pub fn body_accelerations<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    a: Arr<'_, 'py>,
    classical: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb, ab) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?, Batch::shape("a", a, &[m.nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("v", &vb), ("a", &ab)])?;
    let nb = m.nbodies();
    let out = run_rows(py, model, rows, st, 6 * nb, |m, d, k, o| {
        let q = qb.row(k);
        kin::forward_accelerations(m, d, q, vb.row(k), ab.row(k))?;
        for i in 0..nb {
            let acc = if classical { kin::classical_acceleration(&d.a[i], &d.v[i]) } else { d.a[i] };
            acc.write(&mut o[6 * i..6 * i + 6]);
        }
        Ok(())
    })?;
    output(py, out, rows, st, &[nb, 6])
}

/// Centroidal momentum matrix about the inertial origin (6, nv): momentum == A @ v.
#[pyfunction]
pub fn centroidal_momentum_matrix<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let nv = m.nv;
    let out = run_rows(py, model, rows, st, 6 * nv, |m, d, k, o| {
        let q = qb.row(k);
        kin::centroidal_momentum_matrix(m, d, q)?;
        write_rowmajor(&d.jac, o);
        Ok(())
    })?;
    output(py, out, rows, st, &[6, nv])
}

fn write_rowmajor(a: &nalgebra::DMatrix<f64>, o: &mut [f64]) {
    let c = a.ncols();
    for r in 0..a.nrows() {
        for j in 0..c {
            o[r * c + j] = a[(r, j)];
        }
    }
}

/// A row-major matrix view over one sample's output, so the engine writes numpy's layout directly.
fn rowmajor_view(o: &mut [f64], rows: usize, cols: usize) -> MatrixViewMut<'_, f64, Dyn, Dyn, Dyn, Dyn> {
    MatrixViewMut::from_slice_with_strides_generic(o, Dyn(rows), Dyn(cols), Dyn(cols), Dyn(1))
}

/// Momentum regressor (6, 10·nbodies): momentum(q, v) == K @ P.ravel() with P = m.parameters().
/// The link kinematic matrix of Naveen, Shah, Misra (Eq. 10) per body, in our parameter order.
#[pyfunction]
pub fn momentum_regressor<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("v", &vb)])?;
    let np = 10 * m.nbodies();
    let out = run_rows(py, model, rows, st, 6 * np, |m, d, k, o| {
        let q = qb.row(k);
        regressors::momentum_regressor(m, d, q, vb.row(k), &mut rowmajor_view(o, 6, np))?;
        Ok(())
    })?;
    output(py, out, rows, st, &[6, np])
}

/// Inverse-dynamics regressor (nv, 10·nbodies): rnea(q, v, a) == Y @ P.ravel(), gravity included.
/// Per body Valverde 2018's regressor R (Eqs. 4.3, 9.7), the Newton-Euler counterpart of Naveen, Shah,
/// Misra's Eq. 10, projected on every joint between the body and the root.
#[pyfunction]
pub fn dynamics_regressor<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    a: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb, ab) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?, Batch::shape("a", a, &[m.nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("v", &vb), ("a", &ab)])?;
    let (nv, np) = (m.nv, 10 * m.nbodies());
    let out = run_rows(py, model, rows, st, nv * np, |m, d, k, o| {
        let q = qb.row(k);
        regressors::dynamics_regressor(m, d, q, vb.row(k), ab.row(k), &mut rowmajor_view(o, nv, np))?;
        Ok(())
    })?;
    output(py, out, rows, st, &[nv, np])
}

/// Jacobian (6, nv) of a body or frame: its twist [linear; angular] is J @ v.
#[pyfunction]
#[pyo3(signature = (model, q, name, reference = "local"))]
pub fn frame_jacobian<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    name: &str,
    reference: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (body, pl) = name_to_frame(m, name)?;
    let rf = guard(|| Reference::from_name(reference))?;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let nv = m.nv;
    let out = run_rows(py, model, rows, st, 6 * nv, |m, d, k, o| {
        let q = qb.row(k);
        let mut j = nalgebra::DMatrix::zeros(6, m.nv);
        kin::frame_jacobian(m, d, q, body, &pl, rf, &mut j)?;
        write_rowmajor(&j, o);
        Ok(())
    })?;
    output(py, out, rows, st, &[6, nv])
}

/// Generalized Jacobian of a free-floating robot: with total momentum h0 conserved, the frame's
/// twist is Jg @ qdot_joints + offset. Returns (Jg (6, nv - nv_base), offset (6,)).
#[pyfunction]
#[pyo3(signature = (model, q, name, reference = "world", h0 = None))]
pub fn generalized_jacobian<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    name: &str,
    reference: &str,
    h0: Option<[f64; 6]>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (body, pl) = name_to_frame(m, name)?;
    let rf = guard(|| Reference::from_name(reference))?;
    let h0 = h0.unwrap_or([0.0; 6]);
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let nm = m.nv - m.nvs[0];
    let out = run_rows(py, model, rows, st, 6 * nm + 6, |m, d, k, o| {
        let q = qb.row(k);
        let (jg, off) = kin::generalized_jacobian(m, d, q, body, &pl, rf, &h0)?;
        write_rowmajor(&jg, &mut o[..6 * nm]);
        o[6 * nm..].copy_from_slice(&off);
        Ok(())
    })?;
    let (mut jg, mut off) = (Vec::with_capacity(rows * 6 * nm), Vec::with_capacity(rows * 6));
    for k in 0..rows {
        let r = &out[k * (6 * nm + 6)..(k + 1) * (6 * nm + 6)];
        jg.extend_from_slice(&r[..6 * nm]);
        off.extend_from_slice(&r[6 * nm..]);
    }
    Ok((output(py, jg, rows, st, &[6, nm])?, output(py, off, rows, st, &[6])?))
}

/// Inverse dynamics: generalized forces for accelerations `a`.
#[pyfunction]
#[pyo3(signature = (model, q, v, a, fext = None))]
pub fn rnea<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    a: Arr<'_, 'py>,
    fext: Option<Arr<'_, 'py>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb, ab) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?, Batch::shape("a", a, &[m.nv])?);
    let fb = fext_batch(m, fext)?;
    let mut args = vec![("q", &qb), ("v", &vb), ("a", &ab)];
    if let Some(f) = &fb {
        args.push(("fext", f));
    }
    let (rows, st) = common_rows(&args)?;
    let out = run_rows(py, model, rows, st, m.nv, |m, d, k, o| {
        let q = qb.row(k);
        dynamics::rnea(m, d, q, vb.row(k), ab.row(k), fb.as_ref().map(|f| f.row(k)))?;
        o.copy_from_slice(&d.tau);
        Ok(())
    })?;
    output(py, out, rows, st, &[m.nv])
}

/// Joint-space inertia matrix (nv, nv), full symmetric.
#[pyfunction]
pub fn crba<'py>(py: Python<'py>, model: &Bound<'py, PyAny>, q: Arr<'_, 'py>) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let nv = m.nv;
    let out = run_rows(py, model, rows, st, nv * nv, |m, d, k, o| {
        let q = qb.row(k);
        dynamics::crba(m, d, q)?;
        // symmetric: its column-major storage is numpy's row-major layout already (one copy, no index arithmetic)
        o.copy_from_slice(d.mass_matrix.as_slice());
        Ok(())
    })?;
    output(py, out, rows, st, &[nv, nv])
}

/// Forward dynamics (articulated-body algorithm): accelerations for generalized forces `tau`.
#[pyfunction]
#[pyo3(signature = (model, q, v, tau, fext = None))]
pub fn aba<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    tau: Arr<'_, 'py>,
    fext: Option<Arr<'_, 'py>>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb, tb) =
        (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?, Batch::shape("tau", tau, &[m.nv])?);
    let fb = fext_batch(m, fext)?;
    let mut args = vec![("q", &qb), ("v", &vb), ("tau", &tb)];
    if let Some(f) = &fb {
        args.push(("fext", f));
    }
    let (rows, st) = common_rows(&args)?;
    let out = run_rows(py, model, rows, st, m.nv, |m, d, k, o| {
        let q = qb.row(k);
        dynamics::aba(m, d, q, vb.row(k), tb.row(k), fb.as_ref().map(|f| f.row(k)))?;
        o.copy_from_slice(&d.ddq);
        Ok(())
    })?;
    output(py, out, rows, st, &[m.nv])
}

/// Body indices of the named joints (or bodies), rejecting joints without velocity coordinates.
pub fn prescribed_bodies(m: &Model, names: &[String]) -> PyResult<Vec<usize>> {
    names
        .iter()
        .map(|n| {
            let i = m.joint_names.iter().position(|j| j == n).or_else(|| m.body_index(n)).ok_or_else(|| {
                input_err(format!(
                    "prescribed joint '{n}' is not a joint of model '{}' (joints: {})",
                    m.name,
                    m.joint_names.join(", ")
                ))
            })?;
            if m.nvs[i] == 0 {
                return Err(input_err(format!("joint '{}' is fixed: it has no motion to prescribe", m.joint_names[i])));
            }
            Ok(i)
        })
        .collect()
}

/// Hybrid dynamics: joints in `prescribed` follow accelerations `ddq` (their entries of it), the
/// rest respond to `tau`. Returns (ddq_all, tau_all), tau_all holding the forces the prescribed
/// joints needed.
#[pyfunction]
#[pyo3(signature = (model, q, v, tau, ddq, prescribed, fext = None))]
#[allow(clippy::too_many_arguments)]
pub fn hybrid_dynamics<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    tau: Arr<'_, 'py>,
    ddq: Arr<'_, 'py>,
    prescribed: Vec<String>,
    fext: Option<Arr<'_, 'py>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let bodies = prescribed_bodies(m, &prescribed)?;
    let mut mask = vec![false; m.nbodies()];
    for b in bodies {
        mask[b] = true;
    }
    let (qb, vb, tb, ab) = (
        Batch::shape("q", q, &[m.nq])?,
        Batch::shape("v", v, &[m.nv])?,
        Batch::shape("tau", tau, &[m.nv])?,
        Batch::shape("ddq", ddq, &[m.nv])?,
    );
    let fb = fext_batch(m, fext)?;
    let mut args = vec![("q", &qb), ("v", &vb), ("tau", &tb), ("ddq", &ab)];
    if let Some(f) = &fb {
        args.push(("fext", f));
    }
    let (rows, st) = common_rows(&args)?;
    let nv = m.nv;
    let out = run_rows(py, model, rows, st, 2 * nv, |m, d, k, o| {
        let q = qb.row(k);
        let p = Prescribed { mask: &mask, ddq: ab.row(k) };
        dynamics::hybrid_aba(m, d, q, vb.row(k), tb.row(k), fb.as_ref().map(|f| f.row(k)), Some(p))?;
        o[..nv].copy_from_slice(&d.ddq);
        o[nv..].copy_from_slice(&d.tau);
        Ok(())
    })?;
    let (mut a, mut t) = (Vec::with_capacity(rows * nv), Vec::with_capacity(rows * nv));
    for k in 0..rows {
        a.extend_from_slice(&out[k * 2 * nv..k * 2 * nv + nv]);
        t.extend_from_slice(&out[k * 2 * nv + nv..(k + 1) * 2 * nv]);
    }
    Ok((output(py, a, rows, st, &[nv])?, output(py, t, rows, st, &[nv])?))
}
