//! Dynamics derivatives (freefloat_core::dynamics::derivatives) as Python functions. Each takes one
//! sample or a leading time axis, like the other algorithms; matrices come back row-major (numpy).

use crate::algorithms::{at_row, run_rows, Arr};
use crate::batch::{array_copy, common_rows, model_arg, output, Batch};
use crate::errors::guard;
use crate::model::PyModel;
use freefloat_core::dynamics::derivatives::{self as der, Derivatives, Scheme};
use freefloat_core::spatial::{rot_from_quat, Se3, V3};
use freefloat_core::{Data, FfError, Model};
use nalgebra::DMatrix;
use pyo3::prelude::*;
use std::cell::RefCell;

thread_local! {
    // One workspace per thread, remade when a call comes for another model.
    static WORK: RefCell<Option<Derivatives>> = const { RefCell::new(None) };
}

fn with_work<T>(m: &Model, f: impl FnOnce(&mut Derivatives) -> T) -> T {
    WORK.with(|c| {
        let mut b = c.borrow_mut();
        if b.as_ref().is_none_or(|w| w.model_id() != m.id()) {
            *b = Some(Derivatives::new(m));
        }
        f(b.as_mut().expect("just made"))
    })
}

/// `a` (column-major) into `o` row-major: `o` read as a column-major nc × nr matrix receives aᵀ (nalgebra's
/// transposed copy; an indexed copy per entry was ~7 % of the instructions of a single `aba_derivatives` call on a
/// 12-DoF model, callgrind).
fn put(a: &DMatrix<f64>, o: &mut [f64]) {
    let (nr, nc) = a.shape();
    nalgebra::DMatrixViewMut::from_slice(&mut o[..nr * nc], nc, nr).tr_copy_from(a);
}

/// Run `f` per sample writing the concatenation of `parts` (each a shape) into a scratch row, and append each part
/// to its own array. (Writing all samples into one buffer and splitting it afterwards made a stacked call touch
/// every output twice, through memory: fresh pages for a buffer as large as the outputs, then a copy.)
fn multi<'py, F>(
    py: Python<'py>,
    model: &PyModel,
    rows: usize,
    stacked: bool,
    parts: &[&[usize]],
    f: F,
) -> PyResult<Vec<Bound<'py, PyAny>>>
where
    F: Fn(&Model, &mut Data, &mut Derivatives, usize, &mut [f64]) -> Result<(), FfError> + Send + Sync,
{
    let width: usize = parts.iter().map(|p| p.iter().product::<usize>()).sum();
    if !stacked {
        // one sample: its parts straight into fresh numpy arrays (no vectors in between, whose allocations and
        // copies showed in the instruction counts of a single call on a 12-DoF model, callgrind)
        debug_assert_eq!(rows, 1);
        let mut row = vec![0.0; width];
        model.with_data(|m, d| guard(|| with_work(m, |w| f(m, d, w, 0, &mut row))))?;
        let mut off = 0;
        return parts
            .iter()
            .map(|p| {
                let s: usize = p.iter().product();
                off += s;
                array_copy(py, p, &row[off - s..off])
            })
            .collect();
    }
    let sizes: Vec<usize> = parts.iter().map(|p| p.iter().product()).collect();
    let work = || {
        model.with_data(|m, d| {
            guard(|| {
                let mut out: Vec<Vec<f64>> = sizes.iter().map(|&s| Vec::with_capacity(rows * s)).collect();
                let mut row = vec![0.0; width];
                for k in 0..rows {
                    with_work(m, |w| f(m, d, w, k, &mut row)).map_err(|e| at_row(e, k, stacked))?;
                    let mut off = 0;
                    for (o, &s) in out.iter_mut().zip(&sizes) {
                        o.extend_from_slice(&row[off..off + s]);
                        off += s;
                    }
                }
                Ok(out)
            })
        })
    };
    let data = py.detach(work)?;
    data.into_iter().zip(parts).map(|(v, p)| output(py, v, rows, stacked, p)).collect()
}

fn three<'py>(v: Vec<Bound<'py, PyAny>>) -> (Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>) {
    let mut it = v.into_iter();
    let (a, b, c) = (it.next(), it.next(), it.next());
    (a.expect("3 outputs"), b.expect("3 outputs"), c.expect("3 outputs"))
}

fn two<'py>(v: Vec<Bound<'py, PyAny>>) -> (Bound<'py, PyAny>, Bound<'py, PyAny>) {
    let mut it = v.into_iter();
    let (a, b) = (it.next(), it.next());
    (a.expect("2 outputs"), b.expect("2 outputs"))
}

/// Derivatives of forward dynamics a = FD(q, v, tau, fext): (da_dq, da_dv, da_dtau), each (nv, nv).
/// Derivatives with respect to q are taken along the local tangent of q (nv columns): for a free base,
/// a base-frame displacement and a base-frame rotation vector, the axes of the base twist in v
/// (Pinocchio's convention, so they compare with pin.computeABADerivatives). da_dtau = M⁻¹.
#[pyfunction]
#[pyo3(signature = (model, q, v, tau, fext = None))]
pub fn aba_derivatives<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    tau: Arr<'_, 'py>,
    fext: Option<Arr<'_, 'py>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let nv = m.nv;
    let (qb, vb, tb) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[nv])?, Batch::shape("tau", tau, &[nv])?);
    let fb = fext.map(|f| Batch::shape("fext", f, &[m.nbodies(), 6])).transpose()?;
    let mut args = vec![("q", &qb), ("v", &vb), ("tau", &tb)];
    if let Some(f) = &fb {
        args.push(("fext", f));
    }
    let (rows, st) = common_rows(&args)?;
    let out = multi(py, model, rows, st, &[&[nv, nv], &[nv, nv], &[nv, nv]], |m, d, w, k, o| {
        der::aba_derivatives(m, d, w, qb.row(k), vb.row(k), tb.row(k), fb.as_ref().map(|f| f.row(k)))?;
        let n2 = nv * nv;
        put(&w.da_dq, &mut o[..n2]);
        put(&w.da_dv, &mut o[n2..2 * n2]);
        // M⁻¹ is exactly symmetric (its lower triangle is a copy of the upper): row-major = column-major
        o[2 * n2..].copy_from_slice(w.minv.as_slice());
        Ok(())
    })?;
    Ok(three(out))
}

/// Derivatives of inverse dynamics tau = RNEA(q, v, a, fext): (dtau_dq, dtau_dv, dtau_da = M), each
/// (nv, nv); q along its local tangent (see aba_derivatives).
#[pyfunction]
#[pyo3(signature = (model, q, v, a, fext = None))]
pub fn rnea_derivatives<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    a: Arr<'_, 'py>,
    fext: Option<Arr<'_, 'py>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let nv = m.nv;
    let (qb, vb, ab) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[nv])?, Batch::shape("a", a, &[nv])?);
    let fb = fext.map(|f| Batch::shape("fext", f, &[m.nbodies(), 6])).transpose()?;
    let mut args = vec![("q", &qb), ("v", &vb), ("a", &ab)];
    if let Some(f) = &fb {
        args.push(("fext", f));
    }
    let (rows, st) = common_rows(&args)?;
    let out = multi(py, model, rows, st, &[&[nv, nv], &[nv, nv], &[nv, nv]], |m, d, w, k, o| {
        der::rnea_derivatives(m, d, w, qb.row(k), vb.row(k), ab.row(k), fb.as_ref().map(|f| f.row(k)))?;
        let n2 = nv * nv;
        put(&w.dtau_dq, &mut o[..n2]);
        put(&w.dtau_dv, &mut o[n2..2 * n2]);
        freefloat_core::dynamics::crba(m, d, qb.row(k))?;
        put(&d.mass_matrix, &mut o[2 * n2..]);
        Ok(())
    })?;
    Ok(three(out))
}

fn scheme(method: &str) -> PyResult<Scheme> {
    guard(|| {
        Scheme::from_name(method)
            .map_err(|_| FfError::arg("method", format!("expected 'euler' or 'rk4', got '{method}'")))
    })
}

/// One step of the forward dynamics with tau held over it: (q_next (nq), v_next (nv)).
/// method "euler": semi-implicit Euler v+ = v + a dt, q+ = q ⊕ v+ dt (Crocoddyl's
/// IntegratedActionModelEuler); "rk4": Runge-Kutta 4 on the Lie group (the simulator's step).
#[pyfunction]
#[pyo3(signature = (model, q, v, tau, dt, method = "euler"))]
pub fn step<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    tau: Arr<'_, 'py>,
    dt: f64,
    method: &str,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let sc = scheme(method)?;
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (nq, nv) = (m.nq, m.nv);
    let (qb, vb, tb) = (Batch::shape("q", q, &[nq])?, Batch::shape("v", v, &[nv])?, Batch::shape("tau", tau, &[nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("v", &vb), ("tau", &tb)])?;
    let out = multi(py, model, rows, st, &[&[nq], &[nv]], |m, d, w, k, o| {
        der::step(m, d, w, qb.row(k), vb.row(k), tb.row(k), dt, sc)?;
        o[..nq].copy_from_slice(&w.q_next);
        o[nq..].copy_from_slice(&w.v_next);
        Ok(())
    })?;
    Ok(two(out))
}

/// Derivatives of one step (see step) in the tangent error state: (Fx (2nv, 2nv), Fu (2nv, nv)),
/// rows and columns [tangent of q; v], u = tau (all nv generalized forces). For an under-actuated
/// robot with tau = B u use Fu @ B; a free-floating robot with an unactuated base keeps Fu[:, 6:].
#[pyfunction]
#[pyo3(signature = (model, q, v, tau, dt, method = "euler"))]
pub fn step_derivatives<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    tau: Arr<'_, 'py>,
    dt: f64,
    method: &str,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let sc = scheme(method)?;
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let nv = m.nv;
    let (qb, vb, tb) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[nv])?, Batch::shape("tau", tau, &[nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("v", &vb), ("tau", &tb)])?;
    let out = multi(py, model, rows, st, &[&[2 * nv, 2 * nv], &[2 * nv, nv]], |m, d, w, k, o| {
        der::step_derivatives(m, d, w, qb.row(k), vb.row(k), tb.row(k), dt, sc)?;
        let nx = 4 * nv * nv;
        put(&w.fx, &mut o[..nx]);
        put(&w.fu, &mut o[nx..]);
        Ok(())
    })?;
    Ok(two(out))
}

/// q ⊕ dq (nq): the configuration reached from q by the tangent displacement dq (nv; for a free base
/// a base-frame displacement and rotation vector), on R³ × SO(3).
#[pyfunction]
pub fn integrate<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    dq: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, db) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("dq", dq, &[m.nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("dq", &db)])?;
    let out = run_rows(py, model, rows, st, m.nq, |m, _d, k, o| der::integrate(m, qb.row(k), db.row(k), o))?;
    output(py, out, rows, st, &[m.nq])
}

/// q1 ⊖ q0 (nv): the tangent displacement dq with integrate(q0, dq) == q1.
#[pyfunction]
pub fn difference<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: Arr<'_, 'py>,
    q1: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (ab, bb) = (Batch::shape("q0", q0, &[m.nq])?, Batch::shape("q1", q1, &[m.nq])?);
    let (rows, st) = common_rows(&[("q0", &ab), ("q1", &bb)])?;
    let out = run_rows(py, model, rows, st, m.nv, |m, _d, k, o| der::difference(m, ab.row(k), bb.row(k), o))?;
    output(py, out, rows, st, &[m.nv])
}

/// Jacobians of integrate(q, dq), local tangents: (d/dq, d/d(dq)), each (nv, nv).
#[pyfunction]
pub fn integrate_jacobians<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    dq: Arr<'_, 'py>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let nv = m.nv;
    let (qb, db) = (Batch::shape("q", q, &[m.nq])?, Batch::shape("dq", dq, &[nv])?);
    let (rows, st) = common_rows(&[("q", &qb), ("dq", &db)])?;
    let out = multi(py, model, rows, st, &[&[nv, nv], &[nv, nv]], |m, _d, w, k, o| {
        der::integrate_jacobians(m, qb.row(k), db.row(k), &mut w.da_dq, &mut w.da_dv)?;
        put(&w.da_dq, &mut o[..nv * nv]);
        put(&w.da_dv, &mut o[nv * nv..]);
        Ok(())
    })?;
    Ok(two(out))
}

/// Jacobians of difference(q0, q1), local tangents: (d/dq0, d/dq1), each (nv, nv).
#[pyfunction]
pub fn difference_jacobians<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q0: Arr<'_, 'py>,
    q1: Arr<'_, 'py>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let nv = m.nv;
    let (ab, bb) = (Batch::shape("q0", q0, &[m.nq])?, Batch::shape("q1", q1, &[m.nq])?);
    let (rows, st) = common_rows(&[("q0", &ab), ("q1", &bb)])?;
    let out = multi(py, model, rows, st, &[&[nv, nv], &[nv, nv]], |m, _d, w, k, o| {
        let mut buf = std::mem::take(&mut w.ddq);
        let r = der::difference_jacobians(m, ab.row(k), bb.row(k), &mut w.da_dq, &mut w.da_dv, &mut buf);
        w.ddq = buf;
        r?;
        put(&w.da_dq, &mut o[..nv * nv]);
        put(&w.da_dv, &mut o[nv * nv..]);
        Ok(())
    })?;
    Ok(two(out))
}

/// Pose error of frame `name` against `target` (7: position, quaternion x y z w; inertial frame):
/// (e (6,), de_dq (6, nv)) with e = log(T_target⁻¹ T(q)) = [linear; angular] (SE(3) logarithm, the
/// residual of Crocoddyl's ResidualModelFramePlacement) and de_dq = Jlog(e) J_local(q).
#[pyfunction]
pub fn frame_log_error_derivatives<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    name: &str,
    target: Arr<'_, 'py>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let nv = m.nv;
    let (body, pl) = guard(|| m.frame_or_body(name))?;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let tb = Batch::new("target", target, &[7])?;
    let (rows, st) = common_rows(&[("q", &qb), ("target", &tb)])?;
    let out = multi(py, model, rows, st, &[&[6], &[6, nv]], |m, d, w, k, o| {
        let t = tb.row(k);
        let n = (t[3] * t[3] + t[4] * t[4] + t[5] * t[5] + t[6] * t[6]).sqrt();
        if (n - 1.0).abs() > 1e-6 {
            return Err(FfError::arg(
                "target",
                format!("entries 3..7 must be a unit quaternion (x y z w), norm {n:.6}"),
            ));
        }
        let quat = [t[3] / n, t[4] / n, t[5] / n, t[6] / n];
        let reference = Se3::new(rot_from_quat(&quat), V3::new(t[0], t[1], t[2]));
        let mut e = [0.0; 6];
        // w.fx is 2nv × 2nv; use a 6 × nv buffer of its own size class: the workspace's dq Jacobian
        let mut jac = std::mem::replace(&mut w.da_dq, DMatrix::zeros(0, 0));
        jac.resize_mut(6, nv, 0.0);
        let r = der::frame_log_error_derivatives(m, d, qb.row(k), body, &pl, &reference, &mut e, &mut jac);
        if r.is_ok() {
            o[..6].copy_from_slice(&e);
            put(&jac, &mut o[6..]);
        }
        jac.resize_mut(nv, nv, 0.0);
        w.da_dq = jac;
        r
    })?;
    Ok(two(out))
}

/// Dual quaternion of frame `name`'s pose (8: real w x y z, dual w x y z; translation first,
/// q_r + ε ½ r q_r) and its Jacobian (8, nv) along the local tangent of q. The rotation part has a
/// non-negative scalar; for the other sign negate both.
#[pyfunction]
pub fn frame_dq_pose_derivatives<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    name: &str,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let nv = m.nv;
    let (body, pl) = guard(|| m.frame_or_body(name))?;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let out = multi(py, model, rows, st, &[&[8], &[8, nv]], |m, d, w, k, o| {
        let mut x = [0.0; 8];
        let mut jac = std::mem::replace(&mut w.da_dq, DMatrix::zeros(0, 0));
        jac.resize_mut(8, nv, 0.0);
        let r = der::frame_dq_pose_derivatives(m, d, qb.row(k), body, &pl, &mut x, &mut jac);
        if r.is_ok() {
            o[..8].copy_from_slice(&x);
            put(&jac, &mut o[8..]);
        }
        jac.resize_mut(nv, nv, 0.0);
        w.da_dq = jac;
        r
    })?;
    Ok(two(out))
}
