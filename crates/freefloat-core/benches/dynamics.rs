//! Criterion benchmarks of the engine's core algorithms on the built-in `naveen_dual_arm`
//! (free base + two 3R arms + three reaction wheels: nq = 16, nv = 15), and of a 10 s, 1 kHz RK4
//! simulation with sinusoidal arm torques (the same scenario as benches/compare_pinocchio.py).
//!
//!     cargo bench -p freefloat-core                     # everything
//!     cargo bench -p freefloat-core -- aba              # one group (criterion name filter)
//!     cargo bench -p freefloat-core -- --quick          # faster, less precise (criterion flag)
//!
//! The algorithm benches cycle through a fixed set of 64 random states (seeded), so the branch
//! predictor cannot memorise one input; the numbers are per call.

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion};
use freefloat_core::dynamics::{aba, crba, rnea};
use freefloat_core::kinematics::{centroidal_momentum_matrix, momentum};
use freefloat_core::regressors::{dynamics_regressor, momentum_regressor};
use freefloat_core::sim::{simulate, Hold, Inputs, Method, SimOptions, TorqueSource};
use freefloat_core::{Data, Model};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;
use std::time::Duration;

const MODEL: &str = "naveen_dual_arm";
const NSTATES: usize = 64;

struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    u: Vec<f64>,
}

fn model() -> Model {
    freefloat_core::model::builtin::load(MODEL).expect("built-in model")
}

/// Random states: base position in [-1, 1]³, uniform unit quaternion (x, y, z, w), joint angles in
/// [-π, π], velocities and torques standard normal-ish (uniform [-1, 1] scaled).
fn states(m: &Model) -> Vec<State> {
    let mut rng = StdRng::seed_from_u64(7);
    (0..NSTATES)
        .map(|_| {
            let mut q = m.neutral();
            for x in &mut q[0..3] {
                *x = rng.gen_range(-1.0..1.0);
            }
            let mut quat = [0.0f64; 4];
            loop {
                for x in &mut quat {
                    *x = rng.gen_range(-1.0..1.0);
                }
                let n = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
                if n > 0.1 && n <= 1.0 {
                    for x in &mut quat {
                        *x /= n;
                    }
                    break;
                }
            }
            q[3..7].copy_from_slice(&quat);
            for x in &mut q[7..] {
                *x = rng.gen_range(-PI..PI);
            }
            let v = (0..m.nv).map(|_| rng.gen_range(-1.0..1.0)).collect();
            let u = (0..m.nv).map(|_| rng.gen_range(-10.0..10.0)).collect();
            State { q, v, u }
        })
        .collect()
}

fn algorithms(c: &mut Criterion) {
    let m = model();
    let xs = states(&m);
    let mut d = Data::new(&m);
    let mut k = 0usize;
    let mut next = || {
        k = (k + 1) % NSTATES;
        k
    };

    let mut g = c.benchmark_group(MODEL);
    g.bench_function("aba", |b| {
        b.iter(|| {
            let s = &xs[next()];
            aba(&m, &mut d, black_box(&s.q), black_box(&s.v), black_box(&s.u), None).unwrap();
            black_box(d.ddq[0]);
        })
    });
    g.bench_function("rnea", |b| {
        b.iter(|| {
            let s = &xs[next()];
            rnea(&m, &mut d, black_box(&s.q), black_box(&s.v), black_box(&s.u), None).unwrap();
            black_box(d.tau[0]);
        })
    });
    g.bench_function("crba", |b| {
        b.iter(|| {
            let s = &xs[next()];
            crba(&m, &mut d, black_box(&s.q)).unwrap();
            black_box(d.mass_matrix[(0, 0)]);
        })
    });
    g.bench_function("momentum", |b| {
        b.iter(|| {
            let s = &xs[next()];
            black_box(momentum(&m, &mut d, black_box(&s.q), black_box(&s.v)).unwrap());
        })
    });
    g.bench_function("centroidal_momentum_matrix", |b| {
        b.iter(|| {
            let s = &xs[next()];
            centroidal_momentum_matrix(&m, &mut d, black_box(&s.q)).unwrap();
            black_box(d.jac[(0, 0)]);
        })
    });
    let mut y = nalgebra::DMatrix::zeros(m.nv, 10 * m.nbodies());
    g.bench_function("dynamics_regressor", |b| {
        b.iter(|| {
            let s = &xs[next()];
            dynamics_regressor(&m, &mut d, black_box(&s.q), black_box(&s.v), black_box(&s.u), &mut y).unwrap();
            black_box(y[(0, 0)]);
        })
    });
    let mut kr = nalgebra::DMatrix::zeros(6, 10 * m.nbodies());
    g.bench_function("momentum_regressor", |b| {
        b.iter(|| {
            let s = &xs[next()];
            momentum_regressor(&m, &mut d, black_box(&s.q), black_box(&s.v), &mut kr).unwrap();
            black_box(kr[(0, 0)]);
        })
    });
    g.finish();
}

/// Same scenario as benches/compare_pinocchio.py: tau_j = A_j sin(2π f_j t + φ_j) on the six arm
/// joints (v indices 6..12), wheels free, 10 s at dt = 1e-3 with RK4.
const AMP: [f64; 6] = [20.0, 15.0, 8.0, 20.0, 12.0, 10.0];
const FREQ: [f64; 6] = [0.20, 0.30, 0.50, 0.25, 0.35, 0.45];
const PHASE: [f64; 6] = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5];

fn sin_torques(t: f64, out: &mut [f64]) {
    out.fill(0.0);
    for j in 0..6 {
        out[6 + j] = AMP[j] * (2.0 * PI * FREQ[j] * t + PHASE[j]).sin();
    }
}

fn initial_state(m: &Model) -> (Vec<f64>, Vec<f64>) {
    let mut q = m.neutral();
    q[0..3].copy_from_slice(&[0.5, -0.2, 0.1]);
    // 0.6 rad about (0.3, -0.5, 0.8)/|.|, quaternion (x, y, z, w)
    let ax = [0.3f64, -0.5, 0.8];
    let n = ax.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (s, c) = (0.3f64.sin(), 0.3f64.cos());
    q[3..7].copy_from_slice(&[s * ax[0] / n, s * ax[1] / n, s * ax[2] / n, c]);
    let mut v = vec![0.0; m.nv];
    v[0..6].copy_from_slice(&[0.01, -0.02, 0.005, 0.01, 0.02, -0.015]);
    v[6..12].copy_from_slice(&[0.05, -0.1, 0.08, -0.05, 0.1, -0.07]);
    (q, v)
}

fn simulation(c: &mut Criterion) {
    let m = model();
    let (q0, v0) = initial_state(&m);
    let t_final = 10.0;
    let dt = 1e-3;
    let opts = SimOptions { t_final, dt, method: Method::Rk4, record_every: 1, max_steps: usize::MAX };
    let opts_sparse = SimOptions { record_every: 1000, ..opts };

    let mut g = c.benchmark_group(format!("{MODEL}/sim_rk4_10s_1kHz"));
    g.sample_size(10).measurement_time(Duration::from_secs(10)).warm_up_time(Duration::from_secs(1));
    g.bench_function("closure_torques", |b| {
        b.iter(|| {
            let inputs = Inputs {
                torques: TorqueSource::Function(Box::new(|t, _q, _v, out| {
                    sin_torques(t, out);
                    Ok(())
                })),
                ..Default::default()
            };
            black_box(simulate(&m, &q0, &v0, &opts, inputs, None).unwrap())
        })
    });
    g.bench_function("closure_torques_record_every_1000", |b| {
        b.iter(|| {
            let inputs = Inputs {
                torques: TorqueSource::Function(Box::new(|t, _q, _v, out| {
                    sin_torques(t, out);
                    Ok(())
                })),
                ..Default::default()
            };
            black_box(simulate(&m, &q0, &v0, &opts_sparse, inputs, None).unwrap())
        })
    });
    // Torque table sampled at dt/2 (the RK4 stage times), linear hold; the table is built outside
    // the timing but copied into the source inside it (as the Python front end does).
    let nt = (2.0 * t_final / dt).round() as usize + 1;
    let times: Vec<f64> = (0..nt).map(|k| k as f64 * dt / 2.0).collect();
    let mut values = vec![0.0; nt * m.nv];
    for (k, &t) in times.iter().enumerate() {
        sin_torques(t, &mut values[k * m.nv..(k + 1) * m.nv]);
    }
    g.bench_function("table_torques_linear", |b| {
        b.iter_batched(
            || (times.clone(), values.clone()),
            |(tt, vv)| {
                let inputs =
                    Inputs { torques: TorqueSource::table(tt, vv, m.nv, Hold::Linear).unwrap(), ..Default::default() };
                black_box(simulate(&m, &q0, &v0, &opts, inputs, None).unwrap())
            },
            BatchSize::PerIteration,
        )
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = algorithms, simulation
}
criterion_main!(benches);
