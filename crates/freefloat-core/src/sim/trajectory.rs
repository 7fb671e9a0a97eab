//! The recorded result of a simulation.

use crate::data::Data;
use crate::model::Model;

/// Samples stored row-major: `q` is T × nq, `v`, `ddq`, `tau` are T × nv, `momentum` T × 6.
#[derive(Clone, Debug, Default)]
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
    /// several percent of a simulation).
    pub fn with_capacity(m: &Model, samples: usize) -> Self {
        let (nq, nv) = (m.nq, m.nv);
        Trajectory {
            nq,
            nv,
            t: Vec::with_capacity(samples),
            q: Vec::with_capacity(samples * nq),
            v: Vec::with_capacity(samples * nv),
            ddq: Vec::with_capacity(samples * nv),
            tau: Vec::with_capacity(samples * nv),
            momentum: Vec::with_capacity(samples * 6),
            kinetic_energy: Vec::with_capacity(samples),
            work: Vec::with_capacity(samples),
            ..Default::default()
        }
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
