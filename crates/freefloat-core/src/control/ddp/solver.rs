//! The DDP driver (Valverde 2018, ch. 8, Algorithm 2, with the control update of §8.3): derivatives at
//! the nominal trajectory, Riccati backward pass with the regularisation schedule, line search with the
//! expected-improvement test (or the thesis' fixed α), stopping, progress callbacks. Two variants:
//! classical DDP / iLQG (the initial guess is a rollout of the initial controls) and the
//! feasibility-driven one (FDDP-style: an infeasible initial state trajectory is allowed, its gaps are
//! carried through the backward pass and closed by the line search).

use super::backward::{backward_pass, expected_change, Backward};
use super::forward::{evaluate_nominal, rollout_nominal, rollout_trial};
use super::problem::ActionModel;
use super::regularisation::{RegOptions, Regularisation};
use super::workspace::Workspace;
use crate::check::check_finite;
use crate::error::{FfError, Result};
use std::time::Instant;

/// Which DDP.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// Classical DDP/iLQG: the nominal is always a rollout (initial states are ignored).
    Ddp,
    /// Feasibility-driven DDP: the nominal may have gaps between nodes.
    Fddp,
}

/// Options of a solve.
#[derive(Clone, Debug, PartialEq)]
pub struct DdpOptions {
    /// DDP or feasibility-driven DDP.
    pub variant: Variant,
    /// Full DDP: add the second-order dynamics terms (needs `ActionModel::dynamics_hessian`); false = iLQG.
    pub second_order: bool,
    /// Maximum number of iterations (derivative evaluations).
    pub max_iter: usize,
    /// Step lengths tried in this order (backtracking); `[0.1]` is the thesis' fixed-α mode.
    pub alphas: Vec<f64>,
    /// Try every α and keep the one with the largest cost reduction (the thesis' "parallel" line
    /// search) instead of the first acceptable one.
    pub best_alpha: bool,
    /// Accept a step when (actual reduction) / (expected reduction) > this (Tassa: 0; Crocoddyl: 0.1).
    pub accept_ratio: f64,
    /// Regularisation schedule.
    pub reg: RegOptions,
    /// Stop when the expected improvement of a full step falls below this (absolute, cost units).
    pub tol_expected: f64,
    /// Stop when an accepted step changes the cost by less than this, relative (0: off).
    pub tol_cost: f64,
    /// Gaps below this (max norm) count as closed.
    pub tol_gap: f64,
}

impl Default for DdpOptions {
    fn default() -> Self {
        DdpOptions {
            variant: Variant::Fddp,
            second_order: false,
            max_iter: 100,
            // Tassa's default set, 10^linspace(0, −3, 11).
            alphas: (0..11).map(|i| 10f64.powf(-0.3 * i as f64)).collect(),
            best_alpha: false,
            accept_ratio: 0.0,
            reg: RegOptions::default(),
            tol_expected: 1e-9,
            tol_cost: 0.0,
            tol_gap: 1e-12,
        }
    }
}

impl DdpOptions {
    /// Check every option; the error names the bad one.
    pub fn validate(&self) -> Result<()> {
        if self.max_iter == 0 {
            return Err(FfError::arg("max_iter", "must be at least 1"));
        }
        if self.alphas.is_empty() || self.alphas.iter().any(|a| !(*a > 0.0) || *a > 1.0) {
            return Err(FfError::arg(
                "alphas",
                format!("need one or more step lengths in (0, 1], got {:?}", self.alphas),
            ));
        }
        if !self.accept_ratio.is_finite() || self.accept_ratio < 0.0 || self.accept_ratio >= 1.0 {
            return Err(FfError::arg("accept_ratio", format!("must be in [0, 1), got {}", self.accept_ratio)));
        }
        if !(self.tol_expected >= 0.0) || !(self.tol_cost >= 0.0) || !(self.tol_gap >= 0.0) {
            return Err(FfError::arg("tolerances", "tol_expected, tol_cost and tol_gap must be >= 0"));
        }
        self.reg.validate()
    }
}

/// Why a solve stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum StopReason {
    /// The expected improvement of a full step fell below `tol_expected` (converged).
    Converged,
    /// An accepted step changed the cost by less than `tol_cost` (relative).
    CostTolerance,
    /// `max_iter` iterations done.
    MaxIterations,
    /// λ went above its maximum: no descent step could be found.
    RegularisationLimit,
    /// The callback asked to stop (Ctrl-C).
    Interrupted,
    /// The model failed at the nominal trajectory (message); the last good iterate is returned.
    Failed(String),
}

impl StopReason {
    /// A short sentence for people.
    pub fn describe(&self) -> String {
        match self {
            StopReason::Converged => "converged (expected improvement below tolerance)".into(),
            StopReason::CostTolerance => "cost change below tolerance".into(),
            StopReason::MaxIterations => "maximum number of iterations reached".into(),
            StopReason::RegularisationLimit => {
                "regularisation above its maximum: no descent step found (best iterate kept)".into()
            }
            StopReason::Interrupted => "interrupted (best iterate kept)".into(),
            StopReason::Failed(m) => format!("stopped on a numerical failure, best iterate kept: {m}"),
        }
    }
}

/// One iteration, as reported to the callback and kept in the history.
#[derive(Clone, Debug, PartialEq)]
pub struct IterInfo {
    /// Iteration number, from 1.
    pub iter: usize,
    /// Cost of the nominal after the iteration.
    pub cost: f64,
    /// Step length taken (0 if the step was rejected).
    pub alpha: f64,
    /// λ used by the backward pass that produced the step.
    pub lambda: f64,
    /// Expected reduction of a full step, −(d1 + ½ d2).
    pub expected: f64,
    /// Actual reduction of the accepted step (0 if rejected).
    pub reduction: f64,
    /// Whether a step was accepted.
    pub accepted: bool,
    /// Largest gap after the iteration.
    pub gap: f64,
    /// Line-search rollouts in this iteration.
    pub rollouts: usize,
    /// Backward passes in this iteration (more than 1 when λ had to be raised).
    pub backward_passes: usize,
}

/// Result of a solve.
#[derive(Clone, Debug)]
pub struct Solution {
    /// States x₀..x_N of the returned (best) iterate.
    pub xs: Vec<Vec<f64>>,
    /// Controls u₀..u_{N−1}.
    pub us: Vec<Vec<f64>>,
    /// Feedback gains L_k (nu × ndx, row-major) of the last backward pass.
    pub gains: Vec<Vec<f64>>,
    /// Total cost of the returned iterate (at the weights of the last iteration).
    pub cost: f64,
    /// Cost of the initial guess.
    pub initial_cost: f64,
    /// Iterations done.
    pub iterations: usize,
    /// Why it stopped.
    pub stop: StopReason,
    /// Per-iteration history.
    pub history: Vec<IterInfo>,
    /// Largest gap of the returned iterate.
    pub gap: f64,
    /// Wall time spent in each block over the solve.
    pub timings: Timings,
}

/// Wall time (s) per block of a solve and how often each ran.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Derivatives of every node (dynamics and costs).
    pub calc_diff_s: f64,
    /// Derivative evaluations.
    pub calc_diff_calls: usize,
    /// Riccati backward passes (including the expected-change sweep).
    pub backward_s: f64,
    /// Backward passes.
    pub backward_calls: usize,
    /// Line-search rollouts (dynamics and costs along the trial).
    pub forward_s: f64,
    /// Rollouts.
    pub forward_calls: usize,
}

/// A DDP solver with its preallocated workspace for one problem size.
pub struct Solver {
    /// The per-node buffers.
    pub ws: Workspace,
    opts: DdpOptions,
}

impl Solver {
    /// A solver for `model`'s sizes with `opts` (checked).
    pub fn new(model: &dyn ActionModel, opts: DdpOptions) -> Result<Solver> {
        opts.validate()?;
        let n = model.horizon();
        if n == 0 {
            return Err(FfError::arg("horizon", "the horizon must have at least one node (N >= 1)"));
        }
        Ok(Solver { ws: Workspace::new(n, model.nx(), model.ndx(), model.nu()), opts })
    }

    /// The options.
    pub fn options(&self) -> &DdpOptions {
        &self.opts
    }

    /// Replace the options (checked), keeping the workspace: a receding-horizon controller gives its first,
    /// cold solve more iterations than the warm-started re-plans.
    pub fn set_options(&mut self, opts: DdpOptions) -> Result<()> {
        opts.validate()?;
        self.opts = opts;
        Ok(())
    }

    /// Feedback gains at the iterate `solve` returned (still in the workspace), for closed-loop use: the
    /// gains in `Solution::gains` come from the last backward pass, which ran at the nominal *before* the
    /// last accepted step. This runs the derivatives and one backward pass at the returned nominal, starting
    /// at `lambda` and raising it by the regularisation schedule until Q_uu + λI is positive definite.
    /// Returns the gains (N, each nu × ndx row-major) or None if no λ up to the maximum works (then the
    /// caller keeps `Solution::gains`).
    pub fn refresh_gains(&mut self, model: &mut dyn ActionModel, lambda: f64) -> Result<Option<Vec<Vec<f64>>>> {
        self.calc_diff(model)?;
        let gaps = self.opts.variant == Variant::Fddp && !self.ws.is_feasible(self.opts.tol_gap);
        let mut reg = Regularisation::new(RegOptions { init: lambda.max(0.0), ..self.opts.reg });
        loop {
            match backward_pass(model, &mut self.ws, reg.lambda, self.opts.second_order, gaps)? {
                Backward::Done => break,
                Backward::NotPositiveDefinite(_) => {
                    if !reg.increase() {
                        return Ok(None);
                    }
                }
            }
        }
        Ok(Some(self.ws.kfb.iter().map(|k| k.transpose().as_slice().to_vec()).collect()))
    }

    /// Solve from `x0` with the initial controls `us0` (N × nu, flat) and, for the feasibility-driven
    /// variant, optionally an initial state trajectory `xs0` ((N + 1) × nx, flat; default: the rollout).
    /// `callback` sees every iteration and returns false to stop (the best iterate is kept).
    pub fn solve(
        &mut self,
        model: &mut dyn ActionModel,
        x0: &[f64],
        us0: &[f64],
        xs0: Option<&[f64]>,
        callback: &mut dyn FnMut(&IterInfo) -> bool,
    ) -> Result<Solution> {
        let (n, nx, nu) = (self.ws.n, self.ws.nx, self.ws.nu);
        if model.horizon() != n || model.nx() != nx || model.nu() != nu || model.ndx() != self.ws.ndx {
            return Err(FfError::arg("model", "the action model's sizes differ from those the solver was made for"));
        }
        crate::check::check_vec("x0", x0, nx)?;
        crate::check::check_vec("us0", us0, n * nu)?;
        for k in 0..n {
            self.ws.us[k].copy_from_slice(&us0[k * nu..(k + 1) * nu]);
        }
        let opts = self.opts.clone();
        let use_gaps = opts.variant == Variant::Fddp;
        model.set_iteration(1);
        let mut cost = match (xs0, use_gaps) {
            (Some(xs), true) => {
                crate::check::check_vec("xs0", xs, (n + 1) * nx)?;
                check_finite("xs0", xs)?;
                for k in 0..=n {
                    self.ws.xs[k].copy_from_slice(&xs[k * nx..(k + 1) * nx]);
                }
                evaluate_nominal(model, &mut self.ws, x0)?
            }
            _ => rollout_nominal(model, &mut self.ws, x0)?,
        };
        let initial_cost = cost;
        let mut reg = Regularisation::new(opts.reg);
        // Reserved up front so that iterations allocate nothing.
        let mut history = Vec::with_capacity(opts.max_iter);
        let mut need_diff = true;
        let mut stop = StopReason::MaxIterations;
        let mut iterations = 0;
        let mut tm = Timings::default();
        let schedule_end = model.schedule_end();
        for iter in 1..=opts.max_iter {
            iterations = iter;
            if iter > 1 && model.set_iteration(iter) {
                // The weights changed: compare candidates against the nominal at this iteration's weights.
                cost = match evaluate_nominal(model, &mut self.ws, x0) {
                    Ok(c) => c,
                    Err(e) => {
                        stop = StopReason::Failed(e.to_string());
                        break;
                    }
                };
                need_diff = true;
            }
            let feasible = !use_gaps || self.ws.is_feasible(opts.tol_gap);
            if need_diff {
                let t0 = Instant::now();
                let r = self.calc_diff(model);
                tm.calc_diff_s += t0.elapsed().as_secs_f64();
                tm.calc_diff_calls += 1;
                if let Err(e) = r {
                    stop = StopReason::Failed(e.to_string());
                    break;
                }
            }
            // Backward pass, raising λ until Q_uu + λI is positive definite at every node.
            let mut passes = 0;
            let lambda_used;
            let t0 = Instant::now();
            loop {
                passes += 1;
                tm.backward_calls += 1;
                match backward_pass(model, &mut self.ws, reg.lambda, opts.second_order, use_gaps && !feasible) {
                    Ok(Backward::Done) => {
                        lambda_used = reg.lambda;
                        break;
                    }
                    Ok(Backward::NotPositiveDefinite(_)) => {
                        if !reg.increase() {
                            lambda_used = f64::NAN;
                            break;
                        }
                    }
                    Err(e @ FfError::Argument { .. }) => return Err(e),
                    Err(e) => {
                        stop = StopReason::Failed(e.to_string());
                        lambda_used = f64::NAN;
                        break;
                    }
                }
            }
            if lambda_used.is_nan() {
                if !matches!(stop, StopReason::Failed(_)) {
                    stop = StopReason::RegularisationLimit;
                }
                break;
            }
            let (d1, d2) = expected_change(&mut self.ws, use_gaps && !feasible, opts.second_order);
            tm.backward_s += t0.elapsed().as_secs_f64();
            let expected_full = -(d1 + 0.5 * d2);
            if feasible && expected_full.abs() < opts.tol_expected {
                let info = IterInfo {
                    iter,
                    cost,
                    alpha: 0.0,
                    lambda: lambda_used,
                    expected: expected_full,
                    reduction: 0.0,
                    accepted: false,
                    gap: self.ws.gap_norm(),
                    rollouts: 0,
                    backward_passes: passes,
                };
                history.push(info.clone());
                if iter < schedule_end {
                    // Converged at this iteration's weights, but the schedule will still change them: go on
                    // (the next iteration re-evaluates the nominal at the new weights).
                    if !callback(&info) {
                        stop = StopReason::Interrupted;
                        break;
                    }
                    need_diff = false;
                    continue;
                }
                callback(&info);
                stop = StopReason::Converged;
                break;
            }
            // Line search.
            let mut best: Option<(f64, f64)> = None; // (alpha, cost)
            let mut rollouts = 0;
            for &alpha in &opts.alphas {
                rollouts += 1;
                let t0 = Instant::now();
                let trial = rollout_trial(model, &mut self.ws, alpha, use_gaps && !feasible);
                tm.forward_s += t0.elapsed().as_secs_f64();
                tm.forward_calls += 1;
                let Ok(c) = trial else {
                    continue; // diverged: a rejected trial
                };
                let expected = -(alpha * d1 + 0.5 * alpha * alpha * d2);
                let actual = cost - c;
                let ok = if feasible { expected > 0.0 && actual / expected > opts.accept_ratio } else { true };
                if !ok {
                    continue;
                }
                if opts.best_alpha {
                    if best.map(|(_, bc)| c < bc).unwrap_or(true) {
                        best = Some((alpha, c));
                    }
                } else {
                    best = Some((alpha, c));
                    break;
                }
            }
            if let Some((alpha, c)) = best {
                if opts.best_alpha {
                    // Re-run the best trial so the trial buffers hold it.
                    rollouts += 1;
                    if rollout_trial(model, &mut self.ws, alpha, use_gaps && !feasible).is_err() {
                        stop = StopReason::Failed("the accepted rollout could not be reproduced".into());
                        break;
                    }
                }
                let ws = &mut self.ws;
                std::mem::swap(&mut ws.xs, &mut ws.xs_try);
                std::mem::swap(&mut ws.us, &mut ws.us_try);
                std::mem::swap(&mut ws.costs, &mut ws.costs_try);
                std::mem::swap(&mut ws.gaps, &mut ws.gaps_try);
                if !use_gaps || feasible {
                    for g in ws.gaps.iter_mut() {
                        g.fill(0.0);
                    }
                }
                let reduction = cost - c;
                let rel = reduction.abs() / cost.abs().max(1e-300);
                cost = c;
                reg.decrease();
                need_diff = true;
                let info = IterInfo {
                    iter,
                    cost,
                    alpha,
                    lambda: lambda_used,
                    expected: expected_full,
                    reduction,
                    accepted: true,
                    gap: self.ws.gap_norm(),
                    rollouts,
                    backward_passes: passes,
                };
                history.push(info.clone());
                if !callback(&info) {
                    stop = StopReason::Interrupted;
                    break;
                }
                if feasible && opts.tol_cost > 0.0 && rel < opts.tol_cost {
                    stop = StopReason::CostTolerance;
                    break;
                }
            } else {
                need_diff = false;
                let info = IterInfo {
                    iter,
                    cost,
                    alpha: 0.0,
                    lambda: lambda_used,
                    expected: expected_full,
                    reduction: 0.0,
                    accepted: false,
                    gap: self.ws.gap_norm(),
                    rollouts,
                    backward_passes: passes,
                };
                history.push(info.clone());
                if !callback(&info) {
                    stop = StopReason::Interrupted;
                    break;
                }
                if !reg.increase() {
                    stop = StopReason::RegularisationLimit;
                    break;
                }
            }
        }
        let ws = &self.ws;
        Ok(Solution {
            xs: ws.xs.iter().map(|x| x.as_slice().to_vec()).collect(),
            us: ws.us.iter().map(|u| u.as_slice().to_vec()).collect(),
            gains: ws.kfb.iter().map(|k| k.transpose().as_slice().to_vec()).collect(),
            cost,
            initial_cost,
            iterations,
            stop,
            history,
            gap: ws.gap_norm(),
            timings: tm,
        })
    }

    /// Derivatives of every node at the nominal trajectory.
    fn calc_diff(&mut self, model: &mut dyn ActionModel) -> Result<()> {
        let ws = &mut self.ws;
        for k in 0..ws.n {
            model.calc_diff(k, ws.xs[k].as_slice(), ws.us[k].as_slice(), &mut ws.diffs[k])?;
        }
        model.calc_diff_terminal(ws.xs[ws.n].as_slice(), &mut ws.diffs[ws.n])
    }
}
