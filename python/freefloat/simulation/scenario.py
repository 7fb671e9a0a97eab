"""Scenario files of kind `simulate`: a robot, its initial state and torques, and the spacecraft blocks
(`actuators:`, `environment:`, `sensors:`/`telemetry:`), run by `freefloat simulate SCENARIO.yaml` or from Python:

    import freefloat as ff
    sc = ff.load_simulation_scenario("hub_wheels.yaml")
    run = ff.run_simulation_scenario(sc)
    run.trajectory, run.measurement   # the Trajectory; the sensors' Measurement (None without sensors)

A file:

    kind: simulate
    model: hub_wheels.yaml            # a built-in robot, or a model file (relative to this file)
    duration: 30.0
    dt: 0.001
    initial: {q: [...], v: [...]}     # nq and nv numbers (default: neutral, at rest)
    torques: {constant: {rw1: 0.1}}   # joint name -> generalized force held through the run; or
                                      # {steps: [{t: 0, rw1: 0.1}, {t: 5, rw1: 0}]}; or {table: tau.csv}
    actuators: {...}                  # the blocks of docs/actuators.md, docs/environment.md, docs/sensors.md
    environment: {...}
    sensors: [...]

The blocks are the same mappings as `freefloat simulate MODEL --actuators/--environment FILE` and `freefloat
measure --sensors FILE` read, handed to the same engine calls: nothing here computes physics.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._core import InputError
from ..model import Model


@dataclass
class SimulationScenario:
    """A `kind: simulate` scenario, read and checked against its robot."""

    name: str
    description: str
    model: Model
    duration: float
    dt: float
    method: str
    rtol: float
    atol: float
    record_every: int
    formulation: str
    input_timing: str
    q0: np.ndarray
    v0: np.ndarray
    #: (T, nv) generalized forces read at `torque_times` with `torque_hold`, or None (no torques)
    torques: np.ndarray | None
    torque_times: np.ndarray | None
    #: "zoh" (each row held until the next) or "linear"
    torque_hold: str
    #: the `actuators:` block as the engine reads it (freefloat.Actuators.to_dict()), or None
    actuators: dict | None
    environment: object
    sensors: object
    seed: int
    source: str


@dataclass
class SimulationRun:
    scenario: SimulationScenario
    trajectory: object
    #: the sensors' Measurement (freefloat.sensors.measure), or None without a `sensors:` block
    measurement: object = None


def _model(spec: str, source: str, base_dir: Path | None) -> Model:
    from .. import models

    p = Path(spec)
    if not p.suffix and models.is_builtin(spec):
        return models.load(spec)
    if base_dir is not None and not p.is_absolute() and (base_dir / p).is_file():
        p = base_dir / p
    if not p.is_file():
        raise InputError(
            f"{source}: key 'model': '{spec}' is neither a built-in robot ({', '.join(models.names())}) nor a model "
            "file (paths are relative to the scenario file)"
        )
    suffix = p.suffix.lower()
    if suffix in (".yaml", ".yml"):
        return Model.from_yaml(p)
    if suffix == ".urdf":
        return Model.from_urdf(p)
    if suffix in (".xml", ".mjcf"):
        return Model.from_mjcf(p)
    raise InputError(f"{source}: key 'model': '{spec}' is not a .yaml, .urdf or .xml (MJCF) model file")


def _vector(x, n: int, key: str, source: str, default: np.ndarray) -> np.ndarray:
    if x is None:
        return default
    a = np.asarray(x, float)
    if a.shape != (n,):
        raise InputError(f"{source}: key '{key}': expected {n} numbers for this robot, got {a.size}")
    return a


def _joint_column(m: Model, name: str, key: str, source: str) -> int:
    """The velocity index of the one-coordinate joint `name` (the key names where it was given)."""
    from ..io import scenario_files

    if name not in m.joint_names[1:]:
        raise scenario_files.error_at(
            source,
            InputError(f"{key}: the robot '{m.name}' has no joint '{name}' (joints: {', '.join(m.joint_names[1:])})"),
        )
    j = m.joint_names.index(name)
    if m.nvs[j] != 1:
        raise scenario_files.error_at(source, InputError(f"{key}: joint '{name}' has {m.nvs[j]} coordinates, not one"))
    return m.idx_v[j]


# columns a trajectory file has besides its torques (a recorded run can be replayed as a table)
_TRAJECTORY_PREFIXES = ("q.", "v.", "ddq.", "momentum.", "propellant.", "base_parameters.", "orbit.")
_TRAJECTORY_COLUMNS = ("kinetic_energy", "work")


def _torques(block: dict, m: Model, source: str, base_dir: Path | None, duration: float):
    """(T × nv table, its times, its hold) from the scenario's `torques:` block, or (None, None, "zoh")."""
    if block.get("constant"):
        tau = np.zeros((1, m.nv))
        for name, value in block["constant"].items():
            tau[0, _joint_column(m, name, "torques.constant", source)] = float(value)
        return tau, np.array([0.0]), "zoh"
    if block.get("steps"):
        # each entry changes the joints it names from its time on; the others keep their last value (zero at
        # first). A closing row at the run's end keeps the table from looking as if it ended early
        rows, times, cur = [], [], np.zeros(m.nv)
        for k, entry in enumerate(block["steps"]):
            cur = cur.copy()
            for name, value in entry.items():
                if name != "t":
                    cur[_joint_column(m, name, f"torques.steps[{k}].{name}", source)] = float(value)
            times.append(float(entry["t"]))
            rows.append(cur)
        if times[0] > 0.0:
            times.insert(0, 0.0)
            rows.insert(0, np.zeros(m.nv))
        if times[-1] < duration:
            times.append(duration)
            rows.append(rows[-1])
        return np.array(rows), np.array(times), "zoh"
    if block.get("table"):
        return _torque_table(block["table"], m, source, base_dir) + (block.get("hold") or "zoh",)
    return None, None, "zoh"


def _torque_table(spec: str, m: Model, source: str, base_dir: Path | None):
    """Read a torque table: CSV or Parquet, a column t [s] (strictly increasing, from 0) and one column
    tau.<coordinate> per driven coordinate (`Model.v_labels()`, as a trajectory file names them; absent
    coordinates get zero). A trajectory file's other columns are ignored, any other column is refused."""
    from ..io import scenario_files
    from ..io.telemetry import check_finite, check_increasing, read_columns

    p = Path(spec)
    if base_dir is not None and not p.is_absolute():
        p = base_dir / p
    if not p.is_file():
        raise scenario_files.error_at(
            source, InputError(f"torques.table: file '{spec}' not found (paths are relative to the scenario file)")
        )
    cols = read_columns(p)
    where = str(p)
    labels = m.v_labels()
    if "t" not in cols:
        raise InputError(f"{where}: no column 't' (the time of each row, in s)")
    driven = []
    for c in cols:
        if c == "t" or c in _TRAJECTORY_COLUMNS or c.startswith(_TRAJECTORY_PREFIXES):
            continue
        if not c.startswith("tau.") or c[4:] not in labels:
            hint = f" (did you mean 'tau.{c}'?)" if c in labels else ""
            raise InputError(
                f"{where}: column '{c}' is not t or tau.<coordinate> of the robot '{m.name}'{hint}; coordinates: "
                f"{', '.join(labels)}"
            )
        driven.append(c)
    if not driven:
        raise InputError(f"{where}: no tau.<coordinate> column (coordinates of '{m.name}': {', '.join(labels)})")
    check_finite(cols, ["t", *driven], where)
    t = cols["t"]
    if t.size == 0:
        raise InputError(f"{where}: the table has no rows")
    if t[0] != 0.0:
        raise InputError(
            f"{where}: the first row is at t = {float(t[0])!r} s; the table must start at t = 0 (the run start)"
        )
    check_increasing(t, where, first_line=2 if p.suffix.lower() == ".csv" else None)  # a CSV's header is line 1
    tau = np.zeros((t.size, m.nv))
    for c in driven:
        tau[:, labels.index(c[4:])] = cols[c]
    return tau, t.copy()


def load(spec) -> SimulationScenario:
    """Read a `kind: simulate` scenario (a file path or a built-in name), checked against its schema and then,
    by the engine, against its robot (joint names, tank masses, sensor joints): every error names the file,
    line and key."""
    from ..io import scenario_files
    from ..io.scenario_blocks import scenario_blocks

    d, source = scenario_files.read(spec, kind="simulate")
    p = Path(spec)
    base_dir = p.parent if p.suffix and p.is_file() else None
    m = _model(d["model"], source, base_dir)
    init = d.get("initial") or {}
    q0 = _vector(init.get("q"), m.nq, "initial.q", source, m.neutral())
    v0 = _vector(init.get("v"), m.nv, "initial.v", source, np.zeros(m.nv))
    tau, times, hold = _torques(d.get("torques") or {}, m, source, base_dir, float(d["duration"]))
    acts, env, sset = scenario_blocks(d, source, m)
    return SimulationScenario(
        name=str(d.get("name", p.stem if p.suffix else spec)),
        description=str(d.get("description", "")).strip(),
        model=m,
        duration=float(d["duration"]),
        dt=float(d.get("dt", 1e-3)),
        method=d.get("method", "rk4"),
        rtol=float(d.get("rtol", 1e-9)),
        atol=float(d.get("atol", 1e-12)),
        record_every=int(d.get("record_every", 1)),
        formulation=d.get("formulation", "aba"),
        input_timing=d.get("input_timing", "step"),
        q0=q0,
        v0=v0,
        torques=tau,
        torque_times=times,
        torque_hold=hold,
        actuators=acts,
        environment=env,
        sensors=sset,
        seed=int(d.get("seed", 0)),
        source=source,
    )


def run(sc: SimulationScenario | str | Path, progress=False, max_steps: int | None = None) -> SimulationRun:
    """Simulate the scenario (freefloat.simulate with its actuators and environment) and, with sensors, measure
    the run (freefloat.sensors.measure with the scenario's seed)."""
    from .. import sensors as sn
    from .run import simulate

    if not isinstance(sc, SimulationScenario):
        sc = load(sc)
    kw = {}
    if sc.torques is not None:
        kw.update(torques=sc.torques, torque_times=sc.torque_times, hold=sc.torque_hold)
    if max_steps is not None:
        kw["max_steps"] = max_steps
    traj = simulate(
        sc.model,
        sc.q0,
        sc.v0,
        sc.duration,
        sc.dt,
        method=sc.method,
        rtol=sc.rtol,
        atol=sc.atol,
        record_every=sc.record_every,
        formulation=sc.formulation,
        input_timing=sc.input_timing,
        actuators=sc.actuators,
        environment=sc.environment,
        progress=progress,
        **kw,
    )
    meas = sn.measure(sc.model, traj, sc.sensors, seed=sc.seed) if sc.sensors is not None else None
    return SimulationRun(sc, traj, meas)


__all__ = ["SimulationRun", "SimulationScenario", "load", "run"]
