//! Rollouts: the plain nonlinear rollout of a control sequence, and the trial rollout of the line search
//! (Valverde 2018, eq. (8.45)): `û_k = ū_k + α l_k + L_k (x̂_k ⊖ x̄_k)`, `x̂_{k+1} = F(x̂_k, û_k)`,
//! with, in the feasibility-driven variant, the gaps closed by the fraction α:
//! `x̂_{k+1} = F(x̂_k, û_k) ⊕ (α − 1) f̄_{k+1}` (α = 1 gives a true rollout).

use super::dense;
use super::problem::ActionModel;
use super::workspace::Workspace;
use crate::error::{FfError, Result};

/// Roll `ws.us` out from `x0` into `ws.xs`, with costs in `ws.costs` and zero gaps. Returns the total cost.
pub fn rollout_nominal(model: &mut dyn ActionModel, ws: &mut Workspace, x0: &[f64]) -> Result<f64> {
    ws.xs[0].copy_from_slice(x0);
    let mut total = 0.0;
    for k in 0..ws.n {
        let c = model.calc(k, ws.xs[k].as_slice(), ws.us[k].as_slice(), ws.xnext.as_mut_slice())?;
        check_step(k, c, ws.xnext.as_slice(), "the rollout of the initial controls")?;
        ws.costs[k] = c;
        total += c;
        ws.xs[k + 1].copy_from(&ws.xnext);
    }
    let c = model.calc_terminal(ws.xs[ws.n].as_slice())?;
    check_step(ws.n, c, &[], "the rollout of the initial controls")?;
    ws.costs[ws.n] = c;
    for g in ws.gaps.iter_mut() {
        g.fill(0.0);
    }
    Ok(total + c)
}

/// Evaluate the nominal trajectory `ws.xs`, `ws.us` as it stands (possibly infeasible): costs and gaps,
/// with `f̄₀ = x0 ⊖ xs₀`. Returns the total cost.
pub fn evaluate_nominal(model: &mut dyn ActionModel, ws: &mut Workspace, x0: &[f64]) -> Result<f64> {
    model.difference(ws.xs[0].as_slice(), x0, ws.gaps[0].as_mut_slice());
    let mut total = 0.0;
    for k in 0..ws.n {
        let c = model.calc(k, ws.xs[k].as_slice(), ws.us[k].as_slice(), ws.xnext.as_mut_slice())?;
        check_step(k, c, ws.xnext.as_slice(), "the initial guess")?;
        ws.costs[k] = c;
        total += c;
        model.difference(ws.xs[k + 1].as_slice(), ws.xnext.as_slice(), ws.gaps[k + 1].as_mut_slice());
    }
    let c = model.calc_terminal(ws.xs[ws.n].as_slice())?;
    check_step(ws.n, c, &[], "the initial guess")?;
    ws.costs[ws.n] = c;
    Ok(total + c)
}

/// Trial rollout for step α into `ws.xs_try`, `ws.us_try`, `ws.costs_try`, `ws.gaps_try`.
/// Returns the total cost; an error if the rollout diverges (non-finite state or cost).
pub fn rollout_trial(model: &mut dyn ActionModel, ws: &mut Workspace, alpha: f64, gaps: bool) -> Result<f64> {
    let n = ws.n;
    let mut total = 0.0;
    if gaps {
        // x̂₀ = xs₀ ⊕ α f̄₀; the remaining gap is (1 − α) f̄₀.
        ws.dx.copy_from(&ws.gaps[0]);
        ws.dx *= alpha;
        model.integrate(ws.xs[0].as_slice(), ws.dx.as_slice(), ws.xs_try[0].as_mut_slice());
        ws.gaps_try[0].copy_from(&ws.gaps[0]);
        ws.gaps_try[0] *= 1.0 - alpha;
    } else {
        ws.xs_try[0].copy_from(&ws.xs[0]);
    }
    for k in 0..n {
        model.difference(ws.xs[k].as_slice(), ws.xs_try[k].as_slice(), ws.dx.as_mut_slice());
        let u = &mut ws.us_try[k];
        u.copy_from(&ws.us[k]);
        u.axpy(alpha, &ws.kff[k], 1.0);
        let nu = u.len();
        dense::gemv_n_add(u.as_mut_slice(), ws.kfb[k].as_slice(), ws.dx.as_slice(), nu, ws.ndx);
        let c = model.calc(k, ws.xs_try[k].as_slice(), ws.us_try[k].as_slice(), ws.xnext.as_mut_slice())?;
        check_step(k, c, ws.xnext.as_slice(), "the line-search rollout")?;
        ws.costs_try[k] = c;
        total += c;
        if gaps {
            ws.dx.copy_from(&ws.gaps[k + 1]);
            ws.dx *= alpha - 1.0;
            model.integrate(ws.xnext.as_slice(), ws.dx.as_slice(), ws.xs_try[k + 1].as_mut_slice());
            ws.gaps_try[k + 1].copy_from(&ws.gaps[k + 1]);
            ws.gaps_try[k + 1] *= 1.0 - alpha;
        } else {
            ws.xs_try[k + 1].copy_from(&ws.xnext);
        }
    }
    let c = model.calc_terminal(ws.xs_try[n].as_slice())?;
    check_step(n, c, &[], "the line-search rollout")?;
    ws.costs_try[n] = c;
    Ok(total + c)
}

fn check_step(k: usize, cost: f64, x: &[f64], what: &str) -> Result<()> {
    if !cost.is_finite() || x.iter().any(|v| !v.is_finite() || v.abs() > 1e12) {
        return Err(FfError::Numerical(format!("{what} diverged at node {k} (non-finite or huge state or cost)")));
    }
    Ok(())
}
