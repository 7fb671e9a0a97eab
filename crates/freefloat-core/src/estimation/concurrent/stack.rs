//! The concurrent-learning data stack 𝒳, ℱ of Valverde 2018 §9.3: Algorithm 3 (populate it: fill, then
//! replace a stored point only while the smallest singular value is below σ_th and only if no sorted singular
//! value decreases) and Algorithm 4's accumulation `RR = Σ 𝐑_kᵀ𝐑_k`, `Rf = Σ 𝐑_kᵀ𝐅_k` (with the reset to zero
//! that the printed algorithm omits).
//!
//! Block-diagonal structure: 𝐑 = blkdiag(R̂_1, …, R̂_B) (9.9), so ΣRᵀR is block diagonal with B blocks of 7×7
//! and its 7B singular values are the union of the blocks' ones. Every singular-value test below works on the
//! B small symmetric blocks (their eigenvalues: they are Gram matrices), never on the 7B×7B matrix. Each stored
//! point keeps its per-block Gram `R̂ᵀR̂` and `R̂ᵀF`, so a trial replacement costs B rank-updates and B 7×7
//! eigen-decompositions. Nothing here allocates after `DataStack::new`.

use super::{M7, M87, NP, V7, V8};
use crate::error::{FfError, Result};
use nalgebra::{SMatrix, SVD};

type M8 = SMatrix<f64, 8, 8>;
/// The triangular factor of `[a; b]` for two upper-triangular 8×8 factors: `RᵀR = aᵀa + bᵀb` (up to the signs of
/// R's rows, which `RᵀR`, `Tᵀg` and the singular values do not see).
fn merge(a: &M8, b: &M8) -> M8 {
    let (mut r, mut b) = (a.data.0, b.data.0);
    fold_rows::<true>(&mut r, &mut b);
    M8::from_data(nalgebra::ArrayStorage(r))
}

/// The triangular factor of one point's `[R̂|F]` (8×8, full): `RᵀR = [R̂|F]ᵀ[R̂|F]`.
fn triangularize(x: &M8) -> M8 {
    let (mut r, mut b) = ([[0.0; 8]; 8], x.data.0);
    fold_rows::<false>(&mut r, &mut b);
    M8::from_data(nalgebra::ArrayStorage(r))
}

/// Folds the rows of `b` into the upper-triangular `r` by Householder reflections (Golub and Van Loan, §5.1.2,
/// applied to `[r; b]`): afterwards `r` is upper triangular with `rᵀr` = the old `rᵀr + bᵀb`; `b` is used up.
/// Both are column-major (`x[c][row]`). `TRI`: `b` is upper triangular too, so column j's reflection involves
/// only b's rows 0..=j (the rows below j are zero in column j and stay so: earlier reflections only mix rows
/// 0..=j' < j): 624 flops for two factors instead of the 1,968 of a 16×8 QR, which merged the tree's nodes
/// before, in nalgebra's general code (a quarter of the ch. 9 estimator's time, perf).
#[inline]
fn fold_rows<const TRI: bool>(r: &mut [[f64; 8]; 8], b: &mut [[f64; 8]; 8]) {
    for j in 0..8 {
        let nb = if TRI { j + 1 } else { 8 };
        let sigma: f64 = b[j][..nb].iter().map(|x| x * x).sum();
        if sigma == 0.0 {
            continue;
        }
        let alpha = r[j][j];
        let norm = (alpha * alpha + sigma).sqrt();
        // the new diagonal has the opposite sign of alpha: alpha − beta has no cancellation
        let beta = if alpha >= 0.0 { -norm } else { norm };
        let scale = 1.0 / (alpha - beta);
        let tau = (beta - alpha) / beta;
        let mut v = [0.0; 8]; // the reflector is [1; v]
        for k in 0..nb {
            v[k] = b[j][k] * scale;
        }
        r[j][j] = beta;
        for c in j + 1..8 {
            let mut w = r[c][j];
            for k in 0..nb {
                w += v[k] * b[c][k];
            }
            let tw = tau * w;
            r[c][j] -= tw;
            for k in 0..nb {
                b[c][k] -= tw * v[k];
            }
        }
    }
}

/// `R̂ᵀR̂` and `R̂ᵀF` of one block, written out (the generic small-matrix product is several times slower here,
/// and this runs for every candidate).
#[inline]
fn gram(r: &M87, f: &V8) -> (M7, V7) {
    let mut g = M7::zeros();
    let mut gf = V7::zeros();
    for j in 0..NP {
        let cj = r.column(j);
        for k in j..NP {
            let ck = r.column(k);
            let mut s = 0.0;
            for i in 0..8 {
                s += cj[i] * ck[i];
            }
            g[(j, k)] = s;
            g[(k, j)] = s;
        }
        let mut s = 0.0;
        for i in 0..8 {
            s += cj[i] * f[i];
        }
        gf[j] = s;
    }
    (g, gf)
}

/// A small deterministic generator (SplitMix64) for the random visiting order π of Algorithm 3 and for
/// the measurement noise of the studies: reproducible from a seed, no dependency.
#[derive(Clone, Debug)]
pub struct SplitMix(u64);

impl SplitMix {
    /// Generator from a seed.
    pub fn new(seed: u64) -> Self {
        SplitMix(seed)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform integer in 0..n (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n - 1)
    }
    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1]
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Singular values of a symmetric positive semi-definite 7×7 block, in descending order (its eigenvalues,
/// clamped at zero against round-off).
pub fn block_singular_values(a: &M7, out: &mut [f64]) {
    // eigenvalues only (no eigenvectors): about half the work of a full decomposition
    let e = a.symmetric_eigenvalues();
    for (o, x) in out.iter_mut().zip(e.iter()) {
        *o = x.max(0.0);
    }
    out[..NP].sort_unstable_by(|a, b| b.total_cmp(a));
}

/// What Algorithm 3 did with a candidate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Offer {
    /// Stored in an empty slot (filling phase, N_c < N_s).
    Appended,
    /// Replaced the stored point with this index (element-wise singular-value test passed).
    Replaced(usize),
    /// The stack was poor (σ_min < σ_th) but no replacement passed the test.
    Rejected,
    /// The stack was good enough (σ_min ≥ σ_th); the candidate was not tried.
    Full,
}

/// The data stack 𝒳, ℱ with its cached sums and singular values.
#[derive(Clone, Debug)]
pub struct DataStack {
    nb: usize,
    ns: usize,
    sigma_th: f64,
    nc: usize,
    /// stored 𝐑_k, 𝐅_k (slot-major: slot s, body i at s·nb + i)
    r: Vec<M87>,
    f: Vec<V8>,
    g: Vec<M7>,
    gf: Vec<V7>,
    /// RR, Rf per body (Algorithm 4)
    rr: Vec<M7>,
    rf: Vec<V7>,
    /// per body: the triangular factor T (TᵀT = RR) and g (Tᵀg = Rf) of the stacked data
    /// `[R̂_1|F_1; …; R̂_N|F_N]`, kept in a binary tree of 8×8 QR factors over the slots (leaf = the factor of a
    /// point's `[R̂|F]`, node = the factor of its two children stacked, root = the stack's factor): replacing a point
    /// re-factors log₂(N_s) nodes, with no downdating (which would lose the weak modes this form keeps)
    tri: Vec<M7>,
    leaves: usize,
    qtree: Vec<M8>,
    /// whether the tree's ρ (its root's last entry) misses a replacement made without refactoring (`offer`)
    rho_stale: bool,
    gvec: Vec<V7>,
    /// sorted (descending) union of the blocks' singular values of RR, from T (σ = s(T)², accurate down to
    /// ε·σ_max instead of the Gram eigenvalues' √ε·… floor)
    sv: Vec<f64>,
    /// the same from the Gram blocks' eigenvalues: what Algorithm 3's element-wise test compares, for the
    /// stack and for a trial alike
    sv_test: Vec<f64>,
    trial_sv: Vec<f64>,
    /// a trial's blocks, their traces and the order they are decomposed in (see `trial_passes`)
    trial_a: Vec<M7>,
    trial_trace: Vec<f64>,
    trial_order: Vec<usize>,
    /// per-block singular values of RR (body-major, each descending)
    block_sv: Vec<f64>,
    cand_g: Vec<M7>,
    cand_gf: Vec<V7>,
    perm: Vec<usize>,
    rng: SplitMix,
    /// number of changes of the stored set, trial decompositions done (cost counters)
    changes: u64,
    trials: u64,
}

impl DataStack {
    /// An empty stack for `nb` bodies holding up to `ns` points; σ_th is Algorithm 3's threshold and
    /// `seed` fixes the random visiting order π.
    pub fn new(nb: usize, ns: usize, sigma_th: f64, seed: u64) -> Result<Self> {
        if nb == 0 {
            return Err(FfError::arg("nbodies", "the estimator needs at least one body"));
        }
        if ns < 2 {
            return Err(FfError::arg(
                "ns",
                format!("the stack must hold at least 2 points (one sample has rank ≤ 6 of 7), got {ns}"),
            ));
        }
        if !(sigma_th >= 0.0) || !sigma_th.is_finite() {
            return Err(FfError::arg("sigma_th", format!("must be finite and ≥ 0, got {sigma_th}")));
        }
        let z7 = M7::zeros();
        Ok(DataStack {
            nb,
            ns,
            sigma_th,
            nc: 0,
            r: vec![M87::zeros(); ns * nb],
            f: vec![V8::zeros(); ns * nb],
            g: vec![z7; ns * nb],
            gf: vec![V7::zeros(); ns * nb],
            rr: vec![z7; nb],
            rf: vec![V7::zeros(); nb],
            tri: vec![z7; nb],
            leaves: ns.next_power_of_two(),
            qtree: vec![M8::zeros(); 2 * ns.next_power_of_two() * nb],
            rho_stale: false,
            gvec: vec![V7::zeros(); nb],
            sv: vec![0.0; NP * nb],
            sv_test: vec![0.0; NP * nb],
            trial_sv: vec![0.0; NP * nb],
            trial_a: vec![z7; nb],
            trial_trace: vec![0.0; nb],
            trial_order: (0..nb).collect(),
            block_sv: vec![0.0; NP * nb],
            cand_g: vec![z7; nb],
            cand_gf: vec![V7::zeros(); nb],
            perm: (0..ns).collect(),
            rng: SplitMix::new(seed),
            changes: 0,
            trials: 0,
        })
    }

    /// Number of stored points N_c.
    pub fn len(&self) -> usize {
        self.nc
    }
    /// True when nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.nc == 0
    }
    /// Capacity N_s.
    pub fn capacity(&self) -> usize {
        self.ns
    }
    /// Number of bodies B.
    pub fn nbodies(&self) -> usize {
        self.nb
    }
    /// RR's 7×7 blocks (one per body).
    pub fn rr(&self) -> &[M7] {
        &self.rr
    }
    /// Rf's 7-vectors (one per body).
    pub fn rf(&self) -> &[V7] {
        &self.rf
    }
    /// The triangular factors T of the stacked data (TᵀT = RR), one per body.
    pub fn tri(&self) -> &[M7] {
        &self.tri
    }
    /// The vectors g with Tᵀg = Rf, one per body.
    pub fn g(&self) -> &[V7] {
        &self.gvec
    }
    /// The 7B singular values of RR, descending (the union of the blocks' ones).
    pub fn singular_values(&self) -> &[f64] {
        &self.sv
    }
    /// The singular values of each body's block (body-major, each block descending).
    pub fn block_singular_values(&self) -> &[f64] {
        &self.block_sv
    }
    /// The smallest singular value of RR (0 while empty).
    pub fn sigma_min(&self) -> f64 {
        self.sv.last().copied().unwrap_or(0.0)
    }
    /// How often the stored set changed, and how many trial decompositions Algorithm 3 made.
    pub fn counters(&self) -> (u64, u64) {
        (self.changes, self.trials)
    }
    /// The stored point `k` (< N_c): its per-body regressors and wrenches.
    pub fn point(&self, k: usize) -> Option<(&[M87], &[V8])> {
        (k < self.nc).then(|| (&self.r[k * self.nb..(k + 1) * self.nb], &self.f[k * self.nb..(k + 1) * self.nb]))
    }

    /// Algorithm 3 for the candidate (X, F) = (per-body R̂_i, F_i). Returns what was done; when the stored
    /// set changed, RR, Rf and the singular values are recomputed from the stored points (Algorithm 4 with
    /// its missing reset).
    pub fn offer(&mut self, x: &[M87], fw: &[V8]) -> Result<Offer> {
        let nb = self.nb;
        if x.len() != nb || fw.len() != nb {
            return Err(FfError::arg("candidate", format!("needs one 8×7 regressor and one wrench per body ({nb})")));
        }
        if x.iter().any(|r| r.iter().any(|v| !v.is_finite())) || fw.iter().any(|f| f.iter().any(|v| !v.is_finite())) {
            return Err(FfError::arg("candidate", "regressor or wrench has a non-finite entry"));
        }
        for i in 0..nb {
            (self.cand_g[i], self.cand_gf[i]) = gram(&x[i], &fw[i]);
        }
        if self.nc < self.ns {
            // filling phase: accept unconditionally
            let s = self.nc;
            self.store(s, x, fw);
            self.nc += 1;
            self.rebuild();
            return Ok(Offer::Appended);
        }
        if !(self.sigma_min() < self.sigma_th) {
            return Ok(Offer::Full);
        }
        // random order π (Fisher–Yates)
        for k in (1..self.ns).rev() {
            let j = self.rng.below(k + 1);
            self.perm.swap(k, j);
        }
        // a singular value of the current stack counts as "not decreased" within round-off of the largest
        let tol = 64.0 * f64::EPSILON * self.sv_test.first().copied().unwrap_or(0.0).max(1e-300);
        // Element-wise ≥ of the sorted values implies ≥ of their sums, i.e. trace(G_cand) ≥ trace(G_p): a
        // free necessary condition that skips most trials' decompositions without changing the outcome.
        let cand_trace: f64 = self.cand_g.iter().map(|g| g.trace()).sum();
        let all_tol = tol * (NP * nb) as f64;
        for pi in 0..self.ns {
            let p = self.perm[pi];
            let p_trace: f64 = (0..nb).map(|i| self.g[p * nb + i].trace()).sum();
            if cand_trace < p_trace - all_tol {
                continue;
            }
            if cand_trace == 0.0 && p_trace == 0.0 {
                // both carry no information (e.g. a robot at rest: R̂ = 0 exactly): the replacement passes the
                // test and changes neither RR nor T; store the point without recomputing what cannot change
                // (with R̂ = 0 on both sides Rf, g and the tree's T, g are unchanged too: the F column only enters
                // ρ, so the tree's ρ is marked stale and `residual_norm` refactors from the stored points; redoing
                // the tree path here cost the thesis run 7-12 % of its estimator time at N_s = 10-50, in the
                // stretch at rest before the excitation)
                self.store_raw(p, x, fw);
                self.rho_stale = true;
                return Ok(Offer::Replaced(p));
            }
            self.trials += 1;
            if self.trial_passes(p, tol) {
                self.store(p, x, fw);
                self.rebuild();
                return Ok(Offer::Replaced(p));
            }
        }
        Ok(Offer::Rejected)
    }

    /// Remark 17's test for the candidate in slot p: element-wise over the sorted singular values of the trial
    /// stack (its blocks `RR_i − G_p,i + G_cand,i`), every one must be at least the current one less `tol`.
    ///
    /// The blocks are decomposed in decreasing order of their trace, and the test is decided as soon as it can
    /// be: a block's values are at most its trace (positive semi-definite), so once the blocks left all have a
    /// trace below a position's threshold, the values reaching that threshold are all known, and too few of them
    /// fail the test there. The decision is the same as decomposing every block first (the same values, compared
    /// the same way); it only stops early. On the ch. 9 run at N_s = 200, every one of the 10,318 failing trials
    /// failed at the fifth-largest value, which only two blocks could reach: two decompositions instead of eleven.
    fn trial_passes(&mut self, p: usize, tol: f64) -> bool {
        let nb = self.nb;
        for i in 0..nb {
            self.trial_a[i] = self.rr[i] - self.g[p * nb + i] + self.cand_g[i];
            self.trial_trace[i] = self.trial_a[i].trace();
            self.trial_order[i] = i;
        }
        let tr = &self.trial_trace;
        self.trial_order.sort_unstable_by(|&a, &b| tr[b].total_cmp(&tr[a]));
        // a block's computed values exceed its computed trace by round-off at most: the blocks are positive
        // semi-definite up to the rounding of forming them (their values may dip to about −ε·scale); far below
        // any threshold this could matter for, far above that round-off
        let scale: f64 =
            (0..nb).map(|i| self.rr[i].trace() + self.cand_g[i].trace() + self.g[p * nb + i].trace()).sum();
        let margin = 1e-9 * scale;
        let mut known = 0;
        for j in 0..nb {
            let i = self.trial_order[j];
            block_singular_values(&self.trial_a[i], &mut self.trial_sv[known..known + NP]);
            known += NP;
            self.trial_sv[..known].sort_unstable_by(|a, b| b.total_cmp(a));
            // every value of the blocks not decomposed yet is at most `bound`
            let bound = if j + 1 < nb {
                self.trial_trace[self.trial_order[j + 1]].max(0.0) + margin
            } else {
                f64::NEG_INFINITY
            };
            for (k, old) in self.sv_test.iter().enumerate() {
                let threshold = old - tol;
                if threshold <= bound {
                    break; // here and below, blocks not decomposed yet may still reach the threshold
                }
                // (written as `!(≥)` so that a NaN fails, as in the element-wise comparison this replaced)
                if k >= known || !(self.trial_sv[k] >= threshold) {
                    return false;
                }
            }
        }
        true
    }

    /// Store point s without touching the QR tree (for a point whose R̂ is zero replacing one whose R̂ is zero).
    fn store_raw(&mut self, s: usize, x: &[M87], fw: &[V8]) {
        let nb = self.nb;
        for i in 0..nb {
            self.r[s * nb + i] = x[i];
            self.f[s * nb + i] = fw[i];
            self.g[s * nb + i] = self.cand_g[i];
            self.gf[s * nb + i] = self.cand_gf[i];
        }
        self.changes += 1;
    }

    fn store(&mut self, s: usize, x: &[M87], fw: &[V8]) {
        let nb = self.nb;
        let p2 = self.leaves;
        for i in 0..nb {
            self.r[s * nb + i] = x[i];
            self.f[s * nb + i] = fw[i];
            self.g[s * nb + i] = self.cand_g[i];
            self.gf[s * nb + i] = self.cand_gf[i];
            // the slot's leaf, then every node above it
            let base = i * 2 * p2;
            let mut k = p2 + s;
            let mut leaf = M8::zeros();
            leaf.fixed_view_mut::<8, 7>(0, 0).copy_from(&x[i]);
            leaf.fixed_view_mut::<8, 1>(0, 7).copy_from(&fw[i]);
            self.qtree[base + k] = triangularize(&leaf);
            while k > 1 {
                k /= 2;
                self.qtree[base + k] = merge(&self.qtree[base + 2 * k], &self.qtree[base + 2 * k + 1]);
            }
        }
        self.changes += 1;
    }

    /// Body i's least-squares residual norm ρ_i over the stored points: `[R̂_1|F_1; …; R̂_N|F_N] = Q [T g; 0 ρ]`,
    /// so ρ_i = min_𝐌 ‖[R̂_k] 𝐌 − [F_k]‖ (0 while empty); None for i ≥ B. From the tree's root, or, when a
    /// replacement at rest left the tree's ρ stale (`offer`), by refactoring body i's stored points in turn.
    pub fn residual_norm(&self, i: usize) -> Option<f64> {
        if i >= self.nb {
            return None;
        }
        if !self.rho_stale {
            return Some(self.qtree[i * 2 * self.leaves + 1][(7, 7)].abs());
        }
        let mut acc = M8::zeros();
        for s in 0..self.nc {
            let mut leaf = M8::zeros();
            leaf.fixed_view_mut::<8, 7>(0, 0).copy_from(&self.r[s * self.nb + i]);
            leaf.fixed_view_mut::<8, 1>(0, 7).copy_from(&self.f[s * self.nb + i]);
            acc = merge(&acc, &triangularize(&leaf));
        }
        Some(acc[(7, 7)].abs())
    }

    /// Body i's noise estimate σ̂_i = ρ_i / √(n_i − r_i): n_i the stored rows of `[R̂|F]` that are not identically
    /// zero (a robot at rest gives zero rows, which carry nothing), r_i the rank of its block (singular values of
    /// T above `ZERO_RTOL` of the largest over all blocks). The unbiased estimate of the variance per row for
    /// independent equal-variance noise on the wrenches; infinite when there is no redundancy (n_i ≤ r_i); None
    /// for i ≥ B.
    pub fn noise_sigma(&self, i: usize) -> Option<f64> {
        let rho = self.residual_norm(i)?;
        let nb = self.nb;
        let mut rows = 0usize;
        for s in 0..self.nc {
            let (r, f) = (&self.r[s * nb + i], &self.f[s * nb + i]);
            rows += (0..8).filter(|&row| f[row] != 0.0 || r.row(row).iter().any(|x| *x != 0.0)).count();
        }
        let s_ref = self.sv.first().copied().unwrap_or(0.0).sqrt();
        let zero = super::ZERO_RTOL * s_ref;
        let rank = self.block_sv[NP * i..NP * (i + 1)].iter().filter(|x| x.sqrt() > zero).count();
        if rows <= rank {
            return Some(f64::INFINITY);
        }
        Some(rho / ((rows - rank) as f64).sqrt())
    }

    /// Algorithm 4's sums, reset first (the printed algorithm accumulates onto the previous call's RR, Rf),
    /// the triangular factors, and the singular values, block by block.
    fn rebuild(&mut self) {
        let nb = self.nb;
        for i in 0..nb {
            let (mut a, mut b) = (M7::zeros(), V7::zeros());
            for s in 0..self.nc {
                a += self.g[s * nb + i];
                b += self.gf[s * nb + i];
            }
            let tri = &self.qtree[i * 2 * self.leaves + 1];
            self.rr[i] = a;
            self.rf[i] = b;
            self.tri[i] = tri.fixed_view::<7, 7>(0, 0).into_owned();
            self.gvec[i] = tri.fixed_view::<7, 1>(0, 7).into_owned();
            block_singular_values(&a, &mut self.trial_sv[NP * i..NP * (i + 1)]);
            let sv = SVD::new(self.tri[i], false, false).singular_values;
            let out = &mut self.block_sv[NP * i..NP * (i + 1)];
            for (o, x) in out.iter_mut().zip(sv.iter()) {
                *o = x * x;
            }
            out.sort_unstable_by(|a, b| b.total_cmp(a));
        }
        self.sv_test.copy_from_slice(&self.trial_sv);
        self.sv_test.sort_unstable_by(|a, b| b.total_cmp(a));
        self.sv.copy_from_slice(&self.block_sv);
        self.sv.sort_unstable_by(|a, b| b.total_cmp(a));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` points of `nb` bodies: 8×7 regressors and wrenches. The odd bodies' regressors are nearly of rank one
    /// (every row close to a multiple of one direction per body), so that their largest value is nearly their
    /// trace and the trace bound of `trial_passes` is tight for them; the others have standard normal entries.
    fn points(n: usize, nb: usize, seed: u64) -> Vec<(Vec<M87>, Vec<V8>)> {
        let mut rng = SplitMix::new(seed);
        let dirs: Vec<[f64; 7]> = (0..nb).map(|_| std::array::from_fn(|_| rng.normal())).collect();
        let mut one = || {
            let r = (0..nb)
                .map(|b| {
                    let rows: [f64; 8] = std::array::from_fn(|_| rng.normal());
                    M87::from_fn(|i, j| {
                        let noise = rng.normal();
                        if b % 2 == 1 {
                            rows[i] * dirs[b][j] + 0.02 * noise
                        } else {
                            noise
                        }
                    })
                })
                .collect();
            let f = (0..nb).map(|_| V8::from_fn(|_, _| rng.normal())).collect();
            (r, f)
        };
        (0..n).map(|_| one()).collect()
    }

    /// The tree's QR steps against their definition and against nalgebra's QR: the factor of one point's full
    /// 8×8 block and the merge of two factors are upper triangular, reproduce the stacked Gram matrix to round-off,
    /// and equal nalgebra's R up to the signs of its rows; zero blocks (the tree's empty slots) change nothing.
    #[test]
    fn triangularize_and_merge_are_householder_qr() {
        let mut rng = SplitMix::new(11);
        for scale in [1e-3, 1.0, 1e4] {
            let full = |rng: &mut SplitMix| M8::from_fn(|_, _| scale * rng.normal());
            let (x, y) = (full(&mut rng), full(&mut rng));
            let (a, b) = (triangularize(&x), triangularize(&y));
            let m = merge(&a, &b);
            for r in [&a, &b, &m] {
                assert!((0..8).all(|c| (c + 1..8).all(|row| r[(row, c)] == 0.0)), "not upper triangular: {r}");
            }
            let gram = x.transpose() * x + y.transpose() * y;
            let err = (m.transpose() * m - gram).amax() / gram.amax();
            assert!(err < 1e-14, "merge: RᵀR off by {err:e}");
            assert!(((a.transpose() * a) - x.transpose() * x).amax() < 1e-14 * (x.transpose() * x).amax());
            let mut stacked = SMatrix::<f64, 16, 8>::zeros();
            stacked.fixed_view_mut::<8, 8>(0, 0).copy_from(&x);
            stacked.fixed_view_mut::<8, 8>(8, 0).copy_from(&y);
            let r = stacked.qr().r();
            for row in 0..8 {
                let sign = (r[(row, row)] * m[(row, row)]).signum();
                let d = (m.row(row) * sign - r.row(row)).amax();
                assert!(d < 1e-12 * scale, "row {row} differs by {d:e} from nalgebra's QR");
            }
            assert_eq!(merge(&m, &M8::zeros()), m);
            assert_eq!(merge(&M8::zeros(), &M8::zeros()), M8::zeros());
        }
    }

    #[test]
    fn the_early_deciding_trial_test_agrees_with_decomposing_every_block() {
        // `trial_passes` against Remark 17's test on all blocks decomposed first, for every slot of full stacks of
        // points whose bodies differ in scale by orders of magnitude (so that some thresholds only a few blocks can
        // reach, as in the ch. 9 run), including near-ties: a trial point equal to the stored one passes exactly.
        let nb = 5;
        let (mut passed, mut failed) = (0, 0);
        for seed in 0..6u64 {
            let mut pts = points(40, nb, 100 + seed);
            for (k, (r, _)) in pts.iter_mut().enumerate() {
                for (b, rb) in r.iter_mut().enumerate() {
                    *rb *= 10f64.powi(b as i32 - 2) * (1.0 + 0.3 * ((k * 7 + b) % 5) as f64);
                }
            }
            let mut st = DataStack::new(nb, 8, 1e9, seed).unwrap();
            for (r, f) in &pts[..8] {
                st.offer(r, f).unwrap();
            }
            let tol = 64.0 * f64::EPSILON * st.sv_test[0];
            for (r, f) in pts[8..].iter().chain(std::iter::once(&pts[3])) {
                for i in 0..nb {
                    (st.cand_g[i], st.cand_gf[i]) = gram(&r[i], &f[i]);
                }
                for p in 0..8 {
                    let mut all = vec![0.0; NP * nb];
                    for i in 0..nb {
                        let a = st.rr[i] - st.g[p * nb + i] + st.cand_g[i];
                        block_singular_values(&a, &mut all[NP * i..NP * (i + 1)]);
                    }
                    all.sort_unstable_by(|a, b| b.total_cmp(a));
                    let full = all.iter().zip(&st.sv_test).all(|(new, old)| *new >= *old - tol);
                    assert_eq!(st.trial_passes(p, tol), full, "seed {seed}, slot {p}");
                    if full {
                        passed += 1
                    } else {
                        failed += 1
                    }
                }
            }
        }
        assert!(passed > 0 && failed > 0, "both outcomes must occur: {passed} passed, {failed} failed");
    }
}
