"""Actuator models for `simulate`: joint limits, reaction wheels, thrusters and propellant tanks.

They are evaluated in the engine, inside the integrator (no Python runs during the simulation). The joint
limits of the model (URDF ``<limit effort velocity>``, YAML ``limits: {effort, velocity}``) always apply, with or
without these; a `JointLimit` replaces the model's value of each quantity it gives for its joint. See
``docs/actuators.md`` for every formula and choice.

    import freefloat as ff
    acts = ff.Actuators(
        limits=[ff.JointLimit("joint3", effort=5.0)],
        wheels=[ff.Wheel("rw1", max_torque=0.2, max_speed=600.0, coulomb=5e-4, viscous=1e-6)],
        thrusters=[ff.Thruster(position=(0, 0, -0.5), direction=(0, 0, 1), max_thrust=1.0, isp=220.0,
                               tank="main", firings=[(1.0, 0.5)])],
        tanks=[ff.Tank("main", mass=5.0, position=(0, 0, 0))],
    )
    tr = ff.simulate(model, q0, v0, 10.0, 1e-3, actuators=acts)
    tr.propellant[:, 0], tr.base_parameters[:, 0]   # propellant left, base mass over time
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields

from .._core import InputError, actuator_fields
from ..io.schema import NonNegative, Positive, TankRef, Text, block_of, key, numbers

# The keys the engine reads and its wheel defaults (`Wheel::new`): one copy, in the engine; the classes below take
# theirs from here and declare each key's type and range once (`key(TYPE, default)`); the scenario schema's blocks
# (`io/scenario_schemas.py`) are made from these classes (`BLOCKS`, below).
FIELDS = actuator_fields()
WHEEL_DEFAULTS = FIELDS["wheels"]["defaults"]


@dataclass
class JointLimit:
    """Limits of the model's joint `joint` (by name) for one simulation, replacing the model's (URDF `<limit>`)
    value of each quantity given; a quantity left out (None) keeps the model's. Symmetric magnitudes: the drive's
    command is clipped to [-effort, effort] (N m or N) and gives no force that drives |rate| further past
    `velocity` (rad/s or m/s)."""

    joint: str = key(Text)
    effort: float | None = key(Positive | None, None)
    velocity: float | None = key(Positive | None, None)


_W = WHEEL_DEFAULTS
_VEC3 = numbers(3)


@dataclass
class Wheel:
    """A reaction wheel: the model's revolute joint `joint` (by name) with its drive. The commanded torque is that
    joint's entry of the torques/controller; the drive saturates it (torque, power, then speed: no torque that
    drives |Ω| further past max_speed, Basilisk's order) once per step and subtracts friction at every stage.
    Limits are optional (None: none). Units: N m, rad/s, W, N m s/rad, kg m, kg m²."""

    joint: str = key(Text)
    max_torque: float | None = key(Positive | None, _W["max_torque"])
    max_speed: float | None = key(Positive | None, _W["max_speed"])
    max_power: float | None = key(Positive | None, _W["max_power"])
    coulomb: float = key(NonNegative, _W["coulomb"])
    static_friction: float = key(NonNegative, _W["static_friction"])
    stribeck_speed: float | None = key(Positive | None, _W["stribeck_speed"])
    viscous: float = key(NonNegative, _W["viscous"])
    limit_cycle_speed: float = key(Positive, _W["limit_cycle_speed"])
    static_imbalance: float = key(NonNegative, _W["static_imbalance"])
    dynamic_imbalance: float = key(NonNegative, _W["dynamic_imbalance"])


@dataclass
class Thruster:
    """A thruster on `body` (None: the base) at `position` (body frame, m) pushing the body along `direction`
    with max_thrust (N) while a firing is on. `firings`: (start, duration) pairs in seconds; a firing shorter
    than min_on_time lasts min_on_time; thrust ramps linearly over ramp_on/ramp_off seconds. A thruster fed by a
    `tank` (its name or index) needs `isp` (s) and stops when the tank is empty."""

    direction: tuple = key(_VEC3)
    max_thrust: float = key(Positive)
    position: tuple = key(_VEC3, (0.0, 0.0, 0.0))
    body: str | None = key(Text | None, None)
    min_on_time: float = key(NonNegative, 0.0)
    ramp_on: float = key(NonNegative, 0.0)
    ramp_off: float = key(NonNegative, 0.0)
    isp: float | None = key(Positive | None, None)
    tank: str | int | None = key(TankRef, None)
    firings: list = key(list[numbers(2)], default_factory=list)
    name: str | None = key(Text | None, None)


@dataclass
class Tank:
    """A propellant tank on `body` (None: the base) at `position` (body frame, m): `mass` kg of propellant at t = 0,
    already included in the body's mass in the model; a point mass (radius 0) or a uniform sphere of `radius` m.
    The body's inertial parameters follow the propellant left."""

    name: str = key(Text)
    mass: float = key(Positive)
    position: tuple = key(_VEC3, (0.0, 0.0, 0.0))
    body: str | None = key(Text | None, None)
    radius: float = key(NonNegative, 0.0)


@dataclass
class Actuators:
    """Joint limits, wheels, thrusters and tanks of one simulation (`simulate(..., actuators=...)`)."""

    wheels: list = field(default_factory=list)
    thrusters: list = field(default_factory=list)
    tanks: list = field(default_factory=list)
    limits: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """The plain mapping the engine reads (also the layout of a YAML `actuators:` block)."""
        out = {}
        for lst, kind in _KINDS:
            items = []
            for j, a in enumerate(getattr(self, lst)):
                if isinstance(a, dict):
                    items.append(dict(a))
                elif isinstance(a, kind):
                    d = asdict(a)
                    for k in ("position", "direction"):
                        if k in d and d[k] is not None:
                            d[k] = [float(x) for x in d[k]]
                    d["firings"] = [tuple(map(float, f)) for f in d["firings"]] if "firings" in d else None
                    items.append({k: v for k, v in d.items() if v is not None})
                else:
                    raise InputError(
                        f"actuators.{lst}[{j}]: expected a freefloat.{kind.__name__}, got {type(a).__name__}"
                    )
            out[lst] = items
        return out

    @classmethod
    def from_dict(cls, d, where: str = "actuators") -> Actuators:
        """Read an `actuators:` mapping (from a scenario or YAML file): lists `limits`, `wheels`, `thrusters`,
        `tanks` of mappings with the fields of JointLimit, Wheel, Thruster, Tank. Unknown keys are errors naming
        them."""
        allowed = ", ".join(FIELDS["actuators"])
        if not isinstance(d, dict):
            raise InputError(f"{where}: expected a mapping with {allowed}, got {type(d).__name__}")
        unknown = set(d) - set(FIELDS["actuators"])
        if unknown:
            raise InputError(f"{where}: unknown key(s) {sorted(unknown)} (allowed: {allowed})")
        lists = {}
        for lst, kind in _KINDS:
            items = d.get(lst) or []
            if not isinstance(items, list):
                raise InputError(f"{where}.{lst}: expected a list")
            names = {f.name for f in fields(kind)}
            out = []
            for j, it in enumerate(items):
                if not isinstance(it, dict):
                    raise InputError(f"{where}.{lst}[{j}]: expected a mapping of settings")
                bad = set(it) - names
                if bad:
                    raise InputError(f"{where}.{lst}[{j}]: unknown key(s) {sorted(bad)} (allowed: {sorted(names)})")
                try:
                    out.append(kind(**it))
                except TypeError as e:  # a required field is missing
                    raise InputError(f"{where}.{lst}[{j}]: {e}") from None
            lists[lst] = out
        return cls(**lists)


_KINDS = (("limits", JointLimit), ("wheels", Wheel), ("thrusters", Thruster), ("tanks", Tank))
#: the schema block of each list of an `actuators:` block, made from the class above (keys in the engine's order)
BLOCKS = {
    lst: block_of(kind, FIELDS[lst]["keys"], name=name)
    for (lst, kind), name in zip(_KINDS, ("ActLimit", "ActWheel", "ActThruster", "ActTank"))
}


def add_wheels(model_yaml: dict, n: int = 3, *, axes=None, inertia=(0.1, 0.05), mass: float = 1.0, radius=0.2):
    """A convenience for YAML model descriptions: append `n` reaction-wheel bodies (revolute joints named
    rw1..rwn) to the base of the model mapping `model_yaml` (the layout `Model.from_yaml` reads) and return it.
    `axes`: n spin axes in the base frame (default x, y, z, then repeated); `inertia`: (spin, transverse)
    moments of each rotor (kg m²); `radius`: distance of each wheel from the base origin along its axis."""
    import numpy as np

    axes = axes or [np.eye(3)[k % 3] for k in range(n)]
    if len(axes) != n:
        raise InputError(f"argument `axes`: {len(axes)} axes for {n} wheels")
    base = model_yaml["bodies"][0]["name"]
    js, jt = inertia
    for k, a in enumerate(axes):
        a = np.asarray(a, float)
        if not np.linalg.norm(a) > 0:
            raise InputError(f"argument `axes`: wheel {k + 1} has a zero-length axis")
        a = a / np.linalg.norm(a)
        # rotor inertia about its centre, joint-frame axes: Js along the spin axis, Jt across it
        inert = jt * np.eye(3) + (js - jt) * np.outer(a, a)
        model_yaml["bodies"].append(
            {
                "name": f"rw{k + 1}",
                "parent": base,
                "joint": {"type": "revolute", "name": f"rw{k + 1}", "axis": a.tolist()},
                "origin": {"xyz": (radius * a).tolist(), "rpy": [0, 0, 0]},
                "inertial": {
                    "mass": float(mass),
                    "com": [0, 0, 0],
                    "inertia": {
                        "xx": float(inert[0, 0]),
                        "yy": float(inert[1, 1]),
                        "zz": float(inert[2, 2]),
                        "xy": float(inert[0, 1]),
                        "yz": float(inert[1, 2]),
                        "xz": float(inert[0, 2]),
                    },
                },
                "tags": ["wheel"],
            }
        )
    return model_yaml
