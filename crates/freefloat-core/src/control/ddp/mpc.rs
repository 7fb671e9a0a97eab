//! Closed-loop use of DDP: the time-varying feedback policy an optimised trajectory defines, and a
//! receding-horizon (model-predictive) controller that re-solves a window of the task from the measured
//! state, warm-started from its previous solution shifted in time.
//!
//! The policy is the control update of the line search (Valverde 2018, eq. (8.45)) with α = 1 at the
//! converged nominal, applied to the *measured* state: `u_k = ū_k + L_k (x ⊖ x̄_k)`, the state error taken in
//! the tangent space of the state manifold (`ActionModel::difference`), as the backward pass linearised it.
//! With `L_k = 0` it is the open-loop feed-forward, which the tests and the CLI compare against.

use super::problem::ActionModel;
use super::robot::FloatingRobot;
use super::solver::{DdpOptions, Solution, Solver, StopReason};
use crate::check::{check_finite, check_vec};
use crate::error::{FfError, Result};
use std::time::Instant;

/// An initial guess over a whole task: states (N + 1) and controls (N).
pub type Guess = (Vec<Vec<f64>>, Vec<Vec<f64>>);

/// A time-varying affine feedback policy `u_k = ū_k + L_k (x ⊖ x̄_k)` over N nodes.
#[derive(Clone, Debug)]
pub struct Policy {
    xs: Vec<Vec<f64>>,
    us: Vec<Vec<f64>>,
    gains: Vec<Vec<f64>>,
    nx: usize,
    ndx: usize,
    nu: usize,
    dx: Vec<f64>,
}

impl Policy {
    /// A policy from nominal states `xs` (N + 1 or N, nx each), controls `us` (N, nu) and gains (N, nu × ndx
    /// row-major), all checked (sizes, finite).
    pub fn new(
        xs: Vec<Vec<f64>>,
        us: Vec<Vec<f64>>,
        gains: Vec<Vec<f64>>,
        nx: usize,
        ndx: usize,
        nu: usize,
    ) -> Result<Policy> {
        let n = us.len();
        if n == 0 {
            return Err(FfError::arg("us", "the policy needs at least one node"));
        }
        if xs.len() < n {
            return Err(FfError::arg(
                "xs",
                format!("need at least {n} nominal states (one per control), got {}", xs.len()),
            ));
        }
        if gains.len() != n {
            return Err(FfError::arg("gains", format!("need one gain matrix per control ({n}), got {}", gains.len())));
        }
        for (k, x) in xs.iter().enumerate() {
            check_vec(&format!("xs[{k}]"), x, nx)?;
            check_finite(&format!("xs[{k}]"), x)?;
        }
        for k in 0..n {
            check_vec(&format!("us[{k}]"), &us[k], nu)?;
            check_finite(&format!("us[{k}]"), &us[k])?;
            check_vec(&format!("gains[{k}]"), &gains[k], nu * ndx)?;
            check_finite(&format!("gains[{k}]"), &gains[k])?;
        }
        Ok(Policy { xs, us, gains, nx, ndx, nu, dx: vec![0.0; ndx] })
    }

    /// The policy of a solution (its states, controls and gains).
    pub fn from_solution(sol: &Solution, model: &dyn ActionModel) -> Result<Policy> {
        Policy::new(sol.xs.clone(), sol.us.clone(), sol.gains.clone(), model.nx(), model.ndx(), model.nu())
    }

    /// Number of nodes N.
    pub fn len(&self) -> usize {
        self.us.len()
    }

    /// Whether the policy has no nodes (never: `new` refuses that).
    pub fn is_empty(&self) -> bool {
        self.us.is_empty()
    }

    /// Replace the gains (e.g. by `Solver::refresh_gains`).
    pub fn set_gains(&mut self, gains: Vec<Vec<f64>>) -> Result<()> {
        if gains.len() != self.len() || gains.iter().any(|g| g.len() != self.nu * self.ndx) {
            return Err(FfError::arg("gains", "need one nu × ndx gain matrix per node"));
        }
        self.gains = gains;
        Ok(())
    }

    /// `out = ū_k + L_k (x ⊖ x̄_k)` (`feedback = false`: `ū_k` only). Nodes past the end use the last one.
    /// Valverde 2018, eq. (8.45) with α = 1, on the measured state. `model` supplies `⊖` (its sizes must
    /// match). Does not allocate.
    pub fn control(
        &mut self,
        model: &dyn ActionModel,
        k: usize,
        x: &[f64],
        feedback: bool,
        out: &mut [f64],
    ) -> Result<()> {
        if model.nx() != self.nx || model.ndx() != self.ndx || model.nu() != self.nu {
            return Err(FfError::arg("model", "the model's sizes differ from the policy's"));
        }
        check_vec("x", x, self.nx)?;
        check_vec("out", out, self.nu)?;
        if x.iter().any(|v| !v.is_finite()) {
            return Err(FfError::Numerical(format!("the measured state at node {k} is not finite")));
        }
        let k = k.min(self.len() - 1);
        out.copy_from_slice(&self.us[k]);
        if feedback {
            model.difference(&self.xs[k], x, &mut self.dx);
            let g = &self.gains[k];
            for (i, o) in out.iter_mut().enumerate() {
                let row = &g[i * self.ndx..(i + 1) * self.ndx];
                *o += row.iter().zip(&self.dx).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        Ok(())
    }
}

/// Options of the receding-horizon controller.
#[derive(Clone, Debug, PartialEq)]
pub struct MpcOptions {
    /// Nodes in each re-planned window (H ≥ 1).
    pub horizon: usize,
    /// Re-plan every this many nodes (1 ≤ K ≤ H); between re-plans the window's feedback policy runs.
    pub replan: usize,
    /// Solver options of the warm-started re-plans (`max_iter` is the per-re-plan iteration budget).
    pub solver: DdpOptions,
    /// Iterations of the first (cold, or guess-started) solve.
    pub first_max_iter: usize,
    /// Shrinking horizon: a window never reaches past the task's last node (its terminal cost lands on the
    /// task's end, a deadline, instead of H nodes ahead of every re-plan). Off: every window has H nodes, and
    /// past the end the last reference holds (a tracking task that goes on).
    pub shrink: bool,
}

impl MpcOptions {
    /// Check the options; the error names the bad one.
    pub fn validate(&self) -> Result<()> {
        if self.horizon == 0 {
            return Err(FfError::arg("horizon", "the receding horizon must have at least one node (>= 1)"));
        }
        if self.replan == 0 || self.replan > self.horizon {
            return Err(FfError::arg(
                "replan",
                format!("the re-plan period must be between 1 and the horizon ({}), got {}", self.horizon, self.replan),
            ));
        }
        if self.first_max_iter == 0 {
            return Err(FfError::arg("first_max_iter", "must be at least 1"));
        }
        self.solver.validate()
    }
}

/// What the controller did so far.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MpcStats {
    /// Re-plans (solves).
    pub replans: usize,
    /// DDP iterations over all re-plans.
    pub iterations: usize,
    /// Wall time of all solves (s).
    pub solve_time_s: f64,
    /// Slowest single re-plan (s), the first excluded when there was more than one.
    pub max_replan_s: f64,
    /// Re-plans that stopped on a numerical failure or the regularisation limit (their best iterate was used).
    pub troubled: usize,
    /// Why the last re-plan stopped.
    pub last_stop: String,
    /// Cost of each re-plan's solution.
    pub costs: Vec<f64>,
    /// Wall time of each re-plan (s), the first included (it may run more iterations: `first_max_iter`), so
    /// that a caller can take medians and percentiles, not only the total and the maximum.
    pub times: Vec<f64>,
    /// Iterations of each re-plan.
    pub replan_iterations: Vec<usize>,
    /// Times the model's inertial parameters were replaced (`Mpc::set_parameters`).
    pub model_updates: usize,
}

/// A receding-horizon DDP controller over a task (a `FloatingRobot` problem of N nodes): at node k it solves
/// the window k..k + H from the measured state, warm-started with the previous window's solution shifted by
/// the nodes elapsed (the last node repeated), and applies that window's feedback policy until the next re-plan.
pub struct Mpc {
    window: FloatingRobot,
    solver: Solver,
    /// Nodes of the task (the deadline of a shrinking horizon).
    task_n: usize,
    /// The shorter window of a shrinking horizon near the task's end, and its solver (rebuilt when its
    /// length changes).
    tail: Option<(FloatingRobot, Solver)>,
    opts: MpcOptions,
    guess: Option<Guess>,
    plan: Option<(usize, Policy)>,
    warm_us: Vec<f64>,
    warm_xs: Vec<f64>,
    /// Running statistics.
    pub stats: MpcStats,
}

impl Mpc {
    /// A controller for `task` (its costs and reference tables; scheduled weights frozen at End). `guess`:
    /// optional states (N + 1) and controls (N) over the whole task (e.g. an offline solve) that start the
    /// first window; without it the first window starts from zero controls.
    pub fn new(task: &FloatingRobot, opts: MpcOptions, guess: Option<Guess>) -> Result<Mpc> {
        opts.validate()?;
        let window = task.window(opts.horizon)?;
        let (nx, nu) = (window.nx(), window.nu());
        if let Some((xs, us)) = &guess {
            if us.is_empty() || xs.len() != us.len() + 1 {
                return Err(FfError::arg("guess", "need N + 1 states and N >= 1 controls"));
            }
            for (k, x) in xs.iter().enumerate() {
                check_vec(&format!("guess.xs[{k}]"), x, nx)?;
                check_finite(&format!("guess.xs[{k}]"), x)?;
            }
            for (k, u) in us.iter().enumerate() {
                check_vec(&format!("guess.us[{k}]"), u, nu)?;
                check_finite(&format!("guess.us[{k}]"), u)?;
            }
        }
        let solver = Solver::new(&window, opts.solver.clone())?;
        let h = opts.horizon;
        Ok(Mpc {
            task_n: task.horizon(),
            tail: None,
            window,
            solver,
            guess,
            plan: None,
            warm_us: vec![0.0; h * nu],
            warm_xs: vec![0.0; (h + 1) * nx],
            stats: MpcStats::default(),
            opts,
        })
    }

    /// The model the windows are optimised on.
    pub fn model(&self) -> &crate::model::Model {
        self.window.model()
    }

    /// The options.
    pub fn options(&self) -> &MpcOptions {
        &self.opts
    }

    /// Replace the model's inertial parameters (one row of 10 standard parameters per body of the window's
    /// model): the next re-plan optimises on them; until then the current window's policy runs (its gains
    /// belong to the parameters it was planned on). The warm start is kept: the previous plan is still the best
    /// guess of the new optimum when the estimate moves a little.
    pub fn set_parameters(&mut self, params: &[f64]) -> Result<()> {
        self.window.set_parameters(params)?;
        if let Some((w, _)) = &mut self.tail {
            w.set_parameters(params)?;
        }
        self.stats.model_updates += 1;
        Ok(())
    }

    /// Control at task node `k` for the measured state `x` (re-planning first when K nodes have passed since
    /// the last plan, or on the first call, or when `k` went backwards).
    pub fn control(&mut self, k: usize, x: &[f64], out: &mut [f64]) -> Result<()> {
        check_vec("x", x, self.window.nx())?;
        if x.iter().any(|v| !v.is_finite()) {
            return Err(FfError::Numerical(format!("the measured state at node {k} is not finite")));
        }
        let due = match &self.plan {
            None => true,
            Some((start, _)) => k < *start || k - *start >= self.opts.replan,
        };
        if due {
            self.replan(k, x)?;
        }
        let (start, policy) = self.plan.as_mut().expect("a plan exists after replan");
        policy.control(&self.window, k - *start, x, true, out)
    }

    /// Solve the window starting at task node `k` from state `x`.
    fn replan(&mut self, k: usize, x: &[f64]) -> Result<()> {
        let (nx, nu) = (self.window.nx(), self.window.nu());
        let h = if self.opts.shrink {
            self.opts.horizon.min(self.task_n.saturating_sub(k).max(1))
        } else {
            self.opts.horizon
        };
        let first = self.plan.is_none();
        let (warm_us, warm_xs) = (&mut self.warm_us[..h * nu], &mut self.warm_xs[..(h + 1) * nx]);
        match (&self.plan, &self.guess) {
            (Some((start, p)), _) if k >= *start => {
                // Shift the previous window by the nodes elapsed; its last node repeats.
                let d = k - start;
                for i in 0..h {
                    let j = (i + d).min(p.us.len() - 1);
                    warm_us[i * nu..(i + 1) * nu].copy_from_slice(&p.us[j]);
                }
                for i in 0..=h {
                    let j = (i + d).min(p.xs.len() - 1);
                    warm_xs[i * nx..(i + 1) * nx].copy_from_slice(&p.xs[j]);
                }
            }
            (_, Some((gx, gu))) => {
                for i in 0..h {
                    let j = (k + i).min(gu.len() - 1);
                    warm_us[i * nu..(i + 1) * nu].copy_from_slice(&gu[j]);
                }
                for i in 0..=h {
                    let j = (k + i).min(gx.len() - 1);
                    warm_xs[i * nx..(i + 1) * nx].copy_from_slice(&gx[j]);
                }
            }
            _ => {
                warm_us.fill(0.0);
                for i in 0..=h {
                    warm_xs[i * nx..(i + 1) * nx].copy_from_slice(x);
                }
            }
        }
        let cold = first && self.guess.is_none();
        // The window starts at the measured state; the rest of the shifted guess keeps its gaps, which the
        // feasibility-driven line search closes (a cold start is a plain rollout of zero controls).
        warm_xs[..nx].copy_from_slice(x);
        let mut o = self.opts.solver.clone();
        if first {
            o.max_iter = self.opts.first_max_iter;
        }
        // A shrunk window near the task's end (made once per length: the tail's re-plans are few)
        if h != self.opts.horizon && self.tail.as_ref().is_none_or(|(w, _)| w.horizon() != h) {
            let w = self.window.window(h)?;
            let s = Solver::new(&w, o.clone())?;
            self.tail = Some((w, s));
        }
        let (window, solver) = match &mut self.tail {
            Some((w, s)) if h != self.opts.horizon => (w, s),
            _ => (&mut self.window, &mut self.solver),
        };
        solver.set_options(o)?;
        window.set_offset(k);
        let t0 = Instant::now();
        let xs0 = if cold { None } else { Some(&warm_xs[..]) };
        let sol = solver.solve(window, x, warm_us, xs0, &mut |_| true)?;
        let lambda = sol.history.last().map(|i| i.lambda).filter(|l| l.is_finite()).unwrap_or(0.0);
        let mut policy = Policy::from_solution(&sol, window)?;
        if let Some(g) = solver.refresh_gains(window, lambda)? {
            policy.set_gains(g)?;
        }
        let dt = t0.elapsed().as_secs_f64();
        let s = &mut self.stats;
        s.replans += 1;
        s.iterations += sol.iterations;
        s.solve_time_s += dt;
        if !first {
            s.max_replan_s = s.max_replan_s.max(dt);
        }
        if matches!(sol.stop, StopReason::Failed(_) | StopReason::RegularisationLimit) {
            s.troubled += 1;
        }
        s.last_stop = sol.stop.describe();
        s.costs.push(sol.cost);
        s.times.push(dt);
        s.replan_iterations.push(sol.iterations);
        self.plan = Some((k, policy));
        Ok(())
    }
}
