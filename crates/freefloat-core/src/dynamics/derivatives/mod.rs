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
//! ∂τ/∂q and ∂τ/∂v are computed by exact forward-mode differentiation of the recursive
//! Newton-Euler algorithm in inertial coordinates (Featherstone, RBDA §5.3, in the form of Carpentier
//! and Mansard, RSS 2018, §III): a perturbation of joint j along its subspace column ψ = ⁰Sⱼ moves
//! the subtree of j rigidly, so every inertial-frame quantity fixed to a body of that subtree changes
//! by `ψ ×` (motions), `ψ ×*` (forces) or `ψ×* I − I ψ×` (inertias); the twists, accelerations and
//! forces then follow by the chain rule through the two passes. One pass over the subtree (and up its
//! ancestors) per tangent direction: O(nv · depth) work, no finite differences. Forward dynamics:
//! `∂a/∂x = −M⁻¹ ∂τ/∂x |_{a = FD(q, v, τ)}` (Carpentier and Mansard, eq. (9)), with M from CRBA and
//! its Cholesky factor.
//!
//! Universal joints are not supported (their subspace depends on q); the entry points say so.

mod frame;
mod minv;
mod rnea_derivatives;
mod step;

pub use crate::config::{difference, difference_jacobians, integrate, integrate_jacobians};
pub use frame::{frame_dq_pose_derivatives, frame_log_error_derivatives, se3_log, se3_log_jacobian};
pub use rnea_derivatives::{aba_derivatives, rnea_derivatives};
pub(crate) use rnea_derivatives::{cholesky_inverse, dot};
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

/// `c = α a b + β c` without allocating (nalgebra's dynamic `gemm` packs through a heap buffer);
/// zero entries of `b` are skipped, which the block-diagonal Jacobians of ⊕ and the tree-sparse ∂τ/∂x have many of.
/// Each column of c is summed in register tiles of 8 rows (two 4-lane fused multiply-adds per entry of b): an axpy
/// per entry of b would load and store the column of c each time, and the compiler unrolls a plain axpy 16 wide
/// and leaves most of a column of 12 or 26 to its scalar tail.
pub(crate) fn gemm<S: nalgebra::StorageMut<f64, nalgebra::Dyn, nalgebra::Dyn, RStride = nalgebra::U1>>(
    c: &mut nalgebra::Matrix<f64, nalgebra::Dyn, nalgebra::Dyn, S>,
    alpha: f64,
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    beta: f64,
) {
    let (n, p) = (a.nrows(), b.ncols());
    debug_assert_eq!(a.ncols(), b.nrows());
    debug_assert_eq!((c.nrows(), c.ncols()), (n, p));
    let (asl, bsl) = (a.as_slice(), b.as_slice());
    let kk = a.ncols();
    for j in 0..p {
        let mut cj = c.column_mut(j);
        let cs = cj.as_mut_slice();
        let bj = &bsl[j * kk..(j + 1) * kk];
        match (n / 8, n % 8 != 0) {
            (1, false) => whole_column::<8, false>(cs, alpha, asl, bj, beta),
            (1, true) => whole_column::<8, true>(cs, alpha, asl, bj, beta),
            (2, false) => whole_column::<16, false>(cs, alpha, asl, bj, beta),
            (2, true) => whole_column::<16, true>(cs, alpha, asl, bj, beta),
            (3, false) => whole_column::<24, false>(cs, alpha, asl, bj, beta),
            (3, true) => whole_column::<24, true>(cs, alpha, asl, bj, beta),
            (4, false) => whole_column::<32, false>(cs, alpha, asl, bj, beta),
            (4, true) => whole_column::<32, true>(cs, alpha, asl, bj, beta),
            _ => tiled_column(cs, alpha, asl, bj, beta),
        }
    }
}

/// Column `c = α a b_j + β c` of 8 ≤ n < 40 rows in one pass over b_j: the first M = 8⌊n/8⌋ rows and, if `TAIL`,
/// the last 8 rows (overlapping them) summed in registers together.
#[inline(always)]
fn whole_column<const M: usize, const TAIL: bool>(c: &mut [f64], alpha: f64, a: &[f64], bj: &[f64], beta: f64) {
    let n = c.len();
    let (mut acc, mut tail) = ([0.0; M], [0.0; 8]);
    for (ak, &bkj) in a.chunks_exact(n).zip(bj) {
        if bkj == 0.0 {
            continue;
        }
        let head: &[f64; M] = ak[..M].try_into().expect("M ≤ n rows");
        for l in 0..M {
            acc[l] = head[l].mul_add(bkj, acc[l]);
        }
        if TAIL {
            let last: &[f64; 8] = ak[n - 8..].try_into().expect("8 ≤ n rows");
            for l in 0..8 {
                tail[l] = last[l].mul_add(bkj, tail[l]);
            }
        }
    }
    store(&mut c[..M], alpha, &acc, beta);
    if TAIL {
        store(&mut c[M..], alpha, &tail[8 - (n - M)..], beta);
    }
}

/// The same for any number of rows, in tiles of 8, 4 and 1 rows (one pass over b_j each).
fn tiled_column(cs: &mut [f64], alpha: f64, asl: &[f64], bj: &[f64], beta: f64) {
    let n = cs.len();
    let mut r = 0;
    while r + 8 <= n {
        let acc = tile::<8>(asl, n, r, bj);
        store(&mut cs[r..r + 8], alpha, &acc, beta);
        r += 8;
    }
    if r + 4 <= n {
        let acc = tile::<4>(asl, n, r, bj);
        store(&mut cs[r..r + 4], alpha, &acc, beta);
        r += 4;
    }
    while r < n {
        let acc = tile::<1>(asl, n, r, bj);
        store(&mut cs[r..r + 1], alpha, &acc, beta);
        r += 1;
    }
}

/// Rows `r..r + L` of `a b_j` (a: n rows, column-major), skipping the zero entries of `b_j`.
#[inline(always)]
fn tile<const L: usize>(a: &[f64], n: usize, r: usize, bj: &[f64]) -> [f64; L] {
    let mut acc = [0.0; L];
    for (k, &bkj) in bj.iter().enumerate() {
        if bkj == 0.0 {
            continue;
        }
        let ak: &[f64; L] = a[k * n + r..k * n + r + L].try_into().expect("L rows");
        for l in 0..L {
            acc[l] = ak[l].mul_add(bkj, acc[l]);
        }
    }
    acc
}

#[inline(always)]
fn store(c: &mut [f64], alpha: f64, acc: &[f64], beta: f64) {
    for (ci, x) in c.iter_mut().zip(acc) {
        *ci = if beta == 0.0 { alpha * x } else { alpha.mul_add(*x, beta * *ci) };
    }
}
