//! Dual-quaternion multibody dynamics (Valverde 2018, Ch. 5–6): accelerations and every joint's reaction wrench
//! from one linear system solved through the Schur complement of the body block. Cross-checked against the
//! engine's ABA (accelerations) and RNEA (transmitted wrenches) in tests/dqdynamics.rs.

mod body_samples;
mod condition;
pub mod decoupled;
pub mod joints;
mod sixvec;
mod system;
mod tree_solve;
mod workspace;

pub use body_samples::{com_motion, com_wrenches};
pub use sixvec::{ad_in, ad_out, reduce};
pub(crate) use system::solve_system_unchecked;
pub use system::{condition_number, dq_dynamics, dq_dynamics_with, dq_hybrid_dynamics, Solver};
pub use workspace::{DqData, DqDynamics};
