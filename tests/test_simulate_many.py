"""`simulate_many`: each member is exactly the `simulate` run of its own arguments (compared with separate calls,
bit for bit), batch sizes are checked, and a failing member is reported by index while the others are kept."""

from __future__ import annotations

import numpy as np
import pytest

import freefloat as ff
from freefloat import InputError

ROBOT = "naveen_dual_arm_consistent"


@pytest.fixture(scope="module")
def robot():
    return ff.models.load(ROBOT)


def _states(m, B, seed=0):
    rng = np.random.default_rng(seed)
    Q = np.array([m.random_configuration(rng) for _ in range(B)])
    V = 0.05 * rng.normal(size=(B, m.nv))
    return Q, V


def _table(m, T, dt):
    times = np.arange(round(T / dt) + 1) * dt
    vals = np.zeros((len(times), m.nv))
    vals[:, 6:12] = 5.0 * np.sin(2 * np.pi * 0.5 * times[:, None] + np.arange(6))
    return times, vals


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_members_equal_separate_simulate_calls(robot, threads):
    m = robot
    Q, V = _states(m, 5)
    times, vals = _table(m, 0.2, 1e-3)
    runs = ff.simulate_many(m, Q, V, 0.2, 1e-3, torques=vals, torque_times=times, threads=threads)
    assert len(runs) == 5 and runs.failures == {}
    for k in range(5):
        ref = ff.simulate(m, Q[k], V[k], t_final=0.2, dt=1e-3, torques=vals, torque_times=times)
        for name in ("q", "v", "ddq", "tau", "momentum"):
            np.testing.assert_array_equal(getattr(runs[k], name), getattr(ref, name), err_msg=f"member {k}, {name}")


def test_parameter_sets_and_per_member_torques(robot):
    m = robot
    q0, v0 = m.neutral(), np.zeros(m.nv)
    P = np.stack([m.parameters(), m.parameters()])
    P[1, 1:, :] *= 1.5  # heavier arm links: a different robot, still physical
    times, vals = _table(m, 0.1, 1e-3)
    tq = np.stack([vals, 2 * vals])
    runs = ff.simulate_many(m, q0, v0, 0.1, 1e-3, params=P, torques=tq, torque_times=times)
    for k in range(2):
        mk = m.with_parameters(P[k]) if hasattr(m, "with_parameters") else None
        if mk is None:
            pytest.skip("Model.with_parameters is not exposed")
        ref = ff.simulate(mk, q0, v0, t_final=0.1, dt=1e-3, torques=tq[k], torque_times=times)
        np.testing.assert_array_equal(runs[k].q, ref.q)
    assert not np.allclose(runs[0].q, runs[1].q)


def test_bad_batches_are_clear_errors(robot):
    m = robot
    Q, V = _states(m, 3)
    with pytest.raises(InputError, match="`v0`.*2 members but `q0` has 3"):
        ff.simulate_many(m, Q, V[:2], 0.01, 1e-3)
    with pytest.raises(InputError, match="empty"):
        ff.simulate_many(m, Q[:0], V[:0], 0.01, 1e-3)
    with pytest.raises(InputError, match="q0"):
        ff.simulate_many(m, Q[:, :5], V, 0.01, 1e-3)


def test_a_failing_member_is_reported_and_the_others_kept(robot):
    m = robot
    Q, V = _states(m, 3)
    P = np.stack([m.parameters()] * 3)
    P[1, 2, 0] = -1.0  # negative mass: member 1 cannot run
    runs = ff.simulate_many(m, Q, V, 0.01, 1e-3, params=P)
    assert runs[1] is None and set(runs.failures) == {1}
    assert "member 1" in str(runs.failures[1])
    assert runs[0] is not None and runs[2] is not None and len(runs[0]) == 11
