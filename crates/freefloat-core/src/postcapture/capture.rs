//! The grasp of a drifting target as an inelastic impact (the first phase of a capture mission).
//!
//! At the instant of contact the target's grasp frame coincides with the end effector's, and the gripper closes
//! in a time short against the motion: the target becomes a body welded to the end effector (the combined model's
//! fixed-joint leaf). Over the impact the positions do not change and every finite force (joint torques, thrust,
//! gravity gradient) contributes nothing; only the grasp impulse Λ acts, equal and opposite on the servicer and the
//! target. With the joints free during the impact (no impulsive joint torque), integrating the equations of
//! motion of the servicer and the Newton-Euler equation of the target over the impact gives
//!
//!   M_s(q) (v⁺ − v⁻) = J_t(q)ᵀ (−Λ),      I_t (J_t(q) v⁺ − V_t⁻) = Λ,
//!
//! with M_s the servicer's joint-space inertia (the combined model without the target's inertia), J_t the target
//! body's Jacobian (its twist in its own axes), I_t its spatial inertia and V_t⁻ its twist before the grasp.
//! Eliminating Λ: M_c(q) v⁺ = M_s(q) v⁻ + J_tᵀ I_t V_t⁻ with M_c = M_s + J_tᵀ I_t J_t the combined model's inertia
//! (plastic impact of a tree, e.g. Yoshida's impulse formulation of capture). The free base's rows of this equation
//! are the total linear and angular momentum, which are therefore conserved exactly; the kinetic energy can only
//! drop (a plastic impact: the relative twist at the grasp is destroyed, none is stored).

use crate::check::{check_args, check_finite, Args};
use crate::data::Data;
use crate::dynamics::crba;
use crate::error::{FfError, Result};
use crate::kinematics::{forward_kinematics, frame_jacobian, momentum, Reference};
use crate::model::{JointType, Model};
use crate::spatial::{Force, Motion, Se3, V3};
use nalgebra::{DMatrix, DVector};

/// What the grasp does: the velocities after it, the impulse it takes, and the balances that check it.
#[derive(Clone, Debug)]
pub struct CaptureImpact {
    /// Generalized velocity of the combined model just after the grasp (nv).
    pub v_post: Vec<f64>,
    /// Impulse of the grasp on the target [linear (N s); angular (N m s)], in the target frame, about its origin.
    pub impulse_local: Force,
    /// The same impulse in inertial axes, about the target frame origin.
    pub impulse_world: Force,
    /// Total momentum (inertial frame, about the inertial origin) of the servicer plus the free target before.
    pub momentum_before: Force,
    /// Total momentum of the combined model after.
    pub momentum_after: Force,
    /// Kinetic energy before: servicer plus free target (J).
    pub energy_before: f64,
    /// Kinetic energy after: the combined model (J); below `energy_before`, the impact is plastic.
    pub energy_after: f64,
}

/// The grasp impact of a target on `model`, whose body `target` is the grasped target welded to the end effector
/// (a leaf on a fixed joint; its inertial parameters are the target's). `q` is the configuration at contact,
/// `v_pre` the servicer's generalized velocity just before it (the target's rows play no part: a fixed joint has
/// none), `target_twist` the free target's twist just before, in the target frame's own axes ([linear velocity of
/// the frame origin; angular velocity]). See the module comment for the equations.
pub fn capture_impact(
    model: &Model,
    d: &mut Data,
    target: usize,
    q: &[f64],
    v_pre: &[f64],
    target_twist: &[f64; 6],
) -> Result<CaptureImpact> {
    check_args(model, Some(d), &Args::qv(q, v_pre))?;
    check_finite("target_twist", target_twist)?;
    check_target(model, target)?;
    let nv = model.nv;

    // the servicer alone: the same tree with the target's inertia removed (a massless welded leaf adds nothing)
    let mut params: Vec<f64> = model.parameters().iter().flatten().copied().collect();
    params[10 * target..10 * target + 10].fill(0.0);
    let servicer = model.with_parameters(&params)?;
    let mut ds = Data::try_new(&servicer)?;
    crba(&servicer, &mut ds, q)?;
    let m_s = ds.mass_matrix.clone();
    crba(model, d, q)?;
    let m_c = d.mass_matrix.clone();

    let mut jac = DMatrix::zeros(6, nv);
    frame_jacobian(model, d, q, target, &Se3::identity(), Reference::Local, &mut jac)?;
    let it = model.inertias[target];
    let tw_pre = Motion::new(
        V3::new(target_twist[0], target_twist[1], target_twist[2]),
        V3::new(target_twist[3], target_twist[4], target_twist[5]),
    );
    let h_pre = it.mul_motion(&tw_pre);
    let h_pre6 =
        DVector::from_column_slice(&[h_pre.lin.x, h_pre.lin.y, h_pre.lin.z, h_pre.ang.x, h_pre.ang.y, h_pre.ang.z]);

    // M_c v⁺ = M_s v⁻ + J_tᵀ I_t V_t⁻
    let vm = DVector::from_column_slice(v_pre);
    let rhs = &m_s * &vm + jac.transpose() * h_pre6;
    let chol = m_c.clone().cholesky().ok_or_else(|| {
        FfError::Numerical("capture: the combined model's mass matrix is not positive definite at this q".into())
    })?;
    let v_post = chol.solve(&rhs);
    let v_post: Vec<f64> = v_post.iter().copied().collect();

    // Λ = I_t (J_t v⁺ − V_t⁻): the target's change of momentum
    let jv = &jac * DVector::from_column_slice(&v_post);
    let tw_post = Motion::new(V3::new(jv[0], jv[1], jv[2]), V3::new(jv[3], jv[4], jv[5]));
    let h_post = it.mul_motion(&tw_post);
    let impulse_local = Force { lin: h_post.lin - h_pre.lin, ang: h_post.ang - h_pre.ang };

    // balances: the servicer's and the free target's momenta before, the combined model's after
    forward_kinematics(model, d, q)?;
    let o_mt = d.o_mi[target];
    let rot_only = Se3::new(o_mt.rot, V3::zeros());
    let impulse_world = rot_only.act_force(&impulse_local);
    let target_world = o_mt.act_force(&h_pre);
    let p_s = momentum(&servicer, &mut ds, q, v_pre)?;
    let momentum_before = Force { lin: p_s.lin + target_world.lin, ang: p_s.ang + target_world.ang };
    let momentum_after = momentum(model, d, q, &v_post)?;
    let energy_before = 0.5 * vm.dot(&(&m_s * &vm)) + it.kinetic_energy(&tw_pre);
    let vp = DVector::from_column_slice(&v_post);
    let energy_after = 0.5 * vp.dot(&(&m_c * &vp));
    Ok(CaptureImpact {
        v_post,
        impulse_local,
        impulse_world,
        momentum_before,
        momentum_after,
        energy_before,
        energy_after,
    })
}

/// The target must be a leaf welded by a fixed joint below the base (what the grasp makes of it).
fn check_target(model: &Model, target: usize) -> Result<()> {
    let n = model.nbodies();
    if target == 0 || target >= n {
        return Err(FfError::arg("target", format!("expected a body index in 1..{n}, got {target}")));
    }
    if model.joint_types[target] != JointType::Fixed {
        return Err(FfError::arg(
            "target",
            format!("body {target} must be welded to the end effector by a fixed joint (the grasp)"),
        ));
    }
    if model.parents.contains(&Some(target)) {
        return Err(FfError::arg("target", format!("body {target} must be a leaf (nothing is attached to a target)")));
    }
    if model.inertias[target].mass <= 0.0 {
        return Err(FfError::arg("target", format!("body {target} has no mass: nothing to capture")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::builtin;

    fn zhang3d() -> Model {
        builtin::load("zhang2020_3d").unwrap()
    }

    fn state(m: &Model) -> (Vec<f64>, Vec<f64>) {
        let mut q = m.neutral();
        let joints = [0.3, 0.5, 1.0, 0.3, 0.7, 0.2];
        q[7..13].copy_from_slice(&joints);
        q[3..7].copy_from_slice(&[0.1, -0.2, 0.05, (1.0f64 - 0.0525).sqrt()]);
        let v = vec![0.02, -0.01, 0.03, 0.01, -0.02, 0.015, 0.05, -0.04, 0.03, 0.02, -0.01, 0.06];
        (q, v)
    }

    #[test]
    fn momentum_is_conserved_and_energy_drops() {
        let m = zhang3d();
        let t = m.body_index("target").unwrap();
        let mut d = Data::new(&m);
        let (q, v) = state(&m);
        let c = capture_impact(&m, &mut d, t, &q, &v, &[0.3, -0.2, 0.1, 0.05, 0.1, -0.08]).unwrap();
        let scale = c.momentum_before.lin.norm() + c.momentum_before.ang.norm();
        assert!((c.momentum_after.lin - c.momentum_before.lin).norm() < 1e-12 * scale);
        assert!((c.momentum_after.ang - c.momentum_before.ang).norm() < 1e-12 * scale);
        assert!(c.energy_after < c.energy_before);
        // the servicer takes −Λ, so the target's impulse is non-zero for a mismatched twist
        assert!(c.impulse_local.lin.norm() > 1.0);
    }

    #[test]
    fn a_target_already_moving_with_the_gripper_takes_no_impulse() {
        let m = zhang3d();
        let t = m.body_index("target").unwrap();
        let mut d = Data::new(&m);
        let (q, v) = state(&m);
        // the gripper's own twist: no relative velocity at contact, so nothing changes
        let mut jac = DMatrix::zeros(6, m.nv);
        frame_jacobian(&m, &mut d, &q, t, &Se3::identity(), Reference::Local, &mut jac).unwrap();
        let tw = &jac * DVector::from_column_slice(&v);
        let tw: [f64; 6] = std::array::from_fn(|k| tw[k]);
        let c = capture_impact(&m, &mut d, t, &q, &v, &tw).unwrap();
        for (a, b) in c.v_post.iter().zip(&v) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        assert!(c.impulse_local.lin.norm() < 1e-9 && c.impulse_local.ang.norm() < 1e-9);
        assert!((c.energy_after - c.energy_before).abs() < 1e-9 * c.energy_before);
    }

    #[test]
    fn refusals_name_the_argument() {
        let m = zhang3d();
        let mut d = Data::new(&m);
        let (q, v) = state(&m);
        let e = capture_impact(&m, &mut d, 3, &q, &v, &[0.0; 6]).unwrap_err().to_string();
        assert!(e.contains("target") && e.contains("fixed joint"), "{e}");
        let t = m.body_index("target").unwrap();
        let e = capture_impact(&m, &mut d, t, &q, &v, &[f64::NAN, 0., 0., 0., 0., 0.]).unwrap_err().to_string();
        assert!(e.contains("target_twist"), "{e}");
        let e = capture_impact(&m, &mut d, t, &q, &v[..5], &[0.0; 6]).unwrap_err().to_string();
        assert!(e.contains("`v`") || e.contains("v"), "{e}");
    }
}
