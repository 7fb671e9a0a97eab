//! Rate gyro (three axes along the base frame).
//!
//! Error model: the rate-gyro model of IEEE Std 952-1997 (Annex B, the single-axis gyro model, and
//! Annex C, Allan variance), keeping its three terms that matter for attitude estimation, plus a constant
//! bias. Per axis, at the sample instants t_k = k P (P the sample period):
//!
//!   ω̃_k = ω_k + b₀ + b_k + r_k + n_k
//!
//! * angle random walk: n_k white, n_k ~ N(0, N²/P), with N [rad/s/√Hz = rad/√s] the coefficient of the
//!   Allan-variance term σ²(τ) = N²/τ (slope −1/2 of the Allan deviation). A white rate noise of
//!   one-sided density N sampled every P has per-sample variance N²/P: the discretisation.
//! * bias instability: B [rad/s], the coefficient of the flat region of the Allan deviation,
//!   σ(τ) ≈ B √(2 ln 2 / π) ≈ 0.664 B (IEEE Std 952, Annex C). The true flicker (1/f) process has no
//!   finite-state model; we use the usual first-order Gauss-Markov stand-in with correlation time T_c,
//!   exactly discretised: b_{k+1} = φ b_k + σ_b √(1 − φ²) w_k, φ = e^{−P/T_c}, b₀ ~ N(0, σ_b²). Its Allan
//!   deviation peaks at τ ≈ 1.89 T_c at 0.6174 σ_b (from the Gauss-Markov Allan variance
//!   σ²(τ) = (2σ_b² T_c/τ)[1 − (T_c/2τ)(3 − 4e^{−τ/T_c} + e^{−2τ/T_c})]), so σ_b = 0.664 B / 0.6174 makes
//!   the peak, the flattest part of the curve, equal the flat region of the configured B.
//! * rate random walk: r_{k+1} = r_k + K √P w_k, K [rad/s/√s], Allan variance K² τ / 3 (slope +1/2).
//!
//! The gyro samples the true rate at the instant (no integration over the sample period).

use super::fields::Fields;
use super::{base_label, require_free_base, GaussianRng, SensorRun};
use crate::error::Result;

/// Flat-region Allan deviation per unit bias instability, √(2 ln 2 / π) (IEEE Std 952-1997, Annex C).
pub const FLAT_REGION_FACTOR: f64 = 0.664_282_470_267_960_1;
/// Peak Allan deviation of a first-order Gauss-Markov process per unit stationary deviation (at
/// τ ≈ 1.893 T_c; maximum of the Gauss-Markov Allan variance above).
pub const GAUSS_MARKOV_PEAK: f64 = 0.617_364_283_074_298_1;

/// A rate gyro's error terms.
#[derive(Clone, Debug, PartialEq)]
pub struct GyroConfig {
    /// Angle random walk N [rad/s/√Hz] (white rate noise density).
    pub noise_density: f64,
    /// Constant bias [rad/s] per axis.
    pub bias: [f64; 3],
    /// Bias instability B [rad/s] (flat region of the Allan deviation is 0.664 B).
    pub bias_instability: f64,
    /// Correlation time of the Gauss-Markov bias [s].
    pub bias_correlation_time: f64,
    /// Rate random walk K [rad/s/√s].
    pub rate_random_walk: f64,
    /// The white noise as a per-sample standard deviation [rad/s] instead of a density (Naveen, Shah,
    /// Misra quote it so); N = σ √P. Exclusive with `noise_density`.
    pub noise_per_sample: Option<f64>,
}

impl GyroConfig {
    /// Stationary standard deviation of the Gauss-Markov bias that reproduces `bias_instability`.
    pub fn gauss_markov_sigma(&self) -> f64 {
        self.bias_instability * FLAT_REGION_FACTOR / GAUSS_MARKOV_PEAK
    }

    pub(crate) fn parse(f: &mut Fields) -> Result<Self> {
        let density = f.opt_nonneg("noise_density", "rad/s/√Hz")?;
        let per_sample = f.opt_nonneg("noise_per_sample", "rad/s")?;
        if density.is_some() && per_sample.is_some() {
            return Err(crate::error::FfError::arg(
                &format!("{}.noise_per_sample", f.ctx),
                "give either noise_density (rad/s/√Hz) or noise_per_sample (rad/s), not both",
            ));
        }
        Ok(GyroConfig {
            noise_density: density.unwrap_or(0.0),
            noise_per_sample: per_sample,
            bias: f.vec3("bias", [0.0; 3], false)?,
            bias_instability: f.nonneg("bias_instability", 0.0, "rad/s")?,
            bias_correlation_time: f.positive("bias_correlation_time", "s")?.unwrap_or(100.0),
            rate_random_walk: f.nonneg("rate_random_walk", 0.0, "rad/s/√s")?,
        })
    }

    pub(crate) fn run(&self, r: &mut SensorRun, rng: &mut GaussianRng) -> Result<()> {
        require_free_base(r.m, &r.ctx, "a gyro")?;
        let b = base_label(r.m);
        r.columns = ["wx", "wy", "wz"].iter().map(|c| format!("v.{b}.{c}")).collect();
        let p = r.period;
        let sn = self.noise_per_sample.unwrap_or(self.noise_density / p.sqrt());
        let phi = (-p / self.bias_correlation_time).exp();
        let sb = self.gauss_markov_sigma();
        let sw = sb * (1.0 - phi * phi).sqrt();
        let sk = self.rate_random_walk * p.sqrt();
        let mut gm = [0.0; 3];
        for g in gm.iter_mut() {
            *g = sb * rng.normal(); // start in the stationary distribution
        }
        let mut rw = [0.0; 3];
        let nv = r.s.nv;
        for &k in r.idx {
            let w = &r.s.v[k * nv + 3..k * nv + 6];
            for a in 0..3 {
                let y = w[a] + self.bias[a] + gm[a] + rw[a] + sn * rng.normal();
                r.values.push(y);
                gm[a] = phi * gm[a] + sw * rng.normal();
                rw[a] += sk * rng.normal();
            }
        }
        // the white part, for the errors-in-variables bias removal of identification
        r.white_sigma = vec![sn; 3];
        Ok(())
    }
}
