//! Controllers and on-line estimators of Valverde 2018 (Georgia Tech PhD thesis): adaptive dual-quaternion pose
//! tracking with concurrent learning (ch. 4), differential dynamic programming for the end effector (ch. 8) and
//! concurrent-learning mass estimation (ch. 9). Each lives in its own submodule; the numbers they share (the
//! dual-inertia regressor) are in `dualquat`.

pub mod adaptive;
/// Differential dynamic programming (Valverde 2018, ch. 8): Riccati backward pass, regularisation, line
/// search, the feasibility-driven variant, costs and the floating-base robot action model.
pub mod ddp;
