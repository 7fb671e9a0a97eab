"""Identification error by sensor class: each estimator of the package on telemetry from the sensor presets of
`freefloat.sensors` (`navigation`, `tactical`, `mems`), the error of mass, centre of mass and inertia after 10, 30
and 100 s, over noise seeds (docs/sensors.md, "Identification error by sensor class").

    from freefloat.identification import sensor_classes as scl
    rows = [scl.run("zhang", "tactical", seed) for seed in range(16)]   # one run: both forms of Zhang 2020
    print(scl.table(rows))                                             # median and 95th percentile

The campaign kind `sensor_classes` runs the same function on Dask; the built-in campaign
`sensor_class_monte_carlo` is the grid of every estimator and class over 16 seeds.

Estimators and what each run measures (the motion is simulated once per process and measured with the seed):

- `zhang`: Zhang, Yue, Yuan 2020 on the built-in `zhang2020_3d` capture (100 s; its motion is chaotic, and the
  force form's error depends on it: `MOTION_NUDGE`), the telemetry of the preset at 100 Hz (poses integrated by the
  fourth-order Hermite rule, `INTEGRATION`), standard RLS of the momentum form (about the moving base point) and
  of the force form (accelerations from the RTS smoother). Error of the target's mass mₙ, centre of mass b'ₙ and
  inertia I'ₙ.
- `naveen`: Naveen, Shah, Misra's minimal parameters of `naveen_dual_arm` along the shipped exciting trajectory
  (63 s, so the last horizon is its end), plain least squares and with the errors-in-variables bias removed (the
  telemetry declares its rate noise). Minimal parameters group the bodies' parameters, so the groups are by kind:
  mass is the base's mass (the only mass parameter), centre of mass the first moments of each body, inertia the
  inertia combinations of each body; the worst body counts.
- `cl`: Valverde 2018 ch. 9 concurrent learning on `valverde_ch9_two_arm` (run to 100 s; the excitation is the
  thesis' 2-3 s) with the thesis' SVD gain and with the truncated gain (docs/identification.md), the preset's
  gyro white noise per sample on the body twists and twist rates, and the preset's force/torque class (its force
  noise, N, on every wrench component) on the joint wrenches. Its centres of mass are known, so it has no
  centre-of-mass error. Worst body.

Each error is a relative norm: `‖θ̂ − θ‖ / ‖θ‖` over the group's parameters (the inertia as a 3×3 matrix where the
group is one, Frobenius norm), NaN when the estimator gave no estimate at that horizon (too few samples for the
least-squares rank)."""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings

import numpy as np

from .._core import InputError

__all__ = [
    "ESTIMATORS",
    "CLASSES",
    "HORIZONS",
    "QUANTITIES",
    "run",
    "summary",
    "horizons_of",
    "table",
    "table_rows",
    "fmt_error",
]

#: estimator -> its sub-estimators (the run reports both)
ESTIMATORS = {
    "zhang": ("zhang_momentum", "zhang_force"),
    "naveen": ("naveen_ls", "naveen_eiv"),
    "cl": ("cl_thesis", "cl_truncated"),
}
CLASSES = ("navigation", "tactical", "mems")
HORIZONS = (10.0, 30.0, 100.0)
QUANTITIES = ("mass", "com", "inertia")
#: the telemetry's pose rule in these runs: the fourth-order Hermite rule (the motions here have continuous
#: accelerations between samples, where it pays: docs/sensors.md, "Poses")
INTEGRATION = "hermite"


def _rel(est, truth) -> float:
    est, truth = np.asarray(est, float), np.asarray(truth, float)
    den = float(np.linalg.norm(truth))
    return float(np.linalg.norm(est - truth) / den) if den > 0 else float(np.linalg.norm(est - truth))


def _sym(v6) -> np.ndarray:
    """[xx, xy, xz, yy, yz, zz] -> 3×3."""
    xx, xy, xz, yy, yz, zz = v6
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


# -- Zhang, Yue, Yuan 2020 ----------------------------------------------------------------------------------
#: A nudged motion (`_zhang(..., nudge=k)`) has the scenario's initial velocities scaled by 1 + this times N(0, 1) per
#: component (drawn from k). The 3D capture's motion is chaotic: a one-ulp change of one initial velocity grows to
#: 1e-4 of the state in 20 s, so a nudge gives another sample of the motion. The study's runs use the scenario's own
#: motion (some nudged motions reach a singular arm configuration of the eq. 39 controller and are not valid
#: captures); the nudges measure how much the estimators' errors depend on the motion (docs/sensors.md).
MOTION_NUDGE = 1e-9


@functools.lru_cache(maxsize=4)
def _zhang_motion(nudge: int | None = None):
    from .. import models
    from .. import postcapture as pc

    sc = pc.load_scenario("zhang2020_3d")
    if nudge is not None:
        v0 = np.asarray(sc.v0, float)
        rng = np.random.default_rng(nudge)
        sc = dataclasses.replace(sc, v0=v0 * (1.0 + MOTION_NUDGE * rng.standard_normal(v0.shape)))
    m = models.load(sc.model)
    return sc, m, pc.simulate(sc, m)


def _zhang(sensor_class: str, seed: int, horizons, nudge: int | None = None) -> dict:
    from .. import postcapture as pc
    from .. import sensors

    sc, m, sim = _zhang_motion(nudge)
    s2 = dataclasses.replace(
        sc,
        sensors=dataclasses.replace(sensors.load(sensor_class), integration=INTEGRATION),
        sensor_seed=int(seed),
        measurement={"accelerations": "rts", "momentum_point": "base"},
    )
    res = pc.identify(m, pc.measure(m, sim, s2), s2, methods=("momentum", "force"))
    names = list(res.names)
    idx = {g: [names.index(n) for n in ns] for g, ns in _ZHANG_GROUPS.items()}
    out = {}
    for method in ("momentum", "force"):
        t, h = res.histories[(method, "standard_rls")]
        truth = res.truth_at(t)
        for T in horizons:
            k = int(np.searchsorted(t, T + 1e-9, side="right")) - 1
            key = f"zhang_{method}"
            if k < 0:
                for q in QUANTITIES:
                    out[f"{key}.{q}.{T:g}"] = math.nan
                continue
            est, tru = h[k], np.asarray(truth)[k] if np.ndim(truth) == 2 else np.asarray(truth)
            out[f"{key}.mass.{T:g}"] = _rel(est[idx["mass"]], tru[idx["mass"]])
            out[f"{key}.com.{T:g}"] = _rel(est[idx["com"]], tru[idx["com"]])
            out[f"{key}.inertia.{T:g}"] = _rel(_sym(est[idx["inertia"]]), _sym(tru[idx["inertia"]]))
    return out


_ZHANG_GROUPS = {
    "mass": ["mn"],
    "com": ["bnx", "bny", "bnz"],
    "inertia": ["Inxx", "Inxy", "Inxz", "Inyy", "Inyz", "Inzz"],
}


# -- Naveen, Shah, Misra --------------------------------------------------------------------------------------
@functools.lru_cache(maxsize=1)
def _naveen_motion():
    from .. import models
    from ..io.trajectory_files import load_trajectory
    from ..simulation import simulate_driven

    m = models.load("naveen_dual_arm")
    traj, joints = load_trajectory("naveen_exciting_trajectory")
    return m, simulate_driven(m, traj, joints, 1e-3)


def _naveen_groups(names) -> dict:
    """Indices of the minimal parameters by kind and body, from their names ('phi_m(7) base.m',
    'phi_m(16) L1.mcx', 'phi_m(11) L1.Ixx-Iyy', ...)."""
    groups = {"mass": {}, "com": {}, "inertia": {}}
    for i, n in enumerate(names):
        body, _, what = n.split(" ", 1)[1].partition(".")
        kind = "mass" if what == "m" else "com" if what.startswith("mc") else "inertia"
        groups[kind].setdefault(body, []).append(i)
    return groups


def _naveen(sensor_class: str, seed: int, horizons) -> dict:
    from .. import sensors
    from .identify import identify_minimal

    m, sim = _naveen_motion()
    run = {"t": sim.t, "q": sim.q, "v": sim.v, "momentum": sim.momentum}
    sset = dataclasses.replace(sensors.load(sensor_class), integration=INTEGRATION)
    tel = sensors.measure(m, run, sset, seed=int(seed)).require_telemetry()
    out = {}
    end = float(tel.t[-1])
    for T in horizons:
        keep = tel.t <= min(T, end) + 1e-9
        part = dataclasses.replace(
            tel,
            t=tel.t[keep],
            q=tel.q[keep],
            v=tel.v[keep],
            momentum=None if tel.momentum is None else tel.momentum[keep],
            wrench=None if tel.wrench is None else tel.wrench[keep],
        )
        for name, kw in (("naveen_ls", {}), ("naveen_eiv", {"rate_noise": tel.rate_noise})):
            try:
                with warnings.catch_warnings():
                    # plain LS on data that declare their noise, and a correction refused where the noise
                    # dominates a direction (then the plain estimate is returned): both recorded, not warned
                    warnings.simplefilter("ignore")
                    res = identify_minimal(m, part, **kw)
            except InputError:  # too short for the rank
                for q in QUANTITIES:
                    out[f"{name}.{q}.{T:g}"] = math.nan
                continue
            if name == "naveen_eiv":
                out[f"naveen_eiv.applied.{T:g}"] = res.fit.method.endswith("errors-in-variables bias compensation")
            truth = res.truth_values(m)
            for q, bodies in _naveen_groups(res.names).items():
                errs = [_rel(res.estimate[i], truth[i]) for i in bodies.values()]
                out[f"{name}.{q}.{T:g}"] = max(errs) if errs else math.nan
    out["naveen_end_s"] = end
    return out


# -- Valverde 2018 ch. 9 --------------------------------------------------------------------------------------
def _cl(sensor_class: str, seed: int, horizons) -> dict:
    from .. import sensors
    from . import concurrent as cl

    sc = cl.load_scenario("valverde_ch9_two_arm")
    sc = dataclasses.replace(sc, duration=max(float(max(horizons)), sc.duration))
    gyro = next(s for s in sensors.load(sensor_class).to_dicts() if s["type"] == "gyro")
    rate_sigma = float(gyro["noise_density"]) * math.sqrt(1.0 / sc.dt)  # white part per sample
    wrench_sigma = float(sensors.FORCE_TORQUE.force_noise)
    out = {}
    for gain in ("thesis", "truncated"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # unrealisable estimates are the result here, not a failure
            r = cl.run(sc, wrench_noise=wrench_sigma, rate_noise=rate_sigma, noise_seed=int(seed), gain=gain)
        truth = np.asarray(r.truth).reshape(-1, 7)
        for T in horizons:
            k = int(np.searchsorted(r.t, T + 1e-9, side="right")) - 1
            est = np.asarray(r.estimates[k]).reshape(-1, 7)
            out[f"cl_{gain}.mass.{T:g}"] = max(_rel(e[6], t[6]) for e, t in zip(est, truth))
            out[f"cl_{gain}.com.{T:g}"] = math.nan  # known in ch. 9
            out[f"cl_{gain}.inertia.{T:g}"] = max(_rel(_sym(e[:6]), _sym(t[:6])) for e, t in zip(est, truth))
    out["cl_rate_sigma"] = rate_sigma
    out["cl_wrench_sigma"] = wrench_sigma
    return out


_RUNNERS = {"zhang": _zhang, "naveen": _naveen, "cl": _cl}


def run(estimator: str, sensor_class: str, seed: int = 0, horizons=HORIZONS) -> dict:
    """One run: `estimator` (zhang, naveen, cl) on telemetry from the preset `sensor_class` with the noise seed
    `seed` -> {"<sub-estimator>.<mass|com|inertia>.<horizon>": relative error, ..., "estimator", "sensor_class"}."""
    if estimator not in _RUNNERS:
        raise InputError(f"estimator: expected one of {', '.join(_RUNNERS)}, got {estimator!r}")
    if sensor_class not in CLASSES:
        raise InputError(f"sensor_class: expected one of {', '.join(CLASSES)}, got {sensor_class!r}")
    hs = tuple(float(h) for h in horizons)
    if not hs or any(not (math.isfinite(h) and h > 0) for h in hs):
        raise InputError(f"horizons: expected positive numbers of seconds, got {list(horizons)!r}")
    return {**_RUNNERS[estimator](sensor_class, int(seed), hs), "estimator": estimator, "sensor_class": sensor_class}


def horizons_of(rows) -> tuple:
    """The horizons [s] the rows hold errors for (from keys '<sub-estimator>.mass.<horizon>')."""
    subs = {x for v in ESTIMATORS.values() for x in v}
    hs = set()
    for r in rows:
        for k in r:
            part = k.split(".", 2)
            if len(part) == 3 and part[0] in subs and part[1] == "mass":
                hs.add(float(part[2]))
    return tuple(sorted(hs))


def summary(rows, horizons=HORIZONS) -> list[dict]:
    """Median and 95th percentile over the runs of every sub-estimator, class, quantity and horizon. Each row is a
    run's output with its `estimator` and `sensor_class` (as the campaign kind records them); missing or None
    values (a campaign dataset holds every column in every row) count as no estimate."""
    out = []
    for est, subs in ESTIMATORS.items():
        for cls in CLASSES:
            mine = [r for r in rows if r.get("estimator") == est and r.get("sensor_class") == cls]
            if not mine:
                continue
            for sub in subs:
                for q in QUANTITIES:
                    for T in horizons:
                        v = [r.get(f"{sub}.{q}.{T:g}") for r in mine]
                        x = np.array([math.nan if a is None else a for a in v], float)
                        ok = x[np.isfinite(x)]
                        out.append(
                            {
                                "estimator": sub,
                                "sensor_class": cls,
                                "quantity": q,
                                "horizon_s": T,
                                "runs": len(mine),
                                "finite": int(ok.size),
                                "median": float(np.median(ok)) if ok.size else math.nan,
                                "p95": float(np.percentile(ok, 95)) if ok.size else math.nan,
                            }
                        )
    return out


def fmt_error(x: float) -> str:
    """A relative error as a percentage (or a factor from 10 up); — for none."""
    if not math.isfinite(x):
        return "—"
    return f"{100 * x:.2g} %" if x < 10 else f"{x:.2g}×"


def table_rows(rows, horizons=HORIZONS) -> list[list]:
    """[sub-estimator, class, quantity, "median / p95" per horizon..., runs] for every group the rows hold."""
    s = summary(rows, horizons)
    out = []
    for subs in ESTIMATORS.values():
        for sub in subs:
            for cls in CLASSES:
                for q in QUANTITIES:
                    by_h = {
                        x["horizon_s"]: x
                        for x in s
                        if (x["estimator"], x["sensor_class"], x["quantity"]) == (sub, cls, q)
                    }
                    if not by_h:
                        continue
                    cells = [f"{fmt_error(by_h[h]['median'])} / {fmt_error(by_h[h]['p95'])}" for h in horizons]
                    out.append([sub, cls, q, *cells, by_h[horizons[0]]["runs"]])
    return out


def table(rows, horizons=HORIZONS) -> str:
    """Markdown of `table_rows`: median / 95th percentile of each quantity at each horizon."""
    head = ["estimator", "class", "quantity", *[f"{h:g} s" for h in horizons], "runs"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in table_rows(rows, horizons)]
    return "\n".join(lines)
