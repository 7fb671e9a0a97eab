//! The record a simulation returns (its methods, which need a `Model`, are in `sim::trajectory`). The type lives
//! at the bottom of the engine, beside `error`, because an interrupted run hands back the samples it finished inside
//! its error (`error::Partial::Trajectory`): defined in `sim`, it made `error` depend on the simulator.

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
