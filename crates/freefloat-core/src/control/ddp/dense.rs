//! Small dense kernels of the Riccati recursion, on column-major slices, without allocating.
//!
//! The matrices of one DDP node are small (tens of rows) and of run-time size, where nalgebra's dynamic
//! `gemm` packs through a heap buffer on every call and plain index loops neither vectorise nor hide the
//! latency of the multiply-adds. One kernel covers every product of the backward pass:
//! - `mul_nn`: `C (+)= A B` in axpy form, a block of 8 (or 4) rows times 4 columns of C held in registers
//!   while the inner dimension streams by (8 independent accumulator lanes per row block).
//!
//! A product with a transpose, `Aᵀ B`, is `mul_nn` on the transpose formed once (`transpose`): the kernel of dot
//! products of contiguous columns (4 at once, 4 partial sums each) it replaced took about 2–3 times as long per
//! multiply-add at these sizes (measured by leaving products out of the backward pass), far more than the copy
//! costs; in the code we inspected, the compiler had vectorised it across the 4 columns, with shuffles.
//! Products that are symmetric in exact arithmetic keep their upper triangle (`mirror_upper`).
//!
//! The kernels only change the order of the floating-point additions against the textbook loops.

/// `c (+)= a b` with `a` m × k, `b` k × n, `c` m × n, all column-major and contiguous; `acc`: add to `c`
/// instead of overwriting it.
pub(crate) fn mul_nn(c: &mut [f64], a: &[f64], b: &[f64], m: usize, k: usize, n: usize, acc: bool) {
    debug_assert!(a.len() >= m * k && b.len() >= k * n && c.len() >= m * n);
    let mut j = 0;
    while j + 4 <= n {
        let bj = [
            &b[j * k..(j + 1) * k],
            &b[(j + 1) * k..(j + 2) * k],
            &b[(j + 2) * k..(j + 3) * k],
            &b[(j + 3) * k..(j + 4) * k],
        ];
        let mut i = 0;
        while i + 8 <= m {
            let mut s = [[0.0_f64; 8]; 4];
            for p in 0..k {
                let ap: &[f64; 8] = a[p * m + i..p * m + i + 8].try_into().unwrap();
                for (q, sq) in s.iter_mut().enumerate() {
                    let bq = bj[q][p];
                    for r in 0..8 {
                        sq[r] += ap[r] * bq;
                    }
                }
            }
            for (q, sq) in s.iter().enumerate() {
                store(&mut c[(j + q) * m + i..(j + q) * m + i + 8], sq, acc);
            }
            i += 8;
        }
        while i + 4 <= m {
            let mut s = [[0.0_f64; 4]; 4];
            for p in 0..k {
                let ap: &[f64; 4] = a[p * m + i..p * m + i + 4].try_into().unwrap();
                for (q, sq) in s.iter_mut().enumerate() {
                    let bq = bj[q][p];
                    for r in 0..4 {
                        sq[r] += ap[r] * bq;
                    }
                }
            }
            for (q, sq) in s.iter().enumerate() {
                store(&mut c[(j + q) * m + i..(j + q) * m + i + 4], sq, acc);
            }
            i += 4;
        }
        for r in i..m {
            for (q, bq) in bj.iter().enumerate() {
                let mut t = 0.0;
                for p in 0..k {
                    t += a[p * m + r] * bq[p];
                }
                let cij = &mut c[(j + q) * m + r];
                *cij = if acc { *cij + t } else { t };
            }
        }
        j += 4;
    }
    for jj in j..n {
        let bj = &b[jj * k..(jj + 1) * k];
        let cj = &mut c[jj * m..(jj + 1) * m];
        if !acc {
            cj.fill(0.0);
        }
        for (p, &bp) in bj.iter().enumerate() {
            for (ci, ai) in cj.iter_mut().zip(&a[p * m..(p + 1) * m]) {
                *ci += ai * bp;
            }
        }
    }
}

#[inline(always)]
fn store(dst: &mut [f64], s: &[f64], acc: bool) {
    if acc {
        for (d, x) in dst.iter_mut().zip(s) {
            *d += x;
        }
    } else {
        dst.copy_from_slice(s);
    }
}

/// Dot product with 4 partial sums: the one in the dynamics derivatives (the Cholesky inverse uses it too).
pub(crate) use crate::dynamics::derivatives::dot;

/// Copy the upper triangle of the m × m column-major `c` onto its lower one (a product that is symmetric in exact
/// arithmetic made exactly so).
pub(crate) fn mirror_upper(c: &mut [f64], m: usize) {
    for j in 0..m {
        for i in j + 1..m {
            c[j * m + i] = c[i * m + j];
        }
    }
}

/// `t = aᵀ` with `a` m × n column-major (`t` n × m).
pub(crate) fn transpose(t: &mut [f64], a: &[f64], m: usize, n: usize) {
    debug_assert!(a.len() >= m * n && t.len() >= m * n);
    for j in 0..n {
        for (i, &x) in a[j * m..(j + 1) * m].iter().enumerate() {
            t[i * n + j] = x;
        }
    }
}

/// `y (+)= aᵀ x` with `a` k × m column-major: m dot products.
pub(crate) fn gemv_t(y: &mut [f64], a: &[f64], x: &[f64], k: usize, m: usize, acc: bool) {
    for (i, yi) in y.iter_mut().enumerate().take(m) {
        let t = dot(&a[i * k..(i + 1) * k], &x[..k]);
        *yi = if acc { *yi + t } else { t };
    }
}

/// `y += a x` with `a` m × k column-major (axpy form).
pub(crate) fn gemv_n_add(y: &mut [f64], a: &[f64], x: &[f64], m: usize, k: usize) {
    for (p, &xp) in x.iter().enumerate().take(k) {
        for (yi, ai) in y[..m].iter_mut().zip(&a[p * m..(p + 1) * m]) {
            *yi += ai * xp;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn filled(r: usize, c: usize, seed: f64) -> DMatrix<f64> {
        DMatrix::from_fn(r, c, |i, j| ((i * 7 + j * 13) as f64 * 0.37 + seed).sin())
    }

    /// Every kernel against nalgebra's own products, on sizes that hit each edge path.
    #[test]
    fn kernels_match_nalgebra() {
        for &(m, k, n) in &[(24, 24, 24), (24, 24, 12), (12, 12, 24), (13, 7, 5), (3, 9, 2), (1, 1, 1), (9, 4, 7)] {
            let a = filled(m, k, 0.1);
            let b = filled(k, n, 0.7);
            let c0 = filled(m, n, 1.3);
            let mut c = c0.clone();
            mul_nn(c.as_mut_slice(), a.as_slice(), b.as_slice(), m, k, n, true);
            assert!((&c - (&c0 + &a * &b)).amax() < 1e-12, "mul_nn acc {m}x{k}x{n}");
            mul_nn(c.as_mut_slice(), a.as_slice(), b.as_slice(), m, k, n, false);
            assert!((&c - &a * &b).amax() < 1e-12, "mul_nn {m}x{k}x{n}");
            // the transpose and a product with it, and a symmetric product mirrored: aᵀ a (+ a symmetric c)
            let at = filled(k, m, 0.4);
            let mut t = DMatrix::zeros(m, k);
            transpose(t.as_mut_slice(), at.as_slice(), k, m);
            assert_eq!(t, at.transpose(), "transpose {k}x{m}");
            let mut c = c0.clone();
            mul_nn(c.as_mut_slice(), t.as_slice(), b.as_slice(), m, k, n, true);
            assert!((&c - (&c0 + at.transpose() * &b)).amax() < 1e-12, "aᵀ b {m}x{k}x{n}");
            let s0 = &c0.rows(0, m.min(n)).columns(0, m.min(n)).into_owned();
            let s0 = s0 + s0.transpose();
            let mm = s0.nrows();
            let a2 = filled(k, mm, 0.9);
            let mut a2t = DMatrix::zeros(mm, k);
            transpose(a2t.as_mut_slice(), a2.as_slice(), k, mm);
            let mut s = s0.clone();
            mul_nn(s.as_mut_slice(), a2t.as_slice(), a2.as_slice(), mm, k, mm, true);
            mirror_upper(s.as_mut_slice(), mm);
            assert_eq!(s, s.transpose(), "mirror_upper {mm}");
            assert!((&s - (&s0 + a2.transpose() * &a2)).amax() < 1e-12, "aᵀ a {mm}x{k}");
            let x = filled(k, 1, 2.0);
            let mut y = filled(m, 1, 0.2);
            let y0 = y.clone();
            gemv_t(y.as_mut_slice(), at.as_slice(), x.as_slice(), k, m, true);
            assert!((&y - (&y0 + at.transpose() * &x)).amax() < 1e-12);
            let mut y = y0.clone();
            gemv_n_add(y.as_mut_slice(), a.as_slice(), x.as_slice(), m, k);
            assert!((&y - (&y0 + &a * &x)).amax() < 1e-12);
        }
    }
}
