"""freefloat: model, simulate, excite, identify and control free-floating space robots.

    import freefloat as ff
    m = ff.models.load("naveen_dual_arm")
    q, v = m.neutral(), np.zeros(m.nv)
    ff.momentum(m, q, v); ff.aba(m, q, v, tau)
    traj = ff.simulate(m, q, v, t_final=10.0, dt=1e-3)

The package follows the pipeline a user walks (docs/architecture.md): the core (`model`, `models`, `algorithms`,
`trajectories`, `simulation`), `io` (telemetry and trajectory files, shipped data), `identification` (minimal
parameters, excitation design, least squares, consistent parameters, validation, online estimators),
`postcapture` (Zhang, Yue, Yuan 2020), `dq` (Valverde 2018's dual quaternions and reaction wrenches), `control`,
`viz` (plotting helpers) and `cli` (the `freefloat` command). Every number is computed by the Rust engine."""

import sys as _sys

from . import _cpu

_cpu.check()  # before anything loads the engine: a clear ImportError on too old a processor, not SIGILL

from . import constants, control, derivatives, dq, identification, io, models, simulation, trajectories, viz
from ._core import InputError, Interrupted, ModelError, NumericalError
from .algorithms import (
    aba,
    base_twist_for_momentum,
    body_accelerations,
    body_velocities,
    center_of_mass,
    centroidal_momentum_matrix,
    crba,
    dq_dynamics,
    dynamics_regressor,
    forward_kinematics,
    frame_jacobian,
    frame_placement,
    generalized_jacobian,
    hybrid_dynamics,
    integrate_base_poses,
    kinetic_energy,
    matrix_to_quat,
    momentum,
    momentum_regressor,
    quat_to_matrix,
    rnea,
    skew,
)
from .derivatives import aba_derivatives, rnea_derivatives, step_derivatives
from .dq import reactions
from .identification import (
    IdentificationResult,
    MinimalParameters,
    estimation,
    excitation,
    identify,
    identify_minimal,
    minimal,
    minimal_parameters,
    online,
)
from .io import Telemetry, telemetry
from .model import Model
from .simulation import (
    Actuators,
    Environment,
    JointLimit,
    Tank,
    Thruster,
    Trajectories,
    Trajectory,
    Wheel,
    actuators,
    environment,
    load_environment,
    simulate,
    simulate_many,
    torque_table,
)
from .simulation import scenario as simulation_scenario
from .simulation.scenario import load as load_simulation_scenario
from .simulation.scenario import run as run_simulation_scenario

# The simulation stage's modules moved into `freefloat/simulation/`; their former paths still import them
# (`from freefloat.actuators import add_wheels`, `freefloat.environment.environment_from_dict`, ...).
batch_simulation = simulation.batch
for _old, _new in (
    ("actuators", actuators),
    ("environment", environment),
    ("batch_simulation", batch_simulation),
    ("simulation_scenario", simulation_scenario),
):
    _sys.modules[f"{__name__}.{_old}"] = _new
del _old, _new, _sys

__version__ = "0.1.0"

__all__ = [
    "Actuators",
    "JointLimit",
    "Wheel",
    "Thruster",
    "Tank",
    "Environment",
    "load_environment",
    "Model",
    "Trajectory",
    "models",
    "dq",
    "derivatives",
    "aba_derivatives",
    "rnea_derivatives",
    "step_derivatives",
    "online",
    "reactions",
    "simulate",
    "simulate_many",
    "load_simulation_scenario",
    "run_simulation_scenario",
    "torque_table",
    "Trajectories",
    "telemetry",
    "trajectories",
    "excitation",
    "Telemetry",
    "estimation",
    "identify_minimal",
    "IdentificationResult",
    "aba",
    "rnea",
    "crba",
    "hybrid_dynamics",
    "dq_dynamics",
    "forward_kinematics",
    "frame_placement",
    "body_velocities",
    "body_accelerations",
    "frame_jacobian",
    "generalized_jacobian",
    "center_of_mass",
    "momentum",
    "kinetic_energy",
    "centroidal_momentum_matrix",
    "momentum_regressor",
    "dynamics_regressor",
    "base_twist_for_momentum",
    "integrate_base_poses",
    "quat_to_matrix",
    "matrix_to_quat",
    "skew",
    "minimal_parameters",
    "MinimalParameters",
    "ModelError",
    "InputError",
    "NumericalError",
    "Interrupted",
    "constants",
    "control",
    "identification",
    "identify",
    "io",
    "minimal",
    "viz",
]
