"""What the excitation design works with and returns: joint limits (eqs. 33-37), one SQP step's result, and the
whole design's result (trajectory, Table 3 format, summary, results.json, trajectory file, Fig. 4)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._core import InputError
from ..constants import PAPER_KAPPA, PAPER_KEPT, TABLE3_RANGE_RAD, TABLE3_START_DEG
from ..io.trajectory_files import save_trajectory
from ..trajectories import Cycloidal
from .pruning import PruneResult, plot_fig4

if TYPE_CHECKING:  # the design object that made the result (no run-time import: excitation imports this module)
    from .excitation import ExcitationDesign


@dataclass
class Limits:
    """Joint limits of the arm joints (n,): positions [rad], |rate| [rad/s], |acceleration| [rad/s²]."""

    q_min: np.ndarray
    q_max: np.ndarray
    qd_max: np.ndarray
    qdd_max: np.ndarray

    @classmethod
    def naveen(cls, n: int = 6) -> Limits:
        """Our documented choice for the Naveen, Shah, Misra arms (the paper gives none)."""
        return cls(
            np.full(n, -1.5 * np.pi), np.full(n, 1.5 * np.pi), np.full(n, 1.6 * np.pi), np.full(n, 1.6 * np.pi**2)
        )

    @classmethod
    def seed001(cls, n: int = 6) -> Limits:
        """Earlier name of `naveen` (kept as an alias)."""
        return cls.naveen(n)

    def range_max(self, interval: float) -> np.ndarray:
        """θ_jd^max of eq. 36: min of the rate bound (eq. 34) and the acceleration bound (eq. 35)."""
        return np.minimum(0.5 * interval * self.qd_max, interval**2 / (2 * np.pi) * self.qdd_max)

    def check(self, n: int) -> None:
        for name in ("q_min", "q_max", "qd_max", "qdd_max"):
            a = np.asarray(getattr(self, name), dtype=float)
            if a.shape != (n,) or not np.all(np.isfinite(a)):
                raise InputError(f"Limits.{name}: expected {n} finite numbers, got shape {a.shape}")
            setattr(self, name, a)
        bad = np.flatnonzero(self.q_max <= self.q_min)
        if bad.size:
            raise InputError(
                f"Limits: joint {bad[0]} has no feasible position range "
                f"(q_max {self.q_max[bad[0]]} <= q_min {self.q_min[bad[0]]}); widen it"
            )
        bad = np.flatnonzero((self.qd_max <= 0) | (self.qdd_max <= 0))
        if bad.size:
            raise InputError(
                f"Limits: joint {bad[0]} has a non-positive rate or acceleration limit; no motion is feasible"
            )


@dataclass
class StepResult:
    """One SQP run: seeds x = [θ_s; θ_d], the objective's parts, and the optimiser's report."""

    x: np.ndarray
    objective: float
    condition_number: float
    mean_square: float
    iterations: int
    evaluations: int
    message: str
    significant: int = 0  # significant singular values (> σmax/300) of the regressor


@dataclass
class DesignResult:
    design: ExcitationDesign
    step1: StepResult
    prune: PruneResult
    step3: StepResult
    directions: np.ndarray  # surviving direction combinations (K, n_arm + n_wheels)
    timings: dict = field(default_factory=dict)

    def trajectory(self) -> Cycloidal:
        """The exciting trajectory (arm joints then wheels, in `design.joints` order)."""
        return self.design.cycloid(self.step3.x, self.directions)

    def table3(self) -> str:
        """Seed parameters in the format of the paper's Table 3 (start in degrees, range in radians)."""
        d = self.design
        n = d.n_arm
        s, r = self.step3.x[:n], self.step3.x[n:]
        head = f"{'seed':10s}" + "".join(f"{j:>10s}" for j in d.arm)
        lines = [
            "optimal seed parameters (Naveen, Shah, Misra Table 3 format)",
            head,
            f"{'start deg':10s}" + "".join(f"{np.rad2deg(v):10.3f}" for v in s),
            f"{'range rad':10s}" + "".join(f"{v:10.3f}" for v in r),
            f"{'paper':10s}" + "".join(f"{v:10.3f}" for v in TABLE3_START_DEG),
            f"{'paper':10s}" + "".join(f"{v:10.3f}" for v in TABLE3_RANGE_RAD),
        ]
        return "\n".join(lines)

    def summary(self) -> str:
        k = len(self.prune.kept)
        return (
            f"step 1: {self.design.n_intervals} intervals, κ = {self.step1.condition_number:.4g} "
            f"({self.step1.iterations} SQP iterations)\n"
            f"step 2: pruning kept {k} of {self.design.n_intervals} intervals (paper: {PAPER_KEPT} of 256)\n"
            f"step 3: κ = {self.step3.condition_number:.4g} on the kept intervals (paper: {PAPER_KAPPA}); "
            f"significant singular values {self.step3.significant} of {self.design.n_min}; "
            f"duration {k * self.design.interval:g} s"
        )

    def to_dict(self) -> dict:
        d = self.design
        return {
            "model": d.guess.name,
            "arm_joints": d.arm,
            "wheels": d.wheels,
            "interval": d.interval,
            "step1": _step_dict(self.step1, d.n_arm),
            "step3": _step_dict(self.step3, d.n_arm),
            "kept_intervals": self.prune.kept.tolist(),
            "n_kept": int(len(self.prune.kept)),
            "n_candidates": d.n_intervals,
            "significant_singular_values": self.step3.significant,
            "n_min": d.n_min,
            "paper": {"condition_number": PAPER_KAPPA, "kept": PAPER_KEPT},
            "weight": d.weight,
            "limits": {k: np.asarray(v).tolist() for k, v in d.limits.__dict__.items()},
            "timings_s": self.timings,
        }

    def save(self, directory) -> Path:
        """DIR/trajectory.json (for `freefloat simulate/identify --trajectory`), results.json, fig4.png."""
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        save_trajectory(out / "trajectory.json", self.trajectory(), self.design.joints, self.design.guess.name)
        (out / "results.json").write_text(json.dumps(self.to_dict(), indent=2))
        plot_fig4(self.prune, out / "fig4.png")
        return out


def _step_dict(s: StepResult, n: int) -> dict:
    return {
        "start_rad": s.x[:n].tolist(),
        "range_rad": s.x[n:].tolist(),
        "objective": s.objective,
        "condition_number": s.condition_number,
        "mean_square": s.mean_square,
        "iterations": s.iterations,
        "evaluations": s.evaluations,
        "message": s.message,
    }


@dataclass
class PartialDesign:
    """What an interrupted `ExcitationDesign.design` keeps (`freefloat.Interrupted.partial`): the best feasible
    design evaluated before the Ctrl-C, on `directions` (the kept intervals once step 3 has evaluated a point,
    else all intervals), and the steps that had finished."""

    design: ExcitationDesign
    stopped_in: str  # "step 1/3", "step 2/3" or "step 3/3"
    best: StepResult | None  # None: stopped before the first evaluation
    directions: np.ndarray
    step1: StepResult | None = None
    prune: PruneResult | None = None
    timings: dict = field(default_factory=dict)

    def trajectory(self) -> Cycloidal | None:
        """The best trajectory so far (arm joints then wheels), or None."""
        return None if self.best is None else self.design.cycloid(self.best.x, self.directions)

    def summary(self) -> str:
        if self.best is None:
            return f"interrupted in {self.stopped_in} before any design was evaluated"
        return (
            f"interrupted in {self.stopped_in}; best design so far: κ = {self.best.condition_number:.4g}, "
            f"C = {self.best.objective:.4g} on {len(self.directions)} intervals "
            f"({len(self.directions) * self.design.interval:g} s), {self.best.evaluations} evaluations"
        )

    def to_dict(self) -> dict:
        d = self.design
        out = {
            "interrupted": True,
            "stopped_in": self.stopped_in,
            "model": d.guess.name,
            "arm_joints": d.arm,
            "wheels": d.wheels,
            "interval": d.interval,
            "best": None if self.best is None else _step_dict(self.best, d.n_arm),
            "n_intervals": int(len(self.directions)),
            "n_candidates": d.n_intervals,
            "n_min": d.n_min,
            "weight": d.weight,
            "timings_s": self.timings,
        }
        if self.step1 is not None:
            out["step1"] = _step_dict(self.step1, d.n_arm)
        if self.prune is not None:
            out["kept_intervals"] = self.prune.kept.tolist()
        return out

    def save(self, directory) -> Path:
        """DIR/trajectory.json (the best design so far, when there is one) and results.json (with
        `interrupted: true`); no figure, so that the exit after Ctrl-C is not delayed by plotting."""
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        tr = self.trajectory()
        if tr is not None:
            save_trajectory(out / "trajectory.json", tr, self.design.joints, self.design.guess.name)
        (out / "results.json").write_text(json.dumps(self.to_dict(), indent=2))
        return out
