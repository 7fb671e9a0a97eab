"""Poses from measured rates: the trapezoid (the default) and its fourth-order Hermite correction
(`telemetry.integration: hermite`; the engine's orders are checked in `sim::base_poses` against RK4). Here: the
gain on a simulated capture from its true rates, the key's plumbing through sensor sets and scenario files, and
the refusals."""

from __future__ import annotations

import numpy as np
import pytest

import freefloat as ff
from freefloat import sensors
from freefloat.algorithms import quat_to_matrix
from freefloat.io.telemetry import integrate_poses


def test_hermite_poses_of_the_zhang_capture_from_its_true_rates():
    """zhang2020_3d at 100 Hz: the joints' worst error 15 times smaller, the attitude's 100 times (measured 1.9e-3
    -> 1.3e-4 rad and 2.6e-6 -> 2.1e-8 rad; the arm's switching control laws limit the joints' gain)."""
    import freefloat.postcapture as pc

    sc = pc.load_scenario("zhang2020_3d")
    sc.duration = 30.0
    m = ff.models.load(sc.model)
    sim = pc.simulate(sc, m)
    idx = np.arange(0, len(sim["t"]), 20)  # 100 Hz from the 2 kHz record
    t, q, v = sim["t"][idx], sim["q"][idx], sim["v"][idx]
    err = {}
    for rule in ("trapezoid", "hermite"):
        qi = integrate_poses(m, t, v, q[0], rule=rule)
        c = (np.einsum("kij,kij->k", quat_to_matrix(qi[:, 3:7]), quat_to_matrix(q[:, 3:7])) - 1) / 2
        err[rule] = (np.abs(qi[:, 7:] - q[:, 7:]).max(), np.arccos(np.clip(c, -1, 1)).max())
    print("worst joint and attitude errors [rad]:", err)
    assert err["hermite"][0] < err["trapezoid"][0] / 10
    assert err["hermite"][1] < err["trapezoid"][1] / 50


def test_the_key_reaches_the_sensor_set_and_is_checked(tmp_path):
    s = sensors.load({"sensors": [{"type": "gyro"}], "telemetry": {"integration": "hermite"}})
    assert s.integration == "hermite" and s.to_dict()["telemetry"]["integration"] == "hermite"
    assert sensors.load({"sensors": [{"type": "gyro"}]}).integration == "trapezoid"  # the default
    assert sensors.load("naveen").integration == "trapezoid"  # the paper's reconstruction
    assert sensors.load({"preset": "tactical", "telemetry": {"integration": "hermite"}}).integration == "hermite"
    with pytest.raises(ff.InputError, match="telemetry.integration: expected one of trapezoid, hermite"):
        sensors.SensorSet([], integration="simpson")
    with pytest.raises(ff.InputError, match="rule must be 'trapezoid' or 'hermite'"):
        integrate_poses(
            ff.models.load("zhang2020_3d"),
            [0.0, 0.1],
            np.zeros((2, 12)),
            np.r_[0, 0, 0, 0, 0, 0, 1.0, np.zeros(6)],
            rule="rk4",
        )
    # in a scenario file, with the file, line and key
    import freefloat.postcapture as pc
    from freefloat.io import data

    text = data.read_text("scenarios", "zhang2020_3d_thrusters")
    assert "\ntelemetry:\n" in text
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("\ntelemetry:\n", "\ntelemetry:\n  integration: simpson\n"))
    with pytest.raises(ff.InputError) as e:
        pc.load_scenario(bad)
    assert str(e.value).startswith(str(bad)) and "integration" in str(e.value) and "line" in str(e.value)
    good = tmp_path / "good.yaml"
    good.write_text(text.replace("\ntelemetry:\n", "\ntelemetry:\n  integration: hermite\n"))
    assert pc.load_scenario(good).sensors.integration == "hermite"


def test_rates_of_the_wrong_shape_are_refused():
    t = np.linspace(0, 1, 5)
    with pytest.raises(ff.InputError, match="rates"):
        ff.integrate_base_poses(t, np.zeros((5, 6)), [0, 0, 0, 0, 0, 0, 1.0], rates=np.zeros((5, 3)))
    with pytest.raises(ff.InputError, match="rates"):
        ff.integrate_base_poses(t, np.zeros((5, 3)), [0, 0, 0.0], rates=np.full((5, 3), np.nan))
