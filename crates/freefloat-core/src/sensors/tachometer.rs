//! Tachometers: each listed joint's rate (reaction-wheel speeds, or any joint's rate sensor).
//!
//! ω̃_k = Δ · round((ω_k + b + n_k) / Δ), n_k ~ N(0, σ²) white [rad/s, per sample], b a constant bias,
//! Δ the speed resolution [rad/s] (0: none). The quantisation error is uniform on [−Δ/2, Δ/2], variance
//! Δ²/12 (as for the encoders). With Δ = b = 0 this is the joint-rate measurement of Naveen, Shah, Misra
//! (Sec. VI.C): white Gaussian noise of standard deviation σ on every joint rate.

use super::fields::Fields;
use super::{joint_list, quantise, GaussianRng, SensorRun};
use crate::error::Result;

/// A tachometer bank.
#[derive(Clone, Debug, PartialEq)]
pub struct TachometerConfig {
    /// Joint names (None: every one-degree-of-freedom joint).
    pub joints: Option<Vec<String>>,
    /// Speed resolution [rad/s or m/s] (0: no quantisation).
    pub resolution: f64,
    /// Per-sample standard deviation [rad/s or m/s].
    pub noise: f64,
    /// Constant bias [rad/s or m/s].
    pub bias: f64,
}

impl TachometerConfig {
    pub(crate) fn parse(f: &mut Fields) -> Result<Self> {
        Ok(TachometerConfig {
            joints: f.names("joints")?,
            resolution: f.nonneg("resolution", 0.0, "rad/s")?,
            noise: f.nonneg("noise", 0.0, "rad/s")?,
            bias: f.signed("bias", 0.0)?,
        })
    }

    pub(crate) fn run(&self, r: &mut SensorRun, rng: &mut GaussianRng) -> Result<()> {
        let bodies = joint_list(r.m, &r.ctx, self.joints.as_deref())?;
        r.columns = bodies.iter().map(|&b| format!("v.{}", r.m.joint_names[b])).collect();
        let nv = r.s.nv;
        for &k in r.idx {
            for &b in &bodies {
                let x = r.s.v[k * nv + r.m.idx_v[b]] + self.bias + self.noise * rng.normal();
                r.values.push(quantise(x, self.resolution));
            }
        }
        // white part as seen by identification: the noise plus the uniform quantisation error
        let s = (self.noise * self.noise + self.resolution * self.resolution / 12.0).sqrt();
        r.white_sigma = vec![s; bodies.len()];
        Ok(())
    }
}
