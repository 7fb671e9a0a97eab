//! Concurrent-learning estimation of every body's mass properties of a spacecraft-mounted manipulator
//! (Valverde 2018, ch. 9): the stacked Newton–Euler equations 𝐑𝐌 = 𝐅 with the known reaction wrenches
//! (9.8)–(9.11), the data stack of Algorithms 3 and 4, the estimation law (9.15) and the aggressive SVD gain
//! (9.22)–(9.27), with a noise-robust variant of that gain ([`Gain::Truncated`], see `law.rs`).
//!
//! Files by job: `samples.rs` builds 𝐑_k, 𝐅_k from the multibody state; `stack.rs` holds the data stack
//! (Algorithms 3, 4); `law.rs` the law and the gain; `driver.rs` the whole run coupled to a simulated robot.
//! [`ConcurrentEstimator`] is the piece a user drives from their own loop: `add_sample`, `step`.
//!
//! Parameter order per body (§4.1): `v(M) = [I11, I12, I13, I22, I23, I33, m]`, bodies in model order.

mod driver;
mod law;
mod samples;
mod stack;

pub use driver::{
    estimate_recorded, estimate_recorded_interruptible, run_cl, ClRun, ClScenario, Excitation, ProgressFn,
};
pub use law::{block_rate, direction_evidence, rk4_step, svd_gain, truncated_svd_gain, ZERO_RTOL};
pub use samples::{Noise, SampleBuilder};
pub use stack::{block_singular_values, DataStack, Offer, SplitMix};

use crate::error::{FfError, Result};
use nalgebra::{SMatrix, SVector};

/// Parameters per body.
pub const NP: usize = 7;
/// The default κ of the truncated gain (9.27′): a weak direction is accelerated when its least-squares value lies
/// at least this many standard errors from the estimate (`law.rs`: the rule and the measurement behind 6).
pub const KAPPA: f64 = 6.0;
/// A body's 8×7 regressor block R̂ (same type as `dualquat::M87`).
pub type M87 = SMatrix<f64, 8, 7>;
/// A 7×7 block of RR or of the gain.
pub type M7 = SMatrix<f64, 7, 7>;
/// A body's parameter vector.
pub type V7 = SVector<f64, 7>;
/// A body's wrench as an 8-vector.
pub type V8 = SVector<f64, 8>;

/// Which σ̄_i the SVD gain K of (9.24) uses for a direction with 0 < σ_i < σ_th,2.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Gain {
    /// The thesis' (9.27): σ̄_i = σ_new/σ_i for every such direction (the reproduction; the default).
    #[default]
    Thesis,
    /// (9.27) only for the directions whose data outweigh the noise, σ̄_i = 1 (the plain law's rate) for the
    /// others: accelerate direction i only if |p_iᵀ(g − T𝐌̂_ref)| ≥ κ σ̂ (9.27′), 𝐌̂_ref the estimate when the
    /// gain switched on, σ̂ the stack's noise estimate (`law.rs`, [`truncated_svd_gain`]).
    Truncated,
}

impl Gain {
    /// The gain by name: "thesis" or "truncated" (an error naming `gain` otherwise).
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "thesis" => Ok(Gain::Thesis),
            "truncated" => Ok(Gain::Truncated),
            _ => Err(FfError::arg("gain", format!("must be \"thesis\" or \"truncated\", got {name:?}"))),
        }
    }
    /// The name `parse` reads.
    pub fn name(&self) -> &'static str {
        match self {
            Gain::Thesis => "thesis",
            Gain::Truncated => "truncated",
        }
    }
}

/// The concurrent-learning parameters of Valverde 2018 ch. 9 (§9.3–9.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClParams {
    /// Stack size N_s (≥ 2).
    pub ns: usize,
    /// σ_th of Algorithm 3: replacements are tried only while σ_min(ΣRᵀR) < σ_th.
    pub sigma_th: f64,
    /// T_th of Algorithm 4: data are collected for t < T_th, then RR, Rf are frozen.
    pub t_th: f64,
    /// Use the SVD gain K of (9.23)–(9.27) from T_th,2 on (false: the plain law (9.15) throughout).
    pub aggressive: bool,
    /// T_th,2: the time the gain K switches on.
    pub t_th2: f64,
    /// σ_th,2 of (9.27).
    pub sigma_th2: f64,
    /// σ_new of (9.27).
    pub sigma_new: f64,
    /// Which directions (9.27) accelerates: all those below σ_th,2 (the thesis) or only the trusted ones.
    pub gain: Gain,
    /// κ of the truncated gain's rule: a direction is accelerated when its data exceed κ times the noise
    /// estimate σ̂ (used with `Gain::Truncated` only).
    pub kappa: f64,
    /// Seed of Algorithm 3's random visiting order π.
    pub seed: u64,
}

impl Default for ClParams {
    /// The values of the thesis' simulation (§9.5).
    fn default() -> Self {
        ClParams {
            ns: 10,
            sigma_th: 0.001,
            t_th: 5.0,
            aggressive: true,
            t_th2: 4.9,
            sigma_th2: 0.5,
            sigma_new: 100.0,
            gain: Gain::Thesis,
            kappa: KAPPA,
            seed: 1,
        }
    }
}

impl ClParams {
    /// Every parameter in range, with an error naming the one that is not.
    pub fn validate(&self) -> Result<()> {
        if self.ns < 2 {
            return Err(FfError::arg(
                "ns",
                format!("the stack must hold at least 2 points (one sample has rank ≤ 6 of 7), got {}", self.ns),
            ));
        }
        let fin = |name: &str, x: f64, pos: bool| -> Result<()> {
            if !x.is_finite() || x < 0.0 || (pos && x == 0.0) {
                let what = if pos { "positive" } else { "≥ 0" };
                return Err(FfError::arg(name, format!("must be finite and {what}, got {x}")));
            }
            Ok(())
        };
        fin("sigma_th", self.sigma_th, false)?;
        fin("t_th", self.t_th, false)?;
        fin("t_th2", self.t_th2, false)?;
        fin("sigma_th2", self.sigma_th2, true)?;
        fin("sigma_new", self.sigma_new, true)?;
        fin("kappa", self.kappa, true)?;
        Ok(())
    }
}

/// Whether a 7-parameter estimate is a rigid body: mass > 0, inertia positive definite, and the triangle
/// inequalities of the principal moments (the engine's one test, `dualquat::realisability`).
pub fn realisable(v: &V7) -> bool {
    crate::dualquat::realisability(v).is_realisable()
}

/// The concurrent-learning estimator of Valverde 2018 ch. 9 for B bodies, driven sample by sample:
/// `add_sample` (Algorithms 3 and 4 while t < T_th) and `step` (RK4 of (9.15), or of (9.23) with the SVD gain
/// once t ≥ T_th,2). No allocation after `new`.
#[derive(Clone, Debug)]
pub struct ConcurrentEstimator {
    params: ClParams,
    stack: DataStack,
    m: Vec<V7>,
    saved: Vec<V7>,
    k: Vec<M7>,
    /// per body, when the gain was last formed: the directions the truncated rule withheld
    withheld: Vec<usize>,
    /// the estimate when the gain switched on: the truncated rule's reference (9.27′), kept while it stays on
    m_ref: Vec<V7>,
    gain_on: bool,
    gain_stale: bool,
    t: f64,
}

impl ConcurrentEstimator {
    /// Estimator for `nbodies` bodies starting from the flat estimate `m0` (7 per body).
    pub fn new(nbodies: usize, params: ClParams, m0: &[f64]) -> Result<Self> {
        params.validate()?;
        crate::check::check_vec("m0", m0, NP * nbodies)?;
        let stack = DataStack::new(nbodies, params.ns, params.sigma_th, params.seed)?;
        Ok(ConcurrentEstimator {
            params,
            stack,
            m: (0..nbodies).map(|i| V7::from_column_slice(&m0[NP * i..NP * (i + 1)])).collect(),
            saved: vec![V7::zeros(); nbodies],
            k: vec![M7::identity(); nbodies],
            withheld: vec![0; nbodies],
            m_ref: vec![V7::zeros(); nbodies],
            gain_on: false,
            gain_stale: true,
            t: 0.0,
        })
    }

    /// Parameters.
    pub fn params(&self) -> &ClParams {
        &self.params
    }
    /// The data stack.
    pub fn stack(&self) -> &DataStack {
        &self.stack
    }
    /// Current time (advanced by `step`).
    pub fn time(&self) -> f64 {
        self.t
    }
    /// Set the clock (e.g. to start at a time other than 0).
    pub fn set_time(&mut self, t: f64) {
        self.t = t;
    }
    /// Whether the SVD gain is in use.
    pub fn gain_active(&self) -> bool {
        self.gain_on
    }
    /// The current estimate, per body.
    pub fn estimate(&self) -> &[V7] {
        &self.m
    }
    /// Copy the current estimate into `out` (7 per body).
    pub fn estimate_into(&self, out: &mut [f64]) {
        for (i, v) in self.m.iter().enumerate() {
            out[NP * i..NP * (i + 1)].copy_from_slice(v.as_slice());
        }
    }
    /// The gain blocks (identity until T_th,2).
    pub fn gain(&self) -> &[M7] {
        &self.k
    }
    /// Per body: how many directions the truncated gain left at the plain law's rate although (9.27) would
    /// accelerate them, when the gain was last formed (zeros with the thesis gain and before T_th,2).
    pub fn withheld(&self) -> &[usize] {
        &self.withheld
    }

    /// Offer the sample (𝐑_k, 𝐅_k) at the current time: Algorithm 4 feeds it to Algorithm 3 while t < T_th and
    /// ignores it afterwards (`Ok(None)`).
    pub fn add_sample(&mut self, r: &[M87], f: &[V8]) -> Result<Option<Offer>> {
        if !(self.t < self.params.t_th) {
            return Ok(None);
        }
        let o = self.stack.offer(r, f)?;
        if matches!(o, Offer::Appended | Offer::Replaced(_)) {
            self.gain_stale = true;
        }
        Ok(Some(o))
    }

    /// Advance the estimate by one RK4 step of length `dt` (RR, Rf, K constant over the step). Fails, without
    /// changing the estimate, when RK4 would be unstable (largest decay rate × dt > 2.78) or the estimate
    /// would stop being finite.
    pub fn step(&mut self, dt: f64) -> Result<()> {
        if !(dt > 0.0) || !dt.is_finite() {
            return Err(FfError::arg("dt", format!("must be positive and finite, got {dt}")));
        }
        let p = self.params;
        // the switch is decided at the step's start time (half a microstep of slack against 4.9 = 490·0.01)
        let on = p.aggressive && self.t >= p.t_th2 - 1e-9 * dt;
        if on && !self.gain_on {
            self.m_ref.copy_from_slice(&self.m);
        }
        if on && (!self.gain_on || self.gain_stale) {
            let sref = self.stack.singular_values().first().copied().unwrap_or(0.0).sqrt();
            match p.gain {
                Gain::Thesis => {
                    for (k, t) in self.k.iter_mut().zip(self.stack.tri()) {
                        *k = svd_gain(t, p.sigma_th2, p.sigma_new, sref);
                    }
                }
                Gain::Truncated => {
                    for i in 0..self.m.len() {
                        let sh = self.stack.noise_sigma(i).unwrap_or(f64::INFINITY);
                        let (t, g) = (&self.stack.tri()[i], &self.stack.g()[i]);
                        let (k, w) =
                            truncated_svd_gain(t, g, &self.m_ref[i], sh, p.kappa, p.sigma_th2, p.sigma_new, sref);
                        self.k[i] = k;
                        self.withheld[i] = w;
                    }
                }
            }
            self.gain_stale = false;
        }
        self.gain_on = on;
        // stability of classical RK4 on the real axis: |λ dt| ≤ 2.785
        let rate_max = if on {
            // K·RR = U Σ̄ Σ Uᵀ: the rates are σ̄_i σ_i ≤ max(σ_new, σ_max)
            p.sigma_new.max(self.stack.singular_values().first().copied().unwrap_or(0.0))
        } else {
            self.stack.singular_values().first().copied().unwrap_or(0.0)
        };
        if rate_max * dt > 2.78 {
            return Err(FfError::arg(
                "dt",
                format!(
                    "RK4 on the estimation law is unstable: largest decay rate {rate_max:.4e} 1/s × dt {dt} > 2.78 \
                     (reduce dt, sigma_new or the stack size ns)"
                ),
            ));
        }
        self.saved.copy_from_slice(&self.m);
        rk4_step(self.stack.tri(), self.stack.g(), on.then_some(&self.k[..]), &mut self.m, dt);
        if let Some((i, _)) = self.m.iter().enumerate().find(|(_, v)| v.iter().any(|x| !x.is_finite())) {
            self.m.copy_from_slice(&self.saved);
            return Err(FfError::Numerical(format!(
                "the estimate of body {i} stopped being finite at t = {} (check the samples)",
                self.t
            )));
        }
        self.t += dt;
        Ok(())
    }
}

#[cfg(test)]
mod tests;
