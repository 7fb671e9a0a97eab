//! Dual-quaternion toolkit (Valverde 2018, Ch. 2–3): quaternions, dual quaternions, poses, screws, twists and
//! wrenches, dual inertia and Newton–Euler, forward kinematics and the convex pose constraints.
//!
//! Inside this module dual quaternions are 8-vectors `[real (w,x,y,z), dual (w,x,y,z)]` (the thesis'
//! order, (3.26)); the engine's `(x, y, z, w)` quaternions and `Se3` placements are converted at the edges
//! (`Quat::from_xyzw`, `DualQuat::from_se3`, `from_pose_xyzw`). A twist is `ω + ε v`, a wrench `f + ε τ`;
//! the engine's `Motion`/`Force` are `[linear; angular]`, converted by `pose::twist_from_motion` etc.
//! Unit-ness means `q q* = 1`, never `‖q‖ = 1` (a unit pose has `‖q‖² = 1 + ‖r‖²/4`).

pub mod constraints;
mod dual_quaternion;
pub mod inertia;
pub mod kinematics;
pub mod orbital;
pub mod pose;
mod quaternion;
pub mod regressor;
pub mod screw;

pub use dual_quaternion::{swap_matrix, DualQuat, M8, UNIT_TOL, V8};
pub use inertia::DualInertia;
pub use quaternion::{Quat, M4, V4};
pub use regressor::{apply_params, body_regressor, h_vector, params, r_matrix, relative_regressor, M87, V7};
pub use screw::{exp, log, screw_exp, screw_log, Screw};
