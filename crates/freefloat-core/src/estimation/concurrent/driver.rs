//! The whole chapter-9 run (Valverde 2018 §9.5): the multibody robot simulated with classical RK4 on the
//! configuration group (the engine's RKMK; at each major step the dual-quaternion solver of ch. 6, which
//! also gives the joint wrenches the estimator needs; at the three intermediate stages the engine's ABA,
//! which gives the same accelerations to round-off at an eighth of the cost), and at every major step a data point 𝐑_k, 𝐅_k for the concurrent-learning estimator,
//! which is integrated with RK4 over the same step (data enter at major steps only, §9.3: with ODE4 the thesis
//! incorporates data once every four dynamics evaluations). Every buffer and every recorded series is
//! allocated before the first step; a step allocates nothing.

use super::samples::{Noise, SampleBuilder};
use super::stack::{Offer, SplitMix};
use super::{realisable, ClParams, ConcurrentEstimator, NP};
use crate::config::{dexpinv_unchecked as dexpinv, retract_unchecked as retract, tangent_rate_unchecked};
use crate::data::Data;
use crate::dqdynamics::solve_system_unchecked;
use crate::dynamics::hybrid_aba_unchecked;
use crate::error::{FfError, Partial, Result};
use crate::interrupt::{Hook, Poller, POLL_INTERVAL};
use crate::model::{JointType, Model};
use crate::rk::{self, RK4};

/// The joint actuation of (9.28): `amplitude · sin(frequency · t + phase)` on every joint DOF (N for a
/// prismatic joint, N·m otherwise) for `t_start ≤ t ≤ t_end`, zero elsewhere; the base is unactuated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Excitation {
    /// Amplitude (0.5 in the thesis).
    pub amplitude: f64,
    /// Angular frequency, rad/s (1).
    pub frequency: f64,
    /// Phase, rad (0).
    pub phase: f64,
    /// Window start, s (2).
    pub t_start: f64,
    /// Window end, s (3).
    pub t_end: f64,
}

impl Default for Excitation {
    fn default() -> Self {
        Excitation { amplitude: 0.5, frequency: 1.0, phase: 0.0, t_start: 2.0, t_end: 3.0 }
    }
}

impl Excitation {
    fn fill(&self, m: &Model, t: f64, tau: &mut [f64]) {
        tau.fill(0.0);
        if t >= self.t_start && t <= self.t_end {
            let u = self.amplitude * (self.frequency * t + self.phase).sin();
            let nb = if m.joint_types.first() == Some(&JointType::Free) { 6 } else { 0 };
            for x in tau.iter_mut().skip(nb) {
                *x = u;
            }
        }
    }
}

/// One chapter-9 run: robot, initial state, excitation, estimator and measurement noise.
#[derive(Clone, Debug)]
pub struct ClScenario {
    /// Initial configuration (engine convention, nq).
    pub q0: Vec<f64>,
    /// Initial velocity (nv).
    pub v0: Vec<f64>,
    /// Joint actuation.
    pub excitation: Excitation,
    /// Estimator parameters.
    pub params: ClParams,
    /// Initial estimate 𝐌̂(0), 7 per body in model order.
    pub m0: Vec<f64>,
    /// RK4 step (s), for the robot and the estimator.
    pub dt: f64,
    /// Final time (s).
    pub t_final: f64,
    /// Measurement noise (zero: the thesis' exact wrenches and rates).
    pub noise: Noise,
    /// Seed of the noise.
    pub noise_seed: u64,
}

/// Everything a run records, one row per major step `t_k = k·dt`, k = 0..=n.
#[derive(Clone, Debug, Default)]
pub struct ClRun {
    /// Sample times.
    pub times: Vec<f64>,
    /// Estimate at each t_k (before the step from t_k), (n+1) × 7B, row-major.
    pub estimates: Vec<f64>,
    /// The 7B singular values of ΣRᵀR at each t_k (descending), (n+1) × 7B.
    pub singular_values: Vec<f64>,
    /// Per-body singular values at each t_k (each block descending, body-major), (n+1) × 7B.
    pub block_singular_values: Vec<f64>,
    /// What Algorithm 3 did at each t_k: 0 not offered (t ≥ T_th), 1 appended, 2 replaced, 3 rejected,
    /// 4 full (σ_min ≥ σ_th).
    pub offers: Vec<u8>,
    /// The truth 𝐌 (from the model), 7B.
    pub truth: Vec<f64>,
    /// Final estimate, 7B.
    pub final_estimate: Vec<f64>,
    /// Per body: whether the final estimate is a rigid body (`dualquat::realisability`).
    pub realisable: Vec<bool>,
    /// Largest |R̂_i v(M_i) − F_i| over the run with the true parameters and exact measurements (a check that
    /// the reaction wrenches and the regressor agree with the dynamics); NaN with noise.
    pub max_residual: f64,
    /// Per body, at the end: the noise estimate σ̂ of the stored data (`DataStack::noise_sigma`; round-off
    /// without noise, infinite without redundancy).
    pub noise_sigma: Vec<f64>,
    /// Per body: the directions the truncated gain withheld (left at the plain law's rate although (9.27) would
    /// accelerate them) when it was last formed; zeros with the thesis gain.
    pub gain_withheld: Vec<usize>,
    /// Number of changes of the stored set and trial decompositions in Algorithm 3.
    pub stack_changes: u64,
    /// Trial decompositions made by Algorithm 3.
    pub stack_trials: u64,
    /// Whether the run stopped early (progress callback returned false).
    pub interrupted: bool,
}

/// Progress callback: called with the simulated time; return false to stop (the run keeps what was done).
pub type ProgressFn<'a> = &'a mut dyn FnMut(f64) -> bool;

/// Run chapter 9 on `m` (free base, no gravity): RK4 at `dt` to `t_final`, estimator coupled at every step.
pub fn run_cl(m: &Model, sc: &ClScenario, mut progress: Option<ProgressFn>) -> Result<ClRun> {
    if m.joint_types.first() != Some(&JointType::Free) {
        return Err(FfError::Model("the chapter-9 estimator needs a free-floating base".into()));
    }
    if m.gravity.norm() != 0.0 {
        return Err(FfError::Model(format!(
            "the chapter-9 estimator assumes no gravity (deep space, §9.5), the model has g = {:?}",
            m.gravity.as_slice()
        )));
    }
    let n = m.nbodies();
    for i in 0..n {
        if !(m.inertias[i].mass > 0.0) {
            return Err(FfError::Model(format!("body '{}' has no mass; every body is estimated", m.body_names[i])));
        }
    }
    let mut qbuf = Vec::new();
    let q0 = m.checked_q(&sc.q0, &mut qbuf)?.to_vec();
    crate::check::check_vec("v0", &sc.v0, m.nv)?;
    if !(sc.dt > 0.0) || !sc.dt.is_finite() {
        return Err(FfError::arg("dt", format!("must be positive and finite, got {}", sc.dt)));
    }
    if !(sc.t_final >= sc.dt) || !sc.t_final.is_finite() {
        return Err(FfError::arg("t_final", format!("must be finite and at least dt, got {}", sc.t_final)));
    }
    for (name, x) in [("noise.wrench", sc.noise.wrench), ("noise.rate", sc.noise.rate)] {
        if !(x >= 0.0) || !x.is_finite() {
            return Err(FfError::arg(name, format!("must be finite and ≥ 0, got {x}")));
        }
    }
    let e = &sc.excitation;
    for (name, x) in [
        ("excitation.amplitude", e.amplitude),
        ("excitation.frequency", e.frequency),
        ("excitation.phase", e.phase),
        ("excitation.t_start", e.t_start),
        ("excitation.t_end", e.t_end),
    ] {
        if !x.is_finite() {
            return Err(FfError::arg(name, format!("must be finite, got {x}")));
        }
    }
    let mut est = ConcurrentEstimator::new(n, sc.params, &sc.m0)?;
    let np = NP * n;
    let steps = (sc.t_final / sc.dt).round() as usize;
    let rows = steps + 1;

    // the truth, from the model (only for the residual check and the report)
    let mut truth = vec![0.0; np];
    let mut truth_v = Vec::with_capacity(n);
    for i in 0..n {
        let di = crate::dualquat::DualInertia::from_inertia(&m.inertias[i])?;
        let v = crate::dualquat::params(&di);
        truth[NP * i..NP * (i + 1)].copy_from_slice(v.as_slice());
        truth_v.push(v);
    }

    let mut out = ClRun {
        times: Vec::with_capacity(rows),
        estimates: Vec::with_capacity(rows * np),
        singular_values: Vec::with_capacity(rows * np),
        block_singular_values: Vec::with_capacity(rows * np),
        offers: Vec::with_capacity(rows),
        truth,
        ..Default::default()
    };
    let mut d = Data::new(m);
    let mut sb = SampleBuilder::new(m);
    let mut rng = SplitMix::new(sc.noise_seed);
    let (nq, nv) = (m.nq, m.nv);
    let (mut q, mut v) = (q0, sc.v0.clone());
    let (mut qs, mut vs) = (vec![0.0; nq], vec![0.0; nv]);
    let mut tau = vec![0.0; nv];
    // one row per RK4 stage: [rate of the configuration's tangent coordinates (nv) | acceleration (nv)]
    let mut stages = vec![vec![0.0; 2 * nv]; 4];
    let mut delta = vec![0.0; 2 * nv];
    let mut est_row = vec![0.0; np];
    let exact = sc.noise.is_zero();
    let mut max_res: f64 = 0.0;
    let report_every = (steps / 200).max(1);
    let mut last_report = std::time::Instant::now();

    for k in 0..=steps {
        let t = k as f64 * sc.dt;
        est.set_time(t);
        // stage 0 at the major step: dynamics, joint wrenches, and the data point
        e.fill(m, t, &mut tau);
        solve_system_unchecked(m, &mut d, &q, &v, &tau, None, None, None)?;
        sb.build(m, &d, None, &sc.noise, &mut rng)?;
        if exact {
            for i in 0..n {
                let r = sb.r[i] * truth_v[i] - sb.f[i];
                max_res = max_res.max(r.amax());
            }
        }
        let offer = match est.add_sample(&sb.r, &sb.f)? {
            None => 0,
            Some(Offer::Appended) => 1,
            Some(Offer::Replaced(_)) => 2,
            Some(Offer::Rejected) => 3,
            Some(Offer::Full) => 4,
        };
        out.times.push(t);
        est.estimate_into(&mut est_row);
        out.estimates.extend_from_slice(&est_row);
        out.singular_values.extend_from_slice(est.stack().singular_values());
        out.block_singular_values.extend_from_slice(est.stack().block_singular_values());
        out.offers.push(offer);
        if let Some(p) = progress.as_mut() {
            // at every 1/200 of the run and at least every POLL_INTERVAL (Ctrl-C within ~20 ms on a long run)
            let due = k % report_every == 0 || k == steps || last_report.elapsed() >= POLL_INTERVAL;
            if due {
                last_report = std::time::Instant::now();
                if !p(t) {
                    out.interrupted = true;
                    break;
                }
            }
        }
        if k == steps {
            break;
        }
        // the estimator over [t, t + dt]
        est.step(sc.dt)?;
        // the robot over [t, t + dt]: RKMK with the classical RK4 tableau (the engine's one stage loop, `rk::step`)
        let (kq0, kv0) = stages[0].split_at_mut(nv);
        tangent_rate_unchecked(m, &q, &v, kq0);
        kv0.copy_from_slice(&d.dq.out.ddq);
        rk::step(&RK4, t, sc.dt, &mut stages, &mut delta, |_, ts, dl, ks| {
            let (dq, dv) = dl.split_at(nv);
            retract(m, &q, dq, &mut qs);
            for j in 0..nv {
                vs[j] = v[j] + dv[j];
            }
            e.fill(m, ts, &mut tau);
            // intermediate stages need accelerations only: the engine's ABA (same dynamics as the
            // dual-quaternion solver to round-off, tests/dqdynamics.rs, and ~8x cheaper)
            hybrid_aba_unchecked(m, &mut d, &qs, &vs, &tau, None, None)?;
            let (kq, kv) = ks.split_at_mut(nv);
            tangent_rate_unchecked(m, &qs, &vs, kq);
            kv.copy_from_slice(&d.ddq);
            // RKMK: the stage's tangent rate is mapped back through dexp⁻¹ of the stage increment
            dexpinv(m, dq, kq);
            Ok(())
        })?;
        let (dq, dv) = delta.split_at(nv);
        retract(m, &q, dq, &mut qs);
        std::mem::swap(&mut q, &mut qs);
        for j in 0..nv {
            v[j] += dv[j];
        }
        if let Some(j) = v.iter().position(|x| !x.is_finite()) {
            return Err(FfError::Numerical(format!("the robot's velocity {j} became non-finite at t = {t}")));
        }
    }
    out.final_estimate = est_row;
    out.realisable = est.estimate().iter().map(realisable).collect();
    out.max_residual = if exact { max_res } else { f64::NAN };
    out.noise_sigma = (0..n).map(|i| est.stack().noise_sigma(i).unwrap_or(f64::NAN)).collect();
    out.gain_withheld = est.withheld().to_vec();
    let (c, tr) = est.stack().counters();
    out.stack_changes = c;
    out.stack_trials = tr;
    Ok(out)
}

/// The estimator alone over recorded data points: `r` holds n samples × B blocks (sample-major), `f` the matching
/// wrenches, taken at t_k = k·dt; `out` receives the estimate at every t_k (n × 7B, before the step from t_k).
/// The same per-step sequence as `run_cl` (offer, record, step), without the robot.
pub fn estimate_recorded(
    nbodies: usize,
    params: ClParams,
    m0: &[f64],
    dt: f64,
    r: &[super::M87],
    f: &[super::V8],
    out: &mut [f64],
) -> Result<()> {
    estimate_recorded_interruptible(nbodies, params, m0, dt, r, f, out, None)
}

/// [`estimate_recorded`], stoppable: `hook` is polled (at most every `POLL_INTERVAL`, with the fraction of
/// samples done) after each sample; its `false` ends the run with `FfError::Interrupted` carrying
/// `Partial::Samples(k)`: the first k rows of `out` hold the estimates at t_0 … t_{k−1}, the same numbers an
/// uninterrupted call gives there (the estimator is causal).
#[allow(clippy::too_many_arguments)]
pub fn estimate_recorded_interruptible(
    nbodies: usize,
    params: ClParams,
    m0: &[f64],
    dt: f64,
    r: &[super::M87],
    f: &[super::V8],
    out: &mut [f64],
    hook: Option<Hook>,
) -> Result<()> {
    let mut est = ConcurrentEstimator::new(nbodies, params, m0)?;
    if r.len() != f.len() || !r.len().is_multiple_of(nbodies) || r.is_empty() {
        return Err(FfError::arg(
            "R/F",
            format!("need n samples × {nbodies} blocks each, got {} and {}", r.len(), f.len()),
        ));
    }
    let n = r.len() / nbodies;
    crate::check::check_len("out", out.len(), n * NP * nbodies)?;
    let np = NP * nbodies;
    let mut poller = Poller::new(hook);
    for k in 0..n {
        est.set_time(k as f64 * dt);
        est.add_sample(&r[k * nbodies..(k + 1) * nbodies], &f[k * nbodies..(k + 1) * nbodies])?;
        est.estimate_into(&mut out[k * np..(k + 1) * np]);
        if k + 1 < n {
            if let Err(FfError::Interrupted { msg, .. }) = poller.poll((k + 1) as f64 / n as f64, || {
                format!("ch. 9 estimator stopped after sample {} of {n} (t = {} s)", k + 1, k as f64 * dt)
            }) {
                return Err(FfError::Interrupted { msg, partial: Some(Partial::Samples(k + 1)) });
            }
            est.step(dt)?;
        }
    }
    Ok(())
}
