//! Dual-quaternion kinematics (Valverde 2018, Ch. 3) against the engine's forward kinematics, closed forms,
//! the chapter 3 worked examples (§3.5–3.6; the thesis works them symbolically, so the link lengths, angles
//! and expected values here were chosen and computed independently with numpy) and the constraint encodings
//! of §3.4.

mod common;

use common::{random_model, random_q, rng};
use freefloat_core::data::Data;
use freefloat_core::dualquat::constraints::{
    approach_slope, approach_slope_matrix, attitude, attitude_matrix, distance_bound, line_of_sight,
    line_of_sight_matrix,
};
use freefloat_core::dualquat::kinematics::{
    body_poses, dh, dh_chain, dh_exp, dh_product, serial_body_jacobian, ProductOfExponentials,
};
use freefloat_core::dualquat::pose::{body_twist, from_rotation_translation, rotation, translation};
use freefloat_core::dualquat::{DualQuat, Quat, V8};
use freefloat_core::kinematics::forward_kinematics;
use freefloat_core::model::{BodySpec, JointLimits, JointType, ModelBuilder};
use freefloat_core::spatial::{Inertia, Se3, M3, V3};
use rand::Rng;

fn assert_pose_eq(a: &DualQuat, x: &Se3, tol: f64) {
    let y = a.to_se3();
    assert!((y.rot - x.rot).amax() < tol && (y.trans - x.trans).amax() < tol, "{y:?} != {x:?}");
}

fn close(a: &DualQuat, b: &[f64; 8], tol: f64) -> bool {
    (a.to_vec8() - V8::from_column_slice(b)).amax() < tol
}

#[test]
fn chain_and_poe_match_engine_fk_on_random_trees() {
    let mut r = rng(41);
    for base in [JointType::Free, JointType::FixedBase, JointType::Planar] {
        for _ in 0..20 {
            let m = random_model(&mut r, base, 8, false);
            let q = random_q(&m, &mut r);
            let mut d = Data::new(&m);
            forward_kinematics(&m, &mut d, &q).unwrap();
            let chain = body_poses(&m, &q).expect("valid q");
            let poe = ProductOfExponentials::new(&m).expect("supported joints");
            let pp = poe.body_poses(&m, &q).expect("valid q");
            for i in 0..m.nbodies() {
                assert_pose_eq(&chain[i], &d.o_mi[i], 1e-12);
                assert_pose_eq(&pp[i], &d.o_mi[i], 1e-11);
                assert!(chain[i].unit_defect() < 1e-13 && pp[i].unit_defect() < 1e-13);
            }
        }
    }
}

#[test]
fn dh_forms_agree_and_match_the_htm() {
    let mut r = rng(7);
    // independently computed DH vectors (the thesis gives no numbers)
    let a = dh(0.3, 0.8, 1.2, -0.6);
    let expect = [0.87992318, -0.27219214, -0.11508099, 0.37202555, 0.10751145, 0.54521605, 0.18238651, 0.20103707];
    assert!(close(&a, &expect, 1e-8));
    let b = dh(0.5, std::f64::consts::FRAC_PI_2, 1.0, std::f64::consts::FRAC_PI_2);
    assert!(close(&b, &[0.5, 0.5, 0.5, 0.5, -0.375, 0.125, 0.375, -0.125], 1e-15));
    assert!((b.translation() - V3::new(0.0, 1.0, 0.5)).amax() < 1e-15);
    assert!((b.to_se3().rot - M3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0)).amax() < 1e-15);
    for _ in 0..200 {
        let (d, th, aa, al) =
            (r.gen_range(-2.0..2.0), r.gen_range(-3.0..3.0), r.gen_range(-2.0..2.0), r.gen_range(-3.0..3.0));
        let c = dh(d, th, aa, al);
        // (3.26) = product of four elementary motions (with ½) = (3.29)
        assert!((c.to_vec8() - dh_product(d, th, aa, al).to_vec8()).amax() < 1e-14);
        assert!((c.to_vec8() - dh_exp(d, th, aa, al).to_vec8()).amax() < 1e-14);
        // (3.28): the active pose matrix
        let (ct, st, ca, sa) = (th.cos(), th.sin(), al.cos(), al.sin());
        let htm =
            Se3::new(M3::new(ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0.0, sa, ca), V3::new(aa * ct, aa * st, d));
        assert_pose_eq(&c, &htm, 1e-14);
        // (3.27) is its inverse (the passive map i−1 → i), although the thesis calls it the HTM equivalent to q_{i/i−1}
        let inv = Se3::new(
            M3::new(ct, st, 0.0, -ca * st, ca * ct, sa, sa * st, -sa * ct, ca),
            V3::new(-aa, -d * sa, -d * ca),
        );
        assert_pose_eq(&c.conj(), &inv, 1e-14);
        // the literal (3.20) without ½ does not reproduce (3.26): the printed (3.20)–(3.21) drop the ½
        let literal = DualQuat::new(Quat::ONE, Quat::pure(&V3::new(0.0, 0.0, d)))
            .mul(&rotation(&Quat::from_axis_angle(&V3::z(), th)))
            .mul(&DualQuat::new(Quat::ONE, Quat::pure(&V3::new(aa, 0.0, 0.0))))
            .mul(&rotation(&Quat::from_axis_angle(&V3::x(), al)));
        if d.abs() + aa.abs() > 0.1 {
            assert!((literal.to_vec8() - c.to_vec8()).amax() > 1e-3);
        }
    }
}

#[test]
fn dh_chain_matches_engine_model() {
    // An engine model built from standard DH rows: body i's frame sits after Trans_z(d_i) and rotates
    // about z (the joint); the DH frame i is that body frame followed by Trans_x(a_i) Rot_x(α_i).
    let rows = [[0.3, 0.0, 0.5, 1.2], [-0.2, 0.0, 0.9, -0.7], [0.4, 0.0, 0.1, 0.4], [0.1, 0.0, 0.6, 2.0]];
    let inr = Inertia::from_com(1.0, V3::new(0.1, 0.0, 0.0), M3::identity() * 0.1);
    let mut b = ModelBuilder::new("dh", "base", JointType::FixedBase, inr).expect("valid base");
    let tail = |row: &[f64; 4]| {
        translation(&V3::new(row[2], 0.0, 0.0)).mul(&rotation(&Quat::from_axis_angle(&V3::x(), row[3])))
    };
    for (i, row) in rows.iter().enumerate() {
        let prev = if i == 0 { DualQuat::ONE } else { tail(&rows[i - 1]) };
        let placement = prev.mul(&translation(&V3::new(0.0, 0.0, row[0]))).to_se3();
        b.add_body(BodySpec {
            name: format!("l{i}"),
            parent: i,
            joint_name: format!("j{i}"),
            joint_type: JointType::Revolute,
            axis: V3::z(),
            axis2: V3::z(),
            placement,
            inertia: inr,
            limits: JointLimits::default(),
            tags: vec![],
            allow_nonphysical: false,
        })
        .expect("valid body");
    }
    let m = b.build().expect("valid model");
    let mut r = rng(3);
    let mut d = Data::new(&m);
    for _ in 0..50 {
        let q: Vec<f64> = (0..4).map(|_| r.gen_range(-3.0..3.0)).collect();
        forward_kinematics(&m, &mut d, &q).unwrap();
        let mut rr = rows;
        for (k, row) in rr.iter_mut().enumerate() {
            row[1] = q[k];
        }
        let ee = dh_chain(&rr);
        let engine = d.o_mi[4].compose(&tail(&rows[3]).to_se3());
        assert_pose_eq(&ee, &engine, 1e-12);
    }
}

/// Example A (§3.5): planar RR arm, l1 = 1, l2 = 0.5, α = (π/6, π/4), α̇ = (0.3, −0.2).
fn example_a_chain(l1: f64, l2: f64, a1: f64, a2: f64) -> [DualQuat; 3] {
    [
        rotation(&Quat::from_axis_angle(&V3::z(), a1)),
        translation(&V3::new(l1, 0.0, 0.0)).mul(&rotation(&Quat::from_axis_angle(&V3::z(), a2))),
        translation(&V3::new(l2, 0.0, 0.0)),
    ]
}

#[test]
#[allow(clippy::approx_constant)] // 0.70710678 is the reference value to 8 digits, compared to 1e-8
fn chapter3_example_a_planar_rr() {
    let (l1, l2) = (1.0, 0.5);
    let (a1, a2) = (std::f64::consts::FRAC_PI_6, std::f64::consts::FRAC_PI_4);
    let (d1, d2) = (0.3, -0.2);
    let rel = example_a_chain(l1, l2, a1, a2);
    let q = rel[0].mul(&rel[1]).mul(&rel[2]); // (3.43)
    assert!(close(&q, &[0.79335334, 0.0, 0.0, 0.60876143, 0.0, 0.69406077, 0.08692726, 0.0], 1e-8));
    // closed-form planar kinematics
    let r_e = V3::new(l1 * a1.cos() + l2 * (a1 + a2).cos(), l1 * a1.sin() + l2 * (a1 + a2).sin(), 0.0);
    assert!((q.translation() - r_e).amax() < 1e-15);
    assert!((q.translation_body() - V3::new(1.20710678, -0.70710678, 0.0)).amax() < 1e-8);
    // PoE (3.19): home pose and screws ℓ = ẑ, m = 0 and m = [l1,0,0]×ẑ
    let home = translation(&V3::new(l1 + l2, 0.0, 0.0));
    let poe = freefloat_core::dualquat::screw_exp(a1, 0.0, &V3::z(), &V3::zeros())
        .mul(&freefloat_core::dualquat::screw_exp(a2, 0.0, &V3::z(), &V3::new(l1, 0.0, 0.0).cross(&V3::z())))
        .mul(&home);
    assert!((poe.to_vec8() - q.to_vec8()).amax() < 1e-15);
    // body Jacobian (3.57)–(3.60), corrected: closed-form columns and the independently computed twist
    let xi = DualQuat::vector(&V3::z(), &V3::zeros());
    let j = serial_body_jacobian(&rel, &[xi, xi]).expect("3 poses, 2 joints");
    let j1 = DualQuat::vector(&V3::z(), &V3::new(l1 * a2.sin(), l1 * a2.cos() + l2, 0.0));
    let j2 = DualQuat::vector(&V3::z(), &V3::new(0.0, l2, 0.0));
    assert!((j[0].to_vec8() - j1.to_vec8()).amax() < 1e-15 && (j[1].to_vec8() - j2.to_vec8()).amax() < 1e-15);
    let w = j[0].scale(d1) + j[1].scale(d2);
    assert!(close(&w, &[0.0, 0.0, 0.0, 0.1, 0.0, 0.21213203, 0.26213203, 0.0], 1e-8));
    // and by finite differences of the pose: 2 q* q̇
    let h = 1e-6;
    let at = |t: f64| {
        let c = example_a_chain(l1, l2, a1 + d1 * t, a2 + d2 * t);
        c[0].mul(&c[1]).mul(&c[2])
    };
    let qdot = (at(h) - at(-h)).scale(0.5 / h);
    assert!((body_twist(&q, &qdot).to_vec8() - w.to_vec8()).amax() < 1e-9);
}

#[test]
fn chapter3_example_b_floating_pendulum() {
    let (l1, l2, a1, a2, d1, d2) = (1.0, 0.5, std::f64::consts::FRAC_PI_6, std::f64::consts::FRAC_PI_4, 0.3, -0.2);
    let (u, v, ud, vd) = (0.4, -0.2, 0.1, 0.05);
    let at = |t: f64| {
        let c = example_a_chain(l1, l2, a1 + d1 * t, a2 + d2 * t);
        translation(&V3::new(u + ud * t, v + vd * t, 0.0)).mul(&c[0]).mul(&c[1]).mul(&c[2])
    };
    let q = at(0.0);
    assert!(close(&q, &[0.79335334, 0.0, 0.0, 0.60876143, 0.0, 0.79185529, -0.11416036, 0.0], 1e-8));
    assert!((q.translation() - V3::new(1.39543493, 0.78296291, 0.0)).amax() < 1e-8);
    // (3.64): spatial twist of frame 1, and (3.65) corrected: ω^1 = q*_{1/I} ω^I q_{1/I}
    let q1 = from_rotation_translation(&Quat::from_axis_angle(&V3::z(), a1), &V3::new(u, v, 0.0));
    let w1_i = DualQuat::vector(
        &V3::new(0.0, 0.0, d1),
        &(V3::new(ud, vd, 0.0) - V3::new(0.0, 0.0, d1).cross(&V3::new(u, v, 0.0))),
    );
    assert!(close(&w1_i, &[0.0, 0.0, 0.0, 0.3, 0.0, 0.04, -0.07, 0.0], 1e-12));
    let w1_b = q1.shift_in(&w1_i);
    assert!(close(&w1_b, &[0.0, 0.0, 0.0, 0.3, 0.0, 0.11160254, -0.00669873, 0.0], 1e-8));
    // EE twist: Ad_{(q_{2/1} q_{e/2})*} ω^1 + Ad_{q*_{e/2}} ω^2_{2/1}
    let rel = example_a_chain(l1, l2, a1, a2);
    let we =
        rel[1].mul(&rel[2]).shift_in(&w1_b) + rel[2].shift_in(&DualQuat::vector(&V3::new(0.0, 0.0, d2), &V3::zeros()));
    assert!(close(&we, &[0.0, 0.0, 0.0, 0.1, 0.0, 0.28631023, 0.1784804, 0.0], 1e-8));
    let h = 1e-6;
    let qdot = (at(h) - at(-h)).scale(0.5 / h);
    assert!((body_twist(&q, &qdot).to_vec8() - we.to_vec8()).amax() < 1e-9);
}

fn random_pose(r: &mut rand::rngs::StdRng) -> DualQuat {
    let q = Quat::new(r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0));
    let t = V3::new(r.gen_range(-2.0..2.0), r.gen_range(-2.0..2.0), r.gen_range(-2.0..2.0));
    from_rotation_translation(&q.scale(1.0 / q.norm()), &t)
}

#[test]
fn constraint_encodings_and_sign() {
    let mut r = rng(11);
    let (mut in_cone, mut out_cone) = (0, 0);
    for _ in 0..500 {
        let q = random_pose(&mut r); // q_{G/A}
        let v = q.to_vec8();
        let y = V3::new(r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0)).normalize();
        let z = V3::new(r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0)).normalize();
        let r_ga_a = q.translation(); // r^A_{G/A}
        let r_ga_g = q.translation_body(); // r^G_{G/A}
                                           // the encodings of §3.4
        assert!((v.dot(&(approach_slope_matrix(&z) * v)) - r_ga_a.dot(&z)).abs() < 1e-12);
        assert!((v.dot(&(line_of_sight_matrix(&y) * v)) - r_ga_g.dot(&y)).abs() < 1e-12); // the sign issue
        let nb = z;
        assert!((v.dot(&(attitude_matrix(&y, &nb) * v)) + y.dot(&q.r.rotate(&nb))).abs() < 1e-12);
        // line of sight as implemented = physical (3.34): r^G_{A/G}·ŷ ≥ ‖r‖ cos θ
        let th = r.gen_range(0.1..1.4);
        let los = line_of_sight(&q, &y, th).expect("valid axis");
        let phys = (-r_ga_g).dot(&y) - r_ga_g.norm() * th.cos();
        assert!((los.value + phys).abs() < 1e-12);
        if phys > 0.0 {
            in_cone += 1;
        } else {
            out_cone += 1;
        }
        // approach slope: r^A_{G/A}·ẑ ≥ ‖r‖ cos φ; attitude: n^I·(q n^B q*) ≥ cos ψ
        let ap = approach_slope(&q, &z, th).expect("valid axis");
        assert!((ap.value + (r_ga_a.dot(&z) - r_ga_a.norm() * th.cos())).abs() < 1e-12);
        let at = attitude(&q, &y, &nb, th).expect("valid axes");
        assert!((at.value + (y.dot(&q.r.rotate(&nb)) - th.cos())).abs() < 1e-12);
        let bd = distance_bound(&q, 1.5).expect("valid bound");
        assert!((bd.value <= 0.0) == (r_ga_a.norm() <= 1.5));
        // gradients by central differences
        let fd = |f: &dyn Fn(&DualQuat) -> f64| {
            let mut g = V8::zeros();
            for k in 0..8 {
                let mut e = V8::zeros();
                e[k] = 1e-6;
                g[k] = (f(&DualQuat::from_vec8(&(v + e))) - f(&DualQuat::from_vec8(&(v - e)))) / 2e-6;
            }
            g
        };
        let g1 = fd(&|x| line_of_sight(x, &y, th).map(|c| c.value).unwrap_or(f64::NAN));
        let g2 = fd(&|x| approach_slope(x, &z, th).map(|c| c.value).unwrap_or(f64::NAN));
        let g3 = fd(&|x| attitude(x, &y, &nb, th).map(|c| c.value).unwrap_or(f64::NAN));
        assert!(
            (g1 - los.gradient).amax() < 1e-6 && (g2 - ap.gradient).amax() < 1e-6 && (g3 - at.gradient).amax() < 1e-6
        );
    }
    assert!(in_cone > 20 && out_cone > 20, "{in_cone} {out_cone}");
    assert!(line_of_sight(&DualQuat::ONE, &V3::zeros(), 0.3).is_err());
    assert!(distance_bound(&DualQuat::ONE, -1.0).is_err());
}
