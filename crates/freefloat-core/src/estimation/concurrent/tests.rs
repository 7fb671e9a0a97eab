//! Unit tests of the chapter-9 estimator (Valverde 2018 §9); the reproduction's acceptance tests are in
//! tests/test_identify_cl*.py.
use super::*;
use crate::model::builtin;

fn scenario(m: &crate::Model, ns: usize) -> ClScenario {
    ClScenario {
        q0: m.neutral(),
        v0: vec![0.0; m.nv],
        excitation: Excitation::default(),
        params: ClParams { ns, ..ClParams::default() },
        m0: vec![0.0; NP * m.nbodies()],
        dt: 0.01,
        t_final: 10.0,
        noise: Noise::default(),
        noise_seed: 7,
    }
}

#[test]
#[ignore]
fn explore() {
    let name = std::env::var("CL_MODEL").unwrap_or("valverde_ch7_two_arm".into());
    let m = builtin::load(&name).unwrap();
    let mut sc = scenario(&m, std::env::var("CL_NS").map(|x| x.parse().unwrap()).unwrap_or(10));
    let w: f64 = std::env::var("CL_V0").map(|x| x.parse().unwrap()).unwrap_or(0.0);
    for (j, x) in sc.v0.iter_mut().enumerate().skip(6) {
        *x = w * (1.0 + 0.3 * (j as f64).sin());
    }
    if let Ok(x) = std::env::var("CL_TTH") {
        sc.params.t_th = x.parse().unwrap();
    }
    let wb: f64 = std::env::var("CL_WB").map(|x| x.parse().unwrap()).unwrap_or(0.0);
    sc.v0[3] = wb; sc.v0[4] = -0.7 * wb; sc.v0[5] = 0.4 * wb;
    let t0 = std::time::Instant::now();
    let r = run_cl(&m, &sc, None).unwrap();
    println!("run {:?}", t0.elapsed());
    let np = 7 * m.nbodies();
    for &t in &[1.99, 2.0, 2.01, 2.05, 2.09, 2.1, 2.2, 3.0, 5.0, 10.0] {
        let k = (t / 0.01f64).round() as usize;
        let sv = &r.singular_values[k * np..(k + 1) * np];
        println!("t={t} smax={:.3e} smin={:.3e} offers={}", sv[0], sv[np - 1], r.offers[k]);
    }
    let last_change = r.offers.iter().rposition(|&o| o == 1 || o == 2).unwrap();
    println!("last stack change at t={}", last_change as f64 * 0.01);
    let err: f64 = r.final_estimate.iter().zip(&r.truth).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    println!("max final err {err:.3e} residual {:.3e} changes {} trials {}", r.max_residual, r.stack_changes, r.stack_trials);
    for i in 0..m.nbodies() {
        let k = 1000;
        let b = &r.block_singular_values[k * np + 7 * i..k * np + 7 * i + 7];
        println!("body {i}: {:?}", b.iter().map(|x| format!("{x:.2e}")).collect::<Vec<_>>());
    }
}
