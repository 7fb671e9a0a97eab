"""Controllers for free-flying space robots (Valverde 2018, Georgia Tech PhD thesis, "Dynamic modeling and
control of spacecraft robotic systems using dual quaternions").

- chapter 4 (`freefloat.control.adaptive`): adaptive dual-quaternion pose tracking of a rigid spacecraft with
  concurrent learning of its mass and inertia: `AdaptivePoseController` for your own loop
  (`.control(t, q_bd, w_bd)` -> dual force, `.update(t, dt, q_bd, w_bd, w_bd_dot, force)`, `.estimate`),
  `adaptive.run(scenario)` for the thesis' examples (`freefloat control adaptive SCENARIO`), and
  `realisability(v)`, whether a parameter vector `[I11, I12, I13, I22, I23, I33, m]` is a rigid body;
- chapter 8 (`freefloat.control.ddp`): end-effector control of the multibody robot by differential dynamic
  programming, open loop, closed loop (time-varying policy) and model-predictive (`freefloat control ddp
  SCENARIO`; docs/ddp.md);
- chapter 9, concurrent-learning mass-property estimation during control, is an estimator:
  `freefloat.identification.concurrent` (`freefloat identify cl SCENARIO`).

A multibody controller is a callable `f(t, q, v) -> tau` (generalized forces; for a free base the first six
entries are the base-frame thruster wrench), so it plugs into `ff.simulate(..., controller=f,
controller_period=dt)`; its numbers (laws, gradients) belong in the engine (`crates/freefloat-core/src/control/`),
with this package driving them.

Every module of this package is reachable as an attribute (`ff.control.ddp`) without being imported here: a new
controller module needs no line in this file (docs/architecture.md, "Where new code goes").
"""

import importlib

from .._core import AdaptivePoseController
from . import adaptive
from .adaptive import realisability

__all__: list[str] = ["AdaptivePoseController", "adaptive", "realisability"]


def __getattr__(name: str):
    # a controller module imported on first use (PEP 562): `ff.control.ddp` works without an import line here, and
    # importing freefloat lists no folder and imports no controller it does not need
    if not name.startswith("_"):
        try:
            return importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as e:
            if e.name != f"{__name__}.{name}":  # the module exists but something it imports does not: say so
                raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
