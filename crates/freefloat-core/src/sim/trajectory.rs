//! The recorded result of a simulation.

use crate::data::Data;
use crate::error::{FfError, Result};
use crate::model::Model;

/// Samples stored row-major: `q` is T × nq, `v`, `ddq`, `tau` are T × nv, `momentum` T × 6.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    /// Length of one configuration.
    pub nq: usize,
    /// Length of one velocity.
    pub nv: usize,
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Configurations, T × nq.
    pub q: Vec<f64>,
    /// Velocities, T × nv (base twist in the base frame).
    pub v: Vec<f64>,
    /// Accelerations (base: body-frame spatial acceleration, as `v` is body-frame).
    pub ddq: Vec<f64>,
    /// Generalized forces acting: inputs for free joints, the needed forces for prescribed joints.
    pub tau: Vec<f64>,
    /// [linear; angular about the inertial origin], inertial frame.
    pub momentum: Vec<f64>,
    /// Kinetic energy (J).
    pub kinetic_energy: Vec<f64>,
    /// Work done by all generalized forces since t = 0 (integrated with the state).
    pub work: Vec<f64>,
    /// Propellant left in each tank (T × number of tanks; empty without tanks).
    pub propellant: Vec<f64>,
    /// The base's standard inertial parameters over time (T × 10; recorded with tanks only, whose
    /// propellant changes them).
    pub base_parameters: Vec<f64>,
    /// Accepted integration steps.
    pub steps: usize,
    /// Rejected steps (adaptive method).
    pub rejected: usize,
    /// Dynamics evaluations (stages).
    pub evaluations: usize,
}

impl Trajectory {
    /// An empty trajectory with room for `samples` records (growing the arrays during a run costs
    /// several percent of a simulation). The reservation is fallible: a size the allocator refuses
    /// (or whose byte count overflows) is an error naming the size, never an abort.
    pub fn with_capacity(m: &Model, samples: usize) -> Result<Self> {
        let (nq, nv) = (m.nq, m.nv);
        let mut tr = Trajectory { nq, nv, ..Default::default() };
        let refuse = || {
            FfError::arg(
                "t_final",
                format!(
                    "a trajectory of {samples} samples ({:.3} GB) could not be allocated; record fewer samples \
                     (a larger record_every or dt, a shorter t_final)",
                    samples as f64 * Self::bytes_per_sample(m) as f64 / 1e9
                ),
            )
        };
        for (buf, width) in
            [(&mut tr.q, nq), (&mut tr.v, nv), (&mut tr.ddq, nv), (&mut tr.tau, nv), (&mut tr.momentum, 6)]
        {
            let n = samples.checked_mul(width).ok_or_else(refuse)?;
            buf.try_reserve_exact(n).map_err(|_| refuse())?;
        }
        for buf in [&mut tr.t, &mut tr.kinetic_energy, &mut tr.work] {
            buf.try_reserve_exact(samples).map_err(|_| refuse())?;
        }
        Ok(tr)
    }

    /// Bytes one recorded sample takes: t, q, v, ddq, tau, momentum, kinetic energy, work.
    pub fn bytes_per_sample(m: &Model) -> usize {
        8 * (m.nq + 3 * m.nv + 6 + 3)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether no sample was recorded.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Append a sample; `d` must hold the results of the dynamics evaluated at (t, q, v): `ddq`,
    /// `tau`, and the momentum and kinetic energy ABA forms on the way.
    pub(crate) fn push(&mut self, d: &Data, t: f64, q: &[f64], v: &[f64], work: f64) {
        self.t.push(t);
        self.q.extend_from_slice(q);
        self.v.extend_from_slice(v);
        self.ddq.extend_from_slice(&d.ddq);
        self.tau.extend_from_slice(&d.tau);
        let mut h = [0.0; 6];
        d.aba_momentum.write(&mut h);
        self.momentum.extend_from_slice(&h);
        self.kinetic_energy.push(d.aba_kinetic_energy);
        self.work.push(work);
    }
}
