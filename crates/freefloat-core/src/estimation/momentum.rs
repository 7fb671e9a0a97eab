//! Identification from momentum (Naveen, Shah, Misra, eqs. 26–27): `h_k = K(q_k, v_k) P`, streamed over samples.

use super::analysis::{check_rank, finish};
use super::gram::{gram_rows_upper, GramLs, GRAM_TILE};
use super::{LsResult, StreamingLs};
use crate::data::Data;
use crate::error::{check_vec, FfError, Result};
use crate::interrupt::{supervise, Hook};
use crate::kinematics::forward_velocities_unchecked;
use crate::model::Model;
use crate::regressors::body_momentum_columns;
use nalgebra::{DMatrix, DVector};
use std::sync::atomic::{AtomicBool, Ordering};

/// Samples per block of the QR and refinement passes ([`Layout::Columns`]): 64 samples = 384 rows × (n+1) columns
/// (≈160 kB for n = 52), long columns for their reflectors and products, small enough to stay in L2.
const BLOCK_SAMPLES: usize = 64;
/// Samples per block of the Gram pass ([`Layout::Rows`]): 8 samples are 24 linear and 24 angular rows, about
/// 21 kB for n = 52, so the Gram kernel reads them from L1 right after they are written (64-sample blocks, 163 kB,
/// went out to L2 in between).
const ROW_BLOCK_SAMPLES: usize = 8;
/// Normal equations are kept when the equilibrated κ is at most this: then κ²ε ≈ 2e-6, and one
/// refinement step on the true residual brings the error down to the QR level (∝ κε).
pub const GRAM_KAPPA_MAX: f64 = 1e5;
/// Plain normal equations (no refinement pass) are kept when the equilibrated κ is at most this: their
/// error bound κ²ε is then ≈ 2e-11, below what a refinement step would change in any reported digit,
/// and the second pass over the data (a full regressor rebuild) is saved.
pub const GRAM_DIRECT_KAPPA_MAX: f64 = 300.0;
/// ... and when the RSS recovered from the normal equations (`yᵀy − 2xᵀAᵀy + xᵀAᵀAx`, absolute error
/// about n·ε·yᵀy) keeps at least this relative accuracy (a near-perfect fit, e.g. noise-free data, goes
/// through the refinement pass for its true residual).
const GRAM_DIRECT_RSS_RTOL: f64 = 1e-7;
/// Below this many samples a single thread is used (thread start-up would dominate).
const PARALLEL_MIN_SAMPLES: usize = 4096;

/// Which solver produced the estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// normal equations on equilibrated columns + one refinement pass (well-conditioned problems)
    GramRefined,
    /// normal equations on equilibrated columns, one pass (very well-conditioned problems with a
    /// residual large enough to be recovered from the normal equations; see [`GRAM_DIRECT_KAPPA_MAX`])
    Gram,
    /// streaming Householder QR (ill-conditioned problems, or when asked directly)
    StreamingQr,
}

/// A momentum identification problem, all arrays flat and row-major over samples.
#[derive(Debug, Clone, Copy)]
pub struct MomentumProblem<'a> {
    /// T·nq configurations
    pub q: &'a [f64],
    /// T·nv velocities
    pub v: &'a [f64],
    /// T·6 measured momenta [p; L] (inertial frame, about the inertial origin)
    pub h: &'a [f64],
    /// columns of the 6 × 10·nbodies regressor to identify (unknown bodies' kept columns)
    pub unknown_cols: &'a [usize],
    /// 10·nbodies standard parameters; the known bodies' momentum K·P (over the columns not in
    /// `unknown_cols`) is moved to the right-hand side
    pub known_params: &'a [f64],
    /// inverse variances of the 6 momentum components (None: all 1)
    pub weights: Option<[f64; 6]>,
}

impl MomentumProblem<'_> {
    fn samples(&self, m: &Model) -> Result<usize> {
        let t = self.h.len() / 6;
        check_vec("h", self.h, 6 * t)?;
        check_vec("q", self.q, m.nq * t)?;
        check_vec("v", self.v, m.nv * t)?;
        check_vec("known_params", self.known_params, 10 * m.nbodies())?;
        let np = 10 * m.nbodies();
        let mut seen = vec![false; np];
        for &c in self.unknown_cols {
            if c >= np || std::mem::replace(&mut seen[c], true) {
                return Err(FfError::arg("unknown_cols", format!("column {c} is out of range 0..{np} or repeated")));
            }
        }
        if self.unknown_cols.is_empty() {
            return Err(FfError::arg("unknown_cols", "no parameter to identify"));
        }
        if let Some(w) = self.weights {
            if w.iter().any(|x| !(*x > 0.0) || !x.is_finite()) {
                return Err(FfError::arg("weights", "the 6 weights must be finite and > 0"));
            }
        }
        if 6 * t < self.unknown_cols.len() {
            return Err(FfError::arg("h", format!("{} rows for {} unknowns", 6 * t, self.unknown_cols.len())));
        }
        Ok(t)
    }
}

/// How a block `[A_b | y_b]` of up to 6·[`BLOCK_SAMPLES`] (or 6·[`ROW_BLOCK_SAMPLES`]) rows is laid out in memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    /// column-major, 6·BLOCK_SAMPLES rows × (n+1) columns in augmented order (the unknowns, then y): what the
    /// streaming QR and the refinement pass read
    Columns,
    /// row-major, 6·ROW_BLOCK_SAMPLES rows, each padded to a multiple of [`GRAM_TILE`] (the padding left zero),
    /// the columns permuted as [`RowLayout`] says: what the Gram kernel reads without packing (stored as a
    /// (width × rows) column-major matrix, which is the same memory)
    Rows,
}

/// The columns of a [`Layout::Rows`] block: y first, then the unknowns with a linear part (mass and first moments,
/// `unknown_cols[j] % 10 <= 3`), then the inertia columns, whose linear rows are exactly zero (Naveen, Shah, Misra,
/// eq. 10), then zero padding. The linear rows' Gram product then runs over the leading columns only (see
/// [`SplitGram`]).
struct RowLayout {
    /// block column of each augmented index (unknown j < n, y at n)
    slot: Vec<usize>,
    /// the padded row width: n + 1 rounded up to a multiple of [`GRAM_TILE`]
    width: usize,
    /// the padded width of the leading columns whose linear rows can be nonzero
    lin_width: usize,
}

impl RowLayout {
    fn new(p: &MomentumProblem) -> Self {
        let n = p.unknown_cols.len();
        let mut slot = vec![0; n + 1];
        let linear: Vec<usize> = (0..n).filter(|&j| p.unknown_cols[j] % 10 <= 3).collect();
        let rest = (0..n).filter(|&j| p.unknown_cols[j] % 10 > 3);
        for (k, j) in linear.iter().copied().chain(rest).enumerate() {
            slot[j] = k + 1;
        }
        let lin_width = (linear.len() + 1).next_multiple_of(GRAM_TILE);
        RowLayout { slot, width: (n + 1).next_multiple_of(GRAM_TILE), lin_width }
    }
}

/// Per-thread work buffers that turn samples into weighted blocks `[A_b | y_b]`.
struct BlockBuilder<'a> {
    m: &'a Model,
    p: &'a MomentumProblem<'a>,
    d: Data,
    qbuf: Vec<f64>,
    block: DMatrix<f64>,
    /// entry (row, block column) of the block is at `row·strides.0 + column·strides.1` of its storage
    strides: (usize, usize),
    /// samples per block
    block_samples: usize,
    /// block column of the right-hand side
    y_col: usize,
    /// the bodies that have a column to keep or a known, nonzero parameter, in body order
    bodies: Vec<BodyColumns>,
    sw: [f64; 6],
}

/// What the block builder takes from one body's ten regressor columns.
struct BodyColumns {
    body: usize,
    /// (column k of the body, block column) of the unknowns whose linear-momentum rows are written
    kept: Vec<(usize, usize)>,
    /// the same for the unknowns of which only the angular rows are written: in [`Layout::Rows`], the inertia
    /// columns, whose linear rows are exactly zero (eq. 10) and stay as the zeroed block has them. That holds
    /// because the Gram pass only reads its blocks (the QR pass overwrites its blocks, so there every row is
    /// written), and because no row is ever angular before it is linear: the linear rows of a block of `cnt`
    /// samples are rows 0..3·cnt, a full block's angular rows start at 3·ROW_BLOCK_SAMPLES, and only a builder's
    /// last block is partial (its angular rows start lower, but every one of their entries is written)
    kept_angular: Vec<(usize, usize)>,
    /// (column k of the body, parameter) of the known, nonzero standard parameters (moved to the right-hand side)
    known: Vec<(usize, f64)>,
}

impl<'a> BlockBuilder<'a> {
    fn new(m: &'a Model, p: &'a MomentumProblem<'a>, layout: Layout) -> Self {
        let n = p.unknown_cols.len();
        let (slot, block, strides, block_samples) = match layout {
            Layout::Columns => {
                let cap = 6 * BLOCK_SAMPLES;
                ((0..=n).collect(), DMatrix::zeros(cap, n + 1), (1, cap), BLOCK_SAMPLES)
            }
            Layout::Rows => {
                let RowLayout { slot, width: w, .. } = RowLayout::new(p);
                (slot, DMatrix::zeros(w, 6 * ROW_BLOCK_SAMPLES), (w, 1), ROW_BLOCK_SAMPLES)
            }
        };
        let angular_only = |k: usize| layout == Layout::Rows && k >= 4;
        let bodies = (0..m.nbodies())
            .map(|i| {
                let kept =
                    (0..10).filter_map(|k| p.unknown_cols.iter().position(|&c| c == 10 * i + k).map(|j| (k, slot[j])));
                let (kept_angular, kept) = kept.partition(|&(k, _)| angular_only(k));
                BodyColumns {
                    body: i,
                    kept,
                    kept_angular,
                    known: (0..10)
                        .map(|k| (k, p.known_params[10 * i + k]))
                        .filter(|&(k, pk)| pk != 0.0 && !p.unknown_cols.contains(&(10 * i + k)))
                        .collect(),
                }
            })
            .filter(|b| !b.kept.is_empty() || !b.kept_angular.is_empty() || !b.known.is_empty())
            .collect();
        let sw = p.weights.map_or([1.0; 6], |w| w.map(f64::sqrt));
        BlockBuilder {
            m,
            p,
            d: Data::new(m),
            qbuf: Vec::new(),
            block,
            strides,
            block_samples,
            y_col: slot[n],
            bodies,
            sw,
        }
    }

    /// Regressor of sample s of a block of `cnt` samples into the block (weighted, known part moved
    /// to the right-hand side: y = h − K_known P_known): its linear-momentum rows at 3·slot..3·slot+3,
    /// its angular-momentum rows at 3·cnt + 3·slot... The row order changes no least-squares result and
    /// puts the linear rows, which are exactly zero in every inertia column, together (see [`SplitGram`]).
    fn fill(&mut self, s: usize, slot: usize, cnt: usize) -> Result<()> {
        let (m, p) = (self.m, self.p);
        let q = m.checked_q(&p.q[s * m.nq..(s + 1) * m.nq], &mut self.qbuf).map_err(|e| at_sample(e, s))?;
        // q checked just above, v and the sizes by `MomentumProblem::check`: the unchecked core
        forward_velocities_unchecked(m, &mut self.d, q, &p.v[s * m.nv..(s + 1) * m.nv]);
        let bs = self.block.as_mut_slice();
        let (rs, cs) = self.strides;
        let (lin0, ang0) = (3 * slot, 3 * cnt + 3 * slot);
        let sw = self.sw;
        let mut y: [f64; 6] = std::array::from_fn(|r| p.h[6 * s + r]);
        // Only the kept columns are written, straight into their block column (no full 6 × 10·nbodies regressor
        // and no copy of it): the columns of the bodies in use, from the one formula (Naveen, Shah, Misra, eq. 10).
        // (Forming only the needed columns one by one, through a match on the column, measured 1.3x slower:
        // all ten at once share their products and vectorise.)
        for b in &self.bodies {
            let cols = body_momentum_columns(&self.d, b.body);
            for &(k, j) in &b.kept {
                let src = &cols[k];
                for r in 0..3 {
                    bs[(lin0 + r) * rs + j * cs] = sw[r] * src[r];
                    bs[(ang0 + r) * rs + j * cs] = sw[r + 3] * src[r + 3];
                }
            }
            for &(k, j) in &b.kept_angular {
                for r in 0..3 {
                    bs[(ang0 + r) * rs + j * cs] = sw[r + 3] * cols[k][r + 3];
                }
            }
            for &(k, pk) in &b.known {
                for r in 0..6 {
                    y[r] -= cols[k][r] * pk;
                }
            }
        }
        let j = self.y_col;
        for r in 0..3 {
            bs[(lin0 + r) * rs + j * cs] = sw[r] * y[r];
            bs[(ang0 + r) * rs + j * cs] = sw[r + 3] * y[r + 3];
        }
        Ok(())
    }

    /// Stream samples `range` block by block into `feed(block, rows)`.
    fn run(
        &mut self,
        range: std::ops::Range<usize>,
        stop: &AtomicBool,
        mut feed: impl FnMut(&mut DMatrix<f64>, usize),
    ) -> Result<()> {
        let mut s = range.start;
        while s < range.end {
            if stop.load(Ordering::Relaxed) {
                return Err(FfError::interrupted(format!("identification stopped after {s} samples of a pass")));
            }
            let cnt = self.block_samples.min(range.end - s);
            for slot in 0..cnt {
                self.fill(s + slot, slot, cnt)?;
            }
            feed(&mut self.block, 6 * cnt);
            s += cnt;
        }
        Ok(())
    }
}

/// The Gram matrix of [`Layout::Rows`] blocks, exploiting that the linear-momentum rows of the momentum regressor
/// are exactly zero in every inertia column (Naveen, Shah, Misra, eq. 10: `I_jk` columns are
/// `[0; r_j ω_k + r_k ω_j]`): the angular rows go through the upper triangle of the full product, the linear rows
/// only through that of the leading block columns (y, mass and first moments: 17 of 53 columns, padded to 24, for
/// the dual-arm robot). Accumulated in block-column order, put back in augmented order once at the end.
struct SplitGram {
    layout: RowLayout,
    /// width × width, row-major, in block-column order
    acc: Vec<f64>,
    rows: usize,
}

impl SplitGram {
    fn new(p: &MomentumProblem) -> Self {
        let layout = RowLayout::new(p);
        let acc = vec![0.0; layout.width * layout.width];
        SplitGram { layout, acc, rows: 0 }
    }

    /// Add a block filled by [`BlockBuilder::fill`] in [`Layout::Rows`]: rows 0..rows/2 linear, rows/2..rows
    /// angular.
    fn add(&mut self, block: &DMatrix<f64>, rows: usize) {
        let (half, w) = (rows / 2, self.layout.width);
        let b = block.as_slice();
        gram_rows_upper(&mut self.acc, &b[..half * w], w, half, self.layout.lin_width);
        gram_rows_upper(&mut self.acc, &b[half * w..rows * w], w, half, w);
        self.rows += rows;
    }

    fn finish(self) -> GramLs {
        let l = &self.layout;
        let mut g = GramLs::new(l.slot.len() - 1);
        g.add_permuted_upper(&self.acc, l.width, &l.slot, self.rows);
        g
    }
}

fn at_sample(e: FfError, s: usize) -> FfError {
    match e {
        FfError::Argument { name, msg } => FfError::Argument { name, msg: format!("sample {s}: {msg}") },
        other => other,
    }
}

/// One pass over all samples, split across threads; each thread owns an accumulator `A`.
fn par_pass<A: Send>(
    m: &Model,
    p: &MomentumProblem,
    t: usize,
    layout: Layout,
    make: impl Fn() -> A + Sync,
    feed: impl Fn(&mut A, &mut DMatrix<f64>, usize) + Sync,
    hook: &mut Option<Hook>,
) -> Result<Vec<A>> {
    let threads =
        if t < PARALLEL_MIN_SAMPLES { 1 } else { std::thread::available_parallelism().map_or(1, |x| x.get()).min(8) };
    let chunk = t.div_ceil(threads);
    let stop = AtomicBool::new(false);
    let work = |range: std::ops::Range<usize>| -> Result<A> {
        let mut acc = make();
        BlockBuilder::new(m, p, layout).run(range, &stop, |b, rows| feed(&mut acc, b, rows))?;
        Ok(acc)
    };
    if threads == 1 && hook.is_none() {
        return Ok(vec![work(0..t)?]);
    }
    // The workers stream their samples; the calling thread (which may hold the interrupt hook, e.g. a Ctrl-C
    // check that needs the Python interpreter) polls the hook every POLL_INTERVAL and raises the stop flag that
    // the workers read before each block.
    std::thread::scope(|sc| {
        let handles: Vec<_> =
            (0..threads).map(|i| (i * chunk)..((i + 1) * chunk).min(t)).map(|r| sc.spawn(|| work(r))).collect();
        supervise(hook, &stop, &handles, || 0.0);
        handles.into_iter().map(|h| h.join().expect("estimation worker panicked")).collect()
    })
}

/// Identify the parameters in `unknown_cols` from measured momenta, streaming over samples.
///
/// Pass 1 accumulates the Gram matrix and measures the equilibrated condition number κ_s. If
/// κ_s ≤ [`GRAM_DIRECT_KAPPA_MAX`] and the residual is not tiny, that is the answer (one pass). If
/// κ_s ≤ [`GRAM_KAPPA_MAX`], pass 2 computes the true residual `y − A x̂` and corrects x̂ once
/// (corrected semi-normal equations), giving QR-grade accuracy and the exact RSS. Otherwise pass 2
/// is a streaming Householder QR. The tall regressor is never formed; per sample nothing is
/// allocated. A rank-deficient problem is an error naming the unexcited combinations.
pub fn identify_momentum(m: &Model, p: &MomentumProblem) -> Result<LsResult> {
    identify_momentum_with(m, p, false)
}

/// As [`identify_momentum`]; `force_qr` skips the normal equations (for testing and comparison).
pub fn identify_momentum_with(m: &Model, p: &MomentumProblem, force_qr: bool) -> Result<LsResult> {
    identify_momentum_interruptible(m, p, force_qr, None)
}

/// As [`identify_momentum_with`], stoppable: `hook` is called by the calling thread every few milliseconds
/// while the worker threads stream the samples (at most ~20 ms apart in practice); its `false` stops every
/// pass before its next block of samples and returns `FfError::Interrupted`.
pub fn identify_momentum_interruptible(
    m: &Model,
    p: &MomentumProblem,
    force_qr: bool,
    mut hook: Option<Hook>,
) -> Result<LsResult> {
    let hook = &mut hook;
    let t = p.samples(m)?;
    let n = p.unknown_cols.len();
    if !force_qr {
        let mut grams = par_pass(m, p, t, Layout::Rows, || SplitGram::new(p), |g, b, rows| g.add(b, rows), hook)?
            .into_iter()
            .map(SplitGram::finish);
        let mut g = grams.next().expect("one thread");
        grams.for_each(|o| g.merge(&o));
        if let Some(f) = g.factor().filter(|f| f.kappa_scaled <= GRAM_KAPPA_MAX) {
            check_rank(&f.r)?;
            if f.kappa_scaled <= GRAM_DIRECT_KAPPA_MAX {
                let (rss, yty) = g.rss_at(&f.x);
                if rss * GRAM_DIRECT_RSS_RTOL >= n as f64 * f64::EPSILON * yty {
                    return Ok(finish(&f.r, f.x, rss, 6 * t, Method::Gram));
                }
            }
            return refine(m, p, t, f.r, f.x, hook);
        }
    }
    let mut qrs =
        par_pass(m, p, t, Layout::Columns, || StreamingLs::new(n), |q, b, rows| q.add_augmented(b, rows), hook)?
            .into_iter();
    let mut qr = qrs.next().expect("one thread");
    qrs.for_each(|o| qr.merge(&o));
    qr.solve()
}

/// Residual accumulator of the refinement pass: Aᵀr and ‖r‖² for r = y − A x.
struct Residual {
    atr: DVector<f64>,
    rss: f64,
    r: DVector<f64>,
}

/// One step of iterative refinement: x ← x + (RᵀR)⁻¹ Aᵀ(y − A x), and the RSS at the new x.
fn refine(
    m: &Model,
    p: &MomentumProblem,
    t: usize,
    r: DMatrix<f64>,
    x: DVector<f64>,
    hook: &mut Option<Hook>,
) -> Result<LsResult> {
    let n = x.len();
    let make = || Residual { atr: DVector::zeros(n), rss: 0.0, r: DVector::zeros(6 * BLOCK_SAMPLES) };
    let feed = |acc: &mut Residual, b: &mut DMatrix<f64>, rows: usize| {
        let a = b.view((0, 0), (rows, n));
        let mut res = acc.r.rows_mut(0, rows);
        res.copy_from(&b.view((0, n), (rows, 1)));
        res.gemv(-1.0, &a, &x, 1.0);
        acc.rss += res.norm_squared();
        acc.atr.gemv_tr(1.0, &a, &res, 1.0);
    };
    let mut parts = par_pass(m, p, t, Layout::Columns, make, feed, hook)?.into_iter();
    let mut acc = parts.next().expect("one thread");
    for o in parts {
        acc.atr += o.atr;
        acc.rss += o.rss;
    }
    let rt = r.transpose();
    let z = rt.solve_lower_triangular(&acc.atr).ok_or_else(|| FfError::Numerical("singular factor".into()))?;
    let delta = r.solve_upper_triangular(&z).ok_or_else(|| FfError::Numerical("singular factor".into()))?;
    // rss(x + δ) = rss(x) − δᵀAᵀr exactly, since RᵀR δ = Aᵀr
    let rss = (acc.rss - delta.dot(&acc.atr)).max(0.0);
    Ok(finish(&r, x + delta, rss, 6 * t, super::Method::GramRefined))
}

/// One streaming pass that only builds the weighted blocks `[A_b | y_b]` (in the layout of the first, Gram pass)
/// and discards them: the regressor-building cost inside [`identify_momentum`] (per pass), for benchmarks.
/// Returns the sum of the right-hand sides so the work cannot be optimised away.
pub fn momentum_regressor_pass(m: &Model, p: &MomentumProblem) -> Result<f64> {
    let t = p.samples(m)?;
    let l = RowLayout::new(p);
    let (y_col, w) = (l.slot[p.unknown_cols.len()], l.width);
    let rhs_sum = |acc: &mut f64, b: &mut DMatrix<f64>, rows: usize| {
        *acc += b.as_slice().chunks_exact(w).take(rows).map(|row| row[y_col]).sum::<f64>();
    };
    let parts = par_pass(m, p, t, Layout::Rows, || 0.0, rhs_sum, &mut None)?;
    Ok(parts.into_iter().sum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::builtin;

    /// A deterministic, well-mixed number in [-0.5, 0.5).
    fn mix(i: usize, j: usize) -> f64 {
        ((i * 37 + j * 101) % 97) as f64 / 97.0 - 0.5
    }

    #[test]
    fn the_gram_pass_equals_the_dense_gram_of_the_same_blocks() {
        // The row-major, permuted, triangle-only Gram pass (with its unwritten zero linear rows) against the general
        // column-major `GramLs` fed the QR pass's blocks, on a problem with known bodies and weights, a sample count
        // that leaves a partial block and is split over threads.
        let m = builtin::load("naveen_dual_arm").unwrap();
        let t = PARALLEL_MIN_SAMPLES + 13;
        let (mut q, mut v) = (Vec::new(), Vec::new());
        for s in 0..t {
            let mut qs = m.neutral();
            qs.iter_mut().enumerate().for_each(|(k, x)| *x += 3.0 * mix(s, k));
            let nrm = qs[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
            qs[3..7].iter_mut().for_each(|x| *x /= nrm);
            q.extend(qs);
            v.extend((0..m.nv).map(|k| mix(s + 7, k)));
        }
        let h: Vec<f64> = (0..6 * t).map(|k| mix(k, 3)).collect();
        let known: Vec<f64> =
            m.parameters().into_iter().flatten().enumerate().map(|(c, x)| if c >= 70 { x } else { 0.0 }).collect();
        let unknown: Vec<usize> = (0..70).filter(|c| c % 10 != 2 && c % 10 != 6).collect();
        let p = MomentumProblem {
            q: &q,
            v: &v,
            h: &h,
            unknown_cols: &unknown,
            known_params: &known,
            weights: Some([1.0, 2.0, 3.0, 0.5, 0.25, 4.0]),
        };
        let n = unknown.len();
        let fast: Vec<GramLs> =
            par_pass(&m, &p, t, Layout::Rows, || SplitGram::new(&p), |g, b, r| g.add(b, r), &mut None)
                .unwrap()
                .into_iter()
                .map(SplitGram::finish)
                .collect();
        let dense = par_pass(&m, &p, t, Layout::Columns, || GramLs::new(n), |g, b, r| g.add_augmented(b, r), &mut None)
            .unwrap();
        assert!(fast.len() > 1, "the samples were not split over threads");
        let sum = |parts: &[GramLs]| {
            let mut g = parts[0].clone();
            parts[1..].iter().for_each(|o| g.merge(o));
            g
        };
        let (a, b) = (sum(&fast), sum(&dense));
        assert_eq!(a.rows(), 6 * t);
        assert_eq!(a.rows(), b.rows());
        let (ga, gb) = (a.matrix(), b.matrix());
        let scale = gb.amax();
        assert!((ga - gb).amax() <= 1e-13 * scale, "Gram matrices differ by {:.2e} of {scale:.2e}", (ga - gb).amax());
        assert_eq!(ga, &ga.transpose());
    }
}
