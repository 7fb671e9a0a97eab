//! Hamilton quaternions stored scalar-first `(w, x, y, z)`: the operations of Valverde 2018, Table 2.2, and the
//! 4×4 product matrices (2.10)–(2.12).
//!
//! The engine stores quaternions `(x, y, z, w)`; `from_xyzw` / `to_xyzw` are the only crossing points.

use crate::spatial::{skew, M3, V3};
use nalgebra::{Matrix4, Vector4};
use std::ops::{Add, Mul, Neg, Sub};

/// 4×4 matrix on quaternions `(w, x, y, z)`.
pub type M4 = Matrix4<f64>;
/// A quaternion as a 4-vector `(w, x, y, z)`.
pub type V4 = Vector4<f64>;

/// A quaternion `w + x i + y j + z k` with `i² = j² = k² = ijk = −1` (the thesis, §2.2, Table 2.1).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Quat {
    /// Scalar part.
    pub w: f64,
    /// Vector part `(x, y, z)`.
    pub v: V3,
}

impl Quat {
    /// The unit `1`.
    pub const ONE: Quat = Quat { w: 1.0, v: V3::new(0.0, 0.0, 0.0) };
    /// Zero.
    pub const ZERO: Quat = Quat { w: 0.0, v: V3::new(0.0, 0.0, 0.0) };

    /// `w + x i + y j + z k`.
    #[inline]
    pub fn new(w: f64, x: f64, y: f64, z: f64) -> Quat {
        Quat { w, v: V3::new(x, y, z) }
    }
    /// The vector quaternion `(0, s̄)` of a 3-vector (the thesis, §2.2 "vector quaternions").
    #[inline]
    pub fn pure(s: &V3) -> Quat {
        Quat { w: 0.0, v: *s }
    }
    /// From a 4-vector `(w, x, y, z)`.
    #[inline]
    pub fn from_vec4(a: &V4) -> Quat {
        Quat::new(a[0], a[1], a[2], a[3])
    }
    /// As a 4-vector `(w, x, y, z)`.
    #[inline]
    pub fn to_vec4(&self) -> V4 {
        V4::new(self.w, self.v.x, self.v.y, self.v.z)
    }
    /// From the engine's `(x, y, z, w)` storage.
    #[inline]
    pub fn from_xyzw(q: &[f64; 4]) -> Quat {
        Quat::new(q[3], q[0], q[1], q[2])
    }
    /// In the engine's order `(x, y, z, w)`.
    #[inline]
    pub fn to_xyzw(&self) -> [f64; 4] {
        [self.v.x, self.v.y, self.v.z, self.w]
    }
    /// Rotation by `angle` about the unit `axis`: `(cos θ/2, n̄ sin θ/2)` (the thesis, §2.2; the printed
    /// `(cos(φ/2), n̄ sin(θ/2))` is a typo for θ).
    pub fn from_axis_angle(axis: &V3, angle: f64) -> Quat {
        let (s, c) = (0.5 * angle).sin_cos();
        Quat { w: c, v: axis * s }
    }
    /// Quaternion of a rotation matrix `C` with `C v̄ = vec(q (0, v̄) q*)`, scalar part ≥ 0.
    pub fn from_rotation_matrix(r: &M3) -> Quat {
        Quat::from_xyzw(&crate::spatial::quat_from_rot(r))
    }
    /// The active rotation matrix `C(q) = (q₀² − |q̄|²) I + 2 q̄ q̄ᵀ + 2 q₀ [q̄]ˣ` of a unit quaternion
    /// (Hamilton convention, scalar first), so `C(q) v̄ = vec(q v q*)`.
    pub fn rotation_matrix(&self) -> M3 {
        (self.w * self.w - self.v.norm_squared()) * M3::identity()
            + 2.0 * self.v * self.v.transpose()
            + 2.0 * self.w * skew(&self.v)
    }

    /// Product (Table 2.2): `ab = (a₀b₀ − ā·b̄, a₀b̄ + b₀ā + ā×b̄)`.
    #[inline]
    pub fn mul(&self, b: &Quat) -> Quat {
        Quat { w: self.w * b.w - self.v.dot(&b.v), v: self.w * b.v + b.w * self.v + self.v.cross(&b.v) }
    }
    /// Conjugate (Table 2.2): `a* = (a₀, −ā)`.
    #[inline]
    pub fn conj(&self) -> Quat {
        Quat { w: self.w, v: -self.v }
    }
    /// Dot product (Table 2.2): `a·b = (a₀b₀ + ā·b̄, 0̄)`, a quaternion with zero vector part.
    #[inline]
    pub fn dot(&self, b: &Quat) -> Quat {
        Quat { w: self.dot_scalar(b), v: V3::zeros() }
    }
    /// The scalar of `a·b`, i.e. the Euclidean inner product of the 4-vectors.
    #[inline]
    pub fn dot_scalar(&self, b: &Quat) -> f64 {
        self.w * b.w + self.v.dot(&b.v)
    }
    /// Cross product (Table 2.2): `a×b = (0, a₀b̄ + b₀ā + ā×b̄)`, the vector part of `ab`.
    #[inline]
    pub fn cross(&self, b: &Quat) -> Quat {
        Quat { w: 0.0, v: self.w * b.v + b.w * self.v + self.v.cross(&b.v) }
    }
    /// Norm (Table 2.2): `‖a‖ = sqrt(a·a)`.
    #[inline]
    pub fn norm(&self) -> f64 {
        self.dot_scalar(self).sqrt()
    }
    /// Scalar part `sc(a) = (a₀, 0̄)` (Table 2.2).
    #[inline]
    pub fn sc(&self) -> Quat {
        Quat { w: self.w, v: V3::zeros() }
    }
    /// Vector part `vec(a) = (0, ā)` (Table 2.2).
    #[inline]
    pub fn vec(&self) -> Quat {
        Quat { w: 0.0, v: self.v }
    }
    /// Inverse `a⁻¹ = a*/‖a‖²`; `None` for the zero quaternion (no inverse exists).
    pub fn inverse(&self) -> Option<Quat> {
        let n2 = self.dot_scalar(self);
        if n2 > 0.0 && n2.is_finite() {
            Some(self.conj().scale(1.0 / n2))
        } else {
            None
        }
    }
    /// Product with a real scalar.
    #[inline]
    pub fn scale(&self, s: f64) -> Quat {
        Quat { w: self.w * s, v: self.v * s }
    }
    /// Rotate a 3-vector: `vec(q (0, v̄) q*)` (coordinate change `s^X = q_{Y/X} s^Y q*_{Y/X}`, the thesis' passive
    /// convention).
    #[inline]
    pub fn rotate(&self, v: &V3) -> V3 {
        self.mul(&Quat::pure(v)).mul(&self.conj()).v
    }

    /// Left product matrix (2.10)–(2.11): `[[a]]_L b = ab`.
    pub fn left_matrix(&self) -> M4 {
        let mut m = M4::zeros();
        m[(0, 0)] = self.w;
        m.fixed_view_mut::<1, 3>(0, 1).copy_from(&(-self.v.transpose()));
        m.fixed_view_mut::<3, 1>(1, 0).copy_from(&self.v);
        m.fixed_view_mut::<3, 3>(1, 1).copy_from(&(self.w * M3::identity() + skew(&self.v)));
        m
    }
    /// Right product matrix (2.10), (2.12): `[[b]]_R a = ab`.
    pub fn right_matrix(&self) -> M4 {
        let mut m = M4::zeros();
        m[(0, 0)] = self.w;
        m.fixed_view_mut::<1, 3>(0, 1).copy_from(&(-self.v.transpose()));
        m.fixed_view_mut::<3, 1>(1, 0).copy_from(&self.v);
        m.fixed_view_mut::<3, 3>(1, 1).copy_from(&(self.w * M3::identity() - skew(&self.v)));
        m
    }
    /// Skew operator (2.9) of a vector quaternion: `[s]ˣ = blkdiag(0, [s̄]ˣ)`, so `[s]ˣ t = s × t` for
    /// vector quaternions. The scalar part of `self` is ignored.
    pub fn skew_matrix(&self) -> M4 {
        let mut m = M4::zeros();
        m.fixed_view_mut::<3, 3>(1, 1).copy_from(&skew(&self.v));
        m
    }
    /// Whether all 4 entries are finite.
    pub fn is_finite(&self) -> bool {
        self.w.is_finite() && self.v.iter().all(|x| x.is_finite())
    }
}

impl Add for Quat {
    type Output = Quat;
    #[inline]
    fn add(self, b: Quat) -> Quat {
        Quat { w: self.w + b.w, v: self.v + b.v }
    }
}
impl Sub for Quat {
    type Output = Quat;
    #[inline]
    fn sub(self, b: Quat) -> Quat {
        Quat { w: self.w - b.w, v: self.v - b.v }
    }
}
impl Neg for Quat {
    type Output = Quat;
    #[inline]
    fn neg(self) -> Quat {
        Quat { w: -self.w, v: -self.v }
    }
}
impl Mul<Quat> for f64 {
    type Output = Quat;
    #[inline]
    fn mul(self, b: Quat) -> Quat {
        b.scale(self)
    }
}
