//! Objective of the exciting-trajectory design, Naveen, Shah, Misra, eq. (32):
//!     C = κ(G_m) + w · N_l N_m / Σ_i Σ_j h_ij²
//! κ is the 2-norm condition number of the stacked minimal regressor, obtained from the eigenvalues of its
//! small Gram matrix (n_min × n_min) rather than an SVD of the tall matrix; h ranges over the base twist
//! components and the rates of the designed (arm) joints at the sampled points — `ObjectiveSpec::n_signal`.

use super::response::{sample_blocks, Collect, JointPath, Part};
use crate::error::{FfError, Result};
use crate::interrupt::{stopped, supervise, Hook};
use crate::model::Model;
use nalgebra::DMatrix;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Everything about an evaluation except the joint path.
pub struct ObjectiveSpec<'a> {
    /// Initial configuration (nq): base pose and the joints that are not driven.
    pub q0: &'a [f64],
    /// Sample every `stride`-th grid point ...
    pub stride: usize,
    /// ... starting at grid point `offset` (< stride).
    pub offset: usize,
    /// Momentum-regressor columns of the minimal parameters (indices into 10·nbodies).
    pub columns: &'a [usize],
    /// Weight of the signal term against the condition number in eq. (32).
    pub weight: f64,
    /// the first `n_signal` driven joints count in the signal term (see `excitation_rows`)
    pub n_signal: usize,
    /// worker threads of one evaluation (1 inside a batch whose evaluations already run in parallel)
    pub threads: usize,
}

/// One evaluation of eq. (32).
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// Value of eq. (32) (Naveen, Shah, Misra).
    pub objective: f64,
    /// κ(G_m) from the Gram matrix: accurate up to ~1e8; beyond that only indicative (still large and still
    /// decreasing as excitation improves, which is what an optimiser starting from a poor guess needs)
    pub condition_number: f64,
    /// mean square of the base twist and joint rates, Σh² / (N_l N_m)
    pub mean_square: f64,
    /// singular values of G_m, largest first
    pub singular_values: Vec<f64>,
}

/// Evaluate eq. (32) for one joint path, on `spec.threads` worker threads.
pub fn evaluate(m: &Model, spec: &ObjectiveSpec, path: &JointPath) -> Result<Evaluation> {
    evaluate_until(m, spec, path, None)
}

/// [`evaluate`], ending with `FfError::Interrupted` once `stop` is raised (read before every grid point).
fn evaluate_until(m: &Model, spec: &ObjectiveSpec, path: &JointPath, stop: Option<&AtomicBool>) -> Result<Evaluation> {
    let ex = sample_blocks(
        m,
        spec.q0,
        path,
        spec.stride,
        spec.offset,
        spec.columns,
        spec.n_signal,
        spec.threads,
        Collect::Gram,
        stop,
    )?;
    let gram = gram(&ex.parts, spec.columns.len());
    let mut lam: Vec<f64> = gram.symmetric_eigenvalues().iter().map(|&l| l.max(0.0)).collect();
    lam.sort_by(|a, b| b.total_cmp(a));
    let sv: Vec<f64> = lam.iter().map(|l| l.sqrt()).collect();
    let (smax, smin) = (sv[0], *sv.last().unwrap_or(&0.0));
    // Below ~1e-8 of σ_max the Gram matrix cannot resolve σ_min (it squares the condition number); the ratio
    // is kept anyway, floored at 1e-16 σ_max so it stays finite.
    let kappa = if smax > 0.0 { smax / smin.max(1e-16 * smax) } else { f64::INFINITY };
    let ms = ex.sumsq / ex.count as f64;
    Ok(Evaluation {
        objective: kappa + spec.weight / ms,
        condition_number: kappa,
        mean_square: ms,
        singular_values: sv,
    })
}

/// Evaluate many joint paths, split over `threads` worker threads (finite-difference gradients); with fewer
/// paths than threads, each evaluation gets the spare threads.
pub fn evaluate_batch(m: &Model, spec: &ObjectiveSpec, paths: &[JointPath], threads: usize) -> Vec<Result<Evaluation>> {
    match evaluate_batch_interruptible(m, spec, paths, threads, None) {
        Ok(all) => all,
        Err(e) => vec![Err(e)], // unreachable without a hook: nothing else stops the batch as a whole
    }
}

/// [`evaluate_batch`], stoppable: the calling thread polls `hook` (at most every `POLL_INTERVAL`, with the
/// fraction of paths evaluated) while the workers evaluate; its `false` stops every worker before its next
/// grid point and the batch returns `FfError::Interrupted` (no partial result: the caller keeps its own
/// best point, e.g. the design loop's best design so far). The values are those of [`evaluate_batch`].
pub fn evaluate_batch_interruptible(
    m: &Model,
    spec: &ObjectiveSpec,
    paths: &[JointPath],
    threads: usize,
    mut hook: Option<Hook>,
) -> Result<Vec<Result<Evaluation>>> {
    let inner = (threads / paths.len().max(1)).max(1);
    let spec = &ObjectiveSpec { threads: inner, ..*spec };
    let outer = threads.clamp(1, paths.len().max(1));
    let chunk = paths.len().div_ceil(outer).max(1);
    let stop = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let (stop, done) = (&stop, &done);
    let watch = hook.is_some().then_some(stop);
    let (all, finished) = std::thread::scope(|s| {
        let handles: Vec<_> = paths
            .chunks(chunk)
            .map(|part| {
                s.spawn(move || {
                    let mut out = Vec::with_capacity(part.len());
                    for p in part {
                        if stopped(watch) {
                            break;
                        }
                        out.push(evaluate_until(m, spec, p, watch));
                        done.fetch_add(1, Ordering::Relaxed);
                    }
                    out
                })
            })
            .collect();
        let total = paths.len().max(1) as f64;
        let finished = supervise(&mut hook, stop, &handles, || done.load(Ordering::Relaxed) as f64 / total);
        let all: Vec<_> = handles.into_iter().flat_map(|h| h.join().expect("excitation worker panicked")).collect();
        (all, finished)
    });
    if !finished {
        return Err(FfError::interrupted(format!(
            "excitation objective stopped after {} of {} evaluations",
            done.load(Ordering::Relaxed).min(paths.len()),
            paths.len()
        )));
    }
    Ok(all)
}

/// GᵀG from the workers' upper triangles (each accumulated where its rows were built, by the identification's
/// triangle kernel `estimation::gram_rows_upper`), summed and mirrored into the full symmetric n × n matrix.
/// Before, every worker kept its whole block (7680 × 52 for the paper's design, 3 MB) and a second set of threads
/// formed both triangles of each block's product through `matrixmultiply`: the blocks' page faults, the packing and
/// the lower triangle were a fifth of an evaluation (`perf`).
fn gram(parts: &[Part], n: usize) -> DMatrix<f64> {
    let mut g = DMatrix::zeros(n, n);
    for p in parts {
        let w = p.width;
        for i in 0..n {
            for j in i..n {
                g[(i, j)] += p.gram[i * w + j];
            }
        }
    }
    for j in 0..n {
        for i in j + 1..n {
            g[(i, j)] = g[(j, i)];
        }
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::excitation::excitation_rows;
    use crate::model::builtin;

    #[test]
    fn the_streamed_gram_is_the_product_of_the_rows() {
        // The objective's Gram matrix, accumulated per worker in 8-point chunks by the triangle kernel, against the
        // product of the rows `excitation_rows` stacks: 2 workers, 37 sampled points (a partial last chunk in each),
        // columns out of order and from several bodies, one of them repeated.
        let m = builtin::load("naveen_dual_arm_offset").expect("built-in model");
        let (iq, iv): (Vec<usize>, Vec<usize>) = (7..13).map(|k| (k, k - 1)).unzip();
        let samples = 111;
        let t = |i: usize| i as f64 * 0.01;
        let q: Vec<f64> = (0..samples * 6).map(|k| (0.3 * (k % 6) as f64 + 1.7 * t(k / 6)).sin()).collect();
        let qd: Vec<f64> = (0..samples * 6).map(|k| 1.7 * (0.3 * (k % 6) as f64 + 1.7 * t(k / 6)).cos()).collect();
        let path = JointPath { step: 0.01, iq: &iq, iv: &iv, q: &q, qd: &qd };
        let mut q0 = vec![0.0; m.nq];
        q0[6] = 1.0;
        let columns: Vec<usize> = vec![13, 0, 1, 2, 3, 4, 9, 25, 31, 77, 78, 79, 13, 80, 90, 95, 99];
        let spec =
            ObjectiveSpec { q0: &q0, stride: 3, offset: 1, columns: &columns, weight: 10.0, n_signal: 6, threads: 2 };
        let ex = sample_blocks(&m, &q0, &path, 3, 1, &columns, 6, 2, Collect::Gram, None).unwrap();
        assert_eq!(ex.parts.len(), 2);
        let g = gram(&ex.parts, columns.len());
        let rows = excitation_rows(&m, &q0, &path, 3, 1, &columns, 6, 2).unwrap().rows;
        assert_eq!(rows.nrows(), 6 * 37);
        let want = rows.transpose() * &rows;
        let scale = want.amax();
        let diff = (&g - &want).amax();
        assert!(diff <= 1e-13 * scale, "Gram differs by {diff:e} of {scale:e}");
        // and the evaluation built on it is finite and positive
        let e = evaluate(&m, &spec, &path).unwrap();
        assert!(e.objective.is_finite() && e.condition_number >= 1.0);
    }
}
