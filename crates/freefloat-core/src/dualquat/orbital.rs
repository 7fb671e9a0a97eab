//! External dual forces on an Earth-orbiting body (Valverde 2018, §2.3.3, (2.61)–(2.68)) and the relative pose
//! (error) dynamics (2.58). All wrenches are `f + ετ` about the body's CoM in body coordinates. Units are the
//! caller's: with `MU_EARTH` in km³/s², positions are in km.

use super::dual_quaternion::DualQuat;
use super::inertia::DualInertia;
use crate::spatial::{M3, V3};

/// Earth's gravitational parameter μ [km³/s²] (the thesis, after (2.62)).
pub const MU_EARTH: f64 = 398600.4418;
/// Earth's J2 coefficient and equatorial radius [km] (after (2.64)).
pub const J2_EARTH: f64 = 0.0010826267;
/// Earth's equatorial radius (km, WGS 84), for the J2 force.
pub const RE_EARTH: f64 = 6378.137;

/// (2.62)/(2.65): `f_g = M ⋆ (a_g + ε0) = m a_g + ε0`, `a_g = −μ r/‖r‖³`, r = r^B_{B/I} (body coordinates).
pub fn gravity(m: &DualInertia, r_b: &V3, mu: f64) -> DualQuat {
    let a = -r_b * (mu / r_b.norm().powi(3));
    m.apply(&DualQuat::vector(&a, &V3::zeros()))
}

/// Gravity gradient, the thesis' "new" form (2.67): `3μ/‖r‖⁵ (r̂)^s × (M ⋆ r̂)` with `r̂ = 0 + ε r`.
/// Equals `0 + ε 3μ r × (Ī r)/‖r‖⁵` (2.63).
pub fn gravity_gradient(m: &DualInertia, r_b: &V3, mu: f64) -> DualQuat {
    gravity_gradient_of(&m.i_com(), r_b, mu)
}

/// (2.67) from the inertia about the CoM alone: `M ⋆ r̂` with `r̂ = 0 + ε r` only reads the `Ī` block of `M`
/// (`M ⋆ r̂ = 0 + ε Ī r`), so the mass (and an invertible `Ī`, which `DualInertia` demands) is not needed. The
/// simulator uses this form for every body, including point masses and thin rods.
///
/// The dual cross product is formed with its zero parts dropped: `(r̂)^s = r + ε0` and `M ⋆ r̂ = 0 + ε Ī r`, so
/// `(r + ε0) × (0 + ε Ī r) = r × 0 + ε (r × Ī r + 0 × 0) = 0 + ε r × (Ī r)`: one cross product instead of the
/// general dual one (the simulator evaluates this for every body at every stage). `dualquat` tests check it
/// against the old form (2.68) and the CoM-frame closed form (2.63).
pub fn gravity_gradient_of(i_com: &M3, r_b: &V3, mu: f64) -> DualQuat {
    let r2 = r_b.norm_squared();
    let k = 3.0 * mu / (r2 * r2 * r2.sqrt());
    DualQuat::vector(&V3::zeros(), &gravity_gradient_torque(i_com, r_b, k))
}

/// The torque of (2.63) / (2.67) with its factor `k = 3μ/‖r‖⁵` given: `k r × (Ī r)`. The simulator forms k from
/// the `1/‖r‖` it already has for the tidal force of the same body (one square root and division per body).
#[inline]
pub fn gravity_gradient_torque(i_com: &M3, r_b: &V3, k: f64) -> V3 {
    r_b.cross(&(i_com * r_b)) * k
}

/// Differential point-mass gravity `g(R + r) − g(R)`, `g(x) = −μ x/‖x‖³` (2.62), for a point at `r` from a
/// reference point at `R` (both inertial axes): the tidal acceleration of a body relative to a free-falling
/// frame origin. Formed without the cancellation of the plain difference (which loses ‖R‖/‖r‖ ≈ 1e7 of the
/// ≈1e-5 m/s² result at low Earth orbit): with `d = R + r` and `x = (2R·r + r·r)/‖R‖²`,
/// `g(d) − g(R) = −μ/‖d‖³ [r − R x(3 + 3x + x²)/(1 + (1 + x)^{3/2})]`, since `1 − (1 + x)^{3/2} =
/// −x(3 + 3x + x²)/(1 + (1 + x)^{3/2})` (Battin 1999, §8.4, the same device as his f(q)).
pub fn tidal_acceleration(big_r: &V3, r: &V3, mu: f64) -> V3 {
    let inv_r2 = 1.0 / big_r.norm_squared();
    tidal_acceleration_inv(big_r, r, inv_r2, inv_r2.sqrt(), mu).0
}

/// [`tidal_acceleration`] with `1/‖R‖²` and `1/‖R‖` given (the simulator computes them once per evaluation for
/// all bodies), and `1/‖R + r‖` besides, which the body's gravity-gradient torque reuses. In three
/// steps, which the simulator runs as three loops over the bodies so that the square roots and divisions of all
/// bodies issue together instead of each stalling its body's chain (they were most of the environment's cost,
/// perf): [`tidal_x`], [`tidal_roots`], [`tidal_from_roots`].
#[inline]
pub fn tidal_acceleration_inv(big_r: &V3, r: &V3, inv_r2: f64, inv_r: f64, mu: f64) -> (V3, f64) {
    let x = tidal_x(big_r, r, inv_r2);
    tidal_from_roots(big_r, r, x, tidal_roots(x), inv_r, mu)
}

/// The series variable `x = (2R·r + r·r)/‖R‖²` of [`tidal_acceleration`]: `‖R + r‖² = ‖R‖² (1 + x)` exactly.
#[inline(always)]
pub fn tidal_x(big_r: &V3, r: &V3, inv_r2: f64) -> f64 {
    (2.0 * big_r.dot(r) + r.norm_squared()) * inv_r2
}

/// `(√(1 + x), 1/(√(1 + x) (1 + (1 + x)^{3/2})))`: the one square root and the one division of a body's tidal
/// acceleration and distance.
#[inline(always)]
pub fn tidal_roots(x: f64) -> (f64, f64) {
    let s1 = (1.0 + x).sqrt();
    (s1, 1.0 / (s1 * (1.0 + (1.0 + x) * s1)))
}

/// The tidal acceleration and `1/‖R + r‖` from x and its roots: `1/‖R + r‖ = (1/‖R‖)/√(1 + x)` and the series
/// factor `x(3 + 3x + x²)/(1 + (1 + x)^{3/2})`, both products of the one reciprocal.
#[inline(always)]
pub fn tidal_from_roots(big_r: &V3, r: &V3, x: f64, (s1, inv): (f64, f64), inv_r: f64, mu: f64) -> (V3, f64) {
    let b = 1.0 + (1.0 + x) * s1;
    let inv_d = inv_r * b * inv; // 1/(‖R‖ √(1 + x))
    let s = x * (3.0 + x * (3.0 + x)) * (s1 * inv); // x(3 + 3x + x²)/(1 + (1 + x)^{3/2})
    let mu_d3 = mu * inv_d * inv_d * inv_d;
    (-(r - big_r * s) * mu_d3, inv_d)
}

/// Gravity gradient, the "old" form of [50] (2.68): `3μ/‖r‖⁵ r̂ × (M ⋆ r̂^s)` with `r̂ = r + ε0`.
pub fn gravity_gradient_old(m: &DualInertia, r_b: &V3, mu: f64) -> DualQuat {
    let rr = DualQuat::vector(r_b, &V3::zeros());
    rr.cross(&m.apply(&rr.swap())).scale(3.0 * mu / r_b.norm().powi(5))
}

/// J2 acceleration (2.64) in inertial coordinates for the inertial position `r_i`.
pub fn j2_acceleration(r_i: &V3, mu: f64, j2: f64, re: f64) -> V3 {
    j2_acceleration_inv(r_i, 1.0 / r_i.norm(), mu, j2, re)
}

/// [`j2_acceleration`] with `1/‖r_i‖` given: `k = −(3/2) μ J2 Re²/‖r‖⁵`, `a = k [(1 − 5z²/r²) x, (1 − 5z²/r²) y,
/// (3 − 5z²/r²) z]`, multiplications only.
#[inline]
pub fn j2_acceleration_inv(r_i: &V3, inv_r: f64, mu: f64, j2: f64, re: f64) -> V3 {
    let z2 = (r_i.z * inv_r).powi(2);
    let inv_r2 = inv_r * inv_r;
    let k = -1.5 * mu * j2 * re * re * inv_r2 * inv_r2 * inv_r;
    let kxy = k * (1.0 - 5.0 * z2);
    V3::new(kxy * r_i.x, kxy * r_i.y, k * (3.0 - 5.0 * z2) * r_i.z)
}

/// (2.66): `f_J2 = M ⋆ (a_J2^B + ε0)` with `a_J2^B = q_{B/I}* a_J2^I q_{B/I}` (the rotation the text implies).
pub fn j2(m: &DualInertia, q_bi: &DualQuat, r_i: &V3, mu: f64, j2: f64, re: f64) -> DualQuat {
    let a_b = q_bi.r.conj().rotate(&j2_acceleration(r_i, mu, j2, re));
    m.apply(&DualQuat::vector(&a_b, &V3::zeros()))
}

/// Relative pose dynamics (2.58): the body-frame rate of the error twist `ω^B_{B/D}`, given the error pose
/// `q_{B/D}`, the desired frame's twist `ω^D_{D/I}` and its rate (both in D), and the net dual force `f^B`:
/// `M(ω̇_{B/D})^s = f − (ω_{B/D} + ω^B_{D/I}) × M((ω_{B/D})^s + (ω^B_{D/I})^s) − M(q* ω̇^D_{D/I} q)^s
///  − M(ω^B_{D/I} × ω_{B/D})^s`, with `ω^B_{D/I} = q* ω^D_{D/I} q`.
pub fn pose_error_acceleration(
    m: &DualInertia,
    q_bd: &DualQuat,
    w_bd: &DualQuat,
    w_di_d: &DualQuat,
    wdot_di_d: &DualQuat,
    f_b: &DualQuat,
) -> DualQuat {
    let w_di = q_bd.shift_in(w_di_d);
    let total = *w_bd + w_di;
    let rhs = *f_b
        - total.cross(&(m.momentum(w_bd) + m.momentum(&w_di)))
        - m.apply(&q_bd.shift_in(wdot_di_d).swap())
        - m.apply(&w_di.cross(w_bd).swap());
    m.solve_swapped(&rhs)
}
