//! The closed loop of Valverde 2018 §4.5: the relative pose-error dynamics (2.58) of a rigid spacecraft with the
//! true mass properties, driven by the adaptive law of §4.2–4.3 (`f^B = f_c^B`, no gravity, no disturbance),
//! as one flat ODE state `x = [q_{B/D} (8), ω^B_{B/D} (8), v(M̂) (7), P (49, column-major), Q (7)]` (P and Q,
//! the cumulative integrals (4.14)–(4.15), only in continuous CL).

use super::gains::{Gains, M7};
use super::law::{control_force, estimate_rate, LawForm};
use super::reference::Reference;
use super::stack::{DataStack, Selection};
use super::tracking::{error_state, ErrorState};
use crate::dualquat::orbital::pose_error_acceleration;
use crate::dualquat::regressor::{relative_regressor, M87, V7};
use crate::dualquat::{DualInertia, DualQuat, V8};
use crate::error::{FfError, Result};
use crate::spatial::M3;

/// Length of the state vector.
pub const NX: usize = 79;
pub(crate) const IQ: usize = 0;
pub(crate) const IW: usize = 8;
pub(crate) const IV: usize = 16;
pub(crate) const IP: usize = 23;
pub(crate) const IQQ: usize = 72;
/// Number of states without P, Q.
pub(crate) const N_CORE: usize = 23;

/// How the estimator learns from recorded data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Learning {
    /// Continuous CL (Theorem 1): `Ṗ = RᵀR`, `Q̇ = Rᵀf`, P(0) = Q(0) = 0, integrated with the state.
    Continuous,
    /// Discrete CL (Theorem 2): a stack of at most `n_s` samples, one candidate per integration step (at its
    /// start), frozen once σ_min(ΣRᵀR) ≥ `sigma_stop`.
    Discrete {
        /// Capacity N_s (≥ 2).
        n_s: usize,
        /// Stop threshold on σ_min (> 0; infinity never stops).
        sigma_stop: f64,
        /// Selection rule of a full stack.
        rule: Selection,
        /// Seed of Algorithm 3's random order.
        seed: u64,
    },
}

/// Everything that defines one closed-loop run.
#[derive(Clone, Debug)]
pub struct Setup {
    /// True parameters `v(M)` of the simulated spacecraft (m > 0 and Ī > 0; the triangle inequality is not
    /// required: the thesis' own truth fails it).
    pub truth: V7,
    /// Gains.
    pub gains: Gains,
    /// Concurrent-learning weight α ≥ 0 (0 = the baseline of [47]).
    pub alpha: f64,
    /// Remark 6 (Valverde 2018 §4.2): "once the rank condition (4.16) is satisfied, α can eventually be set to
    /// α = 0". `Some(d)`: α is switched to 0 at the first step start at least `d` ≥ 0 seconds after the CL matrix
    /// (P in continuous CL, Σ R_kᵀR_k in discrete CL) first has rank 7 (σ_min > `RunOptions::rank_tol`, the
    /// `Run::rank7_time`); `None`: α is kept throughout (the thesis' examples).
    pub alpha_off_after: Option<f64>,
    /// Corrected or printed control law.
    pub law: LawForm,
    /// Continuous or discrete CL.
    pub learning: Learning,
    /// Initial relative pose `q_{B/D}(0)` (unit).
    pub q0: DualQuat,
    /// Initial relative twist `ω^B_{B/D}(0)` (a vector dual quaternion).
    pub w0: DualQuat,
    /// Initial estimate `v(M̂)(0)` (anything finite).
    pub estimate0: V7,
    /// The desired frame's twist.
    pub reference: Reference,
}

/// The true plant as a dual inertia (checked).
pub(crate) fn plant(truth: &V7) -> Result<DualInertia> {
    let i = M3::new(truth[0], truth[1], truth[2], truth[1], truth[3], truth[4], truth[2], truth[4], truth[5]);
    DualInertia::new(truth[6], i).map_err(|e| match e {
        FfError::Argument { msg, .. } => FfError::arg("truth", format!("the simulated spacecraft's {msg}")),
        other => other,
    })
}

#[inline]
pub(crate) fn dq_at(x: &[f64], i: usize) -> DualQuat {
    DualQuat::from_vec8(&V8::from_column_slice(&x[i..i + 8]))
}
#[inline]
pub(crate) fn put_dq(x: &mut [f64], i: usize, q: &DualQuat) {
    x[i..i + 8].copy_from_slice(q.to_vec8().as_slice());
}
#[inline]
pub(crate) fn v7_at(x: &[f64], i: usize) -> V7 {
    V7::from_column_slice(&x[i..i + 7])
}
#[inline]
pub(crate) fn m7_at(x: &[f64], i: usize) -> M7 {
    M7::from_column_slice(&x[i..i + 49])
}

/// What one evaluation of the closed loop found besides the state rate.
#[derive(Clone, Copy, Debug)]
pub struct Eval {
    /// Error variables.
    pub err: ErrorState,
    /// Applied dual force `f^B = f_c^B`.
    pub force: DualQuat,
    /// `ω̇^B_{B/D}` of the true plant.
    pub w_dot: DualQuat,
    /// `(ω^D_{D/I}, ω̇^D_{D/I})` at this time.
    pub reference: (DualQuat, DualQuat),
}

/// The plant part at (t, x): error variables, control force and true relative acceleration (2.58).
#[inline]
pub(crate) fn plant_eval(s: &Setup, m: &DualInertia, t: f64, x: &[f64; NX]) -> Eval {
    let (w_di, wdot_di) = s.reference.eval(t);
    let q = dq_at(x, IQ);
    let w = dq_at(x, IW);
    let v_hat = v7_at(x, IV);
    let err = error_state(&s.gains, &q, &w, &w_di, &wdot_di);
    let force = control_force(&s.gains, &v_hat, &err, s.law);
    let w_dot = pose_error_acceleration(m, &q, &w, &w_di, &wdot_di, &force);
    Eval { err, force, w_dot, reference: (w_di, wdot_di) }
}

/// The regressor (4.3) of an evaluation: `R v(M) = f^B` along the true motion.
#[inline]
pub(crate) fn regressor_of(ev: &Eval, x: &[f64; NX]) -> M87 {
    relative_regressor(&ev.w_dot, &dq_at(x, IW), &ev.reference.1, &ev.reference.0, &dq_at(x, IQ))
}

/// The state rate at (t, x) into `dx` with the CL weight `alpha` in effect (`s.alpha`, or 0 after Remark 6's
/// switch). `stack` holds the discrete-CL sums (ignored in continuous CL).
pub(crate) fn rhs(
    s: &Setup,
    m: &DualInertia,
    t: f64,
    x: &[f64; NX],
    stack: Option<&DataStack>,
    alpha: f64,
    dx: &mut [f64; NX],
) -> Eval {
    let ev = plant_eval(s, m, t, x);
    put_dq(dx, IQ, &ev.err.q_dot);
    put_dq(dx, IW, &ev.w_dot);
    let v_hat = v7_at(x, IV);
    let rate = match s.learning {
        Learning::Continuous => {
            let r = regressor_of(&ev, x);
            let rt = r.transpose();
            let rtr = rt * r;
            let rtf = rt * ev.force.to_vec8();
            dx[IP..IP + 49].copy_from_slice(rtr.as_slice());
            dx[IQQ..IQQ + 7].copy_from_slice(rtf.as_slice());
            let (p, qq) = (m7_at(x, IP), v7_at(x, IQQ));
            estimate_rate(&s.gains, alpha, &v_hat, &ev.err, Some((&p, &qq)))
        }
        Learning::Discrete { .. } => {
            let cl = stack.filter(|st| !st.is_empty()).map(|st| (st.rr(), st.rf()));
            estimate_rate(&s.gains, alpha, &v_hat, &ev.err, cl)
        }
    };
    dx[IV..IV + 7].copy_from_slice(rate.as_slice());
    ev
}
