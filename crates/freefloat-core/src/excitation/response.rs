//! Base response of a free-floating robot to prescribed joint motion with zero total momentum, and the
//! momentum-regressor rows along it.

use crate::data::Data;
use crate::error::{FfError, Result};
use crate::interrupt::stopped;
use crate::kinematics::{base_twist_for_momentum, forward_velocities_unchecked};
use crate::model::{JointType, Model};
use crate::regressors::momentum_regressor_from_data_unchecked;
use crate::sim::{integrate_base_poses, Steps};
use crate::spatial::{rot_from_quat, Motion, Se3, V3};
use nalgebra::{DMatrix, Vector6};
use std::sync::atomic::AtomicBool;

/// Joint angles and rates of the driven joints on a uniform time grid: `q`, `qd` are (samples × n)
/// row-major; `iq`/`iv` are the driven joints' indices into the model's q and v.
pub struct JointPath<'a> {
    /// Grid step (s).
    pub step: f64,
    /// Indices of the driven joints in q.
    pub iq: &'a [usize],
    /// Indices of the driven joints in v (6 or more: after the free base).
    pub iv: &'a [usize],
    /// Joint angles, samples × n, row-major (rad).
    pub q: &'a [f64],
    /// Joint rates, samples × n, row-major (rad/s).
    pub qd: &'a [f64],
}

impl JointPath<'_> {
    /// Number of driven joints.
    pub fn n(&self) -> usize {
        self.iq.len()
    }

    /// Number of grid points.
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
        if !self.q.len().is_multiple_of(n) || self.qd.len() != self.q.len() || self.q.len() < 2 * n {
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

/// Base twist `[v; ω]` in the base frame that keeps the total momentum zero (Naveen, Shah, Misra's
/// `[v_0; ω_0] = H_b⁻¹ (h − H_q q̇)` with h = 0), by the engine's one momentum solve
/// `kinematics::base_twist_for_momentum`. Zero momentum is zero in every frame, so `q`'s base pose is irrelevant; it is
/// evaluated at the identity (`q` is used as scratch), which leaves in `d` the joint-only twists `place_base` needs.
pub fn base_twist_zero_momentum(m: &Model, d: &mut Data, q: &mut [f64], v: &mut [f64]) -> Result<Vector6<f64>> {
    if m.joint_types.first() != Some(&JointType::Free) {
        return Err(FfError::arg("model", "the zero-momentum base twist needs a free-floating base"));
    }
    crate::check::check_args(m, Some(d), &crate::check::Args::qv(q, v))?;
    q[..7].copy_from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    base_twist_for_momentum(m, d, q, &v[6..], &[0.0; 6])
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
/// joints (the designed ones: Naveen et al.'s wheels follow fixed seeds and would swamp it).
///
/// Integration is the trapezoidal rule on the group between grid points: the attitude advances by
/// `exp(h (ω_i + ω_{i+1}) / 2)` and the position by `h (R_i v_i + R_{i+1} v_{i+1}) / 2` (second order;
/// the grid is fine, and the design needs the base motion as a proxy, not as a simulation).
#[allow(clippy::too_many_arguments)]
pub fn excitation_rows(
    m: &Model,
    q0: &[f64],
    path: &JointPath,
    stride: usize,
    offset: usize,
    columns: &[usize],
    n_signal: usize,
    threads: usize,
) -> Result<ExcitationRows> {
    let s = sample_blocks(m, q0, path, stride, offset, columns, n_signal, threads, None)?;
    let total: usize = s.blocks.iter().map(|b| b.nrows()).sum();
    let mut rows = DMatrix::zeros(total, columns.len());
    let mut r0 = 0;
    for b in &s.blocks {
        rows.rows_mut(r0, b.nrows()).copy_from(b);
        r0 += b.nrows();
    }
    Ok(ExcitationRows { rows, sumsq: s.sumsq, count: s.count, q_end: s.q_end })
}

/// The rows of `excitation_rows` as consecutive blocks, one per worker thread (the objective forms each
/// block's Gram matrix where it was built).
pub(crate) struct SampleBlocks {
    pub blocks: Vec<DMatrix<f64>>,
    pub sumsq: f64,
    pub count: usize,
    pub q_end: Vec<f64>,
}

/// Three phases, so that the expensive ones run in parallel: (1) the zero-momentum twist at every grid
/// point depends on the joints only (not on the base pose), so the points are split over threads; (2) the
/// base pose is integrated sequentially (a quaternion product per point); (3) the regressor rows at the
/// sampled points, again split over threads. Every worker reads `stop` (see `interrupt::supervise`) before
/// each grid point and ends with `FfError::Interrupted` once it is raised.
#[allow(clippy::too_many_arguments)]
pub(crate) fn sample_blocks(
    m: &Model,
    q0: &[f64],
    path: &JointPath,
    stride: usize,
    offset: usize,
    columns: &[usize],
    n_signal: usize,
    threads: usize,
    stop: Option<&AtomicBool>,
) -> Result<SampleBlocks> {
    let halt = || FfError::interrupted("excitation objective stopped");
    if m.joint_types[0] != JointType::Free {
        return Err(FfError::arg("model", "exciting-trajectory design needs a free-floating base"));
    }
    path.check(m)?;
    if q0.len() != m.nq {
        return Err(FfError::arg("q0", format!("expected {} numbers, got {}", m.nq, q0.len())));
    }
    crate::check::check_finite("q0", q0)?;
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
    let threads = threads.clamp(1, 16);
    let set_joints = |i: usize, q: &mut [f64], v: &mut [f64]| {
        for k in 0..n {
            q[path.iq[k]] = path.q[i * n + k];
            v[path.iv[k]] = path.qd[i * n + k];
        }
    };

    // (1) twists at every grid point
    let chunk = samples.div_ceil(threads);
    let twists: Vec<Vector6<f64>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..samples)
            .step_by(chunk)
            .map(|i0| {
                s.spawn(move || -> Result<Vec<Vector6<f64>>> {
                    let mut d = Data::new(m);
                    let (mut q, mut v) = (q0.to_vec(), vec![0.0; m.nv]);
                    (i0..(i0 + chunk).min(samples))
                        .map(|i| {
                            if stopped(stop) {
                                return Err(halt());
                            }
                            set_joints(i, &mut q, &mut v);
                            base_twist_zero_momentum(m, &mut d, &mut q, &mut v)
                        })
                        .collect()
                })
            })
            .collect();
        let mut all = Vec::with_capacity(samples);
        for h in handles {
            all.extend(h.join().map_err(|_| FfError::Numerical("excitation worker panicked".into()))??);
        }
        Ok::<_, FfError>(all)
    })?;

    // (2) base poses by the trapezoidal rule on the group (the engine's one copy, `sim::integrate_base_poses`)
    let flat: Vec<f64> = twists.iter().flat_map(|t| t.iter().copied()).collect();
    let mut pose_rows = vec![0.0; 7 * samples];
    integrate_base_poses(Steps::Uniform(path.step), &flat, &q0[..7], &mut pose_rows)?;
    let poses: Vec<Se3> =
        pose_rows.chunks_exact(7).map(|p| Se3::new(rot_from_quat(&p[3..7]), V3::new(p[0], p[1], p[2]))).collect();

    // (3) regressor rows at the sampled points
    let picked: Vec<usize> = (0..samples).filter(|i| i % stride == offset).collect();
    let pchunk = picked.len().div_ceil(threads).max(1);
    let (twists, poses) = (&twists, &poses);
    let parts: Vec<(DMatrix<f64>, f64)> = std::thread::scope(|s| {
        let handles: Vec<_> = picked
            .chunks(pchunk)
            .map(|idx| {
                s.spawn(move || -> Result<(DMatrix<f64>, f64)> {
                    let mut d = Data::new(m);
                    let (mut q, mut v) = (q0.to_vec(), vec![0.0; m.nv]);
                    q[..7].copy_from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
                    let mut full = DMatrix::zeros(6, ncol);
                    let mut rows = DMatrix::zeros(6 * idx.len(), columns.len());
                    let mut sumsq = 0.0;
                    for (r, &i) in idx.iter().enumerate() {
                        if stopped(stop) {
                            return Err(halt());
                        }
                        set_joints(i, &mut q, &mut v);
                        forward_velocities_unchecked(m, &mut d, &q, &v); // identity base, joint-only twists
                        place_base(m, &mut d, &twists[i], &poses[i]);
                        momentum_regressor_from_data_unchecked(m, &d, &mut full);
                        for (c, &col) in columns.iter().enumerate() {
                            for k in 0..6 {
                                rows[(6 * r + k, c)] = full[(k, col)];
                            }
                        }
                        sumsq +=
                            twists[i].norm_squared() + (0..n_signal).map(|k| path.qd[i * n + k].powi(2)).sum::<f64>();
                    }
                    Ok((rows, sumsq))
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("excitation worker panicked")).collect::<Result<Vec<_>>>()
    })?;

    let mut q_end = q0.to_vec();
    for k in 0..n {
        q_end[path.iq[k]] = path.q[(samples - 1) * n + k];
    }
    q_end[..7].copy_from_slice(&pose_rows[7 * (samples - 1)..]);
    let sumsq = parts.iter().map(|p| p.1).sum();
    Ok(SampleBlocks {
        blocks: parts.into_iter().map(|p| p.0).collect(),
        sumsq,
        count: (6 + n_signal) * picked.len(),
        q_end,
    })
}
