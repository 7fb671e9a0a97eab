//! Joint types, their coordinate sizes, their transform and their motion subspace.
//!
//! Every joint's motion subspace is constant in the child (= joint) frame, including the free and
//! planar base joints because their velocities are expressed in the base frame (Pinocchio's
//! convention) — except the universal joint's, whose first column turns with its second angle. So
//! `S` is computed once per model (`Model::subspaces`), the universal joint's column is refreshed by
//! forward kinematics (`Data::s`), and only the universal joint has a bias acceleration `Ṡ q̇`
//! (`universal_bias`).

use crate::spatial::{quat_normalize, rot_from_quat, rotation_about_axis, Se3, M3, M6, V3};

/// Joint types: three for the base (free, planar, fixed), six below it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    /// 6-DoF base: q = [p; quat xyzw], v = [lin; ang] in the base frame.
    Free,
    /// Base moving in the inertial x-y plane: q = [x, y, yaw], v = [vx, vy, yaw rate] in the base frame.
    Planar,
    /// Base welded to the inertial frame.
    FixedBase,
    /// Rotation about the unit axis `a` (joint frame): q = v = [θ] (rad, rad/s).
    Revolute,
    /// Translation along the unit axis `a`: q = v = [d] (m, m/s).
    Prismatic,
    /// Ball joint: q = quat xyzw of the child relative to the joint frame, v = angular velocity (child frame).
    Spherical,
    /// Rotation about and translation along the same axis: q = v = [θ, d] (child frame). Its motion
    /// subspace [[0, a]; [a, 0]] is constant in the child frame because `a` is invariant under the
    /// rotation about itself (Featherstone, RBDA Table 4.1, "cylindrical").
    Cylindrical,
    /// Cardan joint: q = v = [θ1, θ2], rotation θ1 about axis a1, then θ2 about axis a2 of the
    /// intermediate frame (R = R(a1, θ1) R(a2, θ2); a1, a2 not parallel). Child-frame subspace
    /// [0 0; R(a2, θ2)ᵀa1 a2] (Featherstone, RBDA Table 4.1, "universal"): NOT constant.
    Universal,
    /// Child welded to the parent (no coordinates; the child stays a body with its own parameters).
    Fixed,
}

impl JointType {
    /// Number of configuration coordinates (a quaternion counts 4).
    pub fn nq(self) -> usize {
        match self {
            JointType::Free => 7,
            JointType::Planar => 3,
            JointType::Spherical => 4,
            JointType::Cylindrical | JointType::Universal => 2,
            JointType::Revolute | JointType::Prismatic => 1,
            JointType::FixedBase | JointType::Fixed => 0,
        }
    }
    /// Number of velocity coordinates (degrees of freedom).
    pub fn nv(self) -> usize {
        match self {
            JointType::Free => 6,
            JointType::Planar | JointType::Spherical => 3,
            JointType::Cylindrical | JointType::Universal => 2,
            JointType::Revolute | JointType::Prismatic => 1,
            JointType::FixedBase | JointType::Fixed => 0,
        }
    }
    /// Whether this joint type attaches the base to the inertial frame (free, planar, fixed base).
    pub fn is_base(self) -> bool {
        matches!(self, JointType::Free | JointType::Planar | JointType::FixedBase)
    }
    /// The name used in files and in the Python API.
    pub fn name(self) -> &'static str {
        match self {
            JointType::Free => "free",
            JointType::Planar => "planar",
            JointType::FixedBase => "fixed",
            JointType::Revolute => "revolute",
            JointType::Prismatic => "prismatic",
            JointType::Spherical => "spherical",
            JointType::Cylindrical => "cylindrical",
            JointType::Universal => "universal",
            JointType::Fixed => "fixed",
        }
    }
    /// Base joint type from its file/Python name (`free`/`floating`, `planar`, `fixed`).
    pub fn base_from_name(s: &str) -> Option<JointType> {
        match s {
            "free" | "floating" => Some(JointType::Free),
            "planar" => Some(JointType::Planar),
            "fixed" => Some(JointType::FixedBase),
            _ => None,
        }
    }
    /// Joint type below the base from its file name (URDF `continuous` = revolute, `ball` = spherical, `cardan` = universal).
    pub fn child_from_name(s: &str) -> Option<JointType> {
        match s {
            "revolute" | "continuous" => Some(JointType::Revolute),
            "prismatic" => Some(JointType::Prismatic),
            "spherical" | "ball" => Some(JointType::Spherical),
            "cylindrical" => Some(JointType::Cylindrical),
            "universal" | "cardan" => Some(JointType::Universal),
            "fixed" => Some(JointType::Fixed),
            _ => None,
        }
    }
    /// Whether the joint is defined by a unit axis (which the model builder normalises).
    pub fn has_axis(self) -> bool {
        matches!(self, JointType::Revolute | JointType::Prismatic | JointType::Cylindrical | JointType::Universal)
    }
    /// Whether the joint's q holds a quaternion that must stay unit (its offset inside the joint's q).
    pub fn quaternion_offset(self) -> Option<usize> {
        match self {
            JointType::Free => Some(3),
            JointType::Spherical => Some(0),
            _ => None,
        }
    }

    /// Motion subspace `S` (6 × nv, stored in a 6×6 with the unused columns zero), child frame, at
    /// q = 0 (for a universal joint; every other joint's is the same at all q). `axis2` is the
    /// universal joint's second axis (ignored otherwise).
    pub fn subspace(self, axis: &V3, axis2: &V3) -> M6 {
        let mut s = M6::zeros();
        match self {
            JointType::Free => s = M6::identity(),
            JointType::Planar => {
                s[(0, 0)] = 1.0;
                s[(1, 1)] = 1.0;
                s[(5, 2)] = 1.0;
            }
            JointType::Spherical => {
                s[(3, 0)] = 1.0;
                s[(4, 1)] = 1.0;
                s[(5, 2)] = 1.0;
            }
            JointType::Revolute => s.fixed_view_mut::<3, 1>(3, 0).copy_from(axis),
            JointType::Prismatic => s.fixed_view_mut::<3, 1>(0, 0).copy_from(axis),
            JointType::Cylindrical => {
                // column 0: rotation θ about a; column 1: translation d along a (q order)
                s.fixed_view_mut::<3, 1>(3, 0).copy_from(axis);
                s.fixed_view_mut::<3, 1>(0, 1).copy_from(axis);
            }
            JointType::Universal => {
                s.fixed_view_mut::<3, 1>(3, 0).copy_from(axis);
                s.fixed_view_mut::<3, 1>(3, 1).copy_from(axis2);
            }
            JointType::FixedBase | JointType::Fixed => {}
        }
        s
    }

    /// Placement of the child frame in the joint's rest frame for coordinates `q` (len nq).
    /// Quaternions are used as given: callers normalise `q` once on entry.
    ///
    /// # Panics
    /// If the slice is shorter than this joint's nq (a per-joint helper of the hot loops; the algorithms
    /// pass it the joint's sub-slice of a checked `q`).
    #[inline]
    pub fn transform(self, axis: &V3, axis2: &V3, q: &[f64]) -> Se3 {
        match self {
            JointType::Universal => {
                Se3::new(rotation_about_axis(axis, q[0]) * rotation_about_axis(axis2, q[1]), V3::zeros())
            }
            JointType::Revolute => Se3::new(rotation_about_axis(axis, q[0]), V3::zeros()),
            JointType::Prismatic => Se3::new(M3::identity(), axis * q[0]),
            // Rotation and translation along one axis commute, so their order does not matter.
            JointType::Cylindrical => Se3::new(rotation_about_axis(axis, q[0]), axis * q[1]),
            JointType::Free => Se3::new(rot_from_quat(&q[3..7]), V3::new(q[0], q[1], q[2])),
            JointType::Planar => {
                let (s, c) = crate::spatial::trig::sin_cos(q[2]);
                Se3::new(M3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0), V3::new(q[0], q[1], 0.0))
            }
            JointType::Spherical => Se3::new(rot_from_quat(&q[0..4]), V3::zeros()),
            JointType::FixedBase | JointType::Fixed => Se3::identity(),
        }
    }

    /// Neutral coordinates (identity quaternions, zeros elsewhere).
    ///
    /// # Panics
    /// If the slice is shorter than this joint's nq (a per-joint helper of the hot loops; the algorithms
    /// pass it the joint's sub-slice of a checked `q`).
    pub fn neutral(self, out: &mut [f64]) {
        out.fill(0.0);
        if let Some(k) = self.quaternion_offset() {
            out[k + 3] = 1.0;
        }
    }

    /// Normalise the quaternion part of this joint's q in place.
    ///
    /// # Panics
    /// If the slice is shorter than this joint's nq (a per-joint helper of the hot loops; the algorithms
    /// pass it the joint's sub-slice of a checked `q`).
    pub fn normalize(self, q: &mut [f64]) {
        if let Some(k) = self.quaternion_offset() {
            quat_normalize(&mut q[k..k + 4]);
        }
    }
}

/// Angular part of a universal joint's first subspace column in the child frame: `R(a2, θ2)ᵀ a1`.
#[inline]
pub fn universal_first_axis(a1: &V3, a2: &V3, theta2: f64) -> V3 {
    rotation_about_axis(a2, -theta2) * a1
}

/// A universal joint's bias acceleration `Ṡ q̇` in the child frame, `[0; θ̇1 θ̇2 (R(a2, θ2)ᵀa1 × a2)]`
/// (RBDA Table 4.1 `c_J`): from `d/dt R(a2, θ2)ᵀ = −θ̇2 [a2]× R(a2, θ2)ᵀ`. `s1` is the first
/// column's angular part (`universal_first_axis`).
#[inline]
pub fn universal_bias(s1: &V3, a2: &V3, qd1: f64, qd2: f64) -> V3 {
    s1.cross(a2) * (qd1 * qd2)
}

/// Optional joint limits (from URDF/YAML); `None` where the file gives none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointLimits {
    /// Lower position limit (rad or m).
    pub lower: Option<f64>,
    /// Upper position limit (rad or m).
    pub upper: Option<f64>,
    /// Velocity limit (rad/s or m/s).
    pub velocity: Option<f64>,
    /// Effort limit (N m or N).
    pub effort: Option<f64>,
}
