"""Kinematics and dynamics. Every function takes one sample or a leading time axis (q of shape
(T, nq), ...) and computes all samples in one call into the engine, with the GIL released.

Frames: momentum is [linear; angular about the inertial origin] in the inertial frame; fext is
(nbodies, 6) body-frame wrenches [force; torque about the body origin]; for a free base, the first
six generalized forces are the base-frame wrench [force; torque] on the base (thrusters)."""

from __future__ import annotations

import numpy as np

from . import _core
from ._arrays import as_f64, as_f64_or_none
from .model import Model


def _m(model) -> _core.Model:
    if isinstance(model, Model):
        return model._core
    raise TypeError(f"expected a freefloat.Model, got {type(model).__name__}")


def forward_kinematics(model: Model, q) -> np.ndarray:
    """(nbodies, 7): position and quaternion (x, y, z, w) of every body frame, inertial frame."""
    return _core.forward_kinematics(_m(model), as_f64(q, "q"))


def frame_placement(model: Model, q, name: str) -> np.ndarray:
    """(7,): position and quaternion (x, y, z, w) of a body or frame, inertial frame."""
    return _core.frame_placement(_m(model), as_f64(q, "q"), name)


def body_velocities(model: Model, q, v) -> np.ndarray:
    """(nbodies, 6): twist [linear; angular] of every body, in its own body frame."""
    return _core.body_velocities(_m(model), as_f64(q, "q"), as_f64(v, "v"))


def body_accelerations(model: Model, q, v, a, classical: bool = False) -> np.ndarray:
    """(nbodies, 6): acceleration of every body in its own frame, gravity not included.

    Spatial (default): time derivative of the body-frame twist components (Pinocchio LOCAL).
    classical=True: acceleration of the body origin, a_lin + ω × v_lin, and the angular acceleration."""
    return _core.body_accelerations(_m(model), as_f64(q, "q"), as_f64(v, "v"), as_f64(a, "a"), bool(classical))


def center_of_mass(model: Model, q) -> np.ndarray:
    """(3,): centre of mass of the whole system, inertial frame."""
    return _core.center_of_mass(_m(model), as_f64(q, "q"))


def momentum(model: Model, q, v) -> np.ndarray:
    """(6,): [linear momentum; angular momentum about the inertial origin], inertial frame."""
    return _core.momentum(_m(model), as_f64(q, "q"), as_f64(v, "v"))


def kinetic_energy(model: Model, q, v):
    """Kinetic energy of the whole system (a float, or (T,) for stacked input)."""
    return _core.kinetic_energy(_m(model), as_f64(q, "q"), as_f64(v, "v"))


def centroidal_momentum_matrix(model: Model, q) -> np.ndarray:
    """(6, nv) matrix A with momentum(q, v) == A @ v (about the inertial origin, inertial frame)."""
    return _core.centroidal_momentum_matrix(_m(model), as_f64(q, "q"))


def frame_jacobian(model: Model, q, name: str, reference: str = "local") -> np.ndarray:
    """(6, nv) Jacobian of a body or frame; twist [linear; angular] = J @ v.

    reference="local": twist of the frame origin in the frame's axes (Pinocchio LOCAL);
    reference="world": velocity of the frame origin and angular velocity in inertial axes
    (Pinocchio LOCAL_WORLD_ALIGNED)."""
    return _core.frame_jacobian(_m(model), as_f64(q, "q"), name, reference)


def generalized_jacobian(model: Model, q, name: str, reference: str = "world", h0=None):
    """Generalized Jacobian of a free-floating robot (Umetani & Yoshida).

    With the total momentum held at h0 (default zero), the twist of frame `name` is
    Jg @ qdot_joints + offset. Returns (Jg of shape (6, nv - nv_base), offset (6,))."""
    h0 = None if h0 is None else tuple(as_f64(h0, "h0").reshape(-1))
    return _core.generalized_jacobian(_m(model), as_f64(q, "q"), name, reference, h0)


def rnea(model: Model, q, v, a, fext=None) -> np.ndarray:
    """Inverse dynamics (recursive Newton-Euler): (nv,) generalized forces producing accelerations a."""
    return _core.rnea(_m(model), as_f64(q, "q"), as_f64(v, "v"), as_f64(a, "a"), as_f64_or_none(fext, "fext"))


def crba(model: Model, q) -> np.ndarray:
    """Joint-space inertia matrix (nv, nv) by the composite-rigid-body algorithm (full, symmetric)."""
    return _core.crba(_m(model), as_f64(q, "q"))


def aba(model: Model, q, v, tau, fext=None) -> np.ndarray:
    """Forward dynamics (articulated-body algorithm): (nv,) accelerations."""
    return _core.aba(_m(model), as_f64(q, "q"), as_f64(v, "v"), as_f64(tau, "tau"), as_f64_or_none(fext, "fext"))


def hybrid_dynamics(model: Model, q, v, tau, ddq, prescribed, fext=None):
    """Hybrid dynamics: the joints named in `prescribed` follow the accelerations `ddq` (their
    entries; the other entries are ignored) while the base and the other joints respond to `tau`.

    Returns (ddq_all, tau_all): all accelerations, and all generalized forces, in which the prescribed
    joints' entries are the forces they needed."""
    if isinstance(prescribed, str):
        prescribed = [prescribed]
    return _core.hybrid_dynamics(
        _m(model), as_f64(q, "q"), as_f64(v, "v"), as_f64(tau, "tau"), as_f64(ddq, "ddq"), list(prescribed),
        as_f64_or_none(fext, "fext"),
    )
