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

fn random_points(n: usize, nb: usize, seed: u64) -> Vec<(Vec<M87>, Vec<V8>)> {
    let mut rng = SplitMix::new(seed);
    (0..n)
        .map(|_| {
            let r = (0..nb).map(|_| M87::from_fn(|i, _| if i == 0 || i == 4 { 0.0 } else { rng.normal() })).collect();
            let f = (0..nb).map(|_| V8::from_fn(|_, _| rng.normal())).collect();
            (r, f)
        })
        .collect()
}

#[test]
fn per_block_singular_values_equal_the_full_svd_and_the_tree_matches_the_gram() {
    // D2: Σ𝐑ᵀ𝐑 is block diagonal; its 7B singular values are the union of the blocks' ones
    let (nb, ns) = (4, 6);
    let mut st = DataStack::new(nb, ns, 1e9, 5).unwrap();
    let pts = random_points(15, nb, 9);
    let mut kept: Vec<Option<usize>> = vec![None; ns];
    for (k, (r, f)) in pts.iter().enumerate() {
        match st.offer(r, f).unwrap() {
            Offer::Appended => kept[st.len() - 1] = Some(k),
            Offer::Replaced(p) => kept[p] = Some(k),
            _ => {}
        }
    }
    let rows = 8 * nb * st.len();
    let mut full = nalgebra::DMatrix::<f64>::zeros(rows, NP * nb);
    for (s, k) in kept.iter().enumerate().take(st.len()) {
        let (r, _) = &pts[k.unwrap()];
        for b in 0..nb {
            full.view_mut((8 * nb * s + 8 * b, NP * b), (8, NP)).copy_from(&r[b]);
        }
    }
    let mut sv: Vec<f64> = full.singular_values().iter().map(|s| s * s).collect();
    sv.sort_by(|a, b| b.total_cmp(a));
    for (a, b) in sv.iter().zip(st.singular_values()) {
        assert!((a - b).abs() <= 1e-10 * sv[0], "{a} vs {b}");
    }
    // the QR tree's T has TᵀT = RR (Gram, summed from scratch) after the replacements
    for b in 0..nb {
        let t = st.tri()[b];
        let d = (t.transpose() * t - st.rr()[b]).amax();
        assert!(d <= 1e-10 * st.rr()[b].amax(), "block {b}: {d}");
        let dg = (t.transpose() * st.g()[b] - st.rf()[b]).amax();
        assert!(dg <= 1e-10 * st.rf()[b].amax().max(1.0), "block {b}: {dg}");
    }
}

#[test]
fn written_out_law_equals_the_gram_form() {
    let mut rng = SplitMix::new(4);
    let a = nalgebra::SMatrix::<f64, 16, 7>::from_fn(|_, _| rng.normal());
    let t: M7 = a.qr().r();
    let g = V7::from_fn(|_, _| rng.normal());
    let m = V7::from_fn(|_, _| rng.normal());
    let k = M7::from_fn(|_, _| rng.normal());
    let rr = t.transpose() * t;
    let rf = t.transpose() * g;
    let want = -(k * (rr * m - rf));
    assert!((block_rate(&t, &g, Some(&k), &m) - want).amax() < 1e-10 * want.amax());
    assert!((block_rate(&t, &g, None, &m) + (rr * m - rf)).amax() < 1e-10 * want.amax());
}

#[test]
fn bad_parameters_name_the_argument() {
    let bad = |p: ClParams, name: &str| {
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains(name), "{e}");
    };
    bad(ClParams { ns: 1, ..ClParams::default() }, "`ns`");
    bad(ClParams { sigma_th: -1.0, ..ClParams::default() }, "`sigma_th`");
    bad(ClParams { sigma_th2: 0.0, ..ClParams::default() }, "`sigma_th2`");
    bad(ClParams { sigma_new: f64::NAN, ..ClParams::default() }, "`sigma_new`");
    bad(ClParams { t_th: f64::INFINITY, ..ClParams::default() }, "`t_th`");
}

#[test]
fn thesis_run_on_the_builtin_robot() {
    // D4/D5 from Rust: rank 77, no new data after 2.1 s, every parameter within 1 % at 10 s
    let m = builtin::load("valverde_ch9_two_arm").unwrap();
    let r = run_cl(&m, &scenario(&m, 10), None).unwrap();
    let np = 7 * m.nbodies();
    let last = r.offers.iter().rposition(|&o| o == 1 || o == 2).unwrap();
    assert!(r.times[last] <= 2.1 + 1e-9, "{}", r.times[last]);
    let sv = &r.singular_values[r.singular_values.len() - np..];
    let smax = sv[0].sqrt();
    assert!(sv.iter().all(|s| s.sqrt() > ZERO_RTOL * smax), "rank < 77");
    for (j, (e, t)) in r.final_estimate.iter().zip(&r.truth).enumerate() {
        let scale = if *t != 0.0 {
            t.abs()
        } else if j / 7 == 0 {
            10.0
        } else {
            1.0
        };
        assert!((e - t).abs() < 0.01 * scale, "parameter {j}: {e} vs {t}");
    }
    assert!(r.max_residual < 1e-12);
    assert!(r.realisable.iter().all(|&x| x));
}

#[test]
fn truncated_gain_rule_by_hand() {
    // T = diag(s): P = W = I up to signs, so the evidence of direction i is |g_i − s_i m_i| (9.27′)
    let s = [3.0, 1.0, 0.6, 0.3, 0.05, 0.01, 0.002];
    let t = M7::from_diagonal(&V7::from_column_slice(&s));
    let g = V7::from_column_slice(&[1.0, 1.0, 0.13, 0.004, 0.5, 0.02, 0.0001]);
    let m = V7::from_column_slice(&[0.0, 0.0, 0.05, 0.01, 0.0, 0.0, 0.0]);
    // evidence: |0.13 − 0.6·0.05| = 0.1, |0.004 − 0.3·0.01| = 0.001, 0.5, 0.02, 1e-4; κσ̂ = 6·0.01 = 0.06
    let (sigma_hat, kappa, sth2, snew) = (0.01, 6.0, 0.5, 100.0);
    let ev = direction_evidence(&t, &g, &m, &s, &M7::identity());
    let want_ev = [1.0, 1.0, 0.1, 0.001, 0.5, 0.02, 1e-4];
    for (a, b) in ev.iter().zip(want_ev) {
        assert!((a - b).abs() < 1e-15, "{ev:?}");
    }
    // σ = s² = 9, 1, 0.36, 0.09, 0.0025, 1e-4, 4e-6: (9.27) accelerates the last five; the rule keeps 0.36
    // (0.1 ≥ 0.06) and 0.0025 (0.5 ≥ 0.06) and withholds 0.09, 1e-4, 4e-6
    let (k, withheld) = truncated_svd_gain(&t, &g, &m, sigma_hat, kappa, sth2, snew, s[0]);
    assert_eq!(withheld, 3);
    let want = [1.0, 1.0, snew / 0.36, 1.0, snew / 0.0025, 1.0, 1.0];
    for i in 0..NP {
        for j in 0..NP {
            let w = if i == j { want[i] } else { 0.0 };
            assert!((k[(i, j)] - w).abs() <= 1e-12 * w.abs().max(1.0), "K[{i},{j}] = {} ≠ {w}", k[(i, j)]);
        }
    }
    // the same problem in rotated coordinates: T' = T Wᵀ, m' = W m (g unchanged) gives K' = W K Wᵀ
    let mut rng = SplitMix::new(2);
    let w = M7::from_fn(|_, _| rng.normal()).qr().q();
    let (t2, m2) = (t * w.transpose(), w * m);
    let (k2, withheld2) = truncated_svd_gain(&t2, &g, &m2, sigma_hat, kappa, sth2, snew, s[0]);
    assert_eq!(withheld2, 3);
    let d = (k2 - w * k * w.transpose()).amax();
    assert!(d <= 1e-9 * k.amax(), "rotated gain off by {d:e}");
    // every direction passing (σ̂ = 0) gives the thesis gain to the bit; σ̂ = ∞ or NaN withholds all five
    let thesis = svd_gain(&t2, sth2, snew, s[0]);
    assert_eq!(truncated_svd_gain(&t2, &g, &m2, 0.0, kappa, sth2, snew, s[0]), (thesis, 0));
    for bad in [f64::INFINITY, f64::NAN] {
        let (k3, n) = truncated_svd_gain(&t2, &g, &m2, bad, kappa, sth2, snew, s[0]);
        assert_eq!(n, 5);
        assert!((k3 - M7::identity()).amax() < 1e-12, "{k3}");
    }
}

#[test]
fn noise_sigma_is_the_least_squares_residual_per_degree_of_freedom() {
    // σ̂ = ρ/√(n − r) against a dense least-squares solve (nalgebra's SVD), with the scalar rows (0 and 4) of every
    // point zero as in real data, and points at rest (R̂ = 0, F = 0) not counted
    let (nb, ns) = (2, 6);
    let mut rng = SplitMix::new(21);
    let mut st = DataStack::new(nb, ns, 1e9, 3).unwrap();
    let mut rows: Vec<Vec<(M87, V8)>> = vec![Vec::new(); nb];
    for k in 0..ns {
        let rest = k == 1;
        let r: Vec<M87> =
            (0..nb).map(|_| M87::from_fn(|i, _| if rest || i == 0 || i == 4 { 0.0 } else { rng.normal() })).collect();
        let f: Vec<V8> =
            (0..nb).map(|_| V8::from_fn(|i, _| if rest || i == 0 || i == 4 { 0.0 } else { rng.normal() })).collect();
        assert_eq!(st.offer(&r, &f).unwrap(), Offer::Appended);
        for b in 0..nb {
            rows[b].push((r[b], f[b]));
        }
    }
    for b in 0..nb {
        let a = nalgebra::DMatrix::<f64>::from_fn(8 * ns, NP, |i, j| rows[b][i / 8].0[(i % 8, j)]);
        let y = nalgebra::DVector::<f64>::from_fn(8 * ns, |i, _| rows[b][i / 8].1[i % 8]);
        let x = a.clone().svd(true, true).solve(&y, 1e-14).unwrap();
        let rho = (&a * x - &y).norm();
        let n = 6 * (ns - 1); // five moving points, six nonzero rows each
        let want = rho / ((n - NP) as f64).sqrt();
        let got = st.noise_sigma(b).unwrap();
        assert!((got - want).abs() < 1e-12 * want, "body {b}: {got} vs {want}");
        assert!((st.residual_norm(b).unwrap() - rho).abs() < 1e-12 * rho);
    }
    // no redundancy: one moving point (6 rows) cannot estimate a rank-6 fit's noise
    let mut one = DataStack::new(1, 2, 1e9, 3).unwrap();
    let r = [M87::from_fn(|i, _| if i == 0 || i == 4 { 0.0 } else { rng.normal() })];
    let f = [V8::from_fn(|i, _| if i == 0 || i == 4 { 0.0 } else { rng.normal() })];
    one.offer(&r, &f).unwrap();
    assert_eq!(one.noise_sigma(0), Some(f64::INFINITY));
    assert_eq!(one.noise_sigma(1), None);
}

#[test]
fn bad_gain_arguments_name_the_argument() {
    for k in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = ClParams { kappa: k, ..ClParams::default() }.validate().unwrap_err().to_string();
        assert!(e.contains("`kappa`"), "{e}");
    }
    let e = Gain::parse("tikhonov").unwrap_err().to_string();
    assert!(e.contains("`gain`") && e.contains("thesis") && e.contains("truncated"), "{e}");
    assert_eq!(Gain::parse("truncated").unwrap(), Gain::Truncated);
    assert_eq!(ClParams::default().gain, Gain::Thesis);
    let e = ConcurrentEstimator::new(1, ClParams { kappa: -2.0, ..ClParams::default() }, &[0.0; 7]).unwrap_err();
    assert!(e.to_string().contains("`kappa`"), "{e}");
}

#[test]
fn truncated_gain_keeps_the_noise_free_run_and_bounds_the_noisy_one() {
    // the ch. 9 run: without noise every direction passes and the run is the thesis' to the bit; with 1e-3 N of
    // joint-wrench noise (noise seed 7, every parameter starting at 0.1) the thesis gain's largest relative error
    // is 7.3e4 and the truncated gain's 0.98, below the prior's own largest (0.998, the base's 0.1 kg for 50 kg)
    let m = builtin::load("valverde_ch9_two_arm").unwrap();
    let sc = scenario(&m, 10);
    let tr = |sc: &ClScenario| ClScenario { params: ClParams { gain: Gain::Truncated, ..sc.params }, ..sc.clone() };
    let a = run_cl(&m, &sc, None).unwrap();
    let b = run_cl(&m, &tr(&sc), None).unwrap();
    assert_eq!(a.estimates, b.estimates);
    assert!(b.gain_withheld.iter().all(|&w| w == 0));
    assert!(b.noise_sigma.iter().all(|&s| s < 1e-12), "{:?}", b.noise_sigma);
    let noisy = ClScenario { noise: Noise { wrench: 1e-3, rate: 0.0 }, m0: vec![0.1; NP * m.nbodies()], ..sc };
    let rel = |r: &ClRun| {
        let mut worst: f64 = 0.0;
        for (j, (e, t)) in r.final_estimate.iter().zip(&r.truth).enumerate() {
            let scale = if *t != 0.0 { t.abs() } else { r.truth[7 * (j / 7)].abs() };
            worst = worst.max((e - t).abs() / scale);
        }
        worst
    };
    let a = run_cl(&m, &noisy, None).unwrap();
    let b = run_cl(&m, &tr(&noisy), None).unwrap();
    assert!(rel(&a) > 1e3, "thesis {}", rel(&a));
    assert!(rel(&b) < 1.0, "truncated {}", rel(&b));
    assert!(b.gain_withheld.iter().sum::<usize>() > 0);
    // σ̂ is the wrench noise's size (each body's wrench combines one or two joints' sensors)
    assert!(b.noise_sigma.iter().all(|&s| s > 5e-4 && s < 3e-3), "{:?}", b.noise_sigma);
}
