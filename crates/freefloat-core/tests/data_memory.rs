//! Data's memory is linear in the number of bodies: a 50,000-link chain loads and runs ABA and RNEA without the
//! nv × nv mass matrix (20 GB at this size), which exists only once CRBA (or what needs it) asks for it.

use freefloat_core::dynamics::{aba, crba, rnea};
use freefloat_core::model::{builtin, BodySpec, JointLimits, ModelBuilder};
use freefloat_core::spatial::{Inertia, Se3, M3, V3};
use freefloat_core::{Data, JointType};

fn chain(n: usize) -> freefloat_core::Model {
    let rod = Inertia::from_com(1.0, V3::new(0.05, 0.0, 0.0), M3::from_diagonal(&V3::new(1e-3, 2e-3, 2e-3)));
    let mut b = ModelBuilder::new(
        "chain",
        "base",
        JointType::Free,
        Inertia::from_com(100.0, V3::zeros(), M3::identity() * 10.0),
    )
    .expect("builder");
    for i in 1..=n {
        b.add_body(BodySpec {
            name: format!("l{i}"),
            parent: i - 1,
            joint_name: format!("j{i}"),
            joint_type: JointType::Revolute,
            axis: if i % 2 == 0 { V3::z() } else { V3::y() },
            axis2: V3::z(),
            placement: Se3::new(M3::identity(), V3::new(0.1, 0.0, 0.0)),
            inertia: rod,
            limits: JointLimits::default(),
            tags: vec![],
            allow_nonphysical: false,
        })
        .expect("body");
    }
    b.build().expect("model")
}

#[test]
fn fifty_thousand_links_run_aba_without_the_mass_matrix() {
    let m = chain(50_000);
    let mut d = Data::try_new(&m).expect("Data for 50,000 bodies");
    assert_eq!(d.mass_matrix.shape(), (0, 0), "the nv x nv matrix must not exist before CRBA");
    let q = m.neutral();
    let v = vec![1e-3; m.nv];
    let tau = vec![0.0; m.nv];
    aba(&m, &mut d, &q, &v, &tau, None).expect("aba");
    assert!(d.ddq.iter().all(|x| x.is_finite()));
    let ddq = d.ddq.clone();
    // scale of the joint forces in this state: the velocity-product forces (RNEA at zero acceleration)
    rnea(&m, &mut d, &q, &v, &vec![0.0; m.nv], None).expect("rnea");
    let scale = d.tau.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    rnea(&m, &mut d, &q, &v, &ddq, None).expect("rnea");
    // RNEA of ABA's accelerations gives back the torques (zero): the long chain is solved, not just run
    let worst = d.tau.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(scale > 0.0 && worst < 1e-9 * scale, "rnea(aba(tau)) - tau = {worst} (force scale {scale})");
    assert_eq!(d.mass_matrix.shape(), (0, 0), "ABA and RNEA must not allocate the mass matrix");
}

#[test]
fn crba_allocates_the_mass_matrix_on_first_use() {
    let m = builtin::load("naveen_dual_arm_consistent").expect("built-in");
    let mut d = Data::new(&m);
    assert_eq!(d.mass_matrix.shape(), (0, 0));
    assert!(d.sized_for(&m));
    crba(&m, &mut d, &m.neutral()).expect("crba");
    assert_eq!(d.mass_matrix.shape(), (m.nv, m.nv));
    assert!(d.sized_for(&m));
    // symmetric positive definite: its Cholesky factorisation exists
    assert!(d.mass_matrix.clone().cholesky().is_some());
}
