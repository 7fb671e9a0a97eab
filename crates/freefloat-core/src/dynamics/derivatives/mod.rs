//! Analytic derivatives of the dynamics: RNEA (∂τ/∂q, ∂τ/∂v; ∂τ/∂a = M), forward dynamics
//! (∂a/∂q, ∂a/∂v, ∂a/∂τ = M⁻¹), one discrete step (semi-implicit Euler, RK4 on the Lie group) in the
//! tangent error state, the Jacobians of `⊕`/`⊖`, and the derivatives of a frame's pose (SE(3)
//! log error, dual quaternion).
//!
//! # Tangent convention (every `∂/∂q` here)
//! A derivative with respect to `q` has nv columns: the **local (right) tangent** of the
//! configuration, the one the generalized velocity `v` lives in. Column k is `d/dε f(q ⊕ ε e_k)` at
//! ε = 0, where moving along `e_k` for a unit time at velocity `v = e_k` is what `⊕` means:
//! - free base: `p ← p + R δ_lin`, `R ← R Exp(δ_ang)` (δ in **base-frame** axes, the same axes as the
//!   base twist in `v`); a planar base likewise (`[x, y] ← [x, y] + R(yaw) δ_xy`, `yaw ← yaw + δ_θ`);
//! - spherical joint: `quat ← quat ⊗ exp(δ)` (child-frame axes);
//! - scalar joints: `θ ← θ + δ`.
//!
//! To first order this is Pinocchio's convention (`computeABADerivatives`, whose `q`-tangent is the
//! SE(3) exponential of a base-frame twist), so the matrices compare column for column with
//! Pinocchio's. The finite step `⊕` used by the integrators is the product group R³ × SO(3) above
//! (the group the engine's simulator integrates on), **not** SE(3): `integrate(q, v dt)` therefore
//! differs from `pin.integrate` at O(dt²) when the base rotates and translates at once.
//!
//! # Algorithm
//! ∂τ/∂q and ∂τ/∂v: the single-pass algorithm of Carpentier and Mansard, "Analytical Derivatives of Rigid Body
//! Dynamics Algorithms", RSS 2018 (Alg. 1), in inertial coordinates (`rnea_derivatives.rs`). A perturbation of
//! joint j along its subspace column ψ = ⁰Sⱼ turns the subtree of j rigidly, so every inertial-frame quantity fixed
//! to a body of that subtree changes by `ψ ×` (motions), `ψ ×*` (forces) or `ψ×* I − I ψ×` (inertias), plus a part
//! that does not depend on the body: Ψ̇ = v_λ(j) × ψ for the twists and Ψ̈ = a_λ(j) × ψ + v_λ(j) × Ψ̇ for the
//! accelerations. The turning part cancels in `τᵢ = Sᵢᵀ Fᵢ` for i in the subtree, so with the subtree sums Fᵢ,
//! Icᵢ = Σ I and Bcᵢ = Σ B (B the map `e ↦ I (e × v) + e ×* (I v) + v ×* (I e)`, whose linear-input half is zero):
//! - `∂τᵢ/∂q_j = Sᵢᵀ (Icᵢ Ψ̈_j + Bcᵢ Ψ̇_j)` for j on the path from the root to i (row i),
//! - `∂τ_j/∂qᵢ = S_jᵀ (ψ ×* Fᵢ + Icᵢ Ψ̈ᵢ + Bcᵢ Ψ̇ᵢ)` for the strict ancestors j of i (column i),
//!
//! and likewise for q̇ with `∂v/∂q̇_j = ψ` and `∂a/∂q̇_j = Ψ̇_j + v_j × ψ` (Bc ψ + Ic (Ψ̇ + Ṡ)); every other entry is
//! zero (joints on different branches). One forward pass and one backward pass filling whole rows and columns:
//! O(nv · depth) 6-vector products.
//!
//! Forward dynamics: `∂a/∂x = −M⁻¹ ∂τ/∂x |_{a = FD(q, v, τ)}` (Carpentier and Mansard, eq. (9)), with a from the
//! articulated-body algorithm and M⁻¹ from the articulated-body recursion run on all nv unit torques at once
//! (`minv.rs`, O(nv · n)), then two products that skip the zero entries of ∂τ/∂x.
//!
//! Universal joints are not supported (their subspace depends on q); the entry points say so.

mod dense;
mod frame;
mod minv;
mod rnea_derivatives;
mod step;

pub use crate::config::{difference, difference_jacobians, integrate, integrate_jacobians};
pub(crate) use dense::{cholesky_inverse, dot, gemm, gemm_pair};
pub use frame::{frame_dq_pose_derivatives, frame_log_error_derivatives, se3_log, se3_log_jacobian};
pub use rnea_derivatives::{aba_derivatives, rnea_derivatives};
pub use step::{step, step_derivatives, Scheme};

use crate::error::{FfError, Result};
use crate::model::{JointType, Model};
use crate::spatial::{Force, Inertia, Motion};
use nalgebra::DMatrix;

/// Work buffers and outputs of the derivative routines for one model (make it with
/// `Derivatives::new(&model)`, once; every call then runs without allocating).
#[derive(Clone, Debug)]
pub struct Derivatives {
    /// ∂τ/∂q (nv × nv, local tangent of q), from `rnea_derivatives` or `aba_derivatives` (at a = FD).
    pub dtau_dq: DMatrix<f64>,
    /// ∂τ/∂v (nv × nv).
    pub dtau_dv: DMatrix<f64>,
    /// ∂a/∂q (nv × nv), from `aba_derivatives`.
    pub da_dq: DMatrix<f64>,
    /// ∂a/∂v (nv × nv), from `aba_derivatives`.
    pub da_dv: DMatrix<f64>,
    /// ∂a/∂τ = M⁻¹ (nv × nv, full symmetric), from `aba_derivatives`.
    pub minv: DMatrix<f64>,
    /// Accelerations `a = FD(q, v, τ)` at the point of the last `aba_derivatives` call (nv).
    pub ddq: Vec<f64>,
    /// Step outputs: next configuration (nq) of `step` / `step_derivatives`.
    pub q_next: Vec<f64>,
    /// Step outputs: next velocity (nv).
    pub v_next: Vec<f64>,
    /// ∂x⁺/∂x (2nv × 2nv): rows and columns `[tangent of q; v]` (x⁺ ⊖ x̄⁺ against x ⊖ x̄).
    pub fx: DMatrix<f64>,
    /// ∂x⁺/∂u (2nv × nv), u = τ (all nv generalized forces; select columns for an under-actuated base).
    pub fu: DMatrix<f64>,
    // ---- scratch of the RNEA derivative passes (inertial frame): per body
    pub(crate) ov: Vec<Motion>,
    pub(crate) oa: Vec<Motion>,
    pub(crate) oi: Vec<Inertia>,
    pub(crate) ff: Vec<Force>,
    pub(crate) ic: Vec<Inertia>,
    pub(crate) bc: Vec<rnea_derivatives::BMap>,
    // per velocity coordinate (column ψ of a joint subspace): ψ in the inertial frame
    pub(crate) sw: Vec<Motion>,
    // per velocity coordinate (column ψ of a joint subspace): Ψ̇ = v_λ × ψ, Ψ̈ = a_λ × ψ + v_λ × Ψ̇, Ψ̇ + v × ψ
    pub(crate) psi_d: Vec<Motion>,
    pub(crate) psi_dd: Vec<Motion>,
    pub(crate) dadv: Vec<Motion>,
    // per velocity index, the previous one on its path to the root: the one before it in its joint, else the last
    // one of the nearest ancestor joint that has any (None at the root)
    pub(crate) dof_parent: Vec<Option<usize>>,
    // ---- scratch of the M⁻¹ pass (`minv`): per body Iᴬ, U, D⁻¹, the end of its subtree's velocity range, and
    // pᴬ / a as 6 × nv matrices
    pub(crate) ia: Vec<crate::spatial::M6>,
    pub(crate) mu: Vec<crate::spatial::M6>,
    pub(crate) mdinv: Vec<crate::spatial::M6>,
    pub(crate) sub_end: Vec<usize>,
    pub(crate) fm: Vec<f64>,
    // ---- scratch of the step derivatives
    pub(crate) rk: step::StepWork,
    model_id: u64,
}

impl Derivatives {
    /// Every buffer sized for `m`.
    pub fn new(m: &Model) -> Derivatives {
        let (n, nv) = (m.nbodies(), m.nv);
        let z = || DMatrix::zeros(nv, nv);
        Derivatives {
            dtau_dq: z(),
            dtau_dv: z(),
            da_dq: z(),
            da_dv: z(),
            minv: z(),
            ddq: vec![0.0; nv],
            q_next: vec![0.0; m.nq],
            v_next: vec![0.0; nv],
            fx: DMatrix::zeros(2 * nv, 2 * nv),
            fu: DMatrix::zeros(2 * nv, nv),
            ov: vec![Motion::ZERO; n],
            oa: vec![Motion::ZERO; n],
            oi: vec![Inertia::zero(); n],
            ff: vec![Force::ZERO; n],
            ic: vec![Inertia::zero(); n],
            bc: vec![rnea_derivatives::BMap::ZERO; n],
            sw: vec![Motion::ZERO; nv],
            psi_d: vec![Motion::ZERO; nv],
            psi_dd: vec![Motion::ZERO; nv],
            dadv: vec![Motion::ZERO; nv],
            dof_parent: dof_parents(m),
            ia: vec![crate::spatial::M6::zeros(); n],
            mu: vec![crate::spatial::M6::zeros(); n],
            mdinv: vec![crate::spatial::M6::zeros(); n],
            sub_end: subtree_ends(m),
            fm: vec![0.0; 6 * nv * n],
            rk: step::StepWork::new(m),
            model_id: m.id(),
        }
    }
}

impl Derivatives {
    /// Identity of the model this workspace was made for (`Model::id`).
    pub fn model_id(&self) -> u64 {
        self.model_id
    }
}

/// `Derivatives::dof_parent`.
fn dof_parents(m: &Model) -> Vec<Option<usize>> {
    let mut last: Vec<Option<usize>> = vec![None; m.nbodies()];
    let mut out = vec![None; m.nv];
    for i in 0..m.nbodies() {
        let mut prev = m.parents[i].and_then(|p| last[p]);
        for c in m.idx_v[i]..m.idx_v[i] + m.nvs[i] {
            out[c] = prev;
            prev = Some(c);
        }
        last[i] = prev;
    }
    out
}

/// For each body, one past the last velocity index of its subtree (bodies are numbered parents first and velocity
/// indices follow the body order, so the subtree's indices lie in `idx_v[i]..end`).
fn subtree_ends(m: &Model) -> Vec<usize> {
    let mut end: Vec<usize> = (0..m.nbodies()).map(|i| m.idx_v[i] + m.nvs[i]).collect();
    for i in (0..m.nbodies()).rev() {
        if let Some(p) = m.parents[i] {
            end[p] = end[p].max(end[i]);
        }
    }
    end
}

/// Check that `w` was made for `m` and that `m` has no universal joint.
pub(crate) fn check_workspace(m: &Model, w: &Derivatives) -> Result<()> {
    if w.model_id != m.id() || w.ddq.len() != m.nv || w.ov.len() != m.nbodies() {
        return Err(FfError::arg(
            "derivatives",
            format!("this Derivatives workspace was made for another model; make one with Derivatives::new(&model) for model '{}'", m.name),
        ));
    }
    check_supported(m)
}

/// The derivative routines do not support universal joints (q-dependent subspace).
pub(crate) fn check_supported(m: &Model) -> Result<()> {
    if let Some(i) = m.joint_types.iter().position(|&t| t == JointType::Universal) {
        return Err(FfError::arg(
            "model",
            format!(
                "joint '{}' is universal; the dynamics derivatives support every joint type but universal",
                m.joint_names[i]
            ),
        ));
    }
    Ok(())
}
