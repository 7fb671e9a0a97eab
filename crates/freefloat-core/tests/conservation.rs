//! Conservation laws and convergence order of the integrators on the Naveen, Shah, Misra dual-arm robot.
#![allow(clippy::needless_range_loop)]

use freefloat_core::model::builtin;
use freefloat_core::sim::{simulate, InputTiming, Inputs, Method, SimOptions, TorqueSource};
use freefloat_core::Model;

fn initial_state(m: &Model) -> (Vec<f64>, Vec<f64>) {
    let mut q = m.neutral();
    q[0..3].copy_from_slice(&[0.5, -0.2, 0.1]);
    let (s, c) = (0.3f64.sin(), 0.3f64.cos());
    q[3..7].copy_from_slice(&[s * 0.6, -s * 0.48, s * 0.64, c]);
    for (k, x) in q[7..].iter_mut().enumerate() {
        *x = 0.3 * (k as f64 + 1.0).sin();
    }
    let mut v = vec![0.0; m.nv];
    v[..6].copy_from_slice(&[0.01, -0.02, 0.005, 0.01, 0.02, -0.015]);
    for (k, x) in v[6..].iter_mut().enumerate() {
        *x = 0.1 * (k as f64 + 2.0).cos();
    }
    (q, v)
}

/// Internal joint torques only (arm joints and wheels), smooth in time.
fn torques<'a>(nv: usize) -> TorqueSource<'a> {
    TorqueSource::Function(Box::new(move |t, _q, _v, out| {
        out.fill(0.0);
        let amp = [20.0, 15.0, 8.0, 20.0, 12.0, 10.0, 0.5, 0.5, 0.5];
        for k in 6..nv {
            let j = k - 6;
            out[k] = amp[j] * (2.0 * std::f64::consts::PI * (0.2 + 0.05 * j as f64) * t + j as f64).sin();
        }
        Ok(())
    }))
}

fn run(m: &Model, t_final: f64, dt: f64, method: Method) -> freefloat_core::sim::Trajectory {
    let (q, v) = initial_state(m);
    let opts = SimOptions { t_final, dt, method, record_every: 100, max_steps: 10_000_000 };
    // Smooth torques read at every stage: the integrator's order is what these tests measure (held per step,
    // the default, a torque function is a zero-order hold and the run first order in the input).
    let inputs = Inputs { torques: torques(m.nv), timing: InputTiming::Stage, ..Default::default() };
    simulate(m, &q, &v, &opts, inputs, None).unwrap()
}

fn drift(tr: &freefloat_core::sim::Trajectory) -> (f64, f64) {
    let n = tr.len();
    let (mut dp, mut dl, mut sp, mut sl) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for k in 0..n {
        let h = &tr.momentum[6 * k..6 * k + 6];
        let h0 = &tr.momentum[0..6];
        let n3 = |x: &[f64]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        dp = dp.max(n3(&[h[0] - h0[0], h[1] - h0[1], h[2] - h0[2]]));
        dl = dl.max(n3(&[h[3] - h0[3], h[4] - h0[4], h[5] - h0[5]]));
        sp = sp.max(n3(&h[0..3]));
        sl = sl.max(n3(&h[3..6]));
    }
    (dp / sp, dl / sl)
}

#[test]
fn rk4_conserves_momentum_and_energy_over_60s() {
    let m = builtin::load("naveen_dual_arm").unwrap();
    let tr = run(&m, 60.0, 1e-3, Method::Rk4);
    let (dp, dl) = drift(&tr);
    assert!(dp < 1e-9 && dl < 1e-9, "relative momentum drift {dp:e} / {dl:e}");
    let n = tr.len();
    let emax = tr.kinetic_energy.iter().cloned().fold(0.0, f64::max);
    let bal = (0..n).map(|k| (tr.kinetic_energy[k] - tr.kinetic_energy[0] - tr.work[k]).abs()).fold(0.0, f64::max);
    assert!(bal < 1e-9 * emax, "energy - work = {bal:e} (max energy {emax})");
    println!("60 s RK4: momentum drift {dp:.2e} / {dl:.2e}, |ΔE - W| / E = {:.2e}", bal / emax);
}

/// Error against a fine reference shrinks ~16× when dt halves (fourth order, base attitude included).
#[test]
fn rk4_is_fourth_order_on_the_rotation_group() {
    let m = builtin::load("naveen_dual_arm").unwrap();
    let t = 2.0;
    let reference = run(&m, t, 1e-3 / 8.0, Method::Rk4);
    let last = |tr: &freefloat_core::sim::Trajectory| tr.q[(tr.len() - 1) * m.nq..].to_vec();
    let qref = last(&reference);
    let err = |dt: f64| {
        let q = last(&run(&m, t, dt, Method::Rk4));
        q.iter().zip(&qref).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
    };
    let (e1, e2, e3) = (err(2e-2), err(1e-2), err(5e-3));
    let (r1, r2) = (e1 / e2, e2 / e3);
    println!("RK4 errors {e1:.3e} {e2:.3e} {e3:.3e}, ratios {r1:.2} {r2:.2}");
    assert!(r1 > 12.0 && r1 < 20.0 && r2 > 12.0 && r2 < 20.0, "ratios {r1} {r2} are not ~16");
}

#[test]
fn rk45_meets_its_tolerance() {
    let m = builtin::load("naveen_dual_arm").unwrap();
    let reference = run(&m, 3.0, 1e-3 / 4.0, Method::Rk4);
    let tr = run(&m, 3.0, 1e-1, Method::Rk45 { rtol: 1e-10, atol: 1e-12, max_step: f64::INFINITY });
    let qa = &tr.q[(tr.len() - 1) * m.nq..];
    let qb = &reference.q[(reference.len() - 1) * m.nq..];
    let e = qa.iter().zip(qb).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(tr.steps < 3000, "too many steps: {}", tr.steps);
    assert!(e < 1e-7, "rk45 vs fine rk4: {e:e}");
    assert!((tr.t[tr.len() - 1] - 3.0).abs() < 1e-12);
}
