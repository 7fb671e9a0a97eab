//! Small dense kernels without allocation: the product of the forward-dynamics derivatives (`gemm`, which skips
//! zero entries of its right factor), the inverse of a symmetric positive-definite matrix through its Cholesky
//! factor, and a vectorising dot product (the last two also serve the DDP backward pass, `control::ddp`).

use nalgebra::DMatrix;

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

/// Cholesky factor `l` of the symmetric positive-definite `a` and `inv = a⁻¹` (full), in place,
/// without allocating. False if `a` is not positive definite.
pub(crate) fn cholesky_inverse(a: &DMatrix<f64>, l: &mut DMatrix<f64>, inv: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    l.copy_from(a);
    // Left-looking, column-major: column j -= Σ_{k<j} L[j,k] L[j.., k], then scale by 1/√pivot.
    let ls = l.as_mut_slice();
    for j in 0..n {
        for k in 0..j {
            let ljk = ls[k * n + j];
            if ljk == 0.0 {
                continue;
            }
            let (left, right) = ls.split_at_mut(j * n);
            let ck = &left[k * n + j..k * n + n];
            for (x, y) in right[j..n].iter_mut().zip(ck) {
                *x -= ljk * y;
            }
        }
        let s = ls[j * n + j];
        if !(s > 0.0) || !s.is_finite() {
            return false;
        }
        let dj = s.sqrt();
        let inv_d = 1.0 / dj;
        ls[j * n + j] = dj;
        for x in ls[j * n + j + 1..(j + 1) * n].iter_mut() {
            *x *= inv_d;
        }
    }
    // inv = L⁻ᵀ L⁻¹ = Yᵀ Y with Y = L⁻¹ (lower triangular). First Y into inv, column by column by forward
    // substitution in axpy form (L y = e_c).
    let ls = l.as_slice();
    let is = inv.as_mut_slice();
    for c in 0..n {
        let x = &mut is[c * n..(c + 1) * n];
        x.fill(0.0);
        x[c] = 1.0;
        for k in c..n {
            let yk = x[k] / ls[k * n + k];
            x[k] = yk;
            for (xi, li) in x[k + 1..].iter_mut().zip(&ls[k * n + k + 1..(k + 1) * n]) {
                *xi -= yk * li;
            }
        }
    }
    // Then (Yᵀ Y)ᵢⱼ = Σ_{k ≥ j} Y_ki Y_kj for i ≤ j, in place: column by column, the diagonal last. An entry
    // written at (i < j) overwrites a zero of Y; the diagonal Y_jj is read only by entries (i, j') with
    // i, j' ≤ j, all done by then; the strict lower triangle of Y stays until the mirror at the end.
    for j in 0..n {
        for i in 0..=j {
            let (ci, cj) = (i * n, j * n);
            let t = dot(&is[ci + j..ci + n], &is[cj + j..cj + n]);
            is[cj + i] = t;
        }
    }
    for j in 0..n {
        for i in j + 1..n {
            is[j * n + i] = is[i * n + j];
        }
    }
    true
}

/// Dot product of two equally long slices with 4 partial sums (vectorises; a plain sum is one long dependency
/// chain). Also the DDP backward pass's dot product (`control::ddp::dense`).
#[inline(always)]
pub(crate) fn dot(x: &[f64], y: &[f64]) -> f64 {
    let mut s = [0.0_f64; 4];
    let (xc, yc) = (x.chunks_exact(4), y.chunks_exact(4));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (a, b) in xc.zip(yc) {
        for l in 0..4 {
            s[l] += a[l] * b[l];
        }
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for (a, b) in xr.iter().zip(yr) {
        t += a * b;
    }
    t
}
