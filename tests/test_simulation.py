"""Simulation from Python: stacked calls, inputs (tables, controllers, thrusters, prescribed
joints), conservation and momentum balance, file round trip."""

import gc

import numpy as np
import pytest

import freefloat as ff


@pytest.fixture(scope="module")
def robot():
    return ff.models.load("naveen_dual_arm")


def state(m, seed=0):
    rng = np.random.default_rng(seed)
    return m.random_configuration(rng), 0.1 * rng.normal(size=m.nv)


def test_stacked_calls_equal_loops(robot):
    m = robot
    rng = np.random.default_rng(1)
    Q = np.array([m.random_configuration(rng) for _ in range(7)])
    V, T = rng.normal(size=(7, m.nv)), rng.normal(size=(7, m.nv))
    A = ff.aba(m, Q, V, T)
    assert A.shape == (7, m.nv)
    for k in range(7):
        np.testing.assert_array_equal(A[k], ff.aba(m, Q[k], V[k], T[k]))
    assert ff.crba(m, Q).shape == (7, m.nv, m.nv)
    assert ff.forward_kinematics(m, Q).shape == (7, m.nbodies, 7)
    assert ff.kinetic_energy(m, Q, V).shape == (7,)
    # A single sample broadcasts against stacked ones.
    np.testing.assert_array_equal(ff.rnea(m, Q, V, T[0])[3], ff.rnea(m, Q[3], V[3], T[0]))


def test_internal_torques_conserve_momentum_and_energy(robot):
    m = robot
    q, v = state(m)
    f = 0.2 + 0.05 * np.arange(m.nv - 6)

    def torques(t, q, v):
        out = np.zeros(m.nv)
        out[6:] = 5 * np.sin(2 * np.pi * f * t)
        return out

    tr = ff.simulate(m, q, v, 5.0, 1e-3, torques=torques, record_every=50)
    # The recorded momentum and energy (by-products of the dynamics) equal the kinematic functions'.
    np.testing.assert_allclose(tr.momentum, ff.momentum(m, tr.q, tr.v), rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(tr.kinetic_energy, ff.kinetic_energy(m, tr.q, tr.v), rtol=1e-13)
    d = tr.momentum_drift()
    assert d["linear_rel"] < 1e-10 and d["angular_rel"] < 1e-10, d
    assert tr.energy_balance()["rel"] < 1e-9
    np.testing.assert_allclose(np.linalg.norm(tr.q[:, 3:7], axis=1), 1, atol=1e-14)


def test_thruster_wrench_changes_momentum_by_its_impulse():
    # Linear momentum obeys dp/dt = R(t) F for a base-frame force F; check the integral over the run.
    m = ff.models.load("zhang2020_3d")
    q, v = m.neutral(), np.zeros(m.nv)
    v[3:6] = [0.05, -0.02, 0.03]
    F = np.array([3.0, -1.0, 2.0])
    tau = np.zeros(m.nv)
    tau[:3] = F
    tr = ff.simulate(m, q, v, 4.0, 1e-3, torques=lambda t, q, v: tau)
    x, y, z, w = tr.q[:, 3], tr.q[:, 4], tr.q[:, 5], tr.q[:, 6]
    RF = np.stack(
        [
            (1 - 2 * (y * y + z * z)) * F[0] + 2 * (x * y - w * z) * F[1] + 2 * (x * z + w * y) * F[2],
            2 * (x * y + w * z) * F[0] + (1 - 2 * (x * x + z * z)) * F[1] + 2 * (y * z - w * x) * F[2],
            2 * (x * z - w * y) * F[0] + 2 * (y * z + w * x) * F[1] + (1 - 2 * (x * x + y * y)) * F[2],
        ],
        axis=1,
    )
    impulse = np.trapezoid(RF, tr.t, axis=0) if hasattr(np, "trapezoid") else np.trapz(RF, tr.t, axis=0)
    np.testing.assert_allclose(tr.momentum[-1, :3] - tr.momentum[0, :3], impulse, rtol=1e-6)


def test_torque_table_equals_function_with_zero_order_hold(robot):
    m = robot
    q, v = state(m, 2)
    times = np.arange(0, 1.0, 0.1)
    table = np.zeros((len(times), m.nv))
    table[:, 6:] = np.sin(np.outer(times, np.arange(1, m.nv - 5)))

    def f(t, q, v):
        k = min(int(np.floor(t / 0.1 + 1e-9)), len(times) - 1)
        return table[k]

    a = ff.simulate(m, q, v, 1.0, 1e-3, torques=table, torque_times=times, hold="zoh")
    # a table is held per step by default; a function is read at every stage unless asked to hold per step too
    b = ff.simulate(m, q, v, 1.0, 1e-3, torques=f, input_timing="step")
    np.testing.assert_allclose(a.q, b.q, atol=1e-12)


def test_controller_is_sampled_and_held(robot):
    m = robot
    q, v = state(m, 3)
    calls = []

    def ctrl(t, q, v):
        calls.append(t)
        out = np.zeros(m.nv)
        out[6:] = -20 * v[6:]  # joint damping, recomputed every 0.1 s
        return out

    tr = ff.simulate(m, q, v, 1.0, 1e-3, controller=ctrl, controller_period=0.1)
    np.testing.assert_allclose(calls, np.arange(11) * 0.1, atol=1e-12)  # k·period for every k·period <= t_final
    # Held between samples: the recorded joint forces are piecewise constant.
    k = np.searchsorted(tr.t, 0.25)
    np.testing.assert_array_equal(tr.tau[k, 6:], tr.tau[k + 20, 6:])
    assert not np.array_equal(tr.tau[k, 6:], tr.tau[k + 80, 6:])


def test_prescribed_joints_follow_and_report_needed_torques(robot):
    m = robot
    arm = ["J1", "J2", "J3", "J4", "J5", "J6"]
    vi = [m.idx_v[m.joint_names.index(j)] for j in arm]
    qi = [m.idx_q[m.joint_names.index(j)] for j in arm]
    amp = np.linspace(0.3, 0.8, 6)

    def presc(t):
        q, v, a = m.neutral(), np.zeros(m.nv), np.zeros(m.nv)
        q[qi], v[vi], a[vi] = amp * np.sin(t), amp * np.cos(t), -amp * np.sin(t)
        return q, v, a

    tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 2.0, 1e-3, prescribed=arm, prescription=presc, record_every=100)
    np.testing.assert_allclose(tr.q[:, qi], np.outer(np.sin(tr.t), amp), atol=1e-14)
    # Independent check by inverse dynamics: the recorded state and accelerations need exactly the
    # recorded forces: zero on the free base and wheels, tau on the prescribed joints.
    tau = ff.rnea(m, tr.q, tr.v, tr.ddq)
    np.testing.assert_allclose(tau, tr.tau, atol=1e-9 * np.abs(tr.tau).max())
    assert np.abs(tr.tau[:, :6]).max() < 1e-9
    d = tr.momentum_drift()
    assert d["linear_abs"] < 1e-9 and d["angular_abs"] < 1e-9


def test_planar_base_reproduces_in_plane_motion():
    def yaml(base):
        return f"""name: planar_pair
base: {base}
bodies:
  - name: base
    inertial: {{mass: 50, com: [0.1, -0.1, 0], inertia: [4, 5, 8]}}
  - name: l1
    parent: base
    joint: {{name: j1, type: revolute, axis: [0, 0, 1]}}
    origin: {{xyz: [0.5, 0, 0]}}
    inertial: {{mass: 5, com: [0.5, 0.05, 0], inertia: [0.1, 0.4, 0.45]}}
  - name: l2
    parent: l1
    joint: {{name: j2, type: revolute, axis: [0, 0, 1]}}
    origin: {{xyz: [1, 0, 0]}}
    inertial: {{mass: 3, com: [0.4, 0, 0], inertia: [0.05, 0.3, 0.33]}}
"""

    mp, mf = ff.Model.from_yaml_string(yaml("planar")), ff.Model.from_yaml_string(yaml("free"))
    qp, vp = np.array([0.3, -0.2, 0.7, 0.4, -0.9]), np.array([0.1, 0.2, 0.3, -0.4, 0.5])
    qf = np.array([0.3, -0.2, 0, 0, 0, np.sin(0.35), np.cos(0.35), 0.4, -0.9])
    vf = np.array([0.1, 0.2, 0, 0, 0, 0.3, -0.4, 0.5])
    tp = ff.simulate(mp, qp, vp, 5.0, 1e-3, torques=lambda t, q, v: np.array([0, 0, 0, np.sin(t), -np.cos(t)]))
    tf = ff.simulate(mf, qf, vf, 5.0, 1e-3, torques=lambda t, q, v: np.array([0, 0, 0, 0, 0, 0, np.sin(t), -np.cos(t)]))
    yaw = 2 * np.arctan2(tf.q[:, 5], tf.q[:, 6])
    np.testing.assert_allclose(tf.q[:, :2], tp.q[:, :2], atol=1e-10)
    np.testing.assert_allclose(np.unwrap(yaw), tp.q[:, 2], atol=1e-10)
    np.testing.assert_allclose(tf.q[:, 7:], tp.q[:, 3:], atol=1e-10)
    np.testing.assert_allclose(tf.q[:, 2:5], 0, atol=1e-13)


def test_rk45_agrees_with_rk4(robot):
    m = robot
    q, v = state(m, 4)
    a = ff.simulate(m, q, v, 2.0, 1e-3)
    b = ff.simulate(m, q, v, 2.0, 0.5, method="rk45", rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(b.t, [0, 0.5, 1.0, 1.5, 2.0])
    np.testing.assert_allclose(b.q[-1], a.q[-1], atol=1e-9)
    assert b.stats["steps"] < a.stats["steps"]


def test_parquet_round_trip(robot, tmp_path):
    m = robot
    q, v = state(m, 5)
    tr = ff.simulate(m, q, v, 0.5, 1e-3, record_every=10)
    p = tmp_path / "run.parquet"
    tr.to_parquet(p)
    back = ff.Trajectory.from_parquet(p)
    for k, x in tr.to_numpy().items():
        np.testing.assert_array_equal(getattr(back, k), x, err_msg=k)
    assert back.q_labels == m.q_labels() and back.model_name == m.name
    with pytest.raises(FileNotFoundError):
        ff.Trajectory.from_parquet(tmp_path / "missing.parquet")


def test_progress_callback_can_abort(robot):
    m = robot
    seen = []

    def progress(f):
        seen.append(f)
        return f < 0.3

    # a stop asked for is an interruption (a KeyboardInterrupt with the samples so far), not a numerical failure;
    # the hook is polled every 20 ms of work, so the run is long enough for several polls
    with pytest.raises(ff.Interrupted, match="returned False") as info:
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 200.0, 1e-3, record_every=100, progress=progress)
    assert 0 < len(seen) and max(seen) >= 0.3
    assert info.value.partial.t[-1] == pytest.approx(200.0 * seen[-1], rel=1e-6)


NEW_JOINTS_YAML = """
name: cardan_and_cylinder
base: free
bodies:
  - name: base
    inertial: {mass: 50, com: [0.1, -0.05, 0.02], inertia: {xx: 6, yy: 5, zz: 4, xy: 0.2}}
  - name: slider
    parent: base
    joint: {name: cyl, type: cylindrical, axis: [0.3, 0.4, 1.2]}
    origin: {xyz: [0.5, 0.2, 0.3], rpy: [0.3, -0.2, 0.5]}
    inertial: {mass: 4, com: [0.2, 0.05, -0.1], inertia: {xx: 0.3, yy: 0.25, zz: 0.2, xz: 0.01}}
  - name: cross
    parent: slider
    joint: {name: cardan, type: universal, axis: [0.6, 0.8, 0], axis2: [-0.8, 0.6, 0]}
    origin: {xyz: [0.4, 0, 0.1]}
    inertial: {mass: 3, com: [0.3, -0.1, 0.2], inertia: {xx: 0.2, yy: 0.3, zz: 0.25, xy: -0.02}}
  - name: tip
    parent: cross
    joint: {name: wrist, type: universal, axis: [1, 0, 0], axis2: [0, 0, 1]}
    origin: {xyz: [0.5, 0.1, 0]}
    inertial: {mass: 2, com: [0.1, 0.1, 0.1], inertia: [0.05, 0.06, 0.07]}
"""


@pytest.mark.parametrize("formulation", ["aba", "dq"])
def test_cylindrical_and_universal_joints_conserve_momentum_and_energy(formulation):
    """Internal torques on cylindrical and universal joints: momentum is conserved and ΔE_kin = W (the
    universal joint's bias acceleration Ṡq̇ must be right for this to hold)."""
    m = ff.Model.from_yaml_string(NEW_JOINTS_YAML)
    assert list(m.joint_types) == ["free", "cylindrical", "universal", "universal"]
    q, v = state(m, seed=3)
    v[6:] *= 20  # fast joints: large velocity products

    def torques(t, q, v):
        out = np.zeros(m.nv)
        out[6:] = 2 * np.sin(3 * t + np.arange(m.nv - 6))
        return out

    # The joints are fast, so RK4's error is visible at dt = 1 ms (drift ~1e-9): check that it is the
    # integrator's, i.e. that it falls by 2⁴ when dt halves (a wrong bias term would leave a floor).
    runs = [
        ff.simulate(m, q, v, 3.0, dt, torques=torques, record_every=round(0.05 / dt), formulation=formulation)
        for dt in (1e-3, 5e-4)
    ]
    for tr in runs:
        np.testing.assert_allclose(tr.momentum, ff.momentum(m, tr.q, tr.v), rtol=1e-10, atol=1e-10)
    (d1, d2), (e1, e2) = [r.momentum_drift() for r in runs], [r.energy_balance()["rel"] for r in runs]
    for k in ("linear_rel", "angular_rel"):
        assert d2[k] < 2e-10 and d1[k] / d2[k] > 12, (k, d1[k], d2[k])
    assert e2 < 2e-10 and e1 / e2 > 12, (e1, e2)


def test_recorded_arrays_stay_their_own_when_later_runs_reuse_record_buffers():
    """The engine reuses the record buffers of freed trajectories (no fresh pages to fault in): a trajectory that is
    still alive keeps its values whatever later runs write, a run into reused buffers records the same numbers, and
    the arrays are writable, contiguous and independent of each other."""
    m = ff.models.load("seed001_dual_arm_consistent")
    rng = np.random.default_rng(3)
    q0, v0 = m.random_configuration(rng), 0.05 * rng.normal(size=m.nv)
    times = np.arange(0, 0.3001, 5e-4)
    vals = np.zeros((len(times), m.nv))
    vals[:, 6:12] = 3.0 * np.sin(7.0 * times[:, None] + np.arange(6))

    def run(scale=1.0):
        return ff.simulate(m, q0, v0, 0.3, 1e-3, torques=scale * vals, torque_times=times, hold="linear")

    fields = ("t", "q", "v", "ddq", "tau", "momentum", "kinetic_energy", "work")
    kept = run()
    snapshot = {k: getattr(kept, k).copy() for k in fields}
    for _ in range(3):  # freed at once: their buffers go back and are taken again
        other = run(scale=-2.0)
        assert not np.array_equal(other.q, snapshot["q"])
        del other
        gc.collect()
    again = run()
    for k in fields:
        assert np.array_equal(getattr(kept, k), snapshot[k]), k
        assert np.array_equal(getattr(again, k), snapshot[k]), k
    assert again.q.flags.writeable and again.q.flags.c_contiguous
    again.q[:] = 0.0
    assert np.array_equal(kept.q, snapshot["q"])
