//! Streaming Householder QR: the n×n triangle of all rows seen so far, never the rows themselves.

use super::analysis::{check_rank, finish};
use super::{LsResult, Method};
use crate::error::{FfError, Result};
use nalgebra::{DMatrix, Dim, Matrix, Storage};

/// Least squares by a QR updated one block of rows at a time.
///
/// Holds `[R | z]` (n × (n+1)), where `QᵀA = [R; 0]`, `z` = the first n entries of `Qᵀy`, and the
/// residual sum of squares (the squared norm of the rest of `Qᵀy`). Adding a block is a QR of
/// `[R z; A_b y_b]`; since R is already triangular, each Householder reflector only mixes one row
/// of R with the block, costing O(rows·n²) per block and O(n²) memory in total.
#[derive(Debug, Clone)]
pub struct StreamingLs {
    n: usize,
    r: DMatrix<f64>,
    rss: f64,
    rows: usize,
    work: DMatrix<f64>,
}

impl StreamingLs {
    /// An empty factorisation for `n` unknowns.
    pub fn new(n: usize) -> Self {
        StreamingLs { n, r: DMatrix::zeros(n, n + 1), rss: 0.0, rows: 0, work: DMatrix::zeros(0, n + 1) }
    }

    /// Number of unknowns.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Rows added so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Residual sum of squares of the least-squares solution of the rows seen so far.
    pub fn rss(&self) -> f64 {
        self.rss
    }

    /// The upper-triangular factor R (n × n).
    pub fn r(&self) -> DMatrix<f64> {
        self.r.columns(0, self.n).into_owned()
    }

    /// Add rows `a` (rows × n) with right-hand side `y`, optionally weighted: row k then counts as
    /// `√w_k · (a_k, y_k)`, i.e. `w_k` is an inverse variance.
    pub fn add_block<R: Dim, C: Dim, S: Storage<f64, R, C>>(
        &mut self,
        a: &Matrix<f64, R, C, S>,
        y: &[f64],
        w: Option<&[f64]>,
    ) -> Result<()> {
        let (rows, n) = (a.nrows(), self.n);
        if a.ncols() != n || y.len() != rows || w.is_some_and(|w| w.len() != rows) {
            return Err(FfError::arg("a", format!("expected {rows}×{n} rows with {rows} y (and weights)")));
        }
        if let Some(k) = w.and_then(|w| w.iter().position(|x| !(*x >= 0.0) || !x.is_finite())) {
            return Err(FfError::arg("w", format!("weight {k} must be finite and ≥ 0")));
        }
        if self.work.nrows() < rows {
            self.work = DMatrix::zeros(rows, n + 1);
        }
        let mut work = std::mem::replace(&mut self.work, DMatrix::zeros(0, 0));
        for k in 0..rows {
            let s = w.map_or(1.0, |w| w[k].sqrt());
            for j in 0..n {
                work[(k, j)] = s * a[(k, j)];
            }
            work[(k, n)] = s * y[k];
        }
        self.add_augmented(&mut work, rows);
        self.work = work;
        Ok(())
    }

    /// Fold the first `rows` rows of `block` = `[A_b | y_b]` (column-major, n+1 columns, already
    /// weighted) into the factor. The block is overwritten. This is the allocation-free hot path.
    pub fn add_augmented(&mut self, block: &mut DMatrix<f64>, rows: usize) {
        let n = self.n;
        debug_assert_eq!(block.ncols(), n + 1);
        let cap = block.nrows();
        let b = block.as_mut_slice();
        let r = self.r.as_mut_slice(); // column-major n × (n+1)
        for j in 0..n {
            // reflector zeroing column j of the block against R[j][j]
            let bj = &b[j * cap..j * cap + rows];
            let sb: f64 = bj.iter().map(|x| x * x).sum();
            if sb == 0.0 {
                continue;
            }
            let x0 = r[j * n + j];
            let norm = (x0 * x0 + sb).sqrt();
            let alpha = if x0 >= 0.0 { -norm } else { norm };
            let v0 = x0 - alpha;
            let vtv = v0 * v0 + sb;
            // apply H = I − 2vvᵀ/vᵀv to the remaining columns (v = [v0; block column j])
            for c in j + 1..=n {
                let (head, tail) = b.split_at_mut(c * cap);
                let vj = &head[j * cap..j * cap + rows];
                let bc = &mut tail[..rows];
                let dot: f64 = vj.iter().zip(bc.iter()).map(|(p, q)| p * q).sum();
                let f = 2.0 * (v0 * r[c * n + j] + dot) / vtv;
                r[c * n + j] -= f * v0;
                for (q, p) in bc.iter_mut().zip(vj) {
                    *q -= f * p;
                }
            }
            r[j * n + j] = alpha;
        }
        // what is left of the right-hand side in the block rows is residual (Q is orthogonal)
        self.rss += b[n * cap..n * cap + rows].iter().map(|x| x * x).sum::<f64>();
        self.rows += rows;
    }

    /// Merge another accumulator (e.g. from another thread): QR of `[R₁; R₂]` (TSQR).
    pub fn merge(&mut self, other: &StreamingLs) {
        assert_eq!(self.n, other.n, "merge: accumulators of different size");
        let mut block = other.r.clone();
        let rows = self.rows;
        self.add_augmented(&mut block, self.n);
        // add_augmented counted the n rows of R₂; the data behind them are other.rows rows
        self.rows = rows + other.rows;
        self.rss += other.rss;
    }

    /// Least-squares solution with covariance and statistics; an error naming the unexcited
    /// parameter combinations if R is rank deficient.
    pub fn solve(&self) -> Result<LsResult> {
        let r = self.r();
        check_rank(&r)?;
        let x = r
            .solve_upper_triangular(&self.r.column(self.n))
            .ok_or_else(|| FfError::Numerical("singular triangular factor".into()))?;
        Ok(finish(&r, x, self.rss, self.rows, Method::StreamingQr))
    }

    /// σ̂²(RᵀR)⁻¹ (see [`StreamingLs::solve`]).
    pub fn covariance(&self) -> Result<DMatrix<f64>> {
        Ok(self.solve()?.covariance)
    }

    /// Standard deviations of the estimate.
    pub fn std(&self) -> Result<nalgebra::DVector<f64>> {
        Ok(self.solve()?.std)
    }

    /// Exact 2-norm condition number of the weighted regressor, from the singular values of R.
    pub fn condition_number(&self) -> f64 {
        super::analysis::condition_number(&self.r())
    }

    /// The parameter combinations the data leave unexcited (empty if full rank).
    pub fn unexcited(&self) -> Vec<super::Direction> {
        super::unexcited_directions(&self.r())
    }
}
