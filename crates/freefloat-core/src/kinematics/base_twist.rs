//! The base twist of a free-floating robot that gives a stated total momentum: the base block of the
//! momentum equation `A_b v_b + A_m q̇_m = h` solved for `v_b` (Naveen, Shah, Misra's momentum model;
//! the base part of Umetani-Yoshida's generalized Jacobian; with h = 0 it is the base twist
//! `[v_0; ω_0] = H_b⁻¹ (h − H_q q̇)` that Naveen et al. use for prediction, Sec. VI.D).
//!
//! This is the one copy of that formula: the exciting-trajectory design (`excitation::response`), the
//! generalized Jacobian (`kinematics::jacobian`) and, through the binding, Python's zero-momentum driven
//! simulation all call it.
//!
//! It is solved in the base frame: with every placement taken relative to the base, `Ic` is the composite
//! inertia of the whole robot about the base origin in base axes (symmetric positive definite for any
//! robot with mass) and `h_m` the momentum of the joint motion alone (base at rest), so
//! `Sᵀ Ic S v_b = Sᵀ (h_b − h_m)`, with `S` the base joint's motion subspace (the identity for a free
//! base; x, y and yaw for a planar base) and `h_b` the requested momentum carried into the base frame.
//! For a planar base this imposes the in-plane momenta (p_x, p_y, L_z) only; the others are not
//! controllable by an in-plane base.

use super::forward_velocities_unchecked;
use crate::check::check_vec;
use crate::data::Data;
use crate::error::{FfError, Result};
use crate::model::{JointType, Model};
use crate::spatial::{Force, Inertia, V3};
use nalgebra::{Matrix6x3, Vector3, Vector6};

/// Base twist `[v; ω]` in the base frame that gives the total momentum `momentum` (`[p; L about the
/// inertial origin]`, inertial frame: ARCHITECTURE.md) when the joints after the base move with
/// `joint_rates` (`v[nb..]`, length `nv − nb`) at configuration `q`. Zero momentum is zero in every frame,
/// so then the base pose in `q` does not matter.
///
/// For a planar base the twist is `[vx, vy, 0, 0, 0, ω_z]` (`base_velocity_coordinates` gives the three
/// entries of `v`). Uses `d.tau` and `d.qbuf` as scratch (no allocation) and leaves in `d` the kinematics
/// of `q` with the base at rest. Errors: wrong sizes or non-finite entries, a non-unit quaternion, a fixed
/// base, a robot without mass (the base block is then singular).
pub fn base_twist_for_momentum(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    joint_rates: &[f64],
    momentum: &[f64; 6],
) -> Result<Vector6<f64>> {
    let nb = m.nvs[0];
    if nb == 0 {
        return Err(FfError::arg("model", "the base is fixed: there is no base twist to solve for"));
    }
    crate::check::check_data(m, d)?;
    check_vec("joint_rates", joint_rates, m.nv - nb)?;
    check_vec("momentum", momentum, 6)?;
    // Borrow the scratch buffers out of `d` (moves, no allocation) so that `d` can be passed on.
    let mut qbuf = std::mem::take(&mut d.qbuf);
    let mut v = std::mem::take(&mut d.tau);
    let out = (|| {
        let q = m.checked_q(q, &mut qbuf)?;
        v[..nb].fill(0.0);
        v[nb..].copy_from_slice(joint_rates);
        // q checked above; d.tau and d.qbuf are out of `d` here, so the unchecked core
        forward_velocities_unchecked(m, d, q, &v);
        solve_base_block(m, d, momentum)
    })();
    d.qbuf = qbuf;
    d.tau = v;
    out
}

/// The three base velocity coordinates of a planar base, or the six of a free base, from the base twist.
pub fn base_velocity_coordinates(m: &Model, twist: &Vector6<f64>, out: &mut [f64]) -> Result<()> {
    let nb = m.nvs[0];
    if out.len() != nb {
        return Err(FfError::arg("out", format!("expected {nb} entries, got {}", out.len())));
    }
    // The base subspace columns are unit vectors (free: identity; planar: x, y, yaw), so Sᵀ twist selects.
    let s = &m.subspaces[0];
    for c in 0..nb {
        out[c] = (0..6).map(|r| s[(r, c)] * twist[r]).sum();
    }
    Ok(())
}

/// After `forward_velocities` with the base at rest: solve `Sᵀ Ic S x = Sᵀ (h_b − h_m)` in the base frame.
fn solve_base_block(m: &Model, d: &Data, momentum: &[f64; 6]) -> Result<Vector6<f64>> {
    let base = d.o_mi[0];
    // One pass: the joint motion's momentum and the whole robot's inertia, both about the base origin
    // in base axes (placements relative to the base; exact when the base is at the identity).
    let (mut h, mut ic) = (Force::ZERO, Inertia::zero());
    for i in 0..m.nbodies() {
        let b_mi = base.inv_compose(&d.o_mi[i]);
        h += b_mi.act_force(&m.inertias[i].mul_motion(&d.v[i]));
        ic = ic.add(&m.inertias[i].transformed(&b_mi));
    }
    let target = base.inv_act_force(&Force::new(
        V3::new(momentum[0], momentum[1], momentum[2]),
        V3::new(momentum[3], momentum[4], momentum[5]),
    ));
    let rhs = Vector6::new(
        target.lin.x - h.lin.x,
        target.lin.y - h.lin.y,
        target.lin.z - h.lin.z,
        target.ang.x - h.ang.x,
        target.ang.y - h.ang.y,
        target.ang.z - h.ang.z,
    );
    let singular = || FfError::Numerical("the composite inertia of the robot is not positive definite".into());
    match m.joint_types[0] {
        JointType::Free => ic.to_matrix().cholesky().map(|c| c.solve(&rhs)).ok_or_else(singular),
        JointType::Planar => {
            let s: Matrix6x3<f64> = m.subspaces[0].fixed_columns::<3>(0).into_owned();
            let x: Vector3<f64> = (s.transpose() * ic.to_matrix() * s)
                .cholesky()
                .map(|c| c.solve(&(s.transpose() * rhs)))
                .ok_or_else(singular)?;
            Ok(s * x)
        }
        other => Err(FfError::arg("model", format!("a base of type '{}' has no twist to solve for", other.name()))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{centroidal_momentum_matrix, momentum};
    use crate::model::builtin::load as builtin;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    fn random_state(m: &Model, seed: &mut u64) -> (Vec<f64>, Vec<f64>) {
        let mut q = vec![0.0; m.nq];
        for i in 0..m.nbodies() {
            let s = m.idx_q[i];
            m.joint_types[i].neutral(&mut q[s..s + m.nqs[i]]);
        }
        for x in q.iter_mut() {
            *x += 0.5 * lcg(seed);
        }
        for i in 0..m.nbodies() {
            let s = m.idx_q[i];
            m.joint_types[i].normalize(&mut q[s..s + m.nqs[i]]);
        }
        let rates = (0..m.nv - m.nvs[0]).map(|_| lcg(seed)).collect();
        (q, rates)
    }

    /// Conservation check: the state with the computed base velocity has the requested momentum.
    #[test]
    fn momentum_of_the_solved_state_is_the_requested_one() {
        let mut seed = 7u64;
        for name in ["naveen_dual_arm", "zhang2020_3d", "zhang2020_2d_medium", "valverde_ch7_two_arm"] {
            let m = builtin(name).unwrap();
            let mut d = Data::new(&m);
            let nb = m.nvs[0];
            for trial in 0..5 {
                let (q, rates) = random_state(&m, &mut seed);
                let h0: [f64; 6] = if trial == 0 { [0.0; 6] } else { std::array::from_fn(|_| 10.0 * lcg(&mut seed)) };
                let tw = base_twist_for_momentum(&m, &mut d, &q, &rates, &h0).unwrap();
                let mut v = vec![0.0; m.nv];
                base_velocity_coordinates(&m, &tw, &mut v[..nb]).unwrap();
                v[nb..].copy_from_slice(&rates);
                let h = momentum(&m, &mut d, &q, &v).unwrap().to_v6();
                let rows: &[usize] = if nb == 3 { &[0, 1, 5] } else { &[0, 1, 2, 3, 4, 5] };
                let scale = 1.0 + h0.iter().map(|x| x.abs()).fold(0.0, f64::max) + h.abs().max();
                for &r in rows {
                    assert!((h[r] - h0[r]).abs() < 1e-11 * scale, "{name} row {r}: {} vs {}", h[r], h0[r]);
                }
            }
        }
    }

    /// Independent oracle: the old inertial-frame formula A_b v_b = h − A_m q̇_m with the centroidal
    /// momentum matrix and an LU solve (what `generalized_jacobian` and Python's simulation did).
    #[test]
    fn matches_the_centroidal_momentum_matrix_solve() {
        let mut seed = 11u64;
        let m = builtin("naveen_dual_arm").unwrap();
        let mut d = Data::new(&m);
        for _ in 0..10 {
            let (q, rates) = random_state(&m, &mut seed);
            let h0: [f64; 6] = std::array::from_fn(|_| lcg(&mut seed));
            let tw = base_twist_for_momentum(&m, &mut d, &q, &rates, &h0).unwrap();
            centroidal_momentum_matrix(&m, &mut d, &q).unwrap();
            let a = d.jac.clone();
            let ab = a.columns(0, 6).into_owned();
            let am = a.columns(6, m.nv - 6).into_owned();
            let rhs = nalgebra::DVector::from_row_slice(&h0) - am * nalgebra::DVector::from_row_slice(&rates);
            let x = ab.lu().solve(&rhs).unwrap();
            for r in 0..6 {
                assert!((x[r] - tw[r]).abs() < 1e-11 * (1.0 + x.amax()), "row {r}: {} vs {}", x[r], tw[r]);
            }
        }
    }

    #[test]
    fn bad_arguments_are_errors() {
        let m = builtin("naveen_dual_arm").unwrap();
        let mut d = Data::new(&m);
        let (q, rates) = random_state(&m, &mut 3u64);
        assert!(base_twist_for_momentum(&m, &mut d, &q[1..], &rates, &[0.0; 6]).is_err());
        assert!(base_twist_for_momentum(&m, &mut d, &q, &rates[1..], &[0.0; 6]).is_err());
        assert!(base_twist_for_momentum(&m, &mut d, &q, &rates, &[f64::NAN; 6]).is_err());
        let mut q2 = q.clone();
        q2[3] += 0.5;
        assert!(base_twist_for_momentum(&m, &mut d, &q2, &rates, &[0.0; 6]).is_err());
        let mut out = [0.0; 5];
        assert!(base_velocity_coordinates(&m, &Vector6::zeros(), &mut out).is_err());
    }
}
