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
