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

    /// The accumulated `[A y]ᵀ[A y]` ((n+1) × (n+1), symmetric).
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.g
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

    /// Add the Gram matrix accumulated by [`gram_rows_upper`] in a permuted, padded layout: augmented index a
    /// (unknown a < n, or y at a = n) is column `slot[a]` of the w × w row-major `acc`, of which only the entries
    /// on and above the diagonal are read; `rows` rows are counted.
    pub(super) fn add_permuted_upper(&mut self, acc: &[f64], w: usize, slot: &[usize], rows: usize) {
        assert!(slot.len() == self.n + 1 && acc.len() == w * w, "permuted Gram: shapes");
        for (a, &sa) in slot.iter().enumerate() {
            for (b, &sb) in slot.iter().enumerate() {
                self.g[(a, b)] += acc[sa.min(sb) * w + sa.max(sb)];
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

/// Width of the column tiles of [`gram_rows_upper`]: two 4-wide FMA registers. Row-major blocks fed to it are
/// padded to a multiple of this (the padding columns left zero).
pub const GRAM_TILE: usize = 8;
/// Rows per pass of the tiles in [`gram_rows_upper`]: 24 rows of 56 columns are 10.5 kB, which stay in L1.
const GRAM_CHUNK: usize = 24;

/// `g += BᵀB` on and above the diagonal, for B = the `rows` rows of the row-major block `b` (row r at
/// `b[r·w..]`), its first `cols` columns (a multiple of 4, at most `w`); `g` is w × w, row-major (entry (i, j) at
/// `i·w + j`). Some entries below the diagonal, next to it, are accumulated too and are to be ignored.
///
/// Why not the BLAS-style product of [`gram_update`]: that computes both triangles and packs both operands into
/// panels on every call (in `perf` of the identification, packing took 38 % of the product's time). Here the block
/// builder writes the rows in the layout the kernel reads, so nothing is packed, and only the tiles that reach the
/// diagonal or lie above it are formed. Each tile of G is 4 rows × 8 columns, held in eight 4-wide registers while
/// the rows stream past: per row, two vector loads, four broadcasts, eight FMAs. On 192 rows × 53 columns: 210 ns
/// per sample against 470 for [`GramLs`] (`examples/identify_profile.rs gram 3000`, same checksum). Where a
/// whole 4 × 8 tile would mostly lie below the diagonal or in the padding, a 4 × 4 tile does: the lower half of a
/// diagonal 8 × 8 block needs only its right four columns, and `cols` that is 4 past a multiple of 8 ends with a
/// 4-wide column strip (the identification's 17 linear columns are then padded to 20, not 24). That drops a fifth
/// of the multiply-adds of the identification's Gram pass; every entry on and above the diagonal is the same chain
/// of fused multiply-adds, row by row, as with whole tiles (the same bits). Public for that benchmark; the
/// identification calls it through its own pass.
pub fn gram_rows_upper(g: &mut [f64], b: &[f64], w: usize, rows: usize, cols: usize) {
    assert!(cols.is_multiple_of(4) && cols <= w && g.len() == w * w && b.len() >= rows * w, "Gram rows: shapes");
    // Rows are taken GRAM_CHUNK at a time so that they stay in L1 while every tile of G passes over them.
    for chunk in b[..rows * w].chunks(GRAM_CHUNK * w) {
        let mut j0 = 0;
        while j0 < cols {
            if j0 + GRAM_TILE <= cols {
                // rows above the diagonal block, and its upper half: all eight columns
                for i0 in (0..=j0).step_by(4) {
                    gram_tile::<GRAM_TILE>(g, chunk, w, i0, j0);
                }
                // its lower half: only the right four columns reach the diagonal
                gram_tile::<4>(g, chunk, w, j0 + 4, j0 + 4);
                j0 += GRAM_TILE;
            } else {
                // a last strip four columns wide
                for i0 in (0..=j0).step_by(4) {
                    gram_tile::<4>(g, chunk, w, i0, j0);
                }
                j0 += 4;
            }
        }
    }
}

/// `g[i0..i0+4, j0..j0+W] += Bᵀ B` over the rows of `chunk` (row length `w`): the tile of G in 4·W/4 registers
/// while the rows stream past, each entry one chain of fused multiply-adds in row order.
#[inline(always)]
fn gram_tile<const W: usize>(g: &mut [f64], chunk: &[f64], w: usize, i0: usize, j0: usize) {
    let mut acc = [[0.0f64; W]; 4];
    for (ii, a) in acc.iter_mut().enumerate() {
        a.copy_from_slice(&g[(i0 + ii) * w + j0..(i0 + ii) * w + j0 + W]);
    }
    for row in chunk.chunks_exact(w) {
        let bj: &[f64; W] = row[j0..j0 + W].try_into().expect("tile inside the row");
        let bi: &[f64; 4] = row[i0..i0 + 4].try_into().expect("tile inside the row");
        for (a, &x) in acc.iter_mut().zip(bi) {
            for (s, &y) in a.iter_mut().zip(bj) {
                *s = x.mul_add(y, *s);
            }
        }
    }
    for (ii, a) in acc.iter().enumerate() {
        g[(i0 + ii) * w + j0..(i0 + ii) * w + j0 + W].copy_from_slice(a);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic, well-mixed number in [-0.5, 0.5).
    fn mix(i: usize, j: usize) -> f64 {
        ((i * 37 + j * 101 + i * j) % 97) as f64 / 97.0 - 0.5
    }

    #[test]
    fn row_kernel_is_the_upper_triangle_of_the_product() {
        // row counts below, at and across the L1 chunk; column tiles narrower than the row
        let w = 24;
        for rows in [1, 7, GRAM_CHUNK, GRAM_CHUNK + 1, 3 * GRAM_CHUNK + 5] {
            for cols in [4, 8, 12, 16, 20, 24] {
                let b: Vec<f64> = (0..rows * w).map(|k| mix(k / w, k % w)).collect();
                let mut g = vec![1.0; w * w]; // accumulates onto what is there
                gram_rows_upper(&mut g, &b, w, rows, cols);
                for i in 0..cols {
                    for j in i..cols {
                        let want = 1.0 + (0..rows).map(|r| b[r * w + i] * b[r * w + j]).sum::<f64>();
                        let got = g[i * w + j];
                        assert!(
                            (got - want).abs() <= 1e-13 * (1.0 + want.abs()),
                            "rows {rows} ({i},{j}): {got} vs {want}"
                        );
                    }
                }
                // outside the column range nothing is touched
                assert!((0..w).all(|i| (cols..w).all(|j| g[i * w + j] == 1.0)));
            }
        }
    }
}
