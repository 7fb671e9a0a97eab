//! freefloat-core: the numerical engine of freefloat — floating-base rigid-body trees for space
//! robots. Pure Rust, no Python. See docs/architecture.md for the layout and conventions.
//!
//! Pattern (Pinocchio/MuJoCo): a `Model` is an immutable description, a `Data` holds every work
//! buffer, algorithms are free functions `algo(&model, &mut data, ...)` that allocate nothing.

// `!(x > 0.0)` is how this crate rejects NaN along with non-positive values; and loops index several
// joint-aligned arrays at once, which reads better than zipping them.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod check;
pub mod config;
pub mod data;
pub mod dqdynamics;
pub mod dualquat;
pub mod dynamics;
pub mod error;
pub mod estimation;
pub mod excitation;
pub mod kinematics;
pub mod model;
pub mod postcapture;
pub mod regressors;
pub mod sim;
pub mod spatial;

pub use data::Data;
pub use error::{FfError, Result};
pub use model::{JointType, Model};
