//! Identification from momentum (Naveen, Shah, Misra, eqs. 26–27): `h_k = K(q_k, v_k) P`, streamed over samples.

use super::analysis::{finish, RANK_RTOL};
use super::gram::{gram_rows_upper, GramLs, GRAM_TILE};
use super::{LsResult, Method, StreamingLs};
use crate::check::check_vec;
use crate::check::{check_finite, check_len};
use crate::data::Data;
use crate::error::{FfError, Result};
use crate::interrupt::{Hook, POLL_INTERVAL};
use crate::kinematics::{forward_velocities_unchecked, Kin, Kin4};
use crate::model::Model;
use crate::regressors::{body_momentum_columns, momentum_columns_into};
use crate::spatial::lanes::{Lanes, Real};
use nalgebra::{DMatrix, DVector};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// Samples per block of the QR and refinement passes ([`Layout::Columns`]): 64 samples = 384 rows × (n+1) columns
/// (≈160 kB for n = 52), long columns for their reflectors and products, small enough to stay in L2.
const BLOCK_SAMPLES: usize = 64;
/// Samples per block of the Gram pass ([`Layout::Rows`]): 16 samples are 48 linear and 48 angular rows, about
/// 43 kB for n = 52, so the Gram kernel reads them from L1 (48 kB on Zen 5) right after they are written (64-sample
/// blocks, 163 kB, went out to L2 in between). 16 rather than 8: the AVX-512 kernel loads and stores its
/// accumulators once per 48 rows instead of 24 (identification 2-3 % less CPU time, `identify_profile identify`,
/// five interleaved pairs).
const ROW_BLOCK_SAMPLES: usize = 16;
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
/// Samples per chunk of a pass over several threads (see [`par_pass`]): 2048 samples are about 1 ms of work on
/// one core, long beside handing out a chunk, short enough that 67 000 samples make 33 chunks to balance. A
/// multiple of both block sizes, so that only the last chunk ends with a partial block.
const CHUNK_SAMPLES: usize = 2048;
const _: () = assert!(CHUNK_SAMPLES.is_multiple_of(BLOCK_SAMPLES) && CHUNK_SAMPLES.is_multiple_of(ROW_BLOCK_SAMPLES));
// the normal equations are only kept far from the rank threshold (see `identify_momentum_interruptible`)
const _: () = assert!(GRAM_KAPPA_MAX * RANK_RTOL <= 1e-5);

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
        // sizes here; finiteness sample by sample in the passes (`BlockBuilder::fill`, `fill_lanes`: on the worker
        // threads, naming the sample), where a scan of every entry here held up the start of every pass
        check_len("h", self.h.len(), 6 * t)?;
        check_len("q", self.q.len(), m.nq * t)?;
        check_len("v", self.v.len(), m.nv * t)?;
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
    /// the width (a multiple of 4) of the leading columns whose linear rows can be nonzero
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
        // the Gram kernel takes a four-wide last strip: the linear rows' product stops at a multiple of 4
        let lin_width = (linear.len() + 1).next_multiple_of(4);
        RowLayout { slot, width: (n + 1).next_multiple_of(GRAM_TILE), lin_width }
    }
}

/// Per-thread work buffers that turn samples into weighted blocks `[A_b | y_b]`.
struct BlockBuilder<'a> {
    m: &'a Model,
    p: &'a MomentumProblem<'a>,
    d: Data,
    qbuf: Vec<f64>,
    /// the four-sample sweep, if the model is of its kind (then four samples at a time go through `fill_lanes`)
    kin: Option<Kin4>,
    /// the eight-sample sweep, if the model is of its kind and the processor runs AVX-512 ([`avx512_lanes`]):
    /// then eight samples at a time go through `fill_lanes`, compiled for AVX-512 (`fill_groups_avx512`)
    kin8: Option<Kin<8>>,
    /// the configuration buffers of the samples of one sweep
    qbufs: [Vec<f64>; 8],
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
    /// v and h of the samples being streamed are known to be finite (one scan per range in `run`): the per-sample
    /// checks of `fill` and `fill_lanes` are left to a range that has a non-finite entry, where they name it
    vh_finite: bool,
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
    /// bit k set: column k is used (kept or known), the columns `fill_lanes` forms
    need: u16,
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
        let bodies: Vec<BodyColumns> = (0..m.nbodies())
            .map(|i| {
                let kept =
                    (0..10).filter_map(|k| p.unknown_cols.iter().position(|&c| c == 10 * i + k).map(|j| (k, slot[j])));
                let (kept_angular, kept): (Vec<_>, Vec<_>) = kept.partition(|&(k, _)| angular_only(k));
                let known: Vec<(usize, f64)> = (0..10)
                    .map(|k| (k, p.known_params[10 * i + k]))
                    .filter(|&(k, pk)| pk != 0.0 && !p.unknown_cols.contains(&(10 * i + k)))
                    .collect();
                let used = kept.iter().chain(&kept_angular).map(|&(k, _)| k).chain(known.iter().map(|&(k, _)| k));
                let need = used.fold(0u16, |acc, k| acc | (1 << k));
                BodyColumns { body: i, kept, kept_angular, known, need }
            })
            .filter(|b| !b.kept.is_empty() || !b.kept_angular.is_empty() || !b.known.is_empty())
            .collect();
        let sw = p.weights.map_or([1.0; 6], |w| w.map(f64::sqrt));
        // every block column written lies inside the block (what `fill_lanes`'s unchecked stores rely on)
        let (rs, cs) = strides;
        let last = |j: usize| (6 * block_samples - 1) * rs + j * cs;
        let cols = bodies.iter().flat_map(|b| b.kept.iter().chain(&b.kept_angular).map(|&(_, j)| j));
        assert!(cols.chain([slot[n]]).all(|j| last(j) < block.len()), "a block column outside the block");
        let d = Data::new(m);
        BlockBuilder {
            m,
            p,
            kin: Kin4::for_model(m, &d),
            kin8: if avx512_lanes() { Kin::for_model(m, &d) } else { None },
            d,
            qbuf: Vec::new(),
            qbufs: Default::default(),
            block,
            strides,
            block_samples,
            y_col: slot[n],
            bodies,
            sw,
            vh_finite: false,
        }
    }

    /// Regressor of sample s of a block of `cnt` samples into the block (weighted, known part moved
    /// to the right-hand side: y = h − K_known P_known): its linear-momentum rows at 3·slot..3·slot+3,
    /// its angular-momentum rows at 3·cnt + 3·slot... The row order changes no least-squares result and
    /// puts the linear rows, which are exactly zero in every inertia column, together (see [`SplitGram`]).
    fn fill(&mut self, s: usize, slot: usize, cnt: usize) -> Result<()> {
        let (m, p) = (self.m, self.p);
        let q = m.checked_q(&p.q[s * m.nq..(s + 1) * m.nq], &mut self.qbuf).map_err(|e| at_sample(e, s))?;
        if !self.vh_finite {
            vh_finite_at(p, m.nv, s).map_err(|e| at_sample(e, s))?;
        }
        let v = &p.v[s * m.nv..(s + 1) * m.nv];
        // q and v checked just above, the sizes by `MomentumProblem::samples`: the unchecked core
        forward_velocities_unchecked(m, &mut self.d, q, v);
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

    /// [`fill`](Self::fill) for the L samples s..s+L at slots slot..slot+L: their kinematics and regressor
    /// columns side by side, one sample per lane ([`Kin`], [`momentum_columns_into`]), every entry the same to the
    /// bit as `fill` would write it (the same operations in the same order, lane by lane). Four samples per step cost
    /// less than half the instructions of four one-sample steps (11 982 → 5 570 per sample in `identify_profile
    /// pass`, callgrind). Inlined, so that the eight-lane copy is compiled for AVX-512 in `fill_groups_avx512`.
    #[inline(always)]
    fn fill_lanes<const L: usize>(&mut self, kin: &mut Kin<L>, s: usize, slot: usize, cnt: usize) -> Result<()> {
        let (m, p) = (self.m, self.p);
        let (nq, nv) = (m.nq, m.nv);
        let vh_finite = self.vh_finite;
        // each sample's q (size, finite, unit quaternions), v and h (finite), in sample order as `fill` checks them
        let check = |l: usize, buf| {
            let q = m.checked_q(&p.q[(s + l) * nq..(s + l + 1) * nq], buf);
            let vh = |q| if vh_finite { Ok(q) } else { vh_finite_at(p, nv, s + l).map(|_| q) };
            q.and_then(vh).map_err(|e| at_sample(e, s + l))
        };
        // (loops rather than `std::array::from_fn`, which with eight lanes stayed a call: see `Lanes::from_fn`)
        let (mut q, mut v): ([&[f64]; L], [&[f64]; L]) = ([&[]; L], [&[]; L]);
        for (l, (ql, buf)) in q.iter_mut().zip(&mut self.qbufs).enumerate() {
            *ql = check(l, buf)?;
            v[l] = &p.v[(s + l) * nv..(s + l + 1) * nv];
        }
        kin.run(m, &mut self.d, q, v);
        assert!(slot + L <= cnt && cnt <= self.block_samples);
        let bs = self.block.as_mut_slice();
        let (rs, cs) = self.strides;
        let sw = [0, 1, 2, 3, 4, 5].map(|r| Lanes::<L>::splat(self.sw[r]));
        // SAFETY: every store below is at `row[l][r] + j·cs` with a row below 6·cnt ≤ 6·block_samples (asserted just
        // above) and j a block column (a slot of `bodies` or `y_col`, checked against the block's width in `new`):
        // inside the block, which `new` sized for exactly that. The bounds checks cost about a sixth of the pass
        // (callgrind), one store being a load, an add and the check.
        let mut put = |at: usize, x: f64| unsafe { *bs.get_unchecked_mut(at) = x };
        // where each lane's six rows start: linear rows at 3·slot.., angular rows at 3·cnt + 3·slot.. (see `fill`)
        let mut row = [[0; 6]; L];
        for (l, row) in row.iter_mut().enumerate() {
            for (r, at) in row.iter_mut().enumerate() {
                *at = if r < 3 { 3 * (slot + l) + r } else { 3 * cnt + 3 * (slot + l) + r - 3 } * rs;
            }
        }
        let mut y = [0, 1, 2, 3, 4, 5].map(|r| Lanes::<L>::from_fn(|l| p.h[6 * (s + l) + r]));
        // one buffer for every body: each body reads only the columns it has just written (its `need`)
        let mut cols = [[Lanes::splat(0.0); 6]; 10];
        for b in &self.bodies {
            let i = b.body;
            momentum_columns_into(&mut cols, &kin.rot[i], &kin.pos[i], &kin.lin[i], &kin.ang[i], b.need);
            // weighted L lanes at once (the same product per lane as `fill`), then one store per lane
            for &(k, j) in &b.kept {
                for r in 0..6 {
                    let x = sw[r] * cols[k][r];
                    for l in 0..L {
                        put(row[l][r] + j * cs, x.0[l]);
                    }
                }
            }
            for &(k, j) in &b.kept_angular {
                for r in 3..6 {
                    let x = sw[r] * cols[k][r];
                    for l in 0..L {
                        put(row[l][r] + j * cs, x.0[l]);
                    }
                }
            }
            for &(k, pk) in &b.known {
                for r in 0..6 {
                    y[r] = y[r] - cols[k][r] * Lanes::splat(pk);
                }
            }
        }
        let j = self.y_col;
        for r in 0..6 {
            let x = sw[r] * y[r];
            for l in 0..L {
                put(row[l][r] + j * cs, x.0[l]);
            }
        }
        Ok(())
    }

    /// The samples s+slot.. of a block of `cnt` through [`fill_lanes`](Self::fill_lanes), L at a time while L
    /// remain; the first slot left.
    #[inline(always)]
    fn fill_groups<const L: usize>(
        &mut self,
        kin: &mut Kin<L>,
        s: usize,
        mut slot: usize,
        cnt: usize,
    ) -> Result<usize> {
        while slot + L <= cnt {
            self.fill_lanes(kin, s + slot, slot, cnt)?;
            slot += L;
        }
        Ok(slot)
    }

    /// [`fill_groups`](Self::fill_groups) with eight lanes, compiled for AVX-512 (one register per [`Lanes<8>`]):
    /// half the sweeps of four-lane groups, each about as many instructions. `identify_profile identify` (67,000
    /// samples of naveen_dual_arm, 2 cores, AMD Zen 5): 1149 → 982 ms process CPU per 40 runs (−15 %, median of 5
    /// interleaved pairs, `perf stat -e task-clock`), same checksum.
    ///
    /// # Safety
    /// The processor must have AVX-512F, VL and DQ ([`avx512_lanes`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx512dq")]
    unsafe fn fill_groups_avx512(&mut self, kin: &mut Kin<8>, s: usize, cnt: usize) -> Result<usize> {
        self.fill_groups(kin, s, 0, cnt)
    }

    /// The samples of the block s..s+cnt that go through a many-sample sweep: eight at a time where the processor
    /// runs AVX-512, then four; the first slot left for [`fill`](Self::fill).
    fn fill_block_lanes(&mut self, s: usize, cnt: usize) -> Result<usize> {
        let mut slot = 0;
        // each sweep is taken out of `self` for its pass (its samples are written into `self.block`) and put back
        if let Some(mut kin) = self.kin8.take() {
            // SAFETY: `kin8` is built only where `avx512_lanes()` found AVX-512F, VL and DQ (see `new`).
            #[cfg(target_arch = "x86_64")]
            let r = unsafe { self.fill_groups_avx512(&mut kin, s, cnt) };
            // (elsewhere `kin8` is never built; the generic body keeps the field in use for the compiler)
            #[cfg(not(target_arch = "x86_64"))]
            let r = self.fill_groups(&mut kin, s, 0, cnt);
            self.kin8 = Some(kin);
            slot = r?;
        }
        if let Some(mut kin) = self.kin.take() {
            let r = self.fill_groups(&mut kin, s, slot, cnt);
            self.kin = Some(kin);
            slot = r?;
        }
        Ok(slot)
    }

    /// Stream samples `range` block by block into `feed(block, rows)`.
    fn run(
        &mut self,
        range: std::ops::Range<usize>,
        stop: &AtomicBool,
        mut feed: impl FnMut(&mut DMatrix<f64>, usize),
    ) -> Result<()> {
        // v and h of the whole range in one vectorised scan each (two short scans per sample took 3 % of the
        // pass); a range that fails it is checked sample by sample, which names the first bad sample and entry
        let (nv, p) = (self.m.nv, self.p);
        let (v, h) = (&p.v[range.start * nv..range.end * nv], &p.h[6 * range.start..6 * range.end]);
        self.vh_finite = check_finite("v", v).is_ok() && check_finite("h", h).is_ok();
        let mut s = range.start;
        while s < range.end {
            if stop.load(Ordering::Relaxed) {
                return Err(FfError::interrupted(format!("identification stopped after {s} samples of a pass")));
            }
            let cnt = self.block_samples.min(range.end - s);
            let slot = self.fill_block_lanes(s, cnt)?;
            for slot in slot..cnt {
                self.fill(s + slot, slot, cnt)?;
            }
            feed(&mut self.block, 6 * cnt);
            if cnt < self.block_samples {
                // A partial block writes angular rows where a full one has linear rows, which `Layout::Rows` never
                // writes for the inertia columns (they stay zero from the start, see `BodyColumns`): a builder used
                // for another range after one starts from a zero block again.
                self.block.fill(0.0);
            }
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

/// Whether the block builder's eight-sample sweep runs (compiled for AVX-512F, VL and DQ): where the Gram pass takes
/// its AVX-512 kernel ([`super::gram::avx512`], which `FREEFLOAT_NO_AVX512` turns off) and the processor also has
/// VL and DQ. Decided once per process.
fn avx512_lanes() -> bool {
    static USE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *USE.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        let has = std::arch::is_x86_feature_detected!("avx512vl") && std::arch::is_x86_feature_detected!("avx512dq");
        #[cfg(not(target_arch = "x86_64"))]
        let has = false;
        has && super::gram::avx512()
    })
}

/// v and h of sample s are finite (the per-sample check of `fill` and `fill_lanes`, for a range whose one scan in `run`
/// found a non-finite entry).
fn vh_finite_at(p: &MomentumProblem, nv: usize, s: usize) -> Result<()> {
    check_finite("v", &p.v[s * nv..(s + 1) * nv]).and_then(|_| check_finite("h", &p.h[6 * s..6 * s + 6]))
}

fn at_sample(e: FfError, s: usize) -> FfError {
    match e {
        FfError::Argument { name, msg } => FfError::Argument { name, msg: format!("sample {s}: {msg}") },
        other => other,
    }
}

/// What one worker of [`par_pass`] did: (chunk, accumulator) of the chunks it finished, and (chunk, error) of the
/// one it stopped at, if any.
type Worked<A> = (Vec<(usize, A)>, Option<(usize, FfError)>);

/// One pass over all samples: one accumulator `A` per chunk of [`CHUNK_SAMPLES`] consecutive samples, returned in
/// sample order, the chunks handed out to the threads one at a time as they finish the previous one.
///
/// Fixed chunks, not one share per thread: the caller merges the accumulators in chunk order, so the result is
/// the same to the bit whatever the number of threads or the order they ran in (with one half per thread it
/// depended on the core count); and a thread slowed by the rest of a shared machine takes fewer chunks instead of
/// holding up the whole pass (with halves, the pass always waited for the slower thread).
fn par_pass<A: Send>(
    m: &Model,
    p: &MomentumProblem,
    t: usize,
    layout: Layout,
    make: impl Fn() -> A + Sync,
    feed: impl Fn(&mut A, &mut DMatrix<f64>, usize) + Sync,
    hook: &mut Option<Hook>,
) -> Result<Vec<A>> {
    // whole blocks per chunk (only the last one ends with a partial block)
    let size = if t < PARALLEL_MIN_SAMPLES { t.max(1) } else { CHUNK_SAMPLES };
    let chunks = t.div_ceil(size).max(1);
    let threads = crate::threads::available_cores().min(8).min(chunks);
    let (stop, next) = (AtomicBool::new(false), AtomicUsize::new(0));
    // One worker: chunks in increasing order until none is left or one fails (then it stops taking chunks; the
    // others go on, so every chunk before the failing one is still done and the first bad sample is the one
    // named). `poll`, on the calling thread only, runs before every chunk and says whether to go on.
    let work = |mut poll: Option<&mut dyn FnMut() -> bool>| -> Worked<A> {
        let mut builder = BlockBuilder::new(m, p, layout);
        let mut done = Vec::new();
        loop {
            if let Some(go_on) = poll.as_mut() {
                if !go_on() {
                    // every worker stops before its next block, this one too (`run` reads the flag first)
                    stop.store(true, Ordering::Relaxed);
                }
            }
            let c = next.fetch_add(1, Ordering::Relaxed);
            if c >= chunks {
                return (done, None);
            }
            let mut acc = make();
            match builder.run((c * size)..((c + 1) * size).min(t), &stop, |b, rows| feed(&mut acc, b, rows)) {
                Ok(()) => done.push((c, acc)),
                Err(e) => return (done, Some((c, e))),
            }
        }
    };
    // The calling thread works too, and between its chunks (about a millisecond each) calls the hook every
    // POLL_INTERVAL: it may hold what the hook needs (the Python interpreter, for a Ctrl-C check). Watching the
    // workers from a sleeping thread instead left a core idle and, when they finished, woke up to 5 ms late.
    let mut last = Instant::now();
    let mut poll = || -> bool {
        let Some(h) = hook.as_mut() else { return true };
        if last.elapsed() < POLL_INTERVAL {
            return true;
        }
        last = Instant::now();
        h(next.load(Ordering::Relaxed).min(chunks) as f64 / chunks as f64)
    };
    let results = std::thread::scope(|sc| {
        let handles: Vec<_> = (1..threads).map(|_| sc.spawn(|| work(None))).collect();
        let mine = work(Some(&mut poll));
        let mut all = vec![mine];
        all.extend(handles.into_iter().map(|h| h.join().expect("estimation worker panicked")));
        all
    });
    let mut parts = Vec::with_capacity(chunks);
    let mut first_error: Option<(usize, FfError)> = None;
    for (done, err) in results {
        parts.extend(done);
        if let Some((c, e)) = err {
            // the earliest chunk's error; a real one before an interruption
            let better = first_error.as_ref().is_none_or(|(c0, e0)| {
                (e0.is_interrupted() && !e.is_interrupted()) || (e0.is_interrupted() == e.is_interrupted() && c < *c0)
            });
            if better {
                first_error = Some((c, e));
            }
        }
    }
    if let Some((_, e)) = first_error {
        return Err(e);
    }
    parts.sort_by_key(|(c, _)| *c);
    debug_assert!(parts.iter().enumerate().all(|(k, (c, _))| k == *c), "a chunk missing or done twice");
    Ok(parts.into_iter().map(|(_, a)| a).collect())
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
            // No rank check here: κ_s ≤ GRAM_KAPPA_MAX puts the smallest singular value of the equilibrated factor
            // at ≥ 1e-5 of the largest, and `check_rank` judges that same matrix (R with unit columns, equal to
            // `factor`'s to round-off) against RANK_RTOL = 1e-11: it cannot fail, and its SVD with singular vectors
            // was a serial 0.1 ms after the parallel pass. A rank-deficient problem fails the Cholesky or the κ
            // test and goes to the QR pass, which checks.
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

    /// Deterministic, well-mixed data of `t` samples (unit quaternions) and the problem the tests pose on it: the
    /// columns below `first_known` unknown except h_y and I_yy, the model's parameters from there on known, weights.
    struct Case {
        q: Vec<f64>,
        v: Vec<f64>,
        h: Vec<f64>,
        known: Vec<f64>,
        unknown: Vec<usize>,
    }

    impl Case {
        fn new(m: &Model, t: usize, first_known: usize) -> Case {
            let (mut q, mut v) = (Vec::new(), Vec::new());
            for s in 0..t {
                let mut qs = m.neutral();
                qs.iter_mut().enumerate().for_each(|(k, x)| *x += 3.0 * mix(s, k));
                for &(_, o) in m.quaternions() {
                    let nrm = qs[o..o + 4].iter().map(|x| x * x).sum::<f64>().sqrt();
                    qs[o..o + 4].iter_mut().for_each(|x| *x /= nrm);
                }
                q.extend(qs);
                v.extend((0..m.nv).map(|k| mix(s + 7, k)));
            }
            let h = (0..6 * t).map(|k| mix(k, 3)).collect();
            let params = m.parameters().into_iter().flatten().enumerate();
            let known = params.map(|(c, x)| if c >= first_known { x } else { 0.0 }).collect();
            let unknown = (0..first_known).filter(|c| c % 10 != 2 && c % 10 != 6).collect();
            Case { q, v, h, known, unknown }
        }

        fn problem(&self) -> MomentumProblem<'_> {
            MomentumProblem {
                q: &self.q,
                v: &self.v,
                h: &self.h,
                unknown_cols: &self.unknown,
                known_params: &self.known,
                weights: Some([1.0, 2.0, 3.0, 0.5, 0.25, 4.0]),
            }
        }
    }

    #[test]
    fn a_bad_sample_is_named_whichever_thread_or_lane_meets_it() {
        // finiteness of v and h is checked sample by sample in the passes (not up front): the first bad sample is
        // named, in a four-sample step (lane 2) or in the one-sample remainder of the last block, in any chunk
        let m = builtin::load("naveen_dual_arm").unwrap();
        let t = 2 * CHUNK_SAMPLES + 13;
        let mut q = Vec::new();
        for _ in 0..t {
            q.extend(m.neutral());
        }
        let (v, h) = (vec![0.1; m.nv * t], vec![0.2; 6 * t]);
        let unknown: Vec<usize> = (10..70).collect();
        let known = vec![0.0; 10 * m.nbodies()];
        for (what, s) in [("v", 2 * CHUNK_SAMPLES + 2), ("h", CHUNK_SAMPLES + 6), ("v", t - 1), ("h", 3)] {
            let (mut v, mut h) = (v.clone(), h.clone());
            if what == "v" {
                v[s * m.nv + 4] = f64::NAN;
            } else {
                h[6 * s + 5] = f64::INFINITY;
            }
            let p =
                MomentumProblem { q: &q, v: &v, h: &h, unknown_cols: &unknown, known_params: &known, weights: None };
            let e = identify_momentum(&m, &p).unwrap_err().to_string();
            assert!(e.contains(&format!("sample {s}:")) && e.contains(&format!("`{what}`")), "{what} at {s}: {e}");
        }
    }

    #[test]
    fn samples_side_by_side_fill_a_block_as_one_at_a_time_does() {
        // `fill_lanes` against `fill` on the same samples, every entry of the block to the bit: both layouts, known
        // bodies moved to the right-hand side, weights, a robot with a fixed joint (the captured target); four
        // lanes, eight compiled for the baseline, and eight compiled for AVX-512 where the processor has it.
        for name in ["naveen_dual_arm", "zhang2020_3d"] {
            let m = builtin::load(name).unwrap();
            let t = 64;
            let case = Case::new(&m, t, 10 * m.nbodies() - 20);
            let p = case.problem();
            for layout in [Layout::Rows, Layout::Columns] {
                let mut bb = BlockBuilder::new(&m, &p, layout);
                let (Some(mut kin4), Some(mut kin8)) = (bb.kin.take(), Kin::<8>::for_model(&m, &bb.d)) else {
                    panic!("{name}: no many-sample sweep")
                };
                assert_eq!(bb.kin8.is_some(), avx512_lanes());
                let cnt = bb.block_samples;
                for start in [0, t - cnt] {
                    bb.block.fill(0.0);
                    for slot in 0..cnt {
                        bb.fill(start + slot, slot, cnt).unwrap();
                    }
                    let one = bb.block.clone();
                    assert!(one.iter().any(|x| *x != 0.0));
                    // the AVX-512 way only where the processor has it
                    let ways = if avx512_lanes() { 3 } else { 2 };
                    for way in ["4 lanes", "8 lanes", "8 lanes, AVX-512"].into_iter().take(ways) {
                        bb.block.fill(0.0);
                        let filled = match way {
                            "4 lanes" => bb.fill_groups(&mut kin4, start, 0, cnt),
                            "8 lanes" => bb.fill_groups(&mut kin8, start, 0, cnt),
                            // SAFETY: `avx512_lanes()` found AVX-512F, VL and DQ (`ways`).
                            #[cfg(target_arch = "x86_64")]
                            _ => unsafe { bb.fill_groups_avx512(&mut kin8, start, cnt) },
                            #[cfg(not(target_arch = "x86_64"))]
                            _ => unreachable!(),
                        };
                        assert_eq!(filled.unwrap(), cnt, "{way}");
                        for (a, b) in bb.block.iter().zip(one.iter()) {
                            assert_eq!(a.to_bits(), b.to_bits(), "{name} {layout:?} {way}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_gram_pass_equals_the_dense_gram_of_the_same_blocks() {
        // The row-major, permuted, triangle-only Gram pass (with its unwritten zero linear rows) against the general
        // column-major `GramLs` fed the QR pass's blocks, on a problem with known bodies and weights, a sample count
        // that leaves a partial block and is split over threads.
        let m = builtin::load("naveen_dual_arm").unwrap();
        let t = PARALLEL_MIN_SAMPLES + 13;
        let case = Case::new(&m, t, 70);
        let p = case.problem();
        let n = case.unknown.len();
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
