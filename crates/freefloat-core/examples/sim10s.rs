//! A 10 s, 1 kHz RK4 simulation of the Naveen, Shah, Misra robot (`naveen_dual_arm`) with smooth arm torques: a fixed
//! workload for instruction counting (`valgrind --tool=callgrind`), which, unlike wall time, does not depend on what
//! else the shared machine is doing.
//!
//!     cargo build --release --example sim10s && valgrind --tool=callgrind target/release/examples/sim10s

use freefloat_core::model::builtin;
use freefloat_core::sim::{simulate, Inputs, Method, SimOptions, TorqueSource};

fn main() {
    let m = builtin::load("naveen_dual_arm").expect("built-in model");
    let mut q = m.neutral();
    q[0..3].copy_from_slice(&[0.5, -0.2, 0.1]);
    let mut v = vec![0.0; m.nv];
    v[..6].copy_from_slice(&[0.01, -0.02, 0.005, 0.01, 0.02, -0.015]);
    let amp = [20.0, 15.0, 8.0, 20.0, 12.0, 10.0];
    let torques = TorqueSource::Function(Box::new(move |t, _q, _v, out| {
        out.fill(0.0);
        for j in 0..6 {
            out[6 + j] = amp[j] * (2.0 * std::f64::consts::PI * (0.2 + 0.05 * j as f64) * t).sin();
        }
        Ok(())
    }));
    let opts = SimOptions { t_final: 10.0, dt: 1e-3, method: Method::Rk4, record_every: 1, max_steps: 1_000_000 };
    let tr = simulate(&m, &q, &v, &opts, Inputs { torques, ..Default::default() }, None).expect("simulation");
    println!("{} samples, final kinetic energy {:.6}", tr.len(), tr.kinetic_energy[tr.len() - 1]);
}
