"""Post-capture scenarios (Zhang, Yue, Yuan 2020): the YAML files that name the robot, the captured target, the
controller gains, the initial velocities and the identification settings. Built-in ones ship in
`freefloat/data/scenarios/` (`list_scenarios`); any file path works too."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import algorithms as alg
from .. import models
from .._core import InputError
from ..algorithms import quat_to_matrix
from ..io import scenario_files
from ..io.scenario_blocks import scenario_blocks

# Noise study levels (the paper has no noise): white, per sample. Velocities [m/s, rad/s] and accelerations
# [m/s², rad/s²] at the 10 Hz samples; thrust [N, N·m] at the 1 kHz step rate before integration.
DEFAULT_NOISE = {"velocity": 1e-4, "acceleration": 1e-4, "force": 0.01}


@dataclass
class Scenario:
    name: str
    description: str
    model: str
    duration: float
    dt: float
    sample_period: float
    q0: np.ndarray
    v0: np.ndarray
    control: dict
    excitation: dict
    tolerance: float
    P0: float
    forgetting: float
    guess: dict
    project: bool = False
    measurement: dict = field(default_factory=dict)
    noise: dict | None = None
    paper: dict = field(default_factory=dict)
    sweep: dict | None = None
    paper_sweep: dict | None = None
    source: str = ""
    #: the `actuators:` block as the engine reads it (freefloat.Actuators.to_dict()), or None
    actuators: dict | None = None
    #: the `environment:` block as a freefloat.Environment, or None
    environment: object = None
    #: the `sensors:` (+ `telemetry:`) blocks as a freefloat.sensors.SensorSet, or None (the plain samples)
    sensors: object = None
    #: seed of the sensors' random streams (`freefloat identify postcapture --seed`)
    sensor_seed: int = 0

    def with_base_velocity(self, vel) -> Scenario:
        """Copy with the initial base (sensor) linear velocity replaced (inertial frame)."""
        import copy

        s = copy.deepcopy(self)
        vel = np.asarray(vel, float)
        A = _base_attitude(models.load(self.model) if isinstance(self.model, str) else self.model, s.q0)
        s.v0[: len(vel)] = (A.T @ np.pad(vel, (0, 3 - len(vel))))[: len(vel)]
        return s


def list_scenarios() -> list[tuple[str, str]]:
    """Built-in post-capture scenarios (name, description), shipped inside the package (`freefloat.data`)."""
    return [(s.name, s.description) for s in scenario_files.listing() if s.kind == "postcapture"]


def load_scenario(spec: str | Path) -> Scenario:
    """A post-capture scenario by built-in name or file path."""
    d, source = scenario_files.read(spec, kind="postcapture")
    try:
        return parse_scenario(d, source)
    except KeyError as e:
        raise InputError(f"{source}: missing key {e}") from None


def parse_scenario(d: dict, source: str, model=None) -> Scenario:
    """A checked scenario mapping as a Scenario; `model` (a freefloat.Model) instead of the built-in robot that
    `d["model"]` names (a mission's servicer with its target attached)."""
    m = model if model is not None else models.load(d["model"])
    planar = m.joint_types[0] == "planar"
    ini = d["initial"]
    deg = np.pi / 180
    joints = np.asarray(ini["joints_deg"], float) * deg
    nj = m.nv - (3 if planar else 6)
    if len(joints) != nj:
        raise InputError(f"{source}: initial.joints_deg needs {nj} entries, got {len(joints)}")
    if planar:
        q0 = np.concatenate([[*ini.get("base_position", [0, 0]), ini.get("base_yaw_deg", 0.0) * deg], joints])
        vel = np.asarray(ini["base_velocity"], float)
        rate = float(ini["base_rate"])
        A = _base_attitude(m, q0)[:2, :2]
        v0 = np.concatenate([A.T @ vel, [rate], np.zeros(nj)])
    else:
        q0 = np.concatenate([ini.get("base_position", [0, 0, 0]), [0, 0, 0, 1], joints])
        vel, rate = np.asarray(ini["base_velocity"], float), np.asarray(ini["base_rate"], float)
        v0 = np.concatenate([vel, rate, np.zeros(nj)])  # attitude identity: body = inertial
    ex = d["excitation"]
    exc = {
        "damping": float(ex.get("damping", 0.0)),
        "amp": list(map(float, ex["amplitude"])),
        "freq": list(map(float, ex["frequency"])),
        "phase": [float(x) * deg for x in ex.get("phase_deg", [0] * nj)],
    }
    ident = d["identification"]
    acts, env, sset = scenario_blocks(d, source, m)
    return Scenario(
        name=d["name"],
        description=str(d.get("description", "")).strip(),
        model=d["model"],
        duration=float(d["duration"]),
        dt=float(d.get("dt", 1e-3)),
        sample_period=float(d.get("sample_period", 0.1)),
        q0=q0,
        v0=v0,
        control=dict(d["control"]),
        excitation=exc,
        tolerance=float(ident["transit_tolerance"]),
        P0=float(ident.get("P0", 1e6)),
        forgetting=float(ident.get("forgetting", 1.0)),
        guess=ident["guess"],
        project=bool(ident.get("project", False)),
        measurement=dict(d.get("measurement") or {}),
        noise=d.get("noise"),
        paper=d.get("paper", {}) or {},
        sweep=d.get("sweep"),
        paper_sweep=d.get("paper_sweep"),
        source=source,
        actuators=acts,
        environment=env,
        sensors=sset,
    )


def _base_attitude(m, q) -> np.ndarray:
    fk = np.asarray(alg.forward_kinematics(m, q))[0]
    return quat_to_matrix(fk[None, 3:])[0]
