//! Runs are sized up front and stoppable: fallible reservation of the trajectory, refusal of a fixed-step run
//! longer than `max_steps` and of an unattainable RK45 tolerance, and a progress hook's `false` reported as an
//! interruption carrying the samples recorded so far.

use freefloat_core::error::Partial;
use freefloat_core::model::builtin;
use freefloat_core::sim::{self, Inputs, Method, SimOptions, Trajectory};
use freefloat_core::FfError;

fn robot() -> freefloat_core::Model {
    builtin::load("naveen_dual_arm").expect("built-in")
}

fn opts(t_final: f64, dt: f64) -> SimOptions {
    SimOptions { t_final, dt, method: Method::Rk4, record_every: 1, max_steps: usize::MAX }
}

#[test]
fn a_trajectory_too_large_to_allocate_is_an_error_not_an_abort() {
    let m = robot();
    // 2^60 samples: the byte count overflows or the allocator refuses; either way an error naming the size
    match Trajectory::with_capacity(&m, 1usize << 60) {
        Err(FfError::Argument { name, msg }) => {
            assert_eq!(name, "t_final");
            assert!(msg.contains("could not be allocated") && msg.contains("GB"), "{msg}");
        }
        other => panic!("expected an argument error, got {:?}", other.map(|t| t.len())),
    }
    assert!(Trajectory::with_capacity(&m, 10).is_ok());
}

#[test]
fn an_absurd_simulation_is_refused_before_any_work() {
    let m = robot();
    let q0 = m.neutral();
    let v0 = vec![0.0; m.nv];
    let t = std::time::Instant::now();
    let r = sim::simulate(&m, &q0, &v0, &opts(1e9, 1e-3), Inputs::default(), None);
    assert!(t.elapsed().as_secs_f64() < 1.0);
    match r {
        Err(FfError::Argument { name, .. }) => assert_eq!(name, "t_final"),
        other => panic!("expected a refusal, got {:?}", other.map(|t| t.len())),
    }
    // the planned size is what the refusal is computed from
    let o = opts(1.0, 1e-3);
    assert_eq!(sim::planned_samples(&o), 1002.0);
    assert_eq!(sim::planned_bytes(&m, &o), 1002.0 * (8 * (m.nq + 3 * m.nv + 9)) as f64);
}

#[test]
fn rk4_longer_than_max_steps_is_refused_up_front() {
    let m = robot();
    let mut o = opts(10.0, 1e-3);
    o.max_steps = 100;
    match sim::simulate(&m, &m.neutral(), &vec![0.0; m.nv], &o, Inputs::default(), None) {
        Err(FfError::Argument { name, msg }) => assert!(name == "t_final" && msg.contains("max_steps"), "{msg}"),
        other => panic!("expected a refusal, got {:?}", other.map(|t| t.len())),
    }
}

#[test]
fn rk45_tolerance_below_round_off_is_refused() {
    let m = robot();
    let mut o = opts(1.0, 0.1);
    o.method = Method::Rk45 { rtol: 1e-20, atol: 1e-12, max_step: f64::INFINITY };
    match sim::simulate(&m, &m.neutral(), &vec![0.1; m.nv], &o, Inputs::default(), None) {
        Err(FfError::Argument { name, msg }) => {
            assert_eq!(name, "rtol");
            assert!(msg.contains("machine epsilon") && msg.contains(&format!("{:.1e}", sim::MIN_RTOL)), "{msg}");
        }
        other => panic!("expected a refusal, got {:?}", other.map(|t| t.len())),
    }
}

#[test]
fn a_hook_returning_false_interrupts_with_the_samples_so_far() {
    let m = robot();
    let v0 = vec![0.01; m.nv];
    let mut o = opts(1e4, 1e-3);
    o.record_every = 100;
    let mut calls = 0;
    let mut hook = |_f: f64| {
        calls += 1;
        calls < 3
    };
    let t = std::time::Instant::now();
    let r = sim::simulate(&m, &m.neutral(), &v0, &o, Inputs::default(), Some(&mut hook));
    // three polls at least 20 ms apart: well under a second, not the minutes the whole run takes
    assert!(t.elapsed().as_secs_f64() < 5.0);
    match r {
        Err(FfError::Interrupted { msg, partial: Some(Partial::Trajectory(tr)) }) => {
            assert!(msg.contains("t = "), "{msg}");
            assert!(tr.len() >= 2 && *tr.t.last().unwrap() < 1e4);
            assert_eq!(tr.q.len(), tr.len() * m.nq);
            assert!(tr.steps > 0);
        }
        other => panic!("expected an interruption with a partial trajectory, got {:?}", other.map(|t| t.len())),
    }
}
