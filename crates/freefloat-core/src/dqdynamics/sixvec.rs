//! The dual-quaternion shifting laws and products on 6-vectors (the vector slots of the 8-vector: twist
//! `[ω; v]`, wrench `[f; τ]`), used in the hot loop of the dual-quaternion dynamics.

use crate::dualquat::{DualInertia, DualQuat};
use crate::spatial::V6;
use nalgebra::Matrix6;

/// 6×6 matrix on the vector slots of dual quaternions (twists `[ω; v]`, wrenches `[f; τ]`).
pub type M6 = Matrix6<f64>;

/// The 6×6 restriction of an 8×8 sandwich matrix to the vector slots (1..4, 5..8) — exact for unit q,
/// which maps vector dual quaternions to vector dual quaternions. Valverde 2018's form; kept as the reference
/// the closed forms below are tested against.
pub fn reduce(m: &crate::dualquat::M8) -> M6 {
    const IDX: [usize; 6] = [1, 2, 3, 5, 6, 7];
    M6::from_fn(|r, c| m[(IDX[r], IDX[c])])
}
/// `x ↦ q* x q` ((2.41)/(2.43)) on 6-vectors, in closed form: `[Rᵀ, 0; −Rᵀ[t]ˣ, Rᵀ]` with `R = C(q_r)`,
/// `t = 2 q_d q_r*` — the shifting law `s_r^Y + ε(s_d^Y + r^Y_{X/Y} × s_r^Y)` written as a matrix. It replaces
/// `[[q*]]_L [[q]]_R` (two 8×8 products) in the hot loop.
pub fn ad_in(q: &DualQuat) -> M6 {
    let rt = q.r.rotation_matrix().transpose();
    let t = q.translation();
    let mut m = M6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-rt * crate::spatial::skew(&t)));
    m
}
/// `x ↦ q x q*` ((2.42)/(2.44)) on 6-vectors: `[R, 0; [t]ˣ R, R]`.
pub fn ad_out(q: &DualQuat) -> M6 {
    let r = q.r.rotation_matrix();
    let t = q.translation();
    let mut m = M6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(crate::spatial::skew(&t) * r));
    m
}
/// The swap on 6-vectors: `[a; b] ↦ [b; a]`.
pub(super) fn swap6(x: &V6) -> V6 {
    V6::new(x[3], x[4], x[5], x[0], x[1], x[2])
}
/// Dual-quaternion cross product (Table 2.4) of two vector dual quaternions as 6-vectors:
/// `(a_r × b_r) + ε(a_d × b_r + a_r × b_d)`.
pub(super) fn cross6(a: &V6, b: &V6) -> V6 {
    let (ar, ad) = (a.fixed_rows::<3>(0).into_owned(), a.fixed_rows::<3>(3).into_owned());
    let (br, bd) = (b.fixed_rows::<3>(0).into_owned(), b.fixed_rows::<3>(3).into_owned());
    let r = ar.cross(&br);
    let d = ad.cross(&br) + ar.cross(&bd);
    V6::new(r.x, r.y, r.z, d.x, d.y, d.z)
}
/// `M⁻¹ [f; τ] = [f/m; Ī⁻¹τ]`, i.e. `(ẏ)^s` from a wrench (Lemma 3 without the swap).
pub(super) fn minv(mi: &DualInertia, iinv: &nalgebra::Matrix3<f64>, w: &V6) -> V6 {
    let f = w.fixed_rows::<3>(0) / mi.mass();
    let t = iinv * w.fixed_rows::<3>(3);
    V6::new(f.x, f.y, f.z, t.x, t.y, t.z)
}
