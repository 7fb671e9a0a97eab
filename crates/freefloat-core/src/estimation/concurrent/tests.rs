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
    let name = std::env::var("CL_MODEL").unwrap_or("valverde_ch9_two_arm".into());
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
    sc.v0[3] = wb;
    sc.v0[4] = -0.7 * wb;
    sc.v0[5] = 0.4 * wb;
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
    println!(
        "max final err {err:.3e} residual {:.3e} changes {} trials {}",
        r.max_residual, r.stack_changes, r.stack_trials
    );
    for i in 0..m.nbodies() {
        let k = 1000;
        let b = &r.block_singular_values[k * np + 7 * i..k * np + 7 * i + 7];
        println!("body {i}: {:?}", b.iter().map(|x| format!("{x:.2e}")).collect::<Vec<_>>());
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
    let r = M87::from_fn(|_, _| rng.normal());
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
    let _ = r;
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
