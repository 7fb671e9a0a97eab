//! Gravity gradient on one body relative to the free-falling frame origin: the tidal force on its centre of
//! mass (the differential point-mass gravity) and the gravity-gradient torque about it (Valverde 2018, (2.63)
//! in the dual form (2.67)).

use crate::dualquat::orbital::{gravity_gradient_torque, tidal_acceleration_from};
use crate::spatial::{M3, V3};

/// The body's gravity-gradient dual force about its CoM in body axes, `f + ετ` (2.39), as (f, τ):
/// `f = C^T m [g(R + r) − g(R)]` (the real part, `M ⋆ (a + ε0)` of (2.65) with the differential acceleration)
/// and `τ = 3μ d × (Ī d)/‖d‖⁵` with `d = C^T (R + r)` the body's position from the central body in body axes
/// (the dual part, (2.67)).
///
/// `rot` rotates body axes to inertial axes, `r` is the body's CoM from the frame origin and `big_r` the frame
/// origin from the central body (both inertial axes), `inv_r2` = 1/‖R‖² (the same for every body of one
/// evaluation); `mass`, `i_com` are the body's. One square root and one division give both parts' powers of
/// ‖R + r‖ (‖C^T d‖ = ‖d‖).
pub fn wrench(rot: &M3, big_r: &V3, inv_r2: f64, r: &V3, mass: f64, i_com: &M3, mu: f64) -> (V3, V3) {
    let d = big_r + r;
    let inv_d = 1.0 / d.norm_squared().sqrt();
    let mu_d3 = mu * inv_d * inv_d * inv_d;
    let f_b = rot.tr_mul(&(tidal_acceleration_from(big_r, r, inv_r2, mu_d3) * mass));
    let d_b = rot.tr_mul(&d);
    (f_b, gravity_gradient_torque(i_com, &d_b, 3.0 * mu_d3 * inv_d * inv_d))
}
