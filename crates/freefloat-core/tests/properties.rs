//! Property tests (proptest): identities that must hold for every input, on inputs proptest draws and, when one
//! fails, shrinks to a small failing case. The same identities are checked from Python with hypothesis
//! (tests/test_properties.py); here they run on the engine directly.
//!
//! - spatial algebra: Se3 composition is associative, X⁻¹X = 1, the motion/force actions are dual
//!   (⟨X·v, X*·f⟩ = ⟨v, f⟩), the spatial cross product is a derivation of the pairing (⟨v×m, f⟩ = −⟨m, v×*f⟩),
//!   exp6(log6(X)) = X;
//! - dual-quaternion algebra: (ab)c = a(bc), (ab)* = b*a*, unit poses compose to unit poses, exp(log q) = ±q,
//!   and a pose dual quaternion transforms points as its Se3 does;
//! - dynamics on random trees (every joint type, free/planar/fixed base): ABA(q, v, RNEA(q, v, a)) = a,
//!   momentum = CMM(q)·v, momentum regressor·φ = momentum (φ the model's own parameters), CRBA symmetric
//!   positive definite with ½vᵀMv = kinetic energy.
//!
//! A random tree is drawn from a proptest-chosen seed and size through tests/common.rs, so a failure shrinks to
//! the smallest tree (and the seed that builds it).

mod common;
use common::*;
use freefloat_core::dualquat::pose::from_rotation_translation;
use freefloat_core::dualquat::{exp, log, DualQuat, Quat};
use freefloat_core::dynamics::{aba, crba, rnea};
use freefloat_core::kinematics::{centroidal_momentum_matrix, kinetic_energy, momentum};
use freefloat_core::regressors::momentum_regressor;
use freefloat_core::spatial::lie::{exp6, log6};
use freefloat_core::spatial::{rpy_to_rot, Force, Motion, Se3, V3};
use freefloat_core::Data;
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

fn v3() -> impl Strategy<Value = V3> {
    prop::array::uniform3(-10.0f64..10.0).prop_map(V3::from)
}

fn se3() -> impl Strategy<Value = Se3> {
    (prop::array::uniform3(-3.0f64..3.0), v3()).prop_map(|(rpy, t)| Se3::new(rpy_to_rot(&V3::from(rpy)), t))
}

fn motion() -> impl Strategy<Value = Motion> {
    (v3(), v3()).prop_map(|(l, a)| Motion::new(l, a))
}

fn force() -> impl Strategy<Value = Force> {
    (v3(), v3()).prop_map(|(l, a)| Force::new(l, a))
}

fn quat() -> impl Strategy<Value = Quat> {
    prop::array::uniform4(-10.0f64..10.0).prop_map(|q| Quat::new(q[0], q[1], q[2], q[3]))
}

fn dq() -> impl Strategy<Value = DualQuat> {
    (quat(), quat()).prop_map(|(r, d)| DualQuat::new(r, d))
}

/// A unit pose: rotation from a quaternion kept away from zero (normalised), translation in [−10, 10]³.
fn pose() -> impl Strategy<Value = DualQuat> {
    (prop::array::uniform4(-1.0f64..1.0), v3()).prop_filter_map("quaternion too small to normalise", |(q, t)| {
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        (n > 0.1).then(|| from_rotation_translation(&Quat::new(q[0] / n, q[1] / n, q[2] / n, q[3] / n), &t))
    })
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    let scale = 1.0 + b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol * scale)
}

fn dq8(q: &DualQuat) -> Vec<f64> {
    q.to_array().to_vec()
}

fn se3_12(x: &Se3) -> Vec<f64> {
    x.rot.iter().chain(x.trans.iter()).copied().collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    // ---- spatial algebra ---------------------------------------------------------------------------------
    #[test]
    fn se3_composition_is_associative_and_inverts(a in se3(), b in se3(), c in se3()) {
        let l = a.compose(&b).compose(&c);
        let r = a.compose(&b.compose(&c));
        prop_assert!(close(&se3_12(&l), &se3_12(&r), 1e-12));
        let id = a.inverse().compose(&a);
        prop_assert!(close(&se3_12(&id), &se3_12(&Se3::identity()), 1e-12));
    }

    #[test]
    fn motion_and_force_actions_are_dual(x in se3(), v in motion(), f in force()) {
        // ⟨X v, X* f⟩ = ⟨v, f⟩: power does not depend on the frame it is computed in
        let lhs = x.act_motion(&v).dot(&x.act_force(&f));
        let rhs = v.dot(&f);
        prop_assert!((lhs - rhs).abs() <= 1e-10 * (1.0 + rhs.abs() + v.to_v6().norm() * f.to_v6().norm()));
        let back = x.inv_act_motion(&x.act_motion(&v));
        prop_assert!(close(back.to_v6().as_slice(), v.to_v6().as_slice(), 1e-12));
    }

    #[test]
    fn spatial_cross_products_are_dual(v in motion(), m in motion(), f in force()) {
        // ⟨v × m, f⟩ = −⟨m, v ×* f⟩ (Featherstone 2008, eq. 2.22: ×* = −×ᵀ)
        let lhs = v.cross_motion(&m).dot(&f);
        let rhs = -m.dot(&v.cross_force(&f));
        let scale = v.to_v6().norm() * m.to_v6().norm() * f.to_v6().norm();
        prop_assert!((lhs - rhs).abs() <= 1e-12 * (1.0 + scale));
    }

    #[test]
    fn exp6_inverts_log6(
        // rotations up to ~1.7 rad: log is ill-conditioned near π, where the axis is lost
        x in (prop::array::uniform3(-1.0f64..1.0), v3()).prop_map(|(rpy, t)| Se3::new(rpy_to_rot(&V3::from(rpy)), t))
    ) {
        let y = exp6(&log6(&x));
        prop_assert!(close(&se3_12(&y), &se3_12(&x), 1e-9));
    }

    // ---- dual-quaternion algebra ----------------------------------------------------------------------------
    #[test]
    fn dual_quaternion_product_is_associative_and_conjugation_reverses(a in dq(), b in dq(), c in dq()) {
        prop_assert!(close(&dq8(&a.mul(&b).mul(&c)), &dq8(&a.mul(&b.mul(&c))), 1e-12));
        prop_assert!(close(&dq8(&a.mul(&b).conj()), &dq8(&b.conj().mul(&a.conj())), 1e-12));
        prop_assert!(close(&dq8(&a.swap().swap()), &dq8(&a), 0.0));
    }

    #[test]
    fn unit_poses_compose_to_unit_poses_and_exp_inverts_log(a in pose(), b in pose()) {
        let c = a.mul(&b);
        prop_assert!(c.unit_defect() < 1e-12, "defect {}", c.unit_defect());
        let e = exp(&log(&c).unwrap());
        let (x, y) = (dq8(&e), dq8(&c));
        let minus: Vec<f64> = y.iter().map(|v| -v).collect();
        prop_assert!(close(&x, &y, 1e-9) || close(&x, &minus, 1e-9), "exp(log q) = {x:?}, q = {y:?}");
    }

    #[test]
    fn pose_dual_quaternion_moves_points_as_its_se3(a in pose(), p in v3()) {
        // q (1 + ε p) q̄ carries the point p as the homogeneous transform does
        let x = a.to_se3();
        // the full conjugate r* − ε d* (quaternion and dual conjugation together)
        let c = a.conj();
        let full = DualQuat::new(c.r, -c.d);
        let moved = a.mul(&DualQuat::new(Quat::ONE, Quat::pure(&p))).mul(&full);
        let expected = x.act_point(&p);
        prop_assert!(close(moved.d.v.as_slice(), expected.as_slice(), 1e-10));
    }

    // ---- dynamics identities on random trees ---------------------------------------------------------------
    #[test]
    fn aba_inverts_rnea(seed in 0u64..1_000_000, n in 1usize..12, base in 0usize..3, gravity: bool) {
        let mut r = rng(seed);
        let m = random_model(&mut r, BASES[base], n, gravity);
        let mut d = Data::new(&m);
        let (q, v, a) = (random_q(&m, &mut r), random_vec(m.nv, &mut r), random_vec(m.nv, &mut r));
        rnea(&m, &mut d, &q, &v, &a, None).unwrap();
        let tau = d.tau.clone();
        aba(&m, &mut d, &q, &v, &tau, None).unwrap();
        prop_assert!(rel_err(&d.ddq, &a) < 1e-9, "ABA(RNEA(a)) = {:?}, a = {:?}", d.ddq, a);
    }

    #[test]
    fn momentum_is_cmm_times_v_and_regressor_times_parameters(
        seed in 0u64..1_000_000, n in 1usize..12, base in 0usize..3
    ) {
        let mut r = rng(seed);
        let m = random_model(&mut r, BASES[base], n, false);
        let mut d = Data::new(&m);
        let (q, v) = (random_q(&m, &mut r), random_vec(m.nv, &mut r));
        let h = momentum(&m, &mut d, &q, &v).unwrap().to_v6();
        centroidal_momentum_matrix(&m, &mut d, &q).unwrap();
        let av = &d.jac * DVector::from_vec(v.clone());
        prop_assert!(rel_err(av.as_slice(), h.as_slice()) < 1e-10, "CMM v = {av} vs h = {h}");
        let mut k = DMatrix::zeros(6, 10 * m.nbodies());
        momentum_regressor(&m, &mut d, &q, &v, &mut k).unwrap();
        let phi = DVector::from_iterator(10 * m.nbodies(), m.parameters().into_iter().flatten());
        let kphi = &k * phi;
        prop_assert!(rel_err(kphi.as_slice(), h.as_slice()) < 1e-10, "K phi = {kphi} vs h = {h}");
    }

    #[test]
    fn crba_is_symmetric_positive_definite_and_gives_the_kinetic_energy(
        seed in 0u64..1_000_000, n in 1usize..12, base in 0usize..3
    ) {
        let mut r = rng(seed);
        let m = random_model(&mut r, BASES[base], n, false);
        let mut d = Data::new(&m);
        let (q, v) = (random_q(&m, &mut r), random_vec(m.nv, &mut r));
        crba(&m, &mut d, &q).unwrap();
        let mm = d.mass_matrix.clone();
        prop_assert!((&mm - mm.transpose()).abs().max() < 1e-12);
        prop_assert!(mm.clone().cholesky().is_some(), "mass matrix not positive definite");
        let vv = DVector::from_vec(v.clone());
        let ke = kinetic_energy(&m, &mut d, &q, &v).unwrap();
        prop_assert!((ke - 0.5 * vv.dot(&(&mm * &vv))).abs() < 1e-10 * ke.max(1.0));
    }
}
