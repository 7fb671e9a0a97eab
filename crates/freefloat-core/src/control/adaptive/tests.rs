//! Checks of the ch. 4 controller against things it does not compute itself: the closed-form components of the
//! error variables, the Lyapunov identity (4.21) by central differences, the regression `R v(M) = f` along the
//! simulated motion, the dense output's order, and the data-stack invariants.

use super::closed_loop::{dq_at, put_dq, v7_at};
use super::closed_loop::{rhs, Learning, Setup, IP, IQ, IQQ, IV, IW, NX};
use super::gains::{Gains, M7};
use super::law::{lyapunov, lyapunov_rate_theory, LawForm};
use super::reference::{Harmonic3, Reference};
use super::simulate::{simulate, Integrator, RunOptions};
use super::stack::{DataStack, Selection};
use super::tracking::{error_state, pose_error};
use crate::dualquat::pose::from_rotation_body_translation;
use crate::dualquat::regressor::{relative_regressor, V7};
use crate::dualquat::{DualQuat, Quat};
use crate::spatial::V3;
use rand::{Rng, SeedableRng};

fn truth() -> V7 {
    V7::from_column_slice(&[5.0, 2.0, 3.0, 5.0, 1.0, 4.0, 10.0])
}
fn thesis_gains() -> Gains {
    Gains::scalar(0.74 / 3.0, 0.2 / 3.0, 84.37, 15.0, 10.0).unwrap()
}
fn rv3(r: &mut impl Rng) -> V3 {
    V3::new(r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0))
}
fn rpose(r: &mut impl Rng) -> (DualQuat, Quat, V3) {
    let q = Quat::from_vec4(&nalgebra::Vector4::new(r.gen(), r.gen(), r.gen(), r.gen()).normalize());
    let p = rv3(r) * 2.0;
    (from_rotation_body_translation(&q, &p), q, p)
}

fn example_a_setup(alpha: f64, law: LawForm) -> Setup {
    let qr = Quat::from_vec4(&nalgebra::Vector4::new(0.8721, -0.1178, -0.4621, -0.1097).normalize());
    let angular =
        Harmonic3 { amplitude: V3::new(0.0, 1.0, 0.0), frequency: V3::new(0.0, 1.0, 0.0), ..Default::default() };
    Setup {
        truth: truth(),
        gains: thesis_gains(),
        alpha,
        alpha_off_after: None,
        law,
        learning: Learning::Continuous,
        q0: from_rotation_body_translation(&qr, &V3::new(1.0, 2.0, 0.5)),
        w0: DualQuat::vector(&V3::new(0.5, 1.0, 1.0), &V3::new(0.5, -0.5, 1.0)),
        estimate0: V7::zeros(),
        reference: Reference::harmonic(angular, Harmonic3::constant(V3::new(1.0, 0.0, 0.0))).unwrap(),
    }
}

#[test]
fn error_variables_match_their_closed_forms() {
    // A9, A10 of the acceptance list
    let mut r = rand::rngs::StdRng::seed_from_u64(1);
    let g = Gains::new(
        crate::spatial::M3::from_diagonal(&V3::new(0.3, 0.5, 0.7)),
        crate::spatial::M3::from_diagonal(&V3::new(0.2, 0.4, 0.6)),
        crate::spatial::M3::identity(),
        crate::spatial::M3::identity(),
        M7::identity(),
    )
    .unwrap();
    for _ in 0..20 {
        let (q, qr, p) = rpose(&mut r);
        let (wb, vb) = (rv3(&mut r), rv3(&mut r));
        let w = DualQuat::vector(&wb, &vb);
        let x = error_state(&g, &q, &w, &DualQuat::ZERO, &DualQuat::ZERO);
        let e = x.e;
        assert!((e.r.v - 0.5 * p).norm() < 1e-14 && e.r.w.abs() < 1e-14);
        assert!((e.d.w - (0.25 * p.norm_squared() + 1.0 - qr.w)).abs() < 1e-13);
        assert!((e.d.v - qr.v).norm() < 1e-14);
        assert!((x.e_dot.r.v - 0.5 * (vb - wb.cross(&p))).norm() < 1e-13);
        assert!((x.e_dot.d.v - 0.5 * (qr.w * wb + qr.v.cross(&wb))).norm() < 1e-13);
        assert!((x.s.r.v - (wb + g.k_q * qr.v)).norm() < 1e-13);
        assert!((x.s.d.v - (vb + 0.5 * g.k_r * p)).norm() < 1e-13);
    }
    assert_eq!(pose_error(&DualQuat::ONE).to_vec8().amax(), 0.0);
    let em = pose_error(&-DualQuat::ONE).to_vec8();
    assert_eq!(em.as_slice(), &[0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0]);
}

/// dV/dt along the closed loop by central differences, and (4.21), at a random state (A11).
fn lyapunov_check(law: LawForm, seed: u64) -> (f64, f64) {
    let mut r = rand::rngs::StdRng::seed_from_u64(seed);
    let mut s = example_a_setup(0.7, law);
    s.reference = Reference::harmonic(
        Harmonic3 {
            offset: rv3(&mut r),
            amplitude: rv3(&mut r),
            frequency: V3::new(1.0, 2.0, 3.0),
            phase: rv3(&mut r),
        },
        Harmonic3 {
            offset: rv3(&mut r),
            amplitude: rv3(&mut r),
            frequency: V3::new(0.5, 1.5, 2.5),
            phase: rv3(&mut r),
        },
    )
    .unwrap();
    let m = super::closed_loop::plant(&s.truth).unwrap();
    let (q, _, _) = rpose(&mut r);
    let w = DualQuat::vector(&rv3(&mut r), &rv3(&mut r));
    let v_hat = truth() + V7::from_fn(|_, _| r.gen_range(-2.0..2.0));
    let a = nalgebra::SMatrix::<f64, 9, 7>::from_fn(|_, _| r.gen_range(-1.0..1.0));
    let p = a.transpose() * a;
    let mut x = [0.0; NX];
    put_dq(&mut x, IQ, &q);
    put_dq(&mut x, IW, &w);
    x[IV..IV + 7].copy_from_slice(v_hat.as_slice());
    x[IP..IP + 49].copy_from_slice(p.as_slice());
    x[IQQ..IQQ + 7].copy_from_slice((p * truth()).as_slice());
    let t = 0.3;
    let mut dx = [0.0; NX];
    let ev = rhs(&s, &m, t, &x, None, s.alpha, &mut dx);
    let v_of = |x: &[f64; NX]| {
        let q = dq_at(x, IQ);
        let err = error_state(&s.gains, &q, &dq_at(x, IW), &DualQuat::ZERO, &DualQuat::ZERO);
        lyapunov(&s.gains, &q, &err, &v7_at(x, IV), &s.truth)
    };
    let h = 1e-5;
    let (mut xp, mut xm) = (x, x);
    for i in 0..NX {
        xp[i] += h * dx[i];
        xm[i] -= h * dx[i];
    }
    let fd = (v_of(&xp) - v_of(&xm)) / (2.0 * h);
    let theory = lyapunov_rate_theory(&s.gains, &ev.err, s.alpha, &v_hat, &s.truth, Some(&p));
    (fd, theory)
}

#[test]
fn lyapunov_derivative_is_4_21_for_the_corrected_law_only() {
    for seed in 0..10 {
        let (fd, th) = lyapunov_check(LawForm::Corrected, seed);
        assert!((fd - th).abs() <= 1e-7 * th.abs().max(1.0), "seed {seed}: {fd} vs {th}");
        assert!(th < 0.0);
        let (fd, th) = lyapunov_check(LawForm::Printed, seed);
        assert!((fd - th).abs() > 1e-5 * th.abs().max(1.0), "printed law seed {seed}: {fd} vs {th}");
    }
}

#[test]
fn regression_holds_along_the_simulated_motion() {
    // A4: R v(M) = f^B at every recorded sample (the plant's true acceleration, the applied force)
    let s = example_a_setup(1.0, LawForm::Corrected);
    let m = super::closed_loop::plant(&s.truth).unwrap();
    let o = RunOptions {
        t_final: 2.0,
        integrator: Integrator::Rk4 { dt: 0.01 },
        output_dt: 0.1,
        max_steps: 1_000_000,
        rank_tol: 1e-8,
    };
    let run = simulate(&s, &o, None).unwrap();
    for k in 0..run.t.len() {
        let mut x = [0.0; NX];
        x[..8].copy_from_slice(&run.q[8 * k..8 * k + 8]);
        x[8..16].copy_from_slice(&run.w[8 * k..8 * k + 8]);
        x[16..23].copy_from_slice(&run.estimate[7 * k..7 * k + 7]);
        let mut dx = [0.0; NX];
        let ev = rhs(&s, &m, run.t[k], &x, None, s.alpha, &mut dx);
        let r = relative_regressor(&ev.w_dot, &dq_at(&x, IW), &ev.reference.1, &ev.reference.0, &dq_at(&x, IQ));
        let res = (r * s.truth - ev.force.to_vec8()).amax();
        assert!(res < 1e-9 * ev.force.to_vec8().amax().max(1.0), "t = {}: {res}", run.t[k]);
        assert!(
            (ev.force.to_vec8() - nalgebra::SVector::<f64, 8>::from_column_slice(&run.force[8 * k..8 * k + 8])).amax()
                < 1e-12
        );
    }
    // V non-increasing
    assert!(run.lyapunov.windows(2).all(|w| w[1] <= w[0] + 1e-9 * w[0]));
}

#[test]
fn dense_output_is_fourth_order() {
    // one DOPRI5 step of y' = cos(t) y from y(0) = 1; the interpolant at interior points against exp(sin t)
    let tab = &crate::rk::DOPRI5;
    let f = |t: f64, y: f64| t.cos() * y;
    let mut errs = vec![];
    for &h in &[0.2, 0.1] {
        let mut k = [[0.0; 1]; 7];
        k[0][0] = f(0.0, 1.0);
        let mut y1 = 0.0;
        for s in 1..7 {
            let ys = 1.0 + h * tab.a[s].iter().enumerate().map(|(j, a)| a * k[j][0]).sum::<f64>();
            k[s][0] = f(tab.c[s] * h, ys);
            if s == 6 {
                y1 = ys;
            }
        }
        let mut e = 0.0f64;
        for &th in &[0.25, 0.5, 0.8] {
            let y = super::simulate::dense_output_for_test(&[1.0], &[y1], &k, h, th);
            e = e.max((y - (th * h).sin().exp()).abs());
        }
        errs.push(e);
    }
    // local error of a 4th-order interpolant is O(h^5): halving h divides it by ~32
    assert!(errs[0] / errs[1] > 20.0, "{errs:?}");
    assert!(errs[1] < 1e-7);
}

#[test]
fn stack_fills_then_only_improves_every_singular_value() {
    // C6: N_c ≤ N_s; with Algorithm 3 each accepted replacement leaves every sorted σ ≥ before; stop rule
    let mut r = rand::rngs::StdRng::seed_from_u64(3);
    let mut st = DataStack::new(8, 1e9, Selection::Elementwise, 5).unwrap();
    let mut prev = [0.0; 7];
    for k in 0..300 {
        let w = DualQuat::vector(&rv3(&mut r), &rv3(&mut r));
        let wd = DualQuat::vector(&rv3(&mut r), &rv3(&mut r));
        let rr = crate::dualquat::regressor::body_regressor(&w, &wd);
        let changed = st.offer(&rr, &(rr * truth()));
        assert!(st.len() <= 8);
        if k >= 8 && changed {
            assert!(st.singular_values().iter().zip(&prev).all(|(a, b)| *a >= *b - 1e-12));
        }
        prev = *st.singular_values();
        // the sums are the regression of the truth: RR v(M) = Rf
        assert!((st.rr() * truth() - st.rf()).amax() < 1e-9 * st.rf().amax().max(1.0));
    }
    let mut st = DataStack::new(4, 1e-3, Selection::MaxMinSingularValue, 0).unwrap();
    let mut frozen = None;
    for _ in 0..50 {
        let w = DualQuat::vector(&rv3(&mut r), &rv3(&mut r));
        let rr = crate::dualquat::regressor::body_regressor(&w, &w);
        st.offer(&rr, &(rr * truth()));
        if st.stopped() {
            let now = (*st.rr(), st.changes());
            if let Some(f) = frozen {
                assert_eq!(f, now);
            }
            frozen = Some(now);
        }
    }
    assert!(frozen.is_some());
    assert!(DataStack::new(1, 20.0, Selection::Elementwise, 0).is_err());
    assert!(DataStack::new(50, -1.0, Selection::Elementwise, 0).is_err());
}

/// Example B's setting (constant reference w = v = [1, 0, 0], discrete learning with a stack of `n_s`, stop at
/// σ_min 20, α = 0.005), RK4 at 0.01 s for `t_final` seconds.
fn example_b_setup(n_s: usize, t_final: f64) -> (Setup, RunOptions) {
    let mut s = example_a_setup(0.005, LawForm::Corrected);
    s.reference = Reference::constant(V3::new(1.0, 0.0, 0.0), V3::new(1.0, 0.0, 0.0));
    s.learning = Learning::Discrete { n_s, sigma_stop: 20.0, rule: Selection::Elementwise, seed: 0 };
    let o = RunOptions {
        t_final,
        integrator: Integrator::Rk4 { dt: 0.01 },
        output_dt: 0.01,
        max_steps: 1_000_000,
        rank_tol: 1e-8,
    };
    (s, o)
}

#[test]
fn example_b_reaches_rank_7_at_the_second_sample() {
    // C1: the second stored sample (t = 0.01 s) gives rank 7
    let (s, o) = example_b_setup(50, 1.0);
    let run = simulate(&s, &o, None).unwrap();
    let t7 = run.rank7_time.unwrap();
    assert!(t7 <= 0.02 + 1e-12 && t7 > 0.0, "{t7}");
    assert!(run.stack_len.iter().all(|&n| n <= 50));
    assert_eq!(run.stack_len[10], 11); // one sample per step while filling
                                       // mass within 1 % well before 1 s (C2 asks t ≥ 1 s)
    let m = run.estimate[7 * (run.t.len() - 1) + 6];
    assert!((m - 10.0).abs() < 0.1, "{m}");
}

#[test]
fn bad_input_is_named() {
    let mut s = example_a_setup(1.0, LawForm::Corrected);
    let o = RunOptions {
        t_final: 1.0,
        integrator: Integrator::Rk4 { dt: 0.01 },
        output_dt: 0.01,
        max_steps: 10,
        rank_tol: 1e-8,
    };
    s.q0 = DualQuat::ONE.scale(1.01);
    assert!(simulate(&s, &o, None).unwrap_err().to_string().contains("q0"));
    let mut s = example_a_setup(-1.0, LawForm::Corrected);
    assert!(simulate(&s, &o, None).unwrap_err().to_string().contains("alpha"));
    s.alpha = 1.0;
    s.w0 = DualQuat::ONE;
    assert!(simulate(&s, &o, None).unwrap_err().to_string().contains("w0"));
    assert!(Gains::scalar(-1.0, 1.0, 1.0, 1.0, 1.0).unwrap_err().to_string().contains("K_r"));
    assert!(Gains::scalar(1.0, 1.0, 1.0, 1.0, 0.0).unwrap_err().to_string().contains("K_i"));
    let s = example_a_setup(1.0, LawForm::Corrected);
    let bad = RunOptions { integrator: Integrator::Dopri5 { rtol: 2.0, atol: 1e-10, max_step: 1.0 }, ..o };
    assert!(simulate(&s, &bad, None).unwrap_err().to_string().contains("rtol"));
    let long = RunOptions { max_steps: 10, ..o };
    assert!(simulate(&s, &long, None).unwrap_err().to_string().contains("max_steps"));
}

#[test]
fn remark_6_switches_alpha_off_after_the_rank_condition() {
    // Valverde 2018 Remark 6: α = 0 from the first step start `delay` after rank 7; before it the run is the one
    // with α kept (to the bit), after it the stack no longer enters: two stacks of different capacity, which hold
    // different samples once the smaller is full (0.5 s), give the same run.
    let (mut s, o) = example_b_setup(50, 2.0);
    let kept = simulate(&s, &o, None).unwrap();
    assert!(kept.alpha_off_time.is_none() && kept.alpha_in_effect.iter().all(|&a| a == 0.005));
    s.alpha_off_after = Some(0.3);
    let off = simulate(&s, &o, None).unwrap();
    let t_off = off.alpha_off_time.unwrap();
    assert!((t_off - (off.rank7_time.unwrap() + 0.3)).abs() < 1e-12, "{t_off}");
    let k_off = (t_off / 0.01).round() as usize;
    assert_eq!(off.estimate[..7 * (k_off + 1)], kept.estimate[..7 * (k_off + 1)]);
    assert!(off.alpha_in_effect[..k_off].iter().all(|&a| a == 0.005));
    assert!(off.alpha_in_effect[k_off..].iter().all(|&a| a == 0.0));
    let mut bigger = s.clone();
    bigger.learning = example_b_setup(80, 2.0).0.learning;
    let other = simulate(&bigger, &o, None).unwrap();
    assert_eq!(other.estimate, off.estimate);
    bigger.alpha_off_after = None;
    let other_kept = simulate(&bigger, &o, None).unwrap();
    // the stacks differ, and matter while α is on
    assert_ne!(other_kept.estimate, kept.estimate);

    // bad input is named
    s.alpha_off_after = Some(-1.0);
    assert!(simulate(&s, &o, None).unwrap_err().to_string().contains("alpha_off_after"));
    s.alpha_off_after = Some(f64::NAN);
    assert!(simulate(&s, &o, None).unwrap_err().to_string().contains("alpha_off_after"));
}
