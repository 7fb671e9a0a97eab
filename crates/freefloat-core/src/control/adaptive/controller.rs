//! `AdaptivePoseController`: the ch. 4 controller and estimator as an object a user drives from their own
//! simulation loop (or flight software): ask for the dual force at the present state, then advance the
//! estimate by one sample period and offer the sample `(R_k, f_k)` to the concurrent-learning memory. The
//! formulas are those of `law` and `stack`, the same the built-in closed loop uses.

use super::closed_loop::Learning;
use super::gains::{Gains, M7};
use super::law::{control_force, estimate_rate, LawForm};
use super::reference::check_vector;
use super::stack::{singular_values_psd, DataStack};
use super::tracking::{error_state, ErrorState};
use crate::dualquat::realisable::{realisability, Realisability};
use crate::dualquat::regressor::{relative_regressor, V7};
use crate::dualquat::DualQuat;
use crate::error::{FfError, Result};

/// The concurrent-learning memory of a controller.
#[derive(Clone, Debug)]
enum Memory {
    /// Cumulative P, Q (Theorem 1), integrated by the rectangle rule over the sample periods given to `update`.
    Continuous { p: M7, q: V7 },
    /// Stored stack (Theorem 2).
    Discrete(DataStack),
}

/// Adaptive pose tracking with concurrent learning (Valverde 2018, Theorems 1 and 2).
#[derive(Clone, Debug)]
pub struct AdaptivePoseController {
    gains: Gains,
    alpha: f64,
    law: LawForm,
    estimate: V7,
    memory: Memory,
}

/// Largest unit defect `max |q q* − 1|` of a measured pose the controller accepts.
pub const POSE_TOL: f64 = 1e-6;

/// A measured state: unit pose error `q_{B/D}` and twist `ω^B_{B/D}`, with the reference `(ω^D_{D/I}, ω̇^D_{D/I})`.
fn checked_state(q: &DualQuat, w: &DualQuat, w_di: &DualQuat, wdot_di: &DualQuat) -> Result<()> {
    // a pose integrated by the user's own loop drifts off the unit constraint by round-off and truncation
    // (RK4 at 0.01 s: ~1e-9 after a second); the law is defined for any q, so accept a small defect as it is
    // and reject only a pose that is not unit at all (wrong layout, unnormalised data)
    if !q.is_finite() {
        return Err(FfError::arg("q_bd", "has non-finite entries"));
    }
    let defect = q.unit_defect();
    if !(defect <= POSE_TOL) {
        return Err(FfError::arg(
            "q_bd",
            format!(
                "is not a unit dual quaternion (max |q q* − 1| = {defect:.3e} > {POSE_TOL:e}; layout [w x y z | w x y z], normalise it with (2.30))"
            ),
        ));
    }
    check_vector("w_bd", w)?;
    check_vector("w_di", w_di)?;
    check_vector("wdot_di", wdot_di)
}

impl AdaptivePoseController {
    /// A controller with the initial estimate `estimate0` (anything finite; the thesis starts from 0).
    pub fn new(gains: Gains, alpha: f64, learning: Learning, law: LawForm, estimate0: V7) -> Result<Self> {
        if !(alpha >= 0.0) || !alpha.is_finite() {
            return Err(FfError::arg("alpha", format!("must be finite and ≥ 0, got {alpha}")));
        }
        if estimate0.iter().any(|x| !x.is_finite()) {
            return Err(FfError::arg("estimate0", "has non-finite entries"));
        }
        let memory = match learning {
            Learning::Continuous => Memory::Continuous { p: M7::zeros(), q: V7::zeros() },
            Learning::Discrete { n_s, sigma_stop, rule, seed } => {
                Memory::Discrete(DataStack::new(n_s, sigma_stop, rule, seed)?)
            }
        };
        Ok(AdaptivePoseController { gains, alpha, law, estimate: estimate0, memory })
    }
    /// The present estimate `v(M̂) = [I11, I12, I13, I22, I23, I33, m]`.
    pub fn estimate(&self) -> &V7 {
        &self.estimate
    }
    /// Replace the estimate (finite numbers).
    pub fn set_estimate(&mut self, v: V7) -> Result<()> {
        if v.iter().any(|x| !x.is_finite()) {
            return Err(FfError::arg("estimate", "has non-finite entries"));
        }
        self.estimate = v;
        Ok(())
    }
    /// Whether the present estimate is a realisable rigid body.
    pub fn realisability(&self) -> Realisability {
        realisability(&self.estimate)
    }
    /// Gains.
    pub fn gains(&self) -> &Gains {
        &self.gains
    }
    /// α.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }
    /// The CL matrix (P or Σ R_kᵀR_k) and vector (Q or Σ R_kᵀf_k).
    pub fn memory(&self) -> (M7, V7) {
        match &self.memory {
            Memory::Continuous { p, q } => (*p, *q),
            Memory::Discrete(s) => (*s.rr(), *s.rf()),
        }
    }
    /// Singular values of the CL matrix, descending.
    pub fn singular_values(&self) -> [f64; 7] {
        match &self.memory {
            Memory::Continuous { p, .. } => singular_values_psd(p),
            Memory::Discrete(s) => *s.singular_values(),
        }
    }
    /// Samples stored (discrete CL), None in continuous CL.
    pub fn stack_len(&self) -> Option<usize> {
        match &self.memory {
            Memory::Continuous { .. } => None,
            Memory::Discrete(s) => Some(s.len()),
        }
    }

    fn errors(&self, q: &DualQuat, w: &DualQuat, w_di: &DualQuat, wdot_di: &DualQuat) -> Result<ErrorState> {
        checked_state(q, w, w_di, wdot_di)?;
        Ok(error_state(&self.gains, q, w, w_di, wdot_di))
    }

    /// The dual control force `f_c^B = f + ετ` (4.9) at the state `(q_{B/D}, ω^B_{B/D})` for the reference
    /// `(ω^D_{D/I}, ω̇^D_{D/I})`.
    pub fn control(&self, q: &DualQuat, w: &DualQuat, w_di: &DualQuat, wdot_di: &DualQuat) -> Result<DualQuat> {
        let x = self.errors(q, w, w_di, wdot_di)?;
        Ok(control_force(&self.gains, &self.estimate, &x, self.law))
    }

    /// `d v(M̂)/dt` (4.13)/(4.29) at the state with the present memory.
    pub fn estimate_rate(&self, q: &DualQuat, w: &DualQuat, w_di: &DualQuat, wdot_di: &DualQuat) -> Result<V7> {
        let x = self.errors(q, w, w_di, wdot_di)?;
        let (p, qq) = self.memory();
        let cl = match &self.memory {
            Memory::Discrete(s) if s.is_empty() => None,
            _ => Some((&p, &qq)),
        };
        Ok(estimate_rate(&self.gains, self.alpha, &self.estimate, &x, cl))
    }

    /// Record the sample of the state: the regressor `R` (4.3) from the measured `ω̇^B_{B/D}` and the dual force
    /// `f` that was applied. Continuous CL adds `dt RᵀR` and `dt Rᵀf` to P and Q; discrete CL offers the sample
    /// to the stack (`dt` unused). Returns whether the memory changed.
    #[allow(clippy::too_many_arguments)]
    pub fn observe(
        &mut self,
        q: &DualQuat,
        w: &DualQuat,
        w_dot: &DualQuat,
        w_di: &DualQuat,
        wdot_di: &DualQuat,
        force: &DualQuat,
        dt: f64,
    ) -> Result<bool> {
        checked_state(q, w, w_di, wdot_di)?;
        check_vector("w_bd_dot", w_dot)?;
        check_vector("force", force)?;
        let r = relative_regressor(w_dot, w, wdot_di, w_di, q);
        let f = force.to_vec8();
        Ok(match &mut self.memory {
            Memory::Continuous { p, q } => {
                if !(dt > 0.0) || !dt.is_finite() {
                    return Err(FfError::arg("dt", format!("must be positive and finite, got {dt}")));
                }
                *p += dt * r.transpose() * r;
                *q += dt * r.transpose() * f;
                true
            }
            Memory::Discrete(s) => s.offer(&r, &f),
        })
    }

    /// One sample period of an on-board loop: optionally `observe` the sample (when the measured
    /// `ω̇^B_{B/D}` and the applied force are given), then advance the estimate by `dt` with the update law
    /// evaluated at this state (forward Euler, i.e. a zero-order hold of the rate). Errors, leaving the estimate
    /// unchanged, if the new estimate would not be finite.
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        dt: f64,
        q: &DualQuat,
        w: &DualQuat,
        w_di: &DualQuat,
        wdot_di: &DualQuat,
        sample: Option<(&DualQuat, &DualQuat)>,
    ) -> Result<V7> {
        if !(dt > 0.0) || !dt.is_finite() {
            return Err(FfError::arg("dt", format!("must be positive and finite, got {dt}")));
        }
        if let Some((w_dot, f)) = sample {
            self.observe(q, w, w_dot, w_di, wdot_di, f, dt)?;
        }
        let rate = self.estimate_rate(q, w, w_di, wdot_di)?;
        let next = self.estimate + dt * rate;
        if next.iter().any(|x| !x.is_finite()) {
            return Err(FfError::Numerical(format!(
                "the estimate would become non-finite (rate {:?}); reduce dt or the gains",
                rate.as_slice()
            )));
        }
        self.estimate = next;
        Ok(next)
    }
}
