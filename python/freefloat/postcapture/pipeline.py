"""The post-capture reproduction end to end (Zhang, Yue, Yuan 2020): simulate a scenario, measure, identify
with both forms and both solvers; the initial-velocity sweep (Figs. 6-9) and the noise study."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from .. import models
from . import equations as eq
from .estimators import (
    METHODS,
    SOLVERS,
    _target_index,
    equation_residuals,
    identify_modified,
    identify_standard,
    parameter_names,
    truth_vector,
)
from .results import PostcaptureResult
from .scenario import DEFAULT_NOISE, Scenario, load_scenario
from .simulation import measure, simulate


def identify(model, meas: eq.Measurements, sc: Scenario, methods=METHODS, timings=None) -> PostcaptureResult:
    planar = model.joint_types[0] == "planar"
    base, target = 0, _target_index(model)
    truth = truth_vector(model, planar)
    hist, res, timings = {}, {}, dict(timings or {})
    for method in methods:
        t0 = time.perf_counter()
        if method == "momentum":
            paper_rows = eq.paper_momentum_rows(model, meas, base, target)
            std_rows = eq.standard_momentum_rows(model, meas, base, target)
        else:
            paper_rows = eq.paper_force_rows(model, meas, base, target)
            std_rows = eq.standard_force_rows(model, meas, base, target)
        timings[f"{method}_rows"] = time.perf_counter() - t0
        res[method] = equation_residuals(model, paper_rows, std_rows, planar, base, target)
        t0 = time.perf_counter()
        hist[(method, "modified_rls")] = (paper_rows.t, identify_modified(model, paper_rows, sc, planar))
        hist[(method, "standard_rls")] = (
            std_rows.t,
            identify_standard(model, std_rows, sc, planar, project=sc.project),
        )
        timings[f"{method}_estimators"] = time.perf_counter() - t0
    return PostcaptureResult(sc, parameter_names(planar), truth, hist, timings, res)


def run(sc: Scenario | str, methods=METHODS, seed: int | None = 0, progress=None) -> PostcaptureResult:
    """Simulate the scenario and identify with both forms and both solvers."""
    if not isinstance(sc, Scenario):
        sc = load_scenario(sc)
    m = models.load(sc.model)
    _target_index(m)
    t0 = time.perf_counter()
    sim = simulate(sc, m)
    t_sim = time.perf_counter() - t0
    if progress:
        progress("simulated")
    rng = np.random.default_rng(seed) if sc.noise else None
    if sc.sensors is not None:
        sc = dataclasses.replace(sc, sensor_seed=0 if seed is None else int(seed))
    t0 = time.perf_counter()
    meas = measure(m, sim, sc, rng)
    t_meas = time.perf_counter() - t0
    res = identify(m, meas, sc, methods, timings={"simulation": t_sim, "measurements": t_meas})
    _spacecraft_extras(m, sim, sc, res)
    if progress:
        progress("identified")
    return res


def _spacecraft_extras(m, sim: dict, sc: Scenario, res: PostcaptureResult) -> None:
    """The base's truth over time, the propellant used, the balance checks and the tracking summary of a run
    with actuators/sensors (results.json)."""
    from . import spacecraft

    planar = m.joint_types[0] == "planar"
    res.truth_history = spacecraft.truth_history(m, sim, planar, _target_index(m))
    if sc.actuators:
        res.extra["actuators"] = sc.actuators
        res.extra.update(spacecraft.balances(m, sim, sc))
        mp = np.asarray(sim.get("propellant"), float)
        if mp.size:
            step = max(1, int(round(0.1 / sc.dt)))
            res.extra["propellant_history"] = {
                "tanks": [tk.get("name", f"tank{k}") for k, tk in enumerate(sc.actuators.get("tanks", []))],
                "t": np.asarray(sim["t"])[::step].tolist(),
                "kg": mp[::step].tolist(),
            }
    if sc.environment is not None:
        res.extra["environment"] = repr(sc.environment)
    if sc.sensors is not None:
        res.extra["sensors"] = {"set": sc.sensors.to_dict(), "seed": sc.sensor_seed}
    if res.truth_history is not None:
        res.extra["base_truth_history"] = {
            "names": [n for n in res.names if len(n) > 1 and n[1] == "1"],
            "t": res.truth_history[0][:: max(1, int(round(1.0 / sc.dt)))].tolist(),
            "values": res.truth_history[1][:: max(1, int(round(1.0 / sc.dt))), : len(res.names) // 2].tolist(),
        }
        res.extra["tracking"] = spacecraft.tracking(res, sc)


# -- initial-velocity sweep (Figs. 6-9) ----------------------------------------------------------------
def sweep(sc: Scenario, velocities=None, progress=None) -> dict:
    """Relative error of every parameter at the end of the run (the paper: 60 s) for each initial base
    velocity; both methods, both solvers."""
    vels = np.asarray(velocities if velocities is not None else sc.sweep["velocities"], float)
    out = {"velocities": vels.tolist(), "errors": {}}
    names = None
    for k, vel in enumerate(vels):
        res = run(sc.with_base_velocity(vel))
        names = res.names
        for method in METHODS:
            for solver in SOLVERS:
                out["errors"].setdefault(f"{method}/{solver}", []).append(res.rel_error(method, solver).tolist())
        if progress:
            progress(k + 1, len(vels))
    out["names"] = names
    return out


# -- noise study --------------------------------------------------------------------------------------
def noise_study(sc: Scenario, scales=(0.0, 0.01, 0.1, 1.0), seeds=(0, 1, 2)) -> dict:
    """Relative error at the end of the run for DEFAULT_NOISE × scale (the paper has no noise), the
    median over seeds, per method/solver and parameter."""
    import copy

    out = {"levels": [], "names": None}
    for scale in scales:
        s = copy.deepcopy(sc)
        s.noise = {k: v * scale for k, v in DEFAULT_NOISE.items()} if scale > 0 else None
        errs = {}
        for seed in seeds if scale > 0 else seeds[:1]:
            res = run(s, seed=seed)
            out["names"] = res.names
            for method in METHODS:
                for solver in SOLVERS:
                    errs.setdefault(f"{method}/{solver}", []).append(res.rel_error(method, solver))
        out["levels"].append(
            {"scale": scale, "noise": s.noise, "median_error": {k: np.median(v, 0).tolist() for k, v in errs.items()}}
        )
    return out
