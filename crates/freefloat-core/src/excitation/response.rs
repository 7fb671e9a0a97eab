//! Base response of a free-floating robot to prescribed joint motion with zero total momentum, and the
//! momentum-regressor rows along it.

use crate::data::Data;
use crate::error::{FfError, Result};
use crate::kinematics::forward_velocities;
use crate::model::{JointType, Model};
use crate::regressors::momentum_regressor_from_data;
use crate::spatial::{quat_exp, quat_mul, quat_normalize, rot_from_quat, Force, Inertia, Motion, Se3, V3};
use nalgebra::{DMatrix, Vector6};

/// Joint angles and rates of the driven joints on a uniform time grid: `q`, `qd` are (samples × n)
/// row-major; `iq`/`iv` are the driven joints' indices into the model's q and v.
pub struct JointPath<'a> {
    pub step: f64,
    pub iq: &'a [usize],
    pub iv: &'a [usize],
    pub q: &'a [f64],
    pub qd: &'a [f64],
}

impl JointPath<'_> {
    pub fn n(&self) -> usize {
        self.iq.len()
    }

    pub fn samples(&self) -> usize {
        if self.iq.is_empty() {
            0
        } else {
            self.q.len() / self.iq.len()
        }
    }

    fn check(&self, m: &Model) -> Result<()> {
        let n = self.n();
        if n == 0 || self.iv.len() != n {
            return Err(FfError::arg("joints", "need one or more driven joints, with q and v indices alike"));
        }
        if self.q.len() % n != 0 || self.qd.len() != self.q.len() || self.q.len() < 2 * n {
            return Err(FfError::arg("q/qd", format!("expected two (samples × {n}) arrays of 2+ samples")));
        }
        if !(self.step > 0.0) || !self.step.is_finite() {
            return Err(FfError::arg("step", format!("grid step must be positive, got {}", self.step)));
        }
        if let Some(k) = self.q.iter().chain(self.qd.iter()).position(|x| !x.is_finite()) {
            return Err(FfError::arg("q/qd", format!("entry {k} is not finite")));
        }
        if self.iq.iter().any(|&i| i >= m.nq) || self.iv.iter().any(|&i| i < 6 || i >= m.nv) {
            return Err(FfError::arg("joints", "a driven joint index is outside the model's joints"));
        }
        Ok(())
    }
}

/// Base twist `[v; ω]` in the base frame that keeps the total momentum zero (seed 001 digest A.10 with
/// h = 0): `Ic v_b = −h_joints`, with `Ic` the composite inertia of the whole robot and `h_joints` the
/// momentum of the joint motion alone, both about the base origin in base axes. Zero momentum is zero in
/// every frame, so `q`'s base pose is irrelevant; it is evaluated at the identity (`q` is used as scratch).
pub fn base_twist_zero_momentum(m: &Model, d: &mut Data, q: &mut [f64], v: &mut [f64]) -> Result<Vector6<f64>> {
    q[..7].copy_from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    v[..6].fill(0.0);
    forward_velocities(m, d, q, v);
    // One pass: the joint motion's momentum and the whole robot's inertia, both about the base origin.
    let (mut h, mut ic) = (Force::ZERO, Inertia::zero());
    for i in 0..m.nbodies() {
        h += d.o_mi[i].act_force(&m.inertias[i].mul_motion(&d.v[i]));
        ic = ic.add(&m.inertias[i].transformed(&d.o_mi[i]));
    }
    let rhs = -Vector6::new(h.lin.x, h.lin.y, h.lin.z, h.ang.x, h.ang.y, h.ang.z);
    ic.to_matrix()
        .cholesky()
        .map(|c| c.solve(&rhs))
        .ok_or_else(|| FfError::Numerical("the composite inertia of the robot is not positive definite".into()))
}

/// After `base_twist_zero_momentum` (identity base, joint-only twists in `d`): add the base twist to every
/// body twist (twists are linear in the rates) and move every placement rigidly to the base pose, so `d`
/// describes the real state without a second kinematics pass.
fn place_base(m: &Model, d: &mut Data, tw: &Vector6<f64>, base: &Se3) {
    let vb = Motion::from_slice(tw.as_slice());
    for i in 0..m.nbodies() {
        d.v[i] += d.o_mi[i].inv_act_motion(&vb);
        d.o_mi[i] = base.compose(&d.o_mi[i]);
    }
}

/// Minimal-regressor rows along a joint path, and the signal the objective rewards.
pub struct ExcitationRows {
    /// (6 · sampled points) × columns.len(): momentum-regressor columns `columns` at the sampled points
    pub rows: DMatrix<f64>,
    /// Σ over sampled points of |base twist|² + |rates of the first `n_signal` driven joints|² (eq. 32's Σ h²)
    pub sumsq: f64,
    /// number of terms in `sumsq`: (6 + n_signal) · sampled points (eq. 32's N_l N_m)
    pub count: usize,
    /// configuration at the end of the path (base pose integrated)
    pub q_end: Vec<f64>,
}

/// Integrate the base pose along `path` (starting at `q0`'s base pose, every other joint at `q0`'s value)
/// with the zero-momentum base twist, and stack the momentum-regressor `columns` at grid points
/// `offset, offset + stride, …`. The signal sums the base twist and the rates of the first `n_signal` driven
/// joints (the designed ones: seed 001's wheels follow fixed seeds and would swamp it).
///
/// Integration is the trapezoidal rule on the group between grid points: the attitude advances by
/// `exp(h (ω_i + ω_{i+1}) / 2)` and the position by `h (R_i v_i + R_{i+1} v_{i+1}) / 2` (second order;
/// the grid is fine, and the design needs the base motion as a proxy, not as a simulation).
pub fn excitation_rows(
    m: &Model,
    d: &mut Data,
    q0: &[f64],
    path: &JointPath,
    stride: usize,
    offset: usize,
    columns: &[usize],
    n_signal: usize,
) -> Result<ExcitationRows> {
    if m.joint_types[0] != JointType::Free {
        return Err(FfError::arg("model", "exciting-trajectory design needs a free-floating base"));
    }
    path.check(m)?;
    if q0.len() != m.nq {
        return Err(FfError::arg("q0", format!("expected {} numbers, got {}", m.nq, q0.len())));
    }
    if stride == 0 || offset >= stride {
        return Err(FfError::arg("stride", format!("need stride ≥ 1 and offset < stride, got {stride}, {offset}")));
    }
    let ncol = 10 * m.nbodies();
    if let Some(&c) = columns.iter().find(|&&c| c >= ncol) {
        return Err(FfError::arg("columns", format!("column {c} is outside the {ncol} standard parameters")));
    }
    let (n, samples) = (path.n(), path.samples());
    if n_signal > n {
        return Err(FfError::arg("n_signal", format!("{n_signal} signal joints of {n} driven joints")));
    }
    let picked = (0..samples).filter(|i| i % stride == offset).count();
    let mut rows = DMatrix::zeros(6 * picked, columns.len());
    let mut full = DMatrix::zeros(6, ncol);
    let mut q = q0.to_vec();
    let mut scratch = q0.to_vec();
    let mut v = vec![0.0; m.nv];
    let (mut pos, mut quat) = (V3::new(q[0], q[1], q[2]), [q[3], q[4], q[5], q[6]]);
    quat_normalize(&mut quat);
    let mut prev: Option<(Vector6<f64>, V3)> = None; // twist and inertial-frame base velocity at the last point
    let (mut sumsq, mut r) = (0.0, 0);
    for i in 0..samples {
        for k in 0..n {
            scratch[path.iq[k]] = path.q[i * n + k];
            v[path.iv[k]] = path.qd[i * n + k];
        }
        let tw = base_twist_zero_momentum(m, d, &mut scratch, &mut v)?;
        if let Some((tw0, vel0)) = prev {
            let w = (tw0.fixed_rows::<3>(3) + tw.fixed_rows::<3>(3)) * (0.5 * path.step);
            quat = quat_mul(&quat, &quat_exp(&V3::new(w.x, w.y, w.z)));
            quat_normalize(&mut quat);
            let vel = rot_from_quat(&quat) * V3::new(tw[0], tw[1], tw[2]);
            pos += (vel0 + vel) * (0.5 * path.step);
        }
        let vel = rot_from_quat(&quat) * V3::new(tw[0], tw[1], tw[2]);
        prev = Some((tw, vel));
        if i % stride == offset {
            place_base(m, d, &tw, &Se3::new(rot_from_quat(&quat), pos));
            momentum_regressor_from_data(m, d, &mut full);
            for (c, &col) in columns.iter().enumerate() {
                for k in 0..6 {
                    rows[(6 * r + k, c)] = full[(k, col)];
                }
            }
            sumsq += tw.norm_squared() + (0..n_signal).map(|k| path.qd[i * n + k].powi(2)).sum::<f64>();
            r += 1;
        }
    }
    q.copy_from_slice(&scratch);
    q[..3].copy_from_slice(pos.as_slice());
    q[3..7].copy_from_slice(&quat);
    Ok(ExcitationRows { rows, sumsq, count: (6 + n_signal) * picked, q_end: q })
}
