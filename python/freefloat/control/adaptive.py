"""Adaptive dual-quaternion pose tracking with concurrent learning (Valverde 2018, ch. 4).

A rigid spacecraft tracks a desired frame D on the relative pose-error dynamics (thesis eq. 2.58) while it
estimates its own mass and inertia `v(M) = [I11, I12, I13, I22, I23, I33, m]`. The control law is (4.9)/(4.25)
with the swap typo of its last term corrected; the estimate follows the update law (4.13) with cumulative
P, Q (continuous concurrent learning, Theorem 1) or (4.29) with a stored stack of samples (discrete concurrent
learning, Theorem 2). α = 0 is the baseline of Filipe and Tsiotras. Everything numeric runs in the engine; this
module reads scenario files, runs them and collects the results.

    import freefloat as ff
    from freefloat.control import adaptive
    res = adaptive.run("valverde_ch4_example_a")          # CL (alpha = 1) and the baseline
    res.runs["alpha=1"].final_estimate, res.to_dict()["time_within_1pct_s"]

    # your own loop: the controller as an object
    ctrl = adaptive.controller("valverde_ch4_example_b")  # or ff.control.AdaptivePoseController(...)
    f = ctrl.control(t, q_bd, w_bd)                       # dual force f + eps tau, (8,)
    ctrl.update(t, dt, q_bd, w_bd, w_bd_dot, f)           # record the sample, advance the estimate
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _core
from .._core import AdaptivePoseController, InputError
from ..io import scenario_files

#: the order of the estimated parameters (thesis §4.1), as in every result
PARAMETER_NAMES = ["I11", "I12", "I13", "I22", "I23", "I33", "m"]
KIND = "control_adaptive"


def realisability(v) -> dict:
    """Whether `v = [I11, I12, I13, I22, I23, I33, m]` is a realisable rigid body: mass > 0, inertia positive
    definite, principal moments within the triangle inequality (each at most the sum of the other two). Returns
    the engine's dict (`realisable`, `admissible`, each condition, `principal_moments`, `failures`)."""
    return _core.inertia_realisability(np.asarray(v, float))


@dataclass
class Scenario:
    """A `control_adaptive` scenario: the spacecraft, its initial relative state, gains, learning and reference."""

    name: str
    description: str
    truth: np.ndarray
    q0: np.ndarray  # unit pose q_B/D (8,)
    w0: np.ndarray  # twist w_B/D (8,)
    estimate0: np.ndarray
    gains: dict
    mode: str
    alphas: list
    n_s: int = 50
    sigma_stop: float = float("inf")
    selection: str = "elementwise"
    seed: int = 0
    law: str = "corrected"
    alpha_off_after: float | None = None  # Remark 6: alpha = 0 this long after rank 7 (None: never)
    reference: dict = field(default_factory=dict)
    duration: float = 50.0
    method: str = "dopri5"
    dt: float = 0.01
    rtol: float = 1e-10
    atol: float = 1e-10
    max_step: float = float("inf")
    output_dt: float = 0.01
    paper: dict = field(default_factory=dict)
    source: str = ""


def _vec(d: dict, key: str, n: int, source: str, where: str, default=None) -> np.ndarray:
    if key not in d:
        if default is not None:
            return np.asarray(default, float)
        raise InputError(f"{source}: missing key '{where}{key}'")
    try:
        v = np.asarray(d[key], float)
    except (TypeError, ValueError):
        raise InputError(f"{source}: key '{where}{key}' must be {n} numbers, got {d[key]!r}") from None
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise InputError(f"{source}: key '{where}{key}' must be {n} finite numbers, got {d[key]!r}")
    return v


def _num(d: dict, key: str, source: str, where: str, default=None, lo=None, lo_open=False) -> float:
    if key not in d:
        if default is None:
            raise InputError(f"{source}: missing key '{where}{key}'")
        return float(default)
    try:
        x = float(d[key])
    except (TypeError, ValueError):
        raise InputError(f"{source}: key '{where}{key}' must be a number, got {d[key]!r}") from None
    if np.isnan(x) or (lo is not None and (x <= lo if lo_open else x < lo)):
        raise InputError(f"{source}: key '{where}{key}' must be {'>' if lo_open else '>='} {lo}, got {x}")
    return x


def _section(d: dict, key: str, source: str, required=True) -> dict:
    s = d.get(key)
    if s is None:
        if required:
            raise InputError(f"{source}: missing section '{key}'")
        return {}
    if not isinstance(s, dict):
        raise InputError(f"{source}: '{key}' must be a mapping of keys, got {type(s).__name__}")
    return s


def _pose(attitude: np.ndarray, position: np.ndarray, source: str) -> np.ndarray:
    n = np.linalg.norm(attitude)
    if not abs(n - 1.0) <= 1e-3:
        raise InputError(
            f"{source}: key 'initial.attitude' must be a unit quaternion (w, x, y, z), got norm {n:.6g} "
            "(within 1e-3 of 1 it is normalised)"
        )
    q = attitude / n
    # body-frame translation: q_B/D = q + eps 1/2 q r^B (thesis §2.3), built with the engine's algebra
    from ..dq import DualQuaternion

    p = DualQuaternion([*q, 0, 0, 0, 0]) * DualQuaternion([1, 0, 0, 0, 0, *(0.5 * position)])
    return np.concatenate([p.real, p.dual])


def _gain(g: dict, key: str, n: int, source: str):
    if key not in g:
        raise InputError(f"{source}: missing key 'gains.{key}'")
    v = g[key]
    try:
        a = np.asarray(v, float)
    except (TypeError, ValueError):
        raise InputError(f"{source}: key 'gains.{key}' must be a number, a list or a matrix, got {v!r}") from None
    if a.shape not in ((), (n,), (n, n)) or not np.all(np.isfinite(a)):
        raise InputError(f"{source}: key 'gains.{key}' must be a number, {n} numbers or a {n}x{n} matrix")
    if a.ndim < 2 and np.any(a <= 0):
        raise InputError(f"{source}: key 'gains.{key}' must be positive, got {v!r}")
    return float(a) if a.ndim == 0 else a


def _harmonic(d: dict, source: str, where: str) -> np.ndarray:
    d = d or {}
    if not isinstance(d, dict):
        raise InputError(f"{source}: '{where}' must be a mapping (offset, amplitude, frequency, phase)")
    unknown = set(d) - {"offset", "amplitude", "frequency", "phase"}
    if unknown:
        raise InputError(
            f"{source}: unknown key(s) {sorted(unknown)} in '{where}' (offset, amplitude, frequency, phase)"
        )
    return np.array(
        [_vec(d, k, 3, source, where + ".", default=[0, 0, 0]) for k in ("offset", "amplitude", "frequency", "phase")]
    )


def _reference(d: dict, source: str) -> dict:
    if "table" in d:
        tb = d["table"]
        path = Path(tb) if isinstance(tb, str) else None
        if path is not None:
            if not path.is_absolute() and Path(source).is_file():
                path = Path(source).parent / path
            try:
                arr = np.loadtxt(path, delimiter=",", ndmin=2)
            except (OSError, ValueError) as e:
                raise InputError(f"{source}: key 'reference.table': cannot read {path} ({e})") from None
        else:
            arr = np.asarray(tb, float)
        if arr.ndim != 2 or arr.shape[1] != 7:
            raise InputError(
                f"{source}: key 'reference.table' must be rows [t, wx, wy, wz, vx, vy, vz], got shape {arr.shape}"
            )
        return {"reference_times": arr[:, 0].copy(), "reference_twists": arr[:, 1:].copy()}
    return {
        "reference_angular": _harmonic(d.get("angular"), source, "reference.angular"),
        "reference_linear": _harmonic(d.get("linear"), source, "reference.linear"),
    }


def load_scenario(spec: str | Path) -> Scenario:
    """A `control_adaptive` scenario by built-in name (`freefloat scenarios`) or YAML path; errors name the file
    and the key."""
    d, source = scenario_files.read(spec, kind=KIND)
    ini = _section(d, "initial", source)
    g = _section(d, "gains", source)
    le = _section(d, "learning", source)
    sim = _section(d, "simulation", source)
    ref = _section(d, "reference", source)
    mode = le.get("mode", "continuous")
    if mode not in ("continuous", "discrete"):
        raise InputError(f"{source}: key 'learning.mode' must be 'continuous' or 'discrete', got {mode!r}")
    alphas = le.get("alpha", [1.0])
    alphas = alphas if isinstance(alphas, list) else [alphas]
    alphas = [_num({"alpha": a}, "alpha", source, "learning.", lo=0.0) for a in alphas]
    n_s = le.get("n_s", 50)
    if not isinstance(n_s, int) or n_s < 2:
        raise InputError(
            f"{source}: key 'learning.n_s' must be an integer >= 2 (each sample has rank <= 6), got {n_s!r}"
        )
    method = sim.get("method", "dopri5")
    if method not in ("dopri5", "rk4"):
        raise InputError(f"{source}: key 'simulation.method' must be 'dopri5' or 'rk4', got {method!r}")
    rtol = _num(sim, "rtol", source, "simulation.", default=1e-10, lo=0.0, lo_open=True)
    if rtol >= 1:
        raise InputError(f"{source}: key 'simulation.rtol' must be below 1, got {rtol}")
    selection = le.get("selection", "elementwise")
    if selection not in ("elementwise", "max_min_sv"):
        raise InputError(f"{source}: key 'learning.selection' must be 'elementwise' or 'max_min_sv', got {selection!r}")
    return Scenario(
        name=str(d.get("name", Path(str(spec)).stem)),
        description=str(d.get("description", "")).strip(),
        truth=_vec(d, "truth", 7, source, ""),
        q0=_pose(_vec(ini, "attitude", 4, source, "initial."), _vec(ini, "position", 3, source, "initial."), source),
        w0=np.concatenate(
            [
                [0],
                _vec(ini, "angular_velocity", 3, source, "initial."),
                [0],
                _vec(ini, "linear_velocity", 3, source, "initial."),
            ]
        ),
        estimate0=_vec(ini, "estimate", 7, source, "initial.", default=np.zeros(7)),
        gains={k: _gain(g, k, 7 if k == "K_i" else 3, source) for k in ("K_r", "K_q", "K_v", "K_w", "K_i")},
        mode=mode,
        alphas=alphas,
        n_s=n_s,
        sigma_stop=_num(le, "sigma_stop", source, "learning.", default=float("inf"), lo=0.0, lo_open=True),
        selection=selection,
        seed=int(le.get("seed", 0)),
        law=str(le.get("law", "corrected")),
        alpha_off_after=(
            None if le.get("alpha_off_after") is None else _num(le, "alpha_off_after", source, "learning.", lo=0.0)
        ),
        reference=_reference(ref, source),
        duration=_num(sim, "duration", source, "simulation.", lo=0.0, lo_open=True),
        method=method,
        dt=_num(sim, "dt", source, "simulation.", default=0.01, lo=0.0, lo_open=True),
        rtol=rtol,
        atol=_num(sim, "atol", source, "simulation.", default=1e-10, lo=0.0, lo_open=True),
        max_step=_num(sim, "max_step", source, "simulation.", default=float("inf"), lo=0.0, lo_open=True),
        output_dt=_num(sim, "output_dt", source, "simulation.", default=0.01, lo=0.0, lo_open=True),
        paper=d.get("paper") or {},
        source=source,
    )


def list_scenarios() -> list[tuple[str, str]]:
    """Built-in `control_adaptive` scenarios (name, description)."""
    return [(s.name, s.description) for s in scenario_files.listing() if s.kind == KIND]


def _scenario(sc: Scenario | str | Path) -> Scenario:
    return sc if isinstance(sc, Scenario) else load_scenario(sc)


def controller(sc: Scenario | str | Path, alpha: float | None = None) -> AdaptivePoseController:
    """An `AdaptivePoseController` with the gains, learning settings, reference and initial estimate of a
    scenario (α: the scenario's first unless given)."""
    sc = _scenario(sc)
    g = sc.gains
    return AdaptivePoseController(
        g["K_r"], g["K_q"], g["K_v"], g["K_w"], g["K_i"], sc.alphas[0] if alpha is None else alpha,
        learning=sc.mode, n_s=sc.n_s, sigma_stop=sc.sigma_stop, selection=sc.selection, seed=sc.seed,
        law_form=sc.law, estimate0=sc.estimate0, **sc.reference,
    )  # fmt: skip


def time_within(t: np.ndarray, est: np.ndarray, truth: np.ndarray, tol: float) -> float | None:
    """The time after which every estimate stays within `tol` (relative) of the truth (absolute for a zero
    true value); None if the last sample is not within."""
    scale = np.where(truth != 0, np.abs(truth), 1.0)
    ok = np.all(np.abs(est - truth) <= tol * scale, axis=1)
    if not ok[-1]:
        return None
    bad = np.nonzero(~ok)[0]
    return float(t[0]) if len(bad) == 0 else float(t[bad[-1] + 1])


@dataclass
class AdaptiveRun:
    """One closed-loop run: the engine's histories and its statistics."""

    label: str
    alpha: float
    data: dict
    wall_s: float

    def __getattr__(self, k):
        try:
            return self.__dict__["data"][k]
        except KeyError:
            raise AttributeError(k) from None

    @property
    def final_estimate(self) -> np.ndarray:
        return self.data["estimate"][-1]

    def summary(self, truth: np.ndarray) -> dict:
        d = self.data
        t, est, sv = d["t"], d["estimate"], d["singular_values"]
        per = [time_within(t, est[:, [j]], truth[[j]], 0.01) for j in range(7)]
        reach = np.nonzero(sv[:, 6] >= 0.1)[0]
        V = d["lyapunov"]
        rz = realisability(est[-1])
        return {
            "alpha": self.alpha,
            "final_estimate": est[-1].tolist(),
            "final_error": (est[-1] - truth).tolist(),
            "time_within_1pct_s": time_within(t, est, truth, 0.01),
            "time_within_2pct_s": time_within(t, est, truth, 0.02),
            "parameter_time_within_1pct_s": dict(zip(PARAMETER_NAMES, per)),
            "final_position_error_m": float(np.linalg.norm(d["position_error"][-1])),
            "final_attitude_error_deg": float(np.degrees(d["attitude_error"][-1])),
            "final_singular_values": sv[-1].tolist(),
            "sigma_min_first_reaches_0p1_s": float(t[reach[0]]) if len(reach) else None,
            "rank7_time_s": d["rank7_time"],
            "alpha_off_time_s": d["alpha_off_time"],
            "lyapunov_initial": float(V[0]),
            "lyapunov_final": float(V[-1]),
            "lyapunov_max_increase": float(max(0.0, np.max(np.diff(V)))) if len(V) > 1 else 0.0,
            "final_estimate_realisability": {k: rz[k] for k in ("realisable", "admissible", "failures")},
            "estimate_left_admissible_set_at_s": d["left_admissible_at"],
            "estimate_admissible_since_s": d["admissible_since"],
            "stack_final_size": int(d["stack_len"][-1]),
            "stack_changes": d["stack_changes"],
            "steps": d["steps"],
            "rejected_steps": d["rejected"],
            "evaluations": d["evaluations"],
            "wall_time_s": self.wall_s,
            "interrupted": d["interrupted"],
        }


_KEEP = object()


def simulate(
    sc: Scenario | str | Path, alpha: float, progress=None, law: str | None = None, alpha_off_after=_KEEP
) -> AdaptiveRun:
    """One closed-loop run of a scenario with the CL weight `alpha` (0: the baseline), in the engine.
    `progress(t)` gets the simulated time; returning False or Ctrl-C stops the run, keeping what was done.
    `alpha_off_after` (s, ≥ 0, or None for never; default the scenario's `learning.alpha_off_after`): Valverde 2018
    Remark 6, α is set to 0 that long after the CL matrix first has rank 7 (`rank7_time_s`)."""
    sc = _scenario(sc)
    off = sc.alpha_off_after if alpha_off_after is _KEEP else alpha_off_after
    g = sc.gains
    t0 = time.perf_counter()
    data = _core.adaptive_simulate(
        sc.truth, sc.q0, sc.w0, sc.estimate0, g["K_r"], g["K_q"], g["K_v"], g["K_w"], g["K_i"], alpha,
        sc.duration, learning=sc.mode, n_s=sc.n_s, sigma_stop=sc.sigma_stop, selection=sc.selection,
        seed=sc.seed, law_form=law or sc.law, method=sc.method, dt=sc.dt, rtol=sc.rtol, atol=sc.atol,
        max_step=sc.max_step, output_dt=sc.output_dt, alpha_off_after=off, progress=progress, **sc.reference,
    )  # fmt: skip
    wall = time.perf_counter() - t0
    label = "baseline" if alpha == 0 else f"alpha={alpha:g}"
    run = AdaptiveRun(label, alpha, data, wall)
    if data["left_admissible_at"] is not None:
        warnings.warn(
            f"{sc.name} ({label}): the estimate left the admissible set (m > 0, inertia positive definite) at "
            f"t = {data['left_admissible_at']:.3f} s",
            stacklevel=2,
        )
    return run


@dataclass
class AdaptiveResult:
    """The runs of one scenario (the CL runs and the baseline) and everything `results.json` holds."""

    scenario: Scenario
    runs: dict  # label -> AdaptiveRun

    @property
    def primary(self) -> AdaptiveRun:
        return next(iter(self.runs.values()))

    def to_dict(self) -> dict:
        sc, tr = self.scenario, self.scenario.truth
        runs = {k: r.summary(tr) for k, r in self.runs.items()}
        p = runs[self.primary.label]
        rz = realisability(tr)
        return {
            "scenario": sc.name,
            "description": sc.description,
            "parameters": PARAMETER_NAMES,
            "truth": tr.tolist(),
            "truth_realisability": {k: rz[k] for k in ("realisable", "admissible", "principal_moments", "failures")},
            "primary_run": self.primary.label,
            "final_estimate": p["final_estimate"],
            "time_within_1pct_s": p["time_within_1pct_s"],
            "final_position_error_m": p["final_position_error_m"],
            "final_attitude_error_deg": p["final_attitude_error_deg"],
            "learning": {
                "mode": sc.mode,
                **(
                    {"n_s": sc.n_s, "sigma_stop": sc.sigma_stop, "selection": sc.selection, "seed": sc.seed}
                    if sc.mode == "discrete"
                    else {}
                ),
                "alpha_off_after_s": sc.alpha_off_after,
            },
            "integration": {
                "method": sc.method,
                "dt": sc.dt,
                "rtol": sc.rtol,
                "atol": sc.atol,
                "output_dt": sc.output_dt,
            },
            "duration_s": sc.duration,
            "runs": runs,
            "paper": sc.paper,
        }

    def table(self) -> str:
        tr = self.scenario.truth
        lines = [f"{self.scenario.name}: estimates at t = {self.scenario.duration:g} s"]
        lines.append(f"  {'':<14}" + "".join(f"{n:>9}" for n in PARAMETER_NAMES))
        lines.append(f"  {'truth':<14}" + "".join(f"{x:>9.4g}" for x in tr))
        for k, r in self.runs.items():
            lines.append(f"  {k:<14}" + "".join(f"{x:>9.4g}" for x in r.final_estimate))
        lines.append("")
        hdr = f"  {'run':<14}{'within 1 % from':>17}{'pos. err [m]':>14}{'att. err [deg]':>16}"
        hdr += f"{'rank 7 at':>11}{'sv_min>=0.1':>13}{'steps':>8}{'wall [s]':>10}"
        off = self.scenario.alpha_off_after is not None
        if off:
            hdr += f"{'alpha = 0 from':>16}"
        lines.append(hdr)
        for k, r in self.runs.items():
            s = r.summary(tr)
            w = s["time_within_1pct_s"]
            sm = s["sigma_min_first_reaches_0p1_s"]
            r7 = s["rank7_time_s"]
            ao = s["alpha_off_time_s"]
            lines.append(
                f"  {k:<14}{('never' if w is None else f'{w:.2f} s'):>17}{s['final_position_error_m']:>14.3e}"
                f"{s['final_attitude_error_deg']:>16.3f}{('-' if r7 is None else f'{r7:.4f} s'):>11}"
                f"{('-' if sm is None else f'{sm:.2f} s'):>13}{s['steps']:>8}{s['wall_time_s']:>10.3f}"
                + (f"{('-' if ao is None else f'{ao:.4f} s'):>16}" if off else "")
            )
        rz = realisability(tr)
        if not rz["realisable"]:
            lines.append(
                f"  note: the true mass properties are not a realisable rigid body: {'; '.join(rz['failures'])}"
            )
        for k, r in self.runs.items():
            f = realisability(r.final_estimate)
            if not f["realisable"]:
                lines.append(f"  note: the final estimate of {k} is not realisable: {'; '.join(f['failures'])}")
        if self.scenario.paper:
            lines.append("  thesis: " + ", ".join(f"{k} = {v}" for k, v in self.scenario.paper.items()))
        return "\n".join(lines)

    def save(self, out: str | Path, figures: bool = True) -> Path:
        """Write results.json and (with `figures`) the figures into `out`; returns the results.json path."""
        import json

        from .adaptive_plots import plot_all

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        p = out / "results.json"
        d = self.to_dict()
        d["figures"] = [f.name for f in plot_all(self, out)] if figures else []
        p.write_text(json.dumps(d, indent=1, default=_json_default))
        return p


def _json_default(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(type(x))


def run(
    scenario: Scenario | str | Path,
    alphas: list[float] | None = None,
    baseline: bool = True,
    baseline_only: bool = False,
    progress=None,
) -> AdaptiveResult:
    """Run a scenario: one closed loop per CL weight (the scenario's `learning.alpha`, or `alphas`) and the
    baseline (α = 0) beside them; `baseline_only` runs just the baseline. `progress(label, t)` is called with the
    run's label and the simulated time (return False to stop that run)."""
    sc = _scenario(scenario)
    todo = [] if baseline_only else list(sc.alphas if alphas is None else alphas)
    if any(not (a >= 0 and np.isfinite(a)) for a in todo):
        raise InputError(f"argument `alphas`: every alpha must be finite and >= 0, got {todo}")
    todo = [a for a in todo if a != 0]
    if baseline or baseline_only:
        todo.append(0.0)
    runs = {}
    for a in todo:
        cb = None if progress is None else (lambda t, _a=a: progress("baseline" if _a == 0 else f"alpha={_a:g}", t))
        r = simulate(sc, a, progress=cb)
        runs[r.label] = r
        if r.data["interrupted"]:
            break
    return AdaptiveResult(sc, runs)
