//! "Hot paths allocate nothing", measured: a counting global allocator counts the allocations made by
//! this thread during repeated `aba`, `hybrid_aba`, `rnea`, `crba`, `dq_dynamics` (tree solver, with and
//! without locked joints), `dq_hybrid_dynamics` calls after one warm-up call, and during RK4 steps (the
//! difference between a simulation of 2N and of N steps, with the same number of recorded samples, is
//! the cost of N steps). Every count must be 0.

use freefloat_core::dqdynamics::{dq_dynamics, dq_hybrid_dynamics};
use freefloat_core::dynamics::derivatives::{
    aba_derivatives, frame_dq_pose_derivatives, frame_log_error_derivatives, rnea_derivatives, step, step_derivatives,
    Derivatives, Scheme,
};
use freefloat_core::dynamics::{aba, crba, hybrid_aba, rnea, Prescribed};
use freefloat_core::model::builtin;
use freefloat_core::sim::{simulate_with, Formulation, Inputs, Method, SimOptions, TorqueSource};
use freefloat_core::spatial::Se3;
use freefloat_core::Data;
use std::cell::RefCell;

mod counting_alloc;
use counting_alloc::count;

/// One state: (q, v, tau).
type State = (Vec<f64>, Vec<f64>, Vec<f64>);

#[test]
fn hot_paths_allocate_nothing() {
    let mut report = vec![];
    for name in ["naveen_dual_arm_consistent", "valverde_ch7_two_arm"] {
        let m = builtin::load(name).expect("built-in");
        let mut d = Data::new(&m);
        // states whose quaternion is off by round-off, so the normalised copy (d.qbuf) is exercised
        let states: Vec<State> = (0..16)
            .map(|k| {
                let mut q = m.neutral();
                for i in 1..m.nbodies() {
                    if m.nqs[i] == 1 {
                        q[m.idx_q[i]] = 0.1 * (i + k) as f64;
                    }
                }
                let th = 0.1 * k as f64;
                let s = (1.0 + 1e-9) * th.sin();
                q[3..7].copy_from_slice(&[0.6 * s, 0.0, 0.8 * s, (1.0 + 1e-9) * th.cos()]);
                let v = (0..m.nv).map(|j| 0.05 * ((j + k) as f64).sin()).collect();
                let u = (0..m.nv).map(|j| 0.5 * ((j * k) as f64).cos()).collect();
                (q, v, u)
            })
            .collect();
        let fext = vec![0.01; 6 * m.nbodies()];
        let mask: Vec<bool> = (0..m.nbodies()).map(|i| i == 2).collect();
        let ddq = vec![0.1; m.nv];
        let mut run = |what: &str, d: &mut Data, f: &dyn Fn(&mut Data, &State)| {
            f(d, &states[0]); // warm-up
            let n = count(|| {
                for _ in 0..8 {
                    for s in &states {
                        f(d, s);
                    }
                }
            });
            report.push((format!("{name}: {what}"), n));
        };
        run("aba", &mut d, &|d, (q, v, u)| aba(&m, d, q, v, u, Some(&fext)).expect("aba"));
        run("hybrid_aba", &mut d, &|d, (q, v, u)| {
            hybrid_aba(&m, d, q, v, u, None, Some(Prescribed { mask: &mask, ddq: &ddq })).expect("hybrid")
        });
        run("rnea", &mut d, &|d, (q, v, u)| rnea(&m, d, q, v, u, Some(&fext)).expect("rnea"));
        run("crba", &mut d, &|d, (q, _, _)| crba(&m, d, q).expect("crba"));
        run("dq_dynamics", &mut d, &|d, (q, v, u)| {
            dq_dynamics(&m, d, q, v, u, Some(&fext), None).expect("dq");
        });
        run("dq_dynamics locked", &mut d, &|d, (q, v, u)| {
            dq_dynamics(&m, d, q, v, u, None, Some(&mask)).expect("dq locked");
        });
        let w = RefCell::new(Derivatives::new(&m));
        run("aba_derivatives", &mut d, &|d, (q, v, u)| {
            aba_derivatives(&m, d, &mut w.borrow_mut(), q, v, u, Some(&fext)).expect("aba derivatives")
        });
        run("rnea_derivatives", &mut d, &|d, (q, v, u)| {
            rnea_derivatives(&m, d, &mut w.borrow_mut(), q, v, u, None).expect("rnea derivatives")
        });
        for scheme in [Scheme::Euler, Scheme::Rk4] {
            run(&format!("step_derivatives {scheme:?}"), &mut d, &|d, (q, v, u)| {
                step_derivatives(&m, d, &mut w.borrow_mut(), q, v, u, 0.01, scheme).expect("step derivatives")
            });
            run(&format!("step {scheme:?}"), &mut d, &|d, (q, v, u)| {
                step(&m, d, &mut w.borrow_mut(), q, v, u, 0.01, scheme).expect("step")
            });
        }
        let jac6 = RefCell::new(nalgebra::DMatrix::zeros(6, m.nv));
        let jac8 = RefCell::new(nalgebra::DMatrix::zeros(8, m.nv));
        let tip = m.nbodies() - 1;
        run("frame_log_error_derivatives", &mut d, &|d, (q, _, _)| {
            let mut e = [0.0; 6];
            let r = Se3::identity();
            frame_log_error_derivatives(&m, d, q, tip, &r, &r, &mut e, &mut jac6.borrow_mut()).expect("log error")
        });
        run("frame_dq_pose_derivatives", &mut d, &|d, (q, _, _)| {
            let mut x = [0.0; 8];
            frame_dq_pose_derivatives(&m, d, q, tip, &Se3::identity(), &mut x, &mut jac8.borrow_mut()).expect("dq pose")
        });
        run("dq_hybrid_dynamics", &mut d, &|d, (q, v, u)| {
            dq_hybrid_dynamics(&m, d, q, v, u, None, &mask, &ddq).expect("dq hybrid");
        });

        // RK4 steps: simulate N and 2N steps recording the same two samples (start and end)
        let (q0, v0, _) = &states[3];
        for formulation in [Formulation::Aba, Formulation::DualQuaternion] {
            let sim = |steps: usize| {
                let opts = SimOptions {
                    t_final: steps as f64 * 1e-3,
                    dt: 1e-3,
                    method: Method::Rk4,
                    record_every: 1_000_000,
                    max_steps: usize::MAX,
                };
                let inputs = Inputs {
                    torques: TorqueSource::Function(Box::new(|t, _q, _v, out| {
                        for (k, o) in out.iter_mut().enumerate() {
                            *o = (t + k as f64).sin();
                        }
                        Ok(())
                    })),
                    ..Default::default()
                };
                count(|| {
                    let tr = simulate_with(&m, q0, v0, &opts, inputs, formulation, None).expect("sim");
                    assert_eq!(tr.len(), 2);
                })
            };
            let (n1, n2) = (sim(200), sim(400));
            report.push((format!("{name}: 200 RK4 steps ({formulation:?}); setup {n1} allocations"), n2 - n1.min(n2)));
            assert!(n2 >= n1, "{name}: {n2} allocations for 400 steps, {n1} for 200");
        }
    }
    let text: Vec<String> = report.iter().map(|(w, n)| format!("{w}: {n}")).collect();
    println!("{}", text.join("\n"));
    assert!(report.iter().all(|(_, n)| *n == 0), "allocations in hot paths:\n{}", text.join("\n"));
}
