//! The post-capture scenario of Zhang, Yue, Yuan 2020 (Sec. V; the choices where the paper is silent are
//! listed in docs/postcapture.md): a free-floating base with thrusters, an arm, and a target rigidly grasped at the end
//! effector, driven by
//! - bounded momentum damping by the base thrusters (eq. 40), and
//! - base attitude stabilisation realised by the arm (eq. 39): at every instant the joint
//!   accelerations are solved from the base's angular rows of the equations of motion so that the
//!   base attitude follows `α = −K_D ω − K_P φ`, plus a null-space excitation.
//!
//! The simulation is the engine's RK4 on the configuration group; the controller runs inside every
//! Runge-Kutta stage (continuous control, our choice: the paper does not say). Identification is done on the recorded
//! trajectory: the identification equations (eqs. 11-33, and the standard-parameter rows) are
//! `equations`, the estimators `estimation::{Rls, ModifiedRls}`, the orchestration Python
//! (`freefloat.postcapture`).

pub mod capture;
mod control;
pub mod equations;
pub mod momentum_point;
mod simulate;

pub use capture::{capture_impact, CaptureImpact};
pub use control::{saturate, PostcaptureControl};
pub use momentum_point::momentum_transport;
pub use simulate::{simulate_postcapture, simulate_postcapture_with, thruster_base_wrench};
