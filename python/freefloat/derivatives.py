"""Analytic derivatives of the dynamics, of one discrete step and of frame poses (engine functions).

Every function takes one sample or a leading time axis, like `freefloat.algorithms`, and returns
numpy arrays (matrices row-major).

Tangent convention. A derivative with respect to q has nv columns: the *local* tangent of q, the
space the generalized velocity v lives in. For a free base that is a displacement and a rotation
vector in **base-frame** axes (the axes of the base twist in v); for a spherical joint a child-frame
rotation vector; for the other joints the coordinate itself. To first order this is Pinocchio's
convention, so `aba_derivatives` compares entry for entry with `pinocchio.computeABADerivatives`
(same q and v layout, quaternion x y z w). The finite step ``integrate(q, dq)`` is taken on
R³ × SO(3) (position += R dq_lin, attitude ∘ Exp(dq_ang)), the group the simulator integrates on,
not SE(3) as `pinocchio.integrate`: the two agree to first order only.

- ``aba_derivatives(model, q, v, tau, fext=None) -> (da_dq, da_dv, da_dtau)``, da_dtau = M⁻¹
- ``rnea_derivatives(model, q, v, a, fext=None) -> (dtau_dq, dtau_dv, M)``
- ``step(model, q, v, tau, dt, method="euler") -> (q_next, v_next)``; method "euler" is the
  semi-implicit Euler of Crocoddyl's IntegratedActionModelEuler (v⁺ = v + a dt, q⁺ = q ⊕ v⁺ dt),
  "rk4" the Runge-Kutta-Munthe-Kaas RK4 step of the simulator; tau is held over the step.
- ``step_derivatives(model, q, v, tau, dt, method="euler") -> (Fx, Fu)``, Fx (2nv, 2nv), Fu (2nv, nv),
  rows and columns [tangent of q; v]. The control is the full generalized force tau (base wrench in
  base axes, then joint forces); with an actuation matrix ``tau = B @ u`` use ``Fu @ B`` (an
  unactuated free base: ``Fu[:, 6:]``).
- ``integrate``, ``difference``, ``integrate_jacobians``, ``difference_jacobians``: ⊕, ⊖ and their
  Jacobians in the same tangent.
- ``frame_log_error_derivatives(model, q, name, target) -> (e, de_dq)``: e = log(T_target⁻¹ T(q))
  (SE(3) logarithm, [linear; angular], target = position + quaternion x y z w).
- ``frame_dq_pose_derivatives(model, q, name) -> (pose, dpose_dq)``: unit dual quaternion of the
  frame pose (real w x y z, dual w x y z; translation first) and its (8, nv) Jacobian.

Universal joints are not supported (InputError naming the joint).
"""

from __future__ import annotations

from ._core import (
    aba_derivatives,
    difference,
    difference_jacobians,
    frame_dq_pose_derivatives,
    frame_log_error_derivatives,
    integrate,
    integrate_jacobians,
    rnea_derivatives,
    step,
    step_derivatives,
)

__all__ = [
    "aba_derivatives",
    "difference",
    "difference_jacobians",
    "frame_dq_pose_derivatives",
    "frame_log_error_derivatives",
    "integrate",
    "integrate_jacobians",
    "rnea_derivatives",
    "step",
    "step_derivatives",
]
