//! The stored data of discrete concurrent learning (Valverde 2018, §4.3, Theorem 2, Remark 10): at most N_s
//! samples `(R_k, f_k)` of the regression `f^B(t_k) = R_k v(M)` (4.22), kept as the sums `RR = Σ R_kᵀR_k`,
//! `Rf = Σ R_kᵀf_k` that the update law (4.29) uses, with one of two selection rules and a stop threshold on
//! σ_min(RR) after which the stack is frozen.
//!
//! The ch. 4 text defers the selection to ch. 9: Algorithm 3 there (the element-wise singular-value test with a
//! random order of trial replacements) is the default. Chowdhary's rule (replace the point whose replacement
//! gives the largest σ_min, when that beats the present σ_min) is the alternative Remark 10 cites.

use super::gains::M7;
use crate::dualquat::regressor::{M87, V7};
use crate::dualquat::V8;
use crate::error::{FfError, Result};

/// How a full stack decides whether a candidate replaces a stored point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Selection {
    /// Valverde 2018 ch. 9, Algorithm 3: try the stored points in a random order; the first whose replacement
    /// leaves every sorted singular value of RR ≥ its present value (Remark 17) is replaced.
    #[default]
    Elementwise,
    /// Chowdhary's rule: try every stored point, keep the replacement with the largest σ_min if it exceeds the
    /// present σ_min.
    MaxMinSingularValue,
}

/// One stored sample, as the two products the sums need.
#[derive(Clone, Copy, Debug)]
struct Sample {
    rtr: M7,
    rtf: V7,
    /// trace(RᵀR) = ‖R‖²_F: an exact quick reject of the element-wise test (the sum of the singular values
    /// cannot grow when a point is swapped for one of smaller Frobenius norm).
    trace: f64,
}

/// The stack of discrete CL (the sets 𝒳, ℱ of §4.3).
#[derive(Clone, Debug)]
pub struct DataStack {
    n_s: usize,
    sigma_stop: f64,
    rule: Selection,
    samples: Vec<Sample>,
    rr: M7,
    rf: V7,
    /// singular values of RR, descending
    sv: [f64; 7],
    rng: u64,
    changes: usize,
    order: Vec<usize>,
}

/// Singular values of a symmetric positive semi-definite 7×7 matrix (|eigenvalues|), descending.
pub fn singular_values_psd(m: &M7) -> [f64; 7] {
    let ev = m.symmetric_eigenvalues();
    let mut s = [0.0; 7];
    for (o, e) in s.iter_mut().zip(ev.iter()) {
        *o = e.abs();
    }
    s.sort_by(|a, b| b.total_cmp(a));
    s
}

impl DataStack {
    /// An empty stack of capacity `n_s ≥ 2` (one sample has rank ≤ 6, so two are the least that can reach rank
    /// 7; the thesis asks N_s ≥ 7) that stops taking data once σ_min(RR) ≥ `sigma_stop` (> 0; `f64::INFINITY`
    /// never stops). `seed` drives Algorithm 3's random order.
    pub fn new(n_s: usize, sigma_stop: f64, rule: Selection, seed: u64) -> Result<DataStack> {
        if n_s < 2 {
            return Err(FfError::arg(
                "n_s",
                format!("the stack needs at least 2 samples (each has rank ≤ 6; the thesis uses ≥ 7), got {n_s}"),
            ));
        }
        if n_s > 100_000 {
            return Err(FfError::arg("n_s", format!("at most 100000 samples, got {n_s}")));
        }
        if !(sigma_stop > 0.0) {
            return Err(FfError::arg("sigma_stop", format!("must be > 0 (or infinity: never stop), got {sigma_stop}")));
        }
        Ok(DataStack {
            n_s,
            sigma_stop,
            rule,
            samples: Vec::with_capacity(n_s),
            rr: M7::zeros(),
            rf: V7::zeros(),
            sv: [0.0; 7],
            rng: seed ^ 0x9E37_79B9_7F4A_7C15,
            changes: 0,
            order: (0..n_s).collect(),
        })
    }
    /// Capacity N_s.
    pub fn capacity(&self) -> usize {
        self.n_s
    }
    /// Number of stored samples N_c.
    pub fn len(&self) -> usize {
        self.samples.len()
    }
    /// No sample stored yet.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }
    /// `Σ R_kᵀR_k`.
    pub fn rr(&self) -> &M7 {
        &self.rr
    }
    /// `Σ R_kᵀf_k`.
    pub fn rf(&self) -> &V7 {
        &self.rf
    }
    /// Singular values of RR, descending.
    pub fn singular_values(&self) -> &[f64; 7] {
        &self.sv
    }
    /// σ_min(RR).
    pub fn sigma_min(&self) -> f64 {
        self.sv[6]
    }
    /// Whether the stop threshold is reached (the stack no longer changes).
    pub fn stopped(&self) -> bool {
        self.sv[6] >= self.sigma_stop
    }
    /// How many times the stack changed (additions and replacements).
    pub fn changes(&self) -> usize {
        self.changes
    }

    fn next_u64(&mut self) -> u64 {
        // splitmix64: small, good enough for a permutation, and the same on every platform
        self.rng = self.rng.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.rng;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn resum(&mut self) {
        self.rr = M7::zeros();
        self.rf = V7::zeros();
        for s in &self.samples {
            self.rr += s.rtr;
            self.rf += s.rtf;
        }
        self.sv = singular_values_psd(&self.rr);
        self.changes += 1;
    }

    /// Offer the sample `(R_k, f_k)`; returns whether it was stored (Valverde 2018 ch. 9 Algorithm 3, or
    /// Chowdhary's rule). While N_c < N_s every sample is stored; once σ_min(RR) ≥ `sigma_stop` none is.
    pub fn offer(&mut self, r: &M87, f: &V8) -> bool {
        let rtr = r.transpose() * r;
        let cand = Sample { rtr, rtf: r.transpose() * f, trace: rtr.trace() };
        // the stop rule comes first: once σ_min ≥ σ_stop the search for data ends (§4.5), even in the filling
        // phase (Algorithm 3 checks the filling phase first; with σ_stop reached before N_s samples it would
        // keep adding, which the ch. 4 text rules out)
        if self.stopped() {
            return false;
        }
        if self.samples.len() < self.n_s {
            self.samples.push(cand);
            self.resum();
            return true;
        }
        match self.rule {
            Selection::Elementwise => {
                // Fisher-Yates shuffle of the trial order π(1..N_s)
                for i in (1..self.n_s).rev() {
                    let j = (self.next_u64() % (i as u64 + 1)) as usize;
                    self.order.swap(i, j);
                }
                for k in 0..self.n_s {
                    let i = self.order[k];
                    if cand.trace < self.samples[i].trace {
                        continue;
                    }
                    let trial = self.rr - self.samples[i].rtr + cand.rtr;
                    let sv = singular_values_psd(&trial);
                    if sv.iter().zip(&self.sv).all(|(a, b)| a >= b) {
                        self.samples[i] = cand;
                        self.resum();
                        return true;
                    }
                }
                false
            }
            Selection::MaxMinSingularValue => {
                let mut best = (self.sv[6], None);
                for i in 0..self.n_s {
                    let trial = self.rr - self.samples[i].rtr + cand.rtr;
                    let smin = trial.symmetric_eigenvalues().min().max(0.0);
                    if smin > best.0 {
                        best = (smin, Some(i));
                    }
                }
                match best.1 {
                    Some(i) => {
                        self.samples[i] = cand;
                        self.resum();
                        true
                    }
                    None => false,
                }
            }
        }
    }
}
