//! The regressors are exactly linear in the standard parameters: `K · vec(P)` is the momentum and
//! `Y · vec(P)` the RNEA forces, and neither matrix depends on `P`. Random trees with every joint
//! and base type, with and without gravity. (Pinocchio's regressor is compared in
//! tests/test_regressors.py.)

mod common;
use common::*;
use freefloat_core::dynamics::rnea;
use freefloat_core::kinematics::momentum;
use freefloat_core::regressors::{dynamics_regressor, momentum_regressor};
use freefloat_core::{Data, Model};
use nalgebra::{DMatrix, DVector};

fn flat_params(m: &Model) -> DVector<f64> {
    DVector::from_iterator(10 * m.nbodies(), m.parameters().into_iter().flatten())
}

/// The same tree with other random (physically consistent) parameters.
fn reparametrised(m: &Model, r: &mut rand::rngs::StdRng) -> Model {
    let p: Vec<f64> = (0..m.nbodies()).flat_map(|_| random_inertia(r).to_params()).collect();
    m.with_parameters(&p).unwrap()
}

#[test]
fn momentum_regressor_is_linear_in_the_parameters() {
    let mut r = rng(41);
    for trial in 0..60 {
        let m = random_model(&mut r, BASES[trial % 3], 1 + trial % 15, trial % 2 == 0);
        let m2 = reparametrised(&m, &mut r);
        let mut d = Data::new(&m);
        let mut k = DMatrix::zeros(6, 10 * m.nbodies());
        for _ in 0..3 {
            let q = random_q(&m, &mut r);
            let v = random_vec(m.nv, &mut r);
            momentum_regressor(&m, &mut d, &q, &v, &mut k).unwrap();
            for model in [&m, &m2] {
                let h = momentum(model, &mut d, &q, &v).unwrap().to_v6();
                let kp = &k * flat_params(model);
                assert!(rel_err(kp.as_slice(), h.as_slice()) < 1e-10, "trial {trial}: K P = {kp} vs {h}");
            }
        }
    }
}

#[test]
fn dynamics_regressor_is_linear_in_the_parameters() {
    let mut r = rng(42);
    for trial in 0..60 {
        let m = random_model(&mut r, BASES[trial % 3], 1 + trial % 15, trial % 2 == 0);
        let m2 = reparametrised(&m, &mut r);
        let mut d = Data::new(&m);
        let mut y = DMatrix::zeros(m.nv, 10 * m.nbodies());
        for _ in 0..3 {
            let q = random_q(&m, &mut r);
            let v = random_vec(m.nv, &mut r);
            let a = random_vec(m.nv, &mut r);
            dynamics_regressor(&m, &mut d, &q, &v, &a, &mut y).unwrap();
            for model in [&m, &m2] {
                rnea(model, &mut d, &q, &v, &a, None).unwrap();
                let yp = &y * flat_params(model);
                assert!(rel_err(yp.as_slice(), &d.tau) < 1e-10, "trial {trial}: Y P = {yp} vs {:?}", d.tau);
            }
        }
    }
}

/// At rest with zero acceleration only gravity loads the joints: with gravity off, Y vanishes; and
/// the momentum regressor of a zero velocity is zero.
#[test]
fn regressors_vanish_at_rest_without_gravity() {
    let mut r = rng(43);
    let m = random_model(&mut r, BASES[0], 8, false);
    let mut d = Data::new(&m);
    let q = random_q(&m, &mut r);
    let z = vec![0.0; m.nv];
    let mut y = DMatrix::from_element(m.nv, 10 * m.nbodies(), 1.0);
    dynamics_regressor(&m, &mut d, &q, &z, &z, &mut y).unwrap();
    assert_eq!(y.abs().max(), 0.0);
    let mut k = DMatrix::from_element(6, 10 * m.nbodies(), 1.0);
    momentum_regressor(&m, &mut d, &q, &z, &mut k).unwrap();
    assert_eq!(k.abs().max(), 0.0);
}
