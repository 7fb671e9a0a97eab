//! Rotations: quaternions in the (x, y, z, w) order used by `q`, rotation matrices, the SO(3)
//! exponential/logarithm and the inverse right Jacobian that the Lie-group integrator needs.

use super::{M3, V3};

/// `(sin x, cos x)`, within about one unit in the last place of `f64::sin_cos` (checked in the tests), at half the
/// instructions of the C library's: the joint rotations of forward kinematics take one per revolute joint per
/// evaluation, 7 % of a simulation step (callgrind). `x` is reduced to `r = x - n π/2`, |r| <= π/4, with π/2 in
/// two parts (the first product is exact in the fused multiply-add, so `r` carries one rounding), then the Taylor
/// series of sin and cos on r (their next terms are below 1e-17 there); the quadrant n mod 4 picks the signs.
/// Beyond |x| = 1e6 (where the two-part π/2 would not do) the library's.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    // π/2 = PIO2_HI + PIO2_LO to about 2⁻¹⁰⁷ relative (PIO2_HI: π/2 rounded to double, PIO2_LO: the rest rounded)
    const PIO2_HI: f64 = std::f64::consts::FRAC_PI_2;
    const PIO2_LO: f64 = 6.123233995736766e-17;
    if !(x.abs() < 1e6) {
        return x.sin_cos(); // also inf and NaN
    }
    let n = (x * std::f64::consts::FRAC_2_PI).round_ties_even();
    let r = (-n).mul_add(PIO2_LO, (-n).mul_add(PIO2_HI, x));
    let z = r * r;
    // sin r = r + r z (−1/3! + z (1/5! − …)), to the r¹⁷ term
    let ps = -1.0 / 6.0
        + z * (1.0 / 120.0
            + z * (-1.0 / 5040.0
                + z * (1.0 / 362880.0
                    + z * (-1.0 / 39916800.0
                        + z * (1.0 / 6227020800.0 + z * (-1.0 / 1307674368000.0 + z * (1.0 / 355687428096000.0)))))));
    let sr = r + r * z * ps;
    // cos r = 1 − z/2 + z² (1/4! − …), to the r¹⁶ term; the rounding of w = 1 − z/2 carried into the small part
    let pc = 1.0 / 24.0
        + z * (-1.0 / 720.0
            + z * (1.0 / 40320.0
                + z * (-1.0 / 3628800.0
                    + z * (1.0 / 479001600.0 + z * (-1.0 / 87178291200.0 + z * (1.0 / 20922789888000.0))))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let cr = w + (((1.0 - w) - hz) + z * z * pc);
    match (n as i64) & 3 {
        0 => (sr, cr),
        1 => (cr, -sr),
        2 => (-sr, -cr),
        _ => (-cr, sr),
    }
}

/// Hamilton product of two quaternions stored (x, y, z, w).
#[inline]
pub fn quat_mul(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    let (ax, ay, az, aw) = (a[0], a[1], a[2], a[3]);
    let (bx, by, bz, bw) = (b[0], b[1], b[2], b[3]);
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// Normalise a quaternion (4 entries, any order) in place.
/// # Panics
/// If `q` has fewer than 4 entries (an internal helper: callers pass checked slices).
#[inline]
pub fn quat_normalize(q: &mut [f64]) {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    for x in q.iter_mut().take(4) {
        *x /= n;
    }
}

/// Rotation matrix of a unit quaternion (x, y, z, w).
///
/// # Panics
/// If `q` has fewer than 4 entries (callers pass checked slices).
#[inline]
pub fn rot_from_quat(q: &[f64]) -> M3 {
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz, wx, wy, wz) = (x * y, x * z, y * z, w * x, w * y, w * z);
    M3::new(
        1.0 - 2.0 * (yy + zz),
        2.0 * (xy - wz),
        2.0 * (xz + wy),
        2.0 * (xy + wz),
        1.0 - 2.0 * (xx + zz),
        2.0 * (yz - wx),
        2.0 * (xz - wy),
        2.0 * (yz + wx),
        1.0 - 2.0 * (xx + yy),
    )
}

/// Unit quaternion (x, y, z, w, with w >= 0) of a rotation matrix (Shepperd's method).
pub fn quat_from_rot(r: &M3) -> [f64; 4] {
    let tr = r[(0, 0)] + r[(1, 1)] + r[(2, 2)];
    let q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [(r[(2, 1)] - r[(1, 2)]) / s, (r[(0, 2)] - r[(2, 0)]) / s, (r[(1, 0)] - r[(0, 1)]) / s, 0.25 * s]
    } else if r[(0, 0)] > r[(1, 1)] && r[(0, 0)] > r[(2, 2)] {
        let s = (1.0 + r[(0, 0)] - r[(1, 1)] - r[(2, 2)]).sqrt() * 2.0;
        [0.25 * s, (r[(0, 1)] + r[(1, 0)]) / s, (r[(0, 2)] + r[(2, 0)]) / s, (r[(2, 1)] - r[(1, 2)]) / s]
    } else if r[(1, 1)] > r[(2, 2)] {
        let s = (1.0 + r[(1, 1)] - r[(0, 0)] - r[(2, 2)]).sqrt() * 2.0;
        [(r[(0, 1)] + r[(1, 0)]) / s, 0.25 * s, (r[(1, 2)] + r[(2, 1)]) / s, (r[(0, 2)] - r[(2, 0)]) / s]
    } else {
        let s = (1.0 + r[(2, 2)] - r[(0, 0)] - r[(1, 1)]).sqrt() * 2.0;
        [(r[(0, 2)] + r[(2, 0)]) / s, (r[(1, 2)] + r[(2, 1)]) / s, 0.25 * s, (r[(1, 0)] - r[(0, 1)]) / s]
    };
    let sign = if q[3] < 0.0 { -1.0 } else { 1.0 };
    let mut q = [q[0] * sign, q[1] * sign, q[2] * sign, q[3] * sign];
    quat_normalize(&mut q);
    q
}

/// Quaternion of the rotation vector `phi` (axis * angle): exp(phi/2) in quaternion form.
#[inline]
pub fn quat_exp(phi: &V3) -> [f64; 4] {
    let th2 = phi.norm_squared();
    // Near zero (th < 1e-4, every integrator step of a slowly turning base) sin(th/2)/th and cos(th/2) by their
    // Taylor series, exact to round-off there (the next terms, th⁴/3840 and th⁶/46080, are below 1e-19): no sqrt
    // and no libm call. Otherwise one sincos of half the angle.
    let (k, w) = if th2 < 1e-8 {
        (0.5 - th2 / 48.0, 1.0 - th2 / 8.0 + th2 * th2 / 384.0)
    } else {
        let th = th2.sqrt();
        let (s, c) = (0.5 * th).sin_cos();
        (s / th, c)
    };
    [k * phi.x, k * phi.y, k * phi.z, w]
}

/// Rotation matrix about a unit axis by `angle` (Rodrigues): `R = c 1 + s [a]× + (1 − c) a aᵀ`, entry by entry
/// (the same matrix as `1 + s [a]× + (1 − c)[a]ײ` for a unit axis, without the 3×3 products of skew matrices that
/// made it a tenth of forward kinematics).
#[inline]
pub fn rotation_about_axis(axis: &V3, angle: f64) -> M3 {
    let (s, c) = sin_cos(angle);
    let t = 1.0 - c;
    let (x, y, z) = (axis.x, axis.y, axis.z);
    let (tx, ty, tz) = (t * x, t * y, t * z);
    M3::new(
        c + tx * x,
        tx * y - s * z,
        tx * z + s * y,
        tx * y + s * z,
        c + ty * y,
        ty * z - s * x,
        tx * z - s * y,
        ty * z + s * x,
        c + tz * z,
    )
}

/// The k (0, 1, 2) with `axis` exactly eₖ, if there is one: revolute and prismatic joints about a principal axis
/// (every joint of an URDF arm written the usual way) take the specialised products below.
#[inline(always)]
pub fn principal_axis(axis: &V3) -> Option<usize> {
    match (axis.x, axis.y, axis.z) {
        (x, y, z) if x == 1.0 && y == 0.0 && z == 0.0 => Some(0),
        (x, y, z) if x == 0.0 && y == 1.0 && z == 0.0 => Some(1),
        (x, y, z) if x == 0.0 && y == 0.0 && z == 1.0 => Some(2),
        _ => None,
    }
}

/// `r · R(eₖ, angle)`, `R` as `rotation_about_axis`: a placement's rotation times a rotation about its own k-th
/// axis. Column k of `r` is unchanged and the other two mix by the angle's cosine and sine (R(eₖ) maps
/// eₐ → c eₐ + s e_b and e_b → −s eₐ + c e_b, with (k, a, b) a cyclic order): 12 products instead of
/// Rodrigues' formula and a dense 3×3 product.
#[inline(always)]
pub fn rotate_about_principal_axis(r: &M3, k: usize, angle: f64) -> M3 {
    let (s, c) = sin_cos(angle);
    // one monomorphised body per axis: the column indices are constants, not run-time arithmetic
    match k {
        0 => mix_columns::<1, 2>(r, s, c),
        1 => mix_columns::<2, 0>(r, s, c),
        _ => mix_columns::<0, 1>(r, s, c),
    }
}

#[inline(always)]
fn mix_columns<const A: usize, const B: usize>(r: &M3, s: f64, c: f64) -> M3 {
    let mut out = *r;
    // c eₐ-column + s e_b-column and c e_b-column − s eₐ-column, one fused multiply-add per entry
    for row in 0..3 {
        let (a, b) = (r[(row, A)], r[(row, B)]);
        out[(row, A)] = a.mul_add(c, b * s);
        out[(row, B)] = b.mul_add(c, -(a * s));
    }
    out
}

/// Rotation vector of a rotation matrix (inverse of the exponential), angle in [0, pi].
pub fn so3_log(r: &M3) -> V3 {
    let q = quat_from_rot(r);
    let v = V3::new(q[0], q[1], q[2]);
    let s = v.norm();
    if s < 1e-12 {
        return v * 2.0;
    }
    let th = 2.0 * s.atan2(q[3]);
    v * (th / s)
}

/// Inverse of the right Jacobian of SO(3): if `R(t) = R0 exp(theta(t))` and `R' = R [w]`, then
/// `theta' = Jr(theta)^-1 w`. This is the dexp⁻¹ correction that makes Runge-Kutta on the rotation
/// group fourth order (Munthe-Kaas); without it RK4 on the base attitude is only second order.
pub fn so3_right_jacobian_inv(theta: &V3, w: &V3) -> V3 {
    let th2 = theta.norm_squared();
    let tw = theta.cross(w);
    let ttw = theta.cross(&tw);
    // coefficient of [theta]^2: 1/th^2 - (1 + cos th)/(2 th sin th), series 1/12 + th^2/720 near 0.
    let c2 = if th2 < 1e-6 {
        1.0 / 12.0 + th2 / 720.0
    } else {
        let th = th2.sqrt();
        1.0 / th2 - (1.0 + th.cos()) / (2.0 * th * th.sin())
    };
    w + tw * 0.5 + ttw * c2
}

/// URDF roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll).
pub fn rpy_to_rot(rpy: &V3) -> M3 {
    let (sr, cr) = rpy.x.sin_cos();
    let (sp, cp) = rpy.y.sin_cos();
    let (sy, cy) = rpy.z.sin_cos();
    M3::new(
        cy * cp,
        cy * sp * sr - sy * cr,
        cy * sp * cr + sy * sr,
        sy * cp,
        sy * sp * sr + cy * cr,
        sy * sp * cr - cy * sr,
        -sp,
        cp * sr,
        cp * cr,
    )
}

/// Inverse of `rpy_to_rot` (pitch in [-pi/2, pi/2]).
pub fn rot_to_rpy(r: &M3) -> V3 {
    let pitch = (-r[(2, 0)]).clamp(-1.0, 1.0).asin();
    if (r[(2, 0)].abs() - 1.0).abs() < 1e-12 {
        // Gimbal lock: only roll ± yaw is defined; put it all in yaw.
        let yaw = (-r[(0, 1)]).atan2(r[(1, 1)]);
        return V3::new(0.0, pitch, yaw);
    }
    V3::new(r[(2, 1)].atan2(r[(2, 2)]), pitch, r[(1, 0)].atan2(r[(0, 0)]))
}

#[cfg(test)]
mod tests {
    use super::sin_cos;

    /// Distance in units in the last place between two finite doubles of the same sign (0 if equal).
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        let scale = a.abs().max(b.abs());
        // below 1e-300 the spacing is not what matters: count in the spacing at the result's magnitude 1
        ((a - b).abs() / (f64::EPSILON * scale.max(1e-300))).ceil() as u64
    }

    #[test]
    fn sin_cos_is_the_library_s_to_about_one_ulp() {
        // a deterministic spread: tiny, near multiples of π/2, up to the cut-over at 1e6, and beyond it
        let mut xs = vec![0.0, -0.0, 1e-300, 1e-20, 1e-9, 0.1, 0.5, 1.0, 2.0, 3.0, 1e3, 12345.678, 999_999.9, 1e6, 3e7];
        for k in -64..=64 {
            let m = k as f64 * std::f64::consts::FRAC_PI_2;
            xs.extend([m, m + 1e-12, m - 1e-7, m + 0.3, m - 0.785]);
        }
        let mut u: u64 = 0x9E37_79B9_7F4A_7C15;
        for j in 0..200_000 {
            u ^= u << 13;
            u ^= u >> 7;
            u ^= u << 17;
            let f = (u >> 11) as f64 / (1u64 << 53) as f64; // [0, 1)
            let span = [1.0, 10.0, 1e3, 1e6][j % 4];
            xs.push((2.0 * f - 1.0) * span);
        }
        let mut worst = 0;
        for &x in &xs {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            // absolute against 1 where the value is small (near a zero of sin or cos the argument's own rounding
            // decides the last bits), relative elsewhere
            let e = ulps(s, s0)
                .min(((s - s0).abs() / f64::EPSILON).ceil() as u64)
                .max(ulps(c, c0).min(((c - c0).abs() / f64::EPSILON).ceil() as u64));
            assert!(e <= 2, "x = {x:e}: ({s:e}, {c:e}) against ({s0:e}, {c0:e})");
            worst = worst.max(e);
        }
        assert!(worst >= 1, "the comparison compares");
        assert!(sin_cos(f64::NAN).0.is_nan() && sin_cos(f64::INFINITY).1.is_nan());
    }
}
