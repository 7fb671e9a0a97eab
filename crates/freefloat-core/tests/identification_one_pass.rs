//! The one-pass route of the momentum identification (normal equations without the refinement pass,
//! taken when the equilibrated κ is small and the residual is recoverable from the normal equations)
//! agrees with the streaming Householder QR on noisy data: estimate, RSS and condition number.

mod common;
use common::*;
use freefloat_core::estimation::{identify_momentum, identify_momentum_with, Method, MomentumProblem};
use freefloat_core::model::builtin;
use freefloat_core::regressors::momentum_regressor;
use freefloat_core::Data;
use nalgebra::{DMatrix, DVector};
use rand::Rng;

#[test]
fn one_pass_normal_equations_equal_streaming_qr_on_noisy_data() {
    let m = builtin::load("naveen_dual_arm").unwrap();
    let mut r = rng(21);
    let mut d = Data::new(&m);
    let np = 10 * m.nbodies();
    let p: Vec<f64> = m.parameters().into_iter().flatten().collect();
    let known: Vec<f64> = (0..np).map(|c| if c >= 70 { p[c] } else { 0.0 }).collect();
    let samples = 4000;
    let (mut q, mut v, mut h) = (vec![], vec![], vec![]);
    let mut k_unknown = DMatrix::zeros(6 * samples, 70);
    let mut k = DMatrix::zeros(6, np);
    for s in 0..samples {
        let (qs, vs) = (random_q(&m, &mut r), random_vec(m.nv, &mut r));
        momentum_regressor(&m, &mut d, &qs, &vs, &mut k).unwrap();
        // measured momentum = K P + noise (uniform, σ ≈ 1.7): a residual far above round-off
        h.extend((&k * DVector::from_column_slice(&p)).iter().map(|x| x + r.gen_range(-3.0..3.0)));
        k_unknown.view_mut((6 * s, 0), (6, 70)).copy_from(&k.columns(0, 70));
        q.extend(qs);
        v.extend(vs);
    }
    // 52 independent columns by column-pivoted QR of the unknown bodies' stacked regressor
    let qr = k_unknown.col_piv_qr();
    let mut perm = DMatrix::<f64>::identity(70, 70);
    qr.p().permute_columns(&mut perm);
    let mut cols: Vec<usize> = (0..52).map(|c| perm.column(c).iamax()).collect();
    cols.sort();
    let prob = MomentumProblem { q: &q, v: &v, h: &h, unknown_cols: &cols, known_params: &known, weights: None };
    let fast = identify_momentum(&m, &prob).unwrap();
    let slow = identify_momentum_with(&m, &prob, true).unwrap();
    let hn: f64 = h.iter().map(|x| x * x).sum();
    println!(
        "κ = {:.3e}, method {:?}, rss {:.6e} / {:.6e}, hᵀh/rss {:.2e}",
        fast.condition_number,
        fast.method,
        fast.rss,
        slow.rss,
        hn / slow.rss
    );
    assert_eq!((fast.method, slow.method), (Method::Gram, Method::StreamingQr));
    let dx = (&fast.x - &slow.x).amax() / slow.x.amax();
    assert!(dx < 1e-10, "estimate differs by {dx:e}");
    assert!((fast.rss / slow.rss - 1.0).abs() < 1e-7, "rss {} vs {}", fast.rss, slow.rss);
    assert!((fast.condition_number / slow.condition_number - 1.0).abs() < 1e-8);
    assert!((&fast.std - &slow.std).amax() < 1e-6 * slow.std.amax());
}
