"""Naveen, Shah, Misra trajectories: direction combinations (V.B), multi-interval cycloids (eqs. 28–31), wheel
seeds (VI.A.2), Fourier evaluation trajectory (eqs. 40–41), and a prescribed simulation of the
dual-arm robot with its wheels that must keep the total momentum at zero."""

import numpy as np
import pytest

import freefloat as ff
from freefloat import trajectories as tr
from freefloat._core import InputError

# Table 3 of Naveen, Shah, Misra: start angles in degrees; ranges read as radians, scaled down here
# so the short test run stays gentle.
TABLE3_START = np.deg2rad([40.661, -109.403, -78.782, 125.089, -110.0, 51.228])
TABLE3_RANGE = np.array([0.524, 2.51, 2.51, 2.513, 2.036, 2.5])


@pytest.fixture(scope="module")
def robot():
    return ff.models.load("naveen_dual_arm")


def test_direction_combinations_count_unique_and_fixed():
    D = tr.direction_combinations(9)
    assert D.shape == (256, 9)
    assert len({tuple(r) for r in D}) == 256
    assert np.all(D[:, 0] == 1)
    assert set(np.unique(D)) == {-1, 1}
    np.testing.assert_array_equal(D[0], np.ones(9))  # documented order: row 0 all +1
    np.testing.assert_array_equal(D[1], [1] * 8 + [-1])  # last joint alternates fastest
    D8 = tr.direction_combinations(9, fixed=8)
    assert np.all(D8[:, 8] == 1) and len({tuple(r) for r in D8}) == 256
    with pytest.raises(InputError):
        tr.direction_combinations(0)


def cycloid(K=3, seed=0):
    rng = np.random.default_rng(seed)
    s, r = tr.with_wheels(TABLE3_START, 0.3 * TABLE3_RANGE)
    D = tr.direction_combinations(9)[rng.choice(256, K, replace=False)]
    return tr.Cycloidal(s, r, D, interval=1.0)


def test_cycloid_boundaries_follow_seeds():
    c = cycloid()
    q, qd, qdd = c.evaluate(np.arange(c.n_intervals + 1) * c.interval)
    # eqs. 30–31: θ_i^1 = θ_s, θ_f^k = θ_i^k + d_k θ_d.
    expected = c.start + np.vstack([np.zeros(9), np.cumsum(c.directions * c.range_, axis=0)])
    np.testing.assert_allclose(q, expected, atol=1e-14)
    # Rest-to-rest: zero rate and acceleration at every interval boundary.
    assert np.abs(qd).max() < 1e-13 and np.abs(qdd).max() < 1e-12


def test_cycloid_sign_per_interval_and_peaks():
    c = cycloid()
    t = np.linspace(0, c.duration, 3001)
    _, qd, qdd = c.evaluate(t)
    k = np.minimum((t // c.interval).astype(int), c.n_intervals - 1)
    assert np.all(qd * c.directions[k] >= -1e-15)  # one direction per interval (monotonic q)
    np.testing.assert_allclose(np.abs(qd).max(0), c.peak_rate(), rtol=1e-6)
    np.testing.assert_allclose(np.abs(qdd).max(0), c.peak_acceleration(), rtol=1e-4)


def test_cycloid_continuity_and_derivatives():
    c = cycloid()
    # Continuity across each boundary: values just before and just after agree.
    for k in range(1, c.n_intervals):
        eps = 1e-9
        a, b = c.evaluate([k - eps]), c.evaluate([k + eps])
        for x, y in zip(a, b):
            np.testing.assert_allclose(x, y, atol=1e-6)
    # Central differences: q̇ = dq/dt and q̈ = dq̇/dt everywhere, boundaries included.
    h = 1e-5
    t = np.linspace(0.0, c.duration, 601)[1:-1]
    _, qd, qdd = c.evaluate(t)
    qp, qdp, _ = c.evaluate(t + h)
    qm, qdm, _ = c.evaluate(t - h)
    np.testing.assert_allclose((qp - qm) / (2 * h), qd, atol=1e-7)
    inner = np.abs(t - np.round(t)) > 2 * h
    np.testing.assert_allclose(((qdp - qdm) / (2 * h))[inner], qdd[inner], atol=1e-6)
    # At a boundary q̈ is continuous (zero) but has a kink (the jerk jumps when a direction flips),
    # so the central difference there is only O(h): |error| <= (2π²θ_d/T³)·h.
    hb = 1e-6
    tb = np.arange(1, c.n_intervals, dtype=float)
    fd = (c.evaluate(tb + hb)[1] - c.evaluate(tb - hb)[1]) / (2 * hb)
    assert np.all(np.abs(fd) <= 2 * np.pi**2 * c.range_ * hb * 1.01 + 1e-9)


def test_cycloid_rests_outside_its_duration():
    c = cycloid()
    q, qd, qdd = c.evaluate([-1.0, c.duration + 1.0])
    np.testing.assert_allclose(q, c.boundaries[[0, -1]])
    assert not qd.any() and not qdd.any()


def test_wheel_peak_momentum_matches_seed():
    # Naveen, Shah, Misra VI.A.2: start 0, range 3π per 1-s interval -> 18.8496 kg·m²/s for a 1 kg·m² wheel.
    c = tr.Cycloidal([tr.WHEEL_START], [tr.WHEEL_RANGE], [[1]], interval=1.0)
    _, qd, _ = c.evaluate(np.linspace(0, 1, 10001))
    assert abs(1.0 * qd.max() - 18.8496) < 1e-4
    assert c.peak_rate()[0] == pytest.approx(6 * np.pi)


def test_cycloid_rejects_bad_seeds():
    with pytest.raises(InputError, match="range_ must be > 0"):
        tr.Cycloidal([0, 0], [1, 0], [[1, 1]])
    with pytest.raises(InputError, match="columns"):
        tr.Cycloidal([0, 0], [1, 1], [[1, 1, 1]])
    with pytest.raises(InputError, match=r"\+1 or -1"):
        tr.Cycloidal([0, 0], [1, 1], [[1, 0]])


def test_fourier_derivatives_and_period():
    rng = np.random.default_rng(3)
    f = tr.Fourier(rng.normal(size=(6, 2)), rng.normal(size=(6, 2)), rng.normal(size=6))
    assert f.duration == pytest.approx(40.0)  # ω_f = π/20
    t = np.linspace(0, 40, 401)
    q, qd, qdd = f.evaluate(t)
    h = 1e-4
    np.testing.assert_allclose((f.evaluate(t + h)[0] - f.evaluate(t - h)[0]) / (2 * h), qd, atol=1e-8)
    np.testing.assert_allclose((f.evaluate(t + h)[1] - f.evaluate(t - h)[1]) / (2 * h), qdd, atol=1e-8)
    np.testing.assert_allclose(f.evaluate([0.0])[0], f.evaluate([40.0])[0], atol=1e-12)
    # Eq. 40 at t = 0: q = q0 + Σ b.
    np.testing.assert_allclose(q[0], f.q0 + f.b.sum(1), atol=1e-14)


def test_prescribed_cycloid_keeps_zero_momentum(robot):
    m = robot
    c = cycloid()
    names = list(m.joint_names[1:])  # J1..J6, Wx, Wy, Wz
    assert names[-3:] == ["Wx", "Wy", "Wz"]
    f = c.prescription(m, names)
    q0, v0, _ = f(0.0)
    assert q0.shape == (m.nq,) and v0.shape == (m.nv,) and not v0.any()
    traj = ff.simulate(m, q0, v0, c.duration, 1e-3, prescribed=names, prescription=f)
    # Starts at rest, so the total momentum (robot + wheels) stays zero.
    assert np.abs(traj.momentum).max() < 1e-9
    qj, qdj, _ = c.evaluate(traj.t)
    np.testing.assert_allclose(traj.q[:, 7:], qj, atol=1e-12)
    np.testing.assert_allclose(traj.v[:, 6:], qdj, atol=1e-12)
    # The base really moved in reaction, so the check above is not vacuous.
    assert np.abs(traj.v[:, :6]).max() > 1e-3


def test_prescription_rejects_unknown_joint(robot):
    c = tr.Cycloidal([0.0], [1.0], [[1]])
    with pytest.raises(InputError, match="not a joint"):
        c.prescription(robot, ["nope"])
    with pytest.raises(InputError, match="joint names"):
        c.prescription(robot, ["J1", "J2"])


def test_with_wheels_appends_seed_values():
    s, r = tr.with_wheels([0.1, 0.2], [0.3, 0.4])
    np.testing.assert_array_equal(s, [0.1, 0.2, 0, 0, 0])
    np.testing.assert_array_equal(r, [0.3, 0.4, 3 * np.pi, 3 * np.pi, 3 * np.pi])


def test_multisine_derivatives_are_consistent():
    traj = tr.MultiSine.random(4, 3)
    t = np.linspace(0.0, 5.0, 2001)
    q, qd, qdd = traj.evaluate(t)
    h = t[1] - t[0]
    np.testing.assert_allclose((q[2:] - q[:-2]) / (2 * h), qd[1:-1], atol=1e-5)
    np.testing.assert_allclose((qd[2:] - qd[:-2]) / (2 * h), qdd[1:-1], atol=1e-4)
    with pytest.raises(ff.InputError, match="positive"):
        tr.MultiSine([[1.0]], [[0.0]], [[0.0]])
