//! The recorded result of a simulation.

use crate::data::Data;
use crate::error::{FfError, Result};
use crate::model::Model;

pub use crate::trajectory::Trajectory;

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
