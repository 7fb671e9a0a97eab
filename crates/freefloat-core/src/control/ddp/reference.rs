//! Pose references of the chapter 8 problems (Valverde 2018, §8.7, eqs. (8.57)–(8.62)): hold a pose, move
//! along a screw (the dual-quaternion exponential of Lemma 5, eq. (3.10)) at constant rates, hold again.

use crate::dualquat::{exp, DualQuat, Quat};
use crate::error::{FfError, Result};
use crate::spatial::V3;

/// `q(t) = q_start · exp(½ θ̂(τ) ŝ)` with `ŝ = ℓ + ε m` (in the start frame), `θ̂ = θ + ε d`,
/// `θ = angle·τ/t_move`, `d = advance·τ/t_move`, `τ = clamp(t − t_hold, 0, t_move)`; sampled at
/// `t_k = k dt`, k = 0..=n. Never properised: the scalar part may change sign along the screw.
#[allow(clippy::too_many_arguments)]
pub fn screw_reference(
    start: &DualQuat,
    axis: &V3,
    moment: &V3,
    angle: f64,
    advance: f64,
    t_hold: f64,
    t_move: f64,
    dt: f64,
    n: usize,
) -> Result<Vec<DualQuat>> {
    if !(dt > 0.0) || !(t_move > 0.0) || !(t_hold >= 0.0) || !angle.is_finite() || !advance.is_finite() {
        return Err(FfError::arg("reference", "need dt > 0, t_move > 0, t_hold >= 0 and finite angle/advance"));
    }
    if !((axis.norm() - 1.0).abs() < 1e-9) || !(axis.dot(moment).abs() < 1e-9) {
        return Err(FfError::arg("axis", "the screw axis must be a unit vector orthogonal to its moment"));
    }
    if !start.is_unit() {
        return Err(FfError::arg("start", "the start pose must be a unit dual quaternion"));
    }
    Ok((0..=n)
        .map(|k| {
            let tau = (k as f64 * dt - t_hold).clamp(0.0, t_move);
            let th = angle * tau / t_move;
            let d = advance * tau / t_move;
            // ½ θ̂ ŝ = ½ (θ ℓ + ε (θ m + d ℓ)).
            let x = DualQuat::new(Quat::pure(&(axis * (0.5 * th))), Quat::pure(&((moment * th + axis * d) * 0.5)));
            start.mul(&exp(&x))
        })
        .collect())
}
