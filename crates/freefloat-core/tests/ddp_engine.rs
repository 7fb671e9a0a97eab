//! DDP engine acceptance tests (Valverde 2018 ch. 8): LQ exactness against the batch
//! least-squares solution, backward-pass equivalence with eqs. (8.32)–(8.33), full DDP vs iLQG on
//! quadratic dynamics, regularisation and line-search behaviour, the feasibility-driven variant, bad input.

// Table values are printed numbers (not approximations of constants); loops index several arrays.
#![allow(clippy::approx_constant, clippy::needless_range_loop)]

use freefloat_core::control::ddp::backward::{backward_pass, Backward};
use freefloat_core::control::ddp::{
    ActionModel, DdpOptions, DynamicsHessian, NodeDiff, RegOptions, Solver, StopReason, Variant, Workspace,
};
use freefloat_core::Result;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};

/// x⁺ = A x + B u + c·(½ xᵀx) (c = 0: linear), ℓ = ½ xᵀQx + qᵀx + ½ uᵀRu + rᵀu, ℓ_N = ½ xᵀQf x + qfᵀx.
struct Lq {
    n: usize,
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    c: DVector<f64>,
    q: DMatrix<f64>,
    ql: DVector<f64>,
    r: DMatrix<f64>,
    rl: DVector<f64>,
    qf: DMatrix<f64>,
    with_hessian: bool,
}

fn spd(rng: &mut rand::rngs::StdRng, n: usize, shift: f64) -> DMatrix<f64> {
    let m = DMatrix::from_fn(n, n, |_, _| rng.gen_range(-1.0..1.0));
    &m * m.transpose() + DMatrix::identity(n, n) * shift
}

impl Lq {
    fn random(seed: u64, nx: usize, nu: usize, n: usize) -> Lq {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let a = DMatrix::from_fn(nx, nx, |i, j| if i == j { 0.9 } else { 0.0 } + 0.2 * rng.gen_range(-1.0..1.0));
        let b = DMatrix::from_fn(nx, nu, |_, _| rng.gen_range(-1.0..1.0));
        Lq {
            n,
            q: spd(&mut rng, nx, 0.1),
            ql: DVector::from_fn(nx, |_, _| rng.gen_range(-1.0..1.0)),
            r: spd(&mut rng, nu, 0.5),
            rl: DVector::from_fn(nu, |_, _| rng.gen_range(-1.0..1.0)),
            qf: spd(&mut rng, nx, 1.0),
            c: DVector::zeros(nx),
            a,
            b,
            with_hessian: false,
        }
    }
}

impl ActionModel for Lq {
    fn nx(&self) -> usize {
        self.a.nrows()
    }
    fn ndx(&self) -> usize {
        self.a.nrows()
    }
    fn nu(&self) -> usize {
        self.b.ncols()
    }
    fn horizon(&self) -> usize {
        self.n
    }
    fn integrate(&self, x: &[f64], dx: &[f64], out: &mut [f64]) {
        for i in 0..x.len() {
            out[i] = x[i] + dx[i];
        }
    }
    fn difference(&self, x0: &[f64], x1: &[f64], out: &mut [f64]) {
        for i in 0..x0.len() {
            out[i] = x1[i] - x0[i];
        }
    }
    fn calc(&mut self, _k: usize, x: &[f64], u: &[f64], xnext: &mut [f64]) -> Result<f64> {
        let x = DVector::from_column_slice(x);
        let u = DVector::from_column_slice(u);
        let xn = &self.a * &x + &self.b * &u + &self.c * (0.5 * x.dot(&x));
        xnext.copy_from_slice(xn.as_slice());
        Ok(0.5 * x.dot(&(&self.q * &x)) + self.ql.dot(&x) + 0.5 * u.dot(&(&self.r * &u)) + self.rl.dot(&u))
    }
    fn calc_terminal(&mut self, x: &[f64]) -> Result<f64> {
        let x = DVector::from_column_slice(x);
        Ok(0.5 * x.dot(&(&self.qf * &x)) + self.ql.dot(&x))
    }
    fn calc_diff(&mut self, _k: usize, x: &[f64], u: &[f64], d: &mut NodeDiff) -> Result<()> {
        let x = DVector::from_column_slice(x);
        let u = DVector::from_column_slice(u);
        d.fx.copy_from(&(&self.a + &self.c * x.transpose()));
        d.fu.copy_from(&self.b);
        d.lx.copy_from(&(&self.q * &x + &self.ql));
        d.lu.copy_from(&(&self.r * &u + &self.rl));
        d.lxx.copy_from(&self.q);
        d.luu.copy_from(&self.r);
        d.lxu.fill(0.0);
        Ok(())
    }
    fn calc_diff_terminal(&mut self, x: &[f64], d: &mut NodeDiff) -> Result<()> {
        let x = DVector::from_column_slice(x);
        d.lx.copy_from(&(&self.qf * &x + &self.ql));
        d.lxx.copy_from(&self.qf);
        Ok(())
    }
    fn dynamics_hessian(
        &mut self,
        _k: usize,
        _x: &[f64],
        _u: &[f64],
        l: &[f64],
        out: &mut DynamicsHessian,
    ) -> Result<bool> {
        if !self.with_hessian {
            return Ok(false);
        }
        // ∂²F^j/∂x² = c_j I.
        let s: f64 = (0..l.len()).map(|j| l[j] * self.c[j]).sum();
        out.hxx.fill(0.0);
        out.hxx.fill_diagonal(s);
        out.huu.fill(0.0);
        out.hux.fill(0.0);
        Ok(true)
    }
}

/// The global optimum by batch least squares: X = S x0 + T U, minimise the whole quadratic in U.
fn batch_optimum(m: &Lq, x0: &DVector<f64>) -> DVector<f64> {
    let (nx, nu, n) = (m.a.nrows(), m.b.ncols(), m.n);
    let mut s = DMatrix::zeros(nx * (n + 1), nx);
    let mut t = DMatrix::zeros(nx * (n + 1), nu * n);
    let mut ak = DMatrix::identity(nx, nx);
    for k in 0..=n {
        s.view_mut((k * nx, 0), (nx, nx)).copy_from(&ak);
        ak = &m.a * ak;
        for j in 0..k {
            // x_k depends on u_j through A^{k-1-j} B.
            let mut p = m.b.clone();
            for _ in 0..(k - 1 - j) {
                p = &m.a * p;
            }
            t.view_mut((k * nx, j * nu), (nx, nu)).copy_from(&p);
        }
    }
    let mut qbig = DMatrix::zeros(nx * (n + 1), nx * (n + 1));
    let mut qlin = DVector::zeros(nx * (n + 1));
    for k in 0..=n {
        let w = if k == n { &m.qf } else { &m.q };
        qbig.view_mut((k * nx, k * nx), (nx, nx)).copy_from(w);
        qlin.rows_mut(k * nx, nx).copy_from(&m.ql);
    }
    let mut rbig = DMatrix::zeros(nu * n, nu * n);
    let mut rlin = DVector::zeros(nu * n);
    for k in 0..n {
        rbig.view_mut((k * nu, k * nu), (nu, nu)).copy_from(&m.r);
        rlin.rows_mut(k * nu, nu).copy_from(&m.rl);
    }
    let h = t.transpose() * &qbig * &t + rbig;
    let g = t.transpose() * (qbig * (s * x0) + qlin) + rlin;
    h.cholesky().unwrap().solve(&(-g))
}

fn lq_opts(alphas: Vec<f64>) -> DdpOptions {
    DdpOptions { alphas, reg: RegOptions { init: 0.0, ..Default::default() }, tol_expected: 0.0, ..Default::default() }
}

#[test]
fn lq_exact_in_one_iteration_and_equal_to_batch_least_squares() {
    let mut m = Lq::random(1, 5, 2, 25);
    let x0 = DVector::from_vec(vec![1.0, -0.5, 0.3, 0.2, -1.0]);
    let u_opt = batch_optimum(&m, &x0);
    for variant in [Variant::Ddp, Variant::Fddp] {
        let mut opts = lq_opts(vec![1.0]);
        opts.variant = variant;
        opts.max_iter = 1;
        let mut solver = Solver::new(&m, opts.clone()).unwrap();
        let sol = solver.solve(&mut m, x0.as_slice(), &vec![0.0; 50], None, &mut |_| true).unwrap();
        let u: Vec<f64> = sol.us.concat();
        let err = (DVector::from_vec(u) - &u_opt).amax();
        assert!(err < 1e-8, "{variant:?}: one iteration is {err} from the batch optimum");
        // The next iteration expects (almost) nothing.
        opts.max_iter = 2;
        let mut solver = Solver::new(&m, opts).unwrap();
        let sol = solver.solve(&mut m, x0.as_slice(), &vec![0.0; 50], None, &mut |_| true).unwrap();
        assert!(sol.history[1].expected.abs() < 1e-10, "second expected reduction {}", sol.history[1].expected);
    }
}

#[test]
fn feasibility_driven_variant_closes_gaps_of_an_infeasible_guess() {
    let mut m = Lq::random(2, 4, 2, 15);
    let x0 = DVector::from_vec(vec![0.5, -0.5, 1.0, 0.0]);
    let u_opt = batch_optimum(&m, &x0);
    let mut rng = rand::rngs::StdRng::seed_from_u64(9);
    let xs0: Vec<f64> = (0..16 * 4).map(|_| rng.gen_range(-2.0..2.0)).collect();
    let mut opts = lq_opts(vec![1.0]);
    opts.variant = Variant::Fddp;
    opts.max_iter = 1;
    let mut solver = Solver::new(&m, opts).unwrap();
    let sol = solver.solve(&mut m, x0.as_slice(), &vec![0.3; 30], Some(&xs0), &mut |_| true).unwrap();
    assert!(sol.gap < 1e-12, "gaps left: {}", sol.gap);
    let err = (DVector::from_vec(sol.us.concat()) - &u_opt).amax();
    assert!(err < 1e-8, "FDDP from an infeasible guess is {err} from the optimum");
    // With a partial step the gaps shrink by exactly (1 − α).
    let mut opts = lq_opts(vec![0.25]);
    opts.variant = Variant::Fddp;
    opts.max_iter = 1;
    let mut solver = Solver::new(&m, opts).unwrap();
    let g0 = {
        let mut ws = Workspace::new(15, 4, 4, 2);
        for k in 0..=15 {
            ws.xs[k].copy_from_slice(&xs0[4 * k..4 * k + 4]);
        }
        for k in 0..15 {
            ws.us[k].fill(0.3);
        }
        freefloat_core::control::ddp::forward::evaluate_nominal(&mut m, &mut ws, x0.as_slice()).unwrap();
        ws.gap_norm()
    };
    let sol = solver.solve(&mut m, x0.as_slice(), &vec![0.3; 30], Some(&xs0), &mut |_| true).unwrap();
    assert!((sol.gap - 0.75 * g0).abs() < 1e-9 * g0, "gap {} vs 0.75 × {g0}", sol.gap);
}

#[test]
fn backward_pass_value_update_equals_eqs_8_32_8_33_at_zero_regularisation() {
    let mut m = Lq::random(3, 6, 3, 8);
    m.c = DVector::from_fn(6, |i, _| 0.05 * (i as f64 - 2.0));
    let mut ws = Workspace::new(8, 6, 6, 3);
    let mut rng = rand::rngs::StdRng::seed_from_u64(4);
    for k in 0..8 {
        for v in ws.us[k].iter_mut() {
            *v = rng.gen_range(-1.0..1.0);
        }
    }
    freefloat_core::control::ddp::forward::rollout_nominal(&mut m, &mut ws, &[0.2, 0.1, -0.3, 0.0, 0.5, 0.1]).unwrap();
    for k in 0..8 {
        let (x, u) = (ws.xs[k].clone(), ws.us[k].clone());
        m.calc_diff(k, x.as_slice(), u.as_slice(), &mut ws.diffs[k]).unwrap();
    }
    let xn = ws.xs[8].clone();
    m.calc_diff_terminal(xn.as_slice(), &mut ws.diffs[8]).unwrap();
    assert_eq!(backward_pass(&mut m, &mut ws, 0.0, false, false).unwrap(), Backward::Done);
    for k in 0..8 {
        let d = &ws.diffs[k];
        let (vx1, vxx1) = (&ws.vx[k + 1], &ws.vxx[k + 1]);
        let qx = &d.lx + d.fx.transpose() * vx1;
        let qu = &d.lu + d.fu.transpose() * vx1;
        let qxx = &d.lxx + d.fx.transpose() * vxx1 * &d.fx;
        let quu = &d.luu + d.fu.transpose() * vxx1 * &d.fu;
        let qux = d.lxu.transpose() + d.fu.transpose() * vxx1 * &d.fx;
        let qi = quu.clone().try_inverse().unwrap();
        // Eqs. (8.32)–(8.33): V_x = Q_x − Q_xu Q_uu⁻¹ Q_u, V_xx = Q_xx − Q_xu Q_uu⁻¹ Q_ux.
        let vx = &qx - qux.transpose() * &qi * &qu;
        let vxx = &qxx - qux.transpose() * &qi * &qux;
        let scale = 1.0 + vxx.amax();
        assert!((&vx - &ws.vx[k]).amax() < 1e-10 * scale, "node {k}: V_x");
        assert!((&vxx - &ws.vxx[k]).amax() < 1e-10 * scale, "node {k}: V_xx");
        assert!((-&qi * &qu - &ws.kff[k]).amax() < 1e-10 * scale, "node {k}: feed-forward");
    }
}

#[test]
fn full_ddp_adds_second_order_terms_and_converges_in_fewer_iterations() {
    let mut m = Lq::random(5, 4, 2, 20);
    m.c = DVector::from_vec(vec![0.2, -0.15, 0.1, 0.25]);
    m.a *= 0.8;
    let x0 = [0.6, -0.4, 0.5, 0.3];
    let run = |m: &mut Lq, full: bool| {
        m.with_hessian = full;
        let opts = DdpOptions {
            second_order: full,
            max_iter: 200,
            tol_expected: 1e-12,
            variant: Variant::Ddp,
            ..Default::default()
        };
        let mut solver = Solver::new(m, opts).unwrap();
        let sol = solver.solve(m, &x0, &vec![0.0; 40], None, &mut |_| true).unwrap();
        assert_eq!(sol.stop, StopReason::Converged, "full = {full}: {:?}", sol.stop);
        sol
    };
    let ilqg = run(&mut m, false);
    let full = run(&mut m, true);
    assert!((ilqg.cost - full.cost).abs() < 1e-8 * ilqg.cost.abs().max(1.0), "{} vs {}", ilqg.cost, full.cost);
    assert!(full.iterations < ilqg.iterations, "full DDP {} iterations, iLQG {}", full.iterations, ilqg.iterations);
    // Without the model's second-order terms full DDP is refused, naming the option.
    m.with_hessian = false;
    let opts = DdpOptions { second_order: true, ..Default::default() };
    let mut solver = Solver::new(&m, opts).unwrap();
    let e = solver.solve(&mut m, &x0, &vec![0.0; 40], None, &mut |_| true).unwrap_err();
    assert!(e.to_string().contains("second_order"), "{e}");
}

#[test]
fn non_positive_definite_quu_raises_lambda_on_the_1_6_schedule() {
    let mut m = Lq::random(6, 3, 2, 10);
    m.r = -DMatrix::identity(2, 2) * 3.0; // strongly concave in u
    m.rl.fill(0.0);
    let opts = DdpOptions { max_iter: 3, reg: RegOptions { init: 1.0, ..Default::default() }, ..Default::default() };
    let mut solver = Solver::new(&m, opts).unwrap();
    let sol = solver.solve(&mut m, &[0.1, 0.2, 0.3], &[0.0; 20], None, &mut |_| true).unwrap();
    let h = &sol.history[0];
    assert!(h.backward_passes > 1, "λ was never raised");
    // λ after p failed passes from λ = 1, dλ = 1: λ = Π 1.6^j (dλ = 1.6, 2.56, ...).
    let mut expect = 1.0;
    let mut dl: f64 = 1.0;
    for _ in 1..h.backward_passes {
        dl = (dl * 1.6).max(1.6);
        expect *= dl;
    }
    assert!((h.lambda - expect).abs() < 1e-9 * expect, "λ {} expected {}", h.lambda, expect);
    assert!(sol.cost.is_finite());
}

#[test]
fn line_search_accepts_only_descent_and_fixed_alpha_applies_exactly_a_tenth() {
    let mut m = Lq::random(7, 4, 2, 12);
    m.c = DVector::from_vec(vec![0.15, 0.0, -0.1, 0.05]);
    m.a *= 0.8;
    let x0 = [1.0, 0.0, -1.0, 0.5];
    let opts = DdpOptions { max_iter: 30, accept_ratio: 0.0, variant: Variant::Ddp, ..Default::default() };
    let mut solver = Solver::new(&m, opts).unwrap();
    let mut seen = Vec::new();
    let sol = solver
        .solve(&mut m, &x0, &[0.0; 24], None, &mut |i| {
            seen.push(i.clone());
            true
        })
        .unwrap();
    assert_eq!(seen.len(), sol.history.len());
    for h in &sol.history {
        if h.accepted {
            // Feasible DDP accepts only if the expected reduction is positive and z > 0.
            assert!(h.reduction > 0.0, "iteration {}: accepted a cost increase", h.iter);
            assert!(h.expected > 0.0 && h.alpha > 0.0);
        }
    }
    // Fixed α = 0.1 from a zero start at x0 = 0 on node 0 (δx₀ = 0): u₀ = 0.1 l₀ exactly.
    let opts = DdpOptions {
        max_iter: 1,
        alphas: vec![0.1],
        reg: RegOptions { init: 0.0, ..Default::default() },
        variant: Variant::Ddp,
        ..Default::default()
    };
    let mut solver = Solver::new(&m, opts).unwrap();
    let sol = solver.solve(&mut m, &x0, &[0.0; 24], None, &mut |_| true).unwrap();
    assert!(sol.history[0].accepted, "{:?}", sol.history);
    for i in 0..2 {
        assert_eq!(sol.us[0][i], 0.1 * solver.ws.kff[0][i]);
    }
}

#[test]
fn bad_input_names_the_argument() {
    let mut m = Lq::random(8, 3, 2, 5);
    let e = Solver::new(&m, DdpOptions { alphas: vec![], ..Default::default() }).err().unwrap();
    assert!(e.to_string().contains("alphas"), "{e}");
    let e = Solver::new(&m, DdpOptions { max_iter: 0, ..Default::default() }).err().unwrap();
    assert!(e.to_string().contains("max_iter"), "{e}");
    let e = Solver::new(&m, DdpOptions { reg: RegOptions { factor: 0.5, ..Default::default() }, ..Default::default() })
        .err()
        .unwrap();
    assert!(e.to_string().contains("regularisation"), "{e}");
    let mut solver = Solver::new(&m, DdpOptions::default()).unwrap();
    let e = solver.solve(&mut m, &[f64::NAN, 0.0, 0.0], &[0.0; 10], None, &mut |_| true).unwrap_err();
    assert!(e.to_string().contains("x0"), "{e}");
    let e = solver.solve(&mut m, &[0.0; 3], &[0.0; 9], None, &mut |_| true).unwrap_err();
    assert!(e.to_string().contains("us0"), "{e}");
    let mut z = Lq::random(8, 3, 2, 0);
    let e = Solver::new(&z, DdpOptions::default()).err().unwrap();
    assert!(e.to_string().contains("horizon"), "{e}");
    let _ = &mut z;
    // A diverging rollout is a clear error, not NaN.
    let mut big = Lq::random(8, 3, 2, 400);
    big.a *= 10.0;
    let mut solver = Solver::new(&big, DdpOptions::default()).unwrap();
    let e = solver.solve(&mut big, &[1.0; 3], &vec![0.0; 800], None, &mut |_| true).unwrap_err();
    assert!(e.to_string().contains("diverged"), "{e}");
}

/// Closed loop: on an LQ problem the affine DDP policy `u = ū + L (x − x̄)` is the global optimal feedback, so
/// running it from a *different* initial state must give that state's batch least-squares optimum (an
/// independent oracle), while the open-loop feed-forward ū does not.
#[test]
fn lq_policy_from_a_perturbed_start_is_the_optimum_from_there() {
    use freefloat_core::control::ddp::Policy;
    let mut m = Lq::random(4, 5, 2, 25);
    let x0 = DVector::from_vec(vec![1.0, -0.5, 0.3, 0.2, -1.0]);
    let mut opts = lq_opts(vec![1.0]);
    opts.max_iter = 1;
    let mut solver = Solver::new(&m, opts).unwrap();
    let sol = solver.solve(&mut m, x0.as_slice(), &vec![0.0; 50], None, &mut |_| true).unwrap();
    let gains = solver.refresh_gains(&mut m, 0.0).unwrap().expect("LQ: Quu is positive definite");
    let mut policy = Policy::new(sol.xs.clone(), sol.us.clone(), gains, 5, 5, 2).unwrap();
    let x1 = &x0 + DVector::from_vec(vec![0.4, 0.3, -0.6, 0.1, 0.5]);
    let u_opt = batch_optimum(&m, &x1);
    for feedback in [true, false] {
        let mut x = x1.clone();
        let mut us = vec![];
        let mut u = vec![0.0; 2];
        let mut xn = vec![0.0; 5];
        for k in 0..25 {
            policy.control(&m, k, x.as_slice(), feedback, &mut u).unwrap();
            m.calc(k, x.as_slice(), &u, &mut xn).unwrap();
            us.extend_from_slice(&u);
            x = DVector::from_column_slice(&xn);
        }
        let err = (DVector::from_vec(us) - &u_opt).amax();
        if feedback {
            assert!(err < 1e-8, "the policy's controls are {err} from the optimum from the perturbed start");
        } else {
            assert!(err > 1e-3, "the open-loop controls should not be optimal from the perturbed start ({err})");
        }
    }
    // Bad input: a gain of the wrong size, a non-finite measured state.
    assert!(Policy::new(sol.xs.clone(), sol.us.clone(), vec![vec![0.0; 3]; 25], 5, 5, 2).is_err());
    let mut u = vec![0.0; 2];
    assert!(policy.control(&m, 0, &[f64::NAN, 0.0, 0.0, 0.0, 0.0], true, &mut u).is_err());
}
