"""Controllers for free-flying space robots (not implemented yet; the package holds their place).

What will land here, from Valverde 2018 (Georgia Tech PhD thesis, "Dynamic modeling and control of spacecraft
robotic systems using dual quaternions"):

- chapter 4: adaptive pose tracking of a spacecraft with concurrent learning, on dual quaternions;
- chapter 8: differential dynamic programming (DDP) for the multibody robot;
- chapter 9: concurrent-learning mass-property estimation during control.

A controller is a callable `f(t, q, v) -> tau` (generalized forces; for a free base the first six entries are the
base-frame thruster wrench), so it plugs into `ff.simulate(..., controller=f, controller_period=dt)`; its numbers
(laws, gradients) belong in the engine (`crates/freefloat-core/src/control/`), with this package driving them.
"""

__all__: list[str] = []
