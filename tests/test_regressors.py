"""Momentum and inverse-dynamics regressors: stacked form, bad input, and an independent check against
Pinocchio (`computeJointTorqueRegressor`, `bodyRegressor`, centroidal momentum) on the built-in robots
loaded from our URDF export and on random trees (every joint and base type, gravity).

Pinocchio merges bodies on fixed joints into the joint that carries them, so its regressor has one
10-column block per moving joint, multiplying the merged inertia. Body i carried by joint j at placement X
adds X·I_i to that inertia, a linear map of body i's parameters; so our block i must equal Pinocchio's
block j times the 10×10 matrix of that map (the identity for a body with a joint of its own)."""

import functools

import numpy as np
import pytest

import freefloat as ff

import random_trees as rt  # tests/ is on sys.path under pytest's default import mode

GRAVITY = np.array([0.3, -1.2, -9.81])


def test_regressors_reproduce_momentum_and_rnea():
    m = ff.models.load("naveen_dual_arm").with_gravity(GRAVITY)
    rng = np.random.default_rng(5)
    q = m.random_configuration(rng)
    v, a = rng.normal(size=m.nv), rng.normal(size=m.nv)
    P = m.parameters().ravel()
    K, Y = ff.momentum_regressor(m, q, v), ff.dynamics_regressor(m, q, v, a)
    assert K.shape == (6, 10 * m.nbodies) and Y.shape == (m.nv, 10 * m.nbodies)
    np.testing.assert_allclose(K @ P, ff.momentum(m, q, v), rtol=1e-12, atol=1e-10)
    np.testing.assert_allclose(Y @ P, ff.rnea(m, q, v, a), rtol=1e-12, atol=1e-10)


def test_stacked_equals_loop():
    m = ff.models.load("zhang2020_3d")
    rng = np.random.default_rng(6)
    T = 4
    q = np.array([m.random_configuration(rng) for _ in range(T)])
    v, a = rng.normal(size=(T, m.nv)), rng.normal(size=(T, m.nv))
    K, Y = ff.momentum_regressor(m, q, v), ff.dynamics_regressor(m, q, v, a)
    assert K.shape == (T, 6, 10 * m.nbodies) and Y.shape == (T, m.nv, 10 * m.nbodies)
    for k in range(T):
        np.testing.assert_array_equal(K[k], ff.momentum_regressor(m, q[k], v[k]))
        np.testing.assert_array_equal(Y[k], ff.dynamics_regressor(m, q[k], v[k], a[k]))
    # a single sample broadcasts against stacked ones
    np.testing.assert_array_equal(ff.dynamics_regressor(m, q[0], v, a)[2], ff.dynamics_regressor(m, q[0], v[2], a[2]))


def test_bad_input_names_the_argument():
    m = ff.models.load("zhang2020_3d")
    q, v = m.neutral(), np.zeros(m.nv)
    with pytest.raises(ff.InputError, match=r"`v`.*\(12\) or \(T, 12\)"):
        ff.momentum_regressor(m, q, v[:-1])
    a = v.copy()
    a[3] = np.nan
    with pytest.raises(ff.InputError, match=r"`a`: entry 3 is NaN"):
        ff.dynamics_regressor(m, q, v, a)
    with pytest.raises(ff.InputError, match="share the time axis"):
        ff.dynamics_regressor(m, np.tile(q, (2, 1)), np.zeros((3, m.nv)), v)


# ------------------------------------------------------------------------------------------------------------
# Pinocchio
# ------------------------------------------------------------------------------------------------------------

try:
    import pinocchio as pin
except ImportError:
    pin = None
needs_pin = pytest.mark.skipif(pin is None, reason="Pinocchio (PyPI `pin`) is needed as the oracle")


class PinSide:
    """What the comparison needs from a Pinocchio model: layout maps, and per body of ours the frame id, the
    carrying joint (0: welded to the universe) and the body's placement in that joint."""

    def __init__(self, model, layout, bodies):
        self.model, self.data, self.layout, self.bodies = model, model.createData(), layout, bodies

    @classmethod
    def from_urdf(cls, m, path):
        m.to_urdf(path)
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        model.gravity = pin.Motion(np.asarray(m.gravity, float), np.zeros(3))
        layout = rt.NamedLayout(model, rt.ff_joint_rows(m))
        return cls(model, layout, [layout.body_frame(name) for name in m.body_names])

    @classmethod
    def from_tree(cls, t: rt.PinTree):
        bodies = [(t.frame_id[b.name], j, X) for b, j, X in zip(t.desc.bodies, t.joint_of_body, t.body_in_joint)]
        return cls(t.model, t, bodies)

    def state(self, q, v, a):
        lo = self.layout
        return lo.q_to_pin(q), lo.v_to_pin(v), lo.v_to_pin(a)

    def dynamics_regressor(self, P, q, v, a):
        """Pinocchio's joint-torque regressor spread over our bodies' columns, rows in our v order."""
        Yp = pin.computeJointTorqueRegressor(self.model, self.data, *self.state(q, v, a))
        Y = np.zeros((self.model.nv, 10 * len(self.bodies)))
        for i, (_, j, X) in enumerate(self.bodies):
            if j > 0:
                Y[:, 10 * i : 10 * i + 10] = Yp[:, 10 * (j - 1) : 10 * j] @ carry_matrix(X, P[i])
        return self.layout.cols_from_pin(Y.T).T

    def momentum_regressor(self, q, v):
        """Per body: its momentum regressor in its own frame (`bodyRegressor` with zero velocity and the body
        twist as acceleration gives I·twist) carried to the inertial origin."""
        qp, vp, _ = self.state(q, v, v)
        pin.forwardKinematics(self.model, self.data, qp, vp)
        pin.updateFramePlacements(self.model, self.data)
        blocks = []
        for fid, _, _ in self.bodies:
            twist = pin.getFrameVelocity(self.model, self.data, fid, pin.LOCAL)
            oXf = self.data.oMf[fid].toDualActionMatrix()
            blocks.append(oXf @ pin.bodyRegressor(pin.Motion.Zero(), twist))
        return np.hstack(blocks)

    def momentum(self, q, v):
        qp, vp, _ = self.state(q, v, v)
        return rt.pin_momentum_at_origin(self.model, self.data, qp, vp)

    def rnea(self, q, v, a):
        return self.layout.v_from_pin(pin.rnea(self.model, self.data, *self.state(q, v, a)))


def carry_matrix(X, p):
    """10×10 matrix of the linear map p ↦ params(X·I(p)) (Pinocchio's own Inertia.se3Action), by differences
    about a body with positive mass so that Pinocchio's (mass, com, inertia at com) form is defined."""
    base = X.act(pin.Inertia.FromDynamicParameters(p)).toDynamicParameters()
    return np.column_stack(
        [X.act(pin.Inertia.FromDynamicParameters(p + e)).toDynamicParameters() - base for e in np.eye(10)]
    )


def max_rel(a, b):
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1.0))


ERRORS = {}  # largest relative error seen per check, printed with `pytest -s`


def check(name, a, b, tol=1e-9):
    e = max_rel(a, b)
    ERRORS[name] = max(ERRORS.get(name, 0.0), e)
    assert e < tol, f"{name}: relative error {e:.2e}"


def compare(m, side, rng, n_states=3):
    P = m.parameters()
    for _ in range(n_states):
        q = m.random_configuration(rng)
        v, a = rng.normal(size=m.nv), rng.normal(size=m.nv)
        Y, K = ff.dynamics_regressor(m, q, v, a), ff.momentum_regressor(m, q, v)
        check("Y vs computeJointTorqueRegressor", Y, side.dynamics_regressor(P, q, v, a))
        check("Y P vs pin.rnea", Y @ P.ravel(), side.rnea(q, v, a))
        check("K vs bodyRegressor blocks", K, side.momentum_regressor(q, v))
        check("K P vs centroidal momentum at O", K @ P.ravel(), side.momentum(q, v))


@needs_pin
@pytest.mark.parametrize("gravity", [np.zeros(3), GRAVITY], ids=["zero_g", "g"])
@pytest.mark.parametrize("name", ["naveen_dual_arm_consistent", "zhang2020_3d"])
def test_builtin_robots_match_pinocchio(tmp_path, name, gravity):
    m = ff.models.load(name).with_gravity(gravity)
    side = PinSide.from_urdf(m, tmp_path / "robot.urdf")
    merged = sum(1 for t in m.joint_types if t == "fixed")
    assert side.model.njoints - 1 == m.nbodies - merged  # zhang2020_3d's target is merged into link6 by Pinocchio
    compare(m, side, np.random.default_rng(12))


@functools.cache
def tree(seed):
    d = rt.tree_from_seed(seed)
    return ff.Model.from_yaml_string(d.to_yaml()), PinSide.from_tree(rt.build_pinocchio(d))


@needs_pin
@pytest.mark.parametrize("seed", rt.TREE_SEEDS[::4])
def test_random_trees_match_pinocchio(seed):
    m, side = tree(seed)
    compare(m, side, np.random.default_rng(30_000 + seed), n_states=2)


def teardown_module():
    for k, e in ERRORS.items():
        print(f"  max relative error, {k}: {e:.1e}")
