//! The inner step shared by the recursive estimators: one scalar measurement `y = φᵀθ + e` folded
//! into an estimate θ and its (scaled) covariance P.
//!
//! A sample with r rows is processed as r scalar updates. Without forgetting this is exactly the
//! block update `K = PΦᵀ(I + ΦPΦᵀ)⁻¹` (both give `P_N⁻¹ = P_{N−1}⁻¹ + ΦᵀΦ`), and it needs no r×r
//! inverse. With a forgetting factor λ the caller divides P by λ once per sample before its rows,
//! so that `P_N⁻¹ = λ P_{N−1}⁻¹ + ΦᵀΦ`, the block form again.
//!
//! The size is a run-time value, but the public entry points dispatch the common sizes to a copy of
//! the kernel compiled for that constant size (`#[inline(always)]` + a literal argument), so the
//! loops have known trip counts and vectorise: this is what makes ~10⁶ updates/s possible for 20
//! unknowns.

use crate::error::{FfError, Result};

/// `u = P φ`, `s = 1 + φᵀ u`, gain `k = u / s`; θ += k (y − φᵀθ); P ← P − u uᵀ / s. (Forgetting is
/// applied by the caller as P ← P/λ once per sample before the rows: that equals the λ-RLS update.)
/// Leaves the gain `k = u / s` in `u` for callers that need it (the modified RLS's M).
///
/// Errors (instead of silently producing NaN): `s` not positive/finite, or a diagonal entry of the
/// updated P not positive — P has lost positive definiteness (round-off after long forgetting, or
/// a caller-supplied P that was not positive definite).
#[inline(always)]
fn row_update_n(n: usize, p: &mut [f64], theta: &mut [f64], phi: &[f64], y: f64, u: &mut [f64]) -> Result<()> {
    let p = &mut p[..n * n];
    let theta = &mut theta[..n];
    let phi = &phi[..n];
    let u = &mut u[..n];
    // u = P φ as a sum of rows (P is symmetric): axpy loops vectorise, a dot-product reduction
    // would not (floating-point sums are not reassociated by the compiler). No test for zero entries
    // of φ: the branch costs more than the sparse rows save (measured).
    u.fill(0.0);
    for j in 0..n {
        let (f, row) = (phi[j], &p[j * n..j * n + n]);
        for i in 0..n {
            u[i] += row[i] * f;
        }
    }
    let mut s = 1.0;
    let mut pred = 0.0;
    for i in 0..n {
        s += phi[i] * u[i];
        pred += phi[i] * theta[i];
    }
    if !(s > 0.0) || !s.is_finite() {
        return Err(FfError::Numerical(format!(
            "RLS covariance lost positive definiteness (1 + φᵀPφ = {s:e}); reset the estimator or use less forgetting"
        )));
    }
    let e = y - pred;
    let g = 1.0 / s;
    for i in 0..n {
        theta[i] += u[i] * g * e;
    }
    // P ← P − w wᵀ with w = u/√s, on the upper triangle only, then mirrored: P stays exactly symmetric
    // and the update does half the multiply-subtracts (measured 2.8× faster per 20 × 6 sample than the
    // full square, whose loop the compiler vectorises less well).
    let rg = g.sqrt();
    for x in u.iter_mut() {
        *x *= rg;
    }
    for i in 0..n {
        let wi = u[i];
        let row = &mut p[i * n..i * n + n];
        for j in i..n {
            row[j] -= wi * u[j];
        }
    }
    for i in 1..n {
        for j in 0..i {
            p[i * n + j] = p[j * n + i];
        }
    }
    for i in 0..n {
        let d = p[i * n + i];
        if !(d > 0.0) || !d.is_finite() {
            return Err(FfError::Numerical(format!(
                "RLS covariance lost positive definiteness (diagonal entry {i} = {d:e})"
            )));
        }
    }
    for x in u.iter_mut() {
        *x *= rg;
    }
    Ok(())
}

/// The same step for a size known at compile time: P as an N × N array of rows, φ, θ and the gain as
/// arrays, so every loop has a constant trip count, no bounds checks and vectorises. The covariance
/// update is the full square `P ← P − w wᵀ` with `w = u/√s`: `w_i w_j` and `w_j w_i` are the same
/// floating-point product, so P stays exactly symmetric without the triangle-and-mirror passes the
/// run-time-size kernel needs (with constant sizes the square vectorises fully and is faster).
#[inline(always)]
fn row_update_fixed<const N: usize>(
    p: &mut [f64],
    theta: &mut [f64],
    phi: &[f64],
    y: f64,
    u: &mut [f64],
) -> Result<()> {
    let (rows, _) = p[..N * N].as_chunks_mut::<N>();
    let p: &mut [[f64; N]; N] = rows.try_into().expect("N × N covariance");
    let theta: &mut [f64; N] = (&mut theta[..N]).try_into().expect("N unknowns");
    let phi: &[f64; N] = phi[..N].try_into().expect("N regressors");
    let u: &mut [f64; N] = (&mut u[..N]).try_into().expect("N gains");
    // u = P φ as a sum of rows (P symmetric): axpy loops vectorise
    let mut pu = [0.0; N];
    for j in 0..N {
        let f = phi[j];
        for i in 0..N {
            pu[i] += p[j][i] * f;
        }
    }
    let mut s = 1.0;
    let mut pred = 0.0;
    for i in 0..N {
        s += phi[i] * pu[i];
        pred += phi[i] * theta[i];
    }
    if !(s > 0.0) || !s.is_finite() {
        return Err(FfError::Numerical(format!(
            "RLS covariance lost positive definiteness (1 + φᵀPφ = {s:e}); reset the estimator or use less forgetting"
        )));
    }
    let g = 1.0 / s;
    let ge = g * (y - pred);
    let rg = g.sqrt();
    let mut w = [0.0; N];
    for i in 0..N {
        theta[i] += pu[i] * ge;
        w[i] = pu[i] * rg;
    }
    let mut diag_ok = true;
    for i in 0..N {
        let wi = w[i];
        let row = &mut p[i];
        for j in 0..N {
            row[j] -= wi * w[j];
        }
        diag_ok &= row[i] > 0.0 && row[i].is_finite();
    }
    if !diag_ok {
        let i = (0..N).find(|&i| !(p[i][i] > 0.0 && p[i][i].is_finite())).unwrap_or(0);
        return Err(FfError::Numerical(format!(
            "RLS covariance lost positive definiteness (diagonal entry {i} = {:e})",
            p[i][i]
        )));
    }
    for i in 0..N {
        u[i] = pu[i] * g;
    }
    Ok(())
}

/// Dispatch to a constant-size copy for the sizes of the Zhang, Yue, Yuan 2020 problems (2D/3D, paper and
/// standard forms); any other size runs the same code with a run-time bound.
#[inline(always)]
fn row_update_sized(p: &mut [f64], theta: &mut [f64], phi: &[f64], y: f64, u: &mut [f64]) -> Result<()> {
    match theta.len() {
        2 => row_update_fixed::<2>(p, theta, phi, y, u),
        6 => row_update_fixed::<6>(p, theta, phi, y, u),
        8 => row_update_fixed::<8>(p, theta, phi, y, u),
        12 => row_update_fixed::<12>(p, theta, phi, y, u),
        20 => row_update_fixed::<20>(p, theta, phi, y, u),
        n => row_update_n(n, p, theta, phi, y, u),
    }
}

/// One scalar measurement. (The crate is compiled for the machine it runs on, `-C target-cpu=native`, so
/// the constant-size copies already use its widest vector unit.)
pub(crate) fn row_update(p: &mut [f64], theta: &mut [f64], phi: &[f64], y: f64, u: &mut [f64]) -> Result<()> {
    row_update_sized(p, theta, phi, y, u)
}

/// Check a slice is finite, naming the sample and the field.
pub(crate) fn check_finite(what: &str, sample: usize, x: &[f64]) -> Result<()> {
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(FfError::arg("sample", format!("sample {sample}: {what}[{i}] is {} (must be finite)", x[i])));
    }
    Ok(())
}

/// Check a slice has `n` entries.
pub(crate) fn check_len(what: &str, sample: usize, x: &[f64], n: usize) -> Result<()> {
    if x.len() != n {
        return Err(FfError::arg("sample", format!("sample {sample}: {what} has {} entries, expected {n}", x.len())));
    }
    Ok(())
}

/// Check the sample time is finite and strictly after the previous one.
pub(crate) fn check_time(sample: usize, t: f64, last: Option<f64>) -> Result<()> {
    if !t.is_finite() {
        return Err(FfError::arg("sample", format!("sample {sample}: time is {t} (must be finite)")));
    }
    if let Some(l) = last {
        if !(t > l) {
            return Err(FfError::arg(
                "sample",
                format!("sample {sample}: time {t} is not after the previous sample's time {l} (time going backwards)"),
            ));
        }
    }
    Ok(())
}
