"""Telemetry: file round trips (Parquet, CSV), validation errors that name the column/row, the Naveen, Shah, Misra
measurement noise (Sec. VI.C) and pose reconstruction from rates (Appendix C)."""

import numpy as np
import pytest

import freefloat as ff
from freefloat import telemetry as te
from freefloat import trajectories as tr
from freefloat._core import InputError


@pytest.fixture(scope="module")
def robot():
    return ff.models.load("naveen_dual_arm")


@pytest.fixture(scope="module")
def true_telemetry(robot):
    """3 s of the dual-arm robot driven by a 3-interval cycloid on 6 arm joints + 3 wheels, dt = 1 ms."""
    m = robot
    start = np.deg2rad([40.661, -109.403, -78.782, 125.089, -110.0, 51.228])
    s, r = tr.with_wheels(start, 0.3 * np.array([0.524, 2.51, 2.51, 2.513, 2.036, 2.5]))
    c = tr.Cycloidal(s, r, tr.direction_combinations(9)[[0, 77, 200]])
    names = list(m.joint_names[1:])
    f = c.prescription(m, names)
    q0, v0, _ = f(0.0)
    traj = ff.simulate(m, q0, v0, c.duration, 1e-3, prescribed=names, prescription=f)
    return te.Telemetry.from_trajectory(traj)


def small(m, n=20):
    rng = np.random.default_rng(0)
    t = np.arange(n) * 0.01
    q = np.array([m.random_configuration(rng) for _ in range(n)])
    return te.Telemetry(
        t=t, q=q, v=rng.normal(size=(n, m.nv)), model_name=m.name, q_labels=m.q_labels(), v_labels=m.v_labels()
    )


@pytest.mark.parametrize("ext", ["parquet", "csv"])
def test_round_trip(robot, tmp_path, ext, true_telemetry):
    for tel in (small(robot), true_telemetry):
        p = tmp_path / f"tel.{ext}"
        getattr(tel, f"to_{ext}")(p)
        back = te.Telemetry.from_file(p, robot)
        np.testing.assert_array_equal(back.t, tel.t)
        np.testing.assert_array_equal(back.q, tel.q)
        np.testing.assert_array_equal(back.v, tel.v)
        assert back.q_labels == robot.q_labels() and back.model_name == robot.name
        if tel.momentum is not None:
            np.testing.assert_array_equal(back.momentum, tel.momentum)


def test_reads_trajectory_parquet(robot, tmp_path):
    traj = ff.simulate(robot, robot.neutral(), np.zeros(robot.nv), 0.05, 1e-3)
    traj.to_parquet(tmp_path / "traj.parquet")
    back = te.Telemetry.from_file(tmp_path / "traj.parquet", robot)
    np.testing.assert_array_equal(back.q, traj.q)


def write_csv(path, tel, edit):
    """Write tel to CSV after `edit(columns dict)` changes it."""
    cols = {k: v.copy() for k, v in tel.columns().items()}
    edit(cols)
    np.savetxt(
        path, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols), comments="", fmt="%.17g"
    )


def test_missing_column_is_named(robot, tmp_path):
    p = tmp_path / "m.csv"
    write_csv(p, small(robot), lambda c: (c.pop("v.J3"), c.pop("q.base.qw")))
    with pytest.raises(InputError, match=r"missing columns.*q\.base\.qw.*v\.J3"):
        te.Telemetry.from_file(p, robot)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nonfinite_value_names_column_and_row(robot, tmp_path, bad):
    p = tmp_path / "n.csv"
    write_csv(p, small(robot), lambda c: c["v.Wy"].__setitem__(7, bad))
    with pytest.raises(InputError, match=r"column 'v\.Wy' row 7 is (nan|inf)"):
        te.Telemetry.from_file(p, robot)
    # Same through Parquet.
    tel = small(robot)
    tel.q[4, 9] = bad
    tel.to_parquet(tmp_path / "n.parquet")
    with pytest.raises(InputError, match=r"column 'q\.J3' row 4"):
        te.Telemetry.from_file(tmp_path / "n.parquet", robot)


def test_non_monotonic_time_names_row(robot, tmp_path):
    p = tmp_path / "t.csv"
    write_csv(p, small(robot), lambda c: c["t"].__setitem__(5, c["t"][3]))
    with pytest.raises(InputError, match=r"not strictly increasing at row 5"):
        te.Telemetry.from_file(p, robot)


def test_gap_names_row(robot, tmp_path):
    p = tmp_path / "g.csv"
    write_csv(p, small(robot), lambda c: c["t"].__setitem__(slice(12, None), c["t"][12:] + 0.02))
    with pytest.raises(InputError, match=r"gap in time before row 12"):
        te.Telemetry.from_file(p, robot)


def test_non_numeric_csv_field_is_named(robot, tmp_path):
    p = tmp_path / "x.csv"
    tel = small(robot)
    tel.to_csv(p)
    lines = p.read_text().splitlines()
    fields = lines[3].split(",")
    fields[2] = "abc"
    lines[3] = ",".join(fields)
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"column 'q\.base\.y' row 1"):
        te.Telemetry.from_file(p, robot)


def test_noise_statistics(robot, true_telemetry):
    tel = true_telemetry
    noisy = te.add_noise(tel, robot, np.random.default_rng(1), reconstruct_poses=False)
    e = noisy.v - tel.v
    std = e.std(axis=0)
    sig = np.r_[[te.SIGMA_LIN] * 3, [te.SIGMA_ANG] * 3, [te.SIGMA_JOINT] * (robot.nv - 6)]
    np.testing.assert_allclose(std, sig, rtol=0.10)  # 3001 samples: sampling error of std ~1.3 %
    assert np.all(np.abs(e.mean(axis=0)) < 4 * sig / np.sqrt(len(e)))
    np.testing.assert_array_equal(noisy.q, tel.q)  # poses untouched without reconstruction
    assert noisy.momentum is not None and np.array_equal(noisy.momentum, tel.momentum)


def test_zero_noise_reconstruction_reproduces_poses(robot, true_telemetry):
    tel = true_telemetry
    rec = te.add_noise(tel, robot, np.random.default_rng(0), 0.0, 0.0, 0.0, reconstruct_poses=True)
    np.testing.assert_array_equal(rec.v, tel.v)
    err = np.abs(rec.q - tel.q).max(axis=0)
    # Trapezoidal rule, dt = 1 ms, 3 s: observed base ≤ 1e-7, arm joints ≤ 4e-7, wheels 4.9e-6
    # (= dt²/12 · peak wheel acceleration 2π·3π rad/s²: the O(dt²) trapezoid error mid-interval).
    assert err[:7].max() < 2e-7
    assert err[7:13].max() < 1e-6
    assert err[13:].max() < 1e-5
    # Reconstructed quaternions stay unit.
    np.testing.assert_allclose(np.linalg.norm(rec.q[:, 3:7], axis=1), 1.0, atol=1e-12)


def test_noise_leaks_into_reconstructed_poses(robot, true_telemetry):
    tel = true_telemetry
    noisy = te.add_noise(tel, robot, np.random.default_rng(2))
    drift = np.abs(noisy.q - tel.q)[-1]
    # A random walk of the integrated noise: about sigma·dt·sqrt(N) = 50e-6·1e-3·55 ≈ 3e-6 rad.
    assert 1e-8 < drift[7:].max() < 1e-4
    np.testing.assert_array_equal(noisy.q[0], tel.q[0])  # starts from the true pose


def test_integrate_poses_constant_rotation():
    m = ff.models.load("naveen_dual_arm")
    # Constant body angular velocity about z for 1 s: exact quaternion (0, 0, sin(w/2), cos(w/2)).
    t = np.linspace(0, 1, 101)
    v = np.zeros((101, m.nv))
    v[:, 5] = 0.7
    v[:, 0] = 1.0  # body-frame forward speed: the position traces a circle of radius 1/0.7
    q = te.integrate_poses(m, t, v, m.neutral())
    np.testing.assert_allclose(q[-1, 3:7], [0, 0, np.sin(0.35), np.cos(0.35)], atol=1e-14)
    R = 1 / 0.7
    np.testing.assert_allclose(q[-1, :2], [R * np.sin(0.7), R * (1 - np.cos(0.7))], atol=1e-5)


def test_constructor_checks_shapes():
    with pytest.raises(InputError, match="q must be"):
        te.Telemetry(t=np.zeros(5), q=np.zeros((4, 3)), v=np.zeros((5, 2)))
    with pytest.raises(InputError, match="labels"):
        te.Telemetry(t=np.zeros(5), q=np.zeros((5, 3)), v=np.zeros((5, 2)), q_labels=["a"])


def test_noise_accepts_seed_and_is_reproducible(robot):
    tel = small(robot)
    a = te.add_noise(tel, robot, 7, reconstruct_poses=False)
    b = te.add_noise(tel, robot, np.random.default_rng(7), reconstruct_poses=False)
    np.testing.assert_array_equal(a.v, b.v)
