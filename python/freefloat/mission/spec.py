"""Mission files (`kind: mission`): a servicer, an unknown target and its motion before the grasp, the detumble and
identification phase and the berth manoeuvre. Read and checked like every scenario file (`io/scenario_schemas.py`
declares the keys); this module turns a checked file into a `Mission`."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._core import InputError
from ..io import scenario_files


@dataclass
class Body:
    """Mass, centre of mass (target frame, origin at the grasp point) and inertia about the CoM (target axes)."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray  # (3, 3)


@dataclass
class Mission:
    name: str
    description: str
    servicer: str
    detumble: str | dict  # a post-capture scenario (name or file), or its blocks inline
    grasp: dict | None  # where to weld the target on a servicer that has none: {body, xyz, rpy_deg}
    target: Body
    guess: Body
    target_velocity: np.ndarray  # of the grasp point before the grasp, inertial (m/s)
    target_rate: np.ndarray  # before the grasp, inertial (rad/s)
    joints: np.ndarray  # servicer joint angles at contact (rad)
    base_velocity: np.ndarray
    base_rate: np.ndarray
    approach_s: float
    method: str
    max_duration: float
    min_duration: float
    tolerance: dict
    berth: dict
    source: str = ""
    #: the mission's own `sensors:` (+ `telemetry:`) blocks, replacing the detumble scenario's, or None
    sensors: dict | None = None
    extra: dict = field(default_factory=dict)


def list_missions() -> list[tuple[str, str]]:
    """Built-in missions (name, description), shipped inside the package."""
    return [(s.name, s.description) for s in scenario_files.listing() if s.kind == "mission"]


def _inertia(x, where: str) -> np.ndarray:
    a = np.asarray(x, float)
    if a.shape == (3,):
        return np.diag(a)
    if a.shape == (6,):  # xx, xy, xz, yy, yz, zz
        xx, xy, xz, yy, yz, zz = a
        return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    raise InputError(f"{where}: expected 3 principal moments or 6 entries [xx, xy, xz, yy, yz, zz], got {a.size}")


def _body(d: dict, source: str, key: str) -> Body:
    where = f"{source}: key '{key}.inertia'"
    b = Body(float(d["mass"]), np.asarray(d.get("com", [0, 0, 0]), float), _inertia(d["inertia"], where))
    ev = np.linalg.eigvalsh(b.inertia)
    if ev.min() <= 0 or 2 * ev.max() > ev.sum() * (1 + 1e-9):
        raise InputError(
            f"{where}: not the inertia of a body (principal moments {np.round(ev, 6).tolist()} must be "
            "positive and each at most the sum of the other two)"
        )
    return b


def load_mission(spec: str | Path) -> Mission:
    """A mission by built-in name or file path."""
    d, source = scenario_files.read(spec, kind="mission")
    deg = np.pi / 180
    t, cap, ident, berth = d["target"], d["capture"], d.get("identify") or {}, d["berth"]
    tol = {"mass": 0.02, "com": 0.01, "inertia": 0.05, "window": 5.0}
    tol.update(ident.get("convergence") or {})
    return Mission(
        name=d["name"],
        description=str(d.get("description", "")).strip(),
        servicer=d["servicer"],
        detumble=d["detumble"],
        grasp=d.get("grasp"),
        target=_body(t, source, "target"),
        guess=_body(t["guess"], source, "target.guess"),
        target_velocity=np.asarray(t.get("velocity", [0, 0, 0]), float),
        target_rate=np.asarray(t.get("rate", [0, 0, 0]), float),
        joints=np.asarray(cap["joints_deg"], float) * deg,
        base_velocity=np.asarray(cap.get("base_velocity", [0, 0, 0]), float),
        base_rate=np.asarray(cap.get("base_rate", [0, 0, 0]), float),
        approach_s=float(cap.get("approach_s", 10.0)),
        method=ident.get("method", "momentum"),
        max_duration=float(ident.get("max_duration", 60.0)),
        min_duration=float(ident.get("min_duration", 2.0)),
        tolerance=tol,
        berth=dict(berth),
        source=source,
        sensors={k: d[k] for k in ("sensors", "telemetry") if d.get(k) is not None} or None,
    )
