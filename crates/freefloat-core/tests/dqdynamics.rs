//! The dual-quaternion Newton–Euler formulation (Valverde 2018, Ch. 6) against the engine's independent
//! recursive algorithms: accelerations = ABA, joint wrenches = RNEA's transmitted forces (run at the ABA
//! accelerations), locked joints = hybrid ABA, on random trees with every joint type the engine has.

// as in the crate: loops index several joint-aligned arrays at once
#![allow(clippy::needless_range_loop)]

mod common;

use common::{random_model, random_model_of, random_q, random_vec, rel_err, rng, KINDS};
use freefloat_core::data::Data;
use freefloat_core::dqdynamics::dq_dynamics;
use freefloat_core::dualquat::inertia::DualInertia;
use freefloat_core::dualquat::DualQuat;
use freefloat_core::dynamics::{aba, hybrid_aba, rnea, Prescribed};
use freefloat_core::model::{BodySpec, JointLimits, JointType, ModelBuilder};
use freefloat_core::spatial::{Inertia, Se3, M3, V3};
use freefloat_core::FfError;

fn flat(fs: &[freefloat_core::spatial::Force]) -> Vec<f64> {
    fs.iter().flat_map(|f| f.to_v6().iter().copied().collect::<Vec<_>>()).collect()
}

#[test]
fn matches_aba_and_rnea_on_random_trees() {
    let mut r = rng(2024);
    let mut worst_a: f64 = 0.0;
    let mut worst_w: f64 = 0.0;
    for base in [JointType::Free, JointType::FixedBase] {
        for case in 0..60 {
            let nb = 2 + case % 12;
            let m = random_model(&mut r, base, nb, case % 2 == 0);
            let q = random_q(&m, &mut r);
            let v = random_vec(m.nv, &mut r);
            let tau = random_vec(m.nv, &mut r);
            let fext = random_vec(6 * m.nbodies(), &mut r);
            let fx = if case % 3 == 0 { None } else { Some(&fext[..]) };
            let mut d = Data::new(&m);
            aba(&m, &mut d, &q, &v, &tau, fx).expect("aba");
            let a = d.ddq.clone();
            let res = dq_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, fx, None).cloned().expect("dq dynamics");
            let ea = rel_err(&res.ddq, &a);
            rnea(&m, &mut d, &q, &v, &a, fx).unwrap();
            let f_rnea = flat(&d.f);
            let ew = rel_err(&flat(&res.joint_wrenches), &f_rnea);
            worst_a = worst_a.max(ea);
            worst_w = worst_w.max(ew);
            assert!(ea < 1e-10, "{base:?} case {case}: accelerations differ by {ea:e}");
            assert!(ew < 1e-10, "{base:?} case {case}: joint wrenches differ by {ew:e}");
            // the reaction part does no work on admissible joint motion: it has no component along the
            // actuated directions, S_iᵀ f_reaction = 0
            for i in 1..m.nbodies() {
                let s = &d.s[i]; // the subspace at q (rnea ran forward kinematics)
                let fr = res.reactions[i].to_v6();
                for c in 0..m.nvs[i] {
                    assert!(s.column(c).dot(&fr).abs() < 1e-9 * (1.0 + fr.amax()));
                }
                // and the actuated part is tau
                let ft = res.joint_wrenches[i].to_v6();
                for c in 0..m.nvs[i] {
                    assert!((s.column(c).dot(&ft) - tau[m.idx_v[i] + c]).abs() < 1e-9 * (1.0 + ft.amax()));
                }
            }
        }
    }
    eprintln!("worst relative difference: accelerations {worst_a:e}, wrenches {worst_w:e}");
}

#[test]
fn locked_joints_match_hybrid_aba() {
    let mut r = rng(77);
    for case in 0..40 {
        let m = random_model(&mut r, if case % 2 == 0 { JointType::Free } else { JointType::FixedBase }, 7, true);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let tau = random_vec(m.nv, &mut r);
        let mask: Vec<bool> = (0..m.nbodies()).map(|i| i > 0 && (i + case) % 3 == 0).collect();
        let zero = vec![0.0; m.nv];
        let mut d = Data::new(&m);
        hybrid_aba(&m, &mut d, &q, &v, &tau, None, Some(Prescribed { mask: &mask, ddq: &zero })).expect("hybrid");
        let res = dq_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, None, Some(&mask)).cloned().expect("dq");
        assert!(rel_err(&res.ddq, &d.ddq) < 1e-10, "case {case}: {:e}", rel_err(&res.ddq, &d.ddq));
        for i in 0..m.nbodies() {
            if mask[i] {
                for c in 0..m.nvs[i] {
                    let k = m.idx_v[i] + c;
                    assert!((res.locked_forces[k] - d.tau[k]).abs() < 1e-9 * (1.0 + d.tau[k].abs()), "case {case}");
                    assert_eq!(res.ddq[k], 0.0);
                }
            }
        }
        // and the joint wrenches are RNEA's at those accelerations
        let a = d.ddq.clone();
        rnea(&m, &mut d, &q, &v, &a, None).unwrap();
        assert!(rel_err(&flat(&res.joint_wrenches), &flat(&d.f)) < 1e-10, "case {case}");
    }
}

#[test]
fn single_free_body_is_newton_euler() {
    // one body, no joint (B = 1, J = 0): reproduces (2.56) component-wise.
    let inr =
        Inertia::from_com(2.5, V3::new(0.1, -0.2, 0.3), M3::new(0.9, 0.1, -0.05, 0.1, 1.3, 0.02, -0.05, 0.02, 0.7));
    let m = ModelBuilder::new("one", "b", JointType::Free, inr).expect("base").build().expect("model");
    let q = [0.3, -0.1, 0.2, 0.1, 0.2, -0.3, (1.0f64 - 0.14).sqrt()];
    let v = [0.2, -0.4, 0.1, 0.5, -0.3, 0.8];
    let tau = [1.0, -2.0, 0.5, 0.3, 0.1, -0.2];
    let res = dq_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, None, None).cloned().expect("dq");
    // by hand: CoM twist and wrench, (2.56), then back to the body origin
    let c = inr.com();
    let (w, vb) = (V3::new(v[3], v[4], v[5]), V3::new(v[0], v[1], v[2]));
    let vo = vb + w.cross(&c);
    let (f, tb) = (V3::new(tau[0], tau[1], tau[2]), V3::new(tau[3], tau[4], tau[5]));
    let to = tb - c.cross(&f); // moment about the CoM
    let mi = DualInertia::from_inertia(&inr).expect("physical");
    let acc = mi.acceleration(&DualQuat::vector(&w, &vo), &DualQuat::vector(&f, &to));
    let wd = acc.r.v;
    let vbd = acc.d.v - wd.cross(&c);
    let expect = [vbd.x, vbd.y, vbd.z, wd.x, wd.y, wd.z];
    assert!(rel_err(&res.ddq, &expect) < 1e-13);
}

fn body(name: &str, parent: usize, kind: JointType, axis: V3, placement: Se3, inertia: Inertia) -> BodySpec {
    BodySpec {
        name: name.into(),
        parent,
        joint_name: format!("j_{name}"),
        joint_type: kind,
        axis,
        axis2: V3::z(),
        placement,
        inertia,
        limits: JointLimits::default(),
        tags: vec![],
        allow_nonphysical: false,
    }
}

#[test]
fn bad_input_is_reported() {
    let inr = Inertia::from_com(1.0, V3::new(0.1, 0.0, 0.0), M3::identity() * 0.2);
    let mut r = rng(5);
    let m = random_model(&mut r, JointType::Free, 4, false);
    let q = random_q(&m, &mut r);
    let v = random_vec(m.nv, &mut r);
    let tau = random_vec(m.nv, &mut r);
    assert!(matches!(
        dq_dynamics(&m, &mut Data::new(&m), &q[1..], &v, &tau, None, None),
        Err(FfError::Argument { .. })
    ));
    assert!(matches!(
        dq_dynamics(&m, &mut Data::new(&m), &q, &v[1..], &tau, None, None),
        Err(FfError::Argument { .. })
    ));
    let mut bad = tau.clone();
    bad[0] = f64::NAN;
    assert!(matches!(dq_dynamics(&m, &mut Data::new(&m), &q, &v, &bad, None, None), Err(FfError::Argument { .. })));
    let lock0 = vec![true; m.nbodies()];
    assert!(matches!(
        dq_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, None, Some(&lock0)),
        Err(FfError::Argument { .. })
    ));
    // planar base: not supported
    let mp = random_model(&mut r, JointType::Planar, 3, false);
    let qp = random_q(&mp, &mut r);
    let e = dq_dynamics(&mp, &mut Data::new(&mp), &qp, &vec![0.0; mp.nv], &vec![0.0; mp.nv], None, None).cloned();
    assert!(matches!(e, Err(FfError::Model(_))));
    // a massless intermediate body (allowed by the engine, which merges it into its child's subtree)
    let mut b = ModelBuilder::new("massless", "base", JointType::Free, inr).expect("base");
    b.add_body(body("a", 0, JointType::Revolute, V3::z(), Se3::identity(), Inertia::zero())).expect("a");
    b.add_body(body("b", 1, JointType::Revolute, V3::x(), Se3::new(M3::identity(), V3::x()), inr)).expect("b");
    if let Ok(m0) = b.build() {
        let e = dq_dynamics(&m0, &mut Data::new(&m0), &m0.neutral(), &vec![0.0; m0.nv], &vec![0.0; m0.nv], None, None)
            .cloned();
        match e {
            Err(FfError::Model(msg)) => assert!(msg.contains("'a'"), "{msg}"),
            other => panic!("expected a model error naming body a, got {other:?}"),
        }
    }
}

#[test]
fn tree_and_dense_schur_solves_agree() {
    // the tree-sparse elimination equals the dense solve of the assembled Delassus matrix.
    use freefloat_core::dqdynamics::{dq_dynamics_with, Solver};
    let mut r = rng(99);
    for case in 0..40 {
        let base = if case % 4 == 0 { JointType::FixedBase } else { JointType::Free };
        let m = random_model(&mut r, base, 3 + case % 15, true);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let tau = random_vec(m.nv, &mut r);
        let mask: Vec<bool> = (0..m.nbodies()).map(|i| i > 0 && (i + case) % 4 == 0).collect();
        let lk = if case % 2 == 0 { Some(&mask[..]) } else { None };
        let t = dq_dynamics_with(&m, &mut Data::new(&m), &q, &v, &tau, None, lk, Solver::Tree).cloned().expect("tree");
        let d =
            dq_dynamics_with(&m, &mut Data::new(&m), &q, &v, &tau, None, lk, Solver::Dense).cloned().expect("dense");
        assert!(rel_err(&t.ddq, &d.ddq) < 1e-12, "case {case}");
        assert!(rel_err(&flat(&t.joint_wrenches), &flat(&d.joint_wrenches)) < 1e-12, "case {case}");
    }
}

#[test]
fn closed_form_adjoints_equal_the_product_matrices() {
    use freefloat_core::dqdynamics::{ad_in, ad_out, reduce};
    use freefloat_core::dualquat::pose::from_rotation_translation;
    use freefloat_core::dualquat::Quat;
    use rand::Rng;
    let mut r = rng(8);
    for _ in 0..100 {
        let q =
            Quat::new(r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0));
        let t = V3::new(r.gen_range(-2.0..2.0), r.gen_range(-2.0..2.0), r.gen_range(-2.0..2.0));
        let p = from_rotation_translation(&q.scale(1.0 / q.norm()), &t);
        assert!((ad_in(&p) - reduce(&p.adjoint_in_matrix())).amax() < 1e-13);
        assert!((ad_out(&p) - reduce(&p.adjoint_out_matrix())).amax() < 1e-13);
    }
}

#[test]
fn decoupled_formulation_agrees_with_dq_and_aba() {
    // the chapter-5 decoupled formulation and the dual-quaternion one give the same
    // accelerations and joint wrenches; both equal the engine's ABA / RNEA.
    use freefloat_core::dqdynamics::decoupled::decoupled_dynamics;
    let mut r = rng(55);
    for case in 0..60 {
        let base = if case % 3 == 0 { JointType::FixedBase } else { JointType::Free };
        // the decoupled formulation has no universal joint (checked below)
        let m = random_model_of(&mut r, base, 2 + case % 10, case % 2 == 0, &KINDS[..4]);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let tau = random_vec(m.nv, &mut r);
        let fext = random_vec(6 * m.nbodies(), &mut r);
        let fx = if case % 4 == 1 { Some(&fext[..]) } else { None };
        let dec = decoupled_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, fx).cloned().expect("decoupled");
        let dq = dq_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, fx, None).cloned().expect("dq");
        let mut d = Data::new(&m);
        aba(&m, &mut d, &q, &v, &tau, fx).expect("aba");
        assert!(rel_err(&dec.ddq, &d.ddq) < 1e-10, "case {case}: {:e}", rel_err(&dec.ddq, &d.ddq));
        assert!(rel_err(&dec.ddq, &dq.ddq) < 1e-10, "case {case}");
        assert!(rel_err(&flat(&dec.joint_wrenches), &flat(&dq.joint_wrenches)) < 1e-10, "case {case}");
        assert!(rel_err(&flat(&dec.reactions), &flat(&dq.reactions)) < 1e-10, "case {case}");
    }
    // a universal joint is refused with a clear error
    let m = random_model_of(&mut r, JointType::Free, 1, false, &[JointType::Universal]);
    let err = decoupled_dynamics(&m, &mut Data::new(&m), &m.neutral(), &vec![0.0; m.nv], &vec![0.0; m.nv], None)
        .cloned()
        .expect_err("refused");
    assert!(err.to_string().contains("universal"), "{err}");
    // the chapter-5 robot
    let m = freefloat_core::model::builtin::load("valverde_ch5_single_arm").expect("built-in");
    let q = random_q(&m, &mut r);
    let v = random_vec(m.nv, &mut r);
    let tau = random_vec(m.nv, &mut r);
    let dec = decoupled_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, None).cloned().expect("decoupled");
    let dq = dq_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, None, None).cloned().expect("dq");
    assert!(rel_err(&dec.ddq, &dq.ddq) < 1e-12);
    assert!(rel_err(&flat(&dec.joint_wrenches), &flat(&dq.joint_wrenches)) < 1e-12);
}

#[test]
fn prescribed_accelerations_match_hybrid_aba() {
    use freefloat_core::dqdynamics::dq_hybrid_dynamics;
    let mut r = rng(31);
    for case in 0..30 {
        let m = random_model(&mut r, JointType::Free, 6, case % 2 == 0);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let tau = random_vec(m.nv, &mut r);
        let acc = random_vec(m.nv, &mut r);
        let mask: Vec<bool> = (0..m.nbodies()).map(|i| i > 0 && m.nvs[i] > 0 && (i + case) % 2 == 0).collect();
        let mut d = Data::new(&m);
        hybrid_aba(&m, &mut d, &q, &v, &tau, None, Some(Prescribed { mask: &mask, ddq: &acc })).expect("hybrid");
        let res = dq_hybrid_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, None, &mask, &acc).cloned().expect("dq");
        assert!(rel_err(&res.ddq, &d.ddq) < 1e-10, "case {case}: {:e}", rel_err(&res.ddq, &d.ddq));
        for i in 0..m.nbodies() {
            for c in 0..m.nvs[i] {
                let k = m.idx_v[i] + c;
                if mask[i] {
                    assert_eq!(res.ddq[k], acc[k]);
                    assert!((res.locked_forces[k] - d.tau[k]).abs() < 1e-9 * (1.0 + d.tau[k].abs()), "case {case}");
                }
            }
        }
    }
}

#[test]
fn dual_momentum_and_energy_match_engine() {
    // (2.53) and (2.54) against the momentum and kinetic energy ABA forms on the way
    let mut r = rng(12);
    for case in 0..30 {
        let m = random_model(&mut r, JointType::Free, 2 + case % 8, false);
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let tau = vec![0.0; m.nv];
        let mut d = Data::new(&m);
        aba(&m, &mut d, &q, &v, &tau, None).expect("aba");
        let res = dq_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, None, None).cloned().expect("dq");
        assert!(rel_err(res.momentum.to_v6().as_slice(), d.aba_momentum.to_v6().as_slice()) < 1e-12, "case {case}");
        assert!((res.kinetic_energy - d.aba_kinetic_energy).abs() < 1e-12 * d.aba_kinetic_energy, "case {case}");
    }
}

#[test]
fn simulation_with_the_dual_quaternion_formulation() {
    use freefloat_core::sim::{simulate_with, Formulation, Hold, Inputs, Method, SimOptions, TorqueSource};
    for name in ["valverde_ch5_single_arm", "valverde_ch7_two_arm"] {
        let m = freefloat_core::model::builtin::load(name).expect("built-in");
        let opts = SimOptions { t_final: 1.0, dt: 1e-3, method: Method::Rk4, record_every: 100, max_steps: 1_000_000 };
        let tau: Vec<f64> = (0..m.nv).map(|k| if k >= 6 { 0.3 * ((k % 3) as f64 - 1.0) } else { 0.0 }).collect();
        let mut r = rng(3);
        let v0 = random_vec(m.nv, &mut r);
        let run = |f: Formulation| {
            let values: Vec<f64> = tau.iter().chain(tau.iter()).copied().collect();
            let torques = TorqueSource::Table { times: vec![0.0, 2.0], values, hold: Hold::Zoh };
            let inputs = Inputs { torques, ..Default::default() };
            simulate_with(&m, &m.neutral(), &v0, &opts, inputs, f, None).expect("simulate")
        };
        let (a, b) = (run(Formulation::Aba), run(Formulation::DualQuaternion));
        assert!(rel_err(&b.q, &a.q) < 1e-12 && rel_err(&b.v, &a.v) < 1e-12, "{name}");
        assert!(rel_err(&b.momentum, &a.momentum) < 1e-10 && rel_err(&b.kinetic_energy, &a.kinetic_energy) < 1e-12);
        assert!(rel_err(&b.work, &a.work) < 1e-10, "{name}");
    }
}
