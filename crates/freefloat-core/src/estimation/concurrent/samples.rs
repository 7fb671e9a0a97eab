//! One data point of Valverde 2018 ch. 9 from the multibody state: the per-body regressor
//! R̂(ω̇_i, ω_i) = r((ω̇_i)^s) + [ω_i]^× r((ω_i)^s) (9.7) and the known wrench 𝐅_i = 𝒞_i − (S12)_{i,:} 𝒯 (9.8),
//! stacked (9.9)–(9.11) as B blocks 𝐑 = blkdiag(R̂_1..R̂_B), 𝐅 = [F_1; …; F_B]. The wrench comes from the
//! transmitted joint wrenches (joint force/torque sensors, Remark 16) via `dqdynamics::com_wrenches`; the
//! optional measurement noise goes on those joint wrenches and on the body twists and twist rates.

use super::stack::SplitMix;
use super::{M87, V8};
use crate::data::Data;
use crate::dqdynamics::{com_motion, com_wrenches};
use crate::dualquat::{body_regressor, DualQuat};
use crate::error::Result;
use crate::model::Model;
use crate::spatial::{Force, V3};

/// Standard deviations of the measurement noise of the studies (zero: exact measurements).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Noise {
    /// On every component of every joint's six-axis force/torque reading (N, N·m).
    pub wrench: f64,
    /// On every component of every body's measured twist `ω + ε v` (rad/s, m/s) and of its rate
    /// (rad/s², m/s²).
    pub rate: f64,
}

impl Noise {
    /// True when both are zero.
    pub fn is_zero(&self) -> bool {
        self.wrench == 0.0 && self.rate == 0.0
    }
}

fn jitter(x: &DualQuat, s: f64, rng: &mut SplitMix) -> DualQuat {
    let a = V3::new(rng.normal(), rng.normal(), rng.normal()) * s;
    let b = V3::new(rng.normal(), rng.normal(), rng.normal()) * s;
    *x + DualQuat::vector(&a, &b)
}

/// Buffers that turn a solved multibody state into 𝐑_k, 𝐅_k (allocated once per model).
#[derive(Clone, Debug)]
pub struct SampleBuilder {
    twists: Vec<DualQuat>,
    rates: Vec<DualQuat>,
    wrenches: Vec<DualQuat>,
    jw: Vec<Force>,
    /// R̂_i (8×7) of the last sample, one per body.
    pub r: Vec<M87>,
    /// F_i (8-vector, `f + ε τ` about the CoM in body axes) of the last sample, one per body.
    pub f: Vec<V8>,
}

impl SampleBuilder {
    /// Buffers for the bodies of `m`.
    pub fn new(m: &Model) -> Self {
        let n = m.nbodies();
        SampleBuilder {
            twists: vec![DualQuat::ZERO; n],
            rates: vec![DualQuat::ZERO; n],
            wrenches: vec![DualQuat::ZERO; n],
            jw: vec![Force::ZERO; n],
            r: vec![M87::zeros(); n],
            f: vec![V8::zeros(); n],
        }
    }

    /// The body twists of the last sample (after noise).
    pub fn twists(&self) -> &[DualQuat] {
        &self.twists
    }
    /// The body twist rates of the last sample (after noise).
    pub fn rates(&self) -> &[DualQuat] {
        &self.rates
    }

    /// 𝐑_k, 𝐅_k from the last `dq_dynamics` solution in `d` (with `fext` the external wrenches it used),
    /// with measurement noise drawn from `rng` when `noise` is non-zero.
    pub fn build(
        &mut self,
        m: &Model,
        d: &Data,
        fext: Option<&[f64]>,
        noise: &Noise,
        rng: &mut SplitMix,
    ) -> Result<()> {
        com_motion(m, d, &mut self.twists, &mut self.rates)?;
        self.jw.copy_from_slice(&d.dq.out.joint_wrenches);
        if noise.wrench > 0.0 {
            // a six-axis sensor at every moving joint; the base's entry is its (known) actuation
            for w in self.jw.iter_mut().skip(1) {
                w.lin += V3::new(rng.normal(), rng.normal(), rng.normal()) * noise.wrench;
                w.ang += V3::new(rng.normal(), rng.normal(), rng.normal()) * noise.wrench;
            }
        }
        com_wrenches(m, d, &self.jw, fext, &mut self.wrenches)?;
        if noise.rate > 0.0 {
            for i in 0..self.twists.len() {
                self.twists[i] = jitter(&self.twists[i], noise.rate, rng);
                self.rates[i] = jitter(&self.rates[i], noise.rate, rng);
            }
        }
        for i in 0..self.r.len() {
            // Valverde 2018, eq. (9.7)
            self.r[i] = body_regressor(&self.twists[i], &self.rates[i]);
            self.f[i] = self.wrenches[i].to_vec8();
        }
        Ok(())
    }
}
