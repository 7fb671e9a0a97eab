//! The engine's one copy of the Lie-group functions of SO(3) and SE(3): exponential and logarithm (quaternion
//! and matrix forms), the left and right Jacobians of SO(3) and their inverses, the derivative of the inverse
//! right Jacobian, SE(3)'s `exp6`/`log6` in `[linear; angular]` order with its inverse right Jacobian (Pinocchio's
//! `Jlog6`), and the free-flyer retraction on SE(3) that DDP linearises in. Every other module calls these: the
//! configuration-space `⊕`/`⊖` and their Jacobians (`config`), the integrators (`sim`), the step and frame
//! derivatives (`dynamics::derivatives`) and DDP (`control::ddp`).
//!
//! Formulas: Barfoot, *State Estimation for Robotics* (2017), §7.1.3–7.1.5 (SO(3)/SE(3) Jacobians, the Q(ρ, φ)
//! block, eq. 7.86b), and Sola, Deray, Atchuthan, *A micro Lie theory for state estimation in robotics* (2018),
//! eqs. (143)–(146) (SO(3) right/left Jacobians and inverses) and App. D (SE(3)).
//!
//! # One small-angle treatment
//! Each function of the angle θ that these formulas need is an even function of θ, written in closed form with
//! removable singularities at θ = 0: `(1 − cos θ)/θ²`, `(θ − sin θ)/θ³`, `1/θ² − cot(θ/2)/(2θ)`, … Their closed
//! forms lose digits by cancellation as θ → 0 (a relative error of about `ε/θ²`, `ε/θ⁴` for the derivatives), so
//! for `θ² < SMALL_ANGLE_SQ` (θ < ½) every one is evaluated by its Taylor series in θ², with enough terms that the
//! first omitted one is below 2⁻⁵⁷ of the value at the cutoff (7 to 9 terms, Horner's rule). So both sides of the
//! one cutoff are accurate to round-off: the series by construction, the closed forms because at θ ≥ ½ their
//! cancellation costs at most a few bits. The test `sweep_matches_power_series` compares every function with an
//! independent evaluation (matrix power series, inverted numerically) from θ = 1e-9 to π − 1e-3.
//! The logarithm needs no series: `2 atan2(s, w)/s` has no cancellation; only s = 0 is guarded.

use super::{rot_from_quat, skew, Se3, M3, M6, V3, V6};

/// Below this θ² every angle function is evaluated by its Taylor series (module documentation).
pub const SMALL_ANGLE_SQ: f64 = 0.25;

// Taylor coefficients in θ² (general term in each comment; generated exactly, then rounded to f64).
/// `sin(θ/2)/θ = Σ (−1)ⁿ θ²ⁿ / (2²ⁿ⁺¹ (2n+1)!)`.
const HALF_SINC: [f64; 7] = [
    0.5,
    -0.020833333333333332,
    0.00026041666666666666,
    -1.5500992063492063e-06,
    5.382288910934745e-09,
    -1.2232474797578965e-11,
    1.9603324996120133e-14,
];
/// `cos(θ/2) = Σ (−1)ⁿ θ²ⁿ / (2²ⁿ (2n)!)`.
const HALF_COS: [f64; 7] = [
    1.0,
    -0.125,
    0.0026041666666666665,
    -2.170138888888889e-05,
    9.68812003968254e-08,
    -2.691144455467372e-10,
    5.096864498991235e-13,
];
/// `(1 − cos θ)/θ² = Σ (−1)ⁿ θ²ⁿ / (2n+2)!`.
const ONE_MINUS_COS: [f64; 7] = [
    0.5,
    -0.041666666666666664,
    0.001388888888888889,
    -2.48015873015873e-05,
    2.755731922398589e-07,
    -2.08767569878681e-09,
    1.1470745597729725e-11,
];
/// `(θ − sin θ)/θ³ = Σ (−1)ⁿ θ²ⁿ / (2n+3)!`.
const THETA_MINUS_SIN: [f64; 7] = [
    0.16666666666666666,
    -0.008333333333333333,
    0.0001984126984126984,
    -2.7557319223985893e-06,
    2.505210838544172e-08,
    -1.6059043836821613e-10,
    7.647163731819816e-13,
];
/// `D(θ) = 1/θ² − cot(θ/2)/(2θ) = Σ (−1)ⁿ B₂ₙ₊₂ θ²ⁿ / (2n+2)!` (B: Bernoulli numbers; from the Laurent series of cot).
const JINV: [f64; 8] = [
    0.08333333333333333,
    0.001388888888888889,
    3.306878306878307e-05,
    8.267195767195768e-07,
    2.08767569878681e-08,
    5.284190138687493e-10,
    1.3382536530684679e-11,
    3.3896802963225827e-13,
];
/// `D'(θ)/θ`, the series of `JINV` differentiated term by term and divided by θ.
const JINV_DERIV: [f64; 9] = [
    0.002777777777777778,
    0.00013227513227513228,
    4.96031746031746e-06,
    1.670140559029448e-07,
    5.2841901386874934e-09,
    1.6059043836821613e-10,
    4.745552414851616e-12,
    1.3737699290044552e-13,
    3.914763657404511e-15,
];
/// `(θ² + 2 cos θ − 2)/(2θ⁴) = Σ (−1)ⁿ θ²ⁿ / (2n+4)!`.
const Q_C2: [f64; 7] = [
    0.041666666666666664,
    -0.001388888888888889,
    2.48015873015873e-05,
    -2.755731922398589e-07,
    2.08767569878681e-09,
    -1.1470745597729725e-11,
    4.779477332387385e-14,
];
/// `(2θ − 3 sin θ + θ cos θ)/(2θ⁵) = Σ (−1)ⁿ (n+1) θ²ⁿ / (2n+5)!`.
const Q_C3: [f64; 7] = [
    0.008333333333333333,
    -0.0003968253968253968,
    8.267195767195768e-06,
    -1.0020843354176688e-07,
    8.029521918410807e-10,
    -4.58829823909189e-12,
    1.9680200780418645e-14,
];

/// `Σ c[k] t2ᵏ` by Horner's rule.
#[inline(always)]
fn series(t2: f64, c: &[f64]) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ck| acc * t2 + ck)
}

#[inline(always)]
fn small(t2: f64) -> bool {
    t2 < SMALL_ANGLE_SQ
}

/// `(1 − cos θ)/θ²` and `(θ − sin θ)/θ³` from θ²: the coefficients of the SO(3) Jacobians (and of `exp6`).
#[inline]
fn jacobian_coeffs(t2: f64) -> (f64, f64) {
    if small(t2) {
        (series(t2, &ONE_MINUS_COS), series(t2, &THETA_MINUS_SIN))
    } else {
        let t = t2.sqrt();
        let (s, c) = t.sin_cos();
        ((1.0 - c) / t2, (t - s) / (t2 * t))
    }
}

/// `D(θ) = 1/θ² − cot(θ/2)/(2θ)`, the coefficient of `[θ]²` in `Jr⁻¹`, and `D'(θ)/θ`.
#[inline]
fn jinv_coeffs(t2: f64) -> (f64, f64) {
    if small(t2) {
        (series(t2, &JINV), series(t2, &JINV_DERIV))
    } else {
        let t = t2.sqrt();
        let (s, c) = (0.5 * t).sin_cos();
        let cot = c / s;
        let d = 1.0 / t2 - cot / (2.0 * t);
        // D'(θ) = −2/θ³ + csc²(θ/2)/(4θ) + cot(θ/2)/(2θ²)
        let dd = -2.0 / (t2 * t) + 1.0 / (4.0 * t * s * s) + cot / (2.0 * t2);
        (d, dd / t)
    }
}

/// `D(θ)` alone (the integrators' hot path needs no derivative).
#[inline]
fn jinv_coeff(t2: f64) -> f64 {
    if small(t2) {
        series(t2, &JINV)
    } else {
        let t = t2.sqrt();
        let (s, c) = (0.5 * t).sin_cos();
        1.0 / t2 - c / (2.0 * t * s)
    }
}

// ---------------------------------------------------------------- SO(3)

/// Quaternion (x, y, z, w) of the rotation vector `phi` (axis × angle): `exp(phi/2)` in quaternion form.
#[inline]
pub fn quat_exp(phi: &V3) -> [f64; 4] {
    let t2 = phi.norm_squared();
    let (k, w) = if small(t2) {
        (series(t2, &HALF_SINC), series(t2, &HALF_COS))
    } else {
        let t = t2.sqrt();
        let (s, c) = (0.5 * t).sin_cos();
        (s / t, c)
    };
    [k * phi.x, k * phi.y, k * phi.z, w]
}

/// Rotation vector of a unit quaternion (x, y, z, w), angle in [0, π] (the sign of q is chosen so that w ≥ 0).
#[inline]
pub fn quat_log(q: &[f64; 4]) -> V3 {
    let sign = if q[3] < 0.0 { -1.0 } else { 1.0 };
    let v = V3::new(q[0], q[1], q[2]) * sign;
    let w = q[3] * sign;
    let s = v.norm();
    // θ/s with θ = 2 atan2(s, w): no cancellation at any angle, only 0/0 at s = 0, where the limit is 2/w
    // (the next term, −2s²/(3w³), is below 1e-24 for s < 1e-12).
    let k = if s < 1e-12 { 2.0 / w } else { 2.0 * s.atan2(w) / s };
    v * k
}

/// Rotation matrix `Exp(φ)` (via the quaternion: the same bits as `rot_from_quat(&quat_exp(φ))`).
#[inline]
pub fn so3_exp(phi: &V3) -> M3 {
    rot_from_quat(&quat_exp(phi))
}

/// Rotation vector of a rotation matrix (inverse of the exponential), angle in [0, π].
pub fn so3_log(r: &M3) -> V3 {
    quat_log(&super::quat_from_rot(r))
}

/// Right Jacobian of SO(3): `Exp(φ + η) ≈ Exp(φ) Exp(Jr(φ) η)`;
/// `Jr = I − (1 − cos θ)/θ² [φ] + (θ − sin θ)/θ³ [φ]²` (Sola et al. 2018, eq. 143).
#[inline]
pub fn so3_right_jacobian(phi: &V3) -> M3 {
    let (a, b) = jacobian_coeffs(phi.norm_squared());
    let k = skew(phi);
    M3::identity() - k * a + k * k * b
}

/// Left Jacobian of SO(3), `Jl(φ) = Jr(−φ) = I + (1 − cos θ)/θ² [φ] + (θ − sin θ)/θ³ [φ]²` (Sola et al. eq. 145).
#[inline]
pub fn so3_left_jacobian(phi: &V3) -> M3 {
    let (a, b) = jacobian_coeffs(phi.norm_squared());
    let k = skew(phi);
    M3::identity() + k * a + k * k * b
}

/// Inverse right Jacobian `Jr(φ)⁻¹ = I + ½[φ] + D(θ)[φ]²`, `D = 1/θ² − (1 + cos θ)/(2θ sin θ)` (Sola et al. eq. 144).
#[inline]
pub fn so3_right_jacobian_inv_matrix(phi: &V3) -> M3 {
    let d = jinv_coeff(phi.norm_squared());
    let k = skew(phi);
    M3::identity() + k * 0.5 + k * k * d
}

/// Inverse left Jacobian `Jl(φ)⁻¹ = Jr(−φ)⁻¹ = I − ½[φ] + D(θ)[φ]²` (Sola et al. eq. 146).
#[inline]
pub fn so3_left_jacobian_inv(phi: &V3) -> M3 {
    let d = jinv_coeff(phi.norm_squared());
    let k = skew(phi);
    M3::identity() - k * 0.5 + k * k * d
}

/// `Jr(θ)⁻¹ w` without forming the matrix: if `R(t) = R0 Exp(θ(t))` and `R' = R [w]`, then `θ' = Jr(θ)⁻¹ w`.
/// This is the dexp⁻¹ correction that makes Runge-Kutta on the rotation group fourth order (Munthe-Kaas);
/// without it RK4 on the base attitude is only second order.
#[inline]
pub fn so3_right_jacobian_inv(theta: &V3, w: &V3) -> V3 {
    let d = jinv_coeff(theta.norm_squared());
    let tw = theta.cross(w);
    let ttw = theta.cross(&tw);
    w + tw * 0.5 + ttw * d
}

/// `∂/∂θ (Jr(θ)⁻¹ w)` (3×3): `−½[w] + D ((θ·w)I + θwᵀ − 2wθᵀ) + (θ×(θ×w)) (D'/θ) θᵀ`.
#[inline]
pub fn so3_right_jacobian_inv_dtheta(th: &V3, w: &V3) -> M3 {
    let (d, dd_t) = jinv_coeffs(th.norm_squared());
    let ttw = th.cross(&th.cross(w));
    -skew(w) * 0.5
        + (M3::identity() * th.dot(w) + th * w.transpose() - w * th.transpose() * 2.0) * d
        + ttw * th.transpose() * dd_t
}

// ---------------------------------------------------------------- SE(3)

/// `exp6(ξ)` for `ξ = [ρ; φ]`: rotation `Exp(φ)`, translation `Jl(φ) ρ`.
pub fn exp6(xi: &V6) -> Se3 {
    let rho = V3::new(xi[0], xi[1], xi[2]);
    let phi = V3::new(xi[3], xi[4], xi[5]);
    Se3::new(so3_exp(&phi), so3_left_jacobian(&phi) * rho)
}

/// `log6(M) = [Jl(φ)⁻¹ p; φ]` with `φ = log3(R)`.
pub fn log6(m: &Se3) -> V6 {
    let phi = so3_log(&m.rot);
    let rho = so3_left_jacobian_inv(&phi) * m.trans;
    V6::new(rho.x, rho.y, rho.z, phi.x, phi.y, phi.z)
}

/// Barfoot's `Q(ρ, φ)`, the off-diagonal block of the left Jacobian of SE(3) (eq. 7.86b there).
pub(crate) fn q_block(rho: &V3, phi: &V3) -> M3 {
    let t2 = phi.norm_squared();
    let (c1, c2, c3) = if small(t2) {
        (series(t2, &THETA_MINUS_SIN), series(t2, &Q_C2), series(t2, &Q_C3))
    } else {
        let th = t2.sqrt();
        let (s, c) = th.sin_cos();
        (
            (th - s) / (t2 * th),
            (t2 + 2.0 * c - 2.0) / (2.0 * t2 * t2),
            (2.0 * th - 3.0 * s + th * c) / (2.0 * t2 * t2 * th),
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

// ---------------------------------------------------------------- the free flyer on SE(3)

/// Placement of a free-flyer configuration `[p (3), quat xyzw (4)]`.
pub fn ff_placement(q: &[f64]) -> Se3 {
    Se3::new(rot_from_quat(&q[3..7]), V3::new(q[0], q[1], q[2]))
}

/// Free-flyer retraction on SE(3) (Pinocchio's convention for a free joint, the group Crocoddyl integrates on):
/// `out = q ⊕ δ`, the placement `M(q) exp6(δ)` (δ: body-frame twist × time). The configuration-space `⊕` of
/// `config` is the other retraction (on R³ × SO(3)); the two differ in the position part only.
pub fn ff_integrate(q: &[f64], delta: &[f64], out: &mut [f64]) {
    let xi = V6::from_column_slice(&delta[..6]);
    let e = exp6(&xi);
    let r = rot_from_quat(&q[3..7]);
    let p = V3::new(q[0], q[1], q[2]) + r * e.trans;
    let qa = [q[3], q[4], q[5], q[6]];
    let mut qn = super::quat_mul(&qa, &quat_exp(&V3::new(xi[3], xi[4], xi[5])));
    super::quat_normalize(&mut qn);
    out[..3].copy_from_slice(p.as_slice());
    out[3..7].copy_from_slice(&qn);
}

/// Free-flyer difference on SE(3): `out = q1 ⊖ q0 = log6(M(q0)⁻¹ M(q1))`.
pub fn ff_difference(q0: &[f64], q1: &[f64], out: &mut [f64]) {
    let m = ff_placement(q0).inv_compose(&ff_placement(q1));
    out[..6].copy_from_slice(log6(&m).as_slice());
}

#[cfg(test)]
mod tests;
