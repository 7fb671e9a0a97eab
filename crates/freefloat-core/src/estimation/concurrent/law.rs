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
