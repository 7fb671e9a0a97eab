//! Dual-quaternion multibody dynamics (seed 003, Ch. 5–6): accelerations and every joint's reaction wrench
//! from one linear system solved through the Schur complement of the body block. Cross-checked against the
//! engine's ABA (accelerations) and RNEA (transmitted wrenches) in tests/dqdynamics.rs.

pub mod decoupled;
pub mod joints;
mod system;

pub use system::{
    ad_in, ad_out, condition_number, dq_dynamics, dq_dynamics_with, dq_hybrid_dynamics, reduce, DqDynamics, Solver,
};
