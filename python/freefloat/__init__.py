"""freefloat: model, simulate, excite, identify and control free-floating space robots.

    import freefloat as ff
    m = ff.models.load("seed001_dual_arm")
    q, v = m.neutral(), np.zeros(m.nv)
    ff.momentum(m, q, v); ff.aba(m, q, v, tau)
    traj = ff.simulate(m, q, v, t_final=10.0, dt=1e-3)

Conventions are in docs/architecture.md; every number is computed by the Rust engine."""

from . import dq, estimation, excitation, models, online, reactions, telemetry, trajectories
from ._core import InputError, ModelError, NumericalError
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
from .minimal import MinimalParameters, minimal_parameters
from .model import Model
from .simulation import Trajectory, simulate
from .telemetry import Telemetry
from .identify import IdentificationResult, identify_minimal

__version__ = "0.1.0"

__all__ = [
    "Model", "Trajectory", "models", "dq", "online", "reactions", "simulate", "telemetry", "trajectories", "excitation", "Telemetry", "estimation", "identify_minimal", "IdentificationResult",
    "aba", "rnea", "crba", "hybrid_dynamics", "dq_dynamics",
    "forward_kinematics", "frame_placement", "body_velocities", "body_accelerations", "frame_jacobian", "generalized_jacobian",
    "center_of_mass", "momentum", "kinetic_energy", "centroidal_momentum_matrix",
    "momentum_regressor", "dynamics_regressor",
    "base_twist_for_momentum", "integrate_base_poses", "quat_to_matrix", "matrix_to_quat", "skew",
    "minimal_parameters", "MinimalParameters",
    "ModelError", "InputError", "NumericalError",
]
