//! Adaptive dual-quaternion pose tracking of a rigid spacecraft with concurrent learning of its mass and
//! inertia (Valverde 2018, ch. 4). The plant is the relative pose-error dynamics (2.58) of the body frame B
//! with respect to a desired frame D; the controller is the law (4.9)/(4.25) with the swap typo of its last
//! term corrected; the estimator is the update law (4.13) with cumulative P, Q (continuous CL, Theorem 1) or
//! (4.29) with a stored stack of samples (discrete CL, Theorem 2); α = 0 is the baseline of Filipe and
//! Tsiotras.
//!
//! - `gains`: K_r, K_q, K_v, K_ω, K_i (4.11)–(4.12);
//! - `tracking`: error variables e, ė, s (4.10);
//! - `law`: control law, update law, Lyapunov function (4.17) and its derivative (4.21);
//! - `stack`: the discrete-CL data stack and its selection rules;
//! - `reference`: the desired frame's twist (harmonics or tables);
//! - `closed_loop`, `simulate`: the simulated closed loop (RK4 or Dormand–Prince) with histories;
//! - `controller`: the controller as an object for a user's own loop.
//!
//! Parameter vectors are `v(M) = [I11, I12, I13, I22, I23, I33, m]` (§4.1), as in `dualquat::regressor`.

pub mod closed_loop;
pub mod controller;
pub mod gains;
pub mod law;
pub mod reference;
pub mod simulate;
pub mod stack;
#[cfg(test)]
mod tests;
pub mod tracking;

pub use closed_loop::{Learning, Setup};
pub use controller::AdaptivePoseController;
pub use gains::{Gains, M7};
pub use law::LawForm;
pub use reference::{Harmonic3, Reference, Table};
pub use simulate::{simulate, Integrator, Run, RunOptions};
pub use stack::{DataStack, Selection};
