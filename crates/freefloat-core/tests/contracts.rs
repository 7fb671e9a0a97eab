//! The engine contract (check.rs): every public entry point, given a short, long or empty slice, a
//! non-finite entry, a non-unit quaternion or a `Data` of another model, returns `Err` — and never
//! panics. A panic is caught (`catch_unwind`) and reported as a failure naming the function and the
//! bad argument.

use freefloat_core::config::{dexpinv, retract, tangent_magnitude, tangent_rate};
use freefloat_core::dqdynamics::decoupled::decoupled_dynamics;
use freefloat_core::dqdynamics::{condition_number, dq_dynamics, dq_dynamics_with, dq_hybrid_dynamics, Solver};
use freefloat_core::dualquat::kinematics::{body_poses, joint_pose, ProductOfExponentials};
use freefloat_core::dynamics::{aba, crba, hybrid_aba, rnea, Prescribed};
use freefloat_core::estimation::{identify_momentum, MomentumProblem, Rls};
use freefloat_core::excitation::{base_twist_zero_momentum, excitation_rows, JointPath};
use freefloat_core::kinematics::{
    center_of_mass, centroidal_momentum_matrix, forward_accelerations, forward_kinematics, forward_velocities,
    frame_jacobian, frame_placement, generalized_jacobian, kinetic_energy, kinetic_energy_from_data, momentum,
    momentum_from_data, world_composite_inertias, world_motion_subspaces, Reference,
};
use freefloat_core::model::builtin;
use freefloat_core::regressors::{dynamics_regressor, momentum_regressor, momentum_regressor_from_data};
use freefloat_core::sim::{simulate, simulate_with, Formulation, Hold, Inputs, Method, SimOptions, TorqueSource};
use freefloat_core::spatial::{Se3, V3};
use freefloat_core::{Data, FfError, JointType, Model};
use nalgebra::DMatrix;
use std::panic::{catch_unwind, AssertUnwindSafe};

const MODEL: &str = "naveen_dual_arm_consistent";

/// Calls `f` and fails the test unless it returns `Err` (a panic is a failure, with its message).
fn must_err<T>(what: &str, failures: &mut Vec<String>, f: impl FnOnce() -> Result<T, FfError>) {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Err(_)) => {}
        Ok(Ok(_)) => failures.push(format!("{what}: returned Ok")),
        Err(p) => {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            failures.push(format!("{what}: PANICKED ({msg})"));
        }
    }
}

/// Calls `f` and fails unless it returns `Ok` (the good arguments must pass the check).
fn must_ok<T>(what: &str, failures: &mut Vec<String>, f: impl FnOnce() -> Result<T, FfError>) {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(_)) => {}
        Ok(Err(e)) => failures.push(format!("{what}: good input refused: {e}")),
        Err(_) => failures.push(format!("{what}: PANICKED on good input")),
    }
}

/// Bad versions of a good slice: short, long, empty, NaN, +inf.
fn bad(x: &[f64]) -> Vec<(&'static str, Vec<f64>)> {
    let mut out = vec![("long", [x, &[0.0]].concat()), ("empty", vec![])];
    if !x.is_empty() {
        out.push(("short", x[..x.len() - 1].to_vec()));
        let mut n = x.to_vec();
        n[x.len() / 2] = f64::NAN;
        out.push(("NaN", n));
        let mut i = x.to_vec();
        i[0] = f64::INFINITY;
        out.push(("inf", i));
    }
    out
}

/// Bad configurations: as `bad`, plus a quaternion of norm 2 (a layout mistake).
fn bad_q(m: &Model, q: &[f64]) -> Vec<(&'static str, Vec<f64>)> {
    let mut out = bad(q);
    if m.joint_types[0] == JointType::Free {
        let mut x = q.to_vec();
        for xk in &mut x[3..7] {
            *xk *= 2.0;
        }
        out.push(("quaternion norm 2", x));
    }
    out
}

fn bad_mask(n: usize) -> Vec<(&'static str, Vec<bool>)> {
    vec![("short", vec![false; n.saturating_sub(1)]), ("long", vec![false; n + 1]), ("empty", vec![])]
}

struct Good {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    fext: Vec<f64>,
}

fn good(m: &Model) -> Good {
    let mut q = m.neutral();
    for (k, x) in q.iter_mut().enumerate().skip(7) {
        *x = 0.1 * k as f64;
    }
    let s = 0.6f64.sin();
    q[3..7].copy_from_slice(&[s * 0.6, 0.0, s * 0.8, 0.6f64.cos()]);
    let v = (0..m.nv).map(|k| 0.05 * (k as f64 + 1.0).sin()).collect();
    let a = (0..m.nv).map(|k| 0.3 * (k as f64).cos()).collect();
    let fext = (0..6 * m.nbodies()).map(|k| 0.01 * k as f64).collect();
    Good { q, v, a, fext }
}

#[allow(clippy::too_many_arguments)] // a test helper: one argument per engine argument it varies
/// Every state-taking entry point, with the configuration, velocity, nv-vector and external forces
/// given (each may be bad), and the `Data` to use.
fn state_calls(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    fext: &[f64],
    tag: &str,
    bad_arg: Option<&str>,
    failures: &mut Vec<String>,
) {
    let nb = m.nbodies();
    let expect_err = bad_arg.is_some();
    // `uses`: the arguments a call takes besides the Data ("q", "v", "a"); a call that does not take the
    // bad argument is not run
    let run = |name: &str, uses: &str, failures: &mut Vec<String>, f: &mut dyn FnMut() -> Result<(), FfError>| {
        if let Some(b) = bad_arg {
            if b != "data" && !uses.split(',').any(|u| u == b) {
                return;
            }
        }
        let what = format!("{name} ({tag})");
        if expect_err {
            must_err(&what, failures, f);
        } else {
            must_ok(&what, failures, f);
        }
    };
    let fx = Some(fext);
    run("forward_kinematics", "q", failures, &mut || forward_kinematics(m, d, q));
    run("forward_velocities", "q,v", failures, &mut || forward_velocities(m, d, q, v));
    run("forward_accelerations", "q,v,a", failures, &mut || forward_accelerations(m, d, q, v, a));
    run("center_of_mass", "q", failures, &mut || center_of_mass(m, d, q).map(|_| ()));
    run("momentum", "q,v", failures, &mut || momentum(m, d, q, v).map(|_| ()));
    run("kinetic_energy", "q,v", failures, &mut || kinetic_energy(m, d, q, v).map(|_| ()));
    run("centroidal_momentum_matrix", "q", failures, &mut || centroidal_momentum_matrix(m, d, q));
    run("rnea", "q,v,a", failures, &mut || rnea(m, d, q, v, a, fx));
    run("crba", "q", failures, &mut || crba(m, d, q));
    run("aba", "q,v,a", failures, &mut || aba(m, d, q, v, a, fx));
    let mask: Vec<bool> = (0..nb).map(|i| i == 2).collect();
    let ddq = vec![0.0; m.nv];
    run("hybrid_aba", "q,v,a", failures, &mut || {
        hybrid_aba(m, d, q, v, a, fx, Some(Prescribed { mask: &mask, ddq: &ddq }))
    });
    run("hybrid_aba (ddq)", "q,v,a", failures, &mut || {
        hybrid_aba(m, d, q, v, &ddq, fx, Some(Prescribed { mask: &mask, ddq: a }))
    });
    let mut j = DMatrix::zeros(6, m.nv);
    run("frame_jacobian", "q", failures, &mut || {
        frame_jacobian(m, d, q, nb - 1, &Se3::identity(), Reference::World, &mut j)
    });
    run("generalized_jacobian", "q", failures, &mut || {
        generalized_jacobian(m, d, q, nb - 1, &Se3::identity(), Reference::World, &[0.0; 6]).map(|_| ())
    });
    let mut k = DMatrix::zeros(6, 10 * nb);
    run("momentum_regressor", "q,v", failures, &mut || momentum_regressor(m, d, q, v, &mut k));
    let mut y = DMatrix::zeros(m.nv, 10 * nb);
    run("dynamics_regressor", "q,v,a", failures, &mut || dynamics_regressor(m, d, q, v, a, &mut y));
    run("dq_dynamics", "q,v,a", failures, &mut || dq_dynamics(m, d, q, v, a, fx, None).map(|_| ()));
    run("dq_dynamics_with dense", "q,v,a", failures, &mut || {
        dq_dynamics_with(m, d, q, v, a, fx, None, Solver::Dense).map(|_| ())
    });
    let lock: Vec<bool> = (0..nb).map(|i| i == 3).collect();
    run("dq_dynamics locked", "q,v,a", failures, &mut || dq_dynamics(m, d, q, v, a, fx, Some(&lock)).map(|_| ()));
    run("dq_hybrid_dynamics", "q,v,a", failures, &mut || {
        dq_hybrid_dynamics(m, d, q, v, a, fx, &lock, &ddq).map(|_| ())
    });
    run("dq_hybrid_dynamics (ddq)", "q,v,a", failures, &mut || {
        dq_hybrid_dynamics(m, d, q, v, &ddq, fx, &lock, a).map(|_| ())
    });
    run("decoupled_dynamics", "q,v,a", failures, &mut || decoupled_dynamics(m, d, q, v, a, fx).map(|_| ()));
    let (mut qs, mut vs) = (q.to_vec(), v.to_vec());
    run("base_twist_zero_momentum", "q,v", failures, &mut || {
        base_twist_zero_momentum(m, d, &mut qs, &mut vs).map(|_| ())
    });
}

#[test]
fn every_entry_point_refuses_bad_slices_without_panicking() {
    let m = builtin::load(MODEL).expect("built-in");
    let g = good(&m);
    let mut d = Data::new(&m);
    let mut failures = vec![];
    let (q, v, a, f) = (&g.q, &g.v, &g.a, &g.fext);
    // the good arguments pass
    state_calls(&m, &mut d, q, v, a, f, "good", None, &mut failures);
    for (label, x) in bad_q(&m, q) {
        state_calls(&m, &mut d, &x, v, a, f, &format!("q {label}"), Some("q"), &mut failures);
    }
    for (label, x) in bad(v) {
        state_calls(&m, &mut d, q, &x, a, f, &format!("v {label}"), Some("v"), &mut failures);
    }
    for (label, x) in bad(a) {
        state_calls(&m, &mut d, q, v, &x, f, &format!("a/tau {label}"), Some("a"), &mut failures);
    }
    for (label, x) in bad(f) {
        // the calls without external forces cannot see a bad fext: check those taking it
        let fx = Some(&x[..]);
        let tag = format!("fext {label}");
        must_err(&format!("rnea ({tag})"), &mut failures, || rnea(&m, &mut d, q, v, a, fx));
        must_err(&format!("aba ({tag})"), &mut failures, || aba(&m, &mut d, q, v, a, fx));
        must_err(&format!("hybrid_aba ({tag})"), &mut failures, || hybrid_aba(&m, &mut d, q, v, a, fx, None));
        must_err(&format!("dq_dynamics ({tag})"), &mut failures, || {
            dq_dynamics(&m, &mut d, q, v, a, fx, None).map(|_| ())
        });
        must_err(&format!("decoupled_dynamics ({tag})"), &mut failures, || {
            decoupled_dynamics(&m, &mut d, q, v, a, fx).map(|_| ())
        });
    }
    for (label, x) in bad(a) {
        let tag = format!("a/tau {label}");
        must_err(&format!("forward_accelerations ({tag})"), &mut failures, || {
            forward_accelerations(&m, &mut d, q, v, &x)
        });
        must_err(&format!("rnea ({tag})"), &mut failures, || rnea(&m, &mut d, q, v, &x, None));
        must_err(&format!("aba ({tag})"), &mut failures, || aba(&m, &mut d, q, v, &x, None));
        let mut y = DMatrix::zeros(m.nv, 10 * m.nbodies());
        must_err(&format!("dynamics_regressor ({tag})"), &mut failures, || {
            dynamics_regressor(&m, &mut d, q, v, &x, &mut y)
        });
        must_err(&format!("dq_dynamics ({tag})"), &mut failures, || {
            dq_dynamics(&m, &mut d, q, v, &x, None, None).map(|_| ())
        });
        must_err(&format!("decoupled_dynamics ({tag})"), &mut failures, || {
            decoupled_dynamics(&m, &mut d, q, v, &x, None).map(|_| ())
        });
        let mask = vec![false; m.nbodies()];
        must_err(&format!("hybrid_aba ddq ({tag})"), &mut failures, || {
            hybrid_aba(&m, &mut d, q, v, a, None, Some(Prescribed { mask: &mask, ddq: &x }))
        });
        must_err(&format!("dq_hybrid_dynamics ddq ({tag})"), &mut failures, || {
            dq_hybrid_dynamics(&m, &mut d, q, v, a, None, &mask, &x).map(|_| ())
        });
    }
    for (label, mask) in bad_mask(m.nbodies()) {
        let tag = format!("mask {label}");
        let ddq = vec![0.0; m.nv];
        must_err(&format!("hybrid_aba ({tag})"), &mut failures, || {
            hybrid_aba(&m, &mut d, q, v, a, None, Some(Prescribed { mask: &mask, ddq: &ddq }))
        });
        must_err(&format!("dq_dynamics locked ({tag})"), &mut failures, || {
            dq_dynamics(&m, &mut d, q, v, a, None, Some(&mask)).map(|_| ())
        });
        must_err(&format!("dq_hybrid_dynamics ({tag})"), &mut failures, || {
            dq_hybrid_dynamics(&m, &mut d, q, v, a, None, &mask, &ddq).map(|_| ())
        });
    }
    assert!(failures.is_empty(), "{} contract failures:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn a_data_of_another_model_is_refused() {
    let m = builtin::load(MODEL).expect("built-in");
    let g = good(&m);
    let mut failures = vec![];
    // the same description built again is another model; so is a different robot
    let same_again = builtin::load(MODEL).expect("built-in");
    let other = builtin::load("valverde_ch5_single_arm").expect("built-in");
    for (tag, mut d) in [("same description, built again", Data::new(&same_again)), ("other robot", Data::new(&other))]
    {
        state_calls(&m, &mut d, &g.q, &g.v, &g.a, &g.fext, tag, Some("data"), &mut failures);
        must_err(&format!("momentum_from_data ({tag})"), &mut failures, || momentum_from_data(&m, &d));
        must_err(&format!("kinetic_energy_from_data ({tag})"), &mut failures, || kinetic_energy_from_data(&m, &d));
        must_err(&format!("world_composite_inertias ({tag})"), &mut failures, || world_composite_inertias(&m, &mut d));
        must_err(&format!("world_motion_subspaces ({tag})"), &mut failures, || world_motion_subspaces(&m, &mut d));
        must_err(&format!("frame_placement ({tag})"), &mut failures, || frame_placement(&m, &d, 0, &Se3::identity()));
        let mut k = DMatrix::zeros(6, 10 * m.nbodies());
        must_err(&format!("momentum_regressor_from_data ({tag})"), &mut failures, || {
            momentum_regressor_from_data(&m, &d, &mut k)
        });
    }
    // a clone and a re-parameterised model keep the layout identity: their Data is accepted
    let m2 = m.with_parameters(&m.parameters().concat()).expect("same parameters");
    let mut d2 = Data::new(&m2);
    must_ok("rnea with a Data of with_parameters' model", &mut failures, || rnea(&m, &mut d2, &g.q, &g.v, &g.a, None));
    let mut dc = Data::new(&m.clone());
    must_ok("rnea with a Data of a clone", &mut failures, || rnea(&m, &mut dc, &g.q, &g.v, &g.a, None));
    // a Data whose public buffer was resized is refused
    let mut dr = Data::new(&m);
    dr.ddq.pop();
    must_err("aba with a resized Data buffer", &mut failures, || aba(&m, &mut dr, &g.q, &g.v, &g.a, None));
    assert!(failures.is_empty(), "{} contract failures:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn other_entry_points_refuse_bad_slices_and_indices() {
    let m = builtin::load(MODEL).expect("built-in");
    let g = good(&m);
    let mut d = Data::new(&m);
    let mut failures = vec![];
    let (nq, nv, nb) = (m.nq, m.nv, m.nbodies());
    let mut out_nv = vec![0.0; nv];
    let mut out_nq = vec![0.0; nq];
    must_ok("tangent_rate", &mut failures, || tangent_rate(&m, &g.q, &g.v, &mut out_nv));
    must_ok("retract", &mut failures, || retract(&m, &g.q, &g.v, &mut out_nq));
    for (label, x) in bad(&g.q) {
        must_err(&format!("tangent_rate q {label}"), &mut failures, || tangent_rate(&m, &x, &g.v, &mut out_nv));
        must_err(&format!("retract q0 {label}"), &mut failures, || retract(&m, &x, &g.v, &mut out_nq));
        must_err(&format!("tangent_magnitude q {label}"), &mut failures, || tangent_magnitude(&m, &x, &mut out_nv));
        must_err(&format!("condition_number q {label}"), &mut failures, || condition_number(&m, &x));
        must_err(&format!("body_poses q {label}"), &mut failures, || body_poses(&m, &x));
        let poe = ProductOfExponentials::new(&m).expect("poe");
        must_err(&format!("ProductOfExponentials::body_poses q {label}"), &mut failures, || poe.body_poses(&m, &x));
        let opts = SimOptions { t_final: 0.01, dt: 1e-3, method: Method::Rk4, record_every: 1, max_steps: 100 };
        must_err(&format!("simulate q0 {label}"), &mut failures, || {
            simulate(&m, &x, &g.v, &opts, Inputs::default(), None)
        });
    }
    for (label, x) in bad(&g.v) {
        let mut k = x.clone();
        must_err(&format!("tangent_rate v {label}"), &mut failures, || tangent_rate(&m, &g.q, &x, &mut out_nv));
        must_err(&format!("retract delta {label}"), &mut failures, || retract(&m, &g.q, &x, &mut out_nq));
        must_err(&format!("dexpinv delta {label}"), &mut failures, || dexpinv(&m, &x, &mut out_nv));
        must_err(&format!("dexpinv k {label}"), &mut failures, || dexpinv(&m, &g.v, &mut k));
        let opts = SimOptions { t_final: 0.01, dt: 1e-3, method: Method::Rk4, record_every: 1, max_steps: 100 };
        must_err(&format!("simulate_with dq v0 {label}"), &mut failures, || {
            simulate_with(&m, &g.q, &x, &opts, Inputs::default(), Formulation::DualQuaternion, None)
        });
    }
    for (label, len) in [("short", nv - 1), ("long", nv + 1), ("empty", 0)] {
        let mut o = vec![0.0; len];
        let mut oq = vec![0.0; if len == 0 { 0 } else { len + 1 }]; // nq = nv + 1 for a free base
        must_err(&format!("tangent_rate out {label}"), &mut failures, || tangent_rate(&m, &g.q, &g.v, &mut o));
        must_err(&format!("tangent_magnitude out {label}"), &mut failures, || tangent_magnitude(&m, &g.q, &mut o));
        must_err(&format!("retract out {label}"), &mut failures, || retract(&m, &g.q, &g.v, &mut oq));
        let mut src = TorqueSource::table(vec![0.0, 1.0], vec![0.0; 2 * nv], nv, Hold::Linear).expect("table");
        must_err(&format!("TorqueSource::eval out {label}"), &mut failures, || src.eval(0.5, &g.q, &g.v, &mut o));
    }
    // output matrices of the wrong shape
    for (r, c) in [(5, 10 * nb), (6, 10 * nb + 1), (0, 0)] {
        let mut k = DMatrix::zeros(r, c);
        must_err(&format!("momentum_regressor out {r}x{c}"), &mut failures, || {
            momentum_regressor(&m, &mut d, &g.q, &g.v, &mut k)
        });
        must_err(&format!("momentum_regressor_from_data out {r}x{c}"), &mut failures, || {
            momentum_regressor_from_data(&m, &d, &mut k)
        });
        must_err(&format!("dynamics_regressor out {r}x{c}"), &mut failures, || {
            dynamics_regressor(&m, &mut d, &g.q, &g.v, &g.a, &mut k)
        });
        must_err(&format!("frame_jacobian out {r}x{c}"), &mut failures, || {
            frame_jacobian(&m, &mut d, &g.q, 1, &Se3::identity(), Reference::Local, &mut k)
        });
    }
    // body indices out of range, non-finite h0
    let mut j = DMatrix::zeros(6, nv);
    must_err("frame_jacobian body", &mut failures, || {
        frame_jacobian(&m, &mut d, &g.q, nb, &Se3::identity(), Reference::Local, &mut j)
    });
    must_err("generalized_jacobian body", &mut failures, || {
        generalized_jacobian(&m, &mut d, &g.q, nb, &Se3::identity(), Reference::Local, &[0.0; 6]).map(|_| ())
    });
    must_err("generalized_jacobian h0 NaN", &mut failures, || {
        generalized_jacobian(&m, &mut d, &g.q, 1, &Se3::identity(), Reference::Local, &[f64::NAN; 6]).map(|_| ())
    });
    must_err("frame_placement body", &mut failures, || frame_placement(&m, &d, nb, &Se3::identity()));
    // dual-quaternion joint poses and identification
    for len in [0usize, 1, 2, 5, 8] {
        must_err(&format!("joint_pose free with {len} coordinates"), &mut failures, || {
            joint_pose(JointType::Free, &V3::z(), &V3::x(), &vec![0.0; len])
        });
    }
    let t = 3;
    let (qs, vs, hs) = (g.q.repeat(t), g.v.repeat(t), vec![0.0; 6 * t]);
    let known = m.parameters().concat();
    let cols: Vec<usize> = (0..10).collect();
    for (label, x) in bad(&qs) {
        let p = MomentumProblem { q: &x, v: &vs, h: &hs, unknown_cols: &cols, known_params: &known, weights: None };
        must_err(&format!("identify_momentum q {label}"), &mut failures, || identify_momentum(&m, &p));
    }
    for (label, x) in bad(&hs) {
        let p = MomentumProblem { q: &qs, v: &vs, h: &x, unknown_cols: &cols, known_params: &known, weights: None };
        must_err(&format!("identify_momentum h {label}"), &mut failures, || identify_momentum(&m, &p));
    }
    for (label, x) in bad(&[0.0; 4]) {
        must_err(&format!("Rls::new theta0/p0 {label}"), &mut failures, || Rls::new(&[0.0; 4], &x, 0.99));
        let mut rls = Rls::new(&[0.0; 4], &[1.0; 4], 0.99).expect("rls");
        must_err(&format!("Rls::update phi {label}"), &mut failures, || rls.update(0.0, &x, &[1.0]));
    }
    // excitation: a joint path over the six arm joints
    let (iq, iv): (Vec<usize>, Vec<usize>) = (7..13).map(|k| (k, k - 1)).unzip();
    let samples = 4;
    let path_q = vec![0.1; 6 * samples];
    let path_qd = vec![0.01; 6 * samples];
    for (label, x) in bad(&path_qd) {
        let path = JointPath { step: 0.01, iq: &iq, iv: &iv, q: &path_q, qd: &x };
        must_err(&format!("excitation_rows qd {label}"), &mut failures, || {
            excitation_rows(&m, &g.q, &path, 1, 0, &[0, 1], 2, 1)
        });
    }
    for (label, x) in bad(&g.q) {
        let path = JointPath { step: 0.01, iq: &iq, iv: &iv, q: &path_q, qd: &path_qd };
        must_err(&format!("excitation_rows q0 {label}"), &mut failures, || {
            excitation_rows(&m, &x, &path, 1, 0, &[0, 1], 2, 1)
        });
    }
    assert!(failures.is_empty(), "{} contract failures:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn base_twist_base_poses_and_postcapture_rows_refuse_bad_input() {
    use freefloat_core::kinematics::{base_twist_for_momentum, base_velocity_coordinates};
    use freefloat_core::postcapture::equations::{
        com_form, paper_force_rows, paper_momentum_rows, project_consistent, standard_force_rows,
        standard_momentum_rows, Measurements,
    };
    use freefloat_core::postcapture::momentum_transport;
    use freefloat_core::sim::{integrate_base_poses, integrate_planar_base_poses, Steps};
    let m = builtin::load(MODEL).expect("built-in");
    let g = good(&m);
    let mut d = Data::new(&m);
    let mut failures = vec![];
    let rates = g.v[6..].to_vec();
    must_ok("base_twist_for_momentum", &mut failures, || base_twist_for_momentum(&m, &mut d, &g.q, &rates, &[0.0; 6]));
    for (label, x) in bad_q(&m, &g.q) {
        must_err(&format!("base_twist_for_momentum q {label}"), &mut failures, || {
            base_twist_for_momentum(&m, &mut d, &x, &rates, &[0.0; 6])
        });
    }
    for (label, x) in bad(&rates) {
        must_err(&format!("base_twist_for_momentum joint_rates {label}"), &mut failures, || {
            base_twist_for_momentum(&m, &mut d, &g.q, &x, &[0.0; 6])
        });
    }
    must_err("base_twist_for_momentum momentum NaN", &mut failures, || {
        base_twist_for_momentum(&m, &mut d, &g.q, &rates, &[f64::NAN; 6])
    });
    let mut other = Data::new(&builtin::load("valverde_ch5_single_arm").expect("built-in"));
    must_err("base_twist_for_momentum (Data of another model)", &mut failures, || {
        base_twist_for_momentum(&m, &mut other, &g.q, &rates, &[0.0; 6])
    });
    for len in [0usize, 5, 7] {
        let mut o = vec![0.0; len];
        must_err(&format!("base_velocity_coordinates out {len}"), &mut failures, || {
            base_velocity_coordinates(&m, &nalgebra::Vector6::zeros(), &mut o)
        });
    }
    // base poses: 3 samples of 6 (free) or 3 (planar) twist entries
    let pose0 = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    let tw = vec![0.1; 18];
    for (label, x) in bad(&tw) {
        let mut out = vec![0.0; 21];
        must_err(&format!("integrate_base_poses twists {label}"), &mut failures, || {
            integrate_base_poses(Steps::Uniform(0.01), &x, None, &pose0, &mut out)
        });
    }
    for (label, x) in bad(&pose0) {
        let mut out = vec![0.0; 21];
        must_err(&format!("integrate_base_poses pose0 {label}"), &mut failures, || {
            integrate_base_poses(Steps::Uniform(0.01), &tw, None, &x, &mut out)
        });
    }
    for len in [0usize, 20, 22] {
        let mut out = vec![0.0; len];
        must_err(&format!("integrate_base_poses out {len}"), &mut failures, || {
            integrate_base_poses(Steps::Uniform(0.01), &tw, None, &pose0, &mut out)
        });
        let mut out = vec![0.0; len];
        must_err(&format!("integrate_planar_base_poses out {len}"), &mut failures, || {
            integrate_planar_base_poses(Steps::Uniform(0.01), &tw[..9], None, &[0.0; 3], &mut out)
        });
    }
    for times in [&[0.0, 0.1][..], &[][..], &[0.0, 0.1, 0.2, 0.3][..]] {
        let mut out = vec![0.0; 21];
        must_err(&format!("integrate_base_poses {} times", times.len()), &mut failures, || {
            integrate_base_poses(Steps::Times(times), &tw, None, &pose0, &mut out)
        });
    }
    // post-capture rows on the Zhang, Yue, Yuan 2020 robot (base 0, target = last body)
    let mp = builtin::load("zhang2020_3d").expect("built-in");
    let (n, nv, nb) = (3usize, mp.nv, mp.nvs[0]);
    let target = mp.nbodies() - 1;
    let t: Vec<f64> = (0..n).map(|k| 0.01 * k as f64).collect();
    let q = mp.neutral().repeat(n);
    let (v, ddq, bw, imp) = (vec![0.0; n * nv], vec![0.0; n * nv], vec![0.0; n * nb], vec![0.0; n * 3]);
    for which in ["q", "v", "ddq", "base_wrench", "impulse_f"] {
        let base: &[f64] = match which {
            "q" => &q,
            "v" => &v,
            "ddq" => &ddq,
            "base_wrench" => &bw,
            _ => &imp,
        };
        for (label, x) in bad(base) {
            let pick = |name: &str, good: &[f64]| if name == which { x.clone() } else { good.to_vec() };
            let (qq, vv, aa, ww, ff) =
                (pick("q", &q), pick("v", &v), pick("ddq", &ddq), pick("base_wrench", &bw), pick("impulse_f", &imp));
            let meas = Measurements {
                t: &t,
                q: &qq,
                v: &vv,
                ddq: &aa,
                base_wrench: &ww,
                impulse_f: &ff,
                impulse_m: &imp,
                transport: None,
            };
            let tag = format!("{which} {label}");
            must_err(&format!("paper_momentum_rows ({tag})"), &mut failures, || {
                paper_momentum_rows(&mp, &meas, 0, target)
            });
            must_err(&format!("paper_force_rows ({tag})"), &mut failures, || paper_force_rows(&mp, &meas, 0, target));
            must_err(&format!("standard_momentum_rows ({tag})"), &mut failures, || {
                standard_momentum_rows(&mp, &meas, 0, target)
            });
            must_err(&format!("standard_force_rows ({tag})"), &mut failures, || {
                standard_force_rows(&mp, &meas, 0, target)
            });
        }
    }
    let meas = Measurements {
        t: &t,
        q: &q,
        v: &v,
        ddq: &ddq,
        base_wrench: &bw,
        impulse_f: &imp,
        impulse_m: &imp,
        transport: None,
    };
    // a transport term of the wrong length or with a NaN (the base-point momentum rows)
    let w = 30 * mp.nbodies();
    let mut nan_tr = vec![0.0; n * w];
    nan_tr[w + 7] = f64::NAN;
    for (label, tr) in [("short", vec![0.0; n * w - 1]), ("NaN", nan_tr)] {
        let m2 = Measurements { transport: Some(&tr), ..meas };
        must_err(&format!("standard_momentum_rows transport {label}"), &mut failures, || {
            standard_momentum_rows(&mp, &m2, 0, target)
        });
        must_err(&format!("paper_momentum_rows transport {label}"), &mut failures, || {
            paper_momentum_rows(&mp, &m2, 0, target)
        });
    }
    // the transport integral's own inputs: frames, times, output indices, the point's body
    let (tq, tv) = (mp.neutral().repeat(n), vec![0.0; n * nv]);
    let bad_t = [0.0, 0.01, 0.01];
    for (label, tt, at, point) in [
        ("times not increasing", &bad_t[..], vec![0usize, 2], 0usize),
        ("index past the frames", &t[..], vec![0, 3], 0),
        ("indices decreasing", &t[..], vec![2, 1], 0),
        ("point body out of range", &t[..], vec![0, 2], mp.nbodies()),
    ] {
        must_err(&format!("momentum_transport ({label})"), &mut failures, || {
            momentum_transport(&mp, tt, &tq, &tv, &at, point)
        });
    }
    must_err("momentum_transport (q short)", &mut failures, || momentum_transport(&mp, &t, &tq[1..], &tv, &[0], 0));
    for (b, tg) in [(0, 0), (0, mp.nbodies()), (mp.nbodies(), 1)] {
        must_err(&format!("paper_momentum_rows bodies {b}, {tg}"), &mut failures, || {
            paper_momentum_rows(&mp, &meas, b, tg)
        });
    }
    for len in [0usize, 9, 11] {
        let p = vec![1.0; len];
        must_err(&format!("com_form {len} parameters"), &mut failures, || com_form(&p));
        must_err(&format!("project_consistent {len} parameters"), &mut failures, || project_consistent(&p, 1e-9));
    }
    assert!(failures.is_empty(), "{} contract failures:\n{}", failures.len(), failures.join("\n"));
}
