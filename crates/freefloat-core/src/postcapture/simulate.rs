//! RK4 simulation of the post-capture scenario (Zhang, Yue, Yuan 2020, Sec. V: RK4, step 10⁻³ s).

use super::control::{Controller, PostcaptureControl};
use crate::environment::Environment;
use crate::error::{FfError, Result};
use crate::model::Model;
use crate::sim::actuators::{ActuatorRt, Actuators};
use crate::sim::{simulate, InputTiming, Inputs, Method, Progress, SimOptions, TorqueSource, Trajectory};

/// Simulate from (q0, v0) for `t_final` seconds with RK4 step `dt`, recording every step (the
/// identification integrates the thrust at the step rate). The controller (eqs. 39-40) is
/// evaluated in every Runge-Kutta stage; the recorded `tau` holds its output at each step.
#[allow(clippy::too_many_arguments)]
pub fn simulate_postcapture(
    m: &Model,
    q0: &[f64],
    v0: &[f64],
    control: PostcaptureControl,
    t_final: f64,
    dt: f64,
    record_every: usize,
    progress: Option<Progress>,
) -> Result<Trajectory> {
    simulate_postcapture_with(m, q0, v0, control, t_final, dt, record_every, None, None, progress)
}

/// [`simulate_postcapture`] with actuator models (thrusters with propellant tanks, whose depletion
/// changes the base's inertial parameters along the run; wheels) and an orbital environment, both
/// evaluated by the engine's stepper exactly as `sim::simulate` does. The paper's controller output
/// (the base entries of `tau`) and the thrusters' wrenches add up on the base.
#[allow(clippy::too_many_arguments)]
pub fn simulate_postcapture_with(
    m: &Model,
    q0: &[f64],
    v0: &[f64],
    control: PostcaptureControl,
    t_final: f64,
    dt: f64,
    record_every: usize,
    actuators: Option<Actuators>,
    environment: Option<&Environment>,
    progress: Option<Progress>,
) -> Result<Trajectory> {
    let mut ctl = Controller::new(m, control)?;
    let torques = TorqueSource::Function(Box::new(move |t, q, v, out| ctl.generalized_forces(m, t, q, v, out)));
    // The paper's control law is continuous in time: read it at every stage (not held per step).
    let inputs = Inputs { torques, timing: InputTiming::Stage, actuators, environment, ..Default::default() };
    let opts = SimOptions { t_final, dt, method: Method::Rk4, record_every, max_steps: usize::MAX };
    simulate(m, q0, v0, &opts, inputs, progress)
}

/// The thrusters' wrench on the base (body frame, about the base origin: the base entries of the
/// generalized force, `[f; τ]`, T × 6) and each tank's propellant flow ṁ (kg/s, ≤ 0, T × tanks) at
/// the recorded samples `t` of a run with `propellant` left (T × tanks), from the same
/// `ActuatorRt::forces` the stepper evaluates (the value at t from the right: a firing that starts at t
/// acts). This is what a post-capture identification knows of its commanded thrust. Thrusters on
/// other bodies and wheel imbalance are refused (they are not base thrust).
pub fn thruster_base_wrench(
    m: &Model,
    actuators: &Actuators,
    t: &[f64],
    propellant: &[f64],
) -> Result<(Vec<f64>, Vec<f64>)> {
    if let Some(j) = actuators.thrusters.iter().position(|th| th.body != 0) {
        return Err(FfError::arg(
            &format!("actuators.thrusters[{j}].body"),
            "the post-capture identification reads the base's thrust: put its thrusters on the base",
        ));
    }
    if let Some(j) = actuators.wheels.iter().position(|w| w.static_imbalance != 0.0 || w.dynamic_imbalance != 0.0) {
        return Err(FfError::arg(
            &format!("actuators.wheels[{j}]"),
            "wheel imbalance is an unmeasured disturbance of the base; not supported by the post-capture run",
        ));
    }
    let rt = ActuatorRt::new(m, Some(actuators.clone()), &vec![false; m.nbodies()])?;
    let nt = rt.ntanks();
    if propellant.len() != t.len() * nt {
        return Err(FfError::arg(
            "propellant",
            format!("expected {} × {nt} values, got {}", t.len(), propellant.len()),
        ));
    }
    let (q, v) = (vec![0.0; m.nq], vec![0.0; m.nv]);
    let mut tau = vec![0.0; m.nv];
    let mut fext = vec![0.0; 6 * m.nbodies()];
    let mut mdot = vec![0.0; nt];
    let (mut wrench, mut flow) = (Vec::with_capacity(6 * t.len()), Vec::with_capacity(nt * t.len()));
    for (k, &tk) in t.iter().enumerate() {
        fext.fill(0.0);
        rt.forces(tk, false, &q, &v, &propellant[k * nt..(k + 1) * nt], &mut tau, &mut fext, &mut mdot);
        wrench.extend_from_slice(&fext[..6]);
        flow.extend_from_slice(&mdot);
    }
    Ok((wrench, flow))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::actuators::{Tank, Thruster};
    use crate::spatial::V3;

    /// The base wrench of one thruster is [F d; r × F d] while it fires (closed form, d normalised) and zero
    /// outside its firing; its tank's flow is −F/(Isp g0); an empty tank gives neither.
    #[test]
    fn thruster_base_wrench_is_the_closed_form() {
        let m = crate::model::builtin::load("zhang2020_3d").unwrap();
        let (f, isp) = (40.0, 70.0);
        let th = Thruster {
            body: 0,
            position: V3::new(0.1, -0.2, 0.3),
            direction: V3::new(0.0, 0.0, 2.0),
            max_thrust: f,
            min_on_time: 0.0,
            ramp_on: 0.0,
            ramp_off: 0.0,
            isp: Some(isp),
            tank: Some(0),
            firings: vec![(1.0, 1.0)],
        };
        let tank = Tank { body: 0, position: V3::zeros(), mass: 10.0, radius: 0.0 };
        let acts = Actuators { thrusters: vec![th], tanks: vec![tank], ..Default::default() };
        let t = [0.5, 1.5, 2.5, 1.5];
        let mp = [10.0, 9.0, 8.0, 0.0];
        let (w, flow) = thruster_base_wrench(&m, &acts, &t, &mp).unwrap();
        let expect_on = [0.0, 0.0, f, -0.2 * f, -0.1 * f, 0.0]; // r × (0, 0, F)
        for (k, on) in [false, true, false, false].iter().enumerate() {
            for j in 0..6 {
                let e = if *on { expect_on[j] } else { 0.0 };
                assert!((w[6 * k + j] - e).abs() < 1e-12, "sample {k} entry {j}: {} vs {e}", w[6 * k + j]);
            }
            let e = if *on { -f / (isp * crate::sim::actuators::G0) } else { 0.0 };
            assert!((flow[k] - e).abs() < 1e-15, "sample {k}: flow {} vs {e}", flow[k]);
        }
        let mut off_base = acts.clone();
        off_base.thrusters[0].body = 1;
        assert!(thruster_base_wrench(&m, &off_base, &t, &mp).is_err());
    }

    fn control(nj: usize, f_max: f64) -> PostcaptureControl {
        PostcaptureControl {
            f_max,
            k_f: -1.0,
            m_max: 10.0,
            k_m: -1.0,
            k_d: V3::repeat(std::f64::consts::FRAC_1_SQRT_2),
            k_p: V3::repeat(0.25),
            jet: V3::zeros(),
            damping: 0.2,
            amp: vec![0.02; nj],
            freq: (0..nj).map(|i| 0.3 + 0.1 * i as f64).collect(),
            phase: vec![0.0; nj],
        }
    }

    /// The arm realises eq. (39) exactly: the base yaw follows the closed-form damped oscillation
    /// θ(t) = (θ̇0/ω_d) e^{−σt} sin(ω_d t), σ = K_D/2, ω_d = √(K_P − σ²), to RK4 accuracy.
    #[test]
    fn planar_attitude_follows_eq_39() {
        let m = crate::model::builtin::load("zhang2020_2d_medium").unwrap();
        let d = std::f64::consts::PI / 180.0;
        let q0 = [0.0, 0.0, 0.0, 30.0 * d, 45.0 * d, 45.0 * d];
        let v0 = [1.0, 2.0, 0.1, 0.0, 0.0, 0.0];
        let tr = simulate_postcapture(&m, &q0, &v0, control(3, 10.0), 4.0, 1e-3, 100, None).unwrap();
        let sigma = std::f64::consts::FRAC_1_SQRT_2 / 2.0;
        let wd = (0.25 - sigma * sigma).sqrt();
        let mut worst: f64 = 0.0;
        for (k, &t) in tr.t.iter().enumerate() {
            let exact = 0.1 / wd * (-sigma * t).exp() * (wd * t).sin();
            worst = worst.max((tr.q[k * tr.nq + 2] - exact).abs());
        }
        assert!(worst < 1e-10, "yaw deviates from eq. (39) by {worst:e}");
    }

    /// 3D: the base rotation decays under eq. (39); the linear momentum changes only
    /// through the thrust: |ΔP| ≤ F_max·t per axis (thrust saturated at 10 N, |P| ≫ 10).
    #[test]
    fn spatial_run_is_stabilised() {
        const T: f64 = 8.0;
        let m = crate::model::builtin::load("zhang2020_3d").unwrap();
        let d = std::f64::consts::PI / 180.0;
        let mut q0 = vec![0.0; m.nq];
        q0[6] = 1.0;
        let arm = [20.0, 30.0, 60.0, 20.0, 40.0, 10.0];
        for (i, a) in arm.iter().enumerate() {
            q0[7 + i] = a * d;
        }
        let mut v0 = vec![0.0; m.nv];
        v0[..6].copy_from_slice(&[10.0, 20.0, 30.0, 0.1, 0.2, 0.3]);
        let tr = simulate_postcapture(&m, &q0, &v0, control(6, 10.0), T, 1e-3, 1000, None).unwrap();
        let last = tr.len() - 1;
        let w = &tr.v[last * tr.nv + 3..last * tr.nv + 6];
        let w_norm = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        // e^{−σ T} with σ = K_D/2 ≈ 0.354 is 0.06 at T = 8 s
        assert!(w_norm < 0.1 * 0.14f64.sqrt(), "base still rotating: {w:?}");
        for ax in 0..3 {
            let dp = tr.momentum[last * 6 + ax] - tr.momentum[ax];
            assert!(dp.abs() <= 10.0 * T * (1.0 + 1e-9), "axis {ax}: ΔP = {dp}");
            assert!(dp.abs() >= 10.0 * T * (1.0 - 1e-6), "axis {ax}: thrust not saturated, ΔP = {dp}");
        }
    }
}
