//! Rotations: quaternions in the (x, y, z, w) order used by `q`, rotation matrices, the SO(3)
//! axis-angle rotations and roll-pitch-yaw angles. The exponential, logarithm and Jacobians are in `lie`.

use super::lanes::Real;
use super::{trig, M3, V3};

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
    let r = quat_rotation_rows(q[0], q[1], q[2], q[3]);
    M3::new(r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2])
}

/// The rows of the rotation matrix of the unit quaternion (x, y, z, w), for one sample or four side by side
/// (the one copy of the formula: `rot_from_quat` and the four-sample kinematics).
#[inline(always)]
pub(crate) fn quat_rotation_rows<T: Real>(x: T, y: T, z: T, w: T) -> [[T; 3]; 3] {
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz, wx, wy, wz) = (x * y, x * z, y * z, w * x, w * y, w * z);
    let (one, two) = (T::splat(1.0), T::splat(2.0));
    [
        [one - two * (yy + zz), two * (xy - wz), two * (xz + wy)],
        [two * (xy + wz), one - two * (xx + zz), two * (yz - wx)],
        [two * (xz - wy), two * (yz + wx), one - two * (xx + yy)],
    ]
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

/// Rotation matrix about a unit axis by `angle` (Rodrigues): `R = c 1 + s [a]× + (1 − c) a aᵀ`, entry by entry
/// (the same matrix as `1 + s [a]× + (1 − c)[a]ײ` for a unit axis, without the 3×3 products of skew matrices that
/// made it a tenth of forward kinematics). The sine and cosine are the engine's (`trig::sin_cos`), the same bits as
/// the batched ones of the kinematic sweeps.
#[inline]
pub fn rotation_about_axis(axis: &V3, angle: f64) -> M3 {
    let (s, c) = trig::sin_cos(angle);
    rotation_about_axis_sc(axis, s, c)
}

/// `rotation_about_axis` from the angle's sine `s` and cosine `c`.
#[inline]
pub fn rotation_about_axis_sc(axis: &V3, s: f64, c: f64) -> M3 {
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

/// `r · R(eₖ, θ)` from θ's sine `s` and cosine `c`, `R` as `rotation_about_axis`: a placement's rotation times a
/// rotation about its own k-th axis. Column k of `r` is unchanged and the other two mix by the angle's cosine and
/// sine (R(eₖ) maps eₐ → c eₐ + s e_b and e_b → −s eₐ + c e_b, with (k, a, b) a cyclic order): 12 products instead
/// of Rodrigues' formula and a dense 3×3 product. The kinematic sweeps take s and c from one batched evaluation
/// of all joints (`trig::sin_cos4`, four joints per call) instead of one C-library `sincos` per joint, which was
/// 18 % of a CRBA call.
#[inline(always)]
pub fn rotate_about_principal_axis(r: &M3, k: usize, s: f64, c: f64) -> M3 {
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
