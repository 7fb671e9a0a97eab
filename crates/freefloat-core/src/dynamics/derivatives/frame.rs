//! Derivatives of a frame's pose with respect to q (local tangent, module documentation):
//! the SE(3) logarithm error `e = log(T_ref⁻¹ T(q))` with `∂e/∂q = Jlog(e) J_frame(q)`, and the
//! unit dual quaternion of the pose (Valverde 2018, (3.2)) with its 8 × nv Jacobian.

use super::rnea_derivatives::col;
use crate::check::{check_args, check_body, check_shape, with_unit_q, Args};
use crate::data::Data;
use crate::dualquat::DualQuat;
use crate::dualquat::Quat;
use crate::error::Result;
use crate::kinematics::forward_kinematics_unchecked;
use crate::kinematics::{frame_jacobian, Reference};
use crate::model::Model;
use crate::spatial::lie::{log6, se3_right_jacobian_inv};
use crate::spatial::{Se3, M6, V3, V6};
use nalgebra::DMatrix;

/// SE(3) logarithm `[ρ; φ]` (linear part first, as Pinocchio's `log6`; the engine's `spatial::lie::log6`).
pub fn se3_log(t: &Se3) -> [f64; 6] {
    let x = log6(t);
    [x[0], x[1], x[2], x[3], x[4], x[5]]
}

/// Jacobian of the SE(3) logarithm, `Jr(e)⁻¹` (6 × 6, linear part first): if `T = Exp(e)` then
/// `log(T Exp(ε)) = e + Jr(e)⁻¹ ε + O(ε²)` (Pinocchio's `Jlog6`; the engine's `spatial::lie::se3_right_jacobian_inv`).
pub fn se3_log_jacobian(e: &[f64; 6]) -> M6 {
    se3_right_jacobian_inv(&V6::from_column_slice(e))
}

/// Pose error of the frame `placement` on `body` against `reference` (inertial frame):
/// `e = log(T_ref⁻¹ T(q))` ([linear; angular], the residual of Crocoddyl's
/// `ResidualModelFramePlacement`) into `err`, and `∂e/∂q = Jlog(e) J_local(q)` (6 × nv, local
/// tangent) into `jac`. Runs forward kinematics; checks q, the body index and the shape of `jac`.
#[allow(clippy::too_many_arguments)]
pub fn frame_log_error_derivatives(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    body: usize,
    placement: &Se3,
    reference: &Se3,
    err: &mut [f64; 6],
    jac: &mut DMatrix<f64>,
) -> Result<()> {
    check_args(m, Some(d), &Args::q(q))?;
    check_shape("jac", jac.nrows(), jac.ncols(), (6, m.nv))?;
    frame_jacobian(m, d, q, body, placement, Reference::Local, jac)?;
    let t = d.o_mi[body].compose(placement);
    *err = se3_log(&reference.inv_compose(&t));
    let jl = se3_log_jacobian(err);
    for c in 0..m.nv {
        let x = V6::from_iterator(jac.column(c).iter().copied());
        jac.column_mut(c).copy_from(&(jl * x));
    }
    Ok(())
}

/// Unit dual quaternion of the frame's pose in the inertial frame, translation first
/// (`q_r + ε ½ r q_r`, Valverde 2018 (3.2); layout [real w x y z, dual w x y z]) into `pose`, and
/// its Jacobian `∂pose/∂q` (8 × nv, local tangent) into `jac`. The rotation part has the sign of
/// `Quat::from_rotation_matrix` (its scalar part ≥ 0); for the other sign negate both.
/// A local twist `[ε_lin; ε_ang]` of the frame changes `q_r` by `½ q_r (0, ε_ang)` and `q_d` by
/// `½ q_r (0, ε_lin) + ½ (0, r) · ½ q_r (0, ε_ang)`; composed with the frame Jacobian.
#[allow(clippy::too_many_arguments)]
pub fn frame_dq_pose_derivatives(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    body: usize,
    placement: &Se3,
    pose: &mut [f64; 8],
    jac: &mut DMatrix<f64>,
) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::q(q))?;
    check_body(m, "body", body)?;
    check_shape("jac", jac.nrows(), jac.ncols(), (8, m.nv))?;
    with_unit_q(m, d, q, fix, |d, q| forward_kinematics_unchecked(m, d, q));
    let t = d.o_mi[body].compose(placement);
    let x = DualQuat::from_se3(&t);
    *pose = x.to_array();
    let qr = x.r;
    let rp = Quat::pure(&t.trans);
    // G: 8 × 6 map from a local twist [lin; ang] to d(pose)
    let mut g = nalgebra::SMatrix::<f64, 8, 6>::zeros();
    for k in 0..3 {
        let e = V3::from_fn(|i, _| if i == k { 1.0 } else { 0.0 });
        let dqr = qr.mul(&Quat::pure(&e)).scale(0.5);
        let dqd_ang = rp.mul(&dqr).scale(0.5);
        let (a, b) = (dqr.to_vec4(), dqd_ang.to_vec4());
        for i in 0..4 {
            g[(4 + i, k)] = a[i];
            g[(i, 3 + k)] = a[i];
            g[(4 + i, 3 + k)] = b[i];
        }
    }
    // Local frame Jacobian column by column (as `frame_jacobian` with `Reference::Local`): only the
    // joints on the path to the base move the frame.
    jac.fill(0.0);
    let mut j = Some(body);
    while let Some(i) = j {
        for c in 0..m.nvs[i] {
            let tw = t.inv_act_motion(&d.o_mi[i].act_motion(&col(&d.s[i], c)));
            jac.column_mut(m.idx_v[i] + c).copy_from(&(g * tw.to_v6()));
        }
        j = m.parents[i];
    }
    Ok(())
}
