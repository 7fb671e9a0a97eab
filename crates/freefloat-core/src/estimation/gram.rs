//! Gram-matrix accumulation: the fast first pass of [`super::identify_momentum`].

use nalgebra::{DMatrix, DVector};

/// Accumulates `[A y]ᵀ[A y]` ((n+1)², holding AᵀA, Aᵀy and yᵀy) with blocked matrix products (matrixmultiply).
#[derive(Debug, Clone)]
pub struct GramLs {
    n: usize,
    g: DMatrix<f64>,
    rows: usize,
}

/// Cholesky factor of the normal equations, computed on equilibrated columns.
#[derive(Debug, Clone)]
pub struct GramFactor {
    /// R with AᵀA = RᵀR (unscaled columns)
    pub r: DMatrix<f64>,
    /// semi-normal-equation solution of RᵀR x = Aᵀy
    pub x: DVector<f64>,
    /// κ of the column-equilibrated regressor, from the singular values of its R: what governs
    /// the accuracy of normal equations (van der Sluis)
    pub kappa_scaled: f64,
}

impl GramLs {
    /// An empty accumulator for `n` unknowns (plus the right-hand side column).
    pub fn new(n: usize) -> Self {
        GramLs { n, g: DMatrix::zeros(n + 1, n + 1), rows: 0 }
    }

    /// Number of rows accumulated so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Add the first `rows` rows of `block` = `[A_b | y_b]` (column-major, n+1 columns, weighted).
    pub fn add_augmented(&mut self, block: &DMatrix<f64>, rows: usize) {
        self.add_augmented_range(block, 0, rows);
    }

    /// Add rows `start..start + rows` of `block` = `[A_b | y_b]` (column-major, n+1 columns, weighted).
    pub fn add_augmented_range(&mut self, block: &DMatrix<f64>, start: usize, rows: usize) {
        let cap = block.nrows();
        assert!(start + rows <= cap, "rows {start}..{} outside the block of {cap}", start + rows);
        assert_eq!(block.ncols(), self.n + 1, "block columns");
        gram_update(&mut self.g, block, start, rows);
        self.rows += rows;
    }

    /// Add `small` ((k × k), the Gram matrix of rows whose only nonzero entries are in the augmented
    /// columns `idx`) into the accumulated matrix, counting `rows` rows.
    pub(super) fn add_scattered(&mut self, idx: &[usize], small: &DMatrix<f64>, rows: usize) {
        for (a, &i) in idx.iter().enumerate() {
            for (b, &j) in idx.iter().enumerate() {
                self.g[(i, j)] += small[(a, b)];
            }
        }
        self.rows += rows;
    }

    /// Add another accumulator's rows (the parallel reduction).
    pub fn merge(&mut self, other: &GramLs) {
        self.g += &other.g;
        self.rows += other.rows;
    }

    /// Residual sum of squares at `x` from the accumulated matrix alone: `yᵀy − 2xᵀAᵀy + xᵀAᵀAx`, and
    /// `yᵀy`. The subtraction cancels digits: the absolute error is about n·ε·yᵀy, so the caller
    /// only trusts it when the RSS is not tiny against yᵀy (see [`super::identify_momentum`]).
    pub fn rss_at(&self, x: &DVector<f64>) -> (f64, f64) {
        let n = self.n;
        let g = &self.g;
        let mut quad = 0.0;
        let mut lin = 0.0;
        for j in 0..n {
            let mut row = 0.0;
            for i in 0..n {
                row += g[(i, j)] * x[i];
            }
            quad += row * x[j];
            lin += g[(j, n)] * x[j];
        }
        let yty = g[(n, n)];
        (yty - 2.0 * lin + quad, yty)
    }

    /// Factor the normal equations, or None if the Cholesky fails (numerically singular).
    pub fn factor(&self) -> Option<GramFactor> {
        let n = self.n;
        let ata = self.g.view((0, 0), (n, n));
        // equilibrate: D = √diag(AᵀA); an all-zero column is left unscaled and fails below
        let d: Vec<f64> = (0..n).map(|k| if ata[(k, k)] > 0.0 { ata[(k, k)].sqrt() } else { 1.0 }).collect();
        let gs = DMatrix::from_fn(n, n, |i, j| ata[(i, j)] / (d[i] * d[j]));
        let chol = gs.cholesky()?;
        let rs = chol.l().transpose();
        let kappa_scaled = super::analysis::condition_number(&rs);
        let aty = DVector::from_fn(n, |i, _| self.g[(i, n)] / d[i]);
        let xs = chol.solve(&aty);
        let x = DVector::from_fn(n, |i, _| xs[i] / d[i]);
        let r = DMatrix::from_fn(n, n, |i, j| rs[(i, j)] * d[j]);
        Some(GramFactor { r, x, kappa_scaled })
    }
}

/// `g += BᵀB` for B = rows `start..start + rows` of the column-major `block` (all its columns; `g` square, as
/// wide as the block). The one Gram product of identification, shared by [`GramLs`] and the split linear rows.
pub(super) fn gram_update(g: &mut DMatrix<f64>, block: &DMatrix<f64>, start: usize, rows: usize) {
    let (cap, n1) = (block.nrows(), block.ncols());
    assert!(start + rows <= cap && g.nrows() == n1 && g.ncols() == n1, "Gram update: shapes");
    // G += BᵀB by matrixmultiply's blocked kernel (packed panels, register tiles, FMA), which reads each entry of
    // B a few times; nalgebra's `gemm_tr` forms one dot product per entry of G and reads both columns from memory
    // every time: 3.4× slower on a 192 × 53 block (examples/identify_profile.rs gram). Bᵀ is B itself with its strides
    // swapped (no copy). G is symmetric and the full product costs about twice its triangle, but a triangle
    // made of smaller products (2, 3, 4 column panels: 3, 6, 10 calls) measured 1.4-3× slower than the one full
    // call: each call packs its panels afresh. (A hand-made transposed view fed to nalgebra's `gemm` once
    // read and wrote out of bounds inside nalgebra on some block sizes: the raw call below states its strides.)
    let (cap_s, n1_s) = (cap as isize, n1 as isize);
    // SAFETY: entry (r, c) of B is at offset r + c·cap from block[start, 0], r < rows and start + rows <= cap,
    // c < n1 (asserted): inside the cap × n1 block; Bᵀ reads the same entries; g is n1 × n1 column-major
    // (asserted), written at i + j·n1; g and block are distinct matrices (one is borrowed mutably), no aliasing.
    unsafe {
        let b = block.as_slice().as_ptr().add(start);
        matrixmultiply::dgemm(n1, rows, n1, 1.0, b, cap_s, 1, b, 1, cap_s, 1.0, g.as_mut_slice().as_mut_ptr(), 1, n1_s);
    }
}
