//! Identities the recursive algorithms must satisfy with each other, on random trees with every
//! joint and base type. (The independent check against Pinocchio is in tests/test_pinocchio_oracle.py.)
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use freefloat_core::config::{retract, tangent_rate};
use freefloat_core::dynamics::{aba, crba, hybrid_aba, rnea, Prescribed};
use freefloat_core::kinematics::{
    centroidal_momentum_matrix, forward_kinematics, frame_jacobian, frame_placement, kinetic_energy, momentum,
    Reference,
};
use freefloat_core::Data;
use nalgebra::{DMatrix, DVector};

#[test]
fn aba_inverts_rnea_and_agrees_with_crba() {
    let mut r = rng(1);
    for trial in 0..60 {
        let base = BASES[trial % 3];
        let m = random_model(&mut r, base, 1 + trial % 15, trial % 2 == 0);
        let mut d = Data::new(&m);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let tau = random_vec(m.nv, &mut r);
        let fext = random_vec(6 * m.nbodies(), &mut r);
        aba(&m, &mut d, &q, &v, &tau, Some(&fext)).unwrap();
        let a = d.ddq.clone();
        rnea(&m, &mut d, &q, &v, &a, Some(&fext)).unwrap();
        assert!(rel_err(&d.tau, &tau) < 1e-10, "trial {trial}: rnea(aba).unwrap() = {:?} vs {:?}", d.tau, tau);
        // M a + h = tau with h = rnea(q, v, 0).unwrap()
        crba(&m, &mut d, &q).unwrap();
        let mm = d.mass_matrix.clone();
        assert!((&mm - mm.transpose()).abs().max() < 1e-12);
        assert!(mm.clone().cholesky().is_some(), "trial {trial}: mass matrix not positive definite");
        rnea(&m, &mut d, &q, &v, &vec![0.0; m.nv], Some(&fext)).unwrap();
        let lhs = &mm * DVector::from_vec(a.clone()) + DVector::from_vec(d.tau.clone());
        assert!(rel_err(lhs.as_slice(), &tau) < 1e-10, "trial {trial}: crba");
        // Kinetic energy = v' M v / 2, momentum = A v
        let ke = kinetic_energy(&m, &mut d, &q, &v).unwrap();
        let vv = DVector::from_vec(v.clone());
        assert!((ke - 0.5 * vv.dot(&(&mm * &vv))).abs() < 1e-10 * ke.max(1.0));
        let h = momentum(&m, &mut d, &q, &v).unwrap().to_v6();
        centroidal_momentum_matrix(&m, &mut d, &q).unwrap();
        let av = &d.jac * &vv;
        assert!(rel_err(av.as_slice(), h.as_slice()) < 1e-10, "trial {trial}: momentum matrix");
    }
}

/// The Jacobian must predict how the frame moves: compare with a central finite difference along
/// the flow q(ε) = q ⊕ ε·(tangent rate of v).
#[test]
fn jacobians_match_finite_differences() {
    let mut r = rng(2);
    for trial in 0..30 {
        let m = random_model(&mut r, BASES[trial % 3], 1 + trial % 10, false);
        let mut d = Data::new(&m);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let (body, pl) = m.frame_or_body("tool").unwrap();
        let mut j = DMatrix::zeros(6, m.nv);
        frame_jacobian(&m, &mut d, &q, body, &pl, Reference::World, &mut j).unwrap();
        let tw = &j * DVector::from_vec(v.clone());
        let mut rate = vec![0.0; m.nv];
        tangent_rate(&m, &q, &v, &mut rate).unwrap();
        let eps = 1e-6;
        let place = |s: f64, d: &mut Data| {
            let delta: Vec<f64> = rate.iter().map(|x| x * s).collect();
            let mut qe = vec![0.0; m.nq];
            retract(&m, &q, &delta, &mut qe).unwrap();
            forward_kinematics(&m, d, &qe).unwrap();
            frame_placement(&m, d, body, &pl).unwrap()
        };
        let (pp, pm) = (place(eps, &mut d), place(-eps, &mut d));
        let lin = (pp.trans - pm.trans) / (2.0 * eps);
        let dr = (pp.rot - pm.rot) / (2.0 * eps);
        let w = dr * place(0.0, &mut d).rot.transpose(); // [ω]× in world axes
        let ang = nalgebra::Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        assert!(
            (lin - tw.fixed_rows::<3>(0)).norm() < 1e-6,
            "trial {trial}: linear {lin:?} vs {:?}",
            tw.fixed_rows::<3>(0)
        );
        assert!((ang - tw.fixed_rows::<3>(3)).norm() < 1e-6, "trial {trial}: angular");
        // Local reference = the world one rotated into the frame.
        let mut jl = DMatrix::zeros(6, m.nv);
        frame_jacobian(&m, &mut d, &q, body, &pl, Reference::Local, &mut jl).unwrap();
        let rot = place(0.0, &mut d).rot;
        let twl = &jl * DVector::from_vec(v.clone());
        assert!((rot * twl.fixed_rows::<3>(0) - tw.fixed_rows::<3>(0)).norm() < 1e-10);
        assert!((rot * twl.fixed_rows::<3>(3) - tw.fixed_rows::<3>(3)).norm() < 1e-10);
    }
}

/// Hybrid dynamics against the partitioned mass-matrix solution:
/// M_ff a_f = tau_f − h_f − M_fp a_p and tau_p = M_pf a_f + M_pp a_p + h_p.
#[test]
fn hybrid_dynamics_matches_partitioned_crba() {
    let mut r = rng(3);
    for trial in 0..40 {
        let m = random_model(&mut r, BASES[trial % 3], 2 + trial % 12, trial % 3 == 0);
        let mut d = Data::new(&m);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let tau = random_vec(m.nv, &mut r);
        let ap_given = random_vec(m.nv, &mut r);
        let mask: Vec<bool> = (0..m.nbodies()).map(|i| m.nvs[i] > 0 && (i + trial) % 2 == 0).collect();
        let idx: Vec<bool> = (0..m.nv)
            .map(|k| (0..m.nbodies()).any(|i| mask[i] && k >= m.idx_v[i] && k < m.idx_v[i] + m.nvs[i]))
            .collect();
        hybrid_aba(&m, &mut d, &q, &v, &tau, None, Some(Prescribed { mask: &mask, ddq: &ap_given })).unwrap();
        let (a_h, tau_h) = (d.ddq.clone(), d.tau.clone());
        crba(&m, &mut d, &q).unwrap();
        let mm = d.mass_matrix.clone();
        rnea(&m, &mut d, &q, &v, &vec![0.0; m.nv], None).unwrap();
        let h = d.tau.clone();
        let f: Vec<usize> = (0..m.nv).filter(|&k| !idx[k]).collect();
        let p: Vec<usize> = (0..m.nv).filter(|&k| idx[k]).collect();
        let mut a = ap_given.clone();
        if !f.is_empty() {
            let mff = DMatrix::from_fn(f.len(), f.len(), |i, j| mm[(f[i], f[j])]);
            let rhs = DVector::from_fn(f.len(), |i, _| {
                tau[f[i]] - h[f[i]] - p.iter().map(|&k| mm[(f[i], k)] * ap_given[k]).sum::<f64>()
            });
            let af = mff.cholesky().unwrap().solve(&rhs);
            for (i, &k) in f.iter().enumerate() {
                a[k] = af[i];
            }
        }
        let full = &mm * DVector::from_vec(a.clone()) + DVector::from_vec(h.clone());
        assert!(rel_err(&a_h, &a) < 1e-10, "trial {trial}: accelerations");
        for &k in &p {
            assert!((tau_h[k] - full[k]).abs() < 1e-9 * full.norm().max(1.0), "trial {trial}: prescribed torque {k}");
        }
        for &k in &f {
            assert_eq!(tau_h[k], tau[k]);
        }
    }
}

/// The planar base reproduces the in-plane motion of the same robot on a free base, when all
/// joints move in the plane.
#[test]
fn planar_base_matches_free_base_in_plane() {
    use freefloat_core::model::yaml::from_yaml_str;
    let body = |base: &str| {
        format!(
            "name: planar_test\nbase: {base}\nbodies:\n  - name: base\n    inertial: {{mass: 50, com: [0.1, -0.1, 0], inertia: [4, 5, 8]}}\n  - name: l1\n    parent: base\n    joint: {{type: revolute, axis: [0, 0, 1]}}\n    origin: {{xyz: [0.5, 0, 0]}}\n    inertial: {{mass: 5, com: [0.5, 0.05, 0], inertia: [0.1, 0.4, 0.45]}}\n  - name: l2\n    parent: l1\n    joint: {{type: revolute, axis: [0, 0, 1]}}\n    origin: {{xyz: [1, 0, 0]}}\n    inertial: {{mass: 3, com: [0.4, 0, 0], inertia: [0.05, 0.3, 0.33]}}\n"
        )
    };
    let mp = from_yaml_str(&body("planar"), "planar").unwrap();
    let mf = from_yaml_str(&body("free"), "free").unwrap();
    let (mut dp, mut df) = (Data::new(&mp), Data::new(&mf));
    let yaw: f64 = 0.7;
    let qp = [0.3, -0.2, yaw, 0.4, -0.9];
    let qf = [0.3, -0.2, 0.0, 0.0, 0.0, (yaw / 2.0).sin(), (yaw / 2.0).cos(), 0.4, -0.9];
    let vp = [0.1, 0.2, 0.3, -0.4, 0.5];
    let vf = [0.1, 0.2, 0.0, 0.0, 0.0, 0.3, -0.4, 0.5];
    let taup = [1.0, -2.0, 0.5, 0.3, -0.2];
    let tauf = [1.0, -2.0, 0.0, 0.0, 0.0, 0.5, 0.3, -0.2];
    aba(&mp, &mut dp, &qp, &vp, &taup, None).unwrap();
    aba(&mf, &mut df, &qf, &vf, &tauf, None).unwrap();
    let inplane = [df.ddq[0], df.ddq[1], df.ddq[5], df.ddq[6], df.ddq[7]];
    assert!(rel_err(&dp.ddq, &inplane) < 1e-12, "{:?} vs {:?}", dp.ddq, inplane);
    assert!(df.ddq[2].abs() < 1e-12 && df.ddq[3].abs() < 1e-12 && df.ddq[4].abs() < 1e-12);
}

/// Body accelerations from `forward_accelerations` are the time derivatives of the body twists
/// (body coordinates), checked by central differences along `q(t) = q + v t + a t²/2`, `v(t) = v + a t`.
/// This is what catches a missing or wrong joint bias `Ṡ q̇` (universal joints), which ABA, RNEA and
/// CRBA would otherwise share consistently.
#[test]
fn body_accelerations_are_twist_derivatives() {
    use freefloat_core::kinematics::{forward_accelerations, forward_velocities};
    use freefloat_core::model::JointType;
    let mut r = rng(77);
    let kinds = [JointType::Universal, JointType::Cylindrical, JointType::Revolute, JointType::Prismatic];
    for trial in 0..20 {
        // fixed base and scalar-coordinate joints: q is a vector space, so q(t) is exact
        let m = random_model_of(&mut r, JointType::FixedBase, 2 + trial % 6, false, &kinds);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let a = random_vec(m.nv, &mut r);
        let mut d = Data::new(&m);
        forward_accelerations(&m, &mut d, &q, &v, &a).unwrap();
        let acc = d.a.clone();
        let h = 1e-5;
        let twists = |t: f64, d: &mut Data| {
            let qt: Vec<f64> = (0..m.nq).map(|k| q[k] + v[k] * t + 0.5 * a[k] * t * t).collect();
            let vt: Vec<f64> = (0..m.nv).map(|k| v[k] + a[k] * t).collect();
            forward_velocities(&m, d, &qt, &vt).unwrap();
            d.v.clone()
        };
        let (vp, vm) = (twists(h, &mut d), twists(-h, &mut d));
        for i in 0..m.nbodies() {
            let fd = (vp[i].to_v6() - vm[i].to_v6()) / (2.0 * h);
            let err = (fd - acc[i].to_v6()).amax();
            assert!(err < 1e-6 * (1.0 + acc[i].to_v6().amax()), "trial {trial}, body {i}: {err:e}");
        }
    }
}
