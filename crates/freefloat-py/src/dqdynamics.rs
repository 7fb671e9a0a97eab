//! `ff.dq_dynamics`: forward dynamics and joint wrenches by the dual-quaternion formulation
//! (`freefloat_core::dqdynamics`), one sample or a leading time axis, like the engine's `aba`.

use crate::algorithms::{fext_batch, run_rows, Arr};
use crate::batch::{common_rows, model_arg, output, Batch};
use crate::errors::input_err;
use freefloat_core::dqdynamics::decoupled::decoupled_dynamics;
use freefloat_core::dqdynamics::dq_dynamics as core_dq_dynamics;
use freefloat_core::Model;
use pyo3::prelude::*;

/// Joint names (or child body names) to a per-body lock mask.
fn locked_mask(m: &Model, names: &[String]) -> PyResult<Vec<bool>> {
    let mut mask = vec![false; m.nbodies()];
    for n in names {
        let i = m.joint_names.iter().position(|j| j == n).or_else(|| m.body_index(n)).ok_or_else(|| {
            input_err(format!(
                "argument `locked`: '{n}' is not a joint of model '{}' (joints: {})",
                m.name,
                m.joint_names.join(", ")
            ))
        })?;
        if m.parents[i].is_none() {
            return Err(input_err(format!("argument `locked`: '{n}' is the base joint, which cannot be locked")));
        }
        mask[i] = true;
    }
    Ok(mask)
}

/// Returns `(ddq, W)`: accelerations (nv) and, per joint, the wrench it transmits onto its child body
/// (nbodies × 6, [force; torque about the child body origin], child body axes; row 0 is the base joint).
/// Joints named in `locked` are held at zero acceleration and their `tau` entries are ignored.
/// `formulation`: "dq" (chapter 6, default) or "decoupled" (chapter 5's vector formulation, no locking).
#[pyfunction]
#[pyo3(signature = (model, q, v, tau, fext = None, locked = None, formulation = "dq"))]
#[allow(clippy::too_many_arguments)]
pub fn dq_dynamics<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    tau: Arr<'_, 'py>,
    fext: Option<Arr<'_, 'py>>,
    locked: Option<Vec<String>>,
    formulation: &str,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let decoupled = match formulation {
        "dq" => false,
        "decoupled" => true,
        other => {
            return Err(input_err(format!("argument `formulation`: must be 'dq' or 'decoupled', got '{other}'")));
        }
    };
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let mask = match &locked {
        Some(names) => Some(locked_mask(m, names)?),
        None => None,
    };
    if decoupled && mask.as_ref().is_some_and(|k| k.iter().any(|&x| x)) {
        return Err(input_err("argument `locked`: locking joints is implemented in the 'dq' formulation only"));
    }
    let (qb, vb, tb) =
        (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?, Batch::shape("tau", tau, &[m.nv])?);
    let fb = fext_batch(m, fext)?;
    let mut args = vec![("q", &qb), ("v", &vb), ("tau", &tb)];
    if let Some(f) = &fb {
        args.push(("fext", f));
    }
    let (rows, st) = common_rows(&args)?;
    let (nv, nb) = (m.nv, m.nbodies());
    let width = nv + 6 * nb;
    let out = run_rows(py, model, rows, st, width, |m, d, k, o| {
        let fx = fb.as_ref().map(|f| f.row(k));
        let r = if decoupled {
            decoupled_dynamics(m, d, qb.row(k), vb.row(k), tb.row(k), fx)?
        } else {
            core_dq_dynamics(m, d, qb.row(k), vb.row(k), tb.row(k), fx, mask.as_deref())?
        };
        o[..nv].copy_from_slice(&r.ddq);
        for (i, w) in r.joint_wrenches.iter().enumerate() {
            w.write(&mut o[nv + 6 * i..nv + 6 * i + 6]);
        }
        Ok(())
    })?;
    let (mut a, mut w) = (Vec::with_capacity(rows * nv), Vec::with_capacity(rows * 6 * nb));
    for k in 0..rows {
        a.extend_from_slice(&out[k * width..k * width + nv]);
        w.extend_from_slice(&out[k * width + nv..(k + 1) * width]);
    }
    Ok((output(py, a, rows, st, &[nv])?, output(py, w, rows, st, &[nb, 6])?))
}

/// 2-norm condition number of Valverde 2018's system matrix S (6.17) at each configuration (one q or (T, nq)).
#[pyfunction]
pub fn dq_condition_number<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: Arr<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let qb = Batch::shape("q", q, &[m.nq])?;
    let (rows, st) = common_rows(&[("q", &qb)])?;
    let out = run_rows(py, model, rows, st, 1, |m, _d, k, o| {
        o[0] = freefloat_core::dqdynamics::condition_number(m, qb.row(k))?;
        Ok(())
    })?;
    output(py, out, rows, st, &[])
}
