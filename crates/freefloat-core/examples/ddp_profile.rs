//! A fixed workload for profiling the per-node blocks of the DDP on `valverde_ch8_arm` (nv = 12): the step
//! derivatives and their parts (forward dynamics, ABA derivatives, mass matrix), the whole `calc_diff` of a
//! robot node with a frame-placement, base-twist and control cost, and one `calc` (step and cost). Every block
//! runs `count` times on a cycle of 64 random states; wall time per call is printed (indicative only on a loaded
//! machine; for instruction counts run it under `valgrind --tool=callgrind`).
//!
//!     cargo build --release --example ddp_profile
//!     target/release/examples/ddp_profile 20000

use freefloat_core::control::ddp::costs::{CostTerm, Residual, Weights};
use freefloat_core::control::ddp::{ActionModel, FloatingRobot, NodeDiff};
use freefloat_core::dynamics::derivatives::{aba_derivatives, Derivatives};
use freefloat_core::dynamics::{aba, crba};
use freefloat_core::model::builtin;
use freefloat_core::spatial::Se3;
use freefloat_core::Data;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Instant;

fn time(name: &str, count: usize, mut f: impl FnMut(usize)) {
    for i in 0..count / 10 {
        f(i);
    }
    let t0 = Instant::now();
    for i in 0..count {
        f(i);
    }
    println!("{name:<28} {:8.3} µs", 1e6 * t0.elapsed().as_secs_f64() / count as f64);
}

fn main() {
    let count: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let m = builtin::load("valverde_ch8_arm").expect("built-in model");
    let (nq, nv) = (m.nq, m.nv);
    let mut rng = StdRng::seed_from_u64(7);
    let states: Vec<(Vec<f64>, Vec<f64>)> = (0..64)
        .map(|_| {
            let mut q = m.neutral();
            for x in q.iter_mut() {
                *x += rng.gen_range(-0.5..0.5);
            }
            let n = (q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6]).sqrt();
            for x in q[3..7].iter_mut() {
                *x /= n;
            }
            let mut x = q;
            x.extend((0..nv).map(|_| rng.gen_range(-0.5..0.5)));
            let u: Vec<f64> = (0..nv).map(|_| rng.gen_range(-1.0..1.0)).collect();
            (x, u)
        })
        .collect();
    let mut d = Data::new(&m);
    let mut w = Derivatives::new(&m);
    time("aba", count, |i| {
        let (x, u) = &states[i % 64];
        aba(&m, &mut d, &x[..nq], &x[nq..], u, None).unwrap();
        black_box(&d.ddq);
    });
    time("crba", count, |i| {
        let (x, _) = &states[i % 64];
        crba(&m, &mut d, &x[..nq]).unwrap();
        black_box(&d.mass_matrix);
    });
    time("aba_derivatives", count, |i| {
        let (x, u) = &states[i % 64];
        aba_derivatives(&m, &mut d, &mut w, &x[..nq], &x[nq..], u, None).unwrap();
        black_box(&w.da_dq);
    });
    let body = m.body_index("wrist_x").or_else(|| Some(m.nbodies() - 1)).unwrap();
    let refs = vec![Se3::identity()];
    let running = vec![
        CostTerm {
            name: "ee".into(),
            residual: Residual::FramePlacement { body, placement: Se3::identity(), refs },
            weights: Weights::constant(vec![1.0; 6]).unwrap(),
        },
        CostTerm {
            name: "vel".into(),
            residual: Residual::State { refs: vec![states[0].0.clone()] },
            weights: Weights::constant([vec![0.0; nv], vec![1.0; 6], vec![0.0; nv - 6]].concat()).unwrap(),
        },
        CostTerm {
            name: "u".into(),
            residual: Residual::Control { refs: vec![vec![0.0; nv]] },
            weights: Weights::constant(vec![0.1; nv]).unwrap(),
        },
    ];
    let mut robot = FloatingRobot::new(m.clone(), 0.05, 640, running, vec![], vec![]).unwrap();
    let ndx = robot.ndx();
    let (mut fx, mut fu) = (nalgebra::DMatrix::zeros(ndx, ndx), nalgebra::DMatrix::zeros(ndx, nv));
    time("step_jacobians", count, |i| {
        let (x, u) = &states[i % 64];
        robot.step_jacobians(x, u, &mut fx, &mut fu).unwrap();
        black_box(&fx);
    });
    let mut nd = NodeDiff::zeros(ndx, nv);
    time("calc_diff (node)", count, |i| {
        let (x, u) = &states[i % 64];
        robot.calc_diff(i % 640, x, u, &mut nd).unwrap();
        black_box(&nd);
    });
    let mut xn = vec![0.0; nq + nv];
    time("calc (node)", count, |i| {
        let (x, u) = &states[i % 64];
        black_box(robot.calc(i % 640, x, u, &mut xn).unwrap());
    });
}
