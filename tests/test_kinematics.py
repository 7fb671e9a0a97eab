"""Kinematic quantities not covered by the Pinocchio oracle: the generalized Jacobian."""

import numpy as np
import pytest

import freefloat as ff


@pytest.mark.parametrize(
    "name,frame", [("naveen_dual_arm", "ee_A"), ("zhang2020_3d", "ee"), ("zhang2020_2d_medium", "ee")]
)
def test_generalized_jacobian_predicts_end_effector_twist(name, frame):
    m = ff.models.load(name)
    rng = np.random.default_rng(3)
    q = m.random_configuration(rng)
    nb = m.nvs[0]
    qd = rng.normal(size=m.nv - nb)
    h0 = rng.normal(size=6)
    if m.joint_types[0] == "planar":
        h0[[2, 3, 4]] = 0  # a planar robot cannot hold out-of-plane momentum
    Jg, off = ff.generalized_jacobian(m, q, frame, reference="world", h0=h0)
    # Independent route: find the base twist that gives momentum h0 by least squares on the
    # momentum function itself (it is linear in v), then take the ordinary Jacobian.
    cols = np.eye(m.nv)[:, :nb]
    rows = [0, 1, 2, 3, 4, 5] if nb == 6 else [0, 1, 5]
    A_b = np.column_stack([ff.momentum(m, q, c) for c in cols.T])[rows]
    rest = ff.momentum(m, q, np.r_[np.zeros(nb), qd])[rows]
    vb = np.linalg.solve(A_b, h0[rows] - rest)
    v = np.r_[vb, qd]
    np.testing.assert_allclose(ff.momentum(m, q, v)[rows], h0[rows], atol=1e-9)
    twist = ff.frame_jacobian(m, q, frame, reference="world") @ v
    np.testing.assert_allclose(Jg @ qd + off, twist, rtol=1e-10, atol=1e-10)


@pytest.mark.parametrize("name", ["zhang2020_3d", "naveen_dual_arm_consistent"])
def test_body_velocities_and_accelerations_match_pinocchio(tmp_path, name):
    pin = pytest.importorskip("pinocchio")
    m = ff.models.load(name)
    path = tmp_path / "robot.urdf"
    m.to_urdf(path)
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    pd = pm.createData()
    # Both order joints depth-first; these robots have no sibling joints out of alphabetical order.
    assert [n for n, k in zip(m.joint_names[1:], m.nvs[1:]) if k] == list(pm.names[2:])
    rng = np.random.default_rng(11)
    q = m.random_configuration(rng)
    v, a = rng.normal(size=m.nv), rng.normal(size=m.nv)
    # Limitless revolute joints are written as URDF "continuous"; Pinocchio stores those as (cos, sin).
    q_pin = np.zeros(pm.nq)
    q_pin[:7] = q[:7]
    for i, name in enumerate(m.joint_names[1:], start=1):
        if m.nqs[i]:
            jm = pm.joints[pm.getJointId(name)]
            x = q[m.idx_q[i]]
            q_pin[jm.idx_q : jm.idx_q + jm.nq] = [np.cos(x), np.sin(x)] if jm.nq == 2 else [x]
    pin.forwardKinematics(pm, pd, q_pin, v, a)
    pin.updateFramePlacements(pm, pd)
    V = ff.body_velocities(m, q, v)
    A = ff.body_accelerations(m, q, v, a)
    C = ff.body_accelerations(m, q, v, a, classical=True)
    local = pin.ReferenceFrame.LOCAL
    for i, body in enumerate(m.body_names):
        fid = pm.getFrameId(body)
        np.testing.assert_allclose(V[i], pin.getFrameVelocity(pm, pd, fid, local).vector, atol=1e-10, err_msg=body)
        np.testing.assert_allclose(A[i], pin.getFrameAcceleration(pm, pd, fid, local).vector, atol=1e-10, err_msg=body)
        np.testing.assert_allclose(
            C[i], pin.getFrameClassicalAcceleration(pm, pd, fid, local).vector, atol=1e-10, err_msg=body
        )
    # Stacked form equals the loop.
    np.testing.assert_array_equal(ff.body_velocities(m, np.tile(q, (2, 1)), np.tile(v, (2, 1)))[1], V)
