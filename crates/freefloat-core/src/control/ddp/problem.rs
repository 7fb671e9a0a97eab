//! The optimal-control problem a DDP solver sees: a horizon of nodes sharing one state space, each with
//! a discrete step `x⁺ = F_k(x, u)` and a stage cost `ℓ_k(x, u)`, plus a terminal cost `ℓ_N(x)`.
//!
//! The state may live on a manifold (a floating base's pose): the solver stores states in their own
//! representation (`nx` numbers: position, quaternion, joint angles, velocities...) and linearises in the
//! minimal tangent error state (`ndx` numbers) through `integrate` (x ⊕ δx) and `difference` (x₁ ⊖ x₀).
//! The thesis' 46-dimensional dual-quaternion state of Valverde 2018, eq. (8.50), is only a notation for
//! this: the dual quaternion stays in the rollout, the Riccati recursion never sees it.

use crate::error::Result;
use nalgebra::{DMatrix, DVector};

/// Derivatives of one node in the tangent error state, written by `ActionModel::calc_diff`:
/// `δx⁺ = Fx δx + Fu δu`, `ℓ ≈ ℓ̄ + Lxᵀδx + Luᵀδu + ½[δx;δu]ᵀ[Lxx Lxu; Luxᵀ Luu][δx;δu]`.
/// For the terminal node only `lx` and `lxx` are used (nu columns may be zero-sized).
#[derive(Clone, Debug)]
pub struct NodeDiff {
    /// ∂x⁺/∂x (ndx × ndx).
    pub fx: DMatrix<f64>,
    /// ∂x⁺/∂u (ndx × nu).
    pub fu: DMatrix<f64>,
    /// ∂ℓ/∂x (ndx).
    pub lx: DVector<f64>,
    /// ∂ℓ/∂u (nu).
    pub lu: DVector<f64>,
    /// ∂²ℓ/∂x² (ndx × ndx).
    pub lxx: DMatrix<f64>,
    /// ∂²ℓ/∂u² (nu × nu).
    pub luu: DMatrix<f64>,
    /// ∂²ℓ/∂x∂u (ndx × nu).
    pub lxu: DMatrix<f64>,
}

impl NodeDiff {
    /// All zero, sized for (ndx, nu).
    pub fn zeros(ndx: usize, nu: usize) -> NodeDiff {
        NodeDiff {
            fx: DMatrix::zeros(ndx, ndx),
            fu: DMatrix::zeros(ndx, nu),
            lx: DVector::zeros(ndx),
            lu: DVector::zeros(nu),
            lxx: DMatrix::zeros(ndx, ndx),
            luu: DMatrix::zeros(nu, nu),
            lxu: DMatrix::zeros(ndx, nu),
        }
    }
    /// Set every entry to zero (a model then adds its terms).
    pub fn clear(&mut self) {
        self.fx.fill(0.0);
        self.fu.fill(0.0);
        self.clear_costs();
    }
    /// Set the cost derivatives to zero, leaving fx and fu (for a model that overwrites both).
    pub fn clear_costs(&mut self) {
        self.lx.fill(0.0);
        self.lu.fill(0.0);
        self.lxx.fill(0.0);
        self.luu.fill(0.0);
        self.lxu.fill(0.0);
    }
}

/// Second-order dynamics terms of full DDP at one node, contracted with the value gradient λ at the next
/// node: `Hxx = Σ_j λ_j ∂²F^j/∂x²`, `Huu = Σ_j λ_j ∂²F^j/∂u²`, `Hux = Σ_j λ_j ∂²F^j/∂u∂x`
/// (Valverde 2018, eqs. (8.39)–(8.44), written for the discrete step, so without the Δt of the
/// continuous-time form).
#[derive(Clone, Debug)]
pub struct DynamicsHessian {
    /// ndx × ndx.
    pub hxx: DMatrix<f64>,
    /// nu × nu.
    pub huu: DMatrix<f64>,
    /// nu × ndx.
    pub hux: DMatrix<f64>,
}

impl DynamicsHessian {
    /// All zero, sized for (ndx, nu).
    pub fn zeros(ndx: usize, nu: usize) -> DynamicsHessian {
        DynamicsHessian { hxx: DMatrix::zeros(ndx, ndx), huu: DMatrix::zeros(nu, nu), hux: DMatrix::zeros(nu, ndx) }
    }
}

/// A family of action models over a horizon of `horizon()` nodes (0..N−1 running, N terminal) sharing
/// one state space. Node-indexed rather than one object per node so that a robot model keeps one set of
/// work buffers for the whole horizon and time-varying references are a table lookup.
///
/// Contract: `calc` and `calc_diff` never allocate; they return an error (not NaN) when the dynamics fail.
pub trait ActionModel {
    /// Size of the state representation (e.g. nq + nv).
    fn nx(&self) -> usize;
    /// Size of the tangent error state (e.g. 2 nv).
    fn ndx(&self) -> usize;
    /// Size of the control.
    fn nu(&self) -> usize;
    /// Number of running nodes N (the terminal node has index N).
    fn horizon(&self) -> usize;
    /// `out = x ⊕ dx` (the retraction of the state manifold).
    fn integrate(&self, x: &[f64], dx: &[f64], out: &mut [f64]);
    /// `out = x1 ⊖ x0`, the tangent vector with `x0 ⊕ out = x1`.
    fn difference(&self, x0: &[f64], x1: &[f64], out: &mut [f64]);
    /// Running node k: next state into `xnext`, returns the stage cost.
    fn calc(&mut self, k: usize, x: &[f64], u: &[f64], xnext: &mut [f64]) -> Result<f64>;
    /// Terminal cost at x.
    fn calc_terminal(&mut self, x: &[f64]) -> Result<f64>;
    /// Running node k: every derivative of `NodeDiff` (overwrites all of them).
    fn calc_diff(&mut self, k: usize, x: &[f64], u: &[f64], d: &mut NodeDiff) -> Result<()>;
    /// Terminal node: `lx`, `lxx` (overwrites them).
    fn calc_diff_terminal(&mut self, x: &[f64], d: &mut NodeDiff) -> Result<()>;
    /// Full DDP: the second-order dynamics terms contracted with `lambda` (ndx). Returns false if the
    /// model does not provide them (the solver then says so instead of silently running iLQG).
    fn dynamics_hessian(
        &mut self,
        _k: usize,
        _x: &[f64],
        _u: &[f64],
        _lambda: &[f64],
        _out: &mut DynamicsHessian,
    ) -> Result<bool> {
        Ok(false)
    }
    /// Called at the start of DDP iteration `i` (counted from 1). Returns true if the cost changed (an
    /// iteration-scheduled weight, Valverde 2018 Table 8.2), so that the solver re-evaluates the nominal
    /// cost before comparing candidates against it.
    fn set_iteration(&mut self, _i: usize) -> bool {
        false
    }
    /// The last iteration at which `set_iteration` can still change the cost (0: never). The solver does not
    /// declare convergence before it: a problem converged at Medium weights is not the problem of the End ones.
    fn schedule_end(&self) -> usize {
        0
    }
}
