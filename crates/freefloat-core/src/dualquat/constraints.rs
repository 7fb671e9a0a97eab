//! The convex pose constraints of Valverde 2018, §3.4 (after [112]), as functions usable by controllers: each
//! returns `g(q)` with `g ≤ 0` feasible, and its gradient with respect to the 8-vector of q.
//!
//! Sign of Proposition 1 (a correction of the printed (3.35), checked in tests/dualquat_kinematics.rs): with the
//! thesis' own pose convention `q_{G/A}∘(M_H ⋆ q_{G/A}) = r^G_{G/A}·ŷ^G = −r^G_{A/G}·ŷ^G`, so the printed (3.35)
//! `−q∘(M_H q) + 2‖E_d q‖cos θ ≤ 0` encodes `r^G_{G/A}·ŷ ≥ ‖r‖cos θ`, i.e. the target *behind* the gripper. We
//! implement the physical statement (3.34), the target A inside the cone about ŷ^G seen from G:
//! `+q∘(M_H q) + 2‖E_d q‖cos θ ≤ 0`. Propositions 2 and 3 are sign-consistent as printed.

use super::dual_quaternion::{DualQuat, M8, V8};
use super::quaternion::Quat;
use crate::error::{FfError, Result};
use crate::spatial::V3;

/// A constraint value and its gradient `∂g/∂q` (8-vector, `[real; dual]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstraintValue {
    /// Value of the constraint function (≤ 0 when satisfied).
    pub value: f64,
    /// Its gradient with respect to the 8 entries of the pose.
    pub gradient: V8,
}

fn unit_axis(name: &str, v: &V3) -> Result<V3> {
    let n = v.norm();
    if !(n > 1e-12) || !n.is_finite() {
        return Err(FfError::arg(name, "must be a finite non-zero direction"));
    }
    Ok(v / n)
}

/// `[[0, Bᵀ], [B, 0]]`, the pattern of M_H and M_G.
fn off_diagonal(b: &super::quaternion::M4) -> M8 {
    let mut m = M8::zeros();
    m.fixed_view_mut::<4, 4>(0, 4).copy_from(&b.transpose());
    m.fixed_view_mut::<4, 4>(4, 0).copy_from(b);
    m
}

/// M_H of Prop. 1 (3.36): `[[0, [[ŷ^G]]_Rᵀ], [[[ŷ^G]]_R, 0]]`.
pub fn line_of_sight_matrix(y_g: &V3) -> M8 {
    off_diagonal(&Quat::pure(y_g).right_matrix())
}
/// M_G of Prop. 2 (3.39): `[[0, [[ẑ^A]]_Lᵀ], [[[ẑ^A]]_L, 0]]`.
pub fn approach_slope_matrix(z_a: &V3) -> M8 {
    off_diagonal(&Quat::pure(z_a).left_matrix())
}
/// M_A of Prop. 3 (3.42), read with n̂ for the printed ẑ (the constraint (3.40) uses n̂):
/// `[[ [[n^I]]_L [[n^B]]_R, 0], [0, 0]]`.
pub fn attitude_matrix(n_i: &V3, n_b: &V3) -> M8 {
    let mut m = M8::zeros();
    m.fixed_view_mut::<4, 4>(0, 0).copy_from(&(Quat::pure(n_i).left_matrix() * Quat::pure(n_b).right_matrix()));
    m
}

/// `q∘(M q)` and its gradient `2 M q` (M symmetric).
fn quadratic(m: &M8, q: &V8) -> (f64, V8) {
    let mq = m * q;
    (q.dot(&mq), 2.0 * mq)
}

/// `2‖E_d ⋆ q‖ = ‖r‖` (Lemma 9) and its gradient; zero gradient at r = 0 (a subgradient).
fn distance(q: &V8) -> (f64, V8) {
    let mut ed = V8::zeros();
    ed.fixed_rows_mut::<4>(4).copy_from(&q.fixed_rows::<4>(4));
    let n = ed.norm();
    let g = if n > 0.0 { ed * (2.0 / n) } else { V8::zeros() };
    (2.0 * n, g)
}

/// Line of sight (Prop. 1, (3.34)–(3.36), sign resolved as in the module docs): the target frame A must
/// lie within the cone of half-angle `half_angle` about the gripper axis `y_g` (G coordinates) seen from
/// G's origin. `q_ga = q_{G/A}`, the gripper pose relative to the target.
pub fn line_of_sight(q_ga: &DualQuat, y_g: &V3, half_angle: f64) -> Result<ConstraintValue> {
    let y = unit_axis("y_g", y_g)?;
    let q = q_ga.to_vec8();
    let (h, gh) = quadratic(&line_of_sight_matrix(&y), &q);
    let (r, gr) = distance(&q);
    let c = half_angle.cos();
    Ok(ConstraintValue { value: h + r * c, gradient: gh + gr * c })
}

/// Approach slope (Prop. 2, (3.37)–(3.39)): the gripper G must approach within the cone of half-angle
/// `half_angle` about the target axis `z_a` (A coordinates): `−q∘(M_G q) + 2‖E_d q‖ cos φ ≤ 0`.
pub fn approach_slope(q_ga: &DualQuat, z_a: &V3, half_angle: f64) -> Result<ConstraintValue> {
    let z = unit_axis("z_a", z_a)?;
    let q = q_ga.to_vec8();
    let (h, gh) = quadratic(&approach_slope_matrix(&z), &q);
    let (r, gr) = distance(&q);
    let c = half_angle.cos();
    Ok(ConstraintValue { value: -h + r * c, gradient: -gh + gr * c })
}

/// Attitude (Prop. 3, (3.40)–(3.42)): the body axis `n_b` (B coordinates) must stay within `max_angle` of
/// the inertial direction `n_i`: `q∘(M_A q) + cos ψ ≤ 0`. `q_bi = q_{B/I}`.
pub fn attitude(q_bi: &DualQuat, n_i: &V3, n_b: &V3, max_angle: f64) -> Result<ConstraintValue> {
    let ni = unit_axis("n_i", n_i)?;
    let nb = unit_axis("n_b", n_b)?;
    let q = q_bi.to_vec8();
    let (h, gh) = quadratic(&attitude_matrix(&ni, &nb), &q);
    Ok(ConstraintValue { value: h + max_angle.cos(), gradient: gh })
}

/// Position bound (Lemma 10 / Corollary 1, the domain 𝒟): `‖r‖ ≤ δ` as `q∘q − 1 − δ²/4 ≤ 0` (Lemma 7).
pub fn distance_bound(q: &DualQuat, delta: f64) -> Result<ConstraintValue> {
    if !(delta >= 0.0) || !delta.is_finite() {
        return Err(FfError::arg("delta", format!("must be finite and non-negative, got {delta}")));
    }
    let v = q.to_vec8();
    Ok(ConstraintValue { value: v.dot(&v) - 1.0 - 0.25 * delta * delta, gradient: 2.0 * v })
}
