//! Fixed workloads for the two stages of momentum identification (Naveen, Shah, Misra, eqs. 26-27), for
//! instruction counts (`valgrind --tool=callgrind`) and indicative wall times:
//! - `pass MODEL SAMPLES`: the streaming regressor build (kinematics, the kept columns, the right-hand side) over
//!   deterministic states, every column of the non-root bodies kept (no solve);
//! - `gram REPS`: the Gram accumulation alone, one block of 64 samples (192 angular rows x 53 columns) REPS times,
//!   twice: by the general `GramLs` (column-major blocks, matrixmultiply) and by the row kernel of the
//!   identification's Gram pass (`gram_rows_upper`, the same rows row-major), with their checksums;
//! - `identify FILE REPS`: the whole identification (`identify_momentum`) REPS times on the problem of
//!   `benches/identify_vs_numpy.py` (67,000 samples of naveen_dual_arm, 52 minimal parameters), written to FILE
//!   by `python benches/identify_dump.py FILE`: per-run wall and process CPU time (median, min), the estimate's
//!   checksum.
//!
//! Build and run:
//!
//!     cargo build --release -p freefloat-core --example identify_profile
//!     target/release/examples/identify_profile pass naveen_dual_arm 20000
//!     target/release/examples/identify_profile gram 20000
//!     python benches/identify_dump.py /tmp/naveen67k.bin
//!     target/release/examples/identify_profile identify /tmp/naveen67k.bin 20
use freefloat_core::estimation::{
    gram_rows_upper, identify_momentum, momentum_regressor_pass, GramLs, MomentumProblem, GRAM_TILE,
};
use freefloat_core::model::builtin;
use nalgebra::DMatrix;
use std::time::Instant;

/// A deterministic, well-mixed number in [-0.5, 0.5) (no randomness crate needed for a timing workload).
fn mix(i: usize, j: usize) -> f64 {
    ((i * 37 + j * 101) % 97) as f64 / 97.0 - 0.5
}

fn pass(model: &str, t: usize) {
    let m = builtin::load(model).expect("built-in model");
    let mut q = Vec::with_capacity(t * m.nq);
    let mut v = Vec::with_capacity(t * m.nv);
    for s in 0..t {
        let mut qs = m.neutral();
        for (k, x) in qs.iter_mut().enumerate() {
            *x += 3.0 * mix(s, k);
        }
        let n = qs[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
        qs[3..7].iter_mut().for_each(|x| *x /= n);
        q.extend_from_slice(&qs);
        v.extend((0..m.nv).map(|k| mix(s + 7, k)));
    }
    let h: Vec<f64> = (0..6 * t).map(|k| mix(k, 3)).collect();
    let unknown: Vec<usize> = (10..10 * m.nbodies()).collect();
    let known = vec![0.0; 10 * m.nbodies()];
    let p = MomentumProblem { q: &q, v: &v, h: &h, unknown_cols: &unknown, known_params: &known, weights: None };
    let t0 = Instant::now();
    let sum = momentum_regressor_pass(&m, &p).expect("regressor pass");
    let dt = t0.elapsed().as_secs_f64();
    println!("{:.1} ns per sample ({} columns), checksum {sum:.6e}", dt / t as f64 * 1e9, unknown.len());
}

fn gram(reps: usize) {
    let (rows, n) = (192, 52);
    let block = DMatrix::from_fn(2 * rows, n + 1, mix);
    let mut g = GramLs::new(n);
    let t0 = Instant::now();
    for _ in 0..reps {
        g.add_augmented_range(&block, rows, rows);
    }
    let dt = t0.elapsed().as_secs_f64();
    let (rss, yty) = g.rss_at(&nalgebra::DVector::zeros(n));
    println!("GramLs: {:.1} ns per sample (3 rows), checksum {rss:.6e} {yty:.6e}", dt / (reps * rows / 3) as f64 * 1e9);
    // the same rows, row-major and padded, through the kernel of the identification's Gram pass
    let w = (n + 1).next_multiple_of(GRAM_TILE);
    let mut b = vec![0.0; rows * w];
    for r in 0..rows {
        for c in 0..=n {
            b[r * w + c] = block[(rows + r, c)];
        }
    }
    let mut acc = vec![0.0; w * w];
    let t0 = Instant::now();
    for _ in 0..reps {
        gram_rows_upper(&mut acc, &b, w, rows, w);
    }
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "row kernel: {:.1} ns per sample (3 rows), checksum {:.6e}",
        dt / (reps * rows / 3) as f64 * 1e9,
        acc[n * w + n]
    );
}

/// Process CPU time (user + system, every thread) in seconds, from /proc/self/stat (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // fields after the command name (which ends at the last ')'): utime and stime are the 12th and 13th
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest.split_whitespace().skip(11).take(2).filter_map(|x| x.parse().ok()).collect();
    f.iter().sum::<f64>() / 100.0 // clock ticks (USER_HZ = 100 on Linux)
}

fn identify(file: &str, reps: usize) {
    let bytes = std::fs::read(file).expect("the problem file (python benches/identify_dump.py FILE)");
    let word = |k: usize| u64::from_le_bytes(bytes[8 * k..8 * k + 8].try_into().expect("8 bytes"));
    let [t, nq, nv, ncols, np] = std::array::from_fn(|k| word(k) as usize);
    let mut at = 5;
    let mut take = |len: usize| -> Vec<f64> {
        let v = (at..at + len).map(|k| f64::from_bits(word(k))).collect();
        at += len;
        v
    };
    let (q, v, h) = (take(t * nq), take(t * nv), take(6 * t));
    let unknown: Vec<usize> = take(ncols).into_iter().map(|c| c as usize).collect();
    let known = take(np);
    let m = builtin::load("naveen_dual_arm").expect("built-in model");
    let p = MomentumProblem { q: &q, v: &v, h: &h, unknown_cols: &unknown, known_params: &known, weights: None };
    let (mut wall, mut cpu, mut sum) = (Vec::new(), Vec::new(), 0.0);
    for _ in 0..reps {
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let r = identify_momentum(&m, &p).expect("identification");
        wall.push(t0.elapsed().as_secs_f64() * 1e3);
        cpu.push((cpu_seconds() - c0) * 1e3);
        sum = r.x.sum();
    }
    let med = |x: &mut Vec<f64>| {
        x.sort_by(f64::total_cmp);
        (x[x.len() / 2], x[0])
    };
    let ((wm, w0), (cm, _)) = (med(&mut wall), med(&mut cpu));
    let cpu_mean = cpu.iter().sum::<f64>() / reps as f64;
    println!("identify: {wm:.2} ms median ({w0:.2} min) wall, {cm:.1} ms median ({cpu_mean:.1} mean) CPU, checksum {sum:.12e}");
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    match (a.get(1).map(String::as_str), a.len()) {
        (Some("pass"), 4) => pass(&a[2], a[3].parse().expect("samples: a whole number")),
        (Some("gram"), 3) => gram(a[2].parse().expect("repetitions: a whole number")),
        (Some("identify"), 4) => identify(&a[2], a[3].parse().expect("repetitions: a whole number")),
        _ => {
            eprintln!(
                "usage: identify_profile pass <builtin model> <samples> | identify_profile gram <repetitions> \
                 | identify_profile identify <problem file> <repetitions>"
            );
            std::process::exit(2);
        }
    }
}
