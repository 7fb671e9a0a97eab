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
/// Rows per pass of the tiles in [`gram_rows_upper_avx2`]: 24 rows of 56 columns are 10.5 kB, which stay in L1.
const GRAM_CHUNK: usize = 24;
/// Rows per pass of the strips in [`gram_rows_upper_avx512`]: 48 rows (21 kB at 56 columns; the identification's
/// half-block) load and store each strip's accumulators half as often as 24 did: 106 -> 100 ns per sample in
/// `identify_profile gram` (96 rows: the same, 192: 101).
const GRAM_CHUNK_512: usize = 48;

/// `g += BᵀB` on and above the diagonal, for B = the `rows` rows of the row-major block `b` (row r at
/// `b[r·w..]`), its first `cols` columns (a multiple of 4, at most `w`); `g` is w × w, row-major (entry (i, j) at
/// `i·w + j`). Some entries below the diagonal, next to it, are accumulated too and are to be ignored.
///
/// Why not the BLAS-style product of [`gram_update`]: that computes both triangles and packs both operands into
/// panels on every call (in `perf` of the identification, packing took 38 % of the product's time). Here the block
/// builder writes the rows in the layout the kernel reads, so nothing is packed, and only the tiles that reach the
/// diagonal or lie above it are formed.
///
/// Two kernels, chosen at run time (as OpenBLAS picks its kernels for the processor): on a processor with AVX-512
/// (`avx512f`), [`gram_rows_upper_avx512`] (8-wide registers, up to 24 of them accumulating, each multiply-add
/// reading its broadcast operand from memory); elsewhere, or with the environment variable `FREEFLOAT_NO_AVX512`
/// set (read once per process), the x86-64-v3 kernel [`gram_rows_upper_avx2`]. Every entry on and above the
/// diagonal is the same chain of fused multiply-adds, row by row, in both: the results are the same to the bit.
/// On 192 rows × 53 columns (`examples/identify_profile.rs gram 20000`, AMD Zen 5): 174 ns per sample (AVX2)
/// and 100 ns (AVX-512), against 270 for [`GramLs`]. Public for that benchmark; the identification calls it
/// through its own pass.
pub fn gram_rows_upper(g: &mut [f64], b: &[f64], w: usize, rows: usize, cols: usize) {
    #[cfg(target_arch = "x86_64")]
    if avx512() {
        // SAFETY: `avx512()` is true only where the processor has AVX-512F (detected at run time).
        return unsafe { gram_rows_upper_avx512(g, b, w, rows, cols) };
    }
    gram_rows_upper_avx2(g, b, w, rows, cols)
}

/// Whether the AVX-512 kernels run: the processor has AVX-512F and `FREEFLOAT_NO_AVX512` is not set (it forces the
/// x86-64-v3 kernels, e.g. to compare them). Decided once per process.
pub fn avx512() -> bool {
    static USE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *USE.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        let has = std::arch::is_x86_feature_detected!("avx512f");
        #[cfg(not(target_arch = "x86_64"))]
        let has = false;
        has && std::env::var_os("FREEFLOAT_NO_AVX512").is_none()
    })
}

/// The x86-64-v3 kernel of [`gram_rows_upper`] (same contract). Each tile of G is 4 rows × 8 columns, held in eight
/// 4-wide registers while the rows stream past: per row, two vector loads, four broadcasts, eight FMAs. Where a
/// whole 4 × 8 tile would mostly lie below the diagonal or in the padding, a 4 × 4 tile does: the lower half of a
/// diagonal 8 × 8 block needs only its right four columns, and `cols` that is 4 past a multiple of 8 ends with a
/// 4-wide column strip (the identification's linear columns are then padded to a multiple of 4, not 8). That drops
/// a fifth of the multiply-adds of the identification's Gram pass.
pub fn gram_rows_upper_avx2(g: &mut [f64], b: &[f64], w: usize, rows: usize, cols: usize) {
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

/// The AVX-512 kernel of [`gram_rows_upper`] (same contract; the caller makes sure the processor has AVX-512F).
///
/// G is swept in strips of 8 columns (one 8-wide register; a last strip of 4 through a masked load and store),
/// and in each strip the rows of G from 0 to the strip's diagonal block in groups of up to 24: 24 accumulators,
/// so that the two FMA units (4 cycles of latency) always have independent work; per data row, one load of the
/// strip's 8 entries and one multiply-add per row of G with its factor broadcast from memory (no separate
/// broadcast instruction). The diagonal 8 × 8 block is formed whole, its lower half (28 of 64 entries) wasted: on
/// the identification's 56-wide rows that is 224 8-wide multiply-adds per row against 420 4-wide ones for the AVX2
/// kernel.
///
/// # Safety
/// The processor must support AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
pub unsafe fn gram_rows_upper_avx512(g: &mut [f64], b: &[f64], w: usize, rows: usize, cols: usize) {
    assert!(cols.is_multiple_of(4) && cols <= w && g.len() == w * w && b.len() >= rows * w, "Gram rows: shapes");
    for chunk in b[..rows * w].chunks(GRAM_CHUNK_512 * w) {
        let n = chunk.len() / w;
        for j0 in (0..cols).step_by(8) {
            // the strip's columns j0..j0 + 8, or the last four
            let mask: u8 = if j0 + 8 <= cols { 0xff } else { 0x0f };
            // rows 0..j0 + 8 of G (0..cols in a last four-wide strip), 24 at a time
            let end = (j0 + 8).min(cols);
            let mut i0 = 0;
            while i0 < end {
                let k = (end - i0).min(24);
                // SAFETY: the processor has AVX-512F (this function's contract); the shapes are the ones asserted
                // above and `strip` checks its own bounds.
                unsafe {
                    match k {
                        24 => strip::<24>(g, chunk, w, n, i0, j0, mask),
                        20 => strip::<20>(g, chunk, w, n, i0, j0, mask),
                        16 => strip::<16>(g, chunk, w, n, i0, j0, mask),
                        12 => strip::<12>(g, chunk, w, n, i0, j0, mask),
                        8 => strip::<8>(g, chunk, w, n, i0, j0, mask),
                        _ => strip::<4>(g, chunk, w, n, i0, j0, mask),
                    }
                }
                i0 += k;
            }
        }
    }
}

/// Rows `i0..i0 + R` of G, columns `j0..j0 + 8` (those of `mask`), plus Bᵀ B over the `n` rows of `chunk`.
///
/// # Safety
/// The processor must support AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[inline]
unsafe fn strip<const R: usize>(g: &mut [f64], chunk: &[f64], w: usize, n: usize, i0: usize, j0: usize, mask: u8) {
    use std::arch::x86_64::*;
    // every row i0..i0 + R and column j0..j0 + (8 or 4, as masked) lies inside the w-wide rows of G and of the chunk
    let width = if mask == 0xff { 8 } else { 4 };
    assert!(i0 + R <= w && j0 + width <= w && g.len() == w * w && chunk.len() >= n * w, "Gram strip: shapes");
    let gp = g.as_mut_ptr();
    let bp = chunk.as_ptr();
    // SAFETY: G's row i0 + r at column j0 is at (i0 + r)·w + j0, and a masked load or store touches only the
    // entries of `mask` (j0..j0 + width), inside G (asserted); the chunk's row r is at r·w, its entries j0..j0 +
    // width and i0..i0 + R inside it (asserted), r < n.
    unsafe {
        let mut acc: [__m512d; R] = [_mm512_setzero_pd(); R];
        for (r, a) in acc.iter_mut().enumerate() {
            *a = _mm512_maskz_loadu_pd(mask, gp.add((i0 + r) * w + j0));
        }
        for row in 0..n {
            let x = bp.add(row * w);
            let bj = _mm512_maskz_loadu_pd(mask, x.add(j0));
            for (r, a) in acc.iter_mut().enumerate() {
                *a = _mm512_fmadd_pd(_mm512_set1_pd(*x.add(i0 + r)), bj, *a);
            }
        }
        for (r, a) in acc.iter().enumerate() {
            _mm512_mask_storeu_pd(gp.add((i0 + r) * w + j0), mask, *a);
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
        // row counts below, at and across the L1 chunk; column tiles narrower than the row; both kernels (the
        // AVX-512 one where the processor has it)
        let w = 56;
        type Kernel = fn(&mut [f64], &[f64], usize, usize, usize);
        let mut kernels: Vec<(&str, Kernel)> = vec![("avx2", gram_rows_upper_avx2), ("dispatched", gram_rows_upper)];
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the processor has AVX-512F (just detected)
            kernels.push(("avx512", |g, b, w, r, c| unsafe { gram_rows_upper_avx512(g, b, w, r, c) }));
        }
        for (name, kernel) in kernels {
            for rows in [1, 7, GRAM_CHUNK, GRAM_CHUNK + 1, GRAM_CHUNK_512 + 1, 3 * GRAM_CHUNK_512 + 5] {
                for cols in (4..=w).step_by(4) {
                    let b: Vec<f64> = (0..rows * w).map(|k| mix(k / w, k % w)).collect();
                    let mut g = vec![1.0; w * w]; // accumulates onto what is there
                    kernel(&mut g, &b, w, rows, cols);
                    for i in 0..cols {
                        for j in i..cols {
                            let want = 1.0 + (0..rows).map(|r| b[r * w + i] * b[r * w + j]).sum::<f64>();
                            let got = g[i * w + j];
                            assert!(
                                (got - want).abs() <= 1e-13 * (1.0 + want.abs()),
                                "{name}: rows {rows} ({i},{j}): {got} vs {want}"
                            );
                        }
                    }
                    // outside the column range nothing is touched
                    assert!((0..w).all(|i| (cols..w).all(|j| g[i * w + j] == 1.0)), "{name}");
                }
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_avx512_kernel_gives_the_avx2_kernels_bits() {
        // every entry on and above the diagonal is the same chain of fused multiply-adds in both kernels
        if !std::arch::is_x86_feature_detected!("avx512f") {
            eprintln!("no AVX-512F on this processor: only the AVX2 kernel runs here");
            return;
        }
        let w = 56;
        for (rows, cols) in [(24, 56), (24, 20), (1, 4), (53, 44), (100, 56), (48, 20)] {
            let b: Vec<f64> = (0..rows * w).map(|k| mix(k / w, k % w) * (1.0 + (k % 13) as f64 / 7.0)).collect();
            let start: Vec<f64> = (0..w * w).map(|k| mix(k, 5)).collect();
            let (mut g2, mut g5) = (start.clone(), start);
            gram_rows_upper_avx2(&mut g2, &b, w, rows, cols);
            // SAFETY: the processor has AVX-512F (checked above)
            unsafe { gram_rows_upper_avx512(&mut g5, &b, w, rows, cols) };
            for i in 0..cols {
                for j in i..cols {
                    assert_eq!(g2[i * w + j].to_bits(), g5[i * w + j].to_bits(), "rows {rows} cols {cols} ({i},{j})");
                }
            }
        }
    }
}
