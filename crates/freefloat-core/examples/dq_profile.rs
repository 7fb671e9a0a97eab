//! Profiling helper: many dq_dynamics evaluations on the chapter-7 robot (`perf record` target).
use freefloat_core::dqdynamics::dq_dynamics;
use freefloat_core::model::builtin;
use freefloat_core::Data;

fn main() {
    let m = builtin::load("valverde_ch7_two_arm").expect("built-in");
    let q = m.neutral();
    let v: Vec<f64> = (0..m.nv).map(|k| 0.1 * (k as f64).sin()).collect();
    let tau: Vec<f64> = (0..m.nv).map(|k| 0.2 * (k as f64).cos()).collect();
    let t0 = std::time::Instant::now();
    let n = 200_000;
    let mut s = 0.0;
    let mut d = Data::new(&m);
    for _ in 0..n {
        s += dq_dynamics(&m, &mut d, &q, &v, &tau, None, None).map(|r| r.ddq[7]).unwrap_or(0.0);
    }
    println!("{:.2} us per call ({s})", t0.elapsed().as_secs_f64() * 1e6 / n as f64);
}
