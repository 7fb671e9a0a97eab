//! Base response of a free-floating robot to prescribed joint motion with zero total momentum, and the
//! momentum-regressor rows along it.

use crate::data::Data;
use crate::error::{FfError, Result};
use crate::estimation::{gram_rows_upper, GRAM_TILE};
use crate::interrupt::stopped;
use crate::kinematics::{base_twist_for_momentum, forward_velocities_unchecked};
use crate::model::{JointType, Model};
use crate::regressors::body_momentum_columns;
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
    let s = sample_blocks(m, q0, path, stride, offset, columns, n_signal, threads, Collect::Rows, None)?;
    let total: usize = s.parts.iter().map(|b| b.rows.nrows()).sum();
    let mut rows = DMatrix::zeros(total, columns.len());
    let mut r0 = 0;
    for b in &s.parts {
        rows.rows_mut(r0, b.rows.nrows()).copy_from(&b.rows);
        r0 += b.rows.nrows();
    }
    Ok(ExcitationRows { rows, sumsq: s.sumsq, count: s.count, q_end: s.q_end })
}

/// What the workers of phase 3 of [`sample_blocks`] keep of the rows they build.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Collect {
    /// the rows themselves (`excitation_rows`)
    Rows,
    /// only their Gram matrix (the objective), accumulated while each 8-point chunk of rows is still in L1
    Gram,
}

/// One phase-3 worker's share: its rows (consecutive, in grid order) or their Gram matrix.
pub(crate) struct Part {
    /// (6 · its points) × columns.len() with [`Collect::Rows`]; 0 × 0 otherwise
    pub rows: DMatrix<f64>,
    /// with [`Collect::Gram`]: `width × width` row-major, the upper triangle of RᵀR valid (see `gram_rows_upper`);
    /// empty otherwise
    pub gram: Vec<f64>,
    /// row length of `gram`: columns.len() padded to a multiple of `GRAM_TILE`
    pub width: usize,
}

/// The rows of `excitation_rows`, or their Gram matrix, as one [`Part`] per worker thread.
pub(crate) struct SampleBlocks {
    pub parts: Vec<Part>,
    pub sumsq: f64,
    pub count: usize,
    pub q_end: Vec<f64>,
}

/// Points per chunk of phase 3's row-major row buffer: 48 rows of 56 columns are 21 kB, which stay in L1 between
/// their writes and the Gram kernel's reads (as in the identification's Gram pass).
const CHUNK_POINTS: usize = 8;

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
    collect: Collect,
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
    integrate_base_poses(Steps::Uniform(path.step), &flat, None, &q0[..7], &mut pose_rows)?;
    let poses: Vec<Se3> =
        pose_rows.chunks_exact(7).map(|p| Se3::new(rot_from_quat(&p[3..7]), V3::new(p[0], p[1], p[2]))).collect();

    // (3) regressor rows at the sampled points. Only the bodies with kept columns are formed, each from the one
    // copy of Naveen, Shah, Misra's eq. 10 (`body_momentum_columns`), straight into a row-major chunk of
    // CHUNK_POINTS points; the chunk then goes into the worker's rows or its Gram matrix.
    let ncols = columns.len();
    let width = ncols.div_ceil(GRAM_TILE) * GRAM_TILE;
    let bodies: Vec<(usize, Vec<(usize, usize)>)> = (0..m.nbodies())
        .map(|i| {
            (
                i,
                columns
                    .iter()
                    .enumerate()
                    .filter(|&(_, &c)| c / 10 == i)
                    .map(|(j, &c)| (c % 10, j))
                    .collect::<Vec<_>>(),
            )
        })
        .filter(|(_, kept)| !kept.is_empty())
        .collect();
    let bodies = &bodies;
    let picked: Vec<usize> = (0..samples).filter(|i| i % stride == offset).collect();
    let pchunk = picked.len().div_ceil(threads).max(1);
    let (twists, poses) = (&twists, &poses);
    let parts: Vec<(Part, f64)> = std::thread::scope(|s| {
        let handles: Vec<_> = picked
            .chunks(pchunk)
            .map(|idx| {
                s.spawn(move || -> Result<(Part, f64)> {
                    let mut d = Data::new(m);
                    let (mut q, mut v) = (q0.to_vec(), vec![0.0; m.nv]);
                    q[..7].copy_from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
                    let mut part = Part { rows: DMatrix::zeros(0, 0), gram: vec![], width };
                    match collect {
                        Collect::Rows => part.rows = DMatrix::zeros(6 * idx.len(), ncols),
                        Collect::Gram => part.gram = vec![0.0; width * width],
                    }
                    // the padding columns stay zero
                    let mut buf = vec![0.0; 6 * CHUNK_POINTS * width];
                    let mut sumsq = 0.0;
                    for (c0, chunk) in idx.chunks(CHUNK_POINTS).enumerate() {
                        for (slot, &i) in chunk.iter().enumerate() {
                            if stopped(stop) {
                                return Err(halt());
                            }
                            set_joints(i, &mut q, &mut v);
                            forward_velocities_unchecked(m, &mut d, &q, &v); // identity base, joint-only twists
                            place_base(m, &mut d, &twists[i], &poses[i]);
                            for (body, kept) in bodies {
                                let cols = body_momentum_columns(&d, *body);
                                for &(k, j) in kept {
                                    for r in 0..6 {
                                        buf[(6 * slot + r) * width + j] = cols[k][r];
                                    }
                                }
                            }
                            sumsq += twists[i].norm_squared()
                                + (0..n_signal).map(|k| path.qd[i * n + k].powi(2)).sum::<f64>();
                        }
                        let rows = 6 * chunk.len();
                        match collect {
                            Collect::Gram => gram_rows_upper(&mut part.gram, &buf, width, rows, width),
                            Collect::Rows => {
                                let r0 = 6 * CHUNK_POINTS * c0;
                                for r in 0..rows {
                                    for j in 0..ncols {
                                        part.rows[(r0 + r, j)] = buf[r * width + j];
                                    }
                                }
                            }
                        }
                    }
                    Ok((part, sumsq))
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
        parts: parts.into_iter().map(|p| p.0).collect(),
        sumsq,
        count: (6 + n_signal) * picked.len(),
        q_end,
    })
}
