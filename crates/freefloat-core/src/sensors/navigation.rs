//! Base linear velocity and base position from a navigation solution (relative navigation, GNSS, a
//! ground-truth motion-capture system in a laboratory): the true value plus a constant bias and white
//! Gaussian noise per axis, ṽ_k = v_k + b + n_k, n_k ~ N(0, σ²). The velocity is in the base frame, like
//! `v`; the position in the inertial frame, like `q`. This is the measurement of the base's linear rate
//! in Naveen, Shah, Misra (Sec. VI.C): σ is the per-sample standard deviation, not a density.

use super::fields::Fields;
use super::{base_label, require_free_base, GaussianRng, SensorRun};
use crate::error::Result;

/// Which navigation quantity a sensor measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NavQuantity {
    /// Base linear velocity, base frame [m/s].
    Velocity,
    /// Base position, inertial frame [m].
    Position,
}

/// Noise of a navigation sensor.
#[derive(Clone, Debug, PartialEq)]
pub struct NavigationConfig {
    /// What is measured.
    pub quantity: NavQuantity,
    /// Per-sample standard deviation per axis [m/s or m].
    pub noise: [f64; 3],
    /// Constant bias per axis [m/s or m].
    pub bias: [f64; 3],
}

impl NavigationConfig {
    pub(crate) fn parse(f: &mut Fields, quantity: NavQuantity) -> Result<Self> {
        Ok(NavigationConfig {
            quantity,
            noise: f.vec3("noise", [0.0; 3], true)?,
            bias: f.vec3("bias", [0.0; 3], false)?,
        })
    }

    pub(crate) fn run(&self, r: &mut SensorRun, rng: &mut GaussianRng) -> Result<()> {
        require_free_base(r.m, &r.ctx, "a base velocity or position sensor")?;
        let b = base_label(r.m);
        let (src, stride, names, pre) = match self.quantity {
            NavQuantity::Velocity => (r.s.v, r.s.nv, ["vx", "vy", "vz"], "v"),
            NavQuantity::Position => (r.s.q, r.s.nq, ["x", "y", "z"], "q"),
        };
        r.columns = names.iter().map(|c| format!("{pre}.{b}.{c}")).collect();
        for &k in r.idx {
            for a in 0..3 {
                r.values.push(src[k * stride + a] + self.bias[a] + self.noise[a] * rng.normal());
            }
        }
        if self.quantity == NavQuantity::Velocity {
            r.white_sigma = self.noise.to_vec();
        }
        Ok(())
    }
}
