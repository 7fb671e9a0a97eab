//! Recursive estimators for online identification (Zhang, Yue, Yuan 2020): [`Rls`] (ordinary RLS with
//! forgetting) and [`ModifiedRls`] (the paper's one-step mass/CoM + inertia recursion, eqs. 34-38).
//!
//! Batch least squares for inertial-parameter identification (Naveen, Shah, Misra, eqs. 26–27), without
//! ever forming the tall regressor `G_m` (6N × n).
//!
//! Two accumulators, both fed blocks of rows and merged across threads:
//! - [`StreamingLs`]: a streaming Householder QR. Each block is folded into the n×n triangle `R` by
//!   a QR of `[R; block]`, so accuracy is that of a dense QR of the whole problem (error ∝ κ·ε).
//! - [`GramLs`]: the Gram matrix `[A y]ᵀ[A y]`, accumulated with cache-blocked matrix products (several times
//!   faster; the identification's own pass writes its rows in the layout of a triangle-only kernel,
//!   [`gram_rows_upper`], AVX-512 or x86-64-v3 as the processor allows, and folds each small block while it is
//!   still in L1; it forms the rows eight samples per sweep under AVX-512, four otherwise). Plain normal equations lose twice
//!   the digits (error ∝ κ²·ε), so [`identify_momentum`] only keeps this route when the measured,
//!   column-equilibrated condition number is small, and then adds one refinement pass on the true residual
//!   (corrected semi-normal equations, Björck), which restores QR-grade accuracy. Otherwise it re-streams the data
//!   through [`StreamingLs`].
//!
//! Statistics: `σ̂² = RSS/(m − n)`, `cov = σ̂² (RᵀR)⁻¹`, `std = √diag(cov)`; the condition number is
//! exact, from the singular values of the small factor `R` (σ(R) = σ(A)). A rank-deficient problem
//! is an error naming the unexcited parameter combinations (right singular vectors of the
//! column-equilibrated `R`, so that parameter units do not decide what counts as excited).

mod analysis;
/// Concurrent-learning estimation of every body's mass properties (Valverde 2018, ch. 9).
pub mod concurrent;
mod gram;
mod modified_rls;
mod momentum;
mod rls;
mod rls_kernel;
mod streaming;

pub use analysis::{unexcited_directions, Direction, RANK_RTOL};
#[cfg(target_arch = "x86_64")]
pub use gram::gram_rows_upper_avx512;
pub use gram::{avx512, gram_rows_upper, gram_rows_upper_avx2, GramLs, GRAM_TILE};
pub use modified_rls::{CoupledSample, Coupling, ModifiedRls};
pub use momentum::{
    identify_momentum, identify_momentum_interruptible, identify_momentum_with, momentum_regressor_pass,
    MomentumProblem, GRAM_DIRECT_KAPPA_MAX, GRAM_KAPPA_MAX,
};
pub use rls::Rls;
pub use streaming::StreamingLs;

use nalgebra::{DMatrix, DVector};

/// Which solver produced the estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// normal equations on equilibrated columns + one refinement pass (well-conditioned problems)
    GramRefined,
    /// normal equations on equilibrated columns, one pass (very well-conditioned problems with a
    /// residual large enough to be recovered from the normal equations; see [`GRAM_DIRECT_KAPPA_MAX`])
    Gram,
    /// streaming Householder QR (ill-conditioned problems, or when asked directly)
    StreamingQr,
}

/// Solution of a least-squares problem with its statistics.
#[derive(Debug, Clone)]
pub struct LsResult {
    /// estimate x̂ (eq. 27)
    pub x: DVector<f64>,
    /// standard deviations √diag(cov)
    pub std: DVector<f64>,
    /// σ̂² (RᵀR)⁻¹
    pub covariance: DMatrix<f64>,
    /// residual sum of squares ‖W^½ (y − A x̂)‖²
    pub rss: f64,
    /// degrees of freedom m − n (rows minus unknowns)
    pub dof: usize,
    /// 2-norm condition number of the (weighted) regressor, from the singular values of R
    pub condition_number: f64,
    /// numerical rank (== n on success)
    pub rank: usize,
    /// rows used
    pub rows: usize,
    /// which solver produced x̂
    pub method: Method,
}
