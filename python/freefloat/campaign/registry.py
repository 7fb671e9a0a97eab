"""The scenario kinds a campaign can run. One entry per kind says how to load its scenario (as a plain mapping),
which dotted parameter paths it accepts, and how to run one scenario into its summary numbers (one flat mapping of
name -> number or string, which becomes the run's row in the dataset).

A new kind is one `register(Kind(...))` call (a module of its own is fine; import it from `_builtin_kinds`):

    register(Kind(
        name="identify_cl",
        description="Valverde 2018 ch. 9: concurrent-learning mass estimation",
        load=lambda ref: scenario_files.read(ref, kind="identify_cl")[0] if not isinstance(ref, dict) else ref,
        parameters=lambda base: leaf_paths(base),
        run=lambda scenario, seed: {...},
    ))

`run` executes on a Dask worker: it must be a module-level function (importable there), take the scenario mapping
and the seed, and return plain numbers; an exception it raises is recorded as the run's error.
"""

from __future__ import annotations

import copy
import difflib
import functools
import time

import numpy as np

from .._core import InputError
from . import file_kinds
from .kind import Kind, json_roundtrip, leaf_paths

KINDS: dict[str, Kind] = {}


def register(kind: Kind) -> Kind:
    """Add (or replace) a kind."""
    KINDS[kind.name] = kind
    return kind


def get(name: str, where: str = "kind") -> Kind:
    """The kind called `name`; InputError naming the closest ones otherwise."""
    if name in KINDS:
        return KINDS[name]
    close = difflib.get_close_matches(str(name), list(KINDS), n=2, cutoff=0.4)
    raise InputError(
        f"{where}: unknown scenario kind '{name}'"
        + (f" (did you mean {' or '.join(close)}?)" if close else "")
        + f"; campaign kinds: {', '.join(KINDS)}"
    )


# -- post-capture identification (Zhang, Yue, Yuan 2020) ---------------------------------------------------
#: paths a post-capture scenario accepts beyond the keys its file has (optional sections of the format)
_PC_OPTIONAL = [
    "noise",
    "noise.velocity",
    "noise.acceleration",
    "noise.force",
    "measurement",
    "measurement.accelerations",
    "measurement.impulses",
    "measurement.momentum_point",
    "measurement.savgol_window",
    "measurement.savgol_polyorder",
    "identification.project",
    "identification.forgetting",
    "identification.P0",
    "dt",
    "sample_period",
]


def _pc_load(ref) -> dict:
    from ..io import scenario_files

    if isinstance(ref, dict):
        d = copy.deepcopy(ref)
        d.setdefault("name", "inline")
        return json_roundtrip(d)
    d, _ = scenario_files.read(ref, kind="postcapture")
    return json_roundtrip(d)


def _pc_parameters(base: dict) -> list:
    # the sweep section and the paper's values are not inputs of a run
    return [p for p in leaf_paths(base) if not p.startswith(("paper", "sweep"))] + _PC_OPTIONAL


def _pc_normalize(d: dict) -> dict:
    d = json_roundtrip(d)
    # not inputs of one run: the scenario's own sweep list, the paper's printed values, the description (editing
    # them must not make finished runs look new)
    for k in ("sweep", "paper_sweep", "paper", "description"):
        d.pop(k, None)
    return d


def run_postcapture(scenario: dict, seed: int) -> dict:
    """One post-capture identification (simulate, measure, four estimators) -> final relative errors, estimates
    and transit times of every parameter for each method/solver."""
    from ..postcapture import pipeline
    from ..postcapture.scenario import parse_scenario

    t0 = time.perf_counter()
    sc = parse_scenario(copy.deepcopy(scenario), f"campaign run of '{scenario.get('name', '?')}'")
    res = pipeline.run(sc, seed=seed)
    out = {"wall_s": time.perf_counter() - t0, "simulation_s": float(res.timings.get("simulation", np.nan))}
    for (method, solver), (_t, h) in res.histories.items():
        err = res.rel_error(method, solver)
        trans = res.transits(method, solver)
        for j, n in enumerate(res.names):
            out[f"error.{method}.{solver}.{n}"] = float(err[j])
            out[f"estimate.{method}.{solver}.{n}"] = float(h[-1, j])
            out[f"transit.{method}.{solver}.{n}"] = trans[j][1]
    for j, n in enumerate(res.names):
        out[f"truth.{n}"] = float(res.truth[j])
    return out


# -- minimal-parameter identification (Naveen, Shah, Misra) ------------------------------------------------
#: the defaults of an identify_minimal scenario (there is no scenario file of this kind: the spec's `scenario`
#: is a mapping over these, or a name of a built-in robot)
MINIMAL_DEFAULTS = {
    "kind": "identify_minimal",
    "model": "naveen_dual_arm",
    "trajectory": "naveen_exciting_trajectory",
    "duration": None,  # seconds of the trajectory to use (None: all of it)
    "dt": 1e-3,
    "method": "closed-form",
    "noise": {"scale": 1.0, "velocity_linear": None, "velocity_angular": None, "joint_rate": None},
}


def _min_load(ref) -> dict:
    d = copy.deepcopy(MINIMAL_DEFAULTS)
    if isinstance(ref, str):
        ref = {"model": ref}
    if not isinstance(ref, dict):
        raise InputError(f"scenario of kind identify_minimal: expected a robot name or a mapping, got {ref!r}")
    unknown = [k for k in ref if k not in d and k != "name"]
    if unknown:
        close = difflib.get_close_matches(unknown[0], list(d), n=1)
        raise InputError(
            f"identify_minimal scenario: unknown key '{unknown[0]}'"
            + (f" (did you mean '{close[0]}'?)" if close else "")
            + f"; keys: {', '.join(d)}"
        )
    for k, v in ref.items():
        if k == "noise" and isinstance(v, dict):
            d["noise"].update(v)
        else:
            d[k] = v
    from .. import models
    from ..io.trajectory_files import load_trajectory

    models.load(d["model"])  # InputError naming the built-in robots when unknown
    load_trajectory(d["trajectory"])
    return json_roundtrip(d)


def _min_parameters(base: dict) -> list:
    return [p for p in leaf_paths(base) if p != "kind"]


@functools.lru_cache(maxsize=2)
def _simulated(model: str, trajectory: str, dt: float, duration: float | None):
    """The noise-free motion along the trajectory, kept per worker process: the runs of a noise Monte Carlo differ
    only in their noise draw, so a worker simulates each (robot, trajectory, dt, duration) once."""
    from .. import models
    from ..io.trajectory_files import load_trajectory
    from ..simulation import simulate_driven

    traj, joints = load_trajectory(trajectory)
    return simulate_driven(models.load(model), traj, joints, dt, t_final=duration)


def run_minimal(scenario: dict, seed: int) -> dict:
    """One minimal-parameter identification of Naveen, Shah, Misra: simulate the robot along the trajectory, add
    the rate noise (the paper's levels × noise.scale, or the levels given) with `seed`, identify by plain least
    squares and with the errors-in-variables bias removed -> the paper's error figures (eqs. 38-39) of both and
    every parameter's relative error. The noise-free simulation is cached per worker (`_simulated`), so the
    first run of a worker takes the simulation time and the others only the noise and the two fits."""
    from .. import models
    from ..constants import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN
    from ..identification import identify as idf
    from ..io import telemetry as tm

    t0 = time.perf_counter()
    m = models.load(scenario["model"])
    dur = scenario.get("duration")
    sim = _simulated(
        scenario["model"], scenario["trajectory"], float(scenario["dt"]), None if dur is None else float(dur)
    )
    t_sim = time.perf_counter() - t0
    nz = scenario.get("noise") or {}
    scale = float(nz.get("scale", 1.0))
    sig = (
        np.array(
            [
                SIGMA_LIN if nz.get("velocity_linear") is None else float(nz["velocity_linear"]),
                SIGMA_ANG if nz.get("velocity_angular") is None else float(nz["velocity_angular"]),
                SIGMA_JOINT if nz.get("joint_rate") is None else float(nz["joint_rate"]),
            ]
        )
        * scale
    )
    if not np.all(np.isfinite(sig)) or np.any(sig < 0):
        raise InputError(f"noise: rate noise levels must be finite and non-negative, got {sig.tolist()}")
    telem = tm.from_trajectory(sim)
    if np.any(sig > 0):
        telem = tm.add_noise(telem, m, np.random.default_rng(seed), *sig)
    method = str(scenario.get("method", "closed-form"))
    out = {"samples": len(telem.t), "simulation_s": t_sim}
    fits = {"ls": idf.identify_minimal(m, telem, method=method)}
    if np.any(sig > 0):
        fits["eiv"] = idf.identify_minimal(m, telem, method=method, rate_noise=sig)
    else:
        fits["eiv"] = fits["ls"]
    truth = fits["ls"].truth_values(m)
    scale_t = np.where(truth != 0, np.abs(truth), 1.0)
    for k, res in fits.items():
        e = res.errors(m)
        out[f"{k}.median_rel_error_pct"] = float(e["median_rel_error_pct"])
        out[f"{k}.max_rel_error_pct"] = float(e["max_rel_error_pct"])
        rel = (res.estimate - truth) / scale_t * 100
        for j in range(len(rel)):
            out[f"{k}.rel_error_pct.{j + 1:02d}"] = float(rel[j])
    out["condition_number"] = float(fits["ls"].fit.condition_number)
    out["eiv_applied"] = fits["eiv"].fit.method.endswith("errors-in-variables bias compensation")
    out["wall_s"] = time.perf_counter() - t0
    return out


# -- identification error by sensor class (every estimator on the sensor presets) ----------------------------
SENSOR_CLASSES_DEFAULTS = {"estimator": "zhang", "sensor_class": "tactical", "horizons": [10.0, 30.0, 100.0]}


def _scl_load(ref) -> dict:
    d = copy.deepcopy(SENSOR_CLASSES_DEFAULTS)
    if not isinstance(ref, dict):
        raise InputError(f"scenario of kind sensor_classes: expected a mapping with keys {', '.join(d)}, got {ref!r}")
    unknown = [k for k in ref if k not in d and k != "name"]
    if unknown:
        raise InputError(f"sensor_classes scenario: unknown key '{unknown[0]}'; keys: {', '.join(d)}")
    d.update({k: v for k, v in ref.items() if k != "name"})
    return json_roundtrip(d)


def run_sensor_classes(scenario: dict, seed: int) -> dict:
    """One estimator on telemetry from one sensor preset with `seed` -> relative errors of mass, centre of mass
    and inertia at each horizon (`identification.sensor_classes.run`)."""
    from ..identification import sensor_classes as scl

    t0 = time.perf_counter()
    out = scl.run(scenario["estimator"], scenario["sensor_class"], seed, scenario.get("horizons", scl.HORIZONS))
    return {**out, "wall_s": time.perf_counter() - t0}


def _builtin_kinds() -> None:
    register(
        Kind(
            name="postcapture",
            description="Zhang, Yue, Yuan 2020: post-capture identification of base and target "
            "(scenario: a built-in name such as zhang2020_2d_medium, a file, or a mapping)",
            load=_pc_load,
            parameters=_pc_parameters,
            run=run_postcapture,
            normalize=_pc_normalize,
            headline=("error.momentum.modified_rls.In", "error.force.modified_rls.In"),
        )
    )
    register(
        Kind(
            name="identify_minimal",
            description="Naveen, Shah, Misra: minimal parameters from momentum with rate noise, plain least "
            "squares beside errors-in-variables removal (scenario: a mapping over model, trajectory, duration, "
            "dt, method, noise.{scale, velocity_linear, velocity_angular, joint_rate})",
            load=_min_load,
            parameters=_min_parameters,
            run=run_minimal,
            normalize=json_roundtrip,
            headline=("ls.median_rel_error_pct", "eiv.median_rel_error_pct", "ls.max_rel_error_pct"),
        )
    )
    register(
        Kind(
            name="sensor_classes",
            description="identification error by sensor class: an estimator (zhang, naveen, cl) on telemetry "
            "from a sensor preset (navigation, tactical, mems), errors of mass, centre of mass and inertia at each "
            "horizon (scenario: a mapping over estimator, sensor_class, horizons)",
            load=_scl_load,
            parameters=lambda base: ["estimator", "sensor_class", "horizons"],
            run=run_sensor_classes,
            normalize=json_roundtrip,
            headline=("zhang_momentum.inertia.100", "zhang_force.inertia.100", "naveen_eiv.inertia.100"),
        )
    )
    for kind in file_kinds.kinds():
        register(kind)


_builtin_kinds()
