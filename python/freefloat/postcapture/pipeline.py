"""The post-capture reproduction end to end (Zhang, Yue, Yuan 2020): simulate a scenario, measure, identify
with both forms and both solvers; the initial-velocity sweep (Figs. 6-9) and the noise study."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from .. import models
from .._core import Interrupted
from . import equations as eq
from . import spacecraft
from .estimators import (
    METHODS,
    SOLVERS,
    equation_residuals,
    identify_modified,
    identify_standard,
    parameter_names,
    target_index,
    truth_vector,
)
from .results import PostcaptureResult
from .scenario import DEFAULT_NOISE, Scenario, load_scenario
from .simulation import measure, simulate

#: after a Ctrl-C in the simulation, the measurements and estimators over the partial motion run only if they are
#: expected to take at most POST_BUDGET_S; expected cost = POST_COST_RATIO × the simulation's wall time
#: (measured: 0.045-0.055 for the 2D scenarios, 0.032 for 3D; the ratio is kept conservative)
POST_COST_RATIO = 0.08
POST_BUDGET_S = 0.5


def identify(model, meas: eq.Measurements, sc: Scenario, methods=METHODS, timings=None) -> PostcaptureResult:
    """Both solvers for each method over the measurements. A Ctrl-C here raises `freefloat.Interrupted` whose
    `partial` is the result with the estimator histories finished before it (`interrupted` set)."""
    planar = model.joint_types[0] == "planar"
    base, target = 0, target_index(model)
    truth = truth_vector(model, planar)
    hist, res, timings = {}, {}, dict(timings or {})
    try:
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
    except KeyboardInterrupt as e:
        done = PostcaptureResult(sc, parameter_names(planar), truth, hist, timings, res)
        done.interrupted = f"stopped in the estimators ({e or 'Ctrl-C'}); {len(hist)} of {2 * len(methods)} finished"
        done.t_end = float(meas.t[-1]) if len(meas.t) else 0.0
        raise _interrupted(done) from None
    return PostcaptureResult(sc, parameter_names(planar), truth, hist, timings, res)


def run(sc: Scenario | str, methods=METHODS, seed: int | None = 0, progress=None) -> PostcaptureResult:
    """Simulate the scenario and identify with both forms and both solvers.

    Ctrl-C stops it within a second and raises `freefloat.Interrupted` whose `partial` is a PostcaptureResult
    (`interrupted` set, `simulation` the simulated samples): stopped in the simulation, the motion up to the
    stop (the same samples as the first part of an uninterrupted run), its measurements and the four
    estimators run over them (when that takes at most POST_BUDGET_S; else the motion alone, `histories`
    empty); stopped in the estimators, the whole motion and the estimators that finished."""
    if not isinstance(sc, Scenario):
        sc = load_scenario(sc)
    m = models.load(sc.model)
    target_index(m)
    t0 = time.perf_counter()
    stopped = None
    try:
        sim = simulate(sc, m)
    except Interrupted as e:
        sim, stopped = e.partial, str(e)
        step = int(round(sc.sample_period / sc.dt))
        n = 0 if sim is None else len(sim["t"])
        keep = ((n - 1) // step) * step + 1 if n else 0  # up to the last complete sample period
        t_sim = time.perf_counter() - t0
        # the measurements and estimators over the partial motion cost ~3-6 % of its simulation (2D and 3D
        # scenarios): run them only when that stays within the budget, so that the exit follows the Ctrl-C
        # within a second; otherwise the simulated part alone is kept (and said so)
        skip = None
        if keep < 3 * step + 1:  # fewer than the four samples the estimators start from: nothing to identify
            skip = "too short for the estimators"
        elif POST_COST_RATIO * t_sim > POST_BUDGET_S:
            skip = (
                f"estimators not run on the partial motion (they would take ~{POST_COST_RATIO * t_sim:.1f} s after "
                "the Ctrl-C); the simulated part is kept"
            )
        if skip is not None:
            part = PostcaptureResult(sc, [], np.zeros(0), {}, {"simulation": t_sim})
            part.interrupted, part.simulation = f"{stopped}; {skip}", sim
            part.t_end = float(sim["t"][-1]) if n else 0.0
            raise _interrupted(part) from None
        sim = {k: (v[:keep] if isinstance(v, np.ndarray) and v.ndim and len(v) == n else v) for k, v in sim.items()}
    t_sim = time.perf_counter() - t0
    if progress:
        progress("simulated")
    rng = np.random.default_rng(seed) if sc.noise else None
    if sc.sensors is not None:
        sc = dataclasses.replace(sc, sensor_seed=0 if seed is None else int(seed))
    t0 = time.perf_counter()
    meas = measure(m, sim, sc, rng)
    t_meas = time.perf_counter() - t0
    try:
        res = identify(m, meas, sc, methods, timings={"simulation": t_sim, "measurements": t_meas})
    except Interrupted as e:
        e.partial.simulation = sim
        raise
    res.simulation = sim
    _spacecraft_extras(m, sim, sc, res)
    if stopped is not None:
        res.interrupted, res.t_end = stopped, float(sim["t"][-1])
        raise _interrupted(res)
    if progress:
        progress("identified")
    return res


def _interrupted(res: PostcaptureResult) -> Interrupted:
    e = Interrupted(f"post-capture run {res.interrupted}; kept t = 0 .. {res.t_end:g} s")
    e.partial = res
    return e


def _spacecraft_extras(m, sim: dict, sc: Scenario, res: PostcaptureResult) -> None:
    """The base's truth over time, the propellant used, the balance checks and the tracking summary of a run
    with actuators/sensors (results.json)."""
    planar = m.joint_types[0] == "planar"
    res.truth_history = spacecraft.truth_history(m, sim, planar, target_index(m))
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


def noise_forgetting_study(
    sc: Scenario, gyro_noise=(1e-6, 1e-5, 1e-4), forgetting=(0.98, 0.99, 0.995, 1.0), progress=None
):
    """The tracking error of the force-based standard RLS against the gyro's noise density and the forgetting
    factor, from ONE simulation of the scenario (the sensors are re-run per noise level, the estimator per λ).
    Returns rows {gyro_noise, forgetting, memory_s, rms (second half, per base/target parameter), predicted lag}.

        import freefloat.postcapture as pc
        from freefloat.postcapture.pipeline import noise_forgetting_study
        rows = noise_forgetting_study(pc.load_scenario("zhang2020_3d_thrusters"))
    """
    if sc.sensors is None or not any(
        (s.get("type") if isinstance(s, dict) else getattr(s, "TYPE", "")) == "gyro" for s in sc.sensors.sensors
    ):
        raise ValueError("the scenario needs a gyro in its sensors: block")
    m = models.load(sc.model)
    sim = simulate(sc, m)
    th = spacecraft.truth_history(m, sim, m.joint_types[0] == "planar", target_index(m))
    rows = []
    for n in gyro_noise:
        sens = dataclasses.replace(
            sc.sensors, sensors=[dict(s) if isinstance(s, dict) else s.to_dict() for s in sc.sensors.sensors]
        )
        for s in sens.sensors:
            if s["type"] == "gyro":
                s.pop("noise_per_sample", None)
                s["noise_density"] = float(n)
        for lam in forgetting:
            s2 = dataclasses.replace(sc, sensors=sens, forgetting=float(lam))
            res = identify(m, measure(m, sim, s2), s2, methods=("force",))
            res.truth_history = th
            tr = spacecraft.tracking(res, s2)["estimators"]["force/standard_rls"]
            t, h = res.histories[("force", "standard_rls")]
            truth = res.truth_at(t)
            half = t >= t[0] + 0.5 * (t[-1] - t[0])
            rel = np.abs(h - truth) / np.where(np.abs(truth) > 0, np.abs(truth), 1.0)
            rms = np.sqrt(np.mean(rel[half] ** 2, 0))
            rows.append(
                {
                    "gyro_noise": float(n),
                    "forgetting": float(lam),
                    "memory_s": sc.sample_period / (1 - lam) if lam < 1 else None,
                    "rms_second_half": {nm: float(rms[j]) for j, nm in enumerate(res.names)},
                    "predicted_lag": tr["predicted_lag_relative_error"],
                }
            )
            if progress:
                progress(len(rows), len(gyro_noise) * len(forgetting))
    return rows
