//! SE(3) exponential and logarithm in `[linear; angular]` order, the SO(3) left Jacobian and its inverse, and
//! the inverse right Jacobian of SE(3) (Pinocchio's `Jlog6`). One copy for the engine: the DDP pose costs and
//! free-flyer retraction and the frame-pose derivatives both use these. Formulas: Barfoot, *State Estimation for
//! Robotics* (2017), §7.1.3–7.1.5 (SE(3) Jacobians and the Q(ρ, φ) block), and Sola et al., *A micro Lie theory*
//! (2018).

use super::{quat_exp, rot_from_quat, skew, so3_log, Se3, M3, M6, V3, V6};

/// Left Jacobian of SO(3), `Jl(φ) = I + (1 − cos θ)/θ² [φ]× + (θ − sin θ)/θ³ [φ]ײ`.
pub fn so3_left_jacobian(phi: &V3) -> M3 {
    let th2 = phi.norm_squared();
    let th = th2.sqrt();
    let (a, b) = if th < 1e-4 {
        (0.5 - th2 / 24.0, 1.0 / 6.0 - th2 / 120.0)
    } else {
        ((1.0 - th.cos()) / th2, (th - th.sin()) / (th2 * th))
    };
    let k = skew(phi);
    M3::identity() + k * a + k * k * b
}

/// Inverse of the left Jacobian of SO(3), `Jl⁻¹(φ) = I − ½[φ]× + (1/θ² − (1 + cos θ)/(2θ sin θ)) [φ]ײ`.
pub fn so3_left_jacobian_inv(phi: &V3) -> M3 {
    let th2 = phi.norm_squared();
    let th = th2.sqrt();
    let c = if th < 1e-4 { 1.0 / 12.0 + th2 / 720.0 } else { 1.0 / th2 - (1.0 + th.cos()) / (2.0 * th * th.sin()) };
    let k = skew(phi);
    M3::identity() - k * 0.5 + k * k * c
}

/// `exp6(ξ)` for `ξ = [ρ; φ]`: rotation `exp(φ)`, translation `Jl(φ) ρ`.
pub fn exp6(xi: &V6) -> Se3 {
    let rho = V3::new(xi[0], xi[1], xi[2]);
    let phi = V3::new(xi[3], xi[4], xi[5]);
    let q = quat_exp(&phi);
    Se3::new(rot_from_quat(&q), so3_left_jacobian(&phi) * rho)
}

/// `log6(M) = [Jl(φ)⁻¹ p; φ]` with `φ = log3(R)`.
pub fn log6(m: &Se3) -> V6 {
    let phi = so3_log(&m.rot);
    let rho = so3_left_jacobian_inv(&phi) * m.trans;
    V6::new(rho.x, rho.y, rho.z, phi.x, phi.y, phi.z)
}

/// Barfoot's `Q(ρ, φ)`, the off-diagonal block of the left Jacobian of SE(3) (eq. 7.86b there).
pub(crate) fn q_block(rho: &V3, phi: &V3) -> M3 {
    let th2 = phi.norm_squared();
    let th = th2.sqrt();
    let (c1, c2, c3) = if th < 1e-3 {
        (1.0 / 6.0 - th2 / 120.0, 1.0 / 24.0 - th2 / 720.0, 1.0 / 120.0 - th2 / 2520.0)
    } else {
        let (s, c) = th.sin_cos();
        (
            (th - s) / (th2 * th),
            (th2 + 2.0 * c - 2.0) / (2.0 * th2 * th2),
            (2.0 * th - 3.0 * s + th * c) / (2.0 * th2 * th2 * th),
        )
    };
    let (p, r) = (skew(phi), skew(rho));
    let pr = p * r;
    let rp = r * p;
    let prp = pr * p;
    r * 0.5 + (pr + rp + prp) * c1 + (p * pr + rp * p - prp * 3.0) * c2 + (prp * p + p * prp) * c3
}

/// Inverse right Jacobian of SE(3) at `ξ` (Pinocchio's `Jlog6(exp6(ξ))`): if `M(δ) = exp6(ξ) exp6(δ)` then
/// `log6(M(δ)) = ξ + Jr⁻¹(ξ) δ + O(δ²)`. With `Jr(ξ) = Jl(−ξ) = [[A, Q(−ρ,−φ)]; [0, A]]`, `A = Jl(−φ)`:
/// `Jr⁻¹ = [[A⁻¹, −A⁻¹ Q A⁻¹]; [0, A⁻¹]]`.
pub fn se3_right_jacobian_inv(xi: &V6) -> M6 {
    let rho = V3::new(xi[0], xi[1], xi[2]);
    let phi = V3::new(xi[3], xi[4], xi[5]);
    let ainv = so3_left_jacobian_inv(&(-phi));
    let q = q_block(&(-rho), &(-phi));
    let mut out = M6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&ainv);
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&ainv);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-(ainv * q * ainv)));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xi(s: f64) -> V6 {
        V6::new(0.3 * s, -0.7 * s, 0.2 * s, 0.9 * s, -0.4 * s, 1.1 * s)
    }

    #[test]
    fn exp_and_log_are_inverse() {
        for s in [1e-7, 1e-3, 0.5, 1.0, 2.0] {
            let x = xi(s);
            let back = log6(&exp6(&x));
            assert!((back - x).amax() < 1e-12, "s = {s}: {back:?}");
        }
    }

    #[test]
    fn right_jacobian_inverse_matches_central_differences() {
        for s in [1e-5, 0.3, 1.0, 1.8] {
            let x = xi(s);
            let m = exp6(&x);
            let jac = se3_right_jacobian_inv(&x);
            let h = 1e-6;
            for c in 0..6 {
                let mut d = V6::zeros();
                d[c] = h;
                let p = log6(&m.compose(&exp6(&d)));
                d[c] = -h;
                let mm = log6(&m.compose(&exp6(&d)));
                let col = (p - mm) / (2.0 * h);
                let err = (col - jac.column(c)).amax();
                assert!(err < 1e-8, "s = {s}, column {c}: {err}");
            }
        }
    }
}
