"""Concurrent-learning estimation of every body's mass properties of a spacecraft-mounted manipulator (Valverde
2018, ch. 9): the stacked Newton–Euler equations 𝐑𝐌 = 𝐅 with the known joint (reaction + actuation) wrenches, the
data stack of Algorithms 3 and 4, the estimation law (9.15) and the "aggressive" SVD gain (9.22-9.27), or its
noise-robust truncated form (`gain="truncated"`: a weak direction is accelerated only where the data outweigh their
noise, docs/identification.md).

    from freefloat.identification import concurrent
    res = concurrent.run("valverde_ch9_two_arm")          # the whole 10 s run in the engine
    print(res.table()); res.save("out/")                  # results.json + Figs. 9.1-9.4

    est = ConcurrentLearningEstimator(model.nbodies, m0)  # or drive it from your own loop:
    est.add_state(model, q, v, tau)                       # one data point from a state (or add_sample(R, F))
    est.step(dt); est.estimate; est.singular_values

Parameters per body: [I11, I12, I13, I22, I23, I33, m] (inertia about the CoM in body axes, mass), bodies in
model order. Every number is computed in the engine (`crates/freefloat-core/src/estimation/concurrent/`)."""

from __future__ import annotations

import json
import time
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import _core
from .._core import InputError
from ..dq.regressor import PARAM_NAMES

__all__ = [
    "PARAM_NAMES",
    "ClResult",
    "ClScenario",
    "ConcurrentLearningEstimator",
    "GAINS",
    "load_scenario",
    "parameter_scales",
    "realisable",
    "run",
    "time_within",
]

#: the SVD gains: the thesis' (9.27) (the default) and the truncated one (9.27') that accelerates a weak direction only
#: when the estimate's residual along it is at least `kappa` noise standard deviations
GAINS = ("thesis", "truncated")
#: default κ of the truncated gain (the engine's `KAPPA`)
KAPPA = 6.0


def realisable(v) -> bool:
    """Whether a 7-parameter estimate is a rigid body: m > 0, inertia positive definite, triangle inequalities
    (the engine's one test; `freefloat.control.realisability(v)` says which condition fails)."""
    v = np.asarray(v, dtype=float)
    if v.shape != (7,) or not np.all(np.isfinite(v)):
        return False
    return bool(_core.inertia_realisability(v)["realisable"])


class ConcurrentLearningEstimator:
    """The estimator of Valverde 2018 ch. 9 for `nbodies` bodies, driven from your own simulation loop.

    `add_sample(R, F)` offers one data point (Algorithm 3 while `time < t_th`; R as (B, 8, 7) per-body blocks or the
    (8B, 7B) block-diagonal 𝐑 of (9.9), F as (B, 8) or (8B,)); `add_state(model, q, v, tau)` builds that point
    from a multibody state with the engine's dual-quaternion dynamics; `step(dt)` advances the estimate by one RK4
    step of (9.15), or of (9.23) with the SVD gain once `time >= t_th2` (with `aggressive`). The thesis' values
    are the defaults (§9.5). `gain="truncated"` keeps (9.27) only for the directions whose data reach `kappa` times
    the stored data's noise estimate (`noise_sigma`), the others at the plain law's rate (`gain_withheld` counts
    them). Bad input raises InputError naming the argument; a step that would make the estimate non-finite or RK4
    unstable raises instead of returning NaN."""

    def __init__(
        self,
        nbodies: int,
        m0,
        *,
        ns: int = 10,
        sigma_th: float = 0.001,
        t_th: float = 5.0,
        aggressive: bool = True,
        t_th2: float = 4.9,
        sigma_th2: float = 0.5,
        sigma_new: float = 100.0,
        gain: str = "thesis",
        kappa: float = KAPPA,
        seed: int = 1,
    ):
        m0 = np.ascontiguousarray(m0, dtype=float).ravel()
        self._core = _core.ConcurrentEstimator(
            int(nbodies),
            m0,
            ns=int(ns),
            sigma_th=float(sigma_th),
            t_th=float(t_th),
            aggressive=bool(aggressive),
            t_th2=float(t_th2),
            sigma_th2=float(sigma_th2),
            sigma_new=float(sigma_new),
            gain=str(gain),
            kappa=float(kappa),
            seed=int(seed),
        )
        self._warned: set[int] = set()

    def add_sample(self, R, F) -> str:
        """Offer (𝐑_k, 𝐅_k); returns 'appended', 'replaced', 'rejected', 'full' or 'ignored' (time >= t_th)."""
        return self._core.add_sample(np.asarray(R, dtype=float), np.asarray(F, dtype=float))

    def add_state(self, model, q, v, tau, wrench_noise: float = 0.0, rate_noise: float = 0.0, seed: int = 7) -> str:
        """Offer the data point of the multibody state (q, v) under generalized forces `tau` (free base, no
        gravity): per-body regressors from the CoM twists and their rates, wrenches from the joint wrenches."""
        R, F, _, _ = sample(model, q, v, tau, wrench_noise, rate_noise, seed)
        return self.add_sample(R, F)

    def step(self, dt: float) -> None:
        self._core.step(float(dt))

    @property
    def estimate(self) -> np.ndarray:
        """Current estimate, 7 per body."""
        return self._core.estimate

    @property
    def singular_values(self) -> np.ndarray:
        """The 7B singular values of Σ𝐑ᵀ𝐑, descending."""
        return self._core.singular_values

    @property
    def block_singular_values(self) -> np.ndarray:
        """(B, 7): each body's block's singular values (the 7B values are their union)."""
        return self._core.block_singular_values

    rr = property(lambda self: self._core.rr, doc="(B, 7, 7) diagonal blocks of RR = Σ𝐑_kᵀ𝐑_k.")
    rf = property(lambda self: self._core.rf, doc="(B, 7) blocks of Rf = Σ𝐑_kᵀ𝐅_k.")
    gain = property(lambda self: self._core.gain, doc="(B, 7, 7) blocks of the gain K (identity before t_th2).")
    noise_sigma = property(
        lambda self: self._core.noise_sigma,
        doc="(B,) noise estimate σ̂ = ρ/√(n − r) of the stored data per body (inf without redundancy).",
    )
    gain_withheld = property(
        lambda self: np.asarray(self._core.gain_withheld),
        doc="(B,) directions the truncated gain left at the plain rate when it was last formed (0 for the thesis).",
    )
    stack_size = property(lambda self: self._core.stack_size, doc="Stored points N_c.")
    gain_active = property(lambda self: self._core.gain_active)

    @property
    def time(self) -> float:
        return self._core.time

    @time.setter
    def time(self, t: float) -> None:
        self._core.time = float(t)

    def realisable(self) -> list[bool]:
        """Per body: whether the current estimate is a rigid body (warns once per body that is not)."""
        est = self.estimate.reshape(-1, 7)
        ok = [realisable(e) for e in est]
        for i, good in enumerate(ok):
            if not good and i not in self._warned:
                self._warned.add(i)
                warnings.warn(f"the estimate of body {i} is not a realisable rigid body", stacklevel=2)
        return ok


def sample(model, q, v, tau, wrench_noise: float = 0.0, rate_noise: float = 0.0, seed: int = 7):
    """One data point from a multibody state: (R (B, 8, 7), F (B, 8), twists (B, 8), twist rates (B, 8))."""
    core = getattr(model, "_core", model)
    return _core.cl_sample(
        core,
        np.ascontiguousarray(q, dtype=float),
        np.ascontiguousarray(v, dtype=float),
        np.ascontiguousarray(tau, dtype=float),
        wrench_noise=float(wrench_noise),
        rate_noise=float(rate_noise),
        noise_seed=int(seed),
    )


# ------------------------------------------------------------------------------------------------------------
# Scenario files (kind: identify_cl)

_ESTIMATOR_KEYS = {
    "ns": int,
    "sigma_th": float,
    "t_th": float,
    "aggressive": bool,
    "t_th2": float,
    "sigma_th2": float,
    "sigma_new": float,
    "gain": str,
    "kappa": float,
    "seed": int,
}
_EXCITATION_KEYS = {"amplitude": float, "frequency": float, "phase": float, "t_start": float, "t_end": float}


@dataclass
class ClScenario:
    """A chapter-9 run: robot, initial state, excitation, estimator settings, studies."""

    name: str
    description: str
    model: object
    q0: np.ndarray
    v0: np.ndarray
    m0: np.ndarray
    dt: float = 0.01
    duration: float = 10.0
    estimator: dict = field(default_factory=dict)
    excitation: dict = field(default_factory=dict)
    ns_sweep: list = field(default_factory=lambda: [10, 50, 100, 200, 300])
    wrench_noise_levels: list = field(default_factory=list)
    rate_noise_levels: list = field(default_factory=list)
    noise_seed: int = 7
    source: str = ""


def _err(source: str, key: str, msg: str) -> InputError:
    return InputError(f"{source}: key '{key}': {msg}")


def _num(source, key, x, kind=float):
    if kind is str:  # the gain: one of GAINS
        if x not in GAINS:
            raise _err(source, key, f"expected one of {', '.join(GAINS)}, got {x!r}")
        return x
    if kind is bool:
        if not isinstance(x, bool):
            raise _err(source, key, f"expected true or false, got {x!r}")
        return x
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise _err(source, key, f"expected a number, got {x!r}")
    if kind is int:
        if float(x) != int(x):
            raise _err(source, key, f"expected an integer, got {x!r}")
        return int(x)
    if not np.isfinite(x):
        raise _err(source, key, f"expected a finite number, got {x!r}")
    return float(x)


def _section(d, source, key, allowed) -> dict:
    sec = d.get(key, {}) or {}
    if not isinstance(sec, dict):
        raise _err(source, key, f"expected a mapping, got {type(sec).__name__}")
    out = {}
    for k, x in sec.items():
        if k not in allowed:
            if key == "estimator" and k == "initial_estimate":
                continue
            raise _err(source, f"{key}.{k}", f"unknown key (known: {', '.join(allowed)})")
        out[k] = _num(source, f"{key}.{k}", x, allowed[k])
    return out


def _seven(source, key, x) -> np.ndarray:
    if not isinstance(x, list) or len(x) != 7:
        raise _err(source, key, f"expected 7 numbers [I11, I12, I13, I22, I23, I33, m], got {x!r}")
    return np.array([_num(source, f"{key}[{i}]", y) for i, y in enumerate(x)])


def load_scenario(spec) -> ClScenario:
    """Read a `kind: identify_cl` scenario (built-in name or .yaml path); errors name the file and the key."""
    from ..io import scenario_files
    from ..models import load as load_model

    d, source = scenario_files.read(spec, kind="identify_cl")
    known = {"kind", "name", "description", "model", "duration", "dt", "initial", "excitation", "estimator", "studies"}
    for k in d:
        if k not in known:
            raise _err(source, k, f"unknown key (known: {', '.join(sorted(known))})")
    if "model" not in d:
        raise _err(source, "model", "missing (a built-in robot name or a model file)")
    try:
        p = Path(str(d["model"]))
        if p.suffix in (".yaml", ".yml"):
            from ..model import Model

            model = Model.from_yaml(p if p.is_absolute() or not Path(source).is_file() else Path(source).parent / p)
        else:
            model = load_model(str(d["model"]))
    except (_core.InputError, _core.ModelError, FileNotFoundError) as e:
        raise _err(source, "model", str(e)) from None
    dt = _num(source, "dt", d.get("dt", 0.01))
    duration = _num(source, "duration", d.get("duration", 10.0))
    # initial state
    q0, v0 = model.neutral(), np.zeros(model.nv)
    ini = d.get("initial", {}) or {}
    if not isinstance(ini, dict):
        raise _err(source, "initial", "expected a mapping")
    qlab, vlab = model.q_labels(), model.v_labels()
    for k, x in ini.items():
        if k not in ("joints_deg", "joints", "rates"):
            raise _err(source, f"initial.{k}", "unknown key (known: joints_deg, joints, rates)")
        if not isinstance(x, dict):
            raise _err(source, f"initial.{k}", "expected a mapping of joint name to value")
        labels = vlab if k == "rates" else qlab
        for name, val in x.items():
            if name not in labels:
                raise _err(source, f"initial.{k}.{name}", f"no such coordinate (known: {', '.join(labels)})")
            val = _num(source, f"initial.{k}.{name}", val)
            if k == "rates":
                v0[labels.index(name)] = val
            else:
                q0[labels.index(name)] = np.deg2rad(val) if k == "joints_deg" else val
    est = _section(d, source, "estimator", _ESTIMATOR_KEYS)
    exc = _section(d, source, "excitation", _EXCITATION_KEYS)
    # initial estimate: per body name, with a default
    ie = (d.get("estimator") or {}).get("initial_estimate", {"default": [0.1, 0.0, 0.0, 0.1, 0.0, 0.1, 1.0]})
    if not isinstance(ie, dict):
        raise _err(source, "estimator.initial_estimate", "expected a mapping of body name (or 'default') to 7 numbers")
    m0 = np.zeros((model.nbodies, 7))
    default = _seven(source, "estimator.initial_estimate.default", ie["default"]) if "default" in ie else None
    for i, b in enumerate(model.body_names):
        if b in ie:
            m0[i] = _seven(source, f"estimator.initial_estimate.{b}", ie[b])
        elif default is not None:
            m0[i] = default
        else:
            raise _err(source, "estimator.initial_estimate", f"no value for body '{b}' and no 'default'")
    for b in ie:
        if b != "default" and b not in model.body_names:
            raise _err(
                source, f"estimator.initial_estimate.{b}", f"no such body (bodies: {', '.join(model.body_names)})"
            )
    st = d.get("studies", {}) or {}
    if not isinstance(st, dict):
        raise _err(source, "studies", "expected a mapping")
    for k in st:
        if k not in ("ns_sweep", "wrench_noise", "rate_noise", "noise_seed"):
            raise _err(source, f"studies.{k}", "unknown key (known: ns_sweep, wrench_noise, rate_noise, noise_seed)")

    def nums(key, kind=float):
        x = st.get(key, [])
        if not isinstance(x, list):
            raise _err(source, f"studies.{key}", "expected a list")
        return [_num(source, f"studies.{key}[{i}]", y, kind) for i, y in enumerate(x)]

    sc = ClScenario(
        name=str(d.get("name", Path(str(spec)).stem)),
        description=str(d.get("description", "")).strip(),
        model=model,
        q0=q0,
        v0=v0,
        m0=m0.ravel(),
        dt=dt,
        duration=duration,
        estimator=est,
        excitation=exc,
        ns_sweep=nums("ns_sweep", int) if "ns_sweep" in st else [10, 50, 100, 200, 300],
        wrench_noise_levels=nums("wrench_noise"),
        rate_noise_levels=nums("rate_noise"),
        noise_seed=_num(source, "studies.noise_seed", st.get("noise_seed", 7), int),
        source=source,
    )
    try:
        _core.ConcurrentEstimator(model.nbodies, sc.m0, **est)  # every estimator setting checked now
    except InputError as e:
        raise InputError(f"{source}: key 'estimator': {e}") from None
    return sc


# ------------------------------------------------------------------------------------------------------------
# Results


def parameter_scales(truth) -> np.ndarray:
    """The scale each parameter's error is measured against: |truth| where nonzero, else (a product of inertia
    whose truth is 0) the body's largest principal moment."""
    t = np.asarray(truth, dtype=float).reshape(-1, 7)
    s = np.abs(t).copy()
    big = np.max(np.abs(t[:, [0, 3, 5]]), axis=1)
    for i in range(len(t)):
        s[i, s[i] == 0] = big[i] if big[i] > 0 else 1.0
    return s.ravel()


def time_within(t, estimates, truth, rel: float = 0.01):
    """The time after which every estimate stays within `rel` of its scale (`parameter_scales`), or None."""
    err = np.abs(np.asarray(estimates) - np.asarray(truth)) / parameter_scales(truth)
    bad = np.any(err > rel, axis=1)
    if bad[-1]:
        return None
    idx = np.flatnonzero(bad)
    return float(t[0]) if len(idx) == 0 else float(t[idx[-1] + 1])


@dataclass
class ClResult:
    """One chapter-9 run: time series, final estimate, and what the thesis' claims become here."""

    scenario: ClScenario
    settings: dict
    t: np.ndarray
    estimates: np.ndarray
    singular_values: np.ndarray
    block_singular_values: np.ndarray
    offers: np.ndarray
    truth: np.ndarray
    final_estimate: np.ndarray
    realisable: list
    max_residual: float
    stack_changes: int
    stack_trials: int
    interrupted: bool
    wall_time_s: float
    noise_sigma: np.ndarray = field(default_factory=lambda: np.zeros(0))
    gain_withheld: list = field(default_factory=list)
    extra: dict = field(default_factory=dict)

    @property
    def errors(self) -> np.ndarray:
        """(n, 7B) estimation errors relative to each parameter's scale."""
        return (self.estimates - self.truth) / parameter_scales(self.truth)

    @property
    def time_within_1pct_s(self):
        return time_within(self.t, self.estimates, self.truth, 0.01)

    @property
    def rank(self) -> int:
        """Numerical rank of Σ𝐑ᵀ𝐑 at the end (singular values of the stacked data above 1e-13 of the largest)."""
        s = np.sqrt(np.maximum(self.singular_values[-1], 0))
        return int(np.sum(s > 1e-13 * max(s.max(), 1e-300)))

    @property
    def last_stack_change_s(self):
        """Time of the last change of the stored data (the singular values are constant after it)."""
        k = np.flatnonzero(np.isin(self.offers, (1, 2)))
        return None if len(k) == 0 else float(self.t[k[-1]])

    @property
    def first_nonzero_sv_s(self):
        k = np.flatnonzero(self.singular_values[:, 0] > 0)
        return None if len(k) == 0 else float(self.t[k[0]])

    def sup_error(self, t_from: float = 9.7) -> float:
        """Fig. 9.5's metric: sup over t_k ≥ t_from of the largest relative error over the parameters."""
        sel = self.t >= t_from - 1e-9
        return float(np.max(np.abs(self.errors[sel]))) if np.any(sel) else float("nan")

    def error_decay_rate(self, window: float = 3.0) -> float:
        """How fast the largest relative error fell over the last `window` seconds, ln(e(T − window)/e(T)) / window
        (1/s). Once the stack is frozen the law is linear with constant coefficients, so this is the rate of the
        slowest direction still carrying error: the smallest σ_i ≥ σ_th,2 of the stacked sum under (9.27) with the
        thesis' σ_th,2 (docs/identification.md, "Accuracy against N_s"); near 0 once the error is at its floor."""
        e = np.max(np.abs(self.errors), axis=1)
        ia = int(np.argmin(np.abs(self.t - (self.t[-1] - window))))
        if self.t[-1] - self.t[ia] <= 0 or not (e[ia] > 0 and e[-1] > 0):
            return float("nan")
        return float(np.log(e[ia] / e[-1]) / (self.t[-1] - self.t[ia]))

    def to_dict(self) -> dict:
        fe = self.final_estimate
        rel = np.abs(fe - self.truth) / parameter_scales(self.truth)
        d = {
            "scenario": self.scenario.name,
            "model": self.scenario.model.name,
            "bodies": list(self.scenario.model.body_names),
            "parameter_order": list(PARAM_NAMES),
            "settings": self.settings,
            "truth": self.truth.tolist(),
            "initial_estimate": self.scenario.m0.tolist(),
            "final_estimate": fe.tolist(),
            "final_relative_error": rel.tolist(),
            "max_final_relative_error": float(rel.max()),
            "tolerance_basis": "|truth| where nonzero, else the body's largest principal moment",
            "time_within_1pct_s": self.time_within_1pct_s,
            "all_within_1pct_at_end": bool(rel.max() <= 0.01),
            "rank_final": self.rank,
            "final_singular_values": self.singular_values[-1].tolist(),
            "first_nonzero_singular_value_s": self.first_nonzero_sv_s,
            "singular_values_constant_after_s": self.last_stack_change_s,
            "sup_error_9p7_to_10s": self.sup_error(9.7),
            "error_decay_rate_last_3s": self.error_decay_rate(3.0),
            "max_residual_RM_minus_F": None if not np.isfinite(self.max_residual) else self.max_residual,
            "noise_sigma_final": [float(x) if np.isfinite(x) else None for x in self.noise_sigma],
            "gain_withheld": [int(x) for x in self.gain_withheld],
            "realisable_final": list(self.realisable),
            "realisable_check": "temporary local check (m > 0, inertia PD, triangle inequality)",
            "stack_changes": self.stack_changes,
            "stack_trials": self.stack_trials,
            "interrupted": self.interrupted,
            "wall_time_s": self.wall_time_s,
        }
        d.update(self.extra)
        return d

    def table(self) -> str:
        names = self.scenario.model.body_names
        tr, fe = self.truth.reshape(-1, 7), self.final_estimate.reshape(-1, 7)
        sc = parameter_scales(self.truth).reshape(-1, 7)
        lines = [f"{'body':8s} {'param':5s} {'truth':>10s} {'estimate':>14s} {'rel. err':>10s}"]
        for i, b in enumerate(names):
            for j, p in enumerate(PARAM_NAMES):
                e = abs(fe[i, j] - tr[i, j]) / sc[i, j]
                lines.append(f"{b:8s} {p:5s} {tr[i, j]:10.4g} {fe[i, j]:14.8g} {e:10.2e}")
        w = self.time_within_1pct_s
        worst = self.to_dict()["max_final_relative_error"]
        lines.append(
            f"rank {self.rank}/{len(self.truth)}; singular values constant after "
            f"{self.last_stack_change_s} s; every estimate within 1 % from "
            f"{'never' if w is None else f'{w:.2f} s'}; max final rel. error {worst:.2e}; "
            f"max |R M - F| {self.max_residual:.2e}; run time {self.wall_time_s:.3f} s"
        )
        bad = [names[i] for i, ok in enumerate(self.realisable) if not ok]
        lines.append("every body's estimate is a realisable rigid body" if not bad else f"NOT realisable: {bad}")
        if self.settings.get("gain") == "truncated" and self.settings.get("aggressive", True):
            w = [int(x) for x in self.gain_withheld]
            lines.append(
                f"truncated gain (kappa {self.settings.get('kappa', KAPPA):g}): {sum(w)} weak directions left at the "
                f"plain law's rate (per body {w})"
            )
        return "\n".join(lines)

    def save(self, out, figures: bool = True) -> Path:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps(self.to_dict(), indent=2))
        if figures:
            from . import concurrent_plots

            concurrent_plots.run_figures(self, out)
        return out


def run(
    scenario,
    *,
    ns: int | None = None,
    wrench_noise: float = 0.0,
    rate_noise: float = 0.0,
    aggressive: bool | None = None,
    gain: str | None = None,
    kappa: float | None = None,
    noise_seed: int | None = None,
    progress=None,
) -> ClResult:
    """Run chapter 9 for `scenario` (a ClScenario, a built-in name or a .yaml path) entirely in the engine.
    `ns`, `aggressive`, `gain` ("thesis" or "truncated") and `kappa` override the scenario's estimator settings.
    `progress(t)` gets the simulated time (return False to stop; Ctrl-C stops too and keeps what was done)."""
    sc = scenario if isinstance(scenario, ClScenario) else load_scenario(scenario)
    est = dict(sc.estimator)
    if ns is not None:
        est["ns"] = int(ns)
    if aggressive is not None:
        est["aggressive"] = bool(aggressive)
    if gain is not None:
        est["gain"] = str(gain)
    if kappa is not None:
        est["kappa"] = float(kappa)
    t0 = time.perf_counter()
    r = _core.cl_run(
        sc.model._core,
        sc.q0,
        sc.v0,
        sc.m0,
        dt=sc.dt,
        t_final=sc.duration,
        wrench_noise=float(wrench_noise),
        rate_noise=float(rate_noise),
        noise_seed=int(sc.noise_seed if noise_seed is None else noise_seed),
        progress=progress,
        **est,
        **sc.excitation,
    )
    wall = time.perf_counter() - t0
    settings = {
        "ns": est.get("ns", 10),
        "sigma_th": est.get("sigma_th", 0.001),
        "t_th": est.get("t_th", 5.0),
        "aggressive": est.get("aggressive", True),
        "t_th2": est.get("t_th2", 4.9),
        "sigma_th2": est.get("sigma_th2", 0.5),
        "sigma_new": est.get("sigma_new", 100.0),
        "gain": est.get("gain", "thesis"),
        "kappa": est.get("kappa", KAPPA),
        "dt": sc.dt,
        "duration": sc.duration,
        "excitation": {"amplitude": 0.5, "frequency": 1.0, "phase": 0.0, "t_start": 2.0, "t_end": 3.0, **sc.excitation},
        "wrench_noise": wrench_noise,
        "rate_noise": rate_noise,
    }
    res = ClResult(
        scenario=sc,
        settings=settings,
        t=r["t"],
        estimates=r["estimates"],
        singular_values=r["singular_values"],
        block_singular_values=r["block_singular_values"],
        offers=r["offers"],
        truth=r["truth"],
        final_estimate=r["final_estimate"],
        realisable=list(r["realisable"]),
        max_residual=r["max_residual"],
        stack_changes=r["stack_changes"],
        stack_trials=r["stack_trials"],
        interrupted=r["interrupted"],
        wall_time_s=wall,
        noise_sigma=r["noise_sigma"],
        gain_withheld=list(r["gain_withheld"]),
    )
    bad = [sc.model.body_names[i] for i, ok in enumerate(res.realisable) if not ok]
    if bad:
        warnings.warn(f"the final estimate of {', '.join(bad)} is not a realisable rigid body", stacklevel=2)
    return res


def with_settings(sc: ClScenario, **kw) -> ClScenario:
    """A copy of `sc` with estimator settings changed."""
    return replace(sc, estimator={**sc.estimator, **kw})
