//! Update rate of the online estimators on the seed 000 3D problem (issue 3 target: ≥ 10⁶ updates/s).
//!
//!     nice cargo bench -p freefloat-core --bench rls
//!
//! - `rls_standard_3d`: ordinary RLS, 20 unknowns (standard parameters of base and target), 6 rows
//!   per sample (linear + angular momentum or Newton-Euler).
//! - `modified_rls_3d`: the paper's modified RLS (eqs. 34-38): μ ∈ R⁸ from 3 rows, θ ∈ R¹² from
//!   3 rows, D(μ) ∈ R²⁰ (so M is 12 × 20).
//!
//! Samples are random but well scaled (a fixed pool of 256, cycled), so the numbers are per update.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use freefloat_core::estimation::{CoupledSample, Coupling, ModifiedRls, Rls};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

const POOL: usize = 256;

fn pool(rows: usize, cols: usize, rng: &mut StdRng) -> Vec<Vec<f64>> {
    (0..POOL).map(|_| (0..rows * cols).map(|_| rng.gen_range(-1.0..1.0)).collect()).collect()
}

fn bench(c: &mut Criterion) {
    let mut rng = StdRng::seed_from_u64(3);
    let mut g = c.benchmark_group("estimator_update");
    g.throughput(Throughput::Elements(1));

    let (phi, y) = (pool(6, 20, &mut rng), pool(6, 1, &mut rng));
    let mut est = Rls::new(&[0.0; 20], &[1e6; 20], 0.999).expect("valid prior");
    let mut k = 0usize;
    g.bench_function("rls_standard_3d", |b| {
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
            if k % 4096 == 0 {
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
