//! Cost algebra and derivatives of the DDP costs (Valverde 2018 ch. 8): keep-out table
//! (§6.3), weight schedule (§6.2), the helical reference (§7.2), the initial end-effector pose of
//! `valverde_ch8_arm`, and every analytic cost gradient against central differences in the tangent.

// Table values are printed numbers (not approximations of constants); loops index several arrays.
#![allow(clippy::approx_constant, clippy::needless_range_loop)]

use freefloat_core::control::ddp::costs::{keep_out, schedule_blend, CostTerm, KeepOut, Residual, Weights};
use freefloat_core::control::ddp::reference::screw_reference;
use freefloat_core::control::ddp::{ActionModel, FloatingRobot, NodeDiff};
use freefloat_core::dualquat::{pose, DualQuat, Quat};
use freefloat_core::model::builtin;
use freefloat_core::spatial::{quat_normalize, Se3, V3};
use rand::{Rng, SeedableRng};

fn x0(m: &freefloat_core::Model) -> Vec<f64> {
    let mut x = vec![0.0; m.nq + m.nv];
    x[6] = 1.0; // quaternion w
    let d = std::f64::consts::PI / 180.0;
    x[8] = 5.0 * d; // shoulder
    x[9] = -10.0 * d; // elbow
    x[10] = 5.0 * d; // wrist_z
    x
}

#[test]
fn keep_out_reproduces_the_table_and_its_derivatives_match_differences() {
    let l = std::f64::consts::PI / 180.0;
    // (|θ − θ̄| in degrees, c, |c'|, c'') from the §6.3 table (K = 0.1, ℓ = 1°).
    // Far from the band (e^{2s} would overflow) everything is finite and tiny.
    for deg in [15.0, 19.0, 25.0, 40.0, 1e3] {
        let (v, d1, d2) = keep_out(deg * l, 0.0, l, 0.1);
        assert!(v.is_finite() && d1.is_finite() && d2.is_finite() && v.abs() < 1e-30, "{deg}°: {v} {d1} {d2}");
    }
    for (deg, c, c1, c2) in [
        (0.0, 0.05, 0.0, -164.14),
        (0.5, 0.043782, 1.4102, -151.55),
        (1.0, 0.026894, 2.2530, -9.780),
        (2.0, 0.0017986, 0.40480, 77.84),
    ] {
        let (v, d1, d2) = keep_out(deg * l, 0.0, l, 0.1);
        assert!((v - c).abs() < 1e-4 * c, "{deg}°: c = {v}");
        assert!((d1.abs() - c1).abs() < 5e-4 * c1.max(1.0), "{deg}°: c' = {d1}");
        assert!((d2 - c2).abs() < 5e-3 * c2.abs(), "{deg}°: c'' = {d2}");
        let h = 1e-7;
        let th = deg * l + 0.1 * l;
        let fd1 = (keep_out(th + h, 0.0, l, 0.1).0 - keep_out(th - h, 0.0, l, 0.1).0) / (2.0 * h);
        let fd2 = (keep_out(th + h, 0.0, l, 0.1).1 - keep_out(th - h, 0.0, l, 0.1).1) / (2.0 * h);
        let (_, a1, a2) = keep_out(th, 0.0, l, 0.1);
        assert!((fd1 - a1).abs() < 1e-6 * a1.abs().max(1.0));
        assert!((fd2 - a2).abs() < 1e-6 * a2.abs().max(1.0));
    }
}

#[test]
fn weight_schedule_reproduces_table_8_2_blends() {
    // (i, β_{k,qr}, β_{r,e}) from the §6.2 table under the piecewise-linear reading.
    let b = [40, 45, 60, 65];
    let mut w = Weights::scheduled(
        vec![60.0, 0.5, 168.0, 1.0],
        vec![192.0, 0.1, 240.0, 1.0],
        vec![312.0, 0.001, 648.0, 0.3],
        b,
    )
    .unwrap();
    for (i, kqr, re, fqr, rf) in [
        (1, 60.0, 0.5, 168.0, 1.0),
        (40, 60.0, 0.5, 168.0, 1.0),
        (42, 112.8, 0.34, 196.8, 1.0),
        (45, 192.0, 0.1, 240.0, 1.0),
        (60, 192.0, 0.1, 240.0, 1.0),
        (62, 240.0, 0.0604, 403.2, 0.72),
        (65, 312.0, 0.001, 648.0, 0.3),
        (150, 312.0, 0.001, 648.0, 0.3),
    ] {
        w.set_iteration(i);
        let c = &w.current;
        assert!((c[0] - kqr).abs() < 1e-9 && (c[1] - re).abs() < 1e-9, "i = {i}: {c:?}");
        assert!((c[2] - fqr).abs() < 1e-9 && (c[3] - rf).abs() < 1e-9, "i = {i}: {c:?}");
    }
    assert_eq!(schedule_blend(10, b), (1.0, 0.0, 0.0));
    assert!(Weights::scheduled(vec![1.0], vec![1.0], vec![1.0], [5, 4, 6, 7]).is_err());
    assert!(Weights::constant(vec![-1.0]).is_err());
}

fn thesis_helix(n: usize, dt: f64) -> Vec<DualQuat> {
    let h = std::f64::consts::FRAC_PI_4;
    let q = Quat::new(h.cos(), h.sin(), 0.0, 0.0);
    let start = pose::from_rotation_translation(&q, &V3::new(6.25, 0.35, 5.0));
    let l = V3::new(1.0, 0.0, 0.0);
    let m = V3::new(0.0, 0.0, 0.35).cross(&l);
    screw_reference(&start, &l, &m, 2.0 * std::f64::consts::PI, 0.2, 7.0, 20.0, dt, n).unwrap()
}

#[test]
fn helical_reference_reproduces_the_tabulated_poses() {
    let refs = thesis_helix(640, 0.05);
    let rows = [
        (0.0, [0.70711, 0.70711, 0.0, 0.0], [-2.20971, 2.20971, 1.89151, 1.64402]),
        (9.5, [0.38268, 0.92388, 0.0, 0.0], [-2.89867, 1.20067, 2.47138, 0.88974]),
        (12.0, [0.0, 1.0, 0.0, 0.0], [-3.15, 0.0, 2.675, 0.0]),
        (17.0, [-0.70711, 0.70711, 0.0, 0.0], [-2.24506, -2.24506, 1.89151, -1.64402]),
        (22.0, [-1.0, 0.0, 0.0, 0.0], [0.0, -3.2, 0.0, -2.325]),
        (30.0, [-0.70711, -0.70711, 0.0, 0.0], [2.28042, -2.28042, -1.89151, -1.64402]),
    ];
    for (t, r, d) in rows {
        let a = refs[(t / 0.05_f64).round() as usize].to_array();
        for i in 0..4 {
            assert!((a[i] - r[i]).abs() < 1e-5 && (a[4 + i] - d[i]).abs() < 1e-5, "t = {t}: {a:?}");
        }
    }
    let mut max_step: f64 = 0.0;
    for k in 0..640 {
        let (a, b) = (refs[k].to_array(), refs[k + 1].to_array());
        max_step = max_step.max((0..8).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max));
        assert!(refs[k].unit_defect() < 1e-12);
    }
    assert!(max_step <= 0.0252, "{max_step}");
    assert_eq!(refs[640].to_array(), refs[540].to_array());
}

#[test]
fn ch8_arm_initial_end_effector_pose() {
    let m = builtin::load("valverde_ch8_arm").unwrap();
    assert_eq!((m.nq, m.nv), (13, 12));
    let mut d = freefloat_core::Data::new(&m);
    let x = x0(&m);
    freefloat_core::kinematics::forward_kinematics(&m, &mut d, &x[..13]).unwrap();
    let (body, place) = m.frame_or_body("ee").unwrap();
    let o = d.o_mi[body].compose(&place);
    assert!((o.trans - V3::new(6.72717, 0.0, 5.0)).amax() < 1e-5, "{:?}", o.trans);
    let g = freefloat_core::control::ddp::costs::frame_dual_quat(&m, &x[..13], body, &place, &o).unwrap().to_array();
    let h = std::f64::consts::FRAC_PI_4.cos();
    assert!((g[0].abs() - h).abs() < 1e-9 && (g[1].abs() - h).abs() < 1e-9 && g[2].abs() < 1e-9 && g[3].abs() < 1e-9);
    // ‖q_G − q_D‖² = ¼‖Δr‖² (equal real parts) against the phase-1 target; 0.087507 there with
    // the rounded x = 6.727, ¼((6.72717 − 6.25)² + 0.35²) = 0.087548 with the model's exact position.
    let refs = thesis_helix(640, 0.05);
    let r = refs[0].to_array();
    let e2: f64 = (0..8).map(|i| (g[i] - r[i]).powi(2)).sum();
    assert!((e2 - 0.25 * ((o.trans.x - 6.25).powi(2) + 0.35f64.powi(2))).abs() < 1e-12, "{e2}");
    assert!((e2 - 0.087548).abs() < 1e-6, "{e2}");
}

fn robot_with_all_costs(n: usize) -> FloatingRobot {
    let m = builtin::load("valverde_ch8_arm").unwrap();
    let (body, place) = m.frame_or_body("ee").unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let mut w = |k: usize| -> Vec<f64> { (0..k).map(|_| rng.gen_range(0.5..2.0)).collect() };
    let target = Se3::new(freefloat_core::spatial::rpy_to_rot(&V3::new(0.3, -0.2, 0.5)), V3::new(6.0, 0.4, 5.2));
    let dq = thesis_helix(n, 0.05).iter().map(|q| q.to_array()).collect::<Vec<_>>();
    let mut xr = x0(&m);
    xr[0] = 0.1;
    xr[15] = 0.2;
    let running = vec![
        CostTerm {
            name: "ee".into(),
            residual: Residual::FramePlacement { body, placement: place, refs: vec![target] },
            weights: Weights::constant(w(6)).unwrap(),
        },
        CostTerm {
            name: "ee_dq".into(),
            residual: Residual::FrameDualQuat { body, placement: place, refs: dq.clone(), nearest_sign: false },
            weights: Weights::constant(w(8)).unwrap(),
        },
        CostTerm {
            name: "state".into(),
            residual: Residual::State { refs: vec![xr.clone()] },
            weights: Weights::constant(w(24)).unwrap(),
        },
        CostTerm {
            name: "u".into(),
            residual: Residual::Control { refs: vec![vec![0.1; 12]] },
            weights: Weights::constant(w(12)).unwrap(),
        },
    ];
    let terminal = running[..3].to_vec();
    let l = std::f64::consts::PI / 180.0;
    let ko = vec![
        KeepOut { iq: 8, iv: 7, center: 0.0, width: l, height: 0.1 },
        KeepOut { iq: 9, iv: 8, center: 0.0, width: l, height: 0.1 },
    ];
    FloatingRobot::new(m, 0.05, n, running, terminal, ko).unwrap()
}

#[test]
fn cost_gradients_match_central_differences() {
    let mut rob = robot_with_all_costs(10);
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let (nx, ndx, nu) = (rob.nx(), rob.ndx(), rob.nu());
    for trial in 0..4 {
        let mut x = x0(rob.model());
        for i in 0..3 {
            x[i] = rng.gen_range(-0.5..0.5);
        }
        for i in 3..7 {
            x[i] = rng.gen_range(-1.0..1.0);
        }
        quat_normalize(&mut x[3..7]);
        for i in 7..nx {
            x[i] = rng.gen_range(-0.6..0.6);
        }
        if trial == 0 {
            x[8] = 0.4 * std::f64::consts::PI / 180.0; // inside the keep-out band
        }
        let u: Vec<f64> = (0..nu).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let mut d = NodeDiff::zeros(ndx, nu);
        let k = 3;
        rob.calc_diff(k, &x, &u, &mut d).unwrap();
        let mut xn = vec![0.0; nx];
        let mut cost_at = |rob: &mut FloatingRobot, xx: &[f64], uu: &[f64]| rob.calc(k, xx, uu, &mut xn).unwrap();
        let h = 1e-6;
        let mut xp = vec![0.0; nx];
        for i in 0..ndx {
            let mut t = vec![0.0; ndx];
            t[i] = h;
            rob.integrate(&x, &t, &mut xp);
            let cp = cost_at(&mut rob, &xp.clone(), &u);
            t[i] = -h;
            rob.integrate(&x, &t, &mut xp);
            let cm = cost_at(&mut rob, &xp.clone(), &u);
            let fd = (cp - cm) / (2.0 * h);
            assert!((fd - d.lx[i]).abs() < 1e-5 * (1.0 + fd.abs()), "trial {trial}, Lx[{i}]: fd {fd} vs {}", d.lx[i]);
        }
        for j in 0..nu {
            let mut up = u.clone();
            up[j] += h;
            let cp = cost_at(&mut rob, &x, &up);
            up[j] -= 2.0 * h;
            let cm = cost_at(&mut rob, &x, &up);
            let fd = (cp - cm) / (2.0 * h);
            assert!((fd - d.lu[j]).abs() < 1e-5 * (1.0 + fd.abs()), "Lu[{j}]: fd {fd} vs {}", d.lu[j]);
        }
        // Terminal gradient.
        let mut dt = NodeDiff::zeros(ndx, nu);
        rob.calc_diff_terminal(&x, &mut dt).unwrap();
        for i in 0..ndx {
            let mut t = vec![0.0; ndx];
            t[i] = h;
            rob.integrate(&x, &t, &mut xp);
            let cp = rob.calc_terminal(&xp.clone()).unwrap();
            t[i] = -h;
            rob.integrate(&x, &t, &mut xp);
            let cm = rob.calc_terminal(&xp.clone()).unwrap();
            let fd = (cp - cm) / (2.0 * h);
            assert!((fd - dt.lx[i]).abs() < 1e-5 * (1.0 + fd.abs()), "terminal Lx[{i}]: fd {fd} vs {}", dt.lx[i]);
        }
    }
}

#[test]
fn step_jacobians_are_consistent_and_euler_rates_of_a_rest_state_are_zero() {
    let mut rob = robot_with_all_costs(5);
    let x = x0(rob.model());
    let mut xn = vec![0.0; rob.nx()];
    // At rest with zero control in zero gravity nothing moves.
    rob.calc(0, &x, &[0.0; 12], &mut xn).unwrap();
    for i in 0..rob.nx() {
        assert!((xn[i] - x[i]).abs() < 1e-15, "entry {i}");
    }
    let mut d = NodeDiff::zeros(24, 12);
    rob.calc_diff(0, &x, &[0.0; 12], &mut d).unwrap();
    // δq⁺ = δq + Δt δv⁺ at rest: the q-q block is the identity, the q-v block Δt·I.
    for i in 0..12 {
        assert!((d.fx[(i, i)] - 1.0).abs() < 1e-8);
        assert!((d.fx[(i, 12 + i)] - 0.05).abs() < 1e-8);
    }
}

#[test]
fn bad_references_and_weights_name_the_argument() {
    let m = builtin::load("valverde_ch8_arm").unwrap();
    let (body, place) = m.frame_or_body("ee").unwrap();
    let t = CostTerm {
        name: "ee".into(),
        residual: Residual::FramePlacement { body, placement: place, refs: vec![Se3::identity(); 7] },
        weights: Weights::constant(vec![1.0; 6]).unwrap(),
    };
    let e = FloatingRobot::new(m.clone(), 0.05, 10, vec![t], vec![], vec![]).err().unwrap();
    assert!(e.to_string().contains("ee.reference"), "{e}");
    let t = CostTerm {
        name: "u".into(),
        residual: Residual::Control { refs: vec![vec![0.0; 12]] },
        weights: Weights::constant(vec![1.0; 5]).unwrap(),
    };
    let e = FloatingRobot::new(m.clone(), 0.05, 10, vec![t], vec![], vec![]).err().unwrap();
    assert!(e.to_string().contains("u.weights"), "{e}");
    let e = FloatingRobot::new(m.clone(), 0.0, 10, vec![], vec![], vec![]).err().unwrap();
    assert!(e.to_string().contains("dt"), "{e}");
    let e = FloatingRobot::new(m, 0.05, 0, vec![], vec![], vec![]).err().unwrap();
    assert!(e.to_string().contains("horizon"), "{e}");
}

#[test]
fn nearest_sign_dual_quaternion_cost_measures_the_pose_not_the_sheet() {
    // The reference is the end effector's own pose on the other sheet (−q_G, as the §8.7 reference is after its
    // 2π screw): the thesis' literal cost is 4 Σ w_i g_i², the nearest-sign cost is zero; a reference turned a
    // little off it gives a gradient that central differences confirm.
    let m = builtin::load("valverde_ch8_arm").unwrap();
    let (body, place) = m.frame_or_body("ee").unwrap();
    let mut x = x0(&m);
    x[11] = 0.3;
    let mut data = freefloat_core::Data::new(&m);
    freefloat_core::kinematics::forward_kinematics(&m, &mut data, &x[..m.nq]).unwrap();
    let o_mf = data.o_mi[body].compose(&place);
    let g =
        freefloat_core::control::ddp::costs::frame_dual_quat(&m, &x[..m.nq], body, &place, &o_mf).unwrap().to_array();
    let w: Vec<f64> = (0..8).map(|i| 1.0 + 0.25 * i as f64).collect();
    let robot = |refs: Vec<[f64; 8]>, nearest_sign: bool| {
        let term = CostTerm {
            name: "pose".into(),
            residual: Residual::FrameDualQuat { body, placement: place, refs, nearest_sign },
            weights: Weights::constant(w.clone()).unwrap(),
        };
        FloatingRobot::new(m.clone(), 0.05, 2, vec![], vec![term], vec![]).unwrap()
    };
    let minus_g: [f64; 8] = std::array::from_fn(|i| -g[i]);
    let literal = robot(vec![minus_g], false).calc_terminal(&x).unwrap();
    let expect: f64 = (0..8).map(|i| w[i] * 4.0 * g[i] * g[i]).sum();
    assert!((literal - expect).abs() < 1e-12 * expect, "literal {literal} vs {expect}");
    assert!(robot(vec![minus_g], true).calc_terminal(&x).unwrap() < 1e-28);
    // a nearby reference on the other sheet: 0.2 rad about z and 5 cm away
    let turn = DualQuat::new(Quat::from_axis_angle(&V3::z(), 0.2), Quat::new(0.0, 0.0, 0.0, 0.0));
    let shift = pose::from_rotation_translation(&Quat::new(1.0, 0.0, 0.0, 0.0), &V3::new(0.05, 0.0, 0.0));
    let gq = DualQuat::from_slice(&g);
    let near = shift.mul(&gq).mul(&turn).to_array();
    let near_minus: [f64; 8] = std::array::from_fn(|i| -near[i]);
    let (mut rn, mut rp) = (robot(vec![near_minus], true), robot(vec![near], false));
    assert!((rn.calc_terminal(&x).unwrap() - rp.calc_terminal(&x).unwrap()).abs() < 1e-12);
    let mut d = NodeDiff::zeros(rn.ndx(), rn.nu());
    rn.calc_diff_terminal(&x, &mut d).unwrap();
    let (h, mut xp) = (1e-6, vec![0.0; rn.nx()]);
    for i in 0..rn.ndx() {
        let mut t = vec![0.0; rn.ndx()];
        t[i] = h;
        rn.integrate(&x, &t, &mut xp);
        let cp = rn.calc_terminal(&xp.clone()).unwrap();
        t[i] = -h;
        rn.integrate(&x, &t, &mut xp);
        let cm = rn.calc_terminal(&xp.clone()).unwrap();
        let fd = (cp - cm) / (2.0 * h);
        assert!((fd - d.lx[i]).abs() < 1e-5 * (1.0 + fd.abs()), "Lx[{i}]: fd {fd} vs {}", d.lx[i]);
    }
}
