//! The differential J2 force on one body relative to the frame origin, whose orbit already carries the J2
//! acceleration: `m [a_J2(R + r) − a_J2(R)]` (Valverde 2018, (2.64) and (2.66)). The J2 part of the
//! gravity-gradient torque (≈ J2 (Re/R)² of the point-mass one, 1e-3) is not modelled.

use crate::dualquat::orbital::{j2_acceleration, j2_acceleration_inv};
use crate::dualquat::DualQuat;
use crate::spatial::{M3, V3};

use super::orbit::CentralBody;

/// `a_J2(R)` at the frame origin R: the same for every body of one evaluation, so [`wrench`] takes it computed.
pub fn at_origin(big_r: &V3, c: &CentralBody) -> V3 {
    j2_acceleration(big_r, c.mu, c.j2, c.radius)
}

/// The body's differential J2 dual force `M ⋆ (a + ε0)` (2.66) about its CoM in body axes, from `r` (its CoM from
/// the frame origin R, inertial axes), `inv_d` = `1/‖R + r‖` and `a_origin` = [`at_origin`]`(R)`.
///
/// The plain difference loses about ‖R‖/‖r‖ of the J2 acceleration's 16 digits (≈1e-2 m/s² at low Earth
/// orbit), leaving ~1e-11 relative accuracy on a differential term of ~1e-9 m/s² per metre of offset: far
/// below anything it acts on.
pub fn wrench(rot: &M3, big_r: &V3, r: &V3, inv_d: f64, a_origin: &V3, mass: f64, c: &CentralBody) -> DualQuat {
    let da = j2_acceleration_inv(&(big_r + r), inv_d, c.mu, c.j2, c.radius) - a_origin;
    DualQuat::vector(&rot.tr_mul(&(da * mass)), &V3::zeros())
}
