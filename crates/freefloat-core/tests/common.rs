//! Random trees with every joint type, shared by the integration tests.
#![allow(dead_code)]

use freefloat_core::model::{BodySpec, JointLimits, JointType, Model, ModelBuilder};
use freefloat_core::spatial::{quat_normalize, rotation_about_axis, rpy_to_rot, Inertia, Se3, M3, V3};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

fn unit(r: &mut StdRng) -> V3 {
    loop {
        let v = V3::new(r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0));
        if v.norm() > 0.2 && v.norm() < 1.0 {
            return v.normalize();
        }
    }
}

/// A physically consistent random inertia: principal moments obeying the triangle inequality,
/// a random principal frame and centre of mass.
pub fn random_inertia(r: &mut StdRng) -> Inertia {
    let mass = r.gen_range(0.5..10.0);
    let (a, b): (f64, f64) = (r.gen_range(0.1..2.0), r.gen_range(0.1..2.0));
    let c = r.gen_range((a - b).abs() + 0.01..a + b);
    let rot = rotation_about_axis(&unit(r), r.gen_range(0.0..3.0));
    let ic = rot * M3::from_diagonal(&V3::new(a, b, c)) * rot.transpose();
    let com = V3::new(r.gen_range(-0.5..0.5), r.gen_range(-0.5..0.5), r.gen_range(-0.5..0.5));
    Inertia::from_com(mass, com, ic)
}

/// Every joint type below the base.
pub const KINDS: [JointType; 6] = [
    JointType::Revolute,
    JointType::Prismatic,
    JointType::Spherical,
    JointType::Cylindrical,
    JointType::Universal,
    JointType::Fixed,
];

pub fn random_model(r: &mut StdRng, base: JointType, n: usize, gravity: bool) -> Model {
    random_model_of(r, base, n, gravity, &KINDS)
}

/// A random tree whose joints are drawn from `kinds`.
pub fn random_model_of(r: &mut StdRng, base: JointType, n: usize, gravity: bool, kinds: &[JointType]) -> Model {
    let mut b = ModelBuilder::new("random", "base", base, random_inertia(r)).unwrap();
    if gravity {
        b.set_gravity(V3::new(0.3, -1.2, -9.81));
    }
    for i in 1..=n {
        let parent = r.gen_range(0..i);
        let kind = kinds[r.gen_range(0..kinds.len())];
        let axis = unit(r);
        // a universal joint's second axis: orthogonal to the first (a Cardan joint)
        let axis2 = axis.cross(&unit(r)).normalize();
        let rpy = V3::new(r.gen_range(-3.0..3.0), r.gen_range(-1.5..1.5), r.gen_range(-3.0..3.0));
        let pl =
            Se3::new(rpy_to_rot(&rpy), V3::new(r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0)));
        b.add_body(BodySpec {
            name: format!("b{i}"),
            parent,
            joint_name: format!("j{i}"),
            joint_type: kind,
            axis,
            axis2,
            placement: pl,
            inertia: random_inertia(r),
            limits: JointLimits::default(),
            tags: vec![],
            allow_nonphysical: false,
        })
        .unwrap();
    }
    b.add_frame("tool", n, Se3::new(rpy_to_rot(&V3::new(0.1, 0.2, 0.3)), V3::new(0.2, -0.1, 0.3))).unwrap();
    b.build().unwrap()
}

pub fn random_q(m: &Model, r: &mut StdRng) -> Vec<f64> {
    let mut q: Vec<f64> = (0..m.nq).map(|_| r.gen_range(-1.5..1.5)).collect();
    for i in 0..m.nbodies() {
        if let Some(k) = m.joint_types[i].quaternion_offset() {
            let s = m.idx_q[i] + k;
            quat_normalize(&mut q[s..s + 4]);
        }
    }
    q
}

pub fn random_vec(n: usize, r: &mut StdRng) -> Vec<f64> {
    (0..n).map(|_| r.gen_range(-1.0..1.0)).collect()
}

pub fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    let s: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
    d / s.max(1e-12)
}

pub const BASES: [JointType; 3] = [JointType::Free, JointType::Planar, JointType::FixedBase];
