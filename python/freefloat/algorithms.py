"""Kinematics and dynamics. Every function takes one sample or a leading time axis (q of shape
(T, nq), ...) and computes all samples in one call into the engine (GIL released for stacked input).

They are the engine's own functions: they accept a `freefloat.Model` and anything numpy can read as
float64, and check shapes and finiteness themselves (naming the argument and sample at fault).

Frames: momentum is [linear; angular about the inertial origin] in the inertial frame; fext is
(nbodies, 6) body-frame wrenches [force; torque about the body origin]; for a free base, the first
six generalized forces are the base-frame wrench [force; torque] on the base (thrusters)."""

from __future__ import annotations

from . import _core
from ._arrays import as_f64
from ._core import (
    aba,
    body_accelerations,
    body_velocities,
    center_of_mass,
    centroidal_momentum_matrix,
    crba,
    dynamics_regressor,
    forward_kinematics,
    frame_jacobian,
    frame_placement,
    kinetic_energy,
    matrix_to_quat,
    momentum,
    momentum_regressor,
    quat_to_matrix,
    rnea,
    skew,
)

__all__ = [
    "aba",
    "body_accelerations",
    "body_velocities",
    "center_of_mass",
    "centroidal_momentum_matrix",
    "crba",
    "dq_dynamics",
    "dynamics_regressor",
    "forward_kinematics",
    "frame_jacobian",
    "frame_placement",
    "generalized_jacobian",
    "hybrid_dynamics",
    "kinetic_energy",
    "momentum",
    "momentum_regressor",
    "rnea",
    "base_twist_for_momentum",
    "integrate_base_poses",
    "matrix_to_quat",
    "quat_to_matrix",
    "skew",
]


def base_twist_for_momentum(model, q, joint_rates, momentum=None):
    """Base velocity that gives the total momentum `momentum` ([p; L about the inertial origin], inertial
    frame; default zero) when the joints after the base move with `joint_rates` (nv - nv_base,) at `q`:
    a free base's twist [v; ω] in the base frame (6,), a planar base's [vx, vy, yaw rate] (3,). One sample
    or a leading time axis. The engine's one momentum solve (Naveen, Shah, Misra's momentum model; the base
    part of the generalized Jacobian)."""
    return _core.base_twist_for_momentum(model, q, joint_rates, momentum)


def integrate_base_poses(t, twists, pose0, rates=None):
    """Base poses from sampled base twists by the trapezoidal rule on the group (the engine's
    `sim::integrate_base_poses`). Free base: twists (T, 6) [v; ω] in the base frame, pose0 (7,) position and
    quaternion x y z w, returns (T, 7). Planar base: twists (T, 3) [vx, vy, yaw rate], pose0 (3,)
    [x, y, yaw], returns (T, 3). t (T,) increasing times (steps may be uneven). `rates` (the twists' shape):
    their time derivatives at the samples, which add the fourth-order (Hermite) correction to every step."""
    r = None if rates is None else as_f64(rates, "rates")
    return _core.integrate_base_poses(as_f64(t, "t"), as_f64(twists, "twists"), as_f64(pose0, "pose0"), r)


def generalized_jacobian(model, q, name: str, reference: str = "world", h0=None):
    """Generalized Jacobian of a free-floating robot (Umetani & Yoshida).

    With the total momentum held at h0 (default zero), the twist of frame `name` is
    Jg @ qdot_joints + offset. Returns (Jg of shape (6, nv - nv_base), offset (6,))."""
    h0 = None if h0 is None else tuple(as_f64(h0, "h0").reshape(-1))
    return _core.generalized_jacobian(model, q, name, reference, h0)


def hybrid_dynamics(model, q, v, tau, ddq, prescribed, fext=None):
    """Hybrid dynamics: the joints named in `prescribed` follow the accelerations `ddq` (their
    entries; the other entries are ignored) while the base and the other joints respond to `tau`.

    Returns (ddq_all, tau_all): all accelerations, and all generalized forces, in which the prescribed
    joints' entries are the forces they needed."""
    if isinstance(prescribed, str):
        prescribed = [prescribed]
    return _core.hybrid_dynamics(model, q, v, tau, ddq, list(prescribed), fext)


def dq_dynamics(model, q, v, tau, fext=None, locked=None, formulation="dq"):
    """Forward dynamics and joint wrenches by the dual-quaternion Newton-Euler formulation
    (Valverde 2018, ch. 5-6): one linear system for every body's acceleration and every joint's
    reaction, solved through the Schur complement (a symmetric positive-definite Delassus matrix).

    Returns (a, W): `a` (nv,) the generalized accelerations, equal to `aba(model, q, v, tau, fext)`;
    `W` (nbodies, 6) per joint the wrench it transmits onto its child body -- reaction plus actuation --
    as [force; torque about the child body origin] in child body axes, equal to the spatial force the
    engine's RNEA recovers at those accelerations. Row 0 is the base joint (a free base: `tau[:6]`).
    The pure reaction of a revolute joint is `W` without its torque about the joint axis (which is tau).

    `locked`: joint names held at zero acceleration (their `tau` entries are ignored; the torque they need
    is the actuated component of their row of `W`). Free or fixed base; revolute, prismatic, spherical,
    cylindrical, universal and fixed joints (the decoupled formulation: all but universal); every moving body needs a
    positive mass and a positive-definite inertia.

    `formulation="decoupled"` solves chapter 5's decoupled (3-vector) Newton-Euler system instead, with the
    same outputs (no `locked`); the two agree to round-off."""
    if isinstance(locked, str):
        locked = [locked]
    return _core.dq_dynamics(model, q, v, tau, fext, None if locked is None else list(locked), formulation)
