//! Dual inertia, dual momentum, kinetic energy and the rigid-body Newton–Euler equations in dual-quaternion
//! form (Valverde 2018, §2.3.2, (2.45)–(2.57)). Every quantity is about the centre of mass, in body axes.

use super::dual_quaternion::{swap_matrix, DualQuat, M8};
use super::quaternion::Quat;
use crate::error::{FfError, Result};
use crate::spatial::{Inertia, M3};

/// Mass and inertia about the centre of mass in the CoM frame's axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualInertia {
    mass: f64,
    i_com: M3,
    /// `Ī⁻¹`, kept because every forward solve needs it.
    i_inv: M3,
}

impl DualInertia {
    /// Positive mass and a symmetric positive-definite inertia, so that `H(M)` is invertible (Lemma 3).
    pub fn new(mass: f64, i_com: M3) -> Result<DualInertia> {
        if !(mass > 0.0) || !mass.is_finite() {
            return Err(FfError::arg("mass", format!("must be positive and finite, got {mass}")));
        }
        if i_com.iter().any(|x| !x.is_finite()) || (i_com - i_com.transpose()).amax() > 1e-9 * i_com.amax().max(1.0) {
            return Err(FfError::arg("inertia", "must be a finite symmetric 3×3 matrix"));
        }
        let Some(ch) = i_com.cholesky() else {
            return Err(FfError::arg("inertia", "must be positive definite"));
        };
        Ok(DualInertia { mass, i_com, i_inv: ch.inverse() })
    }
    /// Mass (kg).
    pub fn mass(&self) -> f64 {
        self.mass
    }
    /// Inertia about the centre of mass, body axes (kg m²).
    pub fn i_com(&self) -> M3 {
        self.i_com
    }
    /// `Ī⁻¹`.
    pub fn i_com_inverse(&self) -> M3 {
        self.i_inv
    }
    /// From the engine's inertia (about the body origin): the same body seen from its CoM frame, which has
    /// the body frame's axes. Errors for a massless or singular body (the dual formulation needs `H(M)⁻¹`).
    pub fn from_inertia(inr: &Inertia) -> Result<DualInertia> {
        DualInertia::new(inr.mass, inr.i_com())
    }

    /// (2.45): `M = blkdiag(1, m I₃, 1, Ī)` (the scalar-slot ones only make it invertible).
    pub fn matrix(&self) -> M8 {
        let mut m = M8::zeros();
        m[(0, 0)] = 1.0;
        m[(4, 4)] = 1.0;
        m.fixed_view_mut::<3, 3>(1, 1).copy_from(&(self.mass * M3::identity()));
        m.fixed_view_mut::<3, 3>(5, 5).copy_from(&self.i_com);
        m
    }
    /// (2.48)–(2.50): `H(M) = M P_swap`, so `H(M) a = M a^s`.
    pub fn swapped_matrix(&self) -> M8 {
        self.matrix() * swap_matrix()
    }
    /// Lemma 3 (2.52): `H(M)⁻¹`, the same pattern with `Ī⁻¹` and `I₃/m`.
    pub fn swapped_matrix_inverse(&self) -> M8 {
        let mut m = M8::zeros();
        m[(0, 4)] = 1.0;
        m[(4, 0)] = 1.0;
        m.fixed_view_mut::<3, 3>(1, 5).copy_from(&self.i_inv);
        m.fixed_view_mut::<3, 3>(5, 1).copy_from(&(M3::identity() / self.mass));
        m
    }
    /// `M ⋆ x` without forming M.
    pub fn apply(&self, x: &DualQuat) -> DualQuat {
        DualQuat { r: Quat { w: x.r.w, v: x.r.v * self.mass }, d: Quat { w: x.d.w, v: self.i_com * x.d.v } }
    }
    /// Dual momentum (2.46)/(2.51): `H = M ⋆ ω^s = m v + ε Ī ω` for the body twist `ω + ε v` at the CoM.
    pub fn momentum(&self, twist: &DualQuat) -> DualQuat {
        self.apply(&twist.swap())
    }
    /// Kinetic energy (2.47): `T = ½ ω^s ∘ (M ⋆ ω^s)`.
    pub fn kinetic_energy(&self, twist: &DualQuat) -> f64 {
        0.5 * twist.swap().circle_scalar(&self.momentum(twist))
    }
    /// Newton–Euler (2.55)–(2.57), the residual `M ⋆ (ω̇)^s + ω × (M ⋆ ω^s) − W`: zero when the body twist
    /// `ω` (CoM frame) changes at the body-frame component rate `ω̇` under the net wrench `W` about the CoM.
    pub fn newton_euler_residual(&self, twist: &DualQuat, twist_dot: &DualQuat, wrench: &DualQuat) -> DualQuat {
        self.apply(&twist_dot.swap()) + twist.cross(&self.momentum(twist)) - *wrench
    }
    /// Forward Newton–Euler: `ω̇ = H(M)⁻¹ (W − ω × (M ⋆ ω^s))` (2.56) with `H(M)⁻¹` applied blockwise.
    pub fn acceleration(&self, twist: &DualQuat, wrench: &DualQuat) -> DualQuat {
        let rhs = *wrench - twist.cross(&self.momentum(twist));
        self.solve_swapped(&rhs)
    }
    /// `H(M)⁻¹ x`: `x = M y^s` ⇒ `y^s = M⁻¹ x`.
    pub fn solve_swapped(&self, x: &DualQuat) -> DualQuat {
        DualQuat { r: Quat { w: x.r.w, v: x.r.v / self.mass }, d: Quat { w: x.d.w, v: self.i_inv * x.d.v } }.swap()
    }
}

/// System dual momentum about the inertial origin in inertial coordinates (2.53):
/// `Σ q_i (M_i ⋆ ω_i^s) q_i*` for bodies with CoM-frame poses `q_i = q_{o_i/I}` and body twists `ω_i`.
/// Real part: linear momentum; dual part: angular momentum about O_I.
pub fn system_momentum(bodies: &[(DualInertia, DualQuat, DualQuat)]) -> DualQuat {
    bodies.iter().fold(DualQuat::ZERO, |acc, (m, q, w)| acc + q.shift_out(&m.momentum(w)))
}

/// System kinetic energy (2.54).
pub fn system_kinetic_energy(bodies: &[(DualInertia, DualQuat)]) -> f64 {
    bodies.iter().map(|(m, w)| m.kinetic_energy(w)).sum()
}
