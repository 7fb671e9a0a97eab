//! Spatial algebra: rigid transforms, motion and force 6-vectors, rigid-body inertia.
//!
//! Convention (ARCHITECTURE.md): spatial vectors are `[linear; angular]`. A `Motion` is a twist
//! (velocity of the frame origin, angular velocity); a `Force` is a wrench (force, moment about
//! the frame origin). Both are expressed in some frame's axes; `Se3` moves them between frames.

mod inertia;
pub mod lanes;
pub mod lie;
mod se3;
pub(crate) mod so3;
pub mod trig;
mod vectors;

pub use inertia::{m6_mul_motion, transform_inertia_to_parent, Inertia};
pub use lie::{quat_exp, so3_log, so3_right_jacobian_inv};
pub use se3::Se3;
pub use so3::{
    principal_axis, quat_from_rot, quat_mul, quat_normalize, rot_from_quat, rot_to_rpy, rotate_about_principal_axis,
    rotation_about_axis, rotation_about_axis_sc, rpy_to_rot,
};
pub(crate) use vectors::cross as cross_fma;
pub use vectors::{Force, Motion};

/// 3-vector (f64).
pub type V3 = nalgebra::Vector3<f64>;
/// 3×3 matrix (f64).
pub type M3 = nalgebra::Matrix3<f64>;
/// 6×6 matrix (f64), e.g. a spatial inertia or a motion subspace padded to 6 columns.
pub type M6 = nalgebra::Matrix6<f64>;
/// 6-vector (f64), `[linear; angular]`.
pub type V6 = nalgebra::Vector6<f64>;

/// Skew-symmetric matrix: `skew(a) * b == a × b`.
#[inline]
pub fn skew(a: &V3) -> M3 {
    M3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}
