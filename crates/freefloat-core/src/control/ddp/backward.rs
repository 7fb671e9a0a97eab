//! The Riccati backward pass of DDP (Valverde 2018, §8.2, eqs. (8.20)–(8.33); second-order terms
//! eqs. (8.39)–(8.44)), in the tangent error state, with the gap terms of the feasibility-driven
//! variant (a defect f̄ between the rollout of a node and the next nominal state shifts the value
//! gradient to `V_x' + V_xx' f̄'`).

use super::problem::ActionModel;
use super::workspace::Workspace;
use crate::error::{FfError, Result};
use nalgebra::{DMatrix, DVector};

/// In-place Cholesky `A = L Lᵀ` of a symmetric matrix (lower triangle written, upper left as is).
/// Returns false if A is not positive definite (or not finite).
pub(crate) fn cholesky_in_place(a: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    for j in 0..n {
        let mut d = a[(j, j)];
        for k in 0..j {
            d -= a[(j, k)] * a[(j, k)];
        }
        if !(d > 0.0) || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        a[(j, j)] = d;
        for i in j + 1..n {
            let mut s = a[(i, j)];
            for k in 0..j {
                s -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = s / d;
        }
    }
    true
}

/// Solve `L Lᵀ x = b` in place with the factor of `cholesky_in_place`.
pub(crate) fn cholesky_solve_in_place(l: &DMatrix<f64>, b: &mut [f64]) {
    let n = l.nrows();
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[(i, k)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[(k, i)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
}

/// What the backward pass found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backward {
    /// Gains computed at every node.
    Done,
    /// Q_uu + λI was not positive definite at this node (or the value function overflowed there): raise λ
    /// and try again.
    NotPositiveDefinite(usize),
}

/// One backward pass at the nominal trajectory whose derivatives are in `ws.diffs`.
/// `lambda`: regularisation of Q_uu; `full`: add the second-order dynamics terms (full DDP);
/// `gaps`: use the defects `ws.gaps` (feasibility-driven DDP).
pub fn backward_pass(
    model: &mut dyn ActionModel,
    ws: &mut Workspace,
    lambda: f64,
    full: bool,
    gaps: bool,
) -> Result<Backward> {
    let n = ws.n;
    // V_N = terminal cost.
    ws.vx[n].copy_from(&ws.diffs[n].lx);
    ws.vxx[n].copy_from(&ws.diffs[n].lxx);
    for k in (0..n).rev() {
        let (vx_now, vx_next) = ws.vx.split_at_mut(k + 1);
        let (vxx_now, vxx_next) = ws.vxx.split_at_mut(k + 1);
        let (vxn, vxxn) = (&vx_next[0], &vxx_next[0]);
        // Gap-corrected gradient of the next node.
        ws.vx_plus.copy_from(vxn);
        if gaps {
            ws.vx_plus.gemv(1.0, vxxn, &ws.gaps[k + 1], 1.0);
        }
        let d = &ws.diffs[k];
        // Eqs. (8.20)–(8.26): Q_x = L_x + Fxᵀ V_x', Q_u = L_u + Fuᵀ V_x',
        // Q_xx = L_xx + Fxᵀ V_xx' Fx, Q_uu = L_uu + Fuᵀ V_xx' Fu, Q_ux = L_ux + Fuᵀ V_xx' Fx.
        ws.qx.copy_from(&d.lx);
        ws.qx.gemv_tr(1.0, &d.fx, &ws.vx_plus, 1.0);
        ws.qu.copy_from(&d.lu);
        ws.qu.gemv_tr(1.0, &d.fu, &ws.vx_plus, 1.0);
        // (tr_mul_to, not gemm_tr: nalgebra's gemm_tr allocates a temporary.)
        d.fx.tr_mul_to(vxxn, &mut ws.fxt_v);
        ws.qxx.copy_from(&d.lxx);
        mul_add(&mut ws.qxx, &ws.fxt_v, &d.fx);
        d.fu.tr_mul_to(vxxn, &mut ws.fut_v);
        ws.quu.copy_from(&d.luu);
        mul_add(&mut ws.quu, &ws.fut_v, &d.fu);
        ws.qux.tr_copy_from(&d.lxu);
        mul_add(&mut ws.qux, &ws.fut_v, &d.fx);
        if full {
            // Full DDP (eqs. (8.39)–(8.41)): + Σ_j V_x'[j] ∂²F^j.
            let (xk, uk) = (ws.xs[k].as_slice(), ws.us[k].as_slice());
            if !model.dynamics_hessian(k, xk, uk, ws.vx_plus.as_slice(), &mut ws.hess)? {
                return Err(FfError::arg(
                    "second_order",
                    "full DDP needs the second-order dynamics terms, which this action model does not provide; \
                     use iLQG (second_order = false)",
                ));
            }
            ws.qxx += &ws.hess.hxx;
            ws.quu += &ws.hess.huu;
            ws.qux += &ws.hess.hux;
        }
        // Regularised factorisation, Q̃_uu = Q_uu + λI (eq. (8.27) asks for Q_uu > 0).
        ws.quu_chol.copy_from(&ws.quu);
        for i in 0..ws.nu {
            ws.quu_chol[(i, i)] += lambda;
        }
        if !cholesky_in_place(&mut ws.quu_chol) {
            return Ok(Backward::NotPositiveDefinite(k));
        }
        // Gains (eqs. (8.29)–(8.30)): l = −Q̃_uu⁻¹ Q_u, L = −Q̃_uu⁻¹ Q_ux.
        let kff = &mut ws.kff[k];
        kff.copy_from(&ws.qu);
        cholesky_solve_in_place(&ws.quu_chol, kff.as_mut_slice());
        kff.neg_mut();
        let kfb = &mut ws.kfb[k];
        kfb.copy_from(&ws.qux);
        for c in 0..ws.ndx {
            cholesky_solve_in_place(&ws.quu_chol, kfb.column_mut(c).as_mut_slice());
        }
        kfb.neg_mut();
        // Value update in the form of Tassa's code, valid for any gains:
        // V_x = Q_x + Lᵀ Q_uu l + Lᵀ Q_u + Q_uxᵀ l, V_xx = Q_xx + Lᵀ Q_uu L + Lᵀ Q_ux + Q_uxᵀ L.
        // With λ = 0 it equals eqs. (8.32)–(8.33).
        let (kff, kfb) = (&ws.kff[k], &ws.kfb[k]);
        ws.tmp_u.copy_from(&ws.qu);
        ws.tmp_u.gemv(1.0, &ws.quu, kff, 1.0);
        let vx = &mut vx_now[k];
        vx.copy_from(&ws.qx);
        vx.gemv_tr(1.0, kfb, &ws.tmp_u, 1.0);
        vx.gemv_tr(1.0, &ws.qux, kff, 1.0);
        ws.tmp_ux.copy_from(&ws.qux);
        mul_add(&mut ws.tmp_ux, &ws.quu, kfb);
        let vxx = &mut vxx_now[k];
        vxx.copy_from(&ws.qxx);
        kfb.tr_mul_to(&ws.tmp_ux, &mut ws.fxt_v);
        *vxx += &ws.fxt_v;
        ws.qux.tr_mul_to(kfb, &mut ws.fxt_v);
        *vxx += &ws.fxt_v;
        symmetrise(vxx);
        if !vx.iter().all(|v| v.is_finite()) || !vxx.iter().all(|v| v.is_finite()) {
            // Gains too aggressive for the local model (tiny λ on an ill-conditioned Q_uu): treat it like a
            // failed factorisation so that the caller raises λ instead of stopping.
            return Ok(Backward::NotPositiveDefinite(k));
        }
    }
    Ok(Backward::Done)
}

/// `out += a b` for column-major matrices, column by column (axpy form, vectorises well). Written out
/// because nalgebra's dynamic `gemm` allocates a packing buffer on every call.
fn mul_add(out: &mut DMatrix<f64>, a: &DMatrix<f64>, b: &DMatrix<f64>) {
    let (m, k) = (a.nrows(), a.ncols());
    debug_assert_eq!((out.nrows(), out.ncols(), b.nrows()), (m, b.ncols(), k));
    let asl = a.as_slice();
    for j in 0..b.ncols() {
        let oc = &mut out.as_mut_slice()[j * m..(j + 1) * m];
        for p in 0..k {
            let bpj = b[(p, j)];
            if bpj == 0.0 {
                continue;
            }
            let ac = &asl[p * m..(p + 1) * m];
            for i in 0..m {
                oc[i] += ac[i] * bpj;
            }
        }
    }
}

fn symmetrise(a: &mut DMatrix<f64>) {
    let n = a.nrows();
    for i in 0..n {
        for j in i + 1..n {
            let m = 0.5 * (a[(i, j)] + a[(j, i)]);
            a[(i, j)] = m;
            a[(j, i)] = m;
        }
    }
}

/// Coefficients of the cost change the local LQ model predicts for step α: `ΔJ(α) = α d1 + ½ α² d2`.
/// Exact for the LQ model with the computed gains (any λ, gaps included): the linearised deviations are
/// `δx_k = α d_k` with `d₀ = f̄₀`, `d_{k+1} = Fx d_k + Fu (l_k + L_k d_k) + f̄_{k+1}` (Valverde 2018,
/// eq. (8.45) linearised).
pub fn expected_change(ws: &mut Workspace, gaps: bool) -> (f64, f64) {
    let n = ws.n;
    let (mut d1, mut d2) = (0.0, 0.0);
    if gaps {
        ws.dx.copy_from(&ws.gaps[0]);
    } else {
        ws.dx.fill(0.0);
    }
    for k in 0..n {
        let d = &ws.diffs[k];
        // du = l + L dx
        ws.tmp_u.copy_from(&ws.kff[k]);
        ws.tmp_u.gemv(1.0, &ws.kfb[k], &ws.dx, 1.0);
        d1 += d.lx.dot(&ws.dx) + d.lu.dot(&ws.tmp_u);
        d2 += quad(&d.lxx, &ws.dx) + quad(&d.luu, &ws.tmp_u) + 2.0 * bilinear(&d.lxu, &ws.dx, &ws.tmp_u);
        if gaps {
            ws.dx2.copy_from(&ws.gaps[k + 1]);
        } else {
            ws.dx2.fill(0.0);
        }
        ws.dx2.gemv(1.0, &d.fx, &ws.dx, 1.0);
        ws.dx2.gemv(1.0, &d.fu, &ws.tmp_u, 1.0);
        std::mem::swap(&mut ws.dx, &mut ws.dx2);
    }
    let d = &ws.diffs[n];
    d1 += d.lx.dot(&ws.dx);
    d2 += quad(&d.lxx, &ws.dx);
    (d1, d2)
}

fn quad(a: &DMatrix<f64>, x: &DVector<f64>) -> f64 {
    let mut s = 0.0;
    for j in 0..a.ncols() {
        let xj = x[j];
        if xj == 0.0 {
            continue;
        }
        let mut c = 0.0;
        for i in 0..a.nrows() {
            c += a[(i, j)] * x[i];
        }
        s += c * xj;
    }
    s
}

fn bilinear(a: &DMatrix<f64>, x: &DVector<f64>, y: &DVector<f64>) -> f64 {
    let mut s = 0.0;
    for j in 0..a.ncols() {
        let mut c = 0.0;
        for i in 0..a.nrows() {
            c += a[(i, j)] * x[i];
        }
        s += c * y[j];
    }
    s
}
