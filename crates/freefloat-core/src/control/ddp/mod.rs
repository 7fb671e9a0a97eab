//! Differential dynamic programming for end-effector control of a free-floating robot (Valverde 2018,
//! ch. 8): the Riccati backward pass of iLQG and of full DDP, the 1.6-factor regularisation schedule, a
//! backtracking line search with the expected-improvement test and the thesis' fixed-α mode, and a
//! feasibility-driven variant for infeasible initial guesses. The solver linearises in the minimal
//! tangent error state of the state manifold (`ActionModel::difference`), so a floating base's pose is
//! integrated on the group in the rollout and never linearised in its redundant coordinates.
//!
//! Files by job: `problem` (the action-model trait), `workspace` (per-node buffers), `backward`,
//! `forward` (rollouts), `regularisation`, `solver` (driver), `costs` (SE(3) exp/log and the free-flyer retraction are `spatial::lie`'s),
//! `robot` (the floating-base robot action model), `step_jacobians` (analytic step Jacobians), `step_hessian` (the
//! second-order terms of full DDP), `fd_step` (the central-difference oracle of the Jacobians for the tests).

pub mod backward;
mod dense;
pub mod forward;
pub mod problem;
pub mod regularisation;
pub mod solver;
pub mod workspace;

pub use problem::{ActionModel, DynamicsHessian, NodeDiff};
pub use regularisation::{RegOptions, Regularisation};
pub use solver::{DdpOptions, IterInfo, Solution, Solver, StopReason, Timings, Variant};
pub use workspace::Workspace;
pub mod costs;
pub mod fd_step;
pub mod mpc;
pub use mpc::{Mpc, MpcOptions, MpcStats, Policy};
pub mod robot;
pub mod step_hessian;
pub mod step_jacobians;
pub use robot::FloatingRobot;
pub mod reference;
