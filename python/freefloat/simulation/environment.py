"""The orbital environment of a simulation: point-mass gravity of a central body with the orbit of the system,
the gravity gradient on every body, J2 and a constant disturbance wrench (Valverde 2018, §2.3.3). Every effect is
off unless asked for; the physics is the engine's (`freefloat._core.Environment`), this module only reads the
`environment:` block of a scenario file.

Example::

    env = ff.Environment(altitude=500e3, inclination=np.radians(51.6), gravity_gradient=True)
    traj = ff.simulate(model, q0, v0, 3 * env.period, 1.0, environment=env)
    r_inertial = traj.orbit[:, :3]  # the simulation frame's origin (starts at the system's CoM)

With an orbit the simulator's world frame keeps inertial axes and its origin falls freely along the orbit, so
`q` stays in metres; each body feels the tidal force on its centre of mass and the gravity-gradient torque about
it (see docs/environment.md).

A scenario block::

    environment:
      central_body: {mu: 3.986004418e14, radius: 6378137.0, j2: 1.0826267e-3}   # optional (the Earth)
      orbit: {altitude: 500e3, eccentricity: 0.0, inclination_deg: 51.6, raan_deg: 0,
              arg_periapsis_deg: 0, true_anomaly_deg: 0}     # or semi_major_axis, or position + velocity
      gravity_gradient: true
      j2: false
      disturbance: {force: [0, 0, 0], torque: [1e-6, 0, 0], axes: body, body: 0}
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from .._core import Environment, InputError
from ..io.schema import Bool, Number, Positive, integer, literal, number, numbers

__all__ = ["EARTH", "Environment", "environment_from_dict", "load_environment"]

#: the default central body, the Earth (the engine's `CentralBody::EARTH`: μ in m³/s², equatorial radius in m, J2;
#: tests/test_environment.py checks μ and the radius against the engine)
EARTH = {"mu": 3.986004418e14, "radius": 6378137.0, "j2": 1.0826267e-3}

# The keys of an `environment:` block, with their schema types and defaults: declared once, here. The reader below
# takes the names; the scenario schema (`io/scenario_schemas.py`) makes its blocks from the whole declaration.
_VEC3 = numbers(3)
CENTRAL_BODY_KEYS = {"mu": (Positive, EARTH["mu"]), "radius": (Positive, EARTH["radius"]), "j2": (Number, EARTH["j2"])}
ORBIT_KEYS = {
    "altitude": (Positive | None, None),
    "semi_major_axis": (Positive | None, None),
    "eccentricity": (number(lo=0.0, hi=1.0, hi_open=True), None),
    "inclination_deg": (Number, None),
    "raan_deg": (Number, None),
    "arg_periapsis_deg": (Number, None),
    "true_anomaly_deg": (Number, None),
    "inclination": (Number, None),
    "raan": (Number, None),
    "arg_periapsis": (Number, None),
    "true_anomaly": (Number, None),
    "position": (_VEC3, None),
    "velocity": (_VEC3, None),
}
DISTURBANCE_KEYS = {
    "force": (_VEC3, None),
    "torque": (_VEC3, None),
    "axes": (literal("inertial", "body"), "inertial"),
    "body": (integer(lo=0), 0),
}
#: the top-level keys: the three sections above and the two switches
TOP_KEYS = {
    "central_body": None,
    "orbit": None,
    "gravity_gradient": (Bool, False),
    "j2": (Bool, False),
    "disturbance": None,
}
_ORBIT_KEYS = set(ORBIT_KEYS)
_TOP_KEYS = set(TOP_KEYS)


def _number(x: Any, key: str) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise InputError(f"environment.{key}: expected a number, got {x!r}")
    if not math.isfinite(float(x)):
        raise InputError(f"environment.{key}: must be finite, got {x!r}")
    return float(x)


def _keys(block: Mapping, allowed: set[str], where: str) -> None:
    unknown = sorted(set(block) - allowed)
    if unknown:
        raise InputError(f"{where}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(sorted(allowed))}")


def environment_from_dict(block: Mapping | None) -> Environment | None:
    """An `Environment` from the `environment:` block of a scenario file (None for an absent block). Angles in
    the file are degrees (`*_deg` keys) or radians (the plain keys); lengths are metres. Errors name the key."""
    if block is None:
        return None
    if not isinstance(block, Mapping):
        raise InputError(f"environment: expected a mapping, got {type(block).__name__}")
    _keys(block, _TOP_KEYS, "environment")
    kw: dict[str, Any] = {}
    cb = block.get("central_body")
    if cb is not None:
        if not isinstance(cb, Mapping):
            raise InputError("environment.central_body: expected a mapping with mu, radius, j2")
        _keys(cb, set(CENTRAL_BODY_KEYS), "environment.central_body")
        if "mu" in cb:
            mu = _number(cb["mu"], "central_body.mu")
            if mu <= 0:
                raise InputError(f"environment.central_body.mu: the gravitational parameter must be positive, got {mu}")
            kw["mu"] = mu
        if "radius" in cb:
            r = _number(cb["radius"], "central_body.radius")
            if r <= 0:
                raise InputError(f"environment.central_body.radius: must be positive, got {r}")
            kw["radius"] = r
        if "j2" in cb:
            kw["j2_coefficient"] = _number(cb["j2"], "central_body.j2")
    orbit = block.get("orbit")
    if orbit is not None:
        if not isinstance(orbit, Mapping):
            raise InputError("environment.orbit: expected a mapping (altitude or semi_major_axis, elements)")
        _keys(orbit, _ORBIT_KEYS, "environment.orbit")
        for k in ("altitude", "semi_major_axis", "eccentricity"):
            if k in orbit:
                kw[k] = _number(orbit[k], f"orbit.{k}")
        if "altitude" in kw and kw["altitude"] <= 0:
            raise InputError(
                "environment.orbit.altitude: the orbit must be above the central body's surface, "
                f"got {kw['altitude']} m"
            )
        for k in ("inclination", "raan", "arg_periapsis", "true_anomaly"):
            if f"{k}_deg" in orbit and k in orbit:
                raise InputError(f"environment.orbit: give {k} or {k}_deg, not both")
            if f"{k}_deg" in orbit:
                kw[k] = math.radians(_number(orbit[f"{k}_deg"], f"orbit.{k}_deg"))
            elif k in orbit:
                kw[k] = _number(orbit[k], f"orbit.{k}")
        for k in ("position", "velocity"):
            if k in orbit:
                v = orbit[k]
                if not isinstance(v, (list, tuple)) or len(v) != 3:
                    raise InputError(f"environment.orbit.{k}: expected 3 numbers")
                kw[k] = [_number(x, f"orbit.{k}") for x in v]
    for k in ("gravity_gradient", "j2"):
        if k in block:
            if not isinstance(block[k], bool):
                raise InputError(f"environment.{k}: expected true or false, got {block[k]!r}")
            kw[k] = block[k]
    dist = block.get("disturbance")
    if dist is not None:
        if not isinstance(dist, Mapping):
            raise InputError("environment.disturbance: expected a mapping with force, torque, axes, body")
        _keys(dist, set(DISTURBANCE_KEYS), "environment.disturbance")
        for k in ("force", "torque"):
            if k in dist:
                v = dist[k]
                if not isinstance(v, (list, tuple)) or len(v) != 3:
                    raise InputError(f"environment.disturbance.{k}: expected 3 numbers")
                kw[f"disturbance_{k}"] = [_number(x, f"disturbance.{k}") for x in v]
        if "force" not in dist and "torque" not in dist:
            raise InputError("environment.disturbance: give a force, a torque or both")
        if "axes" in dist:
            if dist["axes"] not in ("inertial", "body"):
                raise InputError(f"environment.disturbance.axes: must be 'inertial' or 'body', got {dist['axes']!r}")
            kw["disturbance_axes"] = dist["axes"]
        if "body" in dist:
            b = dist["body"]
            if isinstance(b, bool) or not isinstance(b, int) or b < 0:
                raise InputError(f"environment.disturbance.body: expected a body index ≥ 0, got {b!r}")
            kw["disturbance_body"] = b
    try:
        return Environment(**kw)
    except InputError as e:
        raise InputError(f"environment: {e}") from None


def load_environment(path) -> Environment | None:
    """The environment of a YAML file: its `environment:` block, or the whole file when it is that block."""
    import yaml

    with open(path, encoding="utf-8") as f:
        doc = yaml.safe_load(f)
    if isinstance(doc, Mapping) and "environment" in doc:
        doc = doc["environment"]
    return environment_from_dict(doc)
