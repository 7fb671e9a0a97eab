//! The online estimators allocate nothing per update (the 10⁶ updates/s target of the Zhang, Yue, Yuan 2020
//! 3D post-capture problem): a counting global allocator counts the allocations of 1,000 updates, which must be
//! zero, for the ordinary RLS (20 unknowns, 6 rows, forgetting) and the paper's modified RLS (μ ∈ R⁸, θ ∈ R¹²,
//! D ∈ R²⁰), and for a size without a constant-size kernel (n = 7).

use freefloat_core::estimation::{CoupledSample, Coupling, ModifiedRls, Rls};

mod counting_alloc;
use counting_alloc::count;

fn rows(seed: u64, len: usize) -> Vec<f64> {
    // a small deterministic generator: the test needs varied, well-scaled rows, not statistics
    let mut x = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (0..len)
        .map(|_| {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}

#[test]
fn rls_updates_allocate_nothing() {
    for n in [20usize, 7] {
        let phi: Vec<Vec<f64>> = (0..64).map(|k| rows(k, 6 * n)).collect();
        let y: Vec<Vec<f64>> = (0..64).map(|k| rows(100 + k, 6)).collect();
        let mut est = Rls::new(&vec![0.0; n], &vec![1e3; n], 0.999).expect("valid prior");
        est.update(0.0, &phi[0], &y[0]).expect("update");
        let allocs = count(|| {
            for k in 1..1001 {
                est.update(k as f64, &phi[k % 64], &y[k % 64]).expect("update");
            }
        });
        assert_eq!(allocs, 0, "n = {n}: 1,000 RLS updates made {allocs} allocations");
        assert!(est.estimate().iter().all(|x| x.is_finite()));
    }
}

#[test]
fn modified_rls_updates_allocate_nothing() {
    let (a, b) =
        ((0..64).map(|k| rows(k, 24)).collect::<Vec<_>>(), (0..64).map(|k| rows(200 + k, 3)).collect::<Vec<_>>());
    let (phi, y) =
        ((0..64).map(|k| rows(300 + k, 36)).collect::<Vec<_>>(), (0..64).map(|k| rows(400 + k, 3)).collect::<Vec<_>>());
    let psi: Vec<Vec<f64>> = (0..64).map(|k| rows(500 + k, 60)).collect();
    let mu0 = [600.0, 0.0, 0.0, 0.0, 100.0, 10.0, 10.0, 10.0];
    let th0 = [100.0, 0.0, 0.0, 100.0, 0.0, 100.0, 10.0, 0.0, 0.0, 10.0, 0.0, 10.0];
    let mut m = ModifiedRls::new(Coupling::Spatial, &mu0, &[1e2; 8], &th0, &[1e2; 12]).expect("valid prior");
    let sample = |k: usize| CoupledSample {
        t: k as f64,
        a: &a[k % 64],
        b: &b[k % 64],
        phi: &phi[k % 64],
        y: &y[k % 64],
        psi: &psi[k % 64],
    };
    m.update(&sample(0)).expect("update");
    let allocs = count(|| {
        for k in 1..1001 {
            m.update(&sample(k)).expect("update");
        }
    });
    assert_eq!(allocs, 0, "1,000 modified-RLS updates made {allocs} allocations");
    assert!(m.mu().iter().chain(m.theta()).all(|x| x.is_finite()));
}
