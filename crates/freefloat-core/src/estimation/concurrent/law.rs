//! The estimation law of Valverde 2018 ch. 9 and its "aggressive" SVD gain.
//!
//! (9.15):  d𝐌̂/dt = −Σ_k 𝐑_kᵀ ε_k = −(RR 𝐌̂ − Rf),  ε_k = 𝐑_k 𝐌̂ − 𝐅_k  (9.13)–(9.14)
//! (9.23):  d𝐌̂/dt = −K (RR 𝐌̂ − Rf),  K = 𝕀 for t < T_th,2,  K = U Σ̄ Uᵀ for t ≥ T_th,2  (9.24)
//! (9.26)–(9.27): σ̄_i = 1 if σ_i ≥ σ_th,2 or σ_i = 0, σ̄_i = σ_new / σ_i if 0 < σ_i < σ_th,2.
//!
//! RR is symmetric positive semi-definite, so its SVD is its eigen-decomposition (U = V on its range) and
//! K·RR = U Σ̄ Σ Uᵀ: each singular direction decays at rate σ̄_i σ_i (σ_new for the small ones). Both RR and
//! K are block diagonal with one 7×7 block per body, so the SVD is done per block (11 decompositions of 7×7
//! instead of one of 77×77). "σ_i = 0" is read with a round-off tolerance: σ_i ≤ `ZERO_RTOL`·σ_max counts as
//! zero (an exact zero test would hand the gain σ_new/1e-18 for a rank-deficient block's round-off).
//!
//! Numerics: RR = Σ R̂ᵀR̂ squares the condition number of the stacked data, and from rest the weakest mode of
//! each body is of order 1e-15·σ_max (see docs), below what RR and Rf hold to round-off. So the law is
//! evaluated in the mathematically identical square-root form: with `[R̂_1|F_1; …; R̂_N|F_N] = Q [T g; 0 ρ]`
//! (a QR kept per body by the stack), `Σ R̂_kᵀ ε_k = Tᵀ(T 𝐌̂ − g)` and `RR = TᵀT = W S² Wᵀ` from the SVD
//! `T = P S Wᵀ`, so U = W and σ_i = s_i².
//!
//! # The truncated gain (noise-robust; not in the thesis)
//!
//! Any nonsingular K leaves the equilibrium of (9.23) at the least-squares solution 𝐌_LS = T⁺g; K only sets the
//! rate of each direction, σ̄_i σ_i. In the coordinates c_i = w_iᵀ𝐌 (w_i the i-th column of W, p_i = T w_i / s_i
//! the matching column of P) the least-squares coordinate is c_i,LS = p_iᵀg / s_i, and with measurement noise of
//! standard deviation σ per row it is off by a random amount of standard deviation σ / s_i. (9.27) drives every
//! direction with σ_i < σ_th,2 to c_i,LS at rate σ_new, however small s_i: on the ch. 9 run s_i goes down to 3e-8
//! (σ_i = 7e-16, so σ_new/σ_i = 1.4e17), and 1e-5 N of joint-wrench noise already puts errors of several hundred
//! (relative) into those directions. The plain law (σ̄_i = 1) leaves such a direction where it is (rate σ_i):
//! an implicit prior.
//!
//! Accelerating direction i trades its current error |Δc_i| = |c_i(𝐌̂) − c_i,true| for one of standard deviation
//! σ / s_i; that pays only when |Δc_i| ≫ σ / s_i. The data measure |Δc_i| up to that same noise:
//! s_i (c_i,LS − c_i(𝐌̂)) = p_iᵀ(g − T𝐌̂) is the estimate's residual along p_i. Hence the rule, for each direction
//! (9.27) would accelerate (0 < σ_i < σ_th,2, σ_i not zero by `ZERO_RTOL`):
//!
//!   σ̄_i = σ_new / σ_i  if  |p_iᵀ(g − T𝐌̂_ref)| ≥ κ σ̂,   σ̄_i = 1 otherwise,      (9.27′)
//!
//! i.e. a direction is accelerated when the least-squares value lies at least κ standard errors σ̂ / s_i from the
//! estimate; it then ends at an error of standard deviation σ / s_i, at most about 1/κ of the distance it moved.
//! A direction whose data are only noise passes with probability 2Φ(−κ) for Gaussian noise of the estimated size
//! (2e-9 at κ = 6; 1.5e-7 per run of 77 directions). κ = 6 rather than the 4.4–4.8 this bound alone asks for (one
//! false pass in 10³–10⁴ runs): σ̂ pools a body's force and torque rows, whose noise differs, so the standard
//! error of a given direction can exceed σ̂ / s_i. Measured on the ch. 9 run with 500 noise seeds at 1e-4 N:
//! κ = 5 let 7 runs end above the prior's error (largest relative error 1.94), κ = 6 none (0.9895).
//!
//! σ̂ is each body's noise estimate from the QR the law already uses: `[R̂_1|F_1; …] = Q [T g; 0 ρ]` gives the
//! least-squares residual norm ρ, and σ̂ = ρ / √(n − r) with n the stored rows that are not identically zero and r
//! the block's rank (`DataStack::noise_sigma`). 𝐌̂_ref is the estimate when the gain switches on (T_th,2); the rule
//! is evaluated whenever K is formed (then, and again when the stack changes afterwards) against that same
//! reference, since an estimate already accelerated sits at its least-squares value and would fail the test. Without
//! noise ρ is round-off (σ̂ ≤ 3e-16 per body on the ch. 9 run), every direction passes and K is the thesis' K to
//! the bit. The rule needs no units or scales (the seven parameters mix kg and kg m², and a direction w_i mixes
//! them): it compares the data with their own noise. It needs redundancy: with n ≤ r rows σ̂ is infinite and no
//! direction is accelerated.

use super::{M7, NP, V7};
use nalgebra::SVD;

/// Singular values of T (√σ of RR) at or below this fraction of the largest one over all blocks count as zero
/// in (9.27) and in the rank (about MATLAB's `rank` tolerance for an 80-row stacked regressor).
pub const ZERO_RTOL: f64 = 1e-13;

/// The SVD gain of one body's block, (9.22)–(9.27), from its triangular factor T (TᵀT = RR). `s_ref` is the
/// largest singular value of T over all blocks (the scale of the zero test).
pub fn svd_gain(t: &M7, sigma_th2: f64, sigma_new: f64, s_ref: f64) -> M7 {
    let svd = SVD::new(*t, false, true);
    let vt = svd.v_t.expect("requested");
    let zero = ZERO_RTOL * s_ref;
    let mut k = M7::zeros();
    for j in 0..NP {
        let s = svd.singular_values[j];
        let sigma = s * s;
        let sbar = if s <= zero || sigma >= sigma_th2 { 1.0 } else { sigma_new / sigma };
        let w = vt.row(j).transpose();
        k += sbar * w * w.transpose();
    }
    k
}

/// The evidence of each singular direction of T, |p_iᵀ(g − T m)| (the left side of (9.27′)), with the
/// singular values s_i and right singular vectors (rows of `v_t`) from the same decomposition the gain uses.
/// p_i = T w_i / s_i; a direction with s_i = 0 has evidence 0.
pub fn direction_evidence(t: &M7, g: &V7, m: &V7, s: &[f64], v_t: &M7) -> [f64; NP] {
    let r = g - t * m;
    std::array::from_fn(|j| {
        if s[j] > 0.0 {
            let tw = t * v_t.row(j).transpose();
            (tw.dot(&r) / s[j]).abs()
        } else {
            0.0
        }
    })
}

/// The truncated SVD gain (9.27′) of one body's block from its T, g (TᵀT = RR, Tᵀg = Rf), the current estimate
/// `m`, the body's noise estimate σ̂ and κ: (9.27) for the directions whose evidence reaches κ σ̂, σ̄_i = 1 for
/// the others. Returns K and how many directions were withheld ((9.27) would have accelerated them). When no
/// direction is withheld, K is `svd_gain`'s to the bit.
#[allow(clippy::too_many_arguments)]
pub fn truncated_svd_gain(
    t: &M7,
    g: &V7,
    m: &V7,
    sigma_hat: f64,
    kappa: f64,
    sigma_th2: f64,
    sigma_new: f64,
    s_ref: f64,
) -> (M7, usize) {
    let svd = SVD::new(*t, false, true);
    let vt = svd.v_t.expect("requested");
    let ev = direction_evidence(t, g, m, svd.singular_values.as_slice(), &vt);
    let zero = ZERO_RTOL * s_ref;
    let mut k = M7::zeros();
    let mut withheld = 0;
    for j in 0..NP {
        let s = svd.singular_values[j];
        let sigma = s * s;
        // (written as `!(≥)` so that a NaN σ̂ withholds)
        let sbar = if s <= zero || sigma >= sigma_th2 {
            1.0
        } else if !(ev[j] >= kappa * sigma_hat) {
            withheld += 1;
            1.0
        } else {
            sigma_new / sigma
        };
        let w = vt.row(j).transpose();
        k += sbar * w * w.transpose();
    }
    (k, withheld)
}

/// `−K Tᵀ(T m − g)` (= −K(RR m − Rf)) for one block; K = None is the identity, (9.15). T is upper triangular
/// (the R of a QR); the products are written out (the generic small-matrix path is several times slower).
#[inline]
pub fn block_rate(t: &M7, g: &V7, k: Option<&M7>, m: &V7) -> V7 {
    let mut e = [0.0; NP];
    for i in 0..NP {
        let mut s = -g[i];
        for j in i..NP {
            s += t[(i, j)] * m[j];
        }
        e[i] = s;
    }
    let mut y = [0.0; NP];
    for j in 0..NP {
        let mut s = 0.0;
        for i in 0..=j {
            s += t[(i, j)] * e[i];
        }
        y[j] = s;
    }
    let mut out = V7::zeros();
    match k {
        Some(k) => {
            for i in 0..NP {
                let mut s = 0.0;
                for j in 0..NP {
                    s += k[(i, j)] * y[j];
                }
                out[i] = -s;
            }
        }
        None => {
            for i in 0..NP {
                out[i] = -y[i];
            }
        }
    }
    out
}

/// One classical RK4 step of (9.15)/(9.23) for every block over `dt`, RR, Rf and K held constant over the
/// step (new data enter at major steps only, §9.3). `m` is updated in place.
/// `rr`, `rf` are the blocks' T and g.
pub fn rk4_step(rr: &[M7], rf: &[V7], k: Option<&[M7]>, m: &mut [V7], dt: f64) {
    for i in 0..rr.len() {
        let ki = k.map(|k| &k[i]);
        let m0 = m[i];
        let k1 = block_rate(&rr[i], &rf[i], ki, &m0);
        let k2 = block_rate(&rr[i], &rf[i], ki, &(m0 + 0.5 * dt * k1));
        let k3 = block_rate(&rr[i], &rf[i], ki, &(m0 + 0.5 * dt * k2));
        let k4 = block_rate(&rr[i], &rf[i], ki, &(m0 + dt * k3));
        m[i] = m0 + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
}
