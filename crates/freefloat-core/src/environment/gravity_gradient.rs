//! Gravity gradient on one body relative to the free-falling frame origin: the tidal force on its centre of
//! mass (the differential point-mass gravity) and the gravity-gradient torque about it (Valverde 2018, (2.63)
//! in the dual form (2.67)).

use crate::dualquat::orbital::{gravity_gradient_of, tidal_acceleration};
use crate::dualquat::DualQuat;
use crate::spatial::{M3, V3};

/// The body's gravity-gradient dual force about its CoM in body axes, `f + ετ` (2.39):
/// `f = C^T m [g(R + r) − g(R)]` (the real part, `M ⋆ (a + ε0)` of (2.65) with the differential acceleration)
/// and `τ = 3μ d × (Ī d)/‖d‖⁵` with `d = C^T (R + r)` the body's position from the central body in body axes
/// (the dual part, (2.67)).
///
/// `rot` rotates body axes to inertial axes, `r` is the body's CoM from the frame origin and `big_r` the frame
/// origin from the central body (both inertial axes); `mass`, `i_com` are the body's.
pub fn wrench(rot: &M3, big_r: &V3, r: &V3, mass: f64, i_com: &M3, mu: f64) -> DualQuat {
    let f_b = rot.tr_mul(&(tidal_acceleration(big_r, r, mu) * mass));
    let d_b = rot.tr_mul(&(big_r + r));
    let tau = gravity_gradient_of(i_com, &d_b, mu);
    DualQuat::vector(&f_b, &tau.d.v)
}
