"""The simulation stage: integrate a robot's motion (`run.py`), in batches (`batch.py`), with its actuators
(`actuators.py`) and its orbital environment (`environment.py`); `kind: simulate` scenario files (`scenario.py`,
which also reads the sensors, so it is imported by name: `freefloat.simulation.scenario`).

    import freefloat as ff
    traj = ff.simulate(m, q0, v0, t_final=10.0, dt=1e-3)       # or: from freefloat.simulation import simulate

Every name of the former module `freefloat.simulation` is here; `freefloat.actuators`, `freefloat.environment`,
`freefloat.batch_simulation` and `freefloat.simulation_scenario` still name the modules that moved here."""

from . import actuators, batch, environment, run
from .actuators import Actuators, JointLimit, Tank, Thruster, Wheel
from .batch import Trajectories, simulate_many, torque_table
from .environment import Environment, environment_from_dict, load_environment
from .run import (
    MOMENTUM_NAMES,
    ORBIT_NAMES,
    PARAMETER_NAMES,
    Trajectory,
    memory_limit,
    simulate,
    simulate_driven,
)

__all__ = [
    "MOMENTUM_NAMES",
    "ORBIT_NAMES",
    "PARAMETER_NAMES",
    "Actuators",
    "Environment",
    "JointLimit",
    "Tank",
    "Thruster",
    "Trajectories",
    "Trajectory",
    "Wheel",
    "actuators",
    "batch",
    "environment",
    "environment_from_dict",
    "load_environment",
    "memory_limit",
    "run",
    "simulate",
    "simulate_driven",
    "simulate_many",
    "torque_table",
]
