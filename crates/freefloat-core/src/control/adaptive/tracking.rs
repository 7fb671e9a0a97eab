//! Error variables of the adaptive pose tracker (Valverde 2018, §4.2): the pose error `e = q*(q^s − 1^s)`, its
//! rate, the sliding variable `s = ω + (K_p ⋆ e)^s` (4.10)/(4.26) and the frame-changed reference terms that the
//! control law, the update law and the regressor share. `q = q_{B/D}`, `ω = ω^B_{B/D}`; the reference twist
//! `ω^D_{D/I}` and its rate are in D axes.

use super::gains::Gains;
use crate::dualquat::{DualQuat, Quat};
use crate::spatial::V3;

/// `1^s = 0 + ε1`.
const ONE_SWAPPED: DualQuat = DualQuat { r: Quat::ZERO, d: Quat::ONE };

/// Pose error `e = q*(q^s − 1^s)`: real part `(0, ½ r̄)`, dual part `(¼‖r̄‖² + 1 − q₀, q̄)` (the (4.6) expansion).
/// `vec(e) = 0` at `q = ±1` (Lemma 12); `e(−1) = 2ε` (Remark 3 prints 0, a typo).
#[inline]
pub fn pose_error(q: &DualQuat) -> DualQuat {
    q.conj().mul(&(q.swap() - ONE_SWAPPED))
}

/// Everything the law needs at one state, computed once.
#[derive(Clone, Copy, Debug, Default)]
pub struct ErrorState {
    /// `e = q*(q^s − 1^s)`.
    pub e: DualQuat,
    /// `q̇ = ½ q ω` (2.38).
    pub q_dot: DualQuat,
    /// `ė = q̇*(q^s − 1^s) + q* (q̇)^s`.
    pub e_dot: DualQuat,
    /// `s = ω + (K_p ⋆ e)^s` (4.10), the printed `q*` restored.
    pub s: DualQuat,
    /// `ω^B_{D/I} = q* ω^D_{D/I} q`.
    pub w_di_b: DualQuat,
    /// `q* ω̇^D_{D/I} q`.
    pub wdot_di_b: DualQuat,
    /// `ω^B_{B/I} = ω^B_{B/D} + ω^B_{D/I}`.
    pub w_bi: DualQuat,
    /// `ω^B_{D/I} × ω^B_{B/D}`.
    pub cross: DualQuat,
}

/// The error variables at `(q, ω)` for the reference `(ω^D_{D/I}, ω̇^D_{D/I})`.
#[inline]
pub fn error_state(g: &Gains, q: &DualQuat, w: &DualQuat, w_di: &DualQuat, wdot_di: &DualQuat) -> ErrorState {
    let e = pose_error(q);
    let q_dot = q.mul(w).scale(0.5);
    let e_dot = q_dot.conj().mul(&(q.swap() - ONE_SWAPPED)) + q.conj().mul(&q_dot.swap());
    let s = *w + g.kp(&e).swap();
    let w_di_b = q.shift_in(w_di);
    let wdot_di_b = q.shift_in(wdot_di);
    ErrorState { e, q_dot, e_dot, s, w_di_b, wdot_di_b, w_bi: *w + w_di_b, cross: w_di_b.cross(w) }
}

/// Position error `r̄^B_{B/D} = 2 q_r* q_d` (m) and attitude error `2 acos|q₀|` (rad) of a unit pose error.
pub fn tracking_errors(q: &DualQuat) -> (V3, f64) {
    // atan2 keeps full precision near zero error, where acos of a number near 1 would not
    (q.translation_body(), 2.0 * q.r.v.norm().atan2(q.r.w.abs()))
}
