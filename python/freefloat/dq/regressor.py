"""The dual-inertia regressor (Valverde 2018, §4.1 and §9.1): rigid-body Newton–Euler written linear in the seven
inertial parameters `v(M) = [I11, I12, I13, I22, I23, I33, m]` (inertia about the centre of mass, body axes).

    import freefloat as ff
    v = ff.dq.inertia_params(10.0, I)                         # v(M)
    R = ff.dq.body_regressor(twist, twist_dot)                # 8×7, R @ v = M ⋆ ω̇^s + ω × (M ⋆ ω^s) = f + ε τ
    R = ff.dq.relative_regressor(w_bd_dot, w_bd, w_di_dot, w_di, q_bd)   # eq. (4.3), relative to a moving frame

Dual quaternions are 8 numbers `[real w x y z, dual w x y z]` or `DualQuaternion`s; twists are `ω + ε v`,
wrenches `f + ε τ` (`ff.dq.vector(a, b)` builds one). The formulas are in the engine; these are its bindings.
"""

from __future__ import annotations

import numpy as np

from .. import _core

#: the seven parameters `v(M)` of one body, in the order of Valverde 2018 §4.1
PARAM_NAMES = ("I11", "I12", "I13", "I22", "I23", "I33", "m")


def inertia_params(mass: float, inertia) -> np.ndarray:
    """`v(M) = [I11, I12, I13, I22, I23, I33, m]` of a body of `mass` [kg] and 3×3 `inertia` about its CoM [kg m²]."""
    return _core.dq_inertia_params(float(mass), inertia)


def r_matrix(b) -> np.ndarray:
    """`r(b)` (8×7), eq. (4.2): `r(b) @ v(M) = M ⋆ b` for a vector dual quaternion `b`."""
    return _core.dq_r_matrix(b)


def h_vector(a, b) -> np.ndarray:
    """`h(a, b)` (7,), §4.2: `a ∘ (M ⋆ b) = h(a, b) @ v(M)` for vector dual quaternions."""
    return _core.dq_h_vector(a, b)


def body_regressor(twist, twist_dot) -> np.ndarray:
    """`R̂(ω̇, ω)` (8×7), eq. (9.7), of a body with absolute twist `twist` (about its CoM, body axes) changing at
    the body-frame rate `twist_dot`: `R̂ @ v(M)` is the net dual force about the CoM."""
    return _core.dq_body_regressor(twist, twist_dot)


def relative_regressor(w_bd_dot, w_bd, w_di_dot, w_di, q_bd) -> np.ndarray:
    """`R(ω̇_B/D, ω_B/D, ω̇_D/I, ω_D/I, q_B/D)` (8×7), eq. (4.3): the dual force on body B (about its CoM, B axes)
    that keeps the relative motion of B to a moving desired frame D. `w_bd`, `w_bd_dot` in B axes; `w_di`,
    `w_di_dot` in D axes; `q_bd` the unit pose of B relative to D."""
    return _core.dq_relative_regressor(w_bd_dot, w_bd, w_di_dot, w_di, q_bd)


__all__ = ["body_regressor", "h_vector", "inertia_params", "r_matrix", "relative_regressor"]
