"""Dual quaternions (Valverde 2018): the algebra of chapters 2-3 (`algebra`, also this package's namespace) and
joint reaction wrenches along a trajectory from the dual-quaternion multibody formulation of chapters 5-7
(`reactions`; the solver itself is `ff.dq_dynamics`), and the dual-inertia regressor of chapters 4 and 9
(`regressor`).

    import freefloat as ff
    q = ff.dq.from_pose(quat_xyzw, t)        # pose of a frame: unit dual quaternion q + eps 1/2 t q
    r = ff.reactions.along(model, traj)      # the same module as ff.dq.reactions
"""

from . import algebra, reactions, regressor
from .algebra import (
    DualQuaternion,
    approach_slope,
    attitude,
    body_poses,
    condition_number,
    dh,
    dh_chain,
    distance_bound,
    exp,
    from_pose,
    identity,
    line_of_sight,
    screw,
    vector,
)
from .regressor import body_regressor, h_vector, inertia_params, r_matrix, relative_regressor

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
    "inertia_params",
    "r_matrix",
    "h_vector",
    "body_regressor",
    "relative_regressor",
    "algebra",
    "regressor",
    "reactions",
]
