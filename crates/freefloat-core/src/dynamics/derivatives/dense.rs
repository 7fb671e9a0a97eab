//! Small dense kernels without allocation: the product of the forward-dynamics derivatives (`gemm`, which skips
//! zero entries of its right factor), the inverse of a symmetric positive-definite matrix through its Cholesky
//! factor, and a vectorising dot product (the last two also serve the DDP backward pass, `control::ddp`).

use nalgebra::DMatrix;

/// `c = α a b + β c` without allocating (nalgebra's dynamic `gemm` packs through a heap buffer);
/// zero entries of `b` are skipped, which the block-diagonal Jacobians of ⊕ and the tree-sparse ∂τ/∂x have many of.
/// Each column of c is summed in registers in one pass over the column of b (up to 39 rows; beyond, tiles of 8 rows): an axpy
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
        match (n / 4, n % 4 != 0) {
            (2, false) => whole_column::<8, false>(cs, alpha, asl, bj, beta),
            (2, true) => whole_column::<8, true>(cs, alpha, asl, bj, beta),
            (3, false) => whole_column::<12, false>(cs, alpha, asl, bj, beta),
            (3, true) => whole_column::<12, true>(cs, alpha, asl, bj, beta),
            (4, false) => whole_column::<16, false>(cs, alpha, asl, bj, beta),
            (4, true) => whole_column::<16, true>(cs, alpha, asl, bj, beta),
            (5, false) => whole_column::<20, false>(cs, alpha, asl, bj, beta),
            (5, true) => whole_column::<20, true>(cs, alpha, asl, bj, beta),
            (6, false) => whole_column::<24, false>(cs, alpha, asl, bj, beta),
            (6, true) => whole_column::<24, true>(cs, alpha, asl, bj, beta),
            (7, false) => whole_column::<28, false>(cs, alpha, asl, bj, beta),
            (7, true) => whole_column::<28, true>(cs, alpha, asl, bj, beta),
            (8, false) => whole_column::<32, false>(cs, alpha, asl, bj, beta),
            (8, true) => whole_column::<32, true>(cs, alpha, asl, bj, beta),
            (9, false) => whole_column::<36, false>(cs, alpha, asl, bj, beta),
            (9, true) => whole_column::<36, true>(cs, alpha, asl, bj, beta),
            _ => tiled_column(cs, alpha, asl, bj, beta),
        }
    }
}

/// Column `c = α a b_j + β c` of 8 ≤ n < 40 rows in one pass over b_j: the first M = 4⌊n/4⌋ rows and, if `TAIL`,
/// the last 4 rows (overlapping them) summed in registers together (at most 10 four-lane accumulators).
#[inline(always)]
fn whole_column<const M: usize, const TAIL: bool>(c: &mut [f64], alpha: f64, a: &[f64], bj: &[f64], beta: f64) {
    let n = c.len();
    let (mut acc, mut tail) = ([0.0; M], [0.0; 4]);
    for (ak, &bkj) in a.chunks_exact(n).zip(bj) {
        if bkj == 0.0 {
            continue;
        }
        let head: &[f64; M] = ak[..M].try_into().expect("M ≤ n rows");
        for l in 0..M {
            acc[l] = head[l].mul_add(bkj, acc[l]);
        }
        if TAIL {
            let last: &[f64; 4] = ak[n - 4..].try_into().expect("4 ≤ n rows");
            for l in 0..4 {
                tail[l] = last[l].mul_add(bkj, tail[l]);
            }
        }
    }
    store(&mut c[..M], alpha, &acc, beta);
    if TAIL {
        store(&mut c[M..], alpha, &tail[4 - (n - M)..], beta);
    }
}

/// `c1 = α a b1` and `c2 = α a b2` (b1, b2 of one shape): the two products of the forward-dynamics derivatives with
/// one M⁻¹, in one pass over the columns of `a` per output column for 8 ≤ n < 28 rows (two sets of register
/// accumulators, each column of a loaded once for both), else as two `gemm`s.
pub(crate) fn gemm_pair(
    c1: &mut DMatrix<f64>,
    c2: &mut DMatrix<f64>,
    alpha: f64,
    a: &DMatrix<f64>,
    b1: &DMatrix<f64>,
    b2: &DMatrix<f64>,
) {
    let (n, p, kk) = (a.nrows(), b1.ncols(), a.ncols());
    debug_assert_eq!((b2.nrows(), b2.ncols()), (kk, p));
    let f = match (n / 4, n % 4 != 0) {
        (2, false) => column_pair::<8, false>,
        (2, true) => column_pair::<8, true>,
        (3, false) => column_pair::<12, false>,
        (3, true) => column_pair::<12, true>,
        (4, false) => column_pair::<16, false>,
        (4, true) => column_pair::<16, true>,
        (5, false) => column_pair::<20, false>,
        (5, true) => column_pair::<20, true>,
        (6, false) => column_pair::<24, false>,
        (6, true) => column_pair::<24, true>,
        _ => {
            gemm(c1, alpha, a, b1, 0.0);
            gemm(c2, alpha, a, b2, 0.0);
            return;
        }
    };
    let (asl, b1s, b2s) = (a.as_slice(), b1.as_slice(), b2.as_slice());
    for (j, (o1, o2)) in c1.as_mut_slice().chunks_exact_mut(n).zip(c2.as_mut_slice().chunks_exact_mut(n)).enumerate() {
        f(o1, o2, alpha, asl, &b1s[j * kk..(j + 1) * kk], &b2s[j * kk..(j + 1) * kk]);
    }
}

/// `whole_column` for two right-hand columns at once (β = 0).
#[inline(always)]
fn column_pair<const M: usize, const TAIL: bool>(
    c1: &mut [f64],
    c2: &mut [f64],
    alpha: f64,
    a: &[f64],
    b1: &[f64],
    b2: &[f64],
) {
    let n = c1.len();
    let (mut acc1, mut acc2, mut tail1, mut tail2) = ([0.0; M], [0.0; M], [0.0; 4], [0.0; 4]);
    for ((ak, &x1), &x2) in a.chunks_exact(n).zip(b1).zip(b2) {
        if x1 == 0.0 && x2 == 0.0 {
            continue;
        }
        let head: &[f64; M] = ak[..M].try_into().expect("M ≤ n rows");
        for l in 0..M {
            acc1[l] = head[l].mul_add(x1, acc1[l]);
            acc2[l] = head[l].mul_add(x2, acc2[l]);
        }
        if TAIL {
            let last: &[f64; 4] = ak[n - 4..].try_into().expect("4 ≤ n rows");
            for l in 0..4 {
                tail1[l] = last[l].mul_add(x1, tail1[l]);
                tail2[l] = last[l].mul_add(x2, tail2[l]);
            }
        }
    }
    store(&mut c1[..M], alpha, &acc1, 0.0);
    store(&mut c2[..M], alpha, &acc2, 0.0);
    if TAIL {
        store(&mut c1[M..], alpha, &tail1[4 - (n - M)..], 0.0);
        store(&mut c2[M..], alpha, &tail2[4 - (n - M)..], 0.0);
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
