//! What the triangular factor R says about the problem: condition number, rank, unexcited
//! directions, and the statistics of the estimate.

use super::{LsResult, Method};
use crate::error::{FfError, Result};
use nalgebra::{DMatrix, DVector};

/// A singular value of the column-equilibrated factor below `RANK_RTOL · σ_max` counts as zero.
/// Round-off leaves an exactly rank-deficient problem at σ ≈ ε·σ_max·√m ≈ 1e-13 relative, while a
/// genuinely excited but ill-conditioned one (κ up to ~1e10) stays above: the tests use κ = 1e8.
pub const RANK_RTOL: f64 = 1e-11;

/// A parameter combination the data does not excite: `Σ coef_k x_k` (unit norm), with its
/// singular value relative to the largest.
#[derive(Debug, Clone, PartialEq)]
pub struct Direction {
    /// Its singular value divided by the largest one.
    pub relative_sigma: f64,
    /// (parameter index, coefficient), largest first; coefficients below 1e-3 dropped
    pub terms: Vec<(usize, f64)>,
}

impl std::fmt::Display for Direction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let t: Vec<String> = self.terms.iter().map(|(k, c)| format!("{c:+.4}·x[{k}]")).collect();
        write!(f, "{} (σ/σmax = {:.1e})", t.join(" "), self.relative_sigma)
    }
}

/// Singular values (descending) and right singular vectors (rows of Vᵀ) of R.
fn svd_of(r: &DMatrix<f64>) -> (DVector<f64>, DMatrix<f64>) {
    let svd = r.clone().svd(false, true);
    let mut s = svd.singular_values.clone();
    let mut vt = svd.v_t.expect("requested V");
    // nalgebra does not promise an order: sort descending
    let mut idx: Vec<usize> = (0..s.len()).collect();
    idx.sort_by(|&a, &b| s[b].partial_cmp(&s[a]).unwrap_or(std::cmp::Ordering::Equal));
    let (s0, vt0) = (s.clone(), vt.clone());
    for (k, &i) in idx.iter().enumerate() {
        s[k] = s0[i];
        vt.row_mut(k).copy_from(&vt0.row(i));
    }
    (s, vt)
}

/// Condition number σ_max/σ_min of R (∞ if singular), exact from its SVD.
pub fn condition_number(r: &DMatrix<f64>) -> f64 {
    let (s, _) = svd_of(r);
    let smin = s[s.len() - 1];
    if smin > 0.0 {
        s[0] / smin
    } else {
        f64::INFINITY
    }
}

/// Column norms of R (= those of A) and R with unit columns. Rank is judged on the equilibrated
/// factor, so that parameter units (kg vs kg·m²) do not decide what counts as excited; an all-zero
/// column keeps scale 1 (it is unexcited either way).
fn equilibrated(r: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>) {
    let d: Vec<f64> = r.column_iter().map(|c| c.norm()).map(|x| if x > 0.0 { x } else { 1.0 }).collect();
    (DMatrix::from_fn(r.nrows(), r.ncols(), |i, j| r[(i, j)] / d[j]), d)
}

/// The directions of parameter space with σ < `RANK_RTOL`·σ_max of the column-equilibrated
/// regressor: what the data cannot identify. Each is `x = D⁻¹ z` (z a right singular vector of
/// `R D⁻¹`, D the column norms), i.e. `A x ≈ 0` in the original parameters, normalised.
pub fn unexcited_directions(r: &DMatrix<f64>) -> Vec<Direction> {
    let (rs, d) = equilibrated(r);
    let (s, vt) = svd_of(&rs);
    let smax = s[0];
    (0..s.len())
        .filter(|&k| !(s[k] > RANK_RTOL * smax))
        .map(|k| {
            let x = DVector::from_fn(d.len(), |i, _| vt[(k, i)] / d[i]).normalize();
            let xmax = x.amax();
            let mut terms: Vec<(usize, f64)> =
                x.iter().enumerate().filter(|(_, c)| c.abs() > 1e-3 * xmax).map(|(i, &c)| (i, c)).collect();
            terms.sort_by(|a, b| b.1.abs().partial_cmp(&a.1.abs()).unwrap());
            Direction { relative_sigma: if smax > 0.0 { s[k] / smax } else { 0.0 }, terms }
        })
        .collect()
}

/// Error if R is rank deficient, listing the unexcited combinations.
pub fn check_rank(r: &DMatrix<f64>) -> Result<()> {
    let dirs = unexcited_directions(r);
    if dirs.is_empty() {
        return Ok(());
    }
    let n = r.nrows();
    let list: Vec<String> = dirs.iter().map(|d| format!("  {d}")).collect();
    Err(FfError::Numerical(format!(
        "rank-deficient least-squares problem: rank {} of {n}; the data do not excite these parameter combinations:\n{}",
        n - dirs.len(),
        list.join("\n")
    )))
}

/// Fill in the statistics of an estimate from R (A = QR, any row order) and the RSS.
pub fn finish(r: &DMatrix<f64>, x: DVector<f64>, rss: f64, rows: usize, method: Method) -> LsResult {
    let n = r.nrows();
    let dof = rows.saturating_sub(n);
    let sigma2 = if dof > 0 { rss / dof as f64 } else { f64::NAN };
    // (RᵀR)⁻¹ = R⁻¹ R⁻ᵀ: invert the triangle (never form RᵀR, which squares κ)
    let mut rinv = DMatrix::identity(n, n);
    r.solve_upper_triangular_mut(&mut rinv);
    let covariance = (&rinv * rinv.transpose()) * sigma2;
    let std = DVector::from_iterator(n, (0..n).map(|k| covariance[(k, k)].max(0.0).sqrt()));
    LsResult { x, std, covariance, rss, dof, condition_number: condition_number(r), rank: n, rows, method }
}
