//! A plain loop over one engine kernel, for instruction counts (`perf stat -e instructions`) and profiles
//! (`perf record`, `valgrind --tool=callgrind`) of the shipped (fat-LTO) build:
//!
//!     cargo build --release -p freefloat-core --example kernel_loop
//!     perf stat -e instructions target/release/examples/kernel_loop crba naveen_dual_arm 100000
//!
//! Kernels: aba, rnea, crba, fk. Model: a built-in model name or a YAML model file. It cycles through 64
//! configurations (so the branch predictor cannot learn one input) and prints a checksum so nothing is optimised
//! away. Per-call instructions: (count of this run − count with 0 calls) / calls. With a fourth argument `wide`
//! every joint coordinate is drawn in [-π, π] and the base quaternion at random instead (the benchmark's states:
//! sincos takes its longer path above about 0.86 rad, which the near-neutral states never reach).
use freefloat_core::dynamics::{aba, crba, rnea};
use freefloat_core::kinematics::forward_kinematics;
use freefloat_core::{Data, Model};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 && !(args.len() == 5 && args[4] == "wide") {
        eprintln!("usage: kernel_loop <aba|rnea|crba|fk> <builtin model name or model.yaml> <calls> [wide]");
        std::process::exit(2);
    }
    let m: Model = if args[2].ends_with(".yaml") || args[2].ends_with(".yml") {
        let text = std::fs::read_to_string(&args[2]).expect("read the model file");
        freefloat_core::model::yaml::from_yaml_str(&text, &args[2]).expect("parse the model file")
    } else {
        freefloat_core::model::builtin::load(&args[2]).expect("built-in model")
    };
    let calls: usize = args[3].parse().expect("calls: a whole number");
    let mut d = Data::new(&m);
    let wide = args.len() == 5;
    // a fixed linear congruential sequence in [0, 1): the same states on every run
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut unit = move || {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    // 64 configurations: neutral with each coordinate nudged by a deterministic pattern, quaternion renormalised
    let states: Vec<(Vec<f64>, Vec<f64>)> = (0..64)
        .map(|k| {
            let mut q = m.neutral();
            for (j, x) in q.iter_mut().enumerate() {
                *x += if wide {
                    std::f64::consts::PI * (2.0 * unit() - 1.0)
                } else {
                    0.3 * (((k * 7 + j * 13) % 17) as f64 / 17.0 - 0.5)
                };
            }
            if m.nq != m.nv {
                let n = q[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
                q[3..7].iter_mut().for_each(|x| *x /= n);
            }
            let v = (0..m.nv).map(|j| (((k * 5 + j * 3) % 11) as f64 / 11.0) - 0.5).collect();
            (q, v)
        })
        .collect();
    let mut sum = 0.0;
    for c in 0..calls {
        let (q, v) = &states[c % 64];
        match args[1].as_str() {
            "aba" => {
                aba(&m, &mut d, q, v, v, None).expect("aba");
                sum += d.ddq[0];
            }
            "rnea" => {
                rnea(&m, &mut d, q, v, v, None).expect("rnea");
                sum += d.tau[0];
            }
            "crba" => {
                crba(&m, &mut d, q).expect("crba");
                sum += d.mass_matrix[(0, 0)];
            }
            "fk" => {
                forward_kinematics(&m, &mut d, q).expect("fk");
                sum += d.o_mi[m.nbodies() - 1].trans[0];
            }
            k => panic!("unknown kernel {k}"),
        }
    }
    println!("{sum}");
}
