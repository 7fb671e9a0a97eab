//! The free-flyer retraction on SE(3) (its exp/log and Jacobians are the engine's, `spatial::lie`, re-exported
//! here) (Pinocchio's convention for a free joint:
//! `q ⊕ δ = M exp6(δ)` with δ a body-frame twist, `q₁ ⊖ q₀ = log6(M₀⁻¹ M₁)`), so that a DDP linearised
//! here is the same problem Crocoddyl solves. Formulas: Barfoot, *State Estimation for Robotics* (2017),
//! §7.1.3–7.1.5 (SE(3) Jacobians and the Q(ρ, φ) block), and Sola et al., *A micro Lie theory* (2018).

pub use crate::spatial::lie::{exp6, log6, se3_right_jacobian_inv, so3_left_jacobian, so3_left_jacobian_inv};
use crate::spatial::{quat_exp, quat_mul, quat_normalize, rot_from_quat, Se3, V3, V6};

/// Placement of a free-flyer configuration `[p (3), quat xyzw (4)]`.
pub fn ff_placement(q: &[f64]) -> Se3 {
    Se3::new(rot_from_quat(&q[3..7]), V3::new(q[0], q[1], q[2]))
}

/// Free-flyer retraction: `out = q ⊕ δ` = placement `M(q) exp6(δ)` (δ: body-frame twist × time).
pub fn ff_integrate(q: &[f64], delta: &[f64], out: &mut [f64]) {
    let xi = V6::from_column_slice(&delta[..6]);
    let e = exp6(&xi);
    let r = rot_from_quat(&q[3..7]);
    let p = V3::new(q[0], q[1], q[2]) + r * e.trans;
    let qa = [q[3], q[4], q[5], q[6]];
    let mut qn = quat_mul(&qa, &quat_exp(&V3::new(xi[3], xi[4], xi[5])));
    quat_normalize(&mut qn);
    out[..3].copy_from_slice(p.as_slice());
    out[3..7].copy_from_slice(&qn);
}

/// Free-flyer difference: `out = q1 ⊖ q0 = log6(M(q0)⁻¹ M(q1))`.
pub fn ff_difference(q0: &[f64], q1: &[f64], out: &mut [f64]) {
    let m = ff_placement(q0).inv_compose(&ff_placement(q1));
    out[..6].copy_from_slice(log6(&m).as_slice());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_flyer_difference_inverts_integrate() {
        let q0 = {
            let mut q = [0.1, -0.2, 0.3, 0.2, -0.1, 0.4, 0.9];
            quat_normalize(&mut q[3..7]);
            q
        };
        let d = [0.4, -0.3, 0.8, 0.5, -0.6, 0.2];
        let mut q1 = [0.0; 7];
        ff_integrate(&q0, &d, &mut q1);
        let mut back = [0.0; 6];
        ff_difference(&q0, &q1, &mut back);
        for i in 0..6 {
            assert!((back[i] - d[i]).abs() < 1e-12);
        }
    }
}
