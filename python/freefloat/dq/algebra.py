"""Dual-quaternion algebra, poses, screws, DH kinematics and constraints (Valverde 2018, chapters 2-3).

    import freefloat as ff
    q = ff.dq.from_pose(quat_xyzw, t)        # pose of a frame: unit dual quaternion q + eps 1/2 t q
    quat_xyzw, t = (q * p).to_pose()         # composition, back to the engine convention
    w = ff.dq.vector(omega, v)               # a twist omega + eps v (a wrench: f + eps tau)
    q.shift_in(w)                            # q* w q: the twist seen from the frame q places

Coefficients are ``[real w, x, y, z, dual w, x, y, z]`` (the thesis' order); the engine's quaternions are
``(x, y, z, w)`` and only ``from_pose``/``to_pose`` cross between the two. "Unit" means ``q q* = 1``
(``q.is_unit()``), never ``norm(q) == 1``. All arithmetic runs in Rust (``freefloat_core::dualquat``).

Constraint functions return ``(value, gradient)`` with ``value <= 0`` feasible and the gradient with
respect to the 8 coefficients. ``line_of_sight`` implements the physical statement (3.34) -- the target
inside the cone about the gripper axis -- which is the opposite sign of the printed (3.35); see
docs/architecture.md.
"""

from __future__ import annotations

import numpy as np

from .. import _core
from .._core import DualQuaternion

__all__ = [
    "DualQuaternion",
    "from_pose",
    "identity",
    "vector",
    "exp",
    "screw",
    "dh",
    "dh_chain",
    "line_of_sight",
    "approach_slope",
    "attitude",
    "distance_bound",
    "body_poses",
    "condition_number",
]


def from_pose(quat_xyzw, t) -> DualQuaternion:
    """Unit dual quaternion ``q + eps 1/2 t q`` of the pose (quaternion x, y, z, w; translation t)."""
    return _core.dq_from_pose(quat_xyzw, t)


def identity() -> DualQuaternion:
    return DualQuaternion([1.0, 0, 0, 0, 0, 0, 0, 0])


def vector(a, b) -> DualQuaternion:
    """The vector dual quaternion ``(0, a) + eps (0, b)``: a twist ``omega + eps v`` or wrench ``f + eps tau``."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != (3,):
        raise _core.InputError(f"argument `a`: expected shape (3,), got {a.shape}")
    if b.shape != (3,):
        raise _core.InputError(f"argument `b`: expected shape (3,), got {b.shape}")
    return DualQuaternion(np.concatenate([[0.0], a, [0.0], b]))


def exp(x) -> DualQuaternion:
    """``exp`` of a vector dual quaternion (a unit dual quaternion); inverse of ``DualQuaternion.log``."""
    return _core.dq_exp(x)


def screw(theta: float, d: float, l, m) -> DualQuaternion:
    """Screw motion (3.10): rotation ``theta`` about and translation ``d`` along the line with unit direction
    ``l`` and moment ``m = p x l``."""
    return _core.dq_screw(float(theta), float(d), l, m)


def dh(d: float, theta: float, a: float, alpha: float) -> DualQuaternion:
    """Standard Denavit-Hartenberg transform (3.26): Trans_z(d) Rot_z(theta) Trans_x(a) Rot_x(alpha)."""
    return _core.dq_dh(float(d), float(theta), float(a), float(alpha))


def dh_chain(rows) -> DualQuaternion:
    """Product of DH transforms over rows ``(d, theta, a, alpha)``."""
    rows = np.asarray(rows, dtype=float)
    if rows.ndim != 2 or rows.shape[1] != 4:
        raise _core.InputError(f"argument `rows`: expected shape (n, 4), got {rows.shape}")
    return _core.dq_dh_chain(rows.tolist())


def _cv(res):
    value, grad = res
    return value, np.asarray(grad)


def line_of_sight(q_ga, y_g, half_angle: float):
    """Target A within ``half_angle`` of the gripper axis ``y_g`` seen from G (Prop. 1, sign resolved).
    ``q_ga`` is the pose of the gripper G relative to the target A."""
    return _cv(_core.dq_line_of_sight(q_ga, y_g, float(half_angle)))


def approach_slope(q_ga, z_a, half_angle: float):
    """Gripper G within the cone of ``half_angle`` about the target axis ``z_a`` (Prop. 2)."""
    return _cv(_core.dq_approach_slope(q_ga, z_a, float(half_angle)))


def attitude(q_bi, n_i, n_b, max_angle: float):
    """Body axis ``n_b`` within ``max_angle`` of the inertial direction ``n_i`` (Prop. 3)."""
    return _cv(_core.dq_attitude(q_bi, n_i, n_b, float(max_angle)))


def distance_bound(q, delta: float):
    """``|translation| <= delta`` as ``q o q - 1 - delta^2/4 <= 0`` (Lemmas 7, 10)."""
    return _cv(_core.dq_distance_bound(q, float(delta)))


def body_poses(model, q, method: str = "chain") -> np.ndarray:
    """Pose of every body as dual-quaternion coefficients, (nbodies, 8): ``method="chain"`` multiplies the
    relative poses (3.43), ``"poe"`` uses the product of exponentials (3.19) with screws taken at the neutral
    configuration (revolute, prismatic, spherical, cylindrical, universal and fixed joints)."""
    return _core.dq_body_poses(model, q, method)


def condition_number(model, q):
    """2-norm condition number of the dissertation's system matrix S (6.17) of the dual-quaternion dynamics at
    configuration ``q`` (or each row of a (T, nq) array): the quantity of its Figs. 5.5 and 7.x."""
    return _core.dq_condition_number(model, q)
