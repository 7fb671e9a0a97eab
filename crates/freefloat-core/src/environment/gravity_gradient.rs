//! Gravity gradient on one body relative to the free-falling frame origin: the tidal force on its centre of
//! mass (the differential point-mass gravity) and the gravity-gradient torque about it (Valverde 2018, (2.63)
//! in the dual form (2.67)).

use crate::dualquat::orbital::{gravity_gradient_torque, tidal_from_roots};
use crate::spatial::{M3, V3};

/// What every body of one evaluation shares: the frame origin's position `R` from the central body (inertial
/// axes), `1/‖R‖²`, `1/‖R‖` and the central body's μ.
#[derive(Clone, Copy, Debug)]
pub struct Origin {
    /// The frame origin from the central body's centre, inertial axes.
    pub big_r: V3,
    /// `1/‖R‖²`.
    pub inv_r2: f64,
    /// `1/‖R‖`.
    pub inv_r: f64,
    /// The central body's gravitational parameter.
    pub mu: f64,
}

impl Origin {
    /// The shared quantities of the origin `big_r` in the field of `mu`.
    pub fn new(big_r: V3, mu: f64) -> Self {
        let inv_r2 = 1.0 / big_r.norm_squared();
        Origin { big_r, inv_r2, inv_r: inv_r2.sqrt(), mu }
    }
}

/// The body's gravity-gradient dual force about its CoM in body axes, `f + ετ` (2.39), as (f, τ):
/// `f = C^T m [g(R + r) − g(R)]` (the real part, `M ⋆ (a + ε0)` of (2.65) with the differential acceleration) and
/// `τ = 3μ d × (Ī d)/‖d‖⁵` with `d = C^T (R + r)` the body's position from the central body in body axes (the dual
/// part, (2.67)).
///
/// `rot` rotates body axes to inertial axes, `r` is the body's CoM from the frame origin (inertial axes), `x` and
/// `roots` its [`tidal_x`](crate::dualquat::orbital::tidal_x) and
/// [`tidal_roots`](crate::dualquat::orbital::tidal_roots); `mass`, `i_com` are the body's. Both parts' powers of
/// ‖R + r‖ come from those roots (‖C^T d‖ = ‖d‖).
pub fn wrench(rot: &M3, o: &Origin, r: &V3, x: f64, roots: (f64, f64), mass: f64, i_com: &M3) -> (V3, V3) {
    let (a, inv_d) = tidal_from_roots(&o.big_r, r, x, roots, o.inv_r, o.mu);
    let f_b = rot.tr_mul(&(a * mass));
    let d_b = rot.tr_mul(&(o.big_r + r));
    let inv_d2 = inv_d * inv_d;
    (f_b, gravity_gradient_torque(i_com, &d_b, 3.0 * o.mu * inv_d2 * inv_d2 * inv_d))
}
