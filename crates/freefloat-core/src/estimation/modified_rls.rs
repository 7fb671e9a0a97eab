//! The modified RLS of Zhang, Yue, Yuan 2020 (eqs. 34-38): mass/CoM and inertia of two bodies in one step.
//!
//! The identification splits into
//! - `A μ = b` (eq. 34), linear in `μ = [m_1, m_1 b'_1, m_n, m_n b'_n]`, and
//! - `Φ θ = y + ψ D(μ)` (eq. 35), linear in the CoM inertias `θ = [I'_1#; I'_n#]` but with the
//!   second-order term `D(μ) = [m_1 J(b'_1); m_n J(b'_n)]` (eq. 23).
//!
//! Per sample: an RLS step on μ; the θ estimate is re-targeted to the new μ with the sensitivity
//! matrix M (eq. 37), then an RLS step on θ with `D(μ_N)`, and M is propagated (eq. 38). Because the
//! batch θ estimate is affine in `D(μ)` with slope `M(N) = P_N Σ Φ_kᵀ ψ_k`, the recursion returns
//! exactly the two-step LS estimate with the current μ plugged in (checked in the tests against a
//! batch solve). Cost per sample: O(r_μ n_μ² + r_θ (n_θ² + n_θ n_D)), independent of N.

use super::rls::full_covariance;
use super::rls_kernel::{check_finite, check_len, check_time, row_update};
use crate::error::{FfError, Result};

/// How `D(μ)` is built from μ (eq. 23, `m J(b') = [m, m b', m·mono(b')]` with the six monomials
/// `b_x², b_x b_y, b_x b_z, b_y², b_y b_z, b_z²`, or its planar reduction `[m, m b', m (b_x² + b_y²)]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coupling {
    /// 3D: per body `m J(b') = [m, m b' (3), m·(bx², bx by, bx bz, by², by bz, bz²)]`, 10 entries;
    /// μ has 4 entries per body.
    Spatial,
    /// Planar: per body `m J₂(b') = [m, m bx, m by, m (bx² + by²)]`, 4 entries; μ has 3 per body.
    Planar,
}

impl Coupling {
    /// Entries of μ per body.
    pub fn mu_per_body(self) -> usize {
        match self {
            Coupling::Spatial => 4,
            Coupling::Planar => 3,
        }
    }

    /// Entries of D(μ) per body.
    pub fn d_per_body(self) -> usize {
        match self {
            Coupling::Spatial => 10,
            Coupling::Planar => 4,
        }
    }

    /// D(μ) for the two bodies (Zhang 2020, eq. 23): `m J(b')` with `b' = (m b')/m`, i.e. the
    /// quadratic entries are `(m b')_k (m b')_l / m`. Errors if a mass estimate is not usable.
    pub fn d_of_mu(self, mu: &[f64], out: &mut [f64]) -> Result<()> {
        let (km, kd) = (self.mu_per_body(), self.d_per_body());
        for body in 0..2 {
            let x = &mu[body * km..(body + 1) * km];
            let o = &mut out[body * kd..(body + 1) * kd];
            let m = x[0];
            if !(m.abs() > 1e-300) || !m.is_finite() {
                return Err(FfError::Numerical(format!(
                    "mass estimate of body {} is {m}: b' = (m b')/m and D(μ) are undefined",
                    if body == 0 { "1 (base)" } else { "n (target)" }
                )));
            }
            o[..km].copy_from_slice(x);
            match self {
                Coupling::Spatial => {
                    let (hx, hy, hz) = (x[1], x[2], x[3]);
                    let g = 1.0 / m;
                    o[4] = hx * hx * g;
                    o[5] = hx * hy * g;
                    o[6] = hx * hz * g;
                    o[7] = hy * hy * g;
                    o[8] = hy * hz * g;
                    o[9] = hz * hz * g;
                }
                Coupling::Planar => o[3] = (x[1] * x[1] + x[2] * x[2]) / m,
            }
        }
        Ok(())
    }
}

/// One sample of the paper's problem; matrices row-major.
#[derive(Debug, Clone, Copy)]
pub struct CoupledSample<'a> {
    /// Sample time (s), increasing from sample to sample.
    pub t: f64,
    /// r_μ × n_μ (eq. 11 rows `ΔB`, or eq. 28 rows `G`)
    pub a: &'a [f64],
    /// r_μ (eq. 11 `ΔC`, or eq. 30 `K`)
    pub b: &'a [f64],
    /// r_θ × n_θ (eq. 17 `ΔD`, or eq. 32 `Q`)
    pub phi: &'a [f64],
    /// r_θ (`ΔE`, eq. 18, or `R`, eq. 33)
    pub y: &'a [f64],
    /// r_θ × n_D (`−[ΔH_1 ΔH_n]`, eq. 16, or `−[S_1 S_n]`, eq. 31)
    pub psi: &'a [f64],
}

/// The modified RLS as an online estimator.
#[derive(Debug, Clone)]
pub struct ModifiedRls {
    coupling: Coupling,
    n_mu: usize,
    n_th: usize,
    n_d: usize,
    mu: Vec<f64>,
    p_mu: Vec<f64>,
    theta: Vec<f64>,
    p_th: Vec<f64>,
    /// M(N), n_θ × n_D row-major, eq. (38); M(0) = 0
    sens: Vec<f64>,
    d_prev: Vec<f64>,
    d_new: Vec<f64>,
    u_mu: Vec<f64>,
    u_th: Vec<f64>,
    w: Vec<f64>,
    samples: usize,
    last_t: Option<f64>,
    failed: Option<String>,
}

impl ModifiedRls {
    /// `mu0` (2·mu_per_body), `theta0` (any n_θ ≥ 1): initial guesses; `p_mu0`, `p_th0`: initial
    /// covariances, diagonal or full (the paper uses 10⁶ I for both).
    pub fn new(coupling: Coupling, mu0: &[f64], p_mu0: &[f64], theta0: &[f64], p_th0: &[f64]) -> Result<Self> {
        let n_mu = 2 * coupling.mu_per_body();
        let n_d = 2 * coupling.d_per_body();
        let n_th = theta0.len();
        if mu0.len() != n_mu {
            return Err(FfError::arg("mu0", format!("expected {n_mu} entries, got {}", mu0.len())));
        }
        if n_th == 0 {
            return Err(FfError::arg("theta0", "no inertia unknowns"));
        }
        for (name, x) in [("mu0", mu0), ("theta0", theta0)] {
            if let Some(i) = x.iter().position(|v| !v.is_finite()) {
                return Err(FfError::arg(name, format!("entry {i} is not finite")));
            }
        }
        let p_mu = full_covariance("p_mu0", p_mu0, n_mu)?;
        let p_th = full_covariance("p_theta0", p_th0, n_th)?;
        let mut d_prev = vec![0.0; n_d];
        coupling.d_of_mu(mu0, &mut d_prev).map_err(|e| FfError::arg("mu0", e.to_string()))?;
        if d_prev.iter().any(|x| !x.is_finite()) {
            return Err(FfError::arg("mu0", "D(μ0) overflows: first moments far too large for the masses"));
        }
        Ok(ModifiedRls {
            coupling,
            n_mu,
            n_th,
            n_d,
            mu: mu0.to_vec(),
            p_mu,
            theta: theta0.to_vec(),
            p_th,
            sens: vec![0.0; n_th * n_d],
            d_new: d_prev.clone(),
            d_prev,
            u_mu: vec![0.0; n_mu],
            u_th: vec![0.0; n_th],
            w: vec![0.0; n_d],
            samples: 0,
            last_t: None,
            failed: None,
        })
    }

    /// Which coupling (2D or 3D scenario) this estimator was built for.
    pub fn coupling(&self) -> Coupling {
        self.coupling
    }

    /// Sizes `(n_mu, n_d, n_theta)` of the estimated vectors.
    pub fn sizes(&self) -> (usize, usize, usize) {
        (self.n_mu, self.n_th, self.n_d)
    }

    /// Number of samples folded in.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Current μ = [m_1, m_1 b'_1, m_n, m_n b'_n].
    pub fn mu(&self) -> &[f64] {
        &self.mu
    }

    /// Current θ = [I'_1#; I'_n#] (θ_{N,N}: consistent with the current μ).
    pub fn theta(&self) -> &[f64] {
        &self.theta
    }

    /// Sensitivity M(N) = ∂θ/∂D (n_θ × n_D, row-major), eq. (38).
    pub fn sensitivity(&self) -> &[f64] {
        &self.sens
    }

    /// Physical parameters of the two bodies: `[m_1, b'_1, m_n, b'_n]` (b' = (m b')/m).
    pub fn mass_and_com(&self) -> Vec<f64> {
        let k = self.coupling.mu_per_body();
        let mut out = self.mu.clone();
        for body in 0..2 {
            let m = self.mu[body * k];
            for j in 1..k {
                out[body * k + j] = self.mu[body * k + j] / m;
            }
        }
        out
    }

    /// Fold in one sample (Zhang 2020, eqs. 36-38). Errors: wrong sizes, NaN/inf, time not after the
    /// previous sample, a covariance losing positive definiteness or a vanishing mass estimate; after
    /// an error inside the recursion the estimator is marked failed.
    pub fn update(&mut self, s: &CoupledSample) -> Result<()> {
        if let Some(msg) = &self.failed {
            return Err(FfError::Numerical(format!("estimator failed earlier and must be reset: {msg}")));
        }
        let k = self.samples;
        let (r_mu, r_th) = (s.b.len(), s.y.len());
        check_time(k, s.t, self.last_t)?;
        check_len("a", k, s.a, r_mu * self.n_mu)?;
        check_len("phi", k, s.phi, r_th * self.n_th)?;
        check_len("psi", k, s.psi, r_th * self.n_d)?;
        for (what, x) in [("a", s.a), ("b", s.b), ("phi", s.phi), ("y", s.y), ("psi", s.psi)] {
            check_finite(what, k, x)?;
        }
        if let Err(e) = self.recurse(s) {
            let msg = format!("sample {k}: {e}");
            self.failed = Some(msg.clone());
            return Err(FfError::Numerical(msg));
        }
        self.samples += 1;
        self.last_t = Some(s.t);
        Ok(())
    }

    fn recurse(&mut self, s: &CoupledSample) -> Result<()> {
        let (n_mu, n_th, n_d) = (self.n_mu, self.n_th, self.n_d);
        // 1. μ-RLS, eq. (34).
        for (j, &bj) in s.b.iter().enumerate() {
            row_update(&mut self.p_mu, &mut self.mu, &s.a[j * n_mu..(j + 1) * n_mu], bj, &mut self.u_mu)?;
        }
        self.coupling.d_of_mu(&self.mu, &mut self.d_new)?;
        // 2. Re-target θ to μ_N, eq. (37): θ_{N−1,N} = θ_{N−1,N−1} + M(N−1) [D(μ_N) − D(μ_{N−1})].
        for i in 0..n_th {
            let row = &self.sens[i * n_d..(i + 1) * n_d];
            let mut acc = 0.0;
            for c in 0..n_d {
                acc += row[c] * (self.d_new[c] - self.d_prev[c]);
            }
            self.theta[i] += acc;
        }
        // 3. θ-RLS on y + ψ D(μ_N), row by row; 4. M(N) = (I − K Φ) M(N−1) + K ψ, eq. (38).
        // The 3D problem's sizes get a copy compiled for constant sizes (vectorised loops), as in rls_kernel.
        let st = ThetaState {
            p: &mut self.p_th,
            theta: &mut self.theta,
            u: &mut self.u_th,
            sens: &mut self.sens,
            w: &mut self.w,
        };
        match (n_th, n_d) {
            (12, 20) => theta_rows_fixed::<12, 20>(st, s, &self.d_new)?,
            _ => theta_rows(n_th, n_d, st, s, &self.d_new)?,
        }
        std::mem::swap(&mut self.d_prev, &mut self.d_new);
        // Overflow (e.g. a mass estimate close to zero making D(μ) huge) must not leak out as inf/NaN.
        if let Some(i) = self.mu.iter().chain(&self.theta).chain(&self.d_prev).position(|x| !x.is_finite()) {
            return Err(FfError::Numerical(format!(
                "estimate overflowed (entry {i} of [μ, θ, D(μ)] is not finite); the data do not determine the masses"
            )));
        }
        Ok(())
    }
}

/// The θ side of one sample, borrowed from the estimator.
struct ThetaState<'a> {
    p: &'a mut [f64],
    theta: &'a mut [f64],
    u: &'a mut [f64],
    sens: &'a mut [f64],
    w: &'a mut [f64],
}

/// Steps 3-4 of the recursion for every θ row of a sample: RLS on y + ψ D(μ_N) (eq. 35 with μ_N), then
/// M(N) = (I − K Φ) M(N−1) + K ψ (eq. 38). `#[inline(always)]` so literal sizes give constant trip counts.
#[inline(always)]
fn theta_rows(n_th: usize, n_d: usize, st: ThetaState, s: &CoupledSample, d_new: &[f64]) -> Result<()> {
    let sens = &mut st.sens[..n_th * n_d];
    let w = &mut st.w[..n_d];
    let d_new = &d_new[..n_d];
    for j in 0..s.y.len() {
        let phi = &s.phi[j * n_th..(j + 1) * n_th];
        let psi = &s.psi[j * n_d..(j + 1) * n_d];
        let mut y = s.y[j];
        for c in 0..n_d {
            y += psi[c] * d_new[c];
        }
        row_update(st.p, st.theta, phi, y, st.u)?;
        // u now holds the gain k; w = ψ_j − φ_jᵀ M (no test for zero φ entries: the branch costs more
        // than it saves, measured).
        w.copy_from_slice(psi);
        for i in 0..n_th {
            let (f, row) = (phi[i], &sens[i * n_d..(i + 1) * n_d]);
            for c in 0..n_d {
                w[c] -= f * row[c];
            }
        }
        for i in 0..n_th {
            let (g, row) = (st.u[i], &mut sens[i * n_d..(i + 1) * n_d]);
            for c in 0..n_d {
                row[c] += g * w[c];
            }
        }
    }
    Ok(())
}

/// [`theta_rows`] for sizes known at compile time (the 3D problem: n_θ = 12, n_D = 20): M as rows of
/// arrays, so the two M passes per row have constant trip counts and no bounds checks.
#[inline(always)]
fn theta_rows_fixed<const NT: usize, const ND: usize>(st: ThetaState, s: &CoupledSample, d_new: &[f64]) -> Result<()> {
    let (rows, _) = st.sens[..NT * ND].as_chunks_mut::<ND>();
    let sens: &mut [[f64; ND]; NT] = rows.try_into().expect("n_θ × n_D sensitivity");
    let d_new: &[f64; ND] = d_new[..ND].try_into().expect("n_D entries of D(μ)");
    for j in 0..s.y.len() {
        let phi: &[f64; NT] = s.phi[j * NT..(j + 1) * NT].try_into().expect("n_θ regressors");
        let psi: &[f64; ND] = s.psi[j * ND..(j + 1) * ND].try_into().expect("n_D coupling entries");
        let mut y = s.y[j];
        for c in 0..ND {
            y += psi[c] * d_new[c];
        }
        row_update(st.p, st.theta, phi, y, st.u)?;
        // u now holds the gain k; w = ψ_j − φ_jᵀ M, then M += k wᵀ (eq. 38)
        let mut w = *psi;
        for i in 0..NT {
            let f = phi[i];
            for c in 0..ND {
                w[c] -= f * sens[i][c];
            }
        }
        for i in 0..NT {
            let g = st.u[i];
            for c in 0..ND {
                sens[i][c] += g * w[c];
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
        m.transpose().as_slice().to_vec()
    }

    /// Draw a random coupled problem from a true (m, b', I) and check the recursion against the
    /// two-step batch least squares with the same priors (the batch estimate is affine in D(μ) with slope M(N),
    /// which is what eq. 38 propagates, so the recursion is exact):
    /// μ_N = ridge LS of (A, b); θ_N = ridge LS of (Φ, y + ψ D(μ_N)).
    fn check_against_batch(coupling: Coupling, n_th: usize, r_mu: usize, r_th: usize) {
        let mut rng = StdRng::seed_from_u64(11);
        let k = coupling.mu_per_body();
        let n_mu = 2 * k;
        let n_d = 2 * coupling.d_per_body();
        // truth: masses ~ 500, 250; offsets ~ 0.1
        let mut mu_true = vec![0.0; n_mu];
        for body in 0..2 {
            let m = if body == 0 { 500.0 } else { 250.0 };
            mu_true[body * k] = m;
            for j in 1..k {
                mu_true[body * k + j] = m * rng.gen_range(-0.3..0.3);
            }
        }
        let mut d_true = vec![0.0; n_d];
        coupling.d_of_mu(&mu_true, &mut d_true).unwrap();
        let th_true = DVector::from_fn(n_th, |_, _| rng.gen_range(5.0..80.0));
        let mu0: Vec<f64> = (0..n_mu).map(|i| if i % k == 0 { 300.0 } else { 1.0 }).collect();
        let th0 = vec![10.0; n_th];
        let (p_mu0, p_th0) = (1e2, 1e3);
        let mut est = ModifiedRls::new(coupling, &mu0, &vec![p_mu0; n_mu], &th0, &vec![p_th0; n_th]).unwrap();
        let mut lhs_mu = DMatrix::identity(n_mu, n_mu) / p_mu0;
        let mut rhs_mu = DVector::from_column_slice(&mu0) / p_mu0;
        let mut lhs_th = DMatrix::identity(n_th, n_th) / p_th0;
        let mut rhs_th = DVector::from_column_slice(&th0) / p_th0;
        let mut rhs_psi = DMatrix::zeros(n_th, n_d);
        for step in 0..25 {
            let a = DMatrix::from_fn(r_mu, n_mu, |_, _| rng.gen_range(-1.0..1.0));
            let phi = DMatrix::from_fn(r_th, n_th, |_, _| rng.gen_range(-1.0..1.0));
            let psi = DMatrix::from_fn(r_th, n_d, |_, _| rng.gen_range(-1.0..1.0));
            // small model error so that the LS solutions are not just the truth
            let b = &a * DVector::from_column_slice(&mu_true) + DVector::from_fn(r_mu, |_, _| rng.gen_range(-1.0..1.0));
            let y = &phi * &th_true - &psi * DVector::from_column_slice(&d_true)
                + DVector::from_fn(r_th, |_, _| rng.gen_range(-0.1..0.1));
            let (ra, rb, rp, ry, rs) =
                (row_major(&a), b.as_slice().to_vec(), row_major(&phi), y.as_slice().to_vec(), row_major(&psi));
            est.update(&CoupledSample { t: step as f64, a: &ra, b: &rb, phi: &rp, y: &ry, psi: &rs }).unwrap();
            lhs_mu += a.transpose() * &a;
            rhs_mu += a.transpose() * &b;
            lhs_th += phi.transpose() * &phi;
            rhs_th += phi.transpose() * &y;
            rhs_psi += phi.transpose() * &psi;
            // batch two-step at this N
            let mu_b = lhs_mu.clone().cholesky().unwrap().solve(&rhs_mu);
            let mut d_b = vec![0.0; n_d];
            coupling.d_of_mu(mu_b.as_slice(), &mut d_b).unwrap();
            let th_b =
                lhs_th.clone().cholesky().unwrap().solve(&(&rhs_th + &rhs_psi * DVector::from_column_slice(&d_b)));
            let e_mu = (DVector::from_column_slice(est.mu()) - &mu_b).amax() / mu_b.amax();
            let e_th = (DVector::from_column_slice(est.theta()) - &th_b).amax() / th_b.amax();
            assert!(e_mu < 1e-10 && e_th < 1e-9, "{coupling:?} step {step}: {e_mu:e} {e_th:e}");
        }
    }

    #[test]
    fn spatial_equals_two_step_batch() {
        check_against_batch(Coupling::Spatial, 12, 3, 3);
    }

    #[test]
    fn planar_equals_two_step_batch() {
        check_against_batch(Coupling::Planar, 2, 2, 1);
    }

    /// D(μ) closed form against m·J(b') built from b' directly (eq. 23).
    #[test]
    fn d_of_mu_matches_eq_23() {
        let (m, b) = (250.0, [0.25, 0.1, -0.3]);
        let mu = [m, m * b[0], m * b[1], m * b[2], 1.0, 0.0, 0.0, 0.0];
        let mut d = [0.0; 20];
        Coupling::Spatial.d_of_mu(&mu, &mut d).unwrap();
        let j = [1.0, b[0], b[1], b[2], b[0] * b[0], b[0] * b[1], b[0] * b[2], b[1] * b[1], b[1] * b[2], b[2] * b[2]];
        for i in 0..10 {
            assert!((d[i] - m * j[i]).abs() < 1e-12 * m, "{i}");
        }
        let mut d2 = [0.0; 8];
        Coupling::Planar.d_of_mu(&[m, m * b[0], m * b[1], 1.0, 0.0, 0.0], &mut d2).unwrap();
        assert!((d2[3] - m * (b[0] * b[0] + b[1] * b[1])).abs() < 1e-12 * m);
    }

    #[test]
    fn bad_samples_are_errors() {
        let c = Coupling::Planar;
        let mut est =
            ModifiedRls::new(c, &[600.0, 0.0, 0.0, 100.0, 10.0, 10.0], &[1e6; 6], &[100.0, 10.0], &[1e6; 2]).unwrap();
        let (a, b, phi, y, psi) = (vec![1.0; 12], vec![1.0; 2], vec![1.0; 2], vec![1.0], vec![0.0; 8]);
        est.update(&CoupledSample { t: 0.1, a: &a, b: &b, phi: &phi, y: &y, psi: &psi }).unwrap();
        let mut bad = a.clone();
        bad[3] = f64::NAN;
        let e = est.update(&CoupledSample { t: 0.2, a: &bad, b: &b, phi: &phi, y: &y, psi: &psi }).unwrap_err();
        assert!(e.to_string().contains("sample 1: a[3]"), "{e}");
        let e = est.update(&CoupledSample { t: 0.05, a: &a, b: &b, phi: &phi, y: &y, psi: &psi }).unwrap_err();
        assert!(e.to_string().contains("backwards"), "{e}");
        let e = est.update(&CoupledSample { t: 0.3, a: &a, b: &b, phi: &phi, y: &y, psi: &psi[..7] }).unwrap_err();
        assert!(e.to_string().contains("psi"), "{e}");
        assert!(est.mu().iter().chain(est.theta()).all(|x| x.is_finite()));
        // a guess whose D(μ) overflows is refused up front (the update also checks its own results)
        assert!(ModifiedRls::new(c, &[1.0, 1e200, 0.0, 1.0, 0.0, 0.0], &[1.0; 6], &[1.0, 1.0], &[1.0; 2]).is_err());
        // a zero initial mass makes D(μ) undefined
        assert!(ModifiedRls::new(c, &[0.0; 6], &[1.0; 6], &[1.0], &[1.0]).is_err());
    }
}
