//! Estimator update rate measured in CPU time of this process (utime + stime from /proc/self/stat),
//! next to wall time: on a shared machine the wall-clock numbers of `benches/rls.rs` include the
//! time the benchmark was descheduled by other jobs, CPU time does not.
//!
//!     nice cargo bench -p freefloat-core --bench rls_cpu
//!
//! Same problems as `benches/rls.rs`: the standard-parameter RLS on random 3D-like rows (20 unknowns,
//! 6 rows; dense) and the paper's modified RLS (μ ∈ R⁸, θ ∈ R¹², D ∈ R²⁰, 3 + 3 rows).

use freefloat_core::estimation::{CoupledSample, Coupling, ModifiedRls, Rls};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Instant;

const POOL: usize = 256;
const UPDATES: usize = 2_000_000;

/// CPU seconds used by this process so far (Linux; clock ticks of 1/100 s).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // fields after the command name in parentheses; utime and stime are fields 14 and 15
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ut: f64 = f.get(11)?.parse().ok()?;
    let st: f64 = f.get(12)?.parse().ok()?;
    Some((ut + st) / 100.0)
}

fn pool(rows: usize, cols: usize, rng: &mut StdRng) -> Vec<Vec<f64>> {
    (0..POOL).map(|_| (0..rows * cols).map(|_| rng.gen_range(-1.0..1.0)).collect()).collect()
}

fn report(name: &str, f: &mut dyn FnMut(usize)) {
    let (c0, w0) = (cpu_seconds(), Instant::now());
    for k in 0..UPDATES {
        f(k);
    }
    let wall = w0.elapsed().as_secs_f64();
    let cpu = cpu_seconds().zip(c0).map(|(a, b)| a - b);
    let per = |s: f64| s / UPDATES as f64 * 1e9;
    match cpu {
        Some(c) => println!(
            "{name:<22} wall {:7.1} ns/update ({:5.2} M/s)   cpu {:7.1} ns/update ({:5.2} M/s)",
            per(wall),
            UPDATES as f64 / wall / 1e6,
            per(c),
            UPDATES as f64 / c / 1e6
        ),
        None => println!("{name:<22} wall {:7.1} ns/update (cpu time unavailable)", per(wall)),
    }
}

fn main() {
    // `cargo bench` passes --bench; nothing to parse
    let mut rng = StdRng::seed_from_u64(3);
    let (phi, y) = (pool(6, 20, &mut rng), pool(6, 1, &mut rng));
    let mut est = Rls::new(&[0.0; 20], &[1e6; 20], 0.999).expect("valid prior");
    report("rls_dense_20x6", &mut |k| {
        let i = k % POOL;
        est.update(k as f64, black_box(&phi[i]), black_box(&y[i])).expect("update");
    });
    let (a, bb) = (pool(3, 8, &mut rng), pool(3, 1, &mut rng));
    let (ph, yy, psi) = (pool(3, 12, &mut rng), pool(3, 1, &mut rng), pool(3, 20, &mut rng));
    let mu0 = [600.0, 0.0, 0.0, 0.0, 100.0, 10.0, 10.0, 10.0];
    let th0 = [100.0, 0.0, 0.0, 100.0, 0.0, 100.0, 10.0, 0.0, 0.0, 10.0, 0.0, 10.0];
    let fresh = || ModifiedRls::new(Coupling::Spatial, &mu0, &[1e6; 8], &th0, &[1e6; 12]).expect("valid prior");
    let mut m = fresh();
    report("modified_rls_3d", &mut |k| {
        let i = k % POOL;
        if k % 4096 == 4095 {
            m = fresh();
        }
        let s = CoupledSample { t: k as f64, a: &a[i], b: &bb[i], phi: &ph[i], y: &yy[i], psi: &psi[i] };
        m.update(black_box(&s)).expect("update");
    });
}
