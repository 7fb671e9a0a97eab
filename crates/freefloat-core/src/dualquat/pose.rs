//! Poses as unit dual quaternions (Valverde 2018, §3.1, (3.1)–(3.4)), conversions to the engine's `Se3` and
//! `(x, y, z, w)` quaternions, and the shifting laws of twists and wrenches ((2.41)–(2.44)).
//!
//! `q_{B/A} = q + ε ½ r^A q` (translation first, (3.2)) is the pose of frame B in frame A: rotation
//! `q_{B/A}` (B's axes are A's axes actively rotated by q) and `r^A` from A's origin to B's origin in A.
//! It is the engine's `Se3 { rot: C(q), trans: r^A }` placing B in A (`x_A = rot x_B + trans`).

use super::dual_quaternion::DualQuat;
use super::quaternion::Quat;
use crate::error::{FfError, Result};
use crate::spatial::{Force, Motion, Se3, V3};

/// (3.2)/(3.4), translation first: `q + ε ½ r^A q`.
pub fn from_rotation_translation(q: &Quat, r_a: &V3) -> DualQuat {
    DualQuat { r: *q, d: Quat::pure(r_a).mul(q).scale(0.5) }
}

/// (3.1)/(3.3), body form: `q + ε ½ q r^B` with the translation in B coordinates.
pub fn from_rotation_body_translation(q: &Quat, r_b: &V3) -> DualQuat {
    DualQuat { r: *q, d: q.mul(&Quat::pure(r_b)).scale(0.5) }
}

/// A pure translation `1 + ε ½ r` (the first factor of (3.4)).
pub fn translation(r: &V3) -> DualQuat {
    DualQuat { r: Quat::ONE, d: Quat::pure(&(r * 0.5)) }
}

/// A pure rotation `q + ε0`.
pub fn rotation(q: &Quat) -> DualQuat {
    DualQuat { r: *q, d: Quat::ZERO }
}

impl DualQuat {
    /// Position of B's origin in A coordinates: `r^A_{B/A} = 2 q_d q_r*` (§3.1).
    pub fn translation(&self) -> V3 {
        self.d.mul(&self.r.conj()).v * 2.0
    }
    /// Position of B's origin in B coordinates: `r^B_{B/A} = 2 q_r* q_d`.
    pub fn translation_body(&self) -> V3 {
        self.r.conj().mul(&self.d).v * 2.0
    }
    /// The rotation part `q_r`.
    pub fn rotation(&self) -> Quat {
        self.r
    }
    /// Pose of a frame from the engine's placement.
    pub fn from_se3(x: &Se3) -> DualQuat {
        from_rotation_translation(&Quat::from_rotation_matrix(&x.rot), &x.trans)
    }
    /// The engine's placement of a unit dual quaternion (unit-ness is the caller's business; see
    /// `checked_pose` for user input).
    pub fn to_se3(&self) -> Se3 {
        Se3::new(self.r.rotation_matrix(), self.translation())
    }
    /// From the engine's pose convention: quaternion `(x, y, z, w)` and translation.
    pub fn from_pose_xyzw(q: &[f64; 4], t: &V3) -> DualQuat {
        from_rotation_translation(&Quat::from_xyzw(q), t)
    }
    /// To the engine's pose convention: quaternion `(x, y, z, w)` and translation.
    pub fn to_pose_xyzw(&self) -> ([f64; 4], V3) {
        (self.r.to_xyzw(), self.translation())
    }

    /// (2.41)/(2.43): `q* x q`. With `self = q_{Y/X}`, carries a wrench `f + ετ` about O_X in X coordinates to
    /// the same wrench about O_Y in Y coordinates, `f^Y + ε(τ^Y + r^Y_{X/Y} × f^Y)`, and a twist the same way.
    pub fn shift_in(&self, x: &DualQuat) -> DualQuat {
        self.conj().mul(x).mul(self)
    }
    /// (2.42)/(2.44): `q x q*`, the inverse of `shift_in` for unit q.
    pub fn shift_out(&self, x: &DualQuat) -> DualQuat {
        self.mul(x).mul(&self.conj())
    }
}

/// Check user input: finite and unit (`q q* = 1`, not the 8-norm), naming the argument otherwise.
pub fn checked_pose(name: &str, q: &DualQuat) -> Result<DualQuat> {
    if !q.is_finite() {
        return Err(FfError::arg(name, "has non-finite entries"));
    }
    let e = q.unit_defect();
    if !(e <= super::dual_quaternion::UNIT_TOL) {
        return Err(FfError::arg(
            name,
            format!("is not a unit dual quaternion (max |q q* − 1| = {e:.3e}; normalise it with (2.30) first)"),
        ));
    }
    Ok(*q)
}

/// A twist `ω + ε v` from the engine's `Motion` ([lin; ang], velocity of the frame origin).
pub fn twist_from_motion(m: &Motion) -> DualQuat {
    DualQuat::vector(&m.ang, &m.lin)
}
/// The engine's `Motion` `[v; ω]` of a twist `ω + εv`.
pub fn twist_to_motion(w: &DualQuat) -> Motion {
    Motion::new(w.d.v, w.r.v)
}
/// A wrench `f + ε τ` (2.39) from the engine's `Force` ([force; moment about the frame origin]).
pub fn wrench_from_force(f: &Force) -> DualQuat {
    DualQuat::vector(&f.lin, &f.ang)
}
/// The engine's `Force` `[f; τ]` of a wrench `f + ετ`.
pub fn wrench_to_force(w: &DualQuat) -> Force {
    Force::new(w.r.v, w.d.v)
}

/// Dual velocity from a pose and its time derivative (2.37): body `ω^B_{B/A} = 2 q* q̇`.
pub fn body_twist(q: &DualQuat, qdot: &DualQuat) -> DualQuat {
    q.conj().mul(qdot).scale(2.0)
}
/// Spatial dual velocity (2.37): `ω^A_{B/A} = 2 q̇ q*` = `ω^A + ε(ṙ^A − ω^A × r^A)` ((3.64)).
pub fn spatial_twist(q: &DualQuat, qdot: &DualQuat) -> DualQuat {
    qdot.mul(&q.conj()).scale(2.0)
}
/// Pose kinematics (2.37): `q̇ = ½ q ω^B`.
pub fn pose_derivative(q: &DualQuat, body_twist: &DualQuat) -> DualQuat {
    q.mul(body_twist).scale(0.5)
}
