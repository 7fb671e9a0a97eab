//! A fixed workload for instruction counting of the dynamics kernels (ABA, RNEA, CRBA) and their derivatives
//! (`aba_derivatives`, `rnea_derivatives`): `count` calls on a cycle of 64 random states of one model. Instruction counts, unlike wall time, do not depend on what else the
//! shared machine is doing.
//!
//!     cargo build --release --example kernels_profile
//!     valgrind --tool=callgrind target/release/examples/kernels_profile aba naveen_dual_arm_consistent 10000
//!     target/release/examples/kernels_profile rnea path/to/tree.yaml 100000     # a model file also works
//!     valgrind --tool=callgrind target/release/examples/kernels_profile aba_derivatives naveen_dual_arm_consistent 2000
//!
//! Prints the wall time per call too (indicative only on a loaded machine).

use freefloat_core::dynamics::derivatives::{aba_derivatives, rnea_derivatives, Derivatives};
use freefloat_core::dynamics::{aba, crba, rnea};
use freefloat_core::model::{builtin, yaml};
use freefloat_core::{Data, Model};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Instant;

fn load(name: &str) -> Model {
    if name.ends_with(".yaml") || name.ends_with(".yml") {
        let text = std::fs::read_to_string(name).expect("readable model file");
        yaml::from_yaml_str(&text, name).expect("valid model file")
    } else {
        builtin::load(name).expect("built-in model")
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let algo = args.get(1).map(String::as_str).unwrap_or("aba").to_string();
    let name = args.get(2).map(String::as_str).unwrap_or("naveen_dual_arm_consistent").to_string();
    let count: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(10_000);
    let m = load(&name);
    let mut rng = StdRng::seed_from_u64(7);
    let states: Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> = (0..64)
        .map(|_| {
            let mut q = m.neutral();
            for x in q.iter_mut() {
                *x += rng.gen_range(-1.0..1.0);
            }
            for &(_, k) in m.quaternions() {
                let n = q[k..k + 4].iter().map(|x| x * x).sum::<f64>().sqrt();
                q[k..k + 4].iter_mut().for_each(|x| *x /= n);
            }
            let v = (0..m.nv).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let u = (0..m.nv).map(|_| rng.gen_range(-10.0..10.0)).collect();
            (q, v, u)
        })
        .collect();
    let mut d = Data::new(&m);
    let mut w = Derivatives::new(&m);
    let t0 = Instant::now();
    let mut acc = 0.0;
    for k in 0..count {
        let (q, v, u) = &states[k % 64];
        match algo.as_str() {
            "aba" => {
                aba(&m, &mut d, q, v, u, None).expect("aba");
                acc += d.ddq[0];
            }
            "rnea" => {
                rnea(&m, &mut d, q, v, u, None).expect("rnea");
                acc += d.tau[0];
            }
            "crba" => {
                crba(&m, &mut d, q).expect("crba");
                acc += d.mass_matrix[(0, 0)];
            }
            "aba_derivatives" => {
                aba_derivatives(&m, &mut d, &mut w, q, v, u, None).expect("aba_derivatives");
                acc += w.da_dq[(m.nv - 1, m.nv - 1)];
            }
            "rnea_derivatives" => {
                rnea_derivatives(&m, &mut d, &mut w, q, v, u, None).expect("rnea_derivatives");
                acc += w.dtau_dq[(m.nv - 1, m.nv - 1)];
            }
            other => panic!("unknown algorithm {other} (aba, rnea, crba, aba_derivatives, rnea_derivatives)"),
        }
    }
    let dt = t0.elapsed().as_secs_f64();
    black_box(acc);
    println!("{algo} on {} (nv = {}): {count} calls, {:.3} us per call", m.name, m.nv, 1e6 * dt / count as f64);
}
