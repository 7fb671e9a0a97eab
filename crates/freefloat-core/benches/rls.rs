//! Update rate of the online estimators on the Zhang, Yue, Yuan 2020 3D problem (issue 3 target: ≥ 10⁶ updates/s).
//!
//!     nice cargo bench -p freefloat-core --bench rls
//!
//! - `rls_standard_3d`: ordinary RLS, 20 unknowns (standard parameters of base and target), 6 rows
//!   per sample: the real rows of the 3D problem, i.e. the base and target columns of the engine's
//!   momentum regressor of `zhang2020_3d` at random states (the linear rows have no inertia columns).
//! - `rls_dense_20x6`: the same estimator on dense random rows (no structure to exploit).
//! - `modified_rls_3d`: the paper's modified RLS (eqs. 34-38): μ ∈ R⁸ from 3 rows, θ ∈ R¹² from
//!   3 rows, D(μ) ∈ R²⁰ (so M is 12 × 20).
//!
//! Samples are random but well scaled (a fixed pool of 256, cycled), so the numbers are per update.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use freefloat_core::estimation::{CoupledSample, Coupling, ModifiedRls, Rls};
use freefloat_core::regressors::momentum_regressor;
use freefloat_core::Data;
use nalgebra::DMatrix;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

const POOL: usize = 256;

fn pool(rows: usize, cols: usize, rng: &mut StdRng) -> Vec<Vec<f64>> {
    (0..POOL).map(|_| (0..rows * cols).map(|_| rng.gen_range(-1.0..1.0)).collect()).collect()
}

/// Rows of the 3D standard-parameter momentum regression: base (body 0) and target columns of the
/// momentum regressor at random states (row-major 6 × 20).
fn real_rows(rng: &mut StdRng) -> Vec<Vec<f64>> {
    let m = freefloat_core::model::builtin::load("zhang2020_3d").expect("built-in model");
    let target = m.nbodies() - 1;
    let mut d = Data::new(&m);
    let mut k = DMatrix::zeros(6, 10 * m.nbodies());
    (0..POOL)
        .map(|_| {
            let mut q = vec![0.0; m.nq];
            q[6] = 1.0;
            for x in q.iter_mut().skip(7) {
                *x = rng.gen_range(-3.0..3.0);
            }
            let v: Vec<f64> = (0..m.nv).map(|_| rng.gen_range(-1.0..1.0)).collect();
            momentum_regressor(&m, &mut d, &q, &v, &mut k).unwrap();
            let mut row = Vec::with_capacity(120);
            for r in 0..6 {
                for c in (0..10).chain(10 * target..10 * target + 10) {
                    row.push(k[(r, c)]);
                }
            }
            row
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut rng = StdRng::seed_from_u64(3);
    let mut g = c.benchmark_group("estimator_update");
    g.throughput(Throughput::Elements(1));

    let (real, y) = (real_rows(&mut rng), pool(6, 1, &mut rng));
    let mut est = Rls::new(&[0.0; 20], &[1e6; 20], 0.999).expect("valid prior");
    let mut k = 0usize;
    g.bench_function("rls_standard_3d", |b| {
        b.iter(|| {
            let i = k % POOL;
            k += 1;
            est.update(k as f64, black_box(&real[i]), black_box(&y[i])).expect("update");
        })
    });

    let phi = pool(6, 20, &mut rng);
    let mut est = Rls::new(&[0.0; 20], &[1e6; 20], 0.999).expect("valid prior");
    let mut k = 0usize;
    g.bench_function("rls_dense_20x6", |b| {
        b.iter(|| {
            let i = k % POOL;
            k += 1;
            // a forgetting factor keeps P from shrinking to round-off over millions of samples
            est.update(k as f64, black_box(&phi[i]), black_box(&y[i])).expect("update");
        })
    });

    let (a, bb) = (pool(3, 8, &mut rng), pool(3, 1, &mut rng));
    let (ph, yy, psi) = (pool(3, 12, &mut rng), pool(3, 1, &mut rng), pool(3, 20, &mut rng));
    let mu0 = [600.0, 0.0, 0.0, 0.0, 100.0, 10.0, 10.0, 10.0];
    let th0 = [100.0, 0.0, 0.0, 100.0, 0.0, 100.0, 10.0, 0.0, 0.0, 10.0, 0.0, 10.0];
    // Fresh estimator every 4096 updates: without forgetting P → 0 over millions of random samples.
    let fresh = || ModifiedRls::new(Coupling::Spatial, &mu0, &[1e6; 8], &th0, &[1e6; 12]).expect("valid prior");
    let mut m = fresh();
    let mut k = 0usize;
    g.bench_function("modified_rls_3d", |b| {
        b.iter(|| {
            let i = k % POOL;
            k += 1;
            if k.is_multiple_of(4096) {
                m = fresh();
            }
            let s = CoupledSample { t: k as f64, a: &a[i], b: &bb[i], phi: &ph[i], y: &yy[i], psi: &psi[i] };
            m.update(black_box(&s)).expect("update");
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
