//! "No allocation inside a DDP iteration", measured with a counting global allocator (as `allocations.rs`):
//! a solve of 6 iterations allocates exactly as much as a solve of 2 (setup and the returned solution only),
//! on the floating-robot model with every cost kind, and the backward pass, the line-search rollout and the
//! node derivatives allocate nothing after a warm-up.

// Table values are printed numbers (not approximations of constants); loops index several arrays.
#![allow(clippy::approx_constant, clippy::needless_range_loop)]

use freefloat_core::control::ddp::backward::backward_pass;
use freefloat_core::control::ddp::costs::{CostTerm, KeepOut, Residual, Weights};
use freefloat_core::control::ddp::forward::rollout_trial;
use freefloat_core::control::ddp::{ActionModel, DdpOptions, FloatingRobot, RegOptions, Solver};
use freefloat_core::model::builtin;
use freefloat_core::spatial::{Se3, V3};

mod counting_alloc;
use counting_alloc::count;

fn robot(n: usize) -> (FloatingRobot, Vec<f64>) {
    let m = builtin::load("valverde_ch8_arm").unwrap();
    let (body, place) = m.frame_or_body("ee").unwrap();
    let target = Se3::new(freefloat_core::spatial::rpy_to_rot(&V3::new(1.5, 0.0, 0.1)), V3::new(6.3, 0.3, 5.1));
    let dq = freefloat_core::dualquat::DualQuat::from_se3(&target).to_array();
    let mut x0 = vec![0.0; m.nq + m.nv];
    x0[6] = 1.0;
    x0[8] = 0.08;
    x0[9] = -0.17;
    let running = vec![
        CostTerm {
            name: "ee".into(),
            residual: Residual::FramePlacement { body, placement: place, refs: vec![target] },
            weights: Weights::constant(vec![40.0; 6]).unwrap(),
        },
        CostTerm {
            name: "ee_dq".into(),
            residual: Residual::FrameDualQuat { body, placement: place, refs: vec![dq], nearest_sign: false },
            weights: Weights::scheduled(vec![10.0; 8], vec![20.0; 8], vec![30.0; 8], [1, 2, 3, 4]).unwrap(),
        },
        CostTerm {
            name: "v".into(),
            residual: Residual::State { refs: vec![x0.clone()] },
            weights: Weights::constant(vec![1.0; 24]).unwrap(),
        },
        CostTerm {
            name: "u".into(),
            residual: Residual::Control { refs: vec![vec![0.0; 12]] },
            weights: Weights::constant(vec![0.1; 12]).unwrap(),
        },
    ];
    let terminal = running[..3].to_vec();
    let ko = vec![KeepOut { iq: 8, iv: 7, center: 0.0, width: 0.0175, height: 0.1 }];
    (FloatingRobot::new(m, 0.05, n, running, terminal, ko).unwrap(), x0)
}

#[test]
fn ddp_iterations_allocate_nothing() {
    let n = 6;
    let (mut rob, x0) = robot(n);
    let opts = |it| DdpOptions {
        max_iter: it,
        alphas: vec![0.5, 0.1],
        tol_expected: 0.0,
        reg: RegOptions { init: 1e-6, ..Default::default() },
        ..Default::default()
    };
    let us0 = vec![0.0; n * 12];
    let mut s2 = Solver::new(&rob, opts(2)).unwrap();
    let mut s6 = Solver::new(&rob, opts(6)).unwrap();
    // Warm-up (first calls may initialise lazily).
    s2.solve(&mut rob, &x0, &us0, None, &mut |_| true).unwrap();
    let mut sol6 = None;
    let a2 = count(|| {
        s2.solve(&mut rob, &x0, &us0, None, &mut |_| true).unwrap();
    });
    let a6 = count(|| {
        sol6 = Some(s6.solve(&mut rob, &x0, &us0, None, &mut |_| true).unwrap());
    });
    assert_eq!(sol6.unwrap().iterations, 6);

    // The blocks one by one.
    let ws = &mut s6.ws;
    let a = count(|| {
        for k in 0..n {
            rob.calc_diff(k, ws.xs[k].as_slice(), ws.us[k].as_slice(), &mut ws.diffs[k]).unwrap();
        }
        rob.calc_diff_terminal(ws.xs[n].as_slice(), &mut ws.diffs[n]).unwrap();
        backward_pass(&mut rob, ws, 1e-6, false, false).unwrap();
        rollout_trial(&mut rob, ws, 0.5, false).unwrap();
        rollout_trial(&mut rob, ws, 0.5, true).unwrap();
    });
    let b = count(|| {
        backward_pass(&mut rob, ws, 1e-6, false, false).unwrap();
    });
    let c = count(|| {
        freefloat_core::control::ddp::backward::expected_change(ws, true, false);
    });
    let e = count(|| {
        rollout_trial(&mut rob, ws, 0.5, false).unwrap();
    });
    assert_eq!((a, b, c, e), (0, 0, 0, 0), "derivatives, backward pass and rollouts allocated");
    assert_eq!(a2, a6, "4 more iterations allocated {} times", a6 as i64 - a2 as i64);
}

/// Allocations of one node's `calc` and `calc_diff` after a warm-up call of each.
fn node_allocations(rob: &mut FloatingRobot, x0: &[f64]) -> (usize, usize) {
    let mut xn = vec![0.0; 25];
    let u = vec![0.1; 12];
    let mut d = freefloat_core::control::ddp::NodeDiff::zeros(24, 12);
    rob.calc(0, x0, &u, &mut xn).unwrap();
    rob.calc_diff(0, x0, &u, &mut d).unwrap();
    let a = count(|| {
        rob.calc(0, x0, &u, &mut xn).unwrap();
    });
    let b = count(|| {
        rob.calc_diff(0, x0, &u, &mut d).unwrap();
    });
    (a, b)
}

#[test]
fn which_block_allocates() {
    let n = 6;
    let (mut rob, x0) = robot(n);
    let (a, b) = node_allocations(&mut rob, &x0);
    let c = count(|| {
        rob.calc_terminal(&x0).unwrap();
    });
    let e = count(|| {
        rob.set_iteration(3);
    });
    assert_eq!((a, b, c, e), (0, 0, 0, 0));
}

#[test]
fn the_rate_driven_wrist_and_the_nearest_sign_allocate_nothing() {
    // the chapter 8 defaults: the thesis' wrist driven by its rates (the leading bodies' dynamics and derivatives,
    // then the full model's kinematics for the costs) and the nearest-sign dual-quaternion cost
    let (mut rob, x0) = robot(6);
    for t in rob.running.iter_mut().chain(rob.terminal.iter_mut()) {
        if let Residual::FrameDualQuat { nearest_sign, .. } = &mut t.residual {
            *nearest_sign = true;
        }
    }
    rob.set_rate_driven(3).unwrap();
    assert_eq!(node_allocations(&mut rob, &x0), (0, 0));
}
