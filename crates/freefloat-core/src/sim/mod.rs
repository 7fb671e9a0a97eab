//! Simulation: explicit Runge-Kutta on the configuration group (RKMK), fixed-step RK4 and adaptive
//! Dormand-Prince 5(4), with joint torques, base thrusters (the base entries of the generalized
//! force), prescribed joint motion (hybrid dynamics) and a sampled controller with zero-order hold.

pub mod actuators;
mod base_poses;
mod batch;
mod inputs;
mod trajectory;

pub use actuators::{Actuators, JointLimit, Tank, Thruster, Wheel};
pub use base_poses::{integrate_base_poses, integrate_planar_base_poses, Steps};
pub use batch::{batch_size, simulate_many, simulate_many_interruptible, BatchSpec, Stacked};
pub use inputs::{Controller, Hold, InputTiming, Prescription, PrescriptionFn, TorqueFn, TorqueSource};
pub use trajectory::{recycle, Trajectory, SPARE_BYTES};

use crate::check::check_vec;
use crate::config::{
    dexpinv_unchecked as dexpinv, retract_unchecked as retract, tangent_magnitude_unchecked as tangent_magnitude,
    tangent_rate_unchecked as tangent_rate,
};
use crate::data::Data;
use crate::dynamics::{hybrid_aba_placed_no_totals_unchecked, hybrid_aba_placed_unchecked, Prescribed};
use crate::environment::{EnvWorkspace, Environment};
use crate::error::{FfError, Partial, Result};
use crate::interrupt::Poller;
use crate::kinematics::forward_kinematics_unchecked;
use crate::model::Model;
use crate::rk::{self, Tableau, DOPRI5, RK4};

/// Integration method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Classical RK4 with fixed step `dt`.
    Rk4,
    /// Dormand-Prince 5(4) with error control; `dt` is then the output interval.
    Rk45 {
        /// Relative tolerance of the local error.
        rtol: f64,
        /// Absolute tolerance of the local error.
        atol: f64,
        /// Largest step (s).
        max_step: f64,
    },
}

/// Options of a simulation.
#[derive(Clone, Copy, Debug)]
pub struct SimOptions {
    /// Simulated duration (s), from t = 0.
    pub t_final: f64,
    /// RK4: the step. RK45: the interval between recorded samples.
    pub dt: f64,
    /// Integration method.
    pub method: Method,
    /// RK4 only: record every n-th step (1 = every step).
    pub record_every: usize,
    /// Give up after this many steps (RK45 runaway protection).
    pub max_steps: usize,
}

/// Which formulation gives the accelerations at every stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Formulation {
    /// The engine's articulated-body algorithm (hybrid ABA with prescribed joints).
    #[default]
    Aba,
    /// The dual-quaternion Newton–Euler system of Valverde 2018, ch. 6 (`dqdynamics`); same results to round-off,
    /// slower, free or fixed base with revolute, prismatic, spherical and fixed joints only.
    DualQuaternion,
}

/// Everything that acts on the robot during a simulation.
pub struct Inputs<'a> {
    /// Generalized forces (joint torques, base thrusters).
    pub torques: TorqueSource<'a>,
    /// A sampled controller whose held output is added to `torques`.
    pub controller: Option<Controller<'a>>,
    /// Joints that follow a prescribed motion (hybrid dynamics).
    pub prescription: Option<Prescription<'a>>,
    /// Wheels, thrusters and tanks (the joint limits of the model always apply).
    pub actuators: Option<Actuators>,
    /// When the torque source is read within a step (default: once per step, held).
    pub timing: InputTiming,
    /// The orbital environment (gravity gradient, J2, disturbance); `None` or all off: no external forces.
    pub environment: Option<&'a Environment>,
}

impl Default for Inputs<'_> {
    fn default() -> Self {
        Inputs {
            torques: TorqueSource::Zero,
            controller: None,
            prescription: None,
            actuators: None,
            timing: InputTiming::PerStep,
            environment: None,
        }
    }
}

/// Optional progress callback: called with the fraction done, returns false to stop the run (polled through
/// [`crate::interrupt::Poller`], at most every 20 ms; a stop is `FfError::Interrupted` carrying the samples
/// recorded so far).
pub type Progress<'a> = crate::interrupt::Hook<'a>;

/// Smallest relative tolerance RK45 accepts: below 100 machine epsilons the local error estimate is
/// round-off and the step size collapses (the bound scipy's `solve_ivp` uses too).
pub const MIN_RTOL: f64 = 100.0 * f64::EPSILON;

/// Number of samples a run will record (as f64, so that an absurd run does not overflow): RK4 records
/// every `record_every`-th of its `round(t_final/dt)` steps and the last; RK45 one sample per `dt`.
pub fn planned_samples(opts: &SimOptions) -> f64 {
    let n = (opts.t_final / opts.dt).round();
    match opts.method {
        Method::Rk4 => (n / opts.record_every.max(1) as f64).floor() + 2.0,
        Method::Rk45 { .. } => (opts.t_final / opts.dt).ceil() + 2.0,
    }
}

/// Bytes the recorded trajectory of a run will take (samples × bytes per sample).
pub fn planned_bytes(m: &Model, opts: &SimOptions) -> f64 {
    planned_samples(opts) * Trajectory::bytes_per_sample(m) as f64
}

/// Work buffers of one simulation.
struct Stepper<'m, 'i> {
    m: &'m Model,
    formulation: Formulation,
    d: Data,
    inputs: Inputs<'i>,
    held: Vec<f64>,
    tau: Vec<f64>,
    /// The shaped command (torque source + controller, after limits and wheel saturation), read at
    /// a step's start and held through its stages (per-step timing).
    cmd: Vec<f64>,
    act: actuators::ActuatorRt,
    /// Per-body external wrenches (nbodies × 6, body frame, about the body origin) that actuators
    /// (and, later, the environment) accumulate into; passed to ABA as `fext`.
    fext: Vec<f64>,
    /// Propellant left in each tank: at the step's start, at the current stage, at the step's end;
    /// its rate at every stage.
    mp: Vec<f64>,
    mps: Vec<f64>,
    mp1: Vec<f64>,
    /// A copy of the model whose tank bodies' inertias follow the propellant (tanks only).
    var_model: Option<Model>,
    presc_mask: Vec<bool>,
    presc_q: Vec<f64>,
    presc_v: Vec<f64>,
    presc_a: Vec<f64>,
    qs: Vec<f64>,
    vs: Vec<f64>,
    /// One row per Runge-Kutta stage, the rate of everything integrated (`Rates` names the parts):
    /// `[tangent rate of q (nv) | acceleration (nv) | propellant flow (tanks) | power (1)]`.
    k: Vec<Vec<f64>>,
    /// The stage increment `h Σⱼ a_sj k_j` (then the step's), laid out as a row of `k`.
    delta: Vec<f64>,
    /// RK45 error control: tangent magnitudes at both ends of a step
    mag0: Vec<f64>,
    mag1: Vec<f64>,
    evals: usize,
    /// The torque table's row at the last read (where the next read starts looking, see `TorqueSource::eval_near`).
    table_row: usize,
    /// The environment's workspace; its `fext` holds the per-body external wrenches of the current stage.
    env: Option<EnvWorkspace>,
}

/// Result of one derivative evaluation at a stage.
impl<'m, 'i> Stepper<'m, 'i> {
    fn new(m: &'m Model, mut inputs: Inputs<'i>, stages: usize) -> Result<Self> {
        let mut presc_mask = vec![false; m.nbodies()];
        if let Some(p) = &inputs.prescription {
            for &b in &p.bodies {
                if b >= m.nbodies() || m.nvs[b] == 0 {
                    return Err(FfError::arg("prescribed", format!("body index {b} has no moving joint to prescribe")));
                }
                presc_mask[b] = true;
            }
        }
        let act = actuators::ActuatorRt::new(m, inputs.actuators.take(), &presc_mask)?;
        let nt = act.ntanks();
        let mut mp = vec![0.0; nt];
        act.initial_propellant(&mut mp);
        let var_model = if act.depletes() { Some(m.clone()) } else { None };
        Ok(Stepper {
            m,
            formulation: Formulation::Aba,
            d: Data::new(m),
            inputs,
            held: vec![0.0; m.nv],
            tau: vec![0.0; m.nv],
            cmd: vec![0.0; m.nv],
            act,
            fext: vec![0.0; 6 * m.nbodies()],
            mps: mp.clone(),
            mp1: mp.clone(),
            mp,
            var_model,
            presc_mask,
            presc_q: vec![0.0; m.nq],
            presc_v: vec![0.0; m.nv],
            presc_a: vec![0.0; m.nv],
            qs: vec![0.0; m.nq],
            vs: vec![0.0; m.nv],
            k: vec![vec![0.0; 2 * m.nv + nt + 1]; stages],
            delta: vec![0.0; 2 * m.nv + nt + 1],
            mag0: vec![0.0; m.nv],
            mag1: vec![0.0; m.nv],
            evals: 0,
            table_row: 0,
            env: None,
        })
    }

    /// Overwrite the prescribed joints' q, v with their prescription at time t.
    #[inline]
    fn impose(&mut self, t: f64, q: &mut [f64], v: &mut [f64]) -> Result<()> {
        // Inlined test, out-of-line work: most runs prescribe nothing, and the call cost more than the test.
        if self.inputs.prescription.is_none() {
            return Ok(());
        }
        self.impose_prescribed(t, q, v)
    }

    #[inline(never)]
    fn impose_prescribed(&mut self, t: f64, q: &mut [f64], v: &mut [f64]) -> Result<()> {
        let Some(p) = self.inputs.prescription.as_mut() else { return Ok(()) };
        (p.f)(t, &mut self.presc_q, &mut self.presc_v, &mut self.presc_a)?;
        let m = self.m;
        for (i, _) in self.presc_mask.iter().enumerate().filter(|(_, &b)| b) {
            let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
            q[iq..iq + m.nqs[i]].copy_from_slice(&self.presc_q[iq..iq + m.nqs[i]]);
            v[iv..iv + m.nvs[i]].copy_from_slice(&self.presc_v[iv..iv + m.nvs[i]]);
        }
        Ok(())
    }

    /// Derivative at (t, qs, vs) into stage `s`: tangent rate, acceleration, power. Leaves the joint
    /// accelerations and forces of this evaluation in `self.d`.
    fn eval(&mut self, t: f64, s: usize) -> Result<()> {
        let mut k = std::mem::take(&mut self.k);
        let r = self.eval_into(t, s, &mut k[s]);
        self.k = k;
        r
    }

    /// `eval` writing the stage's rates into `ks` (a row of `k`).
    fn eval_into(&mut self, t: f64, s: usize, ks: &mut [f64]) -> Result<()> {
        let m = self.m;
        let (nv, nt) = (m.nv, self.mp.len());
        let (kq, rest) = ks.split_at_mut(nv);
        let (kv, rest) = rest.split_at_mut(nv);
        let (kmp, kw) = rest.split_at_mut(nt);
        let kw = &mut kw[0];
        let (mut qs, mut vs) = (std::mem::take(&mut self.qs), std::mem::take(&mut self.vs));
        self.impose(t, &mut qs, &mut vs)?;
        // The command: read at the step's start (stage 0) and held, or at every stage (see InputTiming).
        if s == 0 || self.inputs.timing == InputTiming::Stage || self.inputs.torques.continuous() {
            self.inputs.torques.eval_near(t, &qs, &vs, &mut self.cmd, &mut self.table_row)?;
            if self.inputs.controller.is_some() {
                // the controller's held output (zero without a controller: nothing to add)
                for (x, h) in self.cmd.iter_mut().zip(&self.held) {
                    *x += h;
                }
            }
            self.act.command(&vs, &mut self.cmd);
        }
        self.tau.copy_from_slice(&self.cmd);
        // Actuator forces at this stage: wheel friction, external wrenches, propellant flow.
        self.act.forces(t, s > 0, &qs, &vs, &self.mps, &mut self.tau, &mut self.fext, kmp);
        if let Some(vm) = self.var_model.as_mut() {
            self.act.deplete(vm, &self.mps);
        }
        let ma: &Model = self.var_model.as_ref().unwrap_or(m);
        // The environment's per-body wrenches at this stage (from the placements, computed here once and shared
        // with ABA), added to the actuators' external wrenches; both in ABA's `fext` convention.
        let mut any_fext = self.act.uses_fext;
        let mut placed = false;
        if let (Some(ws), Some(env)) = (self.env.as_mut(), self.inputs.environment) {
            // ABA below reuses these placements instead of repeating the pass (they depend on q alone).
            forward_kinematics_unchecked(ma, &mut self.d, &qs);
            placed = true;
            ws.eval(env, ma, &self.d, t);
            if any_fext {
                for (a, b) in self.fext.iter_mut().zip(&ws.fext) {
                    *a += b;
                }
            } else {
                self.fext.copy_from_slice(&ws.fext);
            }
            any_fext = true;
        }
        let fext = if any_fext { Some(&self.fext[..]) } else { None };
        let presc =
            self.inputs.prescription.as_ref().map(|_| Prescribed { mask: &self.presc_mask, ddq: &self.presc_a });
        match self.formulation {
            Formulation::Aba => {
                if !placed {
                    forward_kinematics_unchecked(ma, &mut self.d, &qs);
                }
                // The momentum and kinetic energy are recorded only with a step's first stage (the state itself):
                // the other stages skip summing them.
                if s == 0 {
                    hybrid_aba_placed_unchecked(ma, &mut self.d, &vs, &self.tau, fext, presc)?
                } else {
                    hybrid_aba_placed_no_totals_unchecked(ma, &mut self.d, &vs, &self.tau, fext, presc)?
                }
            }
            Formulation::DualQuaternion => {
                // same outputs as hybrid ABA: all accelerations, and tau with the prescribed joints' needs
                let (mask, ddq) = match presc {
                    Some(p) => (Some(p.mask), Some(p.ddq)),
                    None => (None, None),
                };
                crate::dqdynamics::solve_system_unchecked(ma, &mut self.d, &qs, &vs, &self.tau, fext, mask, ddq)?;
                let d = &mut self.d;
                d.ddq.copy_from_slice(&d.dq.out.ddq);
                d.tau.copy_from_slice(&self.tau);
                // recorded conservation quantities from the formulation's own algebra, (2.53)/(2.54)
                d.aba_momentum = d.dq.out.momentum;
                d.aba_kinetic_energy = d.dq.out.kinetic_energy;
                for (i, &on) in self.presc_mask.iter().enumerate() {
                    if on && presc.is_some() {
                        let k = m.idx_v[i];
                        d.tau[k..k + m.nvs[i]].copy_from_slice(&d.dq.out.locked_forces[k..k + m.nvs[i]]);
                    }
                }
            }
        }
        if let Some(k) = self.d.ddq.iter().position(|x| !x.is_finite()) {
            return Err(FfError::Numerical(format!("acceleration {k} became non-finite at t = {t}")));
        }
        tangent_rate(m, &qs, &vs, kq);
        kv.copy_from_slice(&self.d.ddq);
        *kw = self.d.tau.iter().zip(&vs).map(|(a, b)| a * b).sum();
        if fext.is_some() && self.formulation == Formulation::Aba {
            // Power of the external wrenches: ABA summed each one's inertial-frame image on its body's twist.
            *kw += self.d.aba_fext_power;
        } else if fext.is_some() {
            // The same sum here (the dual-quaternion solve leaves the placements and the twists at the inertial
            // origin in `d` but not this sum).
            let d = &self.d;
            for (i, fe) in self.fext.chunks_exact(6).enumerate() {
                // most bodies carry none (a thruster on the base): skip their frame change
                if fe.iter().all(|&x| x == 0.0) {
                    continue;
                }
                let f = crate::spatial::Force::from_slice(fe);
                *kw += d.ov[i].dot(&d.o_mi[i].act_force(&f));
            }
        }
        self.evals += 1;
        self.qs = qs;
        self.vs = vs;
        Ok(())
    }

    /// One Runge-Kutta step from (t, q0, v0, w0). Stage 0 must already hold f(y0) (see `eval`).
    /// Writes the new state into q1, v1 and returns (w1, error norm or 0). The stage loop is the engine's one
    /// (`rk::step`); this supplies the stage: `q_s = q0 ⊕ δq` (`config::retract`), `v_s = v0 + δv`, the propellant
    /// `mp + δmp`, the rates there, and the tangent rate mapped through dexp⁻¹(δq) (RKMK).
    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        tab: &Tableau,
        t: f64,
        h: f64,
        q0: &[f64],
        v0: &[f64],
        w0: f64,
        q1: &mut [f64],
        v1: &mut [f64],
        tol: Option<(f64, f64)>,
    ) -> Result<(f64, f64)> {
        let m = self.m;
        let (nv, nt) = (m.nv, self.mp.len());
        let (q0, v0, v1) = (&q0[..m.nq], &v0[..nv], &mut v1[..nv]);
        let (mut k, mut delta) = (std::mem::take(&mut self.k), std::mem::take(&mut self.delta));
        let r = rk::step(tab, t, h, &mut k, &mut delta, |s, ts, dl, ks| {
            let (dq, rest) = dl.split_at(nv);
            let (dv, dmp) = rest.split_at(nv);
            let vs = &mut self.vs[..nv];
            for i in 0..nv {
                vs[i] = v0[i] + dv[i];
            }
            retract(m, q0, dq, &mut self.qs);
            for i in 0..nt {
                self.mps[i] = self.mp[i] + dmp[i];
            }
            self.eval_into(ts, s, ks)?;
            dexpinv(m, dq, &mut ks[..nv]);
            Ok(())
        });
        self.k = k;
        if let Err(e) = r {
            self.delta = delta;
            return Err(e);
        }
        let (dq, rest) = delta.split_at(nv);
        let (dv, rest) = rest.split_at(nv);
        let (dmp, dw) = rest.split_at(nt);
        let w1 = w0 + dw[0];
        for i in 0..nv {
            v1[i] = v0[i] + dv[i];
        }
        for i in 0..nt {
            self.mp1[i] = self.mp[i] + dmp[i];
        }
        retract(m, q0, dq, q1);
        self.delta = delta;
        let mut err = 0.0;
        if let (Some(e), Some((rtol, atol))) = (tab.e, tol) {
            // Hairer's RMS error norm over the tangent coordinates of q and over v.
            let (mag0, mag1) = (&mut self.mag0, &mut self.mag1);
            tangent_magnitude(m, q0, mag0);
            tangent_magnitude(m, q1, mag1);
            let mut acc = 0.0;
            for k in 0..nv {
                let (mut eq, mut ev) = (0.0, 0.0);
                for (j, ej) in e.iter().enumerate() {
                    eq += ej * self.k[j][k];
                    ev += ej * self.k[j][nv + k];
                }
                let sq = atol + rtol * mag0[k].max(mag1[k]);
                let sv = atol + rtol * v0[k].abs().max(v1[k].abs());
                acc += (h * eq / sq).powi(2) + (h * ev / sv).powi(2);
            }
            err = (acc / (2 * nv).max(1) as f64).sqrt();
        }
        Ok((w1, err))
    }
}

/// Simulate from (q0, v0) over [0, t_final].
pub fn simulate(
    m: &Model,
    q0: &[f64],
    v0: &[f64],
    opts: &SimOptions,
    inputs: Inputs,
    progress: Option<Progress>,
) -> Result<Trajectory> {
    simulate_with(m, q0, v0, opts, inputs, Formulation::Aba, progress)
}

/// `simulate` with a choice of the formulation that computes the accelerations.
pub fn simulate_with(
    m: &Model,
    q0: &[f64],
    v0: &[f64],
    opts: &SimOptions,
    inputs: Inputs,
    formulation: Formulation,
    progress: Option<Progress>,
) -> Result<Trajectory> {
    let mut qbuf = Vec::new();
    let q0 = m.checked_q(q0, &mut qbuf)?.to_vec();
    check_vec("v0", v0, m.nv)?;
    if !(opts.t_final > 0.0) || !opts.t_final.is_finite() {
        return Err(FfError::arg("t_final", format!("must be positive and finite, got {}", opts.t_final)));
    }
    if !(opts.dt > 0.0) || !opts.dt.is_finite() || opts.dt > opts.t_final {
        return Err(FfError::arg("dt", format!("must be positive and at most t_final, got {}", opts.dt)));
    }
    if opts.record_every == 0 {
        return Err(FfError::arg("record_every", "must be at least 1"));
    }
    if let Some(c) = &inputs.controller {
        if !(c.period > 0.0) || !c.period.is_finite() {
            return Err(FfError::arg("controller_period", format!("must be positive, got {}", c.period)));
        }
    }
    let tab = match opts.method {
        Method::Rk4 => &RK4,
        Method::Rk45 { rtol, atol, .. } => {
            if !(rtol > 0.0) || !(atol > 0.0) {
                return Err(FfError::arg("rtol/atol", "tolerances must be positive"));
            }
            if rtol < MIN_RTOL {
                return Err(FfError::arg(
                    "rtol",
                    format!(
                        "{rtol:e} is below what double precision can resolve: the smallest useful relative \
                         tolerance is 100 machine epsilons, {MIN_RTOL:.1e} (machine epsilon is {:.1e})",
                        f64::EPSILON
                    ),
                ));
            }
            &DOPRI5
        }
    };
    // Work sized up front: a fixed-step run longer than max_steps is refused before it starts, and the
    // whole recording is reserved now (fallibly), so that a run too large for memory is an error here, not an
    // abort (or a machine swapping) hours later.
    if matches!(opts.method, Method::Rk4) && (opts.t_final / opts.dt).round() > opts.max_steps as f64 {
        return Err(FfError::arg(
            "t_final",
            format!(
                "t_final / dt = {:.3e} steps, more than max_steps = {}; raise max_steps or dt, or shorten t_final",
                (opts.t_final / opts.dt).round(),
                opts.max_steps
            ),
        ));
    }
    let samples = planned_samples(opts);
    if samples > (isize::MAX as usize / Trajectory::bytes_per_sample(m)) as f64 {
        return Err(FfError::arg(
            "t_final",
            format!("{samples:.3e} samples cannot be recorded (more bytes than an address space holds)"),
        ));
    }
    let mut traj = Trajectory::with_capacity(m, samples as usize)?;
    let mut st = Stepper::new(m, inputs, tab.stages())?;
    st.formulation = formulation;
    if formulation == Formulation::DualQuaternion && st.act.uses_fext {
        return Err(FfError::arg(
            "formulation",
            "thrusters and wheel imbalance need formulation 'aba' (the work of external wrenches is formed from ABA's twists)",
        ));
    }
    if let Some(env) = st.inputs.environment.filter(|e| !e.is_off()) {
        st.env = Some(env.workspace(m, &mut st.d, &q0, v0)?);
    }
    let (mut q, mut v) = (q0, v0.to_vec());
    let (mut q1, mut v1) = (vec![0.0; m.nq], vec![0.0; m.nv]);
    let mut w = 0.0;
    let mut t = 0.0;
    let mut next_sample = 0.0;
    let mut sample_k = 0usize;
    st.impose(0.0, &mut q, &mut v)?;

    // The controller is sampled at k·period and held in between.
    let ctrl_update = |st: &mut Stepper, t: f64, q: &[f64], v: &[f64], next: &mut f64, k: &mut usize| -> Result<()> {
        if let Some(c) = st.inputs.controller.as_mut() {
            if t >= *next - 1e-9 * c.period {
                (c.f)(t, q, v, &mut st.held)?;
                if let Some(i) = st.held.iter().position(|x| !x.is_finite()) {
                    return Err(FfError::Numerical(format!("controller output {i} is not finite at t = {t}")));
                }
                *k += 1;
                *next = *k as f64 * c.period;
            }
        }
        Ok(())
    };
    let eps_t = 1e-12 * opts.t_final.max(1.0);
    let n_rk4 = (opts.t_final / opts.dt).round() as usize;
    let mut h = match opts.method {
        Method::Rk4 => opts.dt,
        Method::Rk45 { max_step, .. } => opts.dt.min(max_step).min(opts.t_final),
    };
    let mut steps = 0usize;
    let mut rejected = 0usize;
    let mut next_out = 0.0;
    let mut out_k = 0usize;
    let mut poller = Poller::new(progress);
    // Every way out of the stepping that is an interruption (a stop from the hook, Ctrl-C seen by a callback)
    // leaves with the samples recorded so far and the state reached (see `interrupted`).
    macro_rules! or_stop {
        ($e:expr) => {
            match $e {
                Ok(x) => x,
                Err(e) => return Err(interrupted(e, &mut st, &mut traj, t, &q, &v, w, opts.t_final, steps)),
            }
        };
    }
    loop {
        or_stop!(ctrl_update(&mut st, t, &q, &v, &mut next_sample, &mut sample_k));
        st.qs.copy_from_slice(&q);
        st.vs.copy_from_slice(&v);
        st.mps.copy_from_slice(&st.mp);
        or_stop!(st.eval(t, 0));
        // Record the state together with the accelerations and forces evaluated at it.
        let record = match opts.method {
            Method::Rk4 => steps.is_multiple_of(opts.record_every) || steps == n_rk4,
            Method::Rk45 { .. } => (t - next_out).abs() <= eps_t,
        };
        if record {
            traj.push(&st.d, t, &q, &v, w);
            if st.act.depletes() {
                traj.propellant.extend_from_slice(&st.mp);
                let ma = st.var_model.as_ref().unwrap_or(m);
                traj.base_parameters.extend_from_slice(&ma.inertias[0].to_params());
            }
            out_k += 1;
            next_out = out_k as f64 * opts.dt;
        }
        let done = match opts.method {
            Method::Rk4 => steps >= n_rk4,
            Method::Rk45 { .. } => t >= opts.t_final - eps_t,
        };
        if done {
            break;
        }
        if steps >= opts.max_steps {
            return Err(FfError::Numerical(format!("gave up after {steps} steps at t = {t} (max_steps)")));
        }
        match opts.method {
            Method::Rk4 => {
                let (w1, _) = or_stop!(st.step(tab, t, h, &q, &v, w, &mut q1, &mut v1, None));
                w = w1;
                std::mem::swap(&mut st.mp, &mut st.mp1);
                steps += 1;
                t = steps as f64 * h;
            }
            Method::Rk45 { rtol, atol, max_step } => {
                // Land exactly on output times, controller samples and the end.
                let mut stop = next_out.min(opts.t_final);
                if st.inputs.controller.is_some() {
                    stop = stop.min(next_sample);
                }
                // Held switches of a table and thruster edges: land on them too.
                if st.inputs.timing == InputTiming::PerStep {
                    stop = stop.min(st.inputs.torques.next_switch(t));
                }
                stop = stop.min(st.act.next_event(t));
                loop {
                    let hh = h.min(stop - t).min(max_step);
                    let (w1, err) = or_stop!(st.step(tab, t, hh, &q, &v, w, &mut q1, &mut v1, Some((rtol, atol))));
                    let factor = if err == 0.0 { 5.0 } else { (0.9 * err.powf(-0.2)).clamp(0.2, 5.0) };
                    if err <= 1.0 {
                        w = w1;
                        std::mem::swap(&mut st.mp, &mut st.mp1);
                        t = if (stop - (t + hh)).abs() <= eps_t { stop } else { t + hh };
                        steps += 1;
                        if hh >= h * 0.999 || factor < 1.0 {
                            h = (hh * factor).min(max_step);
                        }
                        break;
                    }
                    rejected += 1;
                    h = hh * factor;
                    if h < 1e-14 * opts.t_final.max(1.0) {
                        return Err(FfError::Numerical(format!(
                            "step size underflow at t = {t}: the tolerances cannot be met"
                        )));
                    }
                    // Stage 0 still holds f(y0): redo from the same state.
                }
            }
        }
        std::mem::swap(&mut q, &mut q1);
        std::mem::swap(&mut v, &mut v1);
        or_stop!(st.impose(t, &mut q, &mut v));
        or_stop!(poller.poll(t / opts.t_final, || format!("simulation stopped at t = {t} s of {} s", opts.t_final)));
    }
    traj.steps = steps;
    traj.rejected = rejected;
    traj.evaluations = st.evals;
    poller.now(1.0);
    Ok(traj)
}

/// An error that leaves the stepping: an interruption gets the samples recorded so far, with the state reached
/// as the last one (recorded with the dynamics at it, as every sample is) unless it was just recorded or cannot
/// be evaluated (a callback that keeps raising); any other error passes unchanged.
#[allow(clippy::too_many_arguments)]
fn interrupted(
    e: FfError,
    st: &mut Stepper,
    traj: &mut Trajectory,
    t: f64,
    q: &[f64],
    v: &[f64],
    w: f64,
    t_final: f64,
    steps: usize,
) -> FfError {
    let FfError::Interrupted { msg, partial: None } = e else { return e };
    if traj.t.last() != Some(&t) {
        // an interrupt inside `eval` leaves its buffers taken: give it fresh ones
        st.qs = q.to_vec();
        st.vs = v.to_vec();
        st.mps.copy_from_slice(&st.mp);
        if st.eval(t, 0).is_ok() {
            traj.push(&st.d, t, q, v, w);
            if st.act.depletes() {
                // the propellant columns keep the length of the other recorded columns
                traj.propellant.extend_from_slice(&st.mp);
                let ma = st.var_model.as_ref().unwrap_or(st.m);
                traj.base_parameters.extend_from_slice(&ma.inertias[0].to_params());
            }
        }
    }
    let mut tr = std::mem::take(traj);
    tr.steps = steps;
    tr.evaluations = st.evals;
    let msg = if msg.contains(" at t = ") { msg } else { format!("{msg} at t = {t} s of {t_final} s") };
    FfError::Interrupted { msg, partial: Some(Partial::Trajectory(Box::new(tr))) }
}
