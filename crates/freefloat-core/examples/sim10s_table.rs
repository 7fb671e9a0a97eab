//! The path of `benches/sim_vs_mujoco.py` without Python: a 10 s, 1 kHz RK4 simulation of the 15-DoF
//! `seed001_dual_arm_consistent` driven by a torque table sampled at dt/2 with linear hold (exact at the RK4
//! stage times), built the way the Python binding builds it (`TorqueSource::table`, default inputs otherwise,
//! every step recorded). A fixed workload for instruction counting (`valgrind --tool=callgrind`).
//!
//!     cargo build --release --example sim10s_table && valgrind --tool=callgrind target/release/examples/sim10s_table
//!
//! An optional argument sets t_final (s): a tiny one measures the fixed cost, to subtract. A second one names a file
//! that receives the recorded q, v, momentum, kinetic energy and work as raw f64 (to compare two builds).

use freefloat_core::model::builtin;
use freefloat_core::sim::{simulate, Hold, Inputs, Method, SimOptions, TorqueSource};

fn main() {
    let t_final: f64 = std::env::args().nth(1).map_or(10.0, |s| s.parse().expect("t_final in s"));
    let m = builtin::load("seed001_dual_arm_consistent").expect("built-in model");
    let dt = 1e-3;
    // the benchmark's initial state: base offset and tilted, base and arms moving
    let mut q = m.neutral();
    q[0..3].copy_from_slice(&[0.5, -0.2, 0.1]);
    let n = (0.09f64 + 0.25 + 0.64).sqrt();
    let (s, c) = 0.3f64.sin_cos();
    q[3..7].copy_from_slice(&[s * 0.3 / n, s * -0.5 / n, s * 0.8 / n, c]);
    let mut v = vec![0.0; m.nv];
    v[..6].copy_from_slice(&[0.01, -0.02, 0.005, 0.01, 0.02, -0.015]);
    v[6..12].copy_from_slice(&[0.05, -0.1, 0.08, -0.05, 0.1, -0.07]);
    // the benchmark's multi-sine arm torques, sampled at dt/2
    let amp = [20.0, 15.0, 8.0, 20.0, 12.0, 10.0];
    let freq = [0.20, 0.30, 0.50, 0.25, 0.35, 0.45];
    let phase = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5];
    let rows = (2.0 * t_final / dt).round() as usize + 1;
    let times: Vec<f64> = (0..rows).map(|k| k as f64 * (dt / 2.0)).collect();
    let mut values = vec![0.0; rows * m.nv];
    for (k, &t) in times.iter().enumerate() {
        for j in 0..6 {
            values[k * m.nv + 6 + j] = amp[j] * (2.0 * std::f64::consts::PI * freq[j] * t + phase[j]).sin();
        }
    }
    let torques = TorqueSource::table(times, values, m.nv, Hold::Linear).expect("torque table");
    let opts = SimOptions { t_final, dt, method: Method::Rk4, record_every: 1, max_steps: 50_000_000 };
    let tr = simulate(&m, &q, &v, &opts, Inputs { torques, ..Default::default() }, None).expect("simulation");
    if let Some(path) = std::env::args().nth(2) {
        let all: Vec<u8> = [&tr.q, &tr.v, &tr.momentum, &tr.kinetic_energy, &tr.work]
            .iter()
            .flat_map(|x| x.iter().flat_map(|y| y.to_le_bytes()))
            .collect();
        std::fs::write(path, all).expect("write the trajectory");
    }
    let l = tr.len() - 1;
    println!(
        "{} samples, final kinetic energy {:.17e}, q[end] {:.17e}, momentum {:.17e}",
        tr.len(),
        tr.kinetic_energy[l],
        tr.q[(l + 1) * tr.nq - 1],
        tr.momentum[6 * l + 5]
    );
}
