//! Ordinary recursive least squares with an optional forgetting factor, for problems that are exactly
//! linear in the unknowns: `Φ_N θ = y_N + e`. In freefloat it solves the identification of Zhang, Yue, Yuan
//! 2020 written in standard parameters (docs/postcapture.md, "The two solvers"):
//! `[m, m b', I about the reference point]` of the base and of the target enter the momentum and Newton-Euler equations
//! linearly, so no second-order term (the paper's `D(μ)`) has to be handled.
//!
//! Cost per sample: O(r n²) for r rows and n unknowns, independent of how many samples came before.
//! Without forgetting the estimate after N samples is the ridge-regularised batch LS
//! `θ_N = (P_0⁻¹ + Σ ΦᵀΦ)⁻¹ (P_0⁻¹ θ_0 + Σ Φᵀ y)`, which the tests check.

use super::rls_kernel::{check_finite, check_len, check_time, row_update};
use crate::error::{FfError, Result};

/// Recursive least squares on `n` unknowns.
#[derive(Debug, Clone)]
pub struct Rls {
    n: usize,
    theta: Vec<f64>,
    /// scaled covariance, n × n row-major
    p: Vec<f64>,
    lambda: f64,
    u: Vec<f64>,
    samples: usize,
    last_t: Option<f64>,
    /// set when an update failed half-way: the state is then unusable and every later call errors
    failed: Option<String>,
}

impl Rls {
    /// `theta0`: initial estimate; `p0`: initial covariance, either n entries (diagonal) or n² (full,
    /// row-major, symmetric positive definite); `lambda` ∈ (0, 1]: forgetting factor (1 = none).
    pub fn new(theta0: &[f64], p0: &[f64], lambda: f64) -> Result<Self> {
        let n = theta0.len();
        if n == 0 {
            return Err(FfError::arg("theta0", "no unknowns"));
        }
        if let Some(i) = theta0.iter().position(|x| !x.is_finite()) {
            return Err(FfError::arg("theta0", format!("entry {i} is not finite")));
        }
        if !(lambda > 0.0 && lambda <= 1.0) {
            return Err(FfError::arg("lambda", format!("forgetting factor must be in (0, 1], got {lambda}")));
        }
        let p = full_covariance("p0", p0, n)?;
        Ok(Rls { n, theta: theta0.to_vec(), p, lambda, u: vec![0.0; n], samples: 0, last_t: None, failed: None })
    }

    /// Number of estimated parameters.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of samples folded in.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The current estimate (n).
    pub fn estimate(&self) -> &[f64] {
        &self.theta
    }

    /// Scaled covariance P (n × n, row-major).
    pub fn covariance(&self) -> &[f64] {
        &self.p
    }

    /// Fold in one sample taken at time `t`: `phi` is r × n row-major, `y` has r entries. O(r n²).
    /// Errors: wrong sizes, NaN/inf entries, `t` not after the previous sample, or a covariance that
    /// has lost positive definiteness (the estimator is then marked failed).
    pub fn update(&mut self, t: f64, phi: &[f64], y: &[f64]) -> Result<()> {
        if let Some(msg) = &self.failed {
            return Err(FfError::Numerical(format!("estimator failed earlier and must be reset: {msg}")));
        }
        let k = self.samples;
        let r = y.len();
        check_time(k, t, self.last_t)?;
        check_len("phi", k, phi, r * self.n)?;
        check_finite("phi", k, phi)?;
        check_finite("y", k, y)?;
        if self.lambda < 1.0 {
            // forgetting once per sample (see rls_kernel)
            let inv = 1.0 / self.lambda;
            self.p.iter_mut().for_each(|x| *x *= inv);
        }
        for (j, &yj) in y.iter().enumerate() {
            let row = &phi[j * self.n..(j + 1) * self.n];
            if let Err(e) = row_update(&mut self.p, &mut self.theta, row, yj, &mut self.u) {
                let msg = format!("sample {k}, row {j}: {e}");
                self.failed = Some(msg.clone());
                return Err(FfError::Numerical(msg));
            }
        }
        if let Some(i) = self.theta.iter().position(|x| !x.is_finite()) {
            let msg = format!("sample {k}: estimate overflowed (entry {i} is not finite)");
            self.failed = Some(msg.clone());
            return Err(FfError::Numerical(msg));
        }
        self.samples += 1;
        self.last_t = Some(t);
        Ok(())
    }
}

/// A covariance given as its diagonal (n entries) or in full (n², row-major), checked: finite,
/// symmetric, positive diagonal and positive definite (Cholesky).
pub(crate) fn full_covariance(name: &str, p0: &[f64], n: usize) -> Result<Vec<f64>> {
    if let Some(i) = p0.iter().position(|x| !x.is_finite()) {
        return Err(FfError::arg(name, format!("entry {i} is not finite")));
    }
    let p = if p0.len() == n {
        let mut p = vec![0.0; n * n];
        for i in 0..n {
            p[i * n + i] = p0[i];
        }
        p
    } else if p0.len() == n * n {
        p0.to_vec()
    } else {
        return Err(FfError::arg(
            name,
            format!("expected {n} (diagonal) or {} (full) entries, got {}", n * n, p0.len()),
        ));
    };
    for i in 0..n {
        for j in 0..i {
            let (a, b) = (p[i * n + j], p[j * n + i]);
            if (a - b).abs() > 1e-12 * (a.abs() + b.abs()).max(f64::MIN_POSITIVE) {
                return Err(FfError::arg(name, format!("not symmetric: entry ({i}, {j}) = {a} but ({j}, {i}) = {b}")));
            }
        }
    }
    let m = nalgebra::DMatrix::from_row_slice(n, n, &p);
    if m.cholesky().is_none() {
        return Err(FfError::arg(name, "the initial covariance must be positive definite"));
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    fn random_problem(n: usize, r: usize, samples: usize, seed: u64) -> (Vec<DMatrix<f64>>, DVector<f64>) {
        let mut rng = StdRng::seed_from_u64(seed);
        let truth = DVector::from_fn(n, |_, _| rng.gen_range(-3.0..3.0));
        let phis = (0..samples).map(|_| DMatrix::from_fn(r, n, |_, _| rng.gen_range(-1.0..1.0))).collect();
        (phis, truth)
    }

    fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
        m.transpose().as_slice().to_vec()
    }

    /// Independent check: the ridge-regularised batch normal equations, solved by Cholesky.
    #[test]
    fn equals_batch_ridge_solution() {
        for &(n, r) in &[(20, 6), (8, 3), (5, 1)] {
            let (phis, truth) = random_problem(n, r, 40, 3);
            let mut rng = StdRng::seed_from_u64(9);
            let theta0 = DVector::from_fn(n, |_, _| rng.gen_range(-1.0..1.0));
            let p0 = 0.5;
            let mut est = Rls::new(theta0.as_slice(), &vec![p0; n], 1.0).unwrap();
            let mut lhs = DMatrix::identity(n, n) / p0;
            let mut rhs = &theta0 / p0;
            for (k, phi) in phis.iter().enumerate() {
                let noise = DVector::from_fn(r, |_, _| rng.gen_range(-0.1..0.1));
                let y = phi * &truth + noise;
                est.update(k as f64, &row_major(phi), y.as_slice()).unwrap();
                lhs += phi.transpose() * phi;
                rhs += phi.transpose() * &y;
            }
            let batch = lhs.cholesky().unwrap().solve(&rhs);
            let got = DVector::from_column_slice(est.estimate());
            assert!((got - &batch).amax() < 1e-10 * batch.amax(), "n = {n}, r = {r}");
        }
    }

    /// With forgetting λ the recursion minimises Σ λ^{N−k} ‖y_k − Φ_k θ‖² + λ^N ‖θ − θ_0‖²_{P0⁻¹}.
    #[test]
    fn forgetting_equals_discounted_batch() {
        let (n, r, lam) = (6, 2, 0.9);
        let (phis, truth) = random_problem(n, r, 30, 5);
        let mut est = Rls::new(&vec![0.0; n], &vec![10.0; n], lam).unwrap();
        let big_n = phis.len() as i32;
        let mut lhs = DMatrix::identity(n, n) / 10.0 * lam.powi(big_n);
        let mut rhs = DVector::zeros(n);
        for (k, phi) in phis.iter().enumerate() {
            let y = phi * &truth + DVector::from_element(r, 0.01 * (k as f64).sin());
            est.update(k as f64, &row_major(phi), y.as_slice()).unwrap();
            let w = lam.powi(big_n - 1 - k as i32);
            lhs += phi.transpose() * phi * w;
            rhs += phi.transpose() * &y * w;
        }
        let batch = lhs.cholesky().unwrap().solve(&rhs);
        let got = DVector::from_column_slice(est.estimate());
        assert!((got - &batch).amax() < 1e-9 * batch.amax());
    }

    /// Forgetting tracks a parameter jump; without it the estimate stays near the average.
    #[test]
    fn forgetting_tracks_a_jump() {
        let mut rng = StdRng::seed_from_u64(1);
        let mut with = Rls::new(&[0.0, 0.0], &[1e3, 1e3], 0.8).unwrap();
        let mut without = Rls::new(&[0.0, 0.0], &[1e3, 1e3], 1.0).unwrap();
        for k in 0..200 {
            let truth = if k < 100 { [1.0, 2.0] } else { [3.0, -1.0] };
            let phi = [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0)];
            let y = [phi[0] * truth[0] + phi[1] * truth[1]];
            with.update(k as f64, &phi, &y).unwrap();
            without.update(k as f64, &phi, &y).unwrap();
        }
        assert!((with.estimate()[0] - 3.0).abs() < 1e-6 && (with.estimate()[1] + 1.0).abs() < 1e-6);
        assert!((without.estimate()[0] - 3.0).abs() > 0.3);
    }

    #[test]
    fn bad_input_is_an_error_not_nan() {
        let mut est = Rls::new(&[0.0, 0.0], &[1.0, 1.0], 1.0).unwrap();
        est.update(0.0, &[1.0, 0.0], &[1.0]).unwrap();
        let e = est.update(1.0, &[f64::NAN, 0.0], &[1.0]).unwrap_err().to_string();
        assert!(e.contains("sample 1") && e.contains("phi[0]"), "{e}");
        let e = est.update(1.0, &[1.0, 0.0], &[f64::INFINITY]).unwrap_err().to_string();
        assert!(e.contains("y[0]"), "{e}");
        let e = est.update(-1.0, &[1.0, 0.0], &[1.0]).unwrap_err().to_string();
        assert!(e.contains("backwards"), "{e}");
        let e = est.update(0.0, &[1.0, 0.0], &[1.0]).unwrap_err().to_string();
        assert!(e.contains("backwards"), "{e}");
        let e = est.update(2.0, &[1.0, 0.0, 3.0], &[1.0]).unwrap_err().to_string();
        assert!(e.contains("entries"), "{e}");
        assert!(est.estimate().iter().all(|x| x.is_finite()));
        assert!(Rls::new(&[0.0, 0.0], &[1.0, -1.0], 1.0).is_err());
        assert!(Rls::new(&[0.0, 0.0], &[1.0, 2.0, 3.0, 1.0], 1.0).unwrap_err().to_string().contains("symmetric"));
        assert!(Rls::new(&[0.0], &[1.0], 1.5).is_err());
        assert!(Rls::new(&[f64::NAN], &[1.0], 1.0).is_err());
    }

    /// A covariance that is not positive definite (an indefinite P injected in place of the valid
    /// one, as round-off under heavy forgetting would produce) is reported and the estimator refuses
    /// to continue, instead of returning NaN.
    #[test]
    fn loss_of_positive_definiteness_is_detected() {
        let mut est = Rls::new(&[0.0, 0.0], &[1.0, 1.0], 1.0).unwrap();
        est.p = vec![1.0, 2.0, 2.0, 1.0]; // eigenvalues 3 and −1
        let e = est.update(0.0, &[1.0, -1.0], &[1.0]).unwrap_err().to_string();
        assert!(e.contains("positive definiteness"), "{e}");
        let e = est.update(1.0, &[1.0, 0.0], &[1.0]).unwrap_err().to_string();
        assert!(e.contains("failed earlier"), "{e}");
    }
}
