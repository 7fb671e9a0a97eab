"""One copy of each formula, in the engine: the bindings of the zero-momentum base twist, base-pose
integration, rotations and skew, and Zhang, Yue, Yuan 2020's identification rows, each checked against an independent
computation -- the numpy formula the package held before (kept here, in the tests, as the oracle), a
conservation law, or a closed form."""

from __future__ import annotations

import numpy as np
import postcapture_numpy_oracle as oracle
import pytest

import freefloat as ff
from freefloat import postcapture as pc
from freefloat.postcapture import equations as eq

import random_trees as rt  # tests/ is on sys.path under pytest's default import mode


def unit_quats(rng, shape):
    q = rng.normal(size=shape + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


# -- rotations and skew ----------------------------------------------------------------------------------
def test_quat_to_matrix_matches_the_closed_form_and_stacks():
    rng = np.random.default_rng(1)
    Q = unit_quats(rng, (7, 5))
    R = ff.quat_to_matrix(Q)
    assert R.shape == (7, 5, 3, 3)
    for i in range(7):
        for j in range(5):
            np.testing.assert_allclose(R[i, j], rt.quat_to_matrix(Q[i, j]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.einsum("...ji,...jk->...ik", R, R), np.broadcast_to(np.eye(3), R.shape), atol=1e-14)
    # the numpy formula the package used (tests/postcapture_numpy_oracle.py); the engine renormalises a
    # quaternion whose norm is not exactly 1 (house policy), hence round-off differences
    flat = Q.reshape(-1, 4)
    np.testing.assert_allclose(ff.quat_to_matrix(flat), oracle.quat_to_matrix(flat), rtol=0, atol=1e-15)
    assert ff.quat_to_matrix(Q[0, 0]).shape == (3, 3)


def test_matrix_to_quat_round_trip():
    rng = np.random.default_rng(2)
    Q = unit_quats(rng, (50,))
    Q[Q[:, 3] < 0] *= -1  # the engine returns w >= 0
    np.testing.assert_allclose(ff.matrix_to_quat(ff.quat_to_matrix(Q)), Q, atol=1e-14)


def test_skew_is_the_cross_product():
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(2, 4, 6, 3))
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", ff.skew(a), b), np.cross(a, b), atol=1e-14)
    S = ff.skew(a[0, 0])
    np.testing.assert_array_equal(S, -S.T)


def test_rotation_bad_input():
    with pytest.raises(ff.InputError, match="quat"):
        ff.quat_to_matrix([0.0, 0.0, 0.0, 2.0])
    with pytest.raises(ff.InputError, match="quat"):
        ff.quat_to_matrix(np.zeros((3, 5)))
    with pytest.raises(ff.InputError, match="quat"):
        ff.quat_to_matrix([np.nan, 0.0, 0.0, 1.0])
    with pytest.raises(ff.InputError, match="rot"):
        ff.matrix_to_quat(2 * np.eye(3))
    with pytest.raises(ff.InputError, match="v"):
        ff.skew(np.zeros(4))


# -- zero-momentum base twist ----------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["naveen_dual_arm", "zhang2020_3d", "zhang2020_2d_medium"])
def test_base_twist_gives_the_requested_momentum(name):
    """Conservation law: with the computed base velocity the engine's momentum is the requested one."""
    m = ff.models.load(name)
    rng = np.random.default_rng(4)
    nb = m.nvs[0]
    T = 6
    q = np.stack([m.random_configuration(rng) for _ in range(T)])
    rates = rng.normal(size=(T, m.nv - nb))
    h0 = rng.normal(size=(T, 6)) * 5
    h0[0] = 0
    vb = ff.base_twist_for_momentum(m, q, rates, h0)
    assert vb.shape == (T, nb)
    h = ff.momentum(m, q, np.concatenate([vb, rates], 1))
    rows = [0, 1, 5] if nb == 3 else list(range(6))
    np.testing.assert_allclose(h[:, rows], h0[:, rows], atol=1e-10 * (1 + np.abs(h0).max()))
    # default: zero momentum
    v0 = ff.base_twist_for_momentum(m, q[1], rates[1])
    np.testing.assert_allclose(ff.momentum(m, q[1], np.r_[v0, rates[1]])[rows], 0, atol=1e-10)


def test_base_twist_matches_the_old_numpy_solve():
    """Oracle: the numpy solve `simulation.simulate_driven` used, A_b v_b = −A_m q̇_m with the
    centroidal momentum matrix."""
    m = ff.models.load("naveen_dual_arm")
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = m.random_configuration(rng)
        rates = rng.normal(size=m.nv - 6)
        A = ff.centroidal_momentum_matrix(m, q)
        old = np.linalg.solve(A[:, :6], -A[:, 6:] @ rates)
        np.testing.assert_allclose(ff.base_twist_for_momentum(m, q, rates), old, rtol=1e-12, atol=1e-14)


def test_base_twist_bad_input():
    m = ff.models.load("naveen_dual_arm")
    with pytest.raises(ff.InputError, match="joint_rates"):
        ff.base_twist_for_momentum(m, m.neutral(), np.zeros(3))
    with pytest.raises(ff.InputError, match="q"):
        ff.base_twist_for_momentum(m, m.neutral()[:-1], np.zeros(m.nv - 6))
    with pytest.raises(ff.InputError, match="momentum"):
        ff.base_twist_for_momentum(m, m.neutral(), np.zeros(m.nv - 6), [np.nan] * 6)


# -- base-pose integration -------------------------------------------------------------------------------
def _old_integrate_attitude(quat0, omega, dt):
    """telemetry._integrate_attitude before the engine took it over (verbatim)."""
    n = len(omega)
    out = np.empty((n, 4))
    x, y, z, w = (float(c) for c in quat0)
    out[0] = x, y, z, w
    half = (omega[:-1] + omega[1:]) * (dt[:, None] / 2)
    ang = np.linalg.norm(half, axis=1)
    small = ang < 1e-8
    sc = np.where(small, 0.5 - ang**2 / 48, np.sin(ang / 2) / np.where(small, 1.0, ang))
    ex = np.column_stack([half * sc[:, None], np.cos(ang / 2)]).tolist()
    for k in range(n - 1):
        bx, by, bz, bw = ex[k]
        x, y, z, w = (
            w * bx + x * bw + y * bz - z * by,
            w * by - x * bz + y * bw + z * bx,
            w * bz + x * by - y * bx + z * bw,
            w * bw - x * bx - y * by - z * bz,
        )
        if k % 1000 == 999:
            nrm = (x * x + y * y + z * z + w * w) ** 0.5
            x, y, z, w = x / nrm, y / nrm, z / nrm, w / nrm
        out[k + 1] = x, y, z, w
    return out


def _old_free_poses(t, tw, pose0):
    dt = np.diff(t)
    quats = _old_integrate_attitude(pose0[3:7], tw[:, 3:6], dt)
    lin = np.einsum("kij,kj->ki", oracle.quat_to_matrix(quats), tw[:, 0:3])
    pos = np.vstack([pose0[:3], pose0[:3] + np.cumsum((lin[:-1] + lin[1:]) * dt[:, None] / 2, axis=0)])
    return np.hstack([pos, quats])


def test_base_poses_match_the_old_telemetry_rule():
    """Oracle: telemetry.integrate_poses' numpy rule (uneven steps). The engine renormalises every step
    (the old loop every 1000) and sums positions step by step (the old code by cumsum): equal to round-off."""
    rng = np.random.default_rng(6)
    T = 3000
    t = np.cumsum(rng.uniform(0.005, 0.015, T)) - 0.01
    tw = np.column_stack([np.sin(t), np.cos(2 * t), 0.3 * t, 0.4 * np.sin(0.5 * t), -0.2 + 0 * t, 0.1 * np.cos(t)])
    tw += rng.normal(scale=1e-3, size=tw.shape)
    pose0 = np.r_[1.0, -2.0, 0.5, unit_quats(rng, ())]
    new = ff.integrate_base_poses(t, tw, pose0)
    old = _old_free_poses(t, tw, pose0)
    np.testing.assert_allclose(new, old, rtol=0, atol=1e-12)


def test_planar_base_poses_match_the_old_rule():
    rng = np.random.default_rng(7)
    T = 500
    t = np.cumsum(rng.uniform(0.01, 0.02, T))
    tw = rng.normal(size=(T, 3))
    pose0 = np.array([0.3, -0.1, 0.7])
    new = ff.integrate_base_poses(t, tw, pose0)
    dt = np.diff(t)
    yaw = np.r_[pose0[2], pose0[2] + np.cumsum((tw[:-1, 2] + tw[1:, 2]) * dt / 2)]
    c, s = np.cos(yaw), np.sin(yaw)
    lin = np.column_stack([c * tw[:, 0] - s * tw[:, 1], s * tw[:, 0] + c * tw[:, 1]])
    xy = np.vstack([pose0[:2], pose0[:2] + np.cumsum((lin[:-1] + lin[1:]) * dt[:, None] / 2, axis=0)])
    np.testing.assert_allclose(new, np.column_stack([xy, yaw]), rtol=0, atol=1e-12)


def test_base_poses_bad_input():
    t = np.arange(5) * 0.1
    with pytest.raises(ff.InputError, match="t"):
        ff.integrate_base_poses(t[::-1], np.zeros((5, 6)), [0, 0, 0, 0, 0, 0, 1])
    with pytest.raises(ff.InputError, match="twists"):
        ff.integrate_base_poses(t, np.zeros((5, 4)), [0, 0, 0, 0, 0, 0, 1])
    with pytest.raises(ff.InputError, match="pose0"):
        ff.integrate_base_poses(t, np.zeros((5, 6)), [0, 0, 0, 0, 0, 0, 3])
    with pytest.raises(ff.InputError, match="t"):
        ff.integrate_base_poses(t[:4], np.zeros((5, 6)), [0, 0, 0, 0, 0, 0, 1])


# -- Zhang, Yue, Yuan 2020's identification rows ----------------------------------------------------------------------
@pytest.fixture(scope="module", params=["zhang2020_2d_medium", "zhang2020_3d"])
def measured(request):
    sc = pc.load_scenario(request.param)
    sc.duration = 6.0
    m = ff.models.load(sc.model)
    sim = pc.simulate(sc, m)
    sc.measurement["momentum_point"] = "base"  # the default (these paper scenarios pin the origin)
    meas = pc.measure(m, sim, sc)
    sc.measurement["momentum_point"] = "origin"  # the paper's eqs. (9)-(10), what the numpy oracle implements
    origin = pc.measure(m, sim, sc)
    return m, meas, origin, sim


def _close(new, old, what):
    # round-off only: the impulse blocks are running sums over every step (6 s at the 3D scenario's 0.5 ms:
    # 12 000 terms, N·ε ≈ 2.7e-12), so the bound is 1e-11; a formula error shows at 1e-6 and above
    scale = np.abs(old).max(axis=tuple(range(1, old.ndim)), keepdims=True) + 1e-300
    err = (np.abs(new - old) / scale).max()
    assert err < 1e-11, f"{what}: {err:.2e}"


@pytest.mark.parametrize("form", ["momentum", "force"])
def test_engine_rows_match_the_old_numpy_equations(measured, form):
    """Oracle: the numpy equations the package held (tests/postcapture_numpy_oracle.py, verbatim), on a
    simulated record: every row block equal to round-off (relative to each sample's largest entry). The oracle
    balances angular momentum about the inertial origin, as the paper does (measurement.momentum_point: origin)."""
    m, _, meas, _ = measured
    assert meas.transport is None
    names = m.body_names
    base, target = 0, len(names) - 1
    new_p = getattr(eq, f"paper_{form}_rows")(m, meas, base, target)
    old_p = getattr(oracle, f"paper_{form}_rows")(m, meas, base, target)
    for k in ("t", "A", "b", "Phi", "y", "Psi"):
        assert getattr(new_p, k).shape == getattr(old_p, k).shape, k
        _close(getattr(new_p, k), getattr(old_p, k), f"paper {form} {k}")
    new_s = getattr(eq, f"standard_{form}_rows")(m, meas, base, target)
    old_s = getattr(oracle, f"standard_{form}_rows")(m, meas, base, target)
    for k in ("t", "Phi", "y"):
        assert getattr(new_s, k).shape == getattr(old_s, k).shape, k
        _close(getattr(new_s, k), getattr(old_s, k), f"standard {form} {k}")


def test_rows_hold_at_the_true_parameters(measured):
    """Closed check: at the model's own parameters the rows' residuals vanish (the engine simulated the
    motion and the engine's regressors and closed forms describe it), about the base point (the transport term
    integrated by Simpson's rule on the simulator's steps) and about the inertial origin."""
    m, meas_b, meas_o, _ = measured
    base, target = 0, len(m.body_names) - 1
    L = eq.Layout(m.joint_types[0] == "planar")
    (m1, b1, I1), (mn, bn, In) = eq.body_truth(m, base), eq.body_truth(m, target)
    mu = np.concatenate([np.r_[mm, mm * b][L.mu_cols] for mm, b in ((m1, b1), (mn, bn))])
    th = np.concatenate([eq.inertia_sharp(I)[L.th_cols] for I in (I1, In)])
    D = np.concatenate([eq.mJ(m1, b1)[L.d_cols], eq.mJ(mn, bn)[L.d_cols]])
    if L.planar:  # the planar D entry is m (bx² + by²)
        D[3], D[7] = m1 * (b1 @ b1), mn * (bn @ bn)
    P = np.array(m.parameters())
    x = np.concatenate([P[base][L.std_cols], P[target][L.std_cols]])
    for form, meas in (("momentum", meas_b), ("momentum", meas_o), ("force", meas_b)):
        pr = getattr(eq, f"paper_{form}_rows")(m, meas, base, target)
        sr = getattr(eq, f"standard_{form}_rows")(m, meas, base, target)
        lin = np.abs(eq.mv(pr.A, mu) - pr.b).max() / np.abs(pr.b).max()
        ang = np.abs(eq.mv(pr.Phi, th) - pr.y - eq.mv(pr.Psi, D)).max() / np.abs(pr.y).max()
        std = np.abs(eq.mv(sr.Phi, x) - sr.y).max() / np.abs(sr.y).max()
        assert max(lin, ang, std) < 1e-6, (form, lin, ang, std)


def test_transport_term_is_the_integral_of_v_B_cross_P(measured):
    """The base point's transport term times the model's parameters is ∫ v_B × P dτ, computed here without the
    regressor: P from the engine's total momentum, v_B the base frame origin's inertial velocity from the base
    attitude (this file's quaternion formula), Simpson's rule in numpy on the simulator's steps."""
    m, meas, _, sim = measured
    t, q, v = sim["t"], sim["q"], sim["v"]
    P = np.asarray(ff.momentum(m, q, v))[:, :3]
    if m.joint_types[0] == "planar":
        c, s_ = np.cos(q[:, 2]), np.sin(q[:, 2])
        vB = np.stack([c * v[:, 0] - s_ * v[:, 1], s_ * v[:, 0] + c * v[:, 1], 0 * c], -1)
    else:
        vB = oracle.mv(oracle.quat_to_matrix(q[:, 3:7]), v[:, 0:3])
    f = np.cross(vB, P)
    h = t[1] - t[0]
    pair = h / 3 * (f[:-2:2] + 4 * f[1:-1:2] + f[2::2])
    cum = np.concatenate([np.zeros((1, 3)), np.cumsum(pair, 0)])
    i = np.searchsorted(t, meas.t - 1e-9 * h)
    assert (i % 2 == 0).all()
    want = cum[i // 2]
    got = meas.transport @ np.asarray(m.parameters(), float).ravel()
    scale = np.abs(want).max() + 1e-300
    assert np.abs(got - want).max() < 1e-10 * scale, np.abs(got - want).max() / scale
    # the balance it closes: ∫ M_B = L_B(t) − L_B(t₀) + ∫ v_B × P, L_B = L_O − r_B × P (a conservation law)
    hq = np.asarray(ff.momentum(m, meas.q, meas.v))
    rB = np.asarray(ff.algorithms.forward_kinematics(m, meas.q))[:, 0, :3]
    LB = hq[:, 3:] - np.cross(rB, hq[:, :3])
    lhs = LB - LB[:1] + got - got[:1]
    rhs = meas.impulse_M - meas.impulse_M[:1]
    rows = [2] if m.joint_types[0] == "planar" else [0, 1, 2]
    assert np.abs(lhs - rhs)[:, rows].max() < 1e-8 * np.abs(LB[:, rows]).max()
    # bad input names the argument
    with pytest.raises(ff.InputError, match="at"):
        eq.momentum_transport(m, t[:5], q[:5], v[:5], [0, 7])
    with pytest.raises(ff.InputError, match="transport"):
        from dataclasses import replace

        eq.standard_momentum_rows(m, replace(meas, transport=meas.transport[:, :, :-1]), 0, len(m.body_names) - 1)


def test_parameter_conversions_match_the_old_numpy():
    m = ff.models.load("zhang2020_3d")
    P = np.array(m.parameters())
    for body in range(len(P)):
        if P[body, 0] <= 0:
            continue
        mo, bo, Io = oracle.body_truth(m, body)
        mn, bn, In = eq.body_truth(m, body)
        np.testing.assert_allclose([mn, *bn], [mo, *bo], rtol=1e-15, atol=0)
        np.testing.assert_allclose(In, Io, rtol=0, atol=1e-14 * np.abs(Io).max())
        np.testing.assert_allclose(
            eq.standard_vector(mo, bo, Io), oracle.standard_vector(mo, bo, Io), rtol=1e-14, atol=1e-15
        )
        np.testing.assert_allclose(eq.standard_vector(mn, bn, In), P[body], rtol=1e-12, atol=1e-14)
    hist = P[[0, -1]]
    for a, b in zip(eq.from_standard(hist), oracle.from_standard(hist)):
        np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(eq.mJ(2.0, [0.1, -0.2, 0.3]), oracle.mJ(2.0, np.array([0.1, -0.2, 0.3])), rtol=1e-15)
    bad = P[-1].copy()
    bad[4] = -1.0
    np.testing.assert_allclose(eq.project_consistent(bad), oracle.project_consistent(bad), rtol=1e-9, atol=1e-9)
    with pytest.raises(ff.InputError, match="mass is zero"):
        eq.from_standard(np.zeros((1, 10)))
    neg = P[[-1]].copy()
    neg[0, 0] *= -1  # an estimate passing through a negative mass converts as before
    for a, b in zip(eq.from_standard(neg), oracle.from_standard(neg)):
        np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-14)


def test_rows_bad_input(measured):
    m, meas, _, _ = measured
    from dataclasses import replace

    with pytest.raises(ff.InputError, match="ddq"):
        eq.paper_force_rows(m, replace(meas, ddq=meas.ddq[:, :-1]), 0, 1)
    bad = meas.v.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ff.InputError, match="v"):
        eq.standard_momentum_rows(m, replace(meas, v=bad), 0, 1)
    with pytest.raises(ff.InputError, match="base/target"):
        eq.standard_force_rows(m, meas, 0, 0)
