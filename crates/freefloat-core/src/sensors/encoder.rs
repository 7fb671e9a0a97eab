//! Joint encoders: each listed joint's coordinate, quantised.
//!
//! θ̃_k = Δ · round((θ_k + n_k) / Δ), n_k ~ N(0, σ²) white (electrical noise before the count), with the
//! quantum Δ = 2π / counts_per_rev [rad] (or `resolution` [rad, or m for a prismatic joint]). Rounding
//! to the nearest count makes the quantisation error uniform on [−Δ/2, Δ/2]: zero mean, variance Δ²/12
//! (the classical uniform model of quantisation, valid when the signal crosses many counts between
//! samples; Widrow & Kollár, *Quantization Noise*, 2008, ch. 4). Δ = 0 switches quantisation off.

use super::fields::Fields;
use super::{joint_list, quantise, GaussianRng, SensorRun};
use crate::error::{FfError, Result};
use crate::model::JointType;

/// An encoder bank.
#[derive(Clone, Debug, PartialEq)]
pub struct EncoderConfig {
    /// Joint names (None: every one-degree-of-freedom joint).
    pub joints: Option<Vec<String>>,
    /// Counts per revolution (revolute joints).
    pub counts_per_rev: Option<f64>,
    /// The quantum itself [rad or m]; overrides `counts_per_rev`.
    pub resolution: Option<f64>,
    /// Standard deviation of the noise before quantisation [rad or m].
    pub noise: f64,
}

impl EncoderConfig {
    pub(crate) fn parse(f: &mut Fields) -> Result<Self> {
        Ok(EncoderConfig {
            joints: f.names("joints")?,
            counts_per_rev: f.positive("counts_per_rev", "counts")?,
            resolution: f.positive("resolution", "rad (or m)")?,
            noise: f.nonneg("noise", 0.0, "rad (or m)")?,
        })
    }

    /// The quantum of joint `body` (0: none).
    fn quantum(&self, r: &SensorRun, body: usize) -> Result<f64> {
        if let Some(d) = self.resolution {
            return Ok(d);
        }
        match (self.counts_per_rev, r.m.joint_types[body]) {
            (None, _) => Ok(0.0),
            (Some(c), JointType::Revolute) => Ok(std::f64::consts::TAU / c),
            (Some(_), _) => Err(FfError::arg(
                &format!("{}.resolution", r.ctx),
                format!(
                    "joint '{}' is prismatic: counts_per_rev applies to revolute joints; give resolution [m]",
                    r.m.joint_names[body]
                ),
            )),
        }
    }

    pub(crate) fn run(&self, r: &mut SensorRun, rng: &mut GaussianRng) -> Result<()> {
        let bodies = joint_list(r.m, &r.ctx, self.joints.as_deref())?;
        let quanta = bodies.iter().map(|&b| self.quantum(r, b)).collect::<Result<Vec<_>>>()?;
        r.columns = bodies.iter().map(|&b| format!("q.{}", r.m.joint_names[b])).collect();
        let nq = r.s.nq;
        for &k in r.idx {
            for (&b, &d) in bodies.iter().zip(&quanta) {
                let x = r.s.q[k * nq + r.m.idx_q[b]] + self.noise * rng.normal();
                r.values.push(quantise(x, d));
            }
        }
        Ok(())
    }
}
