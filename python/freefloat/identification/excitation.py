"""Exciting-trajectory design for minimal-parameter identification (Naveen, Shah, Misra, Sec. V and VI.B).

Three steps (the paper's Fig. 2), from nothing but the geometry and a rough guess of the inertias:

1. Every direction combination of the driven joints (2^(n-1), one 1-s cycloidal interval each) with 2 seeds per arm
   joint (start θ_s and range θ_d, eqs. 30-31); SQP over the seeds minimises eq. 32,
   C = κ(G_m) + w·N_l N_m / Σ h², subject to the linear joint-limit constraints of eqs. 33-37.
2. Pruning (Algorithm 1): intervals are kept in order while they add significant singular values or lower the
   condition number, with up to u_max "free" acceptances in a row.  As printed the algorithm never updates its
   reference rank and condition number; here both are updated on every acceptance.
3. The seeds are re-optimised on the surviving combinations only.

The base response the objective needs comes from the momentum model of the *guessed* robot, in Rust
(`freefloat_core::excitation`), as does the objective itself; Python drives scipy's SLSQP, with finite-difference
gradients whose 2n+1 evaluations go to Rust in one call (worker threads).  The reaction wheels follow
Naveen, Shah, Misra's
predetermined seeds (start 0, range 3π per interval) and are not design variables.

Choices the paper leaves open, all arguments here:
- the last wheel keeps its direction, and the combinations are ordered so the first arm joint alternates fastest
  (`direction_combinations(..., fastest="first")`): the accumulated travel of arm joint j stays within 2^(j-1)
  ranges, so position limits do not force tiny ranges on every joint;
- limits (`Limits.naveen`): ±270° positions; 1.6π rad/s and 1.6π² rad/s² for rates and accelerations, so
  eqs. 34-36 cap the range at 0.8π = 2.513 rad, the largest value in Table 3;
- the signal term Σh² covers the base twist and the *arm* joint rates: the wheels follow fixed seeds, and their
  fast spin (up to 6π rad/s) would otherwise swamp it, leaving the ranges free to shrink — which costs accuracy
  under a fixed rate noise even when κ is good;
- w = 1000 rad²/s²: comparable to κ when the arm moves slowly, about κ/2 at full ranges;
- 10 grid points per interval for the base response (trapezoidal rule on the group) and 5 regressor samples per
  interval (at τ = 0.1, 0.3, ..., 0.9 s);
- SLSQP on log C (the same minimiser, better scaled: κ spans 1e2 to 1e18)."""

from __future__ import annotations

import numpy as np

from .. import _core
from .._core import InputError, Interrupted, NumericalError
from ..constants import DELTA, PAPER_KAPPA, PAPER_KEPT, PAPER_RATE_NOISE, U_MAX, WHEEL_RANGE, WHEEL_START
from ..io.trajectory_files import load_trajectory, save_trajectory
from ..trajectories import Cycloidal, Fourier, direction_combinations
from .comparison import compare, comparison_table
from .estimation import absolute_columns
from .excitation_results import DesignResult, Limits, PartialDesign, StepResult
from .minimal import minimal_parameters
from .pruning import MIN_GAIN, PruneResult, plot_fig4, prune_intervals, significant

__all__ = [
    "PAPER_KAPPA",
    "PAPER_KEPT",
    "DELTA",
    "KAPPA_UNEXCITED",
    "MIN_GAIN",
    "PAPER_RATE_NOISE",
    "U_MAX",
    "WEIGHT",
    "DesignResult",
    "ExcitationDesign",
    "PartialDesign",
    "Limits",
    "PruneResult",
    "StepResult",
    "compare",
    "comparison_table",
    "load_trajectory",
    "plot_fig4",
    "prune_intervals",
    "save_trajectory",
    "significant",
]

#: Algorithm 1 settings (U_MAX, DELTA: the paper's Sec. VI.B) and our MIN_GAIN are in `pruning`.
#: eq. 32 weight (our choice; the paper gives none)
WEIGHT = 1000.0
#: a condition number above this means some parameter combination is not excited (the Gram matrix the objective
#: uses cannot resolve singular values below ~1e-8 of the largest)
KAPPA_UNEXCITED = 1e8


class ExcitationDesign:
    """The design problem for a robot with guessed parameters `guess` (a Model).

    arm: driven joints with design seeds (default: joints tagged arm_*); wheels: joints following the
    predetermined wheel seeds (default: tagged wheel).  grid: points per interval for the base response;
    samples: regressor samples per interval (grid must be a multiple)."""

    def __init__(
        self,
        guess,
        arm=None,
        wheels=None,
        limits: Limits | None = None,
        interval: float = 1.0,
        grid: int = 10,
        samples: int = 5,
        weight: float = WEIGHT,
        threads: int = 2,
    ):
        self.guess = guess
        self.arm = guess.joints_tagged("arm_") if arm is None else list(arm)
        self.wheels = guess.joints_tagged("wheel") if wheels is None else list(wheels)
        self.joints = self.arm + self.wheels
        if not self.arm:
            raise InputError("ExcitationDesign: no arm joints to design (tag them arm_* or pass arm=[...])")
        for j in self.joints:
            if j not in guess.joint_names or guess.nvs[guess.joint_names.index(j)] != 1:
                raise InputError(f"ExcitationDesign: '{j}' is not a 1-DoF joint of '{guess.name}'")
        self.n_arm = len(self.arm)
        self.limits = Limits.naveen(self.n_arm) if limits is None else limits
        self.limits.check(self.n_arm)
        if grid % samples != 0 or samples < 1:
            raise InputError(f"ExcitationDesign: grid ({grid}) must be a multiple of samples ({samples})")
        self.interval, self.grid, self.samples, self.weight, self.threads = (
            float(interval),
            grid,
            samples,
            float(weight),
            threads,
        )
        self.stride = grid // samples
        self.offset = self.stride // 2
        _check_physical(guess)
        try:
            self.mp = minimal_parameters(guess, "closed-form")
        except Exception:  # outside the closed form's scope: the numeric method covers any tree
            self.mp = minimal_parameters(guess, "numeric")
        self.n_min = self.mp.n_min
        self.columns = absolute_columns(self.mp).tolist()
        self.iq = [guess.idx_q[guess.joint_names.index(j)] for j in self.joints]
        self.iv = [guess.idx_v[guess.joint_names.index(j)] for j in self.joints]
        self.q0 = guess.neutral().tolist()
        self.all_directions = direction_combinations(len(self.joints), fixed=len(self.joints) - 1, fastest="first")

    @property
    def n_intervals(self) -> int:
        return len(self.all_directions)

    # -- trajectories ---------------------------------------------------------------------------------
    def cycloid(self, x, directions) -> Cycloidal:
        """Multi-interval cycloid of eqs. 28-31 for arm seeds x = [θ_s; θ_d] and the wheels' fixed seeds."""
        n = self.n_arm
        nw = len(self.wheels)
        start = np.concatenate([x[:n], np.full(nw, WHEEL_START)])
        range_ = np.concatenate([x[n:], np.full(nw, WHEEL_RANGE)])
        return Cycloidal(start, range_, directions, interval=self.interval)

    def _grid(self, n_intervals: int) -> np.ndarray:
        return np.arange(n_intervals * self.grid + 1) * (self.interval / self.grid)

    def evaluate(self, X, directions=None) -> dict:
        """Eq. 32 for one seed vector (2n,) or a batch (B, 2n): dict of objective, condition_number,
        mean_square, singular_values."""
        dirs = self.all_directions if directions is None else np.asarray(directions)
        X = np.atleast_2d(np.asarray(X, dtype=float))
        t = self._grid(len(dirs))
        Q, QD = [], []
        for x in X:
            q, qd, _ = self.cycloid(x, dirs).evaluate(t)
            Q.append(q)
            QD.append(qd)
        return self._objective(np.array(Q), np.array(QD))

    def _objective(self, Q, QD) -> dict:
        return _core.excitation_objective(
            self.guess,
            self.q0,
            self.iq,
            self.iv,
            self.interval / self.grid,
            Q,
            QD,
            self.stride,
            self.offset,
            self.columns,
            self.weight,
            self.n_arm,
            self.threads,
        )

    def rows(self, x, directions=None) -> np.ndarray:
        """Minimal-regressor rows along the trajectory, (intervals, 6·samples, n_min)."""
        dirs = self.all_directions if directions is None else np.asarray(directions)
        q, qd, _ = self.cycloid(x, dirs).evaluate(self._grid(len(dirs)))
        r = _core.excitation_rows(
            self.guess,
            self.q0,
            self.iq,
            self.iv,
            self.interval / self.grid,
            q,
            qd,
            self.stride,
            self.offset,
            self.columns,
            self.n_arm,
        )["rows"]
        return r.reshape(len(dirs), 6 * self.samples, self.n_min)

    # -- constraints (eqs. 33-37) -----------------------------------------------------------------------
    def linear_constraints(self, directions) -> tuple[np.ndarray, np.ndarray]:
        """(A, b) with A x >= b: every interval boundary of every arm joint within its position limits (eq. 33).
        Boundaries are θ_s + c θ_d with c the running sum of directions, so only its extremes matter."""
        n = self.n_arm
        c = np.vstack([np.zeros(n), np.cumsum(np.asarray(directions)[:, :n], axis=0)])
        cmax, cmin = c.max(0), c.min(0)
        A, b = [], []
        for j in range(n):
            up = np.zeros(2 * n)
            up[j], up[n + j] = -1.0, -cmax[j]  # q_max − θ_s − cmax θ_d >= 0
            A.append(up)
            b.append(-self.limits.q_max[j])
            lo = np.zeros(2 * n)
            lo[j], lo[n + j] = 1.0, cmin[j]  # θ_s + cmin θ_d − q_min >= 0
            A.append(lo)
            b.append(self.limits.q_min[j])
        return np.array(A), np.array(b)

    def bounds(self) -> list:
        """θ_s within the position limits; 0 < θ_d <= θ_d^max (eqs. 36-37)."""
        rmax = self.limits.range_max(self.interval)
        return [(lo, hi) for lo, hi in zip(self.limits.q_min, self.limits.q_max)] + [(1e-3 * r, r) for r in rmax]

    def feasible_start(self, directions, x0=None) -> np.ndarray:
        """A feasible seed vector: x0 (default mid-range start, half the maximal range) with the ranges scaled down
        until every boundary is within the limits."""
        n = self.n_arm
        lo, hi = self.limits.q_min, self.limits.q_max
        rmax = self.limits.range_max(self.interval)
        x = np.concatenate([0.5 * (lo + hi), 0.5 * rmax]) if x0 is None else np.array(x0, dtype=float)
        x[:n] = np.clip(x[:n], lo, hi)
        x[n:] = np.clip(x[n:], 1e-3 * rmax, rmax)
        c = np.vstack([np.zeros(n), np.cumsum(np.asarray(directions)[:, :n], axis=0)])
        cmax, cmin = c.max(0), c.min(0)
        for j in range(n):
            span = (cmax[j] - cmin[j]) * x[n + j]
            if span > hi[j] - lo[j]:
                x[n + j] = 0.999 * (hi[j] - lo[j]) / (cmax[j] - cmin[j])
                span = (cmax[j] - cmin[j]) * x[n + j]
            # shift the start so [θ_s + cmin θ_d, θ_s + cmax θ_d] fits
            x[j] = np.clip(x[j], lo[j] - cmin[j] * x[n + j], hi[j] - cmax[j] * x[n + j])
        return x

    # -- the three steps ----------------------------------------------------------------------------------
    def optimize(self, directions, x0=None, maxiter: int = 100, progress=None, best: _Best | None = None) -> StepResult:
        """SLSQP over the 2n seeds on log C with forward-difference gradients (one batched Rust call each).
        best: a `_Best` that keeps the best feasible point evaluated so far (what a Ctrl-C keeps)."""
        dirs = np.asarray(directions)
        x0 = self.feasible_start(dirs, x0)
        A, b = self.linear_constraints(dirs)
        res, count = _slsqp(lambda X: self.evaluate(X, dirs), x0, A, b, self.bounds(), maxiter, progress, best)
        x = np.asarray(res.x, dtype=float)
        # SLSQP may end a hair outside a bound: put the result back inside before reporting it.
        lo, hi = np.array(self.bounds()).T
        x = self.feasible_start(dirs, np.clip(x, lo, hi))
        return _step_result(x, self.evaluate(x, dirs), res, count)

    def prune(
        self, x, directions=None, u_max: int = U_MAX, delta: float = DELTA, min_gain: float = MIN_GAIN
    ) -> PruneResult:
        """Algorithm 1 with the reference rank and condition number updated on acceptance."""
        dirs = self.all_directions if directions is None else np.asarray(directions)
        blocks = self.rows(x, dirs)
        return prune_intervals(blocks, u_max, delta, min_gain)

    def design(self, x0=None, maxiter: int = 100, progress: bool = True, min_gain: float = MIN_GAIN) -> DesignResult:
        """The three steps. progress: a tqdm bar per step.

        Ctrl-C stops the design within a second (the objective batch polls for it in the engine) and raises
        `freefloat.Interrupted` whose `partial` is a `PartialDesign`: the best feasible design evaluated so far
        (in step 3 on the kept intervals; in step 1, or before step 3 has evaluated a point, on all intervals)."""
        import time

        timings = {}
        stage = {"name": "step 1/3", "best": _Best(), "dirs": self.all_directions, "s1": None, "prune": None}
        try:
            t0 = time.perf_counter()
            s1 = self._run_step(
                "step 1/3: SQP on all intervals", self.all_directions, x0, maxiter, progress, stage["best"]
            )
            stage["s1"] = s1
            timings["step1"] = time.perf_counter() - t0
            stage["name"] = "step 2/3"
            t0 = time.perf_counter()
            bar = None
            if progress:
                from tqdm.auto import tqdm

                bar = tqdm(total=len(self.all_directions), desc="step 2/3: Algorithm 1 on the intervals", leave=False)
            try:
                pr = self.prune(s1.x, min_gain=min_gain)
                if bar is not None:
                    bar.update(bar.total)
                    bar.set_postfix(kept=len(pr.kept))
            finally:
                if bar is not None:
                    bar.close()
            stage["prune"] = pr
            timings["step2"] = time.perf_counter() - t0
            kept_dirs = self.all_directions[pr.kept]
            stage.update(name="step 3/3", best=_Best(), dirs=kept_dirs)
            t0 = time.perf_counter()
            s3 = self._run_step(
                "step 3/3: SQP on the kept intervals", kept_dirs, s1.x, maxiter, progress, stage["best"]
            )
            timings["step3"] = time.perf_counter() - t0
        except KeyboardInterrupt as e:
            timings["interrupted_after"] = sum(timings.values()) + time.perf_counter() - t0
            raise _interrupted(self, stage, timings, e) from None
        if not s3.condition_number < KAPPA_UNEXCITED:
            raise NumericalError(
                f"the designed trajectory does not excite every minimal parameter of '{self.guess.name}' "
                f"(κ = {s3.condition_number:.3g} after step 3, {self.n_min} parameters): drive more joints, "
                "widen the joint limits, or declare the unreachable bodies known"
            )
        return DesignResult(design=self, step1=s1, prune=pr, step3=s3, directions=kept_dirs, timings=timings)

    # -- the paper's baseline: a 5-term Fourier series per arm joint ------------------------------------------
    def fourier(self, c, directions, n_terms: int = 5):
        """Arm joints on a Fourier series (c = per joint [q0, a_1..a_N, b_1..b_N], fundamental period = the
        trajectory's duration), wheels on their cycloids over `directions`: a `Stacked` trajectory."""
        from ..trajectories import Stacked

        n, k = self.n_arm, 2 * n_terms + 1
        c = np.asarray(c, dtype=float).reshape(n, k)
        duration = len(directions) * self.interval
        arm = Fourier(c[:, 1 : 1 + n_terms], c[:, 1 + n_terms :], c[:, 0], omega_f=2 * np.pi / duration, n_h=n_terms)
        nw = len(self.wheels)
        wheels = Cycloidal(
            np.full(nw, WHEEL_START),
            np.full(nw, WHEEL_RANGE),
            np.asarray(directions)[:, self.n_arm :],
            interval=self.interval,
        )
        return Stacked(arm, wheels)

    def fourier_baseline(
        self, directions, n_terms: int = 5, maxiter: int = 60, grid: int = 200, progress=None
    ) -> tuple:
        """Optimise a 5-term Fourier series per arm joint (11 variables each, 5.5× the cycloid's 2) on the same
        objective (eq. 32) over the same duration; limits enforced on `grid` time points (linear in the
        coefficients).  Returns (StepResult with x = coefficients, trajectory)."""
        dirs = np.asarray(directions)
        n, k = self.n_arm, 2 * n_terms + 1
        duration = len(dirs) * self.interval
        w = 2 * np.pi / duration
        tg = np.linspace(0.0, duration, grid)
        i = np.arange(1, n_terms + 1)
        S, C = np.sin(np.outer(tg, i * w)), np.cos(np.outer(tg, i * w))
        rows_q = np.hstack([np.ones((grid, 1)), S, C])  # q  = rows_q  @ c_j
        rows_v = np.hstack([np.zeros((grid, 1)), C * (i * w), -S * (i * w)])
        rows_a = np.hstack([np.zeros((grid, 1)), -S * (i * w) ** 2, -C * (i * w) ** 2])
        L = self.limits
        A, b = [], []
        for j in range(n):

            def blk(rows, j=j):
                M = np.zeros((grid, n * k))
                M[:, j * k : (j + 1) * k] = rows
                return M

            A += [blk(rows_q), -blk(rows_q), blk(rows_v), -blk(rows_v), blk(rows_a), -blk(rows_a)]
            b += [
                np.full(grid, L.q_min[j]),
                np.full(grid, -L.q_max[j]),
                np.full(grid, -L.qd_max[j]),
                np.full(grid, -L.qd_max[j]),
                np.full(grid, -L.qdd_max[j]),
                np.full(grid, -L.qdd_max[j]),
            ]
        A, b = np.vstack(A), np.concatenate(b)
        # Start: mid-range offsets; joint j gets a sine on harmonic (j mod N) + 1 and a cosine on the next, at a
        # quarter of what the limits allow, so the joints do not move in lockstep.
        c0 = np.zeros((n, k))
        c0[:, 0] = 0.5 * (L.q_min + L.q_max)
        for j in range(n):
            hs, hc = j % n_terms, (j + 1) % n_terms
            amp = lambda h, j=j: (
                min(0.5 * (L.q_max[j] - L.q_min[j]), L.qd_max[j] / ((h + 1) * w), L.qdd_max[j] / ((h + 1) * w) ** 2) / 4
            )
            c0[j, 1 + hs] = amp(hs)
            c0[j, 1 + n_terms + hc] = amp(hc)
        t = self._grid(len(dirs))

        def evaluate(X):
            paths = [self.fourier(xx, dirs, n_terms).evaluate(t)[:2] for xx in X]
            return self._objective(np.array([p[0] for p in paths]), np.array([p[1] for p in paths]))

        res, count = _slsqp(evaluate, c0.ravel(), A, b, None, maxiter, progress)
        x = np.asarray(res.x)
        step = _step_result(x, evaluate(x[None]), res, count)
        return step, self.fourier(x, dirs, n_terms)

    def _run_step(self, desc, dirs, x0, maxiter, progress, best=None):
        bar = None
        if progress:
            from tqdm.auto import tqdm

            bar = tqdm(total=maxiter, desc=desc, leave=False)

        def cb(it, c):
            if bar is not None:
                bar.update(1)
                bar.set_postfix(C=f"{c:.4g}")

        try:
            res = self.optimize(dirs, x0, maxiter, cb, best)
            if bar is not None:  # converged before maxiter: the step is done, so its bar is full
                bar.update(bar.total - bar.n)
                bar.refresh()
            return res
        finally:
            if bar is not None:
                bar.close()


class _Best:
    """The best point an optimisation has evaluated that satisfies its constraints: what a Ctrl-C keeps."""

    def __init__(self):
        self.x, self.f, self.row, self.evaluations, self.iterations = None, np.inf, None, 0, 0

    def offer(self, x, f, r, A, b, bounds) -> None:
        if not f < self.f or np.any(A @ x < b - 1e-9):
            return
        if bounds is not None and any(not lo - 1e-12 <= xi <= hi + 1e-12 for xi, (lo, hi) in zip(x, bounds)):
            return
        self.x, self.f = x.copy(), f
        self.row = {k: np.asarray(v)[:1] for k, v in r.items()}

    def step_result(self) -> StepResult | None:
        if self.x is None:
            return None
        msg = "interrupted (Ctrl-C): the best feasible point evaluated so far"
        return _step_result(self.x, self.row, _Report(self.iterations, msg), self.evaluations)


class _Report:
    def __init__(self, nit, message):
        self.nit, self.message = nit, message


def _slsqp(evaluate, x0, A, b, bounds, maxiter: int, progress, best: _Best | None = None):
    """SLSQP on log C (eq. 32) under A x >= b and `bounds`. `evaluate(X)` takes a batch of points; the value and
    its forward-difference gradient (steps 1e-6 relative) come from one batched call per point, cached so
    SLSQP's separate value and gradient requests cost one call. Returns (scipy result, evaluations).
    best: kept up to date with the best feasible point evaluated (for a Ctrl-C)."""
    from scipy.optimize import minimize

    cache, count, it = {}, [0], [0]

    def fun_and_grad(x):
        key = x.tobytes()
        if key not in cache:
            h = 1e-6 * np.maximum(1.0, np.abs(x))
            X = np.vstack([x, x + np.diag(h)])
            r = evaluate(X)
            f = _log_objective(r["objective"])
            count[0] += len(X)
            cache.clear()
            cache[key] = (f[0], (f[1:] - f[0]) / h)
            if best is not None:
                best.evaluations, best.iterations = count[0], it[0]
                best.offer(x, f[0], r, A, b, bounds)
        return cache[key]

    def callback(xk):
        it[0] += 1
        if progress is not None:
            progress(it[0], float(np.exp(fun_and_grad(xk)[0])))

    res = minimize(
        lambda x: fun_and_grad(x)[0],
        x0,
        jac=lambda x: fun_and_grad(x)[1],
        method="SLSQP",
        bounds=bounds,
        constraints=[{"type": "ineq", "fun": lambda x: A @ x - b, "jac": lambda x: A}],
        options={"maxiter": maxiter, "ftol": 1e-9},
        callback=callback,
    )
    return res, count[0]


def _interrupted(design: ExcitationDesign, stage: dict, timings: dict, exc: BaseException):
    """The `Interrupted` a Ctrl-C during `design` becomes: partial = the best design so far."""
    best = stage["best"].step_result()
    dirs = stage["dirs"]
    s1 = stage["s1"]
    if best is None and s1 is not None:  # step 3 had not evaluated a point yet: the finished step 1
        best, dirs = s1, design.all_directions
    partial = PartialDesign(
        design=design,
        stopped_in=stage["name"],
        best=best,
        directions=dirs,
        step1=s1,
        prune=stage["prune"],
        timings=timings,
    )
    where = (
        f"κ = {best.condition_number:.4g} on {len(dirs)} intervals" if best is not None else "no design evaluated yet"
    )
    e = Interrupted(f"excitation design stopped in {stage['name']} ({str(exc) or 'Ctrl-C'}); best so far: {where}")
    e.partial = partial
    return e


def _log_objective(c):
    c = np.asarray(c, dtype=float)
    return np.log(np.where(np.isfinite(c), c, 1e300))


def _check_physical(guess) -> None:
    from .consistent import is_consistent

    P = guess.parameters()
    bad = [guess.body_names[b] for b in range(guess.nbodies) if not is_consistent(P[b])]
    if bad:
        raise InputError(
            f"guess '{guess.name}': non-physical inertias for {', '.join(bad)}; the base response "
            "would be meaningless. Use a physically consistent guess (e.g. naveen_dual_arm_offset)"
        )


def _step_result(x: np.ndarray, r: dict, res, count: int) -> StepResult:
    """The report of one SQP run from its final evaluation `r` (first row) and scipy's result `res`."""
    return StepResult(
        x=x,
        objective=float(r["objective"][0]),
        condition_number=float(r["condition_number"][0]),
        mean_square=float(r["mean_square"][0]),
        iterations=int(res.nit),
        evaluations=count,
        message=str(res.message),
        significant=significant(r["singular_values"][0], DELTA),
    )
