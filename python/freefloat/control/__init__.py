"""Controllers for free-flying space robots (Valverde 2018, Georgia Tech PhD thesis, "Dynamic modeling and
control of spacecraft robotic systems using dual quaternions").

- chapter 4 (`freefloat.control.adaptive`): adaptive dual-quaternion pose tracking of a rigid spacecraft with
  concurrent learning of its mass and inertia: `AdaptivePoseController` for your own loop
  (`.control(t, q_bd, w_bd)` -> dual force, `.update(t, dt, q_bd, w_bd, w_bd_dot, force)`, `.estimate`),
  `adaptive.run(scenario)` for the thesis' examples (`freefloat control adaptive SCENARIO`), and
  `realisability(v)`, whether a parameter vector `[I11, I12, I13, I22, I23, I33, m]` is a rigid body;
- chapter 8: differential dynamic programming (DDP) for the multibody robot (not implemented yet);
- chapter 9: concurrent-learning mass-property estimation during control (not implemented yet).

A multibody controller is a callable `f(t, q, v) -> tau` (generalized forces; for a free base the first six
entries are the base-frame thruster wrench), so it plugs into `ff.simulate(..., controller=f,
controller_period=dt)`; its numbers (laws, gradients) belong in the engine (`crates/freefloat-core/src/control/`),
with this package driving them.
"""

from .._core import AdaptivePoseController
from . import adaptive
from .adaptive import realisability

__all__: list[str] = ["AdaptivePoseController", "adaptive", "realisability"]
