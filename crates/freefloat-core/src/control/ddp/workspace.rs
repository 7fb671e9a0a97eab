//! Every buffer one DDP solve needs, allocated once for a horizon (nominal and trial trajectories, node
//! derivatives, gains, value function, scratch), so that an iteration allocates nothing.

use super::problem::{DynamicsHessian, NodeDiff};
use nalgebra::{DMatrix, DVector};

/// Preallocated per-node data of a DDP solve.
#[derive(Clone, Debug)]
pub struct Workspace {
    /// Number of running nodes N.
    pub n: usize,
    /// State representation size.
    pub nx: usize,
    /// Tangent size.
    pub ndx: usize,
    /// Control size.
    pub nu: usize,
    /// Nominal states x₀..x_N (nx each).
    pub xs: Vec<DVector<f64>>,
    /// Nominal controls u₀..u_{N−1}.
    pub us: Vec<DVector<f64>>,
    /// Trial states of the line search.
    pub xs_try: Vec<DVector<f64>>,
    /// Trial controls of the line search.
    pub us_try: Vec<DVector<f64>>,
    /// Stage costs of the nominal trajectory (N + 1, the last one terminal).
    pub costs: Vec<f64>,
    /// Stage costs of the trial.
    pub costs_try: Vec<f64>,
    /// Gaps (defects) `f̄₀ = x₀ ⊖ xs₀`, `f̄ₖ₊₁ = F(xsₖ, usₖ) ⊖ xsₖ₊₁` (N + 1, tangent).
    pub gaps: Vec<DVector<f64>>,
    /// Gaps of the trial.
    pub gaps_try: Vec<DVector<f64>>,
    /// Node derivatives (N + 1, the last one terminal).
    pub diffs: Vec<NodeDiff>,
    /// Feed-forward terms l_k (nu).
    pub kff: Vec<DVector<f64>>,
    /// Feedback gains L_k (nu × ndx).
    pub kfb: Vec<DMatrix<f64>>,
    /// Value gradients V_x (N + 1).
    pub vx: Vec<DVector<f64>>,
    /// Value Hessians V_xx (N + 1).
    pub vxx: Vec<DMatrix<f64>>,
    /// Q-function blocks of the node being processed (scratch).
    pub qx: DVector<f64>,
    /// Q_u.
    pub qu: DVector<f64>,
    /// Q_xx.
    pub qxx: DMatrix<f64>,
    /// Q_uu (unregularised).
    pub quu: DMatrix<f64>,
    /// Q_ux (nu × ndx).
    pub qux: DMatrix<f64>,
    /// Q_uu + λI.
    pub quu_reg: DMatrix<f64>,
    /// Cholesky factor of Q_uu + λI.
    pub quu_chol: DMatrix<f64>,
    /// (Q_uu + λI)⁻¹.
    pub quu_inv: DMatrix<f64>,
    /// V_x' + V_xx' f̄' (the gap-corrected gradient of the next node).
    pub vx_plus: DVector<f64>,
    /// P_x = V_xx' Fx (ndx × ndx).
    pub px: DMatrix<f64>,
    /// P_u = V_xx' Fu (ndx × nu).
    pub pu: DMatrix<f64>,
    /// nu × ndx scratch (Q_ux + Q_uu L).
    pub tmp_ux: DMatrix<f64>,
    /// Fuᵀ (nu × ndx).
    pub fut: DMatrix<f64>,
    /// Fxᵀ (ndx × ndx).
    pub fxt: DMatrix<f64>,
    /// [L; Q_ux]ᵀ (ndx × 2 nu, in a 2 nu × ndx matrix's storage) of the value update.
    pub z1: DMatrix<f64>,
    /// [Q_ux + Q_uu L; L] (2 nu × ndx).
    pub z2: DMatrix<f64>,
    /// nu scratch.
    pub tmp_u: DVector<f64>,
    /// ndx scratch.
    pub dx: DVector<f64>,
    /// ndx scratch.
    pub dx2: DVector<f64>,
    /// nx scratch (the next state of a rollout).
    pub xnext: DVector<f64>,
    /// Full DDP second-order terms of every running node (empty until a full-DDP backward pass needs them;
    /// the expected-change model of the line search reads them back).
    pub hess: Vec<DynamicsHessian>,
}

impl Workspace {
    /// Buffers for a horizon of n nodes.
    pub fn new(n: usize, nx: usize, ndx: usize, nu: usize) -> Workspace {
        let vx = |k: usize, len: usize| vec![DVector::zeros(len); k];
        Workspace {
            n,
            nx,
            ndx,
            nu,
            xs: vx(n + 1, nx),
            us: vx(n, nu),
            xs_try: vx(n + 1, nx),
            us_try: vx(n, nu),
            costs: vec![0.0; n + 1],
            costs_try: vec![0.0; n + 1],
            gaps: vx(n + 1, ndx),
            gaps_try: vx(n + 1, ndx),
            diffs: vec![NodeDiff::zeros(ndx, nu); n + 1],
            kff: vx(n, nu),
            kfb: vec![DMatrix::zeros(nu, ndx); n],
            vx: vx(n + 1, ndx),
            vxx: vec![DMatrix::zeros(ndx, ndx); n + 1],
            qx: DVector::zeros(ndx),
            qu: DVector::zeros(nu),
            qxx: DMatrix::zeros(ndx, ndx),
            quu: DMatrix::zeros(nu, nu),
            qux: DMatrix::zeros(nu, ndx),
            quu_reg: DMatrix::zeros(nu, nu),
            quu_chol: DMatrix::zeros(nu, nu),
            quu_inv: DMatrix::zeros(nu, nu),
            vx_plus: DVector::zeros(ndx),
            px: DMatrix::zeros(ndx, ndx),
            pu: DMatrix::zeros(ndx, nu),
            tmp_ux: DMatrix::zeros(nu, ndx),
            fut: DMatrix::zeros(nu, ndx),
            fxt: DMatrix::zeros(ndx, ndx),
            z1: DMatrix::zeros(2 * nu, ndx),
            z2: DMatrix::zeros(2 * nu, ndx),
            tmp_u: DVector::zeros(nu),
            dx: DVector::zeros(ndx),
            dx2: DVector::zeros(ndx),
            xnext: DVector::zeros(nx),
            hess: Vec::new(),
        }
    }

    /// Whether every gap is below `tol` (max norm): the nominal trajectory is a rollout.
    pub fn is_feasible(&self, tol: f64) -> bool {
        self.gaps.iter().all(|g| g.amax() <= tol)
    }

    /// Largest gap entry (max norm over nodes).
    pub fn gap_norm(&self) -> f64 {
        self.gaps.iter().map(|g| g.amax()).fold(0.0, f64::max)
    }
}

/// Scratch of the robot's step Hessian (`step_hessian`; allocated on the first full-DDP call, then reused). Here,
/// not in `step_hessian`, so that the robot, which owns one, does not import the module that uses it.
#[derive(Clone, Debug)]
pub(crate) struct HessianWork {
    pub(crate) fx: DMatrix<f64>,
    pub(crate) fu: DMatrix<f64>,
    pub(crate) xp: Vec<f64>,
    pub(crate) up: Vec<f64>,
    pub(crate) dz: Vec<f64>,
    pub(crate) lambda: DVector<f64>,
    pub(crate) g_plus: DVector<f64>,
    pub(crate) g_minus: DVector<f64>,
    pub(crate) h: DMatrix<f64>,
}

impl HessianWork {
    pub(crate) fn new(nx: usize, ndx: usize, nu: usize) -> HessianWork {
        HessianWork {
            fx: DMatrix::zeros(ndx, ndx),
            fu: DMatrix::zeros(ndx, nu),
            xp: vec![0.0; nx],
            up: vec![0.0; nu],
            dz: vec![0.0; ndx + nu],
            lambda: DVector::zeros(ndx),
            g_plus: DVector::zeros(ndx + nu),
            g_minus: DVector::zeros(ndx + nu),
            h: DMatrix::zeros(ndx + nu, ndx + nu),
        }
    }
}
