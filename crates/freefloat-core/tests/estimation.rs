//! Streaming least squares (crate `estimation`): the streaming QR matches a dense QR of the whole
//! matrix on ill-conditioned problems where the normal equations lose their digits; rank
//! deficiency is reported with the unexcited combination; the momentum identification's fast
//! route (normal equations + refinement) agrees with the streaming QR.

mod common;
use common::*;
use freefloat_core::estimation::{identify_momentum, identify_momentum_with, Method, MomentumProblem, StreamingLs};
use freefloat_core::model::builtin;
use freefloat_core::regressors::momentum_regressor;
use freefloat_core::Data;
use nalgebra::{DMatrix, DVector};
use rand::Rng;

fn gaussian(rows: usize, cols: usize, r: &mut rand::rngs::StdRng) -> DMatrix<f64> {
    // sum of uniforms is Gaussian enough for a random orthogonal basis
    DMatrix::from_fn(rows, cols, |_, _| (0..4).map(|_| r.gen_range(-1.0..1.0)).sum::<f64>())
}

/// A = U diag(σ) Vᵀ with σ log-spaced from 1 to 1/κ and random orthonormal U, V.
fn ill_conditioned(m: usize, n: usize, kappa: f64, r: &mut rand::rngs::StdRng) -> DMatrix<f64> {
    let u = gaussian(m, n, r).qr().q();
    let v = gaussian(n, n, r).qr().q();
    let s = DMatrix::from_diagonal(&DVector::from_fn(n, |i, _| kappa.powf(-(i as f64) / (n - 1) as f64)));
    u * s * v.transpose()
}

/// Feed A, y to a streaming accumulator in blocks of `block` rows.
fn stream(a: &DMatrix<f64>, y: &DVector<f64>, block: usize) -> StreamingLs {
    let mut ls = StreamingLs::new(a.ncols());
    let mut i = 0;
    while i < a.nrows() {
        let k = block.min(a.nrows() - i);
        ls.add_block(&a.rows(i, k), y.rows(i, k).as_slice(), None).unwrap();
        i += k;
    }
    ls
}

fn dense_qr_solve(a: &DMatrix<f64>, y: &DVector<f64>) -> DVector<f64> {
    let qr = a.clone().qr();
    let qty = qr.q().transpose() * y;
    qr.r().solve_upper_triangular(&qty).unwrap()
}

fn normal_equations(a: &DMatrix<f64>, y: &DVector<f64>) -> Option<DVector<f64>> {
    Some((a.transpose() * a).cholesky()?.solve(&(a.transpose() * y)))
}

fn rel(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

#[test]
fn streaming_qr_matches_dense_qr_where_normal_equations_fail() {
    let mut r = rng(7);
    for trial in 0..5 {
        let (m, n) = (3000, 24);
        let a = ill_conditioned(m, n, 1e8, &mut r);
        let x_true = DVector::from_fn(n, |_, _| r.gen_range(-1.0..1.0));
        // a consistent problem (zero residual): then x is determined to O(κε), with no κ²‖r‖ term
        let y = &a * &x_true;
        let dense = dense_qr_solve(&a, &y);
        let ls = stream(&a, &y, [64, 100, 256, 1000, 3000][trial]);
        let sol = ls.solve().unwrap();
        let kappa = sol.condition_number;
        let e_stream = rel(&sol.x, &dense);
        let e_normal = normal_equations(&a, &y).map_or(f64::INFINITY, |x| rel(&x, &dense));
        // fitted values agree to round-off; the residual sum of squares too
        let fit = (&a * (&sol.x - &dense)).norm() / (&a * &dense).norm();
        let rss_dense = (&y - &a * &dense).norm_squared();
        let (t_stream, t_dense) = (rel(&sol.x, &x_true), rel(&dense, &x_true));
        println!(
            "κ = {kappa:.2e}: streaming vs dense {e_stream:.1e}, normal equations vs dense {e_normal:.1e}; \
             vs truth: streaming {t_stream:.1e}, dense {t_dense:.1e}; fit {fit:.1e}"
        );
        assert!((kappa / 1e8 - 1.0).abs() < 1e-4, "condition number {kappa}");
        // two backward-stable solvers can each be O(κε) = 2e-8 off in x; observed 1e-10..1e-9
        assert!(e_stream < 5e-9, "streaming QR differs from dense QR by {e_stream:.2e}");
        assert!(t_stream < 5e-9, "streaming QR is {t_stream:.2e} off the truth (dense QR: {t_dense:.2e})");
        // κ² ε ≈ 2: the normal equations keep no digit at all
        assert!(e_normal > 1e-3, "normal equations unexpectedly accurate: {e_normal:.2e}");
        assert!(fit < 1e-13);
        assert!((sol.rss - rss_dense).abs() < 1e-20 + 1e-6 * rss_dense);
    }
}

#[test]
fn weights_blocks_and_merging_do_not_change_the_solution() {
    let mut r = rng(8);
    let (m, n) = (500, 10);
    let a = ill_conditioned(m, n, 1e3, &mut r);
    let y = DVector::from_fn(m, |_, _| r.gen_range(-1.0..1.0));
    let w: Vec<f64> = (0..m).map(|_| r.gen_range(0.1..4.0)).collect();
    // weighted rows == rows scaled by √w
    let mut ls = StreamingLs::new(n);
    ls.add_block(&a, y.as_slice(), Some(&w)).unwrap();
    let sw = DVector::from_iterator(m, w.iter().map(|x| x.sqrt()));
    let (aw, yw) = (DMatrix::from_fn(m, n, |i, j| sw[i] * a[(i, j)]), y.component_mul(&sw));
    let dense = dense_qr_solve(&aw, &yw);
    let sol = ls.solve().unwrap();
    assert!(rel(&sol.x, &dense) < 1e-13);
    // two halves merged (TSQR) == one stream
    let (mut h1, h2) = (
        stream(&aw.rows(0, 200).into_owned(), &yw.rows(0, 200).into_owned(), 37),
        stream(&aw.rows(200, 300).into_owned(), &yw.rows(200, 300).into_owned(), 64),
    );
    h1.merge(&h2);
    let merged = h1.solve().unwrap();
    assert_eq!(merged.rows, m);
    assert!(rel(&merged.x, &dense) < 1e-13);
    assert!((merged.rss - sol.rss).abs() < 1e-12 * sol.rss);
    // covariance = σ̂² (AᵀA)⁻¹ of the weighted problem
    let s2 = (&yw - &aw * &dense).norm_squared() / (m - n) as f64;
    let cov = (aw.transpose() * &aw).try_inverse().unwrap() * s2;
    assert!((&sol.covariance - &cov).norm() < 1e-10 * cov.norm());
    assert!((sol.std[3] - cov[(3, 3)].sqrt()).abs() < 1e-10 * sol.std[3]);
    assert_eq!(sol.dof, m - n);
}

#[test]
fn rank_deficiency_names_the_unexcited_combination() {
    let mut r = rng(9);
    let (m, n) = (400, 8);
    let mut a = ill_conditioned(m, n, 10.0, &mut r);
    // column 6 = 2 · column 2
    let c2 = a.column(2).into_owned();
    a.set_column(6, &(c2 * 2.0));
    let y = DVector::from_fn(m, |_, _| r.gen_range(-1.0..1.0));
    let ls = stream(&a, &y, 64);
    // A (2 e₂ − e₆) = 2 c₂ − 2 c₂ = 0: the null direction is (2 e₂ − e₆)/√5
    let dirs = ls.unexcited();
    assert_eq!(dirs.len(), 1);
    let t = &dirs[0].terms;
    assert_eq!(t.len(), 2, "{:?}", t);
    let (k0, c0) = t[0];
    let (k1, c1) = t[1];
    assert_eq!((k0, k1), (2, 6));
    assert!((c0.abs() - 2.0 / 5f64.sqrt()).abs() < 1e-10 && (c1.abs() - 1.0 / 5f64.sqrt()).abs() < 1e-10);
    assert!(c0 * c1 < 0.0);
    let err = ls.solve().unwrap_err().to_string();
    assert!(err.contains("rank 7 of 8") && err.contains("x[2]") && err.contains("x[6]"), "{err}");
}

/// Momentum data of naveen_dual_arm at random states, with the wheels known.
struct DualArm {
    m: freefloat_core::Model,
    q: Vec<f64>,
    v: Vec<f64>,
    h: Vec<f64>,
    known: Vec<f64>,
    k_unknown: DMatrix<f64>,
}

fn dual_arm(samples: usize, seed: u64) -> DualArm {
    let m = builtin::load("naveen_dual_arm").unwrap();
    let mut r = rng(seed);
    let mut d = Data::new(&m);
    let np = 10 * m.nbodies();
    let p: Vec<f64> = m.parameters().into_iter().flatten().collect();
    let known: Vec<f64> = (0..np).map(|c| if c >= 70 { p[c] } else { 0.0 }).collect();
    let (mut q, mut v, mut h) = (vec![], vec![], vec![]);
    let mut k_unknown = DMatrix::zeros(6 * samples, 70);
    let mut k = DMatrix::zeros(6, np);
    for s in 0..samples {
        let (qs, vs) = (random_q(&m, &mut r), random_vec(m.nv, &mut r));
        momentum_regressor(&m, &mut d, &qs, &vs, &mut k).unwrap();
        h.extend((&k * DVector::from_column_slice(&p)).iter());
        k_unknown.view_mut((6 * s, 0), (6, 70)).copy_from(&k.columns(0, 70));
        q.extend(qs);
        v.extend(vs);
    }
    DualArm { m, q, v, h, known, k_unknown }
}

#[test]
fn momentum_identification_reports_the_grouped_parameters_as_unexcited() {
    // all 70 standard parameters of base + 6 links: 18 of them are grouped (Naveen, Shah, Misra: 70 → 52)
    let da = dual_arm(200, 10);
    let cols: Vec<usize> = (0..70).collect();
    let p =
        MomentumProblem { q: &da.q, v: &da.v, h: &da.h, unknown_cols: &cols, known_params: &da.known, weights: None };
    let err = identify_momentum(&da.m, &p).unwrap_err().to_string();
    assert!(err.contains("rank 52 of 70"), "{err}");
}

#[test]
fn momentum_identification_fast_route_equals_streaming_qr() {
    let da = dual_arm(3000, 11);
    // 52 independent columns by column-pivoted QR of the unknown bodies' stacked regressor
    let qr = da.k_unknown.clone().col_piv_qr();
    let rr = qr.r();
    let mut perm = DMatrix::<f64>::identity(70, 70);
    qr.p().permute_columns(&mut perm);
    let mut cols: Vec<usize> = (0..52).map(|k| perm.column(k).iamax()).collect();
    assert!(rr[(51, 51)].abs() > 1e-8 * rr[(0, 0)].abs() && rr[(52, 52)].abs() < 1e-12 * rr[(0, 0)].abs());
    cols.sort();
    for weights in [None, Some([1.0, 2.0, 3.0, 0.5, 0.25, 4.0])] {
        let p = MomentumProblem { q: &da.q, v: &da.v, h: &da.h, unknown_cols: &cols, known_params: &da.known, weights };
        let fast = identify_momentum(&da.m, &p).unwrap();
        let qr = identify_momentum_with(&da.m, &p, true).unwrap();
        println!(
            "κ = {:.3e}, rss fast {:.2e} qr {:.2e}, diff {:.2e}",
            fast.condition_number,
            fast.rss,
            qr.rss,
            rel(&fast.x, &qr.x)
        );
        assert_eq!((fast.method, qr.method), (Method::GramRefined, Method::StreamingQr));
        assert!(rel(&fast.x, &qr.x) < 1e-12);
        assert!((fast.condition_number / qr.condition_number - 1.0).abs() < 1e-8);
        // noise-free data: the residual is round-off
        let hn: f64 = da.h.iter().map(|x| x * x).sum();
        assert!(fast.rss < 1e-24 * hn && qr.rss < 1e-24 * hn, "rss {} {}", fast.rss, qr.rss);
        assert_eq!(fast.rows, 18000);
    }
}

#[test]
fn momentum_regressor_equals_body_frame_columns_carried_to_the_origin() {
    // The expanded inertial-frame formulas of `momentum_regressor` against the direct route:
    // body-frame columns `Inertia::mul_motion_columns` carried by `act_force`.
    use freefloat_core::kinematics::forward_velocities;
    use freefloat_core::spatial::Inertia;
    let mut r = rng(13);
    for trial in 0..60 {
        let m = random_model(&mut r, BASES[trial % 3], 1 + trial % 12, false);
        let mut d = Data::new(&m);
        let (q, v) = (random_q(&m, &mut r), random_vec(m.nv, &mut r));
        let mut k = DMatrix::zeros(6, 10 * m.nbodies());
        momentum_regressor(&m, &mut d, &q, &v, &mut k).unwrap();
        forward_velocities(&m, &mut d, &q, &v).unwrap();
        let scale = k.amax().max(1.0);
        for i in 0..m.nbodies() {
            for (c, f) in Inertia::mul_motion_columns(&d.v[i]).iter().enumerate() {
                let col = d.o_mi[i].act_force(f).to_v6();
                let err = (k.column(10 * i + c) - col).amax();
                assert!(err < 1e-13 * scale, "trial {trial}, body {i}, column {c}: {err:.2e}");
            }
        }
    }
}

#[test]
fn rank_is_judged_independently_of_parameter_units_and_merging_an_empty_accumulator_is_harmless() {
    let mut r = rng(14);
    let (m, n) = (300, 6);
    let mut a = ill_conditioned(m, n, 10.0, &mut r);
    // a parameter in tiny units: its column is 1e-13 of the others, but it is perfectly excited
    let c = a.column(4) * 1e-13;
    a.set_column(4, &c);
    let x_true = DVector::from_fn(n, |i, _| if i == 4 { 1e13 } else { 1.0 + i as f64 });
    let y = &a * &x_true;
    let mut ls = stream(&a, &y, 50);
    ls.merge(&StreamingLs::new(n));
    assert_eq!(ls.rows(), m);
    assert!(ls.unexcited().is_empty());
    let sol = ls.solve().unwrap();
    let e = sol.x.iter().zip(x_true.iter()).map(|(a, b)| ((a - b) / b).abs()).fold(0.0, f64::max);
    assert!(e < 1e-13, "componentwise error {e:.2e}");
    assert!(sol.condition_number > 1e12); // the unscaled κ is reported as is
}
