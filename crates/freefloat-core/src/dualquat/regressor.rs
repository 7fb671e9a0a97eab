//! The dual-inertia regressor: the rigid-body Newton–Euler equations written linear in the seven inertial
//! parameters `v(M) = [I11, I12, I13, I22, I23, I33, m]` (Valverde 2018, §4.1 and §9.1). Chapter 4's adaptive
//! pose tracker and chapter 9's concurrent-learning mass estimator both stand on these four functions.
//!
//! `M ⋆ b` of a vector dual quaternion `b = (0, b̄_r) + ε(0, b̄_d)` is `m b̄_r + ε Ī b̄_d` (the layout (2.45); the
//! two scalar-slot ones of M only make it invertible and carry no parameter, so `b` must be a vector).

use super::dual_quaternion::DualQuat;
use super::inertia::DualInertia;
use super::quaternion::Quat;
use nalgebra::{SMatrix, SVector};

/// An 8×7 regressor: dual-quaternion rows `[real (w,x,y,z), dual (w,x,y,z)]`, parameter columns in the order of
/// `v(M)`.
pub type M87 = SMatrix<f64, 8, 7>;
/// Seven inertial parameters `[I11, I12, I13, I22, I23, I33, m]` (kg m², kg).
pub type V7 = SVector<f64, 7>;

/// `v(M) = [I11, I12, I13, I22, I23, I33, m]` of a dual inertia (Valverde 2018, §4.1; the order of ch. 4 and 9).
pub fn params(m: &DualInertia) -> V7 {
    let i = m.i_com();
    V7::from_column_slice(&[i[(0, 0)], i[(0, 1)], i[(0, 2)], i[(1, 1)], i[(1, 2)], i[(2, 2)], m.mass()])
}

/// `M(v) ⋆ b` for any parameter vector `v` (an estimate need not be a realisable body, so nothing is checked);
/// the scalar parts of `b` pass through as the ones of (2.45) would pass them.
pub fn apply_params(v: &V7, b: &DualQuat) -> DualQuat {
    let (x, y, z) = (b.d.v[0], b.d.v[1], b.d.v[2]);
    let iw = nalgebra::Vector3::new(
        v[0] * x + v[1] * y + v[2] * z,
        v[1] * x + v[3] * y + v[4] * z,
        v[2] * x + v[4] * y + v[5] * z,
    );
    DualQuat { r: Quat { w: b.r.w, v: b.r.v * v[6] }, d: Quat { w: b.d.w, v: iw } }
}

/// `r(b)`, eq. (4.2) (lost in the thesis' transcription; defined by `r(b) v(M) = M ⋆ b` for every vector dual
/// quaternion `b`). Rows 1 and 5 are zero: one sample gives rank 6 at most.
pub fn r_matrix(b: &DualQuat) -> M87 {
    let mut r = M87::zeros();
    // real part: m b̄_r (column 7)
    for k in 0..3 {
        r[(1 + k, 6)] = b.r.v[k];
    }
    // dual part: Ī b̄_d with Ī symmetric, columns I11 I12 I13 I22 I23 I33
    let (b6, b7, b8) = (b.d.v[0], b.d.v[1], b.d.v[2]);
    r[(5, 0)] = b6;
    r[(5, 1)] = b7;
    r[(5, 2)] = b8;
    r[(6, 1)] = b6;
    r[(6, 3)] = b7;
    r[(6, 4)] = b8;
    r[(7, 2)] = b6;
    r[(7, 4)] = b7;
    r[(7, 5)] = b8;
    r
}

/// `h(a, b)`, §4.2 (used by the update laws (4.13), (4.26)): `a ∘ (M ⋆ b) = h(a, b)ᵀ v(M)` for vector dual
/// quaternions `a`, `b` (∘ the circle product: the 8-vector dot product).
pub fn h_vector(a: &DualQuat, b: &DualQuat) -> V7 {
    let (a2, a3, a4) = (a.r.v[0], a.r.v[1], a.r.v[2]);
    let (a6, a7, a8) = (a.d.v[0], a.d.v[1], a.d.v[2]);
    let (b2, b3, b4) = (b.r.v[0], b.r.v[1], b.r.v[2]);
    let (b6, b7, b8) = (b.d.v[0], b.d.v[1], b.d.v[2]);
    V7::from_column_slice(&[
        a6 * b6,
        a7 * b6 + a6 * b7,
        a8 * b6 + a6 * b8,
        a7 * b7,
        a8 * b7 + a7 * b8,
        a8 * b8,
        a2 * b2 + a3 * b3 + a4 * b4,
    ])
}

/// `R̂(ω̇, ω)`, eq. (9.7): `r((ω̇)^s) + [ω]^× r(ω^s)`, so that `R̂ v(M) = M ⋆ (ω̇)^s + ω × (M ⋆ ω^s)`, the left-hand
/// side of the Newton–Euler equation (2.56) (eq. (9.4)). `twist` is the body's absolute twist `ω + ε v` about its
/// centre of mass in body axes, `twist_dot` its body-frame component rate.
pub fn body_regressor(twist: &DualQuat, twist_dot: &DualQuat) -> M87 {
    r_matrix(&twist_dot.swap()) + twist.skew_matrix() * r_matrix(&twist.swap())
}

/// `R(ω̇_B/D, ω_B/D, ω̇_D/I, ω_D/I, q_B/D)`, eq. (4.3) in its five-argument form ((4.22), (4.44)):
/// `R v(M) = f^B`, the dual force about the CoM in B axes that produces the relative motion. `w_bd`, `w_bd_dot` are
/// the twist of B relative to the desired frame D and its rate, in B axes; `w_di`, `w_di_dot` the desired frame's
/// twist and rate in D axes; `q_bd` the unit pose of B relative to D.
///
/// The grouped form of (4.3): with `ω_D/I^B = q* ω_D/I^D q` and `ω_B/I = ω_B/D + ω_D/I^B`,
/// `R = r((ω̇_B/D + q* ω̇_D/I^D q + ω_D/I^B × ω_B/D)^s) + [ω_B/I]^× r((ω_B/I)^s)`, which is `R̂` of the absolute
/// motion (`ω̇_B/I = ω̇_B/D + q* ω̇_D/I q + ω_D/I^B × ω_B/D` in B axes).
pub fn relative_regressor(
    w_bd_dot: &DualQuat,
    w_bd: &DualQuat,
    w_di_dot: &DualQuat,
    w_di: &DualQuat,
    q_bd: &DualQuat,
) -> M87 {
    let w_di_b = q_bd.conj().mul(w_di).mul(q_bd);
    let w_bi = *w_bd + w_di_b;
    let w_bi_dot = *w_bd_dot + q_bd.conj().mul(w_di_dot).mul(q_bd) + w_di_b.cross(w_bd);
    body_regressor(&w_bi, &w_bi_dot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dualquat::pose;
    use crate::spatial::{M3, V3};

    fn rnd(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed % 20001) as f64 / 10000.0 - 1.0
    }
    fn vec_dq(s: &mut u64) -> DualQuat {
        DualQuat::vector(&V3::new(rnd(s), rnd(s), rnd(s)), &V3::new(rnd(s), rnd(s), rnd(s)))
    }
    fn body(s: &mut u64) -> DualInertia {
        let a = M3::from_fn(|_, _| rnd(s));
        DualInertia::new(2.0 + rnd(s), a * a.transpose() + M3::identity()).unwrap()
    }
    fn close(a: &DualQuat, b: &DualQuat) -> f64 {
        (a.to_vec8() - b.to_vec8()).amax() / b.to_vec8().amax().max(1.0)
    }

    #[test]
    fn r_of_b_times_params_is_m_star_b() {
        let mut s = 0x1234_5678_9abc_def1;
        for _ in 0..50 {
            let (m, b) = (body(&mut s), vec_dq(&mut s));
            let lhs = DualQuat::from_vec8(&(r_matrix(&b) * params(&m)));
            assert!(close(&lhs, &m.apply(&b)) < 1e-15);
            assert!(close(&apply_params(&params(&m), &b), &m.apply(&b)) < 1e-15);
        }
    }

    #[test]
    fn h_is_the_circle_product_of_a_with_m_star_b() {
        let mut s = 0xdead_beef_1234_5678;
        for _ in 0..50 {
            let (m, a, b) = (body(&mut s), vec_dq(&mut s), vec_dq(&mut s));
            let lhs = h_vector(&a, &b).dot(&params(&m));
            let rhs = a.circle_scalar(&m.apply(&b));
            assert!((lhs - rhs).abs() < 1e-14 * rhs.abs().max(1.0), "{lhs} vs {rhs}");
        }
    }

    #[test]
    fn body_regressor_reproduces_the_newton_euler_wrench() {
        let mut s = 0x0f0f_1234_8888_0001;
        for _ in 0..50 {
            let (m, w, wd) = (body(&mut s), vec_dq(&mut s), vec_dq(&mut s));
            let f = DualQuat::from_vec8(&(body_regressor(&w, &wd) * params(&m)));
            // residual M ⋆ ω̇^s + ω × (M ⋆ ω^s) − f = 0, formed by the dual-inertia code (2.56)
            assert!(m.newton_euler_residual(&w, &wd, &f).to_vec8().amax() < 1e-14);
        }
    }

    #[test]
    fn relative_regressor_equals_the_absolute_one_of_the_same_motion() {
        // B's absolute twist from the relative one: ω_B/I = ω_B/D + q* ω_D/I q. Differentiate numerically along
        // a relative motion to check the rate formula (4.3) relies on, independently of its algebra.
        let mut s = 0x5555_aaaa_1111_2222;
        let m = body(&mut s);
        let (w_bd0, w_bd_dot) = (vec_dq(&mut s), vec_dq(&mut s));
        let (w_di0, w_di_dot) = (vec_dq(&mut s), vec_dq(&mut s));
        let q0 = pose::from_rotation_translation(
            &Quat::from_axis_angle(&V3::new(0.3, -0.5, 0.8).normalize(), 1.1),
            &V3::new(0.3, -1.0, 2.0),
        );
        // ω_B/I(t) = q(t)* ω_D/I(t) q(t) + ω_B/D(t) with q̇ = ½ q ω_B/D (B axes) and the twists' rates given; a
        // central difference only needs every factor to first order in t (the even terms cancel).
        let at = |t: f64| {
            let w_bd = w_bd0 + w_bd_dot.scale(t);
            let w_di = w_di0 + w_di_dot.scale(t);
            let q = q0.mul(&(DualQuat::ONE + w_bd0.scale(0.5 * t)));
            q.conj().mul(&w_di).mul(&q) + w_bd
        };
        let h = 1e-5;
        let w_bi_dot_fd = (at(h) - at(-h)).scale(0.5 / h);
        let w_bi = at(0.0);
        let r_abs = body_regressor(&w_bi, &w_bi_dot_fd);
        let r_rel = relative_regressor(&w_bd_dot, &w_bd0, &w_di_dot, &w_di0, &q0);
        let diff = (r_abs - r_rel).amax() / r_rel.amax();
        assert!(diff < 1e-8, "relative vs absolute regressor differ by {diff}");
        let f = DualQuat::from_vec8(&(r_rel * params(&m)));
        assert!(m.newton_euler_residual(&w_bi, &w_bi_dot_fd, &f).to_vec8().amax() < 1e-7);
    }
}
