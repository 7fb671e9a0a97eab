//! The recorded result of a simulation.

use crate::data::Data;
use crate::error::Result;
use crate::model::Model;

/// Samples stored row-major: `q` is T × nq, `v`, `ddq`, `tau` are T × nv, `momentum` T × 6.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    pub nq: usize,
    pub nv: usize,
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    /// Accelerations (base: body-frame spatial acceleration, as `v` is body-frame).
    pub ddq: Vec<f64>,
    /// Generalized forces acting: inputs for free joints, the needed forces for prescribed joints.
    pub tau: Vec<f64>,
    /// [linear; angular about the inertial origin], inertial frame.
    pub momentum: Vec<f64>,
    pub kinetic_energy: Vec<f64>,
    /// Work done by all generalized forces since t = 0 (integrated with the state).
    pub work: Vec<f64>,
    pub steps: usize,
    pub rejected: usize,
    pub evaluations: usize,
}

impl Trajectory {
    pub fn new(m: &Model) -> Self {
        Trajectory { nq: m.nq, nv: m.nv, ..Default::default() }
    }

    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Append a sample; `d` must hold `ddq` and `tau` evaluated at (t, q, v).
    pub(crate) fn push(&mut self, m: &Model, d: &mut Data, t: f64, q: &[f64], v: &[f64], work: f64) -> Result<()> {
        self.t.push(t);
        self.q.extend_from_slice(q);
        self.v.extend_from_slice(v);
        self.ddq.extend_from_slice(&d.ddq);
        self.tau.extend_from_slice(&d.tau);
        let (h, e) = super::record_quantities(m, d, q, v);
        self.momentum.extend_from_slice(&h);
        self.kinetic_energy.push(e);
        self.work.push(work);
        Ok(())
    }
}
