//! The control law (4.9) = (4.25) with the corrected swap, the update laws (4.13) (continuous CL, cumulative
//! P, Q) and (4.29) (discrete CL, stored stack), and the Lyapunov function (4.17) with its derivative (4.21)
//! (Valverde 2018, §4.2–4.3). The baseline of [47] is the same update law with α = 0.

use super::gains::{Gains, M7};
use super::tracking::ErrorState;
use crate::dualquat::regressor::{apply_params, h_vector, V7};
use crate::dualquat::DualQuat;

/// Which form of the last term of the control law: the one consistent with s, V̇ and the update law, or the
/// one the thesis prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LawForm {
    /// `− M̂ ⋆ (K_p ⋆ ė)`: the Lyapunov derivative is exactly (4.21).
    #[default]
    Corrected,
    /// `− M̂ ⋆ (K_p ⋆ ė)^s` as printed in (4.9) and (4.25) (a typo: V̇ then differs from (4.21)); for the
    /// test that shows the difference.
    Printed,
}

/// The dual control force `f_c^B` of (4.9)/(4.25), for the estimate `v(M̂)`:
/// `−vec(e) − K_d ⋆ s^s + ω_BI × (M̂ ⋆ ω_BI^s) + M̂ ⋆ (q* ω̇_D q)^s + M̂ ⋆ (ω_D^B × ω)^s − M̂ ⋆ (K_p ⋆ ė)`
/// ((4.25) also drops the dot on ω̇_D; (4.9) has it).
#[inline]
pub fn control_force(g: &Gains, v_hat: &V7, x: &ErrorState, form: LawForm) -> DualQuat {
    let kp_edot = g.kp(&x.e_dot);
    let last = match form {
        LawForm::Corrected => kp_edot,
        LawForm::Printed => kp_edot.swap(),
    };
    -x.e.vec() - g.kd(&x.s.swap())
        + x.w_bi.cross(&apply_params(v_hat, &x.w_bi.swap()))
        + apply_params(v_hat, &(x.wdot_di_b.swap() + x.cross.swap() - last))
}

/// The regressor-free part of the update laws (4.13)/(4.29), before K_i:
/// `−h((s × ω_BI)^s, ω_BI^s) − h(s^s, (q* ω̇_D q)^s + (ω_D^B × ω)^s − K_p ⋆ ė)`.
#[inline]
pub fn adaptation_direction(g: &Gains, x: &ErrorState) -> V7 {
    let b = x.wdot_di_b.swap() + x.cross.swap() - g.kp(&x.e_dot);
    -h_vector(&x.s.cross(&x.w_bi).swap(), &x.w_bi.swap()) - h_vector(&x.s.swap(), &b)
}

/// `d v(M̂)/dt` of (4.13)/(4.29): `K_i [adaptation_direction − α (P v(M̂) − Q)]`, where `(P, Q)` are the
/// cumulative integrals (4.14)–(4.15) (continuous CL) or the stack sums `(Σ R_kᵀR_k, Σ R_kᵀf_k)` (discrete
/// CL); `None` (or α = 0) is the baseline.
#[inline]
pub fn estimate_rate(g: &Gains, alpha: f64, v_hat: &V7, x: &ErrorState, cl: Option<(&M7, &V7)>) -> V7 {
    let mut d = adaptation_direction(g, x);
    if let Some((p, q)) = cl {
        if alpha != 0.0 {
            d -= alpha * (p * v_hat - q);
        }
    }
    g.k_i * d
}

/// The Lyapunov function (4.17): `V = (q − 1)∘(q − 1) + ½ s^s∘(M ⋆ s^s) + ½ v(ΔM)ᵀ K_i⁻¹ v(ΔM)` for the true
/// parameters `truth` (V needs them; the controller never does).
pub fn lyapunov(g: &Gains, q: &DualQuat, x: &ErrorState, v_hat: &V7, truth: &V7) -> f64 {
    let dq = *q - DualQuat::ONE;
    let ss = x.s.swap();
    let dv = v_hat - truth;
    dq.circle_scalar(&dq) + 0.5 * ss.circle_scalar(&apply_params(truth, &ss)) + 0.5 * dv.dot(&(g.k_i_inverse() * dv))
}

/// (4.21)/(4.32): `V̇ = −e∘(K_p ⋆ e) − s^s∘(K_d ⋆ s^s) − α v(ΔM)ᵀ P v(ΔM)`, the value the proof derives (P =
/// the CL matrix, `None` for the baseline). Equals the derivative of [`lyapunov`] along the closed loop with the
/// corrected law and `Q = P v(M)`.
pub fn lyapunov_rate_theory(g: &Gains, x: &ErrorState, alpha: f64, v_hat: &V7, truth: &V7, p: Option<&M7>) -> f64 {
    let ss = x.s.swap();
    let mut r = -x.e.circle_scalar(&g.kp(&x.e)) - ss.circle_scalar(&g.kd(&ss));
    if let Some(p) = p {
        let dv = v_hat - truth;
        r -= alpha * dv.dot(&(p * dv));
    }
    r
}
