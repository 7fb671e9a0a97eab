//! Dynamics derivatives against central finite differences on random trees (every joint type but
//! universal, free / planar / fixed base, with and without gravity and external forces): ∂τ/∂(q, v),
//! ∂a/∂(q, v, τ), the Jacobians of ⊕ and ⊖, one-step derivatives (semi-implicit Euler, RK4) in the
//! tangent error state, and the frame-pose derivatives (SE(3) log error, dual quaternion).
//! Finite differences move q along the local tangent with `integrate`, so they test that convention
//! too (and `integrate` itself is tested against the velocity it integrates).

mod common;

use common::{random_model_of, random_q, random_vec, rng, BASES};
use freefloat_core::dynamics::derivatives::{
    aba_derivatives, difference, difference_jacobians, frame_dq_pose_derivatives, frame_log_error_derivatives,
    integrate, integrate_jacobians, rnea_derivatives, se3_log, se3_log_jacobian, step, step_derivatives, Derivatives,
    Scheme,
};
use freefloat_core::dynamics::{aba, crba, rnea};
use freefloat_core::kinematics::{forward_kinematics, forward_velocities};
use freefloat_core::model::{JointType, Model};
use freefloat_core::spatial::{rpy_to_rot, Se3, V3};
use freefloat_core::Data;
use nalgebra::DMatrix;

const KINDS: [JointType; 5] =
    [JointType::Revolute, JointType::Prismatic, JointType::Spherical, JointType::Cylindrical, JointType::Fixed];
const EPS: f64 = 1e-6;

fn models() -> Vec<Model> {
    let mut r = rng(11);
    let mut out = vec![];
    for base in BASES {
        // 12 bodies: branches several joints deep, whose cross-branch entries the single pass leaves zero
        for (n, g) in [(4, false), (7, true), (12, true)] {
            out.push(random_model_of(&mut r, base, n, g, &KINDS));
        }
    }
    out
}

/// Max |a − b| / max(1, max |b|) over all entries.
fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    let scale = b.iter().fold(1.0f64, |s, x| s.max(x.abs()));
    a.iter().zip(b.iter()).fold(0.0f64, |e, (x, y)| e.max((x - y).abs())) / scale
}

fn q_plus(m: &Model, q: &[f64], k: usize, e: f64) -> Vec<f64> {
    let mut dl = vec![0.0; m.nv];
    dl[k] = e;
    let mut out = vec![0.0; m.nq];
    integrate(m, q, &dl, &mut out).unwrap();
    out
}

/// Central difference of an nv-valued function of q along the local tangent.
fn fd_q(m: &Model, q: &[f64], rows: usize, mut f: impl FnMut(&[f64]) -> Vec<f64>) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(rows, m.nv);
    for k in 0..m.nv {
        let (a, b) = (f(&q_plus(m, q, k, EPS)), f(&q_plus(m, q, k, -EPS)));
        for r in 0..rows {
            j[(r, k)] = (a[r] - b[r]) / (2.0 * EPS);
        }
    }
    j
}

fn fd_vec(x: &[f64], rows: usize, mut f: impl FnMut(&[f64]) -> Vec<f64>) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(rows, x.len());
    for k in 0..x.len() {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[k] += EPS;
        xm[k] -= EPS;
        let (a, b) = (f(&xp), f(&xm));
        for r in 0..rows {
            j[(r, k)] = (a[r] - b[r]) / (2.0 * EPS);
        }
    }
    j
}

#[test]
fn rnea_and_aba_derivatives_match_finite_differences() {
    let mut r = rng(3);
    for m in models() {
        let mut d = Data::new(&m);
        let mut w = Derivatives::new(&m);
        for trial in 0..3 {
            let q = random_q(&m, &mut r);
            let v = random_vec(m.nv, &mut r);
            let a = random_vec(m.nv, &mut r);
            let tau = random_vec(m.nv, &mut r);
            let fext: Vec<f64> = random_vec(6 * m.nbodies(), &mut r);
            let fe = if trial == 2 { Some(&fext[..]) } else { None };
            rnea_derivatives(&m, &mut d, &mut w, &q, &v, &a, fe).unwrap();
            let (tq, tv) = (w.dtau_dq.clone(), w.dtau_dv.clone());
            let mut dd = Data::new(&m);
            let mut tau_of = |q: &[f64], v: &[f64]| {
                rnea(&m, &mut dd, q, v, &a, fe).unwrap();
                dd.tau.clone()
            };
            let fq = fd_q(&m, &q, m.nv, |q| tau_of(q, &v));
            let fv = fd_vec(&v, m.nv, |v| tau_of(&q, v));
            let (eq, ev) = (rel(&tq, &fq), rel(&tv, &fv));
            assert!(
                eq < 1e-6 && ev < 1e-6,
                "{} base {:?}: dtau/dq {eq:.2e}, dtau/dv {ev:.2e}",
                m.name,
                m.joint_types[0]
            );

            aba_derivatives(&m, &mut d, &mut w, &q, &v, &tau, fe).unwrap();
            // It leaves world-frame kinematics in `d`, which callers (the DDP cost Jacobians) read (an earlier
            // version called CRBA, which works relative to the base under a free root, and left `d.o_mi` there).
            let mut fk = Data::new(&m);
            forward_kinematics(&m, &mut fk, &q).unwrap();
            for (i, (x, y)) in d.o_mi.iter().zip(&fk.o_mi).enumerate() {
                let e = (x.rot - y.rot).amax().max((x.trans - y.trans).amax());
                assert!(
                    e < 1e-12,
                    "{} base {:?}: body {i} placement after aba_derivatives off by {e:.1e}",
                    m.name,
                    m.joint_types[0]
                );
            }
            let mut acc = |q: &[f64], v: &[f64], t: &[f64]| {
                aba(&m, &mut dd, q, v, t, fe).unwrap();
                dd.ddq.clone()
            };
            let a0 = acc(&q, &v, &tau);
            assert!(w.ddq.iter().zip(&a0).all(|(x, y)| (x - y).abs() < 1e-12));
            let fq = fd_q(&m, &q, m.nv, |q| acc(q, &v, &tau));
            let fv = fd_vec(&v, m.nv, |v| acc(&q, v, &tau));
            let ft = fd_vec(&tau, m.nv, |t| acc(&q, &v, t));
            let (eq, ev, et) = (rel(&w.da_dq, &fq), rel(&w.da_dv, &fv), rel(&w.minv, &ft));
            assert!(
                eq < 1e-6 && ev < 1e-6 && et < 1e-6,
                "base {:?}, {} bodies: da/dq {eq:.2e}, da/dv {ev:.2e}, da/dtau {et:.2e}",
                m.joint_types[0],
                m.nbodies()
            );
        }
    }
}

#[test]
fn minv_is_the_inverse_of_crbas_mass_matrix() {
    let mut r = rng(5);
    for m in models() {
        let mut d = Data::new(&m);
        let mut w = Derivatives::new(&m);
        for _ in 0..3 {
            let q = random_q(&m, &mut r);
            let v = random_vec(m.nv, &mut r);
            let tau = random_vec(m.nv, &mut r);
            aba_derivatives(&m, &mut d, &mut w, &q, &v, &tau, None).unwrap();
            // exactly symmetric: the Python binding hands its column-major storage over as row-major
            assert_eq!(w.minv, w.minv.transpose(), "{}: M⁻¹ is not exactly symmetric", m.name);
            let mut dm = Data::new(&m);
            crba(&m, &mut dm, &q).unwrap();
            let inv = dm.mass_matrix.clone().try_inverse().expect("M is invertible");
            let e = rel(&w.minv, &inv);
            let id = (&w.minv * &dm.mass_matrix - DMatrix::identity(m.nv, m.nv)).amax();
            assert!(
                e < 1e-10 && id < 1e-10,
                "{} base {:?}: M⁻¹ off by {e:.2e} (relative), M⁻¹ M − 1 by {id:.2e}",
                m.name,
                m.joint_types[0]
            );
        }
    }
}

#[test]
fn integrate_follows_the_velocity_and_difference_inverts_it() {
    // d/dt (q ⊕ t v) at t = 0 is v in the local tangent: the body twist of the base (forward
    // velocities at q with velocity v) equals the one recovered from (q ⊕ εv) ⊖ q.
    let mut r = rng(5);
    for m in models() {
        let q = random_q(&m, &mut r);
        let dl: Vec<f64> = random_vec(m.nv, &mut r).iter().map(|x| 0.7 * x).collect();
        let mut q1 = vec![0.0; m.nq];
        integrate(&m, &q, &dl, &mut q1).unwrap();
        let mut back = vec![0.0; m.nv];
        difference(&m, &q, &q1, &mut back).unwrap();
        for k in 0..m.nv {
            assert!((back[k] - dl[k]).abs() < 1e-12, "q1 ⊖ q ≠ δ at {k}");
        }
        // velocity consistency on the base: finite-difference body twist of the base placement
        let mut d = Data::new(&m);
        let v = random_vec(m.nv, &mut r);
        forward_velocities(&m, &mut d, &q, &v).unwrap();
        let tw = d.v[0];
        let (mut qp, mut qm) = (vec![0.0; m.nq], vec![0.0; m.nq]);
        let vp: Vec<f64> = v.iter().map(|x| x * EPS).collect();
        let vm: Vec<f64> = v.iter().map(|x| -x * EPS).collect();
        integrate(&m, &q, &vp, &mut qp).unwrap();
        integrate(&m, &q, &vm, &mut qm).unwrap();
        freefloat_core::kinematics::forward_kinematics(&m, &mut d, &qp).unwrap();
        let tp = d.o_mi[0];
        freefloat_core::kinematics::forward_kinematics(&m, &mut d, &qm).unwrap();
        let tm = d.o_mi[0];
        freefloat_core::kinematics::forward_kinematics(&m, &mut d, &q).unwrap();
        let t0 = d.o_mi[0];
        let lin = t0.rot.transpose() * (tp.trans - tm.trans) / (2.0 * EPS);
        assert!((lin - tw.lin).norm() < 1e-7, "base linear velocity: {lin} vs {}", tw.lin);
        let rd = t0.rot.transpose() * (tp.rot - tm.rot) / (2.0 * EPS);
        let ang = V3::new(rd[(2, 1)], rd[(0, 2)], rd[(1, 0)]);
        assert!((ang - tw.ang).norm() < 1e-7, "base angular velocity: {ang} vs {}", tw.ang);

        // Jacobians of ⊕ and ⊖
        let (mut jq, mut jd) = (DMatrix::zeros(m.nv, m.nv), DMatrix::zeros(m.nv, m.nv));
        integrate_jacobians(&m, &q, &dl, &mut jq, &mut jd).unwrap();
        let tangent_at_q1 = |x: &[f64]| {
            let mut o = vec![0.0; m.nv];
            difference(&m, &q1, x, &mut o).unwrap();
            o
        };
        let fjq = fd_q(&m, &q, m.nv, |qq| {
            let mut o = vec![0.0; m.nq];
            integrate(&m, qq, &dl, &mut o).unwrap();
            tangent_at_q1(&o)
        });
        let fjd = fd_vec(&dl, m.nv, |dd| {
            let mut o = vec![0.0; m.nq];
            integrate(&m, &q, dd, &mut o).unwrap();
            tangent_at_q1(&o)
        });
        assert!(rel(&jq, &fjq) < 1e-7, "∂(q ⊕ δ)/∂q: {:.2e}", rel(&jq, &fjq));
        assert!(rel(&jd, &fjd) < 1e-7, "∂(q ⊕ δ)/∂δ: {:.2e}", rel(&jd, &fjd));
        let (mut j0, mut j1, mut buf) = (DMatrix::zeros(m.nv, m.nv), DMatrix::zeros(m.nv, m.nv), vec![0.0; m.nv]);
        difference_jacobians(&m, &q, &q1, &mut j0, &mut j1, &mut buf).unwrap();
        let diff = |a: &[f64], b: &[f64]| {
            let mut o = vec![0.0; m.nv];
            difference(&m, a, b, &mut o).unwrap();
            o
        };
        let fj0 = fd_q(&m, &q, m.nv, |qq| diff(qq, &q1));
        let fj1 = fd_q(&m, &q1, m.nv, |qq| diff(&q, qq));
        assert!(rel(&j0, &fj0) < 1e-7, "∂(q1 ⊖ q0)/∂q0: {:.2e}", rel(&j0, &fj0));
        assert!(rel(&j1, &fj1) < 1e-7, "∂(q1 ⊖ q0)/∂q1: {:.2e}", rel(&j1, &fj1));
    }
}

#[test]
fn step_derivatives_match_finite_differences() {
    let mut r = rng(8);
    for m in models() {
        let nv = m.nv;
        let mut d = Data::new(&m);
        let mut w = Derivatives::new(&m);
        let mut w2 = Derivatives::new(&m);
        let q = random_q(&m, &mut r);
        let v = random_vec(nv, &mut r);
        let tau = random_vec(nv, &mut r);
        for (scheme, dt) in [(Scheme::Euler, 0.05), (Scheme::Rk4, 0.05)] {
            step_derivatives(&m, &mut d, &mut w, &q, &v, &tau, dt, scheme).unwrap();
            // the value path agrees with the derivative path
            step(&m, &mut d, &mut w2, &q, &v, &tau, dt, scheme).unwrap();
            assert_eq!(w.q_next, w2.q_next);
            assert_eq!(w.v_next, w2.v_next);
            let (qn, vn) = (w.q_next.clone(), w.v_next.clone());
            let mut next = |q: &[f64], v: &[f64], t: &[f64]| {
                step(&m, &mut d, &mut w2, q, v, t, dt, scheme).unwrap();
                let mut o = vec![0.0; 2 * nv];
                difference(&m, &qn, &w2.q_next, &mut o[..nv]).unwrap();
                for k in 0..nv {
                    o[nv + k] = w2.v_next[k] - vn[k];
                }
                o
            };
            let mut fx = DMatrix::zeros(2 * nv, 2 * nv);
            fx.columns_mut(0, nv).copy_from(&fd_q(&m, &q, 2 * nv, |qq| next(qq, &v, &tau)));
            fx.columns_mut(nv, nv).copy_from(&fd_vec(&v, 2 * nv, |vv| next(&q, vv, &tau)));
            let fu = fd_vec(&tau, 2 * nv, |t| next(&q, &v, t));
            let (ex, eu) = (rel(&w.fx, &fx), rel(&w.fu, &fu));
            assert!(
                ex < 1e-6 && eu < 1e-6,
                "{scheme:?}, base {:?}, {} bodies: Fx {ex:.2e}, Fu {eu:.2e}",
                m.joint_types[0],
                m.nbodies()
            );
        }
    }
}

#[test]
fn rk4_step_is_fourth_order() {
    // Against a reference of 64 substeps: halving dt divides the error by ≈ 16.
    let mut r = rng(21);
    let m = random_model_of(&mut r, JointType::Free, 5, false, &KINDS);
    let mut d = Data::new(&m);
    let mut w = Derivatives::new(&m);
    let q0 = random_q(&m, &mut r);
    let v0: Vec<f64> = random_vec(m.nv, &mut r).iter().map(|x| 2.0 * x).collect();
    let tau = random_vec(m.nv, &mut r);
    let run = |d: &mut Data, w: &mut Derivatives, n: usize, t: f64| {
        let (mut q, mut v) = (q0.clone(), v0.clone());
        for _ in 0..n {
            step(&m, d, w, &q, &v, &tau, t / n as f64, Scheme::Rk4).unwrap();
            q.copy_from_slice(&w.q_next);
            v.copy_from_slice(&w.v_next);
        }
        (q, v)
    };
    let (qr, vr) = run(&mut d, &mut w, 256, 0.4);
    let err = |d: &mut Data, w: &mut Derivatives, n: usize| {
        let (q, v) = run(d, w, n, 0.4);
        let mut o = vec![0.0; m.nv];
        difference(&m, &qr, &q, &mut o).unwrap();
        o.iter()
            .chain(v.iter().zip(&vr).map(|(a, b)| a - b).collect::<Vec<_>>().iter())
            .fold(0.0f64, |s, x| s.max(x.abs()))
    };
    let (e1, e2) = (err(&mut d, &mut w, 4), err(&mut d, &mut w, 8));
    let ratio = e1 / e2;
    assert!(ratio > 12.0 && ratio < 20.0, "RK4 error ratio on halving dt: {ratio:.2} ({e1:.2e} → {e2:.2e})");
}

#[test]
fn frame_pose_derivatives_match_finite_differences() {
    let mut r = rng(9);
    for m in models() {
        let mut d = Data::new(&m);
        let q = random_q(&m, &mut r);
        let body = m.nbodies() - 1;
        let pl = Se3::new(rpy_to_rot(&V3::new(0.3, -0.2, 0.5)), V3::new(0.1, 0.2, -0.3));
        let reference = Se3::new(rpy_to_rot(&V3::new(-1.0, 0.4, 2.0)), V3::new(0.5, -1.0, 2.0));
        let (mut e, mut jac) = ([0.0; 6], DMatrix::zeros(6, m.nv));
        frame_log_error_derivatives(&m, &mut d, &q, body, &pl, &reference, &mut e, &mut jac).unwrap();
        let mut dd = Data::new(&m);
        let fj = fd_q(&m, &q, 6, |qq| {
            let (mut e, mut j) = ([0.0; 6], DMatrix::zeros(6, m.nv));
            frame_log_error_derivatives(&m, &mut dd, qq, body, &pl, &reference, &mut e, &mut j).unwrap();
            e.to_vec()
        });
        assert!(rel(&jac, &fj) < 1e-6, "log-SE(3) error Jacobian: {:.2e}", rel(&jac, &fj));
        let (mut x, mut jx) = ([0.0; 8], DMatrix::zeros(8, m.nv));
        frame_dq_pose_derivatives(&m, &mut d, &q, body, &pl, &mut x, &mut jx).unwrap();
        let fj = fd_q(&m, &q, 8, |qq| {
            let (mut x2, mut j) = ([0.0; 8], DMatrix::zeros(8, m.nv));
            frame_dq_pose_derivatives(&m, &mut dd, qq, body, &pl, &mut x2, &mut j).unwrap();
            // same sign branch as the nominal pose
            let s = if x2[..4].iter().zip(&x[..4]).map(|(a, b)| a * b).sum::<f64>() < 0.0 { -1.0 } else { 1.0 };
            x2.iter().map(|v| v * s).collect()
        });
        assert!(rel(&jx, &fj) < 1e-6, "dual-quaternion pose Jacobian: {:.2e}", rel(&jx, &fj));
    }
}

#[test]
fn se3_log_inverts_the_exponential_and_its_jacobian_is_jr_inverse() {
    // exp via the integrate of a free base: T(q ⊕ [ρ; φ]) relative to T(q) is Exp of the R³ × SO(3)
    // step, not of SE(3), so build SE(3) Exp independently: p = Jl(φ) ρ with Jl from the series.
    let e = [0.3, -0.7, 1.1, 0.4, -0.9, 0.6];
    let t = exp6(&e);
    let l = se3_log(&t);
    for k in 0..6 {
        assert!((l[k] - e[k]).abs() < 1e-9, "log(exp(e)) ≠ e: {l:?}");
    }
    let j = se3_log_jacobian(&e);
    for k in 0..6 {
        let mut ep = [0.0; 6];
        ep[k] = EPS;
        let em: [f64; 6] = ep.map(|x| -x);
        let (a, b) = (se3_log(&t.compose(&exp6(&ep))), se3_log(&t.compose(&exp6(&em))));
        for rr in 0..6 {
            let fdv = (a[rr] - b[rr]) / (2.0 * EPS);
            assert!((fdv - j[(rr, k)]).abs() < 1e-7, "Jlog[{rr},{k}] {} vs {fdv}", j[(rr, k)]);
        }
    }
}

/// SE(3) exponential by integrating the constant twist [ρ; φ] with many small screw steps
/// (independent of the closed forms under test).
fn exp6(e: &[f64; 6]) -> Se3 {
    let n = 1 << 14;
    let h = 1.0 / n as f64;
    let rho = V3::new(e[0], e[1], e[2]);
    let phi = V3::new(e[3], e[4], e[5]);
    if phi.norm() == 0.0 {
        return Se3::new(freefloat_core::spatial::M3::identity(), rho);
    }
    let step_rot = freefloat_core::spatial::rotation_about_axis(&phi.normalize(), phi.norm() * h);
    let mut t = Se3::identity();
    // midpoint rule for the translation: ṗ = R ρ
    let half = freefloat_core::spatial::rotation_about_axis(&phi.normalize(), phi.norm() * h * 0.5);
    for _ in 0..n {
        t.trans += t.rot * half * rho * h;
        t.rot *= step_rot;
    }
    t
}

#[test]
fn bad_arguments_are_rejected() {
    let mut r = rng(1);
    let m = random_model_of(&mut r, JointType::Free, 3, false, &KINDS);
    let other = random_model_of(&mut r, JointType::Free, 3, false, &KINDS);
    let mut d = Data::new(&m);
    let mut w = Derivatives::new(&m);
    let q = random_q(&m, &mut r);
    let v = vec![0.0; m.nv];
    let err = |e: freefloat_core::FfError| e.to_string();
    let e = aba_derivatives(&m, &mut d, &mut w, &q, &v[..m.nv - 1], &v, None).unwrap_err();
    assert!(err(e).contains("`v`"));
    let mut wo = Derivatives::new(&other);
    let e = aba_derivatives(&m, &mut d, &mut wo, &q, &v, &v, None).unwrap_err();
    assert!(err(e).contains("derivatives"));
    let e = step_derivatives(&m, &mut d, &mut w, &q, &v, &v, 0.0, Scheme::Euler).unwrap_err();
    assert!(err(e).contains("`dt`"));
    let e = step(&m, &mut d, &mut w, &q, &v, &[f64::NAN; 64][..m.nv], 0.1, Scheme::Rk4).unwrap_err();
    assert!(err(e).contains("`tau`"));
    let mu = random_model_of(&mut r, JointType::Free, 3, false, &[JointType::Universal]);
    let (mut du, mut wu) = (Data::new(&mu), Derivatives::new(&mu));
    let qu = random_q(&mu, &mut r);
    let vu = vec![0.0; mu.nv];
    let e = aba_derivatives(&mu, &mut du, &mut wu, &qu, &vu, &vu, None).unwrap_err();
    assert!(err(e).contains("universal"));
}

/// Per-call times of the derivative routines on the ch. 8 spacecraft (RRR + Z-Y-X wrist, nv = 12), for
/// profiling: `cargo test --release --test derivatives -- --ignored --nocapture timing`. The benchmark
/// with peers is benches/derivatives_bench.py.
#[test]
#[ignore]
fn timing_profile() {
    use freefloat_core::model::{BodySpec, JointLimits, ModelBuilder};
    use freefloat_core::spatial::{Inertia, M3};
    let i3 = M3::identity();
    let mut b =
        ModelBuilder::new("ch8", "base", JointType::Free, Inertia::from_com(50.0, V3::zeros(), i3 * 10.0)).unwrap();
    let rx = rpy_to_rot(&V3::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0));
    let chain = [
        (V3::z(), Se3::new(M3::identity(), V3::new(0.0, 0.0, 1.0)), 5.0, V3::new(0.0, 0.0, 1.0), i3),
        (V3::z(), Se3::new(rx, V3::new(0.75, 0.0, 4.0)), 5.0, V3::new(1.5, 0.0, 0.0), i3),
        (V3::z(), Se3::new(M3::identity(), V3::new(3.0, 0.0, 0.0)), 5.0, V3::new(1.5, 0.0, 0.0), i3),
        (V3::z(), Se3::new(M3::identity(), V3::new(3.0, 0.0, 0.0)), 0.1, V3::zeros(), i3 * 0.01),
        (V3::y(), Se3::identity(), 0.1, V3::zeros(), i3 * 0.01),
        (V3::x(), Se3::identity(), 0.1, V3::zeros(), i3 * 0.01),
    ];
    for (k, (axis, pl, mass, com, ic)) in chain.into_iter().enumerate() {
        b.add_body(BodySpec {
            name: format!("b{k}"),
            parent: k,
            joint_name: format!("j{k}"),
            joint_type: JointType::Revolute,
            axis,
            axis2: V3::x(),
            placement: pl,
            inertia: Inertia::from_com(mass, com, ic),
            limits: JointLimits::default(),
            tags: vec![],
            allow_nonphysical: false,
        })
        .unwrap();
    }
    let m = b.build().unwrap();
    let mut r = rng(2);
    let (mut d, mut w) = (Data::new(&m), Derivatives::new(&m));
    let q = random_q(&m, &mut r);
    let v = random_vec(m.nv, &mut r);
    let tau = random_vec(m.nv, &mut r);
    let n = 2000;
    let time = |label: &str, f: &mut dyn FnMut()| {
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let t0 = std::time::Instant::now();
            for _ in 0..n {
                f();
            }
            best = best.min(t0.elapsed().as_secs_f64() / n as f64 * 1e6);
        }
        println!("{label:32} {best:7.2} µs");
    };
    time("aba", &mut || aba(&m, &mut d, &q, &v, &tau, None).unwrap());
    time("rnea_derivatives", &mut || rnea_derivatives(&m, &mut d, &mut w, &q, &v, &tau, None).unwrap());
    time("aba_derivatives", &mut || aba_derivatives(&m, &mut d, &mut w, &q, &v, &tau, None).unwrap());
    time("step_derivatives euler", &mut || {
        step_derivatives(&m, &mut d, &mut w, &q, &v, &tau, 0.05, Scheme::Euler).unwrap()
    });
    time("step_derivatives rk4", &mut || {
        step_derivatives(&m, &mut d, &mut w, &q, &v, &tau, 0.05, Scheme::Rk4).unwrap()
    });
    let (mut e, mut jac) = ([0.0; 6], DMatrix::zeros(6, m.nv));
    let target = Se3::new(rpy_to_rot(&V3::new(0.1, 0.2, 0.3)), V3::new(1.0, 2.0, 3.0));
    time("frame_log_error_derivatives", &mut || {
        frame_log_error_derivatives(&m, &mut d, &q, 6, &Se3::identity(), &target, &mut e, &mut jac).unwrap()
    });
}
