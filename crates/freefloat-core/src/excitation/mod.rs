//! Exciting-trajectory design (Naveen, Shah, Misra, Sec. V): the numbers the design loop needs, fast.
//!
//! The design optimises joint trajectories of a free-floating robot so that the momentum regressor of the
//! minimal parameters is well conditioned (eq. 32). Evaluating a candidate needs the base motion it causes,
//! which comes from the momentum model with *guessed* inertial parameters: with zero total momentum the base
//! twist is fixed by the joint angles and rates alone (`response`). Along that motion the minimal regressor
//! rows are stacked and the objective formed from their Gram matrix (`objective`). Joint trajectories arrive
//! sampled on a uniform grid, so any parametrisation (cycloids, Fourier series) is evaluated the same way.

mod objective;
mod response;

pub use objective::{evaluate, evaluate_batch, evaluate_batch_interruptible, Evaluation, ObjectiveSpec};
pub use response::{base_twist_zero_momentum, excitation_rows, ExcitationRows, JointPath};
