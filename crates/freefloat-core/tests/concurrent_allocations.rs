//! The chapter-9 concurrent-learning run allocates nothing per step (Valverde 2018 §9.5): a counting global
//! allocator counts the allocations of whole runs of different lengths; everything is sized up front, so a
//! 9 s run (filling, replacements, the SVD gain at 4.9 s, the frozen stack after 5 s) must make exactly as many
//! allocations as a 1 s run.

use freefloat_core::estimation::concurrent::{run_cl, ClParams, ClScenario, Excitation, Gain, Noise};
use freefloat_core::model::builtin;

mod counting_alloc;
use counting_alloc::count;

fn scenario(m: &freefloat_core::Model, t_final: f64, noise: Noise, gain: Gain) -> ClScenario {
    ClScenario {
        q0: m.neutral(),
        v0: vec![0.0; m.nv],
        excitation: Excitation::default(),
        params: ClParams { ns: 10, gain, ..ClParams::default() },
        m0: vec![0.1; 7 * m.nbodies()],
        dt: 0.01,
        t_final,
        noise,
        noise_seed: 3,
    }
}

#[test]
fn a_cl_run_allocates_nothing_per_step() {
    let m = builtin::load("valverde_ch9_two_arm").expect("built-in");
    for gain in [Gain::Thesis, Gain::Truncated] {
        for noise in [Noise::default(), Noise { wrench: 1e-3, rate: 1e-5 }] {
            let _ = run_cl(&m, &scenario(&m, 1.0, noise, gain), None).expect("runs");
            let short = count(|| {
                run_cl(&m, &scenario(&m, 1.0, noise, gain), None).expect("runs");
            });
            let long = count(|| {
                run_cl(&m, &scenario(&m, 9.0, noise, gain), None).expect("runs");
            });
            assert_eq!(short, long, "a 9 s run allocates {long} times, a 1 s run {short} (noise {noise:?}, {gain:?})");
        }
    }
}
