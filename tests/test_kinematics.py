"""Kinematic quantities not covered by the Pinocchio oracle: the generalized Jacobian."""

import numpy as np
import pytest

import freefloat as ff


@pytest.mark.parametrize("name,frame", [("seed001_dual_arm", "ee_A"), ("seed000_3d", "ee"), ("seed000_2d_medium", "ee")])
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
