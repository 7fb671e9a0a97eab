//! Star tracker: the base attitude with a small random rotation.
//!
//! Q̃_k = Q_k ⊗ exp(δθ_k / 2), δθ_k ~ N(0, diag(σ_x², σ_y², σ_z²)) white, in the base (sensor) frame:
//! the usual multiplicative attitude-error model of star trackers (e.g. Markley & Crassidis,
//! *Fundamentals of Spacecraft Attitude Determination and Control*, 2014, §7.2.4). A tracker is several
//! times less accurate about its boresight than across it, hence one σ per axis [rad]. So the error
//! rotation vector log(Q_k⁻¹ Q̃_k) has covariance diag(σ²).

use super::fields::Fields;
use super::{base_label, require_free_base, GaussianRng, SensorRun};
use crate::error::Result;
use crate::spatial::V3;
use crate::spatial::{quat_exp, quat_mul};

/// A star tracker's attitude noise.
#[derive(Clone, Debug, PartialEq)]
pub struct StarTrackerConfig {
    /// Standard deviation of the error rotation about the base x, y, z axes [rad].
    pub sigma: [f64; 3],
}

impl StarTrackerConfig {
    pub(crate) fn parse(f: &mut Fields) -> Result<Self> {
        Ok(StarTrackerConfig { sigma: f.vec3("sigma", [0.0; 3], true)? })
    }

    pub(crate) fn run(&self, r: &mut SensorRun, rng: &mut GaussianRng) -> Result<()> {
        require_free_base(r.m, &r.ctx, "a star tracker")?;
        let b = base_label(r.m);
        r.columns = ["qx", "qy", "qz", "qw"].iter().map(|c| format!("q.{b}.{c}")).collect();
        let nq = r.s.nq;
        for &k in r.idx {
            let q = &r.s.q[k * nq + 3..k * nq + 7];
            let d = V3::new(self.sigma[0] * rng.normal(), self.sigma[1] * rng.normal(), self.sigma[2] * rng.normal());
            // right multiplication: the error is a rotation of the body (sensor) frame
            let qm = quat_mul(&[q[0], q[1], q[2], q[3]], &quat_exp(&d));
            r.values.extend_from_slice(&qm);
        }
        Ok(())
    }
}
