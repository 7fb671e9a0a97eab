"""Dynamics derivatives (freefloat.derivatives) against independent oracles.

* Pinocchio 4.0.0 `computeABADerivatives` / `computeRNEADerivatives` on random floating, planar and fixed-base
  trees (tests/random_trees.py, built in Pinocchio directly from the description), with and without external
  forces. Layout maps: q and v are reordered by the tree's depth-first permutation only; the q-tangent is the
  same (a base-frame twist) to first order, which `test_tangent_convention_matches_pinocchio_to_first_order`
  checks on its own.
* Crocoddyl 3.2.1 `IntegratedActionModelEuler` (semi-implicit Euler, full actuation) on the ch. 8 spacecraft
  (RRR arm + Z-Y-X wrist, nv = 12): the velocity rows of Fx, Fu and the next velocity must agree to round-off;
  the configuration rows use different groups for ⊕ (ours R³ × SO(3), Crocoddyl SE(3)) and agree to O(dt);
  on a fixed-base tree ⊕ is the same in both, so the whole Fx, Fu must agree.
* central finite differences of `ff.derivatives.step` (Euler and RK4) and of the frame-pose functions.
"""

import functools

import numpy as np
import pytest

import random_trees as rt
from random_trees import assert_close

ff = pytest.importorskip("freefloat", reason="freefloat is not importable yet (the engine is not built)")
pin = pytest.importorskip("pinocchio", reason="Pinocchio (PyPI `pin`) is needed as the oracle")
D = ff.derivatives

NO_UNIVERSAL = ("revolute", "prismatic", "spherical", "cylindrical", "fixed")
SEEDS = range(24)


@functools.cache
def case(seed):
    rng = np.random.default_rng(7_000 + seed)
    base = rt.BASE_TYPES[seed % 3]
    d = rt.random_tree(
        rng, name=f"deriv_tree_{seed}", base=base, joint_types=NO_UNIVERSAL, joint_p=(0.35, 0.15, 0.15, 0.15, 0.2)
    )
    return d, ff.Model.from_yaml_string(d.to_yaml()), rt.build_pinocchio(d)


def square_from_pin(p, M):
    """A (nv, nv) Pinocchio matrix (rows and columns v-indexed) in our layout."""
    M = np.asarray(M, float).reshape(len(p.v_perm), len(p.v_perm))
    return p.cols_from_pin(p.cols_from_pin(M).T).T


@pytest.mark.parametrize("seed", SEEDS)
def test_aba_and_rnea_derivatives_match_pinocchio(seed):
    d, m, p = case(seed)
    rng = np.random.default_rng(seed)
    for k in range(2):
        q, v, tau = d.random_q(rng), d.random_v(rng), rng.normal(size=d.nv)
        fext = d.random_fext(rng) if k == 1 else None
        da_dq, da_dv, da_dtau = D.aba_derivatives(m, q, v, tau, fext=fext)
        args = [p.model, p.data, p.q_to_pin(q), p.v_to_pin(v), p.v_to_pin(tau)]
        if fext is not None:
            args.append(p.fext_to_pin(fext))
        pq, pv, pm = pin.computeABADerivatives(*args)
        assert_close(da_dq, square_from_pin(p, pq), rtol=1e-8, atol=1e-10, what=f"da/dq ({d.base} base)")
        assert_close(da_dv, square_from_pin(p, pv), rtol=1e-8, atol=1e-10, what="da/dv")
        pm = np.asarray(pm, float)
        pm = np.triu(pm) + np.triu(pm, 1).T  # Pinocchio documents filling the upper triangle only
        assert_close(da_dtau, square_from_pin(p, pm), rtol=1e-8, atol=1e-10, what="da/dtau = M^-1")

        a = rng.normal(size=d.nv)
        dt_dq, dt_dv, dt_da = D.rnea_derivatives(m, q, v, a, fext=fext)
        args = [p.model, p.data, p.q_to_pin(q), p.v_to_pin(v), p.v_to_pin(a)]
        if fext is not None:
            args.append(p.fext_to_pin(fext))
        rq, rv, ra = pin.computeRNEADerivatives(*args)
        ra = np.asarray(ra, float)
        ra = np.triu(ra) + np.triu(ra, 1).T
        assert_close(dt_dq, square_from_pin(p, rq), rtol=1e-8, atol=1e-10, what="dtau/dq")
        assert_close(dt_dv, square_from_pin(p, rv), rtol=1e-8, atol=1e-10, what="dtau/dv")
        assert_close(dt_da, square_from_pin(p, ra), rtol=1e-9, atol=1e-10, what="dtau/da = M")


@pytest.mark.parametrize("seed", [0, 3, 6])
def test_tangent_convention_matches_pinocchio_to_first_order(seed):
    """The q-tangent of the derivatives is Pinocchio's: ff.integrate and pin.integrate of the same tangent
    vector agree to O(eps^2) (the error drops 100x when eps drops 10x), while an inertial-frame base
    displacement would disagree at O(eps)."""
    d, m, p = case(seed)  # free bases (seed % 3 == 0)
    assert d.base == "free"
    rng = np.random.default_rng(seed)
    q, dv = d.random_q(rng), rng.normal(size=d.nv)
    errs = []
    for eps in (1e-2, 1e-3):
        ours = np.asarray(D.integrate(m, q, eps * dv), float)
        theirs = p.q_from_pin(pin.integrate(p.model, p.q_to_pin(q), p.v_to_pin(eps * dv)))
        errs.append(np.abs(D.difference(m, theirs, ours)).max())
    assert errs[1] < errs[0] / 50, errs
    # and the columns of da/dq are directional derivatives along exactly that tangent
    tau = rng.normal(size=d.nv)
    da_dq, _, _ = D.aba_derivatives(m, q, rng.normal(size=d.nv) * 0, tau)
    h = 1e-6
    fd = (
        ff.aba(m, D.integrate(m, q, h * dv), np.zeros(d.nv), tau)
        - ff.aba(m, D.integrate(m, q, -h * dv), np.zeros(d.nv), tau)
    ) / (2 * h)
    assert_close(da_dq @ dv, fd, rtol=1e-6, atol=1e-8, what="da/dq along a tangent vector")


def test_universal_joints_are_refused():
    rng = np.random.default_rng(1)
    d = rt.random_tree(rng, name="u", base="free", n_children=3, joint_types=("universal",), joint_p=(1.0,))
    m = ff.Model.from_yaml_string(d.to_yaml())
    with pytest.raises(ff.InputError, match="universal"):
        D.aba_derivatives(m, d.random_q(rng), np.zeros(d.nv), np.zeros(d.nv))


def test_bad_input_names_the_argument():
    d, m, _ = case(0)
    q, z = d.random_q(np.random.default_rng(0)), np.zeros(d.nv)
    with pytest.raises(ff.InputError, match="`tau`"):
        D.aba_derivatives(m, q, z, z[:-1])
    with pytest.raises(ff.InputError, match="`dt`"):
        D.step_derivatives(m, q, z, z, -0.1)
    with pytest.raises(ff.InputError, match="method"):
        D.step_derivatives(m, q, z, z, 0.1, method="rk5")
    bad = z.copy()
    bad[0] = np.nan
    with pytest.raises(ff.InputError, match="`v`"):
        D.step(m, q, bad, z, 0.1)


# ---------------------------------------------------------------- ch. 8 spacecraft: ours and Crocoddyl's

CH8_YAML = """
name: ch8_spacecraft_wrist
base: free
bodies:
  - {name: base, inertial: {mass: 50, com: [0, 0, 0], inertia: [10, 10, 10]}}
  - {name: waist, parent: base, joint: {type: revolute, axis: [0, 0, 1]}, origin: {xyz: [0, 0, 1]},
     inertial: {mass: 5, com: [0, 0, 1], inertia: [1, 1, 1]}}
  - {name: shoulder, parent: waist, joint: {type: revolute, axis: [0, 0, 1]},
     origin: {xyz: [0.75, 0, 4], rpy: [1.5707963267948966, 0, 0]},
     inertial: {mass: 5, com: [1.5, 0, 0], inertia: [1, 1, 1]}}
  - {name: elbow, parent: shoulder, joint: {type: revolute, axis: [0, 0, 1]}, origin: {xyz: [3, 0, 0]},
     inertial: {mass: 5, com: [1.5, 0, 0], inertia: [1, 1, 1]}}
  - {name: wrist_z, parent: elbow, joint: {type: revolute, axis: [0, 0, 1]}, origin: {xyz: [3, 0, 0]},
     inertial: {mass: 0.1, com: [0, 0, 0], inertia: [0.01, 0.01, 0.01]}}
  - {name: wrist_y, parent: wrist_z, joint: {type: revolute, axis: [0, 1, 0]},
     inertial: {mass: 0.1, com: [0, 0, 0], inertia: [0.01, 0.01, 0.01]}}
  - {name: wrist_x, parent: wrist_y, joint: {type: revolute, axis: [1, 0, 0]},
     inertial: {mass: 0.1, com: [0, 0, 0], inertia: [0.01, 0.01, 0.01]}}
frames:
  - {name: ee, body: wrist_x}
"""


def ch8_pinocchio():
    """The same spacecraft built in Pinocchio directly (Crocoddyl baseline §2), root joint 'root_joint'."""
    model = pin.Model()
    model.gravity = pin.Motion.Zero()
    I3 = np.eye(3)
    jid = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
    model.appendBodyToJoint(jid, pin.Inertia(50.0, np.zeros(3), 10 * I3), pin.SE3.Identity())
    rx = pin.SE3(pin.utils.rotate("x", np.pi / 2), np.array([0.75, 0, 4.0]))
    chain = [
        ("waist", pin.JointModelRZ(), pin.SE3(I3, np.array([0, 0, 1.0])), 5.0, [0, 0, 1.0], I3),
        ("shoulder", pin.JointModelRZ(), rx, 5.0, [1.5, 0, 0], I3),
        ("elbow", pin.JointModelRZ(), pin.SE3(I3, np.array([3.0, 0, 0])), 5.0, [1.5, 0, 0], I3),
        ("wrist_z", pin.JointModelRZ(), pin.SE3(I3, np.array([3.0, 0, 0])), 0.1, [0, 0, 0], 0.01 * I3),
        ("wrist_y", pin.JointModelRY(), pin.SE3.Identity(), 0.1, [0, 0, 0], 0.01 * I3),
        ("wrist_x", pin.JointModelRX(), pin.SE3.Identity(), 0.1, [0, 0, 0], 0.01 * I3),
    ]
    for name, jm, pl, mass, com, inertia in chain:
        jid = model.addJoint(jid, jm, pl, name)
        model.appendBodyToJoint(jid, pin.Inertia(mass, np.array(com), inertia), pin.SE3.Identity())
    model.addFrame(pin.Frame("ee", jid, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return model


def ch8_state(rng):
    q = np.zeros(13)
    q[:3] = rng.normal(size=3)
    quat = rng.normal(size=4)
    q[3:7] = quat / np.linalg.norm(quat)
    q[7:] = rng.uniform(-1.5, 1.5, size=6)
    return q, rng.normal(size=12) * 0.5, rng.normal(size=12)


def crocoddyl_euler(pm, dt):
    croc = pytest.importorskip("crocoddyl", reason="Crocoddyl is the oracle for the Euler step")
    state = croc.StateMultibody(pm)
    act = croc.ActuationModelFull(state)
    costs = croc.CostModelSum(state, act.nu)
    dam = croc.DifferentialActionModelFreeFwdDynamics(state, act, costs)
    iam = croc.IntegratedActionModelEuler(dam, dt)
    return iam, iam.createData()


def test_ch8_model_is_the_same_in_both():
    m, pm = ff.Model.from_yaml_string(CH8_YAML), ch8_pinocchio()
    q, v, tau = ch8_state(np.random.default_rng(2))
    assert_close(ff.aba(m, q, v, tau), pin.aba(pm, pm.createData(), q, v, tau), rtol=1e-10, atol=1e-12, what="aba")
    # thesis initial state: (θ2, θ3, ψ) = (5°, −10°, 5°) puts the end effector at [6.72717, 0, 5]
    q0 = np.r_[0, 0, 0, 0, 0, 0, 1, 0, np.radians(5), np.radians(-10), np.radians(5), 0, 0]
    assert_close(ff.frame_placement(m, q0, "ee")[:3], [6.72717, 0, 5], rtol=0, atol=1e-5, what="ee position")


@pytest.mark.parametrize("dt", [0.05, 0.015])
def test_euler_step_derivatives_match_crocoddyl(dt):
    m, pm = ff.Model.from_yaml_string(CH8_YAML), ch8_pinocchio()
    iam, idata = crocoddyl_euler(pm, dt)
    rng = np.random.default_rng(3)
    nv = 12
    for _ in range(3):
        q, v, tau = ch8_state(rng)
        x = np.r_[q, v]
        iam.calc(idata, x, tau)
        iam.calcDiff(idata, x, tau)
        Fx, Fu = D.step_derivatives(m, q, v, tau, dt)
        qn, vn = D.step(m, q, v, tau, dt)
        assert_close(vn, idata.xnext[13:], rtol=1e-12, atol=1e-12, what="v+")
        assert_close(Fx[nv:], idata.Fx[nv:], rtol=1e-9, atol=1e-11, what="velocity rows of Fx")
        assert_close(Fu[nv:], idata.Fu[nv:], rtol=1e-9, atol=1e-11, what="velocity rows of Fu")
        # configuration rows: ⊕ on R³ × SO(3) vs SE(3); same up to O(dt |v+|)
        scale = dt * (1 + np.abs(vn).max())
        assert np.abs(Fx[:nv] - idata.Fx[:nv]).max() < 5 * scale * np.abs(idata.Fx[:nv]).max()
        assert np.abs(D.difference(m, idata.xnext[:13], qn)).max() < (dt * np.abs(vn).max()) ** 2


def test_euler_step_derivatives_match_crocoddyl_exactly_on_a_fixed_base():
    rng = np.random.default_rng(5)
    d = rt.random_tree(
        rng, name="fixed_chain", base="fixed", n_children=6, joint_types=("revolute", "prismatic"), joint_p=(0.7, 0.3)
    )
    for i, b in enumerate(d.bodies[1:], start=1):
        b.parent = i - 1  # a chain: Pinocchio's depth-first order is ours
    m, p = ff.Model.from_yaml_string(d.to_yaml()), rt.build_pinocchio(d)
    dt = 0.02
    iam, idata = crocoddyl_euler(p.model, dt)
    q, v, tau = d.random_q(rng), d.random_v(rng), rng.normal(size=d.nv)
    x = np.r_[p.q_to_pin(q), p.v_to_pin(v)]
    iam.calc(idata, x, p.v_to_pin(tau))
    iam.calcDiff(idata, x, p.v_to_pin(tau))
    Fx, Fu = D.step_derivatives(m, q, v, tau, dt)
    assert list(p.v_perm) == list(range(d.nv)), "a chain keeps the order"
    assert_close(Fx, idata.Fx, rtol=1e-9, atol=1e-11, what="Fx")
    assert_close(Fu, idata.Fu, rtol=1e-9, atol=1e-11, what="Fu")


@pytest.mark.parametrize("method", ["euler", "rk4"])
def test_step_derivatives_match_finite_differences(method):
    m = ff.Model.from_yaml_string(CH8_YAML)
    rng = np.random.default_rng(4)
    q, v, tau = ch8_state(rng)
    dt, h, nv = 0.05, 1e-6, 12
    Fx, Fu = D.step_derivatives(m, q, v, tau, dt, method=method)
    q0n, v0n = D.step(m, q, v, tau, dt, method=method)

    def err(qn, vn):
        return np.r_[D.difference(m, q0n, qn), vn - v0n]

    fd_x, fd_u = np.zeros((2 * nv, 2 * nv)), np.zeros((2 * nv, nv))
    for k in range(nv):
        e = np.zeros(nv)
        e[k] = h
        fd_x[:, k] = (
            err(*D.step(m, D.integrate(m, q, e), v, tau, dt, method=method))
            - err(*D.step(m, D.integrate(m, q, -e), v, tau, dt, method=method))
        ) / (2 * h)
        fd_x[:, nv + k] = (
            err(*D.step(m, q, v + e, tau, dt, method=method)) - err(*D.step(m, q, v - e, tau, dt, method=method))
        ) / (2 * h)
        fd_u[:, k] = (
            err(*D.step(m, q, v, tau + e, dt, method=method)) - err(*D.step(m, q, v, tau - e, dt, method=method))
        ) / (2 * h)
    assert_close(Fx, fd_x, rtol=1e-6, atol=1e-8, what=f"Fx ({method})")
    assert_close(Fu, fd_u, rtol=1e-6, atol=1e-8, what=f"Fu ({method})")


def test_rk4_step_is_the_simulators_step():
    m = ff.Model.from_yaml_string(CH8_YAML)
    q, v, _ = ch8_state(np.random.default_rng(6))
    tau = np.zeros(12)
    qn, vn = D.step(m, q, v, tau, 0.01, method="rk4")
    tr = ff.simulate(m, q, v, t_final=0.01, dt=0.01, method="rk4")
    assert_close(np.asarray(tr.q)[-1], qn, rtol=1e-12, atol=1e-12, what="q+")
    assert_close(np.asarray(tr.v)[-1], vn, rtol=1e-12, atol=1e-12, what="v+")


def test_frame_pose_derivatives():
    m, pm = ff.Model.from_yaml_string(CH8_YAML), ch8_pinocchio()
    pdata = pm.createData()
    rng = np.random.default_rng(8)
    q, _, _ = ch8_state(rng)
    target = np.r_[1.0, -2.0, 3.0, np.array([0.1, 0.7, -0.2, 0.6]) / np.linalg.norm([0.1, 0.7, -0.2, 0.6])]
    e, J = D.frame_log_error_derivatives(m, q, "ee", target)
    # Pinocchio: log6(M_ref^-1 M) and Jlog6 · frame Jacobian (LOCAL), as Crocoddyl's ResidualModelFramePlacement
    fid = pm.getFrameId("ee")
    pin.framesForwardKinematics(pm, pdata, q)
    Mref = pin.XYZQUATToSE3(target)
    rMf = Mref.actInv(pdata.oMf[fid])
    e_pin = pin.log6(rMf).vector
    J_pin = pin.Jlog6(rMf) @ pin.computeFrameJacobian(pm, pdata, q, fid, pin.LOCAL)
    assert_close(e, e_pin, rtol=1e-10, atol=1e-12, what="log6 error")
    assert_close(J, J_pin, rtol=1e-9, atol=1e-11, what="log6 error Jacobian")
    # dual-quaternion pose against central differences (same sign branch)
    x, Jx = D.frame_dq_pose_derivatives(m, q, "ee")
    h = 1e-6
    fd = np.zeros((8, 12))
    for k in range(12):
        e_k = np.zeros(12)
        e_k[k] = h
        xp, _ = D.frame_dq_pose_derivatives(m, D.integrate(m, q, e_k), "ee")
        xm, _ = D.frame_dq_pose_derivatives(m, D.integrate(m, q, -e_k), "ee")
        xp, xm = xp * np.sign(xp[:4] @ x[:4]), xm * np.sign(xm[:4] @ x[:4])
        fd[:, k] = (xp - xm) / (2 * h)
    assert_close(Jx, fd, rtol=1e-6, atol=1e-8, what="dual-quaternion pose Jacobian")
    # the pose itself: translation first, r = 2 q_d q_r*
    r = ff.frame_placement(m, q, "ee")
    qr, qd = x[:4], x[4:]
    pos = 2 * np.array(
        [
            -qd[0] * qr[1] + qd[1] * qr[0] - qd[2] * qr[3] + qd[3] * qr[2],
            -qd[0] * qr[2] + qd[1] * qr[3] + qd[2] * qr[0] - qd[3] * qr[1],
            -qd[0] * qr[3] - qd[1] * qr[2] + qd[2] * qr[1] + qd[3] * qr[0],
        ]
    )
    assert_close(pos, r[:3], rtol=1e-12, atol=1e-12, what="position from the dual quaternion")


def test_stacked_inputs():
    m = ff.Model.from_yaml_string(CH8_YAML)
    rng = np.random.default_rng(9)
    states = [ch8_state(rng) for _ in range(4)]
    Q, V, T = (np.array([s[i] for s in states]) for i in range(3))
    Fx, Fu = D.step_derivatives(m, Q, V, T, 0.05)
    assert Fx.shape == (4, 24, 24) and Fu.shape == (4, 24, 12)
    for k in range(4):
        fx, fu = D.step_derivatives(m, Q[k], V[k], T[k], 0.05)
        np.testing.assert_array_equal(Fx[k], fx)
        np.testing.assert_array_equal(Fu[k], fu)
