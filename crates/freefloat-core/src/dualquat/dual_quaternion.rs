//! Dual quaternions `q_r + ε q_d` (ε² = 0) stored as the 8-vector `[real (w,x,y,z), dual (w,x,y,z)]`:
//! the operations of Valverde 2018, Tables 2.4 and 2.5, the 8×8 product matrices (2.27)–(2.29), the
//! normalisation (2.30) and properisation (2.31).

use super::quaternion::{Quat, M4};
use crate::spatial::V3;
use nalgebra::{SMatrix, SVector};
use std::ops::{Add, Mul, Neg, Sub};

/// An 8-vector `[real (w, x, y, z), dual (w, x, y, z)]` (the thesis' layout, (3.26)).
pub type V8 = SVector<f64, 8>;
/// 8×8 matrix on dual quaternions (product and sandwich matrices).
pub type M8 = SMatrix<f64, 8, 8>;

/// `r + ε d`. Twists are stored `ω + ε v` and wrenches `f + ε τ` (the thesis, (2.36), (2.39)).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct DualQuat {
    /// Real part.
    pub r: Quat,
    /// Dual part.
    pub d: Quat,
}

/// Tolerance of `is_unit`: `‖q q* − 1‖∞`. Loose enough for poses built from rounded data, tight enough to
/// reject a quaternion in the wrong layout.
pub const UNIT_TOL: f64 = 1e-9;

impl DualQuat {
    /// `1 := 1 + ε0` (the thesis, §2.3 constants).
    pub const ONE: DualQuat = DualQuat { r: Quat::ONE, d: Quat::ZERO };
    /// `0 + ε0`.
    pub const ZERO: DualQuat = DualQuat { r: Quat::ZERO, d: Quat::ZERO };

    /// `r + ε d`.
    #[inline]
    pub fn new(r: Quat, d: Quat) -> DualQuat {
        DualQuat { r, d }
    }
    /// A vector dual quaternion `(0, ā) + ε(0, b̄)` (the set ℍ_d^v): a twist `ω + εv` or wrench `f + ετ`.
    #[inline]
    pub fn vector(a: &V3, b: &V3) -> DualQuat {
        DualQuat { r: Quat::pure(a), d: Quat::pure(b) }
    }
    /// From an 8-vector `[r; d]`, each `(w, x, y, z)`.
    #[inline]
    pub fn from_vec8(x: &V8) -> DualQuat {
        DualQuat { r: Quat::new(x[0], x[1], x[2], x[3]), d: Quat::new(x[4], x[5], x[6], x[7]) }
    }
    /// From 8 numbers `[r; d]`, each `(w, x, y, z)`.
    pub fn from_slice(x: &[f64; 8]) -> DualQuat {
        DualQuat::from_vec8(&V8::from_column_slice(x))
    }
    /// As an 8-vector `[r; d]`.
    #[inline]
    pub fn to_vec8(&self) -> V8 {
        let mut x = V8::zeros();
        x.fixed_rows_mut::<4>(0).copy_from(&self.r.to_vec4());
        x.fixed_rows_mut::<4>(4).copy_from(&self.d.to_vec4());
        x
    }
    /// As 8 numbers `[r; d]`.
    pub fn to_array(&self) -> [f64; 8] {
        let x = self.to_vec8();
        [x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]]
    }

    /// Product (Table 2.4): `ab = a_r b_r + ε(a_d b_r + a_r b_d)`.
    #[inline]
    pub fn mul(&self, b: &DualQuat) -> DualQuat {
        DualQuat { r: self.r.mul(&b.r), d: self.d.mul(&b.r) + self.r.mul(&b.d) }
    }
    /// Conjugate (Table 2.4): `a* = a_r* + ε a_d*` — the only conjugate the thesis defines; for a unit dual
    /// quaternion it is the inverse (Table 2.5).
    #[inline]
    pub fn conj(&self) -> DualQuat {
        DualQuat { r: self.r.conj(), d: self.d.conj() }
    }
    /// Swap (Table 2.4): `a^s = a_d + ε a_r`.
    #[inline]
    pub fn swap(&self) -> DualQuat {
        DualQuat { r: self.d, d: self.r }
    }
    /// Dot product (Table 2.4): `a·b = a_r·b_r + ε(a_d·b_r + a_r·b_d)`.
    #[inline]
    pub fn dot(&self, b: &DualQuat) -> DualQuat {
        DualQuat { r: self.r.dot(&b.r), d: self.d.dot(&b.r) + self.r.dot(&b.d) }
    }
    /// Cross product (Table 2.4): `a×b = a_r×b_r + ε(a_d×b_r + a_r×b_d)`.
    #[inline]
    pub fn cross(&self, b: &DualQuat) -> DualQuat {
        DualQuat { r: self.r.cross(&b.r), d: self.d.cross(&b.r) + self.r.cross(&b.d) }
    }
    /// Circle product (Table 2.4) as a dual quaternion: `(a_r·b_r + a_d·b_d) + ε0`.
    #[inline]
    pub fn circle(&self, b: &DualQuat) -> DualQuat {
        DualQuat { r: Quat::new(self.circle_scalar(b), 0.0, 0.0, 0.0), d: Quat::ZERO }
    }
    /// The real number of the circle product: the Euclidean inner product of the 8-vectors.
    #[inline]
    pub fn circle_scalar(&self, b: &DualQuat) -> f64 {
        self.r.dot_scalar(&b.r) + self.d.dot_scalar(&b.d)
    }
    /// Norm (Table 2.4): `‖a‖ = sqrt(a∘a)`. NOT a unit-ness test: a unit pose has `‖q‖² = 1 + ¼‖r‖²`.
    #[inline]
    pub fn norm(&self) -> f64 {
        self.circle_scalar(self).sqrt()
    }
    /// Scalar part (Table 2.4, mislabelled "Vector part" there): `sc(a_r) + ε sc(a_d)`.
    #[inline]
    pub fn sc(&self) -> DualQuat {
        DualQuat { r: self.r.sc(), d: self.d.sc() }
    }
    /// Vector part (Table 2.4): `vec(a_r) + ε vec(a_d)`.
    #[inline]
    pub fn vec(&self) -> DualQuat {
        DualQuat { r: self.r.vec(), d: self.d.vec() }
    }
    /// Product with a real scalar.
    #[inline]
    pub fn scale(&self, s: f64) -> DualQuat {
        DualQuat { r: self.r.scale(s), d: self.d.scale(s) }
    }
    /// Inverse of a general dual quaternion with invertible real part (not in the thesis):
    /// `q⁻¹ = q_r⁻¹ − ε q_r⁻¹ q_d q_r⁻¹`. `None` when `q_r = 0` (a dual number with zero real part has no
    /// inverse; the thesis' "no inverse exists if x ≠ 0" is a typo for x = 0). For a unit dual quaternion this is `q*`.
    pub fn inverse(&self) -> Option<DualQuat> {
        let ri = self.r.inverse()?;
        Some(DualQuat { r: ri, d: -ri.mul(&self.d).mul(&ri) })
    }
    /// `q q* − 1`, the defect of the unit constraints `q_r·q_r = 1`, `q_r·q_d = 0` (the thesis, §2.3).
    pub fn unit_defect(&self) -> f64 {
        let e = self.mul(&self.conj()) - DualQuat::ONE;
        e.to_vec8().amax()
    }
    /// Unit dual quaternion: `q q* = 1` within `UNIT_TOL` (not `‖q‖ = 1`: a unit pose has
    /// `‖q‖² = 1 + ‖r‖²/4`, Lemma 7).
    pub fn is_unit(&self) -> bool {
        self.unit_defect() <= UNIT_TOL
    }
    /// Normalisation (2.30): `q_r ← q_r/‖q_r‖`, `q_d ← (I − q_r q_rᵀ) q_d` (the projection removes the
    /// component of q_d along q_r, so `q_r·q_d = 0`). As in the thesis q_d is not rescaled, so the
    /// translation `2 q_d q_r*` picks up the factor ‖q_r‖_old (negligible for small drift). `None` if `q_r = 0`.
    pub fn normalized(&self) -> Option<DualQuat> {
        let n = self.r.norm();
        if !(n > 0.0) || !n.is_finite() {
            return None;
        }
        let r = self.r.scale(1.0 / n);
        let d = self.d - r.scale(r.dot_scalar(&self.d));
        Some(DualQuat { r, d })
    }
    /// Properisation (2.31): `q ← −q` if `(q_r)₀ < 0`; `q` and `−q` are the same transformation.
    pub fn properized(&self) -> DualQuat {
        if self.r.w < 0.0 {
            -*self
        } else {
            *self
        }
    }
    /// Whether all 8 entries are finite.
    pub fn is_finite(&self) -> bool {
        self.r.is_finite() && self.d.is_finite()
    }
    /// Whether both parts have zero scalar (the set ℍ_d^v) within `tol`.
    pub fn is_vector(&self, tol: f64) -> bool {
        self.r.w.abs() <= tol && self.d.w.abs() <= tol
    }

    /// Left product matrix (2.28)–(2.29): `[[a]]_L = [[a_r]]_L 0; [[a_d]]_L [[a_r]]_L]`, `[[a]]_L b = ab`.
    pub fn left_matrix(&self) -> M8 {
        block_lower(&self.r.left_matrix(), &self.d.left_matrix())
    }
    /// Right product matrix (2.28)–(2.29): `[[b]]_R a = ab`.
    pub fn right_matrix(&self) -> M8 {
        block_lower(&self.r.right_matrix(), &self.d.right_matrix())
    }
    /// Skew operator (2.27) of a vector dual quaternion: `[s]ˣ t = s × t` for vector `t`.
    pub fn skew_matrix(&self) -> M8 {
        block_lower(&self.r.skew_matrix(), &self.d.skew_matrix())
    }
    /// The matrix of `x ↦ q* x q` (a frame change towards the frame q points to, (2.41)/(2.43)).
    pub fn adjoint_in_matrix(&self) -> M8 {
        self.conj().left_matrix() * self.right_matrix()
    }
    /// The matrix of `x ↦ q x q*` ((2.42)/(2.44); the group adjoint (3.59) for unit q).
    pub fn adjoint_out_matrix(&self) -> M8 {
        self.left_matrix() * self.conj().right_matrix()
    }
}

/// `[[a, 0], [b, a]]`, the pattern shared by (2.27), (2.28) and (2.29).
fn block_lower(a: &M4, b: &M4) -> M8 {
    let mut m = M8::zeros();
    m.fixed_view_mut::<4, 4>(0, 0).copy_from(a);
    m.fixed_view_mut::<4, 4>(4, 0).copy_from(b);
    m.fixed_view_mut::<4, 4>(4, 4).copy_from(a);
    m
}

/// The 8×8 permutation of the swap: `P_swap x = x^s`, i.e. `[[0, I₄], [I₄, 0]]`, so that `H(M) = M P_swap`.
pub fn swap_matrix() -> M8 {
    let mut p = M8::zeros();
    for k in 0..4 {
        p[(k, k + 4)] = 1.0;
        p[(k + 4, k)] = 1.0;
    }
    p
}

impl Add for DualQuat {
    type Output = DualQuat;
    #[inline]
    fn add(self, b: DualQuat) -> DualQuat {
        DualQuat { r: self.r + b.r, d: self.d + b.d }
    }
}
impl Sub for DualQuat {
    type Output = DualQuat;
    #[inline]
    fn sub(self, b: DualQuat) -> DualQuat {
        DualQuat { r: self.r - b.r, d: self.d - b.d }
    }
}
impl Neg for DualQuat {
    type Output = DualQuat;
    #[inline]
    fn neg(self) -> DualQuat {
        DualQuat { r: -self.r, d: -self.d }
    }
}
impl Mul<DualQuat> for f64 {
    type Output = DualQuat;
    #[inline]
    fn mul(self, b: DualQuat) -> DualQuat {
        b.scale(self)
    }
}
