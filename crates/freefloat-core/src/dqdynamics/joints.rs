//! Per-joint selectors of the dual-quaternion formulation (Valverde 2018, Tables 6.2–6.4), for the engine's
//! joint types. Inside `dqdynamics` twists and wrenches are 6-vectors holding the vector slots of the
//! dual quaternion: twist `[ω; v]` (real; dual), wrench `[f; τ]` (real; dual). The scalar slots 1 and 5 of
//! the 8-vector are always zero for twists and wrenches, so dropping them loses nothing.
//!
//! Each joint j has a frame J_j fixed to its child body, with its origin at the child body frame's origin
//! and its z-axis along the revolute/prismatic axis (the thesis puts the DOF on Z_i, §2.1). Slot indices:
//! twist/wrench 0..3 = real (ω or f), 3..6 = dual (v or τ).

use crate::dualquat::pose::rotation;
use crate::dualquat::{DualQuat, Quat};
use crate::model::{universal_first_axis, JointType};
use crate::spatial::{M3, V3};

/// Wrench slots of the reduced reaction `W̃` (the columns of V_j, Table 6.2). The actuation slots (Table
/// 6.3) are the swaps of `motion_slots`, and the two sets are disjoint and cover all six.
pub struct JointSlots {
    /// Slots (0..6 of `[f; τ]` in the joint frame) the reaction wrench acts in.
    pub reaction: &'static [usize],
}

const ALL: &[usize] = &[0, 1, 2, 3, 4, 5];

/// R: reaction `[f_x, f_y, f_z, τ_x, τ_y]` (V = E₁₅₈ᵀ), free `ω_z`. P: reaction `[f_x, f_y, τ_x, τ_y, τ_z]`
/// (V = E₁₄₅ᵀ), free `v_z`. S: reaction `[f_x, f_y, f_z]` (V = E₁₅₆₇₈ᵀ), free `ω`. Fixed, or any locked
/// joint: all six slots are reactions. C (cylindrical, not in the thesis' tables): reaction
/// `[f_x, f_y, τ_x, τ_y]`, free `ω_z` and `v_z` — the revolute and prismatic selectors intersected. (the locking recipe of §6.4 with the full wrench unknown).
pub fn slots(kind: JointType, locked: bool) -> JointSlots {
    if locked {
        return JointSlots { reaction: ALL };
    }
    match kind {
        JointType::Revolute => JointSlots { reaction: &[0, 1, 2, 3, 4] },
        JointType::Prismatic => JointSlots { reaction: &[0, 1, 3, 4, 5] },
        JointType::Spherical => JointSlots { reaction: &[0, 1, 2] },
        JointType::Cylindrical => JointSlots { reaction: &[0, 1, 3, 4] },
        // U: in the turning frame of `universal_alignment`, reaction `[f_x, f_y, f_z, τ_z]`, free ω_x, ω_y
        JointType::Universal => JointSlots { reaction: &[0, 1, 2, 5] },
        _ => JointSlots { reaction: ALL },
    }
}

/// Twist slots along which joint `kind` moves (whatever locking): where `S q̇` lands in J_j, in the
/// order of the joint's velocity coordinates (cylindrical: θ̇ then ḋ).
pub fn motion_slots(kind: JointType) -> &'static [usize] {
    match kind {
        JointType::Revolute => &[2],
        JointType::Prismatic => &[5],
        JointType::Spherical => &[0, 1, 2],
        JointType::Cylindrical => &[2, 5],
        JointType::Universal => &[0, 1],
        _ => &[],
    }
}

/// `q_{J/B}`: the rotation taking the child body frame's z-axis onto the joint axis (revolute, prismatic,
/// cylindrical),
/// identity otherwise. For a spherical joint J = B, so J-frame angular rates are the engine's `v`.
pub fn alignment(kind: JointType, axis: &V3) -> DualQuat {
    match kind {
        JointType::Revolute | JointType::Prismatic | JointType::Cylindrical => rotation(&z_to(axis)),
        _ => DualQuat::ONE,
    }
}

/// `q_{J/B}` of a universal joint (orthogonal unit axes a1, a2) at second angle θ2: J has axes
/// x = R(a2, θ2)ᵀ a1 (the first axis seen from the child), y = a2, z = x × y (the one blocked rotation).
/// J turns relative to the child body as θ2 changes, at rate `universal_frame_rate`; in exchange the joint
/// twist in J is `[θ̇1, θ̇2, 0; 0]`, so Table 6.2-style fixed slots still select the constraints (the
/// thesis' tables have no universal joint).
pub fn universal_alignment(a1: &V3, a2: &V3, theta2: f64) -> DualQuat {
    let x = universal_first_axis(a1, a2, theta2);
    let r = M3::from_columns(&[x, *a2, x.cross(a2)]);
    rotation(&Quat::from_rotation_matrix(&r))
}

/// Angular velocity of a universal joint's J frame relative to its child body, as a J-frame twist
/// `[ρ; 0]`: J turns about its y = a2 axis by −θ2 (it follows R(a2, θ2)ᵀ a1), so ρ = (0, −θ̇2, 0).
pub fn universal_frame_rate(theta2_dot: f64) -> crate::spatial::V6 {
    crate::spatial::V6::new(0.0, -theta2_dot, 0.0, 0.0, 0.0, 0.0)
}

/// The shortest rotation taking ẑ onto the unit vector `u` (half-way quaternion).
fn z_to(u: &V3) -> Quat {
    let z = V3::z();
    let c = z.dot(u);
    if c < -1.0 + 1e-12 {
        return Quat::new(0.0, 1.0, 0.0, 0.0); // π about x
    }
    let q = Quat { w: 1.0 + c, v: z.cross(u) };
    q.scale(1.0 / q.norm())
}

/// Index of the swapped slot: twist `ω_k` ↔ wrench `τ_k`, `v_k` ↔ `f_k` (the swap `^s`).
#[inline]
pub fn swapped(s: usize) -> usize {
    (s + 3) % 6
}
