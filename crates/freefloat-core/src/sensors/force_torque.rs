//! Six-axis force/torque sensor at a joint (a wrist): the wrench the joint transmits to its child body.
//!
//! The true wrench is RNEA's joint force (Featherstone, *Rigid Body Dynamics Algorithms*, 2008, eq. 5.9):
//! f_i = I_i a_i + v_i ×* I_i v_i + Σ_{children c} ⁱX_c* f_c, the spatial force the parent exerts on body i
//! through joint i, in body i's frame, moment about body i's origin, evaluated at the recorded (q, v, q̈)
//! with the model's gravity. Forces applied to the bodies beyond the joint (contact, thrusters on the
//! arm) are not recorded by a trajectory and so are not in the measurement.
//! Measured: f̃ = f + b + n, n ~ N(0, diag(σ_f² E₃, σ_τ² E₃)), columns fx, fy, fz [N], mx, my, mz [N·m].

use super::fields::Fields;
use super::{GaussianRng, SensorRun};
use crate::data::Data;
use crate::dynamics::rnea;
use crate::error::{FfError, Result};

/// A force/torque sensor.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceTorqueConfig {
    /// The joint whose transmitted wrench is measured.
    pub joint: String,
    /// Per-sample standard deviation of each force component [N].
    pub force_noise: f64,
    /// Per-sample standard deviation of each moment component [N·m].
    pub torque_noise: f64,
    /// Constant force bias [N].
    pub force_bias: [f64; 3],
    /// Constant moment bias [N·m].
    pub torque_bias: [f64; 3],
}

impl ForceTorqueConfig {
    pub(crate) fn parse(f: &mut Fields) -> Result<Self> {
        let joint = f.string("joint")?.ok_or_else(|| {
            FfError::arg(&format!("{}.joint", f.ctx), "missing: name the joint whose wrench the sensor measures")
        })?;
        Ok(ForceTorqueConfig {
            joint,
            force_noise: f.nonneg("force_noise", 0.0, "N")?,
            torque_noise: f.nonneg("torque_noise", 0.0, "N·m")?,
            force_bias: f.vec3("force_bias", [0.0; 3], false)?,
            torque_bias: f.vec3("torque_bias", [0.0; 3], false)?,
        })
    }

    pub(crate) fn run(&self, r: &mut SensorRun, rng: &mut GaussianRng) -> Result<()> {
        let m = r.m;
        let body = (0..m.nbodies()).find(|&i| m.joint_names[i] == self.joint).ok_or_else(|| {
            FfError::arg(
                &format!("{}.joint", r.ctx),
                format!("'{}' is not a joint of model '{}' (joints: {})", self.joint, m.name, m.joint_names.join(", ")),
            )
        })?;
        let ddq = r.s.ddq.ok_or_else(|| {
            FfError::arg(
                &format!("{}.joint", r.ctx),
                "a force/torque sensor needs the accelerations of the run (ddq), and the data given have none",
            )
        })?;
        r.columns = ["fx", "fy", "fz", "mx", "my", "mz"].iter().map(|c| format!("ft.{}.{c}", r.name)).collect();
        let (nq, nv) = (r.s.nq, r.s.nv);
        let mut d = Data::new(m);
        for &k in r.idx {
            let q = &r.s.q[k * nq..(k + 1) * nq];
            let v = &r.s.v[k * nv..(k + 1) * nv];
            let a = &ddq[k * nv..(k + 1) * nv];
            rnea(m, &mut d, q, v, a, None)?;
            let f = d.f[body];
            for c in 0..3 {
                r.values.push(f.lin[c] + self.force_bias[c] + self.force_noise * rng.normal());
            }
            for c in 0..3 {
                r.values.push(f.ang[c] + self.torque_bias[c] + self.torque_noise * rng.normal());
            }
        }
        Ok(())
    }
}
