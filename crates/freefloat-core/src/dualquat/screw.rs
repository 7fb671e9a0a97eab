//! Exponential and logarithm: `exp` of a vector dual quaternion, the screw exponential of Lemma 5
//! (Valverde 2018, (3.8)–(3.12)) and its inverse (3.18).
//!
//! Write the argument `x = a + ε b` (a, b vector quaternions) and `φ = ‖ā‖`. With the dual angle
//! `φ̂ = φ + ε (ā·b̄)/φ`, `exp(x) = cos φ̂ + x sin(φ̂)/φ̂`; expanding the dual-number functions
//! (`f(φ + εδ) = f(φ) + ε δ f'(φ)`) gives
//!   real: `(cos φ, ā sinc φ)`,  dual: `(−(ā·b̄) sinc φ, b̄ sinc φ + ā (ā·b̄) c(φ))`,
//! with `c(φ) = (φ cos φ − sin φ)/φ³`. Both sinc and c have series at φ → 0, so pure translations need no
//! special case.

use super::dual_quaternion::DualQuat;
use super::quaternion::Quat;
use crate::error::{FfError, Result};
use crate::spatial::V3;

/// `sin φ / φ`.
fn sinc(phi: f64) -> f64 {
    if phi.abs() < 1e-4 {
        let p2 = phi * phi;
        1.0 - p2 / 6.0 + p2 * p2 / 120.0
    } else {
        phi.sin() / phi
    }
}

/// `(φ cos φ − sin φ)/φ³`, the derivative of sinc divided by φ.
fn dsinc_over_phi(phi: f64) -> f64 {
    if phi.abs() < 1e-3 {
        let p2 = phi * phi;
        -1.0 / 3.0 + p2 / 30.0 - p2 * p2 / 840.0
    } else {
        (phi * phi.cos() - phi.sin()) / (phi * phi * phi)
    }
}

/// `exp(x)` of a vector dual quaternion `x = ā + ε b̄` (the scalar parts of x are ignored). For
/// `x = ½ θ̂ ŝ` this is the screw motion of Lemma 5; the result is always a unit dual quaternion.
pub fn exp(x: &DualQuat) -> DualQuat {
    let (a, b) = (x.r.v, x.d.v);
    let phi = a.norm();
    let ab = a.dot(&b);
    let s = sinc(phi);
    DualQuat { r: Quat { w: phi.cos(), v: a * s }, d: Quat { w: -ab * s, v: b * s + a * (ab * dsinc_over_phi(phi)) } }
}

/// Principal logarithm of a unit dual quaternion: the vector dual quaternion `x` with `exp(x) = q` and
/// `‖x_r‖ ∈ [0, π)`. `q` is properised first ((2.31), q and −q are the same pose) so `‖x_r‖ ≤ π/2`, i.e.
/// the rotation angle is at most π. Errors if `q` is not unit.
pub fn log(q: &DualQuat) -> Result<DualQuat> {
    if !q.is_unit() {
        return Err(FfError::arg(
            "q",
            format!("log needs a unit dual quaternion (q q* − 1 = {:.3e})", q.unit_defect()),
        ));
    }
    let q = q.properized();
    let phi = q.r.v.norm().atan2(q.r.w);
    let s = sinc(phi);
    let a = q.r.v / s;
    let ab = -q.d.w / s;
    let b = (q.d.v - a * (ab * dsinc_over_phi(phi))) / s;
    Ok(DualQuat::vector(&a, &b))
}

/// Screw exponential (3.10): `exp(½ θ̂ ŝ)` with dual angle `θ̂ = θ + ε d` and dual axis `ŝ = ℓ + ε m`
/// (unit ℓ, moment `m = p × ℓ` for a point p on the axis):
/// `(cos θ/2, ℓ sin θ/2) + ε(−½ d sin θ/2, ½ d ℓ cos θ/2 + m sin θ/2)`.
/// Revolute joints use d = 0, prismatic θ = 0 (§3.2).
pub fn screw_exp(theta: f64, d: f64, l: &V3, m: &V3) -> DualQuat {
    let (s, c) = (0.5 * theta).sin_cos();
    DualQuat { r: Quat { w: c, v: l * s }, d: Quat { w: -0.5 * d * s, v: l * (0.5 * d * c) + m * s } }
}

/// Screw parameters of a unit dual quaternion: rotation angle θ ∈ [0, π], translation d along the axis,
/// unit axis ℓ and moment m (inverse of (3.10); the thesis defers this to its reference [119], so the formulas here are
/// derived: `θ = 2 atan2(‖q̄_r‖, q_r0)`, `ℓ = q̄_r / sin(θ/2)`, `d = −2 q_d0 / sin(θ/2)`,
/// `m = (q̄_d − ½ d ℓ cos(θ/2)) / sin(θ/2)`; for θ = 0 the axis is the translation's direction, ẑ if there is none, and
/// m = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Screw {
    /// Rotation angle about the screw axis (rad).
    pub theta: f64,
    /// Translation along the screw axis (m).
    pub d: f64,
    /// Unit direction of the screw axis.
    pub l: V3,
    /// Moment of the axis about the origin, `p × l` (m).
    pub m: V3,
}

/// `θ = 2 atan2(‖q̄_r‖, q_r0)`, `ℓ = q̄_r / sin(θ/2)`, `d = −2 q_d0 / sin(θ/2)`,
/// `m = (q̄_d − ½ d ℓ cos(θ/2)) / sin(θ/2)`. For a pure translation (θ below `1e-12`) the axis is the
/// translation direction, `d` its length and `m = 0`; for the identity ℓ = ẑ, d = 0.
pub fn screw_log(q: &DualQuat) -> Result<Screw> {
    if !q.is_unit() {
        return Err(FfError::arg(
            "q",
            format!("screw_log needs a unit dual quaternion (q q* − 1 = {:.3e})", q.unit_defect()),
        ));
    }
    let q = q.properized();
    let sn = q.r.v.norm();
    let theta = 2.0 * sn.atan2(q.r.w);
    if theta < 1e-12 {
        let t = 2.0 * q.d.mul(&q.r.conj()).v;
        let n = t.norm();
        let l = if n > 0.0 { t / n } else { V3::z() };
        return Ok(Screw { theta: 0.0, d: n, l, m: V3::zeros() });
    }
    let l = q.r.v / sn;
    let d = -2.0 * q.d.w / sn;
    let m = (q.d.v - l * (0.5 * d * q.r.w)) / sn;
    Ok(Screw { theta, d, l, m })
}
