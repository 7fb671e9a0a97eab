//! The Riccati backward pass of DDP (Valverde 2018, §8.2, eqs. (8.20)–(8.33); second-order terms
//! eqs. (8.39)–(8.44)), in the tangent error state, with the gap terms of the feasibility-driven
//! variant (a defect f̄ between the rollout of a node and the next nominal state shifts the value
//! gradient to `V_x' + V_xx' f̄'`).

use super::dense;
use super::problem::{ActionModel, DynamicsHessian};
use super::workspace::Workspace;
use crate::dynamics::derivatives::cholesky_inverse;
use crate::error::{FfError, Result};
use nalgebra::{DMatrix, DVector};

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
    let (n, ndx, nu) = (ws.n, ws.ndx, ws.nu);
    // V_N = terminal cost.
    ws.vx[n].copy_from(&ws.diffs[n].lx);
    ws.vxx[n].copy_from(&ws.diffs[n].lxx);
    for k in (0..n).rev() {
        let (vx_now, vx_next) = ws.vx.split_at_mut(k + 1);
        let (vxx_now, vxx_next) = ws.vxx.split_at_mut(k + 1);
        let (vxn, vxxn) = (vx_next[0].as_slice(), vxx_next[0].as_slice());
        // Gap-corrected gradient of the next node.
        ws.vx_plus.as_mut_slice().copy_from_slice(vxn);
        if gaps {
            dense::gemv_n_add(ws.vx_plus.as_mut_slice(), vxxn, ws.gaps[k + 1].as_slice(), ndx, ndx);
        }
        let d = &ws.diffs[k];
        let (fx, fu) = (d.fx.as_slice(), d.fu.as_slice());
        // Eqs. (8.20)–(8.26): Q_x = L_x + Fxᵀ V_x', Q_u = L_u + Fuᵀ V_x',
        // Q_xx = L_xx + Fxᵀ V_xx' Fx, Q_uu = L_uu + Fuᵀ V_xx' Fu, Q_ux = L_ux + Fuᵀ V_xx' Fx,
        // through P_x = V_xx' Fx and P_u = V_xx' Fu (V_xx' is symmetric).
        ws.qx.copy_from(&d.lx);
        dense::gemv_t(ws.qx.as_mut_slice(), fx, ws.vx_plus.as_slice(), ndx, ndx, true);
        ws.qu.copy_from(&d.lu);
        dense::gemv_t(ws.qu.as_mut_slice(), fu, ws.vx_plus.as_slice(), ndx, nu, true);
        dense::mul_nn(ws.px.as_mut_slice(), vxxn, fx, ndx, ndx, ndx, false);
        dense::mul_nn(ws.pu.as_mut_slice(), vxxn, fu, ndx, ndx, nu, false);
        // The products with Fxᵀ and Fuᵀ run on the transposes, formed once per node, in `mul_nn` (see `dense`):
        // 12 % less time per node than dot products of columns on the ch. 8 arm. Q_xx and Q_uu are symmetric in
        // exact arithmetic: their upper triangles are kept and mirrored.
        dense::transpose(ws.fxt.as_mut_slice(), fx, ndx, ndx);
        dense::transpose(ws.fut.as_mut_slice(), fu, ndx, nu);
        ws.qxx.copy_from(&d.lxx);
        dense::mul_nn(ws.qxx.as_mut_slice(), ws.fxt.as_slice(), ws.px.as_slice(), ndx, ndx, ndx, true);
        dense::mirror_upper(ws.qxx.as_mut_slice(), ndx);
        ws.quu.copy_from(&d.luu);
        dense::mul_nn(ws.quu.as_mut_slice(), ws.fut.as_slice(), ws.pu.as_slice(), nu, ndx, nu, true);
        dense::mirror_upper(ws.quu.as_mut_slice(), nu);
        ws.qux.tr_copy_from(&d.lxu);
        dense::mul_nn(ws.qux.as_mut_slice(), ws.fut.as_slice(), ws.px.as_slice(), nu, ndx, ndx, true);
        if full {
            // Full DDP (eqs. (8.39)–(8.41)): + Σ_j V_x'[j] ∂²F^j.
            if ws.hess.len() != n {
                ws.hess = vec![DynamicsHessian::zeros(ndx, nu); n];
            }
            let (xk, uk) = (ws.xs[k].as_slice(), ws.us[k].as_slice());
            if !model.dynamics_hessian(k, xk, uk, ws.vx_plus.as_slice(), &mut ws.hess[k])? {
                return Err(FfError::arg(
                    "second_order",
                    "full DDP needs the second-order dynamics terms, which this action model does not provide; \
                     use iLQG (second_order = false)",
                ));
            }
            ws.qxx += &ws.hess[k].hxx;
            ws.quu += &ws.hess[k].huu;
            ws.qux += &ws.hess[k].hux;
        }
        // Regularised factorisation, Q̃_uu = Q_uu + λI (eq. (8.27) asks for Q_uu > 0), and its inverse.
        ws.quu_reg.copy_from(&ws.quu);
        for i in 0..nu {
            ws.quu_reg[(i, i)] += lambda;
        }
        if !cholesky_inverse(&ws.quu_reg, &mut ws.quu_chol, &mut ws.quu_inv) {
            return Ok(Backward::NotPositiveDefinite(k));
        }
        // Gains (eqs. (8.29)–(8.30)): l = −Q̃_uu⁻¹ Q_u, L = −Q̃_uu⁻¹ Q_ux.
        let kff = &mut ws.kff[k];
        kff.fill(0.0);
        dense::gemv_n_add(kff.as_mut_slice(), ws.quu_inv.as_slice(), ws.qu.as_slice(), nu, nu);
        kff.neg_mut();
        let kfb = &mut ws.kfb[k];
        dense::mul_nn(kfb.as_mut_slice(), ws.quu_inv.as_slice(), ws.qux.as_slice(), nu, nu, ndx, false);
        kfb.neg_mut();
        // Value update in the form of Tassa's code, valid for any gains:
        // V_x = Q_x + Lᵀ (Q_u + Q_uu l) + Q_uxᵀ l, V_xx = Q_xx + Lᵀ (Q_ux + Q_uu L) + Q_uxᵀ L.
        // With λ = 0 it equals eqs. (8.32)–(8.33). The two products of V_xx are one: [L; Q_ux]ᵀ [Q_ux + Q_uu L; L].
        let (kff, kfb) = (&ws.kff[k], &ws.kfb[k]);
        ws.tmp_u.copy_from(&ws.qu);
        dense::gemv_n_add(ws.tmp_u.as_mut_slice(), ws.quu.as_slice(), kff.as_slice(), nu, nu);
        let vx = &mut vx_now[k];
        vx.copy_from(&ws.qx);
        dense::gemv_t(vx.as_mut_slice(), kfb.as_slice(), ws.tmp_u.as_slice(), nu, ndx, true);
        dense::gemv_t(vx.as_mut_slice(), ws.qux.as_slice(), kff.as_slice(), nu, ndx, true);
        ws.tmp_ux.copy_from(&ws.qux);
        dense::mul_nn(ws.tmp_ux.as_mut_slice(), ws.quu.as_slice(), kfb.as_slice(), nu, nu, ndx, true);
        {
            // z1 = [L; Q_ux]ᵀ (ndx × 2nu: written transposed, for `mul_nn`), z2 = [Q_ux + Q_uu L; L] (2nu × ndx)
            let (z1, z2) = (ws.z1.as_mut_slice(), ws.z2.as_mut_slice());
            let (l, qux, h) = (kfb.as_slice(), ws.qux.as_slice(), ws.tmp_ux.as_slice());
            for c in 0..ndx {
                let (s, t) = (c * nu, c * 2 * nu);
                for r in 0..nu {
                    z1[r * ndx + c] = l[s + r];
                    z1[(nu + r) * ndx + c] = qux[s + r];
                }
                z2[t..t + nu].copy_from_slice(&h[s..s + nu]);
                z2[t + nu..t + 2 * nu].copy_from_slice(&l[s..s + nu]);
            }
        }
        let vxx = &mut vxx_now[k];
        vxx.copy_from(&ws.qxx);
        dense::mul_nn(vxx.as_mut_slice(), ws.z1.as_slice(), ws.z2.as_slice(), ndx, 2 * nu, ndx, true);
        // (symmetric in exact arithmetic: the upper triangle is kept and mirrored)
        dense::mirror_upper(vxx.as_mut_slice(), ndx);
        if !vx.iter().all(|v| v.is_finite()) || !vxx.iter().all(|v| v.is_finite()) {
            // Gains too aggressive for the local model (tiny λ on an ill-conditioned Q_uu): treat it like a
            // failed factorisation so that the caller raises λ instead of stopping.
            return Ok(Backward::NotPositiveDefinite(k));
        }
    }
    Ok(Backward::Done)
}

/// Coefficients of the cost change the local LQ model predicts for step α: `ΔJ(α) = α d1 + ½ α² d2`.
/// Exact for the LQ model with the computed gains (any λ, gaps included): the linearised deviations are
/// `δx_k = α d_k` with `d₀ = f̄₀`, `d_{k+1} = Fx d_k + Fu (l_k + L_k d_k) + f̄_{k+1}` (Valverde 2018,
/// eq. (8.45) linearised). With `full`, the model also has the dynamics curvature of full DDP: each node adds
/// `δzᵀ H_k δz` (the terms `ws.hess` the last backward pass added to Q), so that the expected-improvement test
/// judges a full-DDP step against the model it was computed from.
pub fn expected_change(ws: &mut Workspace, gaps: bool, full: bool) -> (f64, f64) {
    let (n, ndx, nu) = (ws.n, ws.ndx, ws.nu);
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
        dense::gemv_n_add(ws.tmp_u.as_mut_slice(), ws.kfb[k].as_slice(), ws.dx.as_slice(), nu, ndx);
        d1 += dense::dot(d.lx.as_slice(), ws.dx.as_slice()) + dense::dot(d.lu.as_slice(), ws.tmp_u.as_slice());
        d2 += quad(&d.lxx, &ws.dx) + quad(&d.luu, &ws.tmp_u) + 2.0 * bilinear(&d.lxu, &ws.dx, &ws.tmp_u);
        if full {
            let h = &ws.hess[k];
            d2 += quad(&h.hxx, &ws.dx) + quad(&h.huu, &ws.tmp_u) + 2.0 * bilinear(&h.hux, &ws.tmp_u, &ws.dx);
        }
        if gaps {
            ws.dx2.copy_from(&ws.gaps[k + 1]);
        } else {
            ws.dx2.fill(0.0);
        }
        dense::gemv_n_add(ws.dx2.as_mut_slice(), d.fx.as_slice(), ws.dx.as_slice(), ndx, ndx);
        dense::gemv_n_add(ws.dx2.as_mut_slice(), d.fu.as_slice(), ws.tmp_u.as_slice(), ndx, nu);
        std::mem::swap(&mut ws.dx, &mut ws.dx2);
    }
    let d = &ws.diffs[n];
    d1 += dense::dot(d.lx.as_slice(), ws.dx.as_slice());
    d2 += quad(&d.lxx, &ws.dx);
    (d1, d2)
}

/// `xᵀ a x` (a square, column-major).
fn quad(a: &DMatrix<f64>, x: &DVector<f64>) -> f64 {
    bilinear(a, x, x)
}

/// `xᵀ a y` (a: len(x) × len(y), column-major).
fn bilinear(a: &DMatrix<f64>, x: &DVector<f64>, y: &DVector<f64>) -> f64 {
    let (m, xs) = (a.nrows(), x.as_slice());
    let mut s = 0.0;
    for (j, &yj) in y.iter().enumerate() {
        if yj != 0.0 {
            s += yj * dense::dot(&a.as_slice()[j * m..(j + 1) * m], xs);
        }
    }
    s
}
