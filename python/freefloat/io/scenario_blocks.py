"""The `actuators:`, `environment:` and `sensors:`/`telemetry:` blocks of a scenario file (post-capture, simulate,
mission) as the objects that run them. One reader for every scenario kind that has the blocks: it sits after the
simulation stage and the sensors in the import order and before the applications that read scenarios."""

from __future__ import annotations

import numpy as np

from .. import _core
from .. import sensors as sn
from .._core import InputError
from ..simulation.actuators import Actuators
from ..simulation.environment import environment_from_dict
from . import scenario_files, schema


def scenario_blocks(d: dict, source: str, m):
    """The `actuators:`, `environment:` and `sensors:`/`telemetry:` blocks as the Python API objects that run
    them (the same readers as `freefloat simulate --actuators/--environment` and `freefloat measure --sensors`),
    checked against the robot by the engine now, so that a tank heavier than its body or an unknown joint is
    refused before the run with the file, line and key."""
    # the blocks as the schema read them: numbers written as YAML 1.1 text (1e5) are numbers, as everywhere
    d = dict(d)
    for key in ("actuators", "environment", "telemetry"):
        if d.get(key) is not None:
            d[key] = schema.validated_block(key, d[key]).model_dump(exclude_unset=True)
    if d.get("sensors") is not None:
        d["sensors"] = [s.model_dump(exclude_unset=True) for s in schema.validated_block("sensors", d["sensors"])]
    acts = env = sset = None
    if d.get("actuators"):
        try:
            acts = Actuators.from_dict(d["actuators"]).to_dict()
            ntanks = len(acts.get("tanks", []))
            # resolves names and runs every engine check (ActuatorRt::new) without simulating
            _core.postcapture_thruster_wrench(m._core, acts, np.zeros(1), np.zeros((1, ntanks)))
        except InputError as e:
            raise scenario_files.error_at(source, e) from None
    if d.get("environment"):
        try:
            env = environment_from_dict(d["environment"])
        except InputError as e:
            raise scenario_files.error_at(source, e) from None
    if d.get("sensors"):
        spec = {"sensors": d["sensors"]}
        if d.get("telemetry"):
            spec["telemetry"] = d["telemetry"]
        try:
            sset = sn.load(spec)
            sset.names()  # the engine's check of the whole set
            for j, s in enumerate(sset.to_dicts()):
                named = s.get("joints") or ([s["joint"]] if s.get("joint") else [])
                for k, jn in enumerate(named):
                    if jn not in m.joint_names:
                        key = f"sensors[{j}].joints[{k}]" if s.get("joints") else f"sensors[{j}].joint"
                        raise InputError(
                            f"{key}: the robot '{m.name}' has no joint '{jn}' (joints: {', '.join(m.joint_names)})"
                        )
        except InputError as e:
            raise scenario_files.error_at(source, e) from None
    return acts, env, sset
