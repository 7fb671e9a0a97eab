//! freefloat-core: the numerical engine of freefloat — floating-base rigid-body trees for space
//! robots. Pure Rust, no Python. See docs/architecture.md for the layout and conventions.
//!
//! Pattern (Pinocchio/MuJoCo): a `Model` is an immutable description, a `Data` holds every work
//! buffer, algorithms are free functions `algo(&model, &mut data, ...)` that allocate nothing.

// `!(x > 0.0)` is how this crate rejects NaN along with non-positive values; and loops index several
// joint-aligned arrays at once, which reads better than zipping them.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]
#![warn(missing_docs)]

/// The one argument check of every public entry point (sizes, finiteness, quaternions, Data ↔ Model).
pub mod check;
/// Configuration-space geometry (tangent rates, retraction, dexp⁻¹) used by the integrators.
pub mod config;
/// Controllers and on-line estimators (Valverde 2018, ch. 4, 8, 9).
pub mod control;
/// `Data`: every work buffer of the algorithms, allocated once per model.
pub mod data;
/// Dual-quaternion multibody dynamics with joint reaction wrenches (Valverde 2018, ch. 5–6).
pub mod dqdynamics;
/// Quaternion and dual-quaternion algebra, poses, kinematics and constraints (Valverde 2018, ch. 2–3).
pub mod dualquat;
/// RNEA, CRBA, ABA and hybrid ABA (Featherstone, body coordinates).
pub mod dynamics;
/// The orbital environment: central-body gravity and orbit, gravity gradient, J2, constant disturbance.
pub mod environment;
/// The engine's error type.
pub mod error;
/// Least squares, RLS and the modified RLS for inertial-parameter identification.
pub mod estimation;
/// Exciting-trajectory design: zero-momentum base response and regressor rows (Naveen, Shah, Misra, Sec. V).
pub mod excitation;
/// The progress/interrupt hook long routines poll (Ctrl-C from the bindings, progress bars).
pub mod interrupt;
/// Forward kinematics, velocities, accelerations, centre of mass, momentum, energy, Jacobians.
pub mod kinematics;
/// `Model`: the immutable rigid-body tree, its builder and readers.
pub mod model;
/// Post-capture scenario of Zhang, Yue, Yuan 2020: thrust and attitude laws, RK4 simulation.
pub mod postcapture;
/// Momentum and inverse-dynamics regressors, linear in the standard inertial parameters.
pub mod regressors;
/// The one explicit Runge-Kutta stage loop (Runge-Kutta-Munthe-Kaas on a group) and its tableaux.
pub mod rk;
/// Sensor models (gyro, star tracker, encoders, tachometers, F/T) and `measure`: a run turned into telemetry.
pub mod sensors;
/// Lie-group Runge-Kutta simulation (RK4, Dormand-Prince 5(4)) with inputs and trajectories.
pub mod sim;
/// SE(3), spatial motion and force vectors, rigid-body inertia, SO(3) helpers; `spatial::lie`, the one copy of the
/// SO(3)/SE(3) exponentials, logarithms and Jacobians.
pub mod spatial;
/// How many threads the parallel passes may use (the process's cores, read once).
pub mod threads;
/// The record a simulation returns (`sim::Trajectory`).
pub mod trajectory;

pub use data::Data;
pub use error::{FfError, Result};
pub use model::{JointType, Model};
