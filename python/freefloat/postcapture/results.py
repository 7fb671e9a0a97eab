"""Results of a post-capture identification: histories, final errors, transit times, the table beside the
paper's values, results.json; the tables of the velocity sweep and the noise study."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .estimators import METHODS, SOLVER_TITLES, SOLVERS, is_product
from .scenario import Scenario


def transit_times(t, hist, truth, tol, zero_abs=1e-8):
    """Per parameter: (first time within tolerance, time after which it stays within). Relative
    tolerance; for a zero true value the paper's absolute 1e-8 (Table 6 note). `truth`: (P,) constant, or
    (N, P) the truth at each time of `t` (a base whose propellant depletes)."""
    out = []
    truth = np.asarray(truth, float)
    tr_t = truth if truth.ndim == 2 else np.broadcast_to(truth, hist.shape)
    for j in range(hist.shape[1]):
        tj = tr_t[:, j]
        err = np.abs(hist[:, j] - tj)
        ok = np.where(tj != 0, err <= tol * np.abs(tj), err <= zero_abs)
        first = float(t[np.argmax(ok)]) if ok.any() else None
        bad = np.nonzero(~ok)[0]
        stays = None if not ok[-1] else (float(t[0]) if len(bad) == 0 else float(t[bad[-1] + 1]))
        out.append((first, stays))
    return out


@dataclass
class PostcaptureResult:
    scenario: Scenario
    names: list
    truth: np.ndarray
    histories: dict  # (method, solver) -> (t (N,), params (N, P))
    timings: dict
    residuals: dict = field(default_factory=dict)
    #: set when the run was stopped (Ctrl-C): where; the histories then cover t = 0 .. t_end only
    interrupted: str | None = None
    t_end: float | None = None
    #: the simulated samples (the engine's dict: t, q, v, ddq, tau, ...), when the run made them
    simulation: dict | None = None
    #: (t (T,), truth (T, P)) when the base's parameters change along the run (propellant depletion): errors
    #: and transit times are then against the truth at each time; `truth` stays the initial (model file) value
    truth_history: tuple | None = None
    #: what a run with actuators and sensors adds to results.json (propellant, balances, tracking, sensors)
    extra: dict = field(default_factory=dict)

    def final(self, method, solver):
        return self.histories[(method, solver)][1][-1]

    def truth_at(self, t) -> np.ndarray:
        """The true parameters at the times t (N, P)."""
        t = np.asarray(t, float)
        if self.truth_history is None:
            return np.broadcast_to(self.truth, (len(t), len(self.truth)))
        th_t, th = self.truth_history
        return np.stack([np.interp(t, th_t, th[:, j]) for j in range(th.shape[1])], -1)

    def final_truth(self, method, solver) -> np.ndarray:
        t, _ = self.histories[(method, solver)]
        return self.truth_at(t[-1:])[0]

    def rel_error(self, method, solver):
        tr = self.final_truth(method, solver)
        est = self.final(method, solver)
        return np.where(tr != 0, np.abs(est - tr) / np.where(tr != 0, np.abs(tr), 1), np.abs(est - tr))

    def rms_rel_error(self, method, solver, names) -> float:
        """RMS over the parameters `names` (e.g. ["m1", "mn", "Inxx", "Inyy", "Inzz"]) of `rel_error`: one number
        for a study's table."""
        e = self.rel_error(method, solver)
        return float(np.sqrt(np.mean([e[self.names.index(n)] ** 2 for n in names])))

    def transits(self, method, solver):
        t, h = self.histories[(method, solver)]
        return transit_times(t, h, self.truth_at(t), self.scenario.tolerance)

    def warnings(self) -> list[str]:
        """Sentences for results that look like answers but are not: an estimate that never moved from its
        initial guess (no excitation reached it), a scenario whose excitation amplitudes are all zero."""
        out = []
        amp = np.asarray(self.scenario.excitation.get("amp", []), float)
        if amp.size == 0 or not np.any(amp):
            out.append(
                "the scenario's excitation amplitudes are all zero: the joints do not move relative to the base, so "
                "the data carry little information about the payload"
            )
        if self.scenario.sensors is not None and self.scenario.measurement.get("accelerations", "exact") == "exact":
            out.append(
                "the force-based estimates use the simulation's exact accelerations, not the sensors' (set "
                "measurement.accelerations: central_difference to difference the measured rates)"
            )
        for (method, solver), (_, h) in self.histories.items():
            h = np.asarray(h, float)
            if len(h) and np.all(np.abs(h - h[0]) <= 1e-12 * np.maximum(np.abs(h[0]), 1.0)):
                out.append(
                    f"the {method}-based {solver} estimate never moved from its initial guess (no excitation reached "
                    "it): the printed values are the guess, not an identification"
                )
        return out

    def to_dict(self) -> dict:
        out = {
            "warnings": self.warnings(),
            "scenario": self.scenario.name,
            "model": self.scenario.model,
            "tolerance": self.scenario.tolerance,
            "P0": self.scenario.P0,
            "forgetting": self.scenario.forgetting,
            "projected": self.scenario.project,
            "duration": self.scenario.duration,
            "timings_s": self.timings,
            "equation_residuals_at_truth": self.residuals,
            "noise": self.scenario.noise,
            # the effective settings (the scenario's keys over the defaults)
            "measurement": {
                "accelerations": "exact",
                "impulses": "simpson",
                "momentum_point": "base",
                **self.scenario.measurement,
            },
            "methods": {},
            **self.extra,
        }
        if self.interrupted is not None:
            out.update(interrupted=True, stopped=self.interrupted, t_end=self.t_end)
        for (method, solver), (_t, h) in self.histories.items():
            tt = self.transits(method, solver)
            err = self.rel_error(method, solver)
            ftr = self.final_truth(method, solver)
            out["methods"].setdefault(method, {})[solver] = {
                n: {
                    "truth": float(ftr[j]),
                    **({"truth_initial": float(self.truth[j])} if self.truth_history is not None else {}),
                    "estimate": float(h[-1, j]),
                    "error": float(err[j]),
                    "error_kind": "relative" if ftr[j] != 0 else "absolute",
                    "transit_time": tt[j][1],
                    "first_within": tt[j][0],
                    "paper": self.scenario.paper.get(method, {}).get(n),
                }
                for j, n in enumerate(self.names)
            }
        return out

    def table(self) -> str:
        """Our final estimates (transit time to the scenario's tolerance, 'stays' reading) beside the paper's."""
        tol = self.scenario.tolerance
        lines = [
            (f"INTERRUPTED ({self.interrupted}): " if self.interrupted else "")
            + f"{self.scenario.name}: final estimates at t = "
            + f"{self.scenario.duration if self.t_end is None else self.t_end:g} s, "
            f"(transit time to {tol * 100:g} %, after which the estimate stays within; prior covariance "
            f"P0 = {self.scenario.P0:g})"
        ]
        if self.truth_history is not None:
            lines.append(
                "(the base's propellant depletes: 'truth' is its value at the end of the run, errors and transit times "
                "are against the truth at each time)"
            )
        for method in METHODS:
            if (method, "modified_rls") not in self.histories:
                continue
            paper = self.scenario.paper.get(method, {})
            hdr = f"{'param':>6} {'truth':>12} | {'PAPER: value (transit)':>26} | " + " | ".join(
                f"{'OURS ' + SOLVER_TITLES[s] + ': value (transit, error)':>40}" for s in SOLVERS
            )
            lines += ["", f"{method}-based", hdr, "-" * len(hdr)]
            tr = {s: self.transits(method, s) for s in SOLVERS}
            err = {s: self.rel_error(method, s) for s in SOLVERS}
            ftr = self.final_truth(method, SOLVERS[0])
            for j, n in enumerate(self.names):
                if n not in paper and paper and is_product(n):
                    continue
                p = paper.get(n)
                ptxt = (
                    "not in the paper"
                    if p is None or p[0] is None
                    else (f"{p[0]:.6g}" + (f" ({p[1]:g} s)" if len(p) > 1 and p[1] is not None else " (no time)"))
                )
                cells = []
                for s in SOLVERS:
                    e = self.final(method, s)[j]
                    tt = tr[s][j][1]
                    cells.append(f"{e:>13.6g} ({'not converged' if tt is None else f'{tt:.1f} s'}, {err[s][j]:.1e})")
                lines.append(f"{n:>6} {ftr[j]:>12.6g} | {ptxt:>26} | " + " | ".join(f"{c:>40}" for c in cells))
        lines.append("")
        lines.append(
            "(PAPER: the paper's printed value and transit time; 'not in the paper': the paper prints no value, "
            "'no time': a value without a transit time. OURS: error relative, absolute for a zero true value; "
            f"'not converged': not within {tol * 100:g} % at the end of the run)"
        )
        return "\n".join(lines)

    def save(self, out) -> Path:
        """results.json, table.txt and the figures; for an interrupted run also simulation.npz (the samples
        simulated) and histories.npz (each estimator's t and estimates), and no figures (plotting would delay
        the exit after Ctrl-C)."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps(self.to_dict(), indent=1))
        (out / "table.txt").write_text(self.table() + "\n")
        if self.interrupted is not None:
            if self.simulation is not None:
                arrays = {k: v for k, v in self.simulation.items() if isinstance(v, np.ndarray)}
                np.savez(out / "simulation.npz", **arrays)
            hist = {}
            for (method, solver), (t, h) in self.histories.items():
                hist[f"{method}_{solver}_t"], hist[f"{method}_{solver}"] = np.asarray(t), np.asarray(h)
            np.savez(out / "histories.npz", names=np.array(self.names, dtype=str), **hist)
            return out / "results.json"
        from .plots import plot_histories

        plot_histories(self, out)
        if self.truth_history is not None:
            from .plots import plot_base_tracking

            plot_base_tracking(self, out)
        return out / "results.json"


def sweep_table(sw: dict, params=("In", "I1", "mn", "bnx"), paper: dict | None = None) -> str:
    names = sw["names"]
    cols = [names.index(p) for p in params]
    lines = [
        "relative error (%) at the end of the run vs initial base velocity [m/s]",
        f"{'velocity':>14} {'method/solver':>26} " + " ".join(f"{p:>10}" for p in params),
    ]
    for k, v in enumerate(sw["velocities"]):
        for key, errs in sw["errors"].items():
            lines.append(
                f"{str([round(x, 1) for x in v]):>14} {key:>26} " + " ".join(f"{100 * errs[k][c]:>10.4f}" for c in cols)
            )
    if paper:
        lines.append(
            "paper (text of Sec. V-A-3): momentum-based I'n "
            + ", ".join(f"{p['error_percent']} % at {p['velocity']}" for p in paper.get("momentum_In", []))
            + f"; force-based: {paper.get('force_In', '')}"
        )
    return "\n".join(lines)


def noise_table(ns: dict) -> str:
    names = ns["names"]
    lines = ["median relative error (%) at the end of the run; noise = DEFAULT_NOISE × scale"]
    lines.append(f"{'scale':>6} {'method/solver':>24} " + " ".join(f"{n:>9}" for n in names))
    for lv in ns["levels"]:
        for key, e in lv["median_error"].items():
            lines.append(f"{lv['scale']:>6g} {key:>24} " + " ".join(f"{100 * x:>9.4f}" for x in e))
    return "\n".join(lines)
