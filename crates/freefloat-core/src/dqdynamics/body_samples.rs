//! Per-body motion and applied wrench after a dual-quaternion solve, in each body's CoM frame `o_i`: what the
//! concurrent-learning mass estimator of Valverde 2018 ch. 9 needs at every sample (the absolute CoM twist
//! `ω^{o_i}_{o_i/I}`, its body-frame rate, and the known wrench on the body about its CoM, (9.4)–(9.11)).
//!
//! The wrench is rebuilt from the *transmitted joint wrenches* (reaction + actuation, what a six-axis
//! force/torque sensor at each joint measures) and the external wrenches, never from the body's mass
//! properties, so that `R̂(ω̇_i, ω_i) v(M_i) = F_i` is a genuine check of the dynamics, and so that sensor
//! noise can be put on the joint wrenches (Remark 16). Allocates nothing.

use super::sixvec::{ad_in, ad_out};
use crate::data::Data;
use crate::dualquat::DualQuat;
use crate::error::{FfError, Result};
use crate::model::Model;
use crate::spatial::{Force, V3, V6};

fn dq_of(x: &V6) -> DualQuat {
    DualQuat::vector(&V3::new(x[0], x[1], x[2]), &V3::new(x[3], x[4], x[5]))
}

/// Motion of every body after the last `dq_dynamics` call on `d`: `twists[i] = ω + ε v` (angular velocity
/// and CoM velocity, both in the body axes, which are those of `o_i`) and `rates[i]`, its component
/// derivative in the same axes (`ω̇ + ε v̇`). Valverde 2018, (2.36) and (6.8).
pub fn com_motion(m: &Model, d: &Data, twists: &mut [DualQuat], rates: &mut [DualQuat]) -> Result<()> {
    let n = m.nbodies();
    let w = &d.dq;
    if w.tw_o.len() != n || w.ydot.len() != n {
        return Err(FfError::arg("d", "holds no dual-quaternion solution for this model (call dq_dynamics first)"));
    }
    if twists.len() != n || rates.len() != n {
        return Err(FfError::arg("twists/rates", format!("need one entry per body ({n})")));
    }
    for i in 0..n {
        twists[i] = dq_of(&w.tw_o[i]);
        rates[i] = dq_of(&w.ydot[i]);
    }
    Ok(())
}

/// The wrench applied to every body about its CoM, in `o_i` axes (`f + ε τ`), from the joint wrenches
/// `joint_wrenches[i]` (what joint i transmits onto body i, body-i frame about its origin, as
/// `DqDynamics::joint_wrenches`; for a free base, the base actuation) and the optional external wrenches
/// `fext` (nbodies × 6, body frame about the body origin). Body i gets `+W_i` and `−W_c` of every child c,
/// each carried to `o_i` by the shifting law (2.42). Gravity is not included (the estimator rejects models
/// with gravity). Needs the kinematics of the last `dq_dynamics` call on `d`.
pub fn com_wrenches(
    m: &Model,
    d: &Data,
    joint_wrenches: &[Force],
    fext: Option<&[f64]>,
    out: &mut [DualQuat],
) -> Result<()> {
    let n = m.nbodies();
    let w = &d.dq;
    if w.to_com.len() != n || w.local.len() != n {
        return Err(FfError::arg("d", "holds no dual-quaternion solution for this model (call dq_dynamics first)"));
    }
    if joint_wrenches.len() != n || out.len() != n {
        return Err(FfError::arg("joint_wrenches/out", format!("need one entry per body ({n})")));
    }
    if let Some(f) = fext {
        crate::check::check_vec("fext", f, 6 * n)?;
    }
    for i in 0..n {
        // q_{B_i/o_i} = q_{o_i/B_i}*: W^{o_i} = q_{B_i/o_i} W^{B_i} q*_{B_i/o_i} = ad_in(q_{o_i/B_i}) W
        let to_o = ad_in(&w.to_com[i]);
        let mut x = to_o * joint_wrenches[i].to_v6();
        if let Some(f) = fext {
            x += to_o * V6::from_column_slice(&f[6 * i..6 * i + 6]);
        }
        out[i] = dq_of(&x);
    }
    for c in 1..n {
        let Some(p) = m.parents[c] else { continue };
        // reaction on the parent: −W_c carried from B_c to o_p, q_{B_c/o_p} = q_{o_p/B_p}* q_{B_c/B_p}
        let q = w.to_com[p].conj().mul(&w.local[c]);
        let x = ad_out(&q) * joint_wrenches[c].to_v6();
        out[p] = out[p] - dq_of(&x);
    }
    Ok(())
}
