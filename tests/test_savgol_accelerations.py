"""`measurement.accelerations: savgol` of post-capture scenarios: the Savitzky-Golay derivative of the measured
rates, checked against closed forms (exact on polynomials, the white-noise gain of a least-squares slope), its
settings validated with the file, line and key, and its effect on the telemetry's accelerations."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

import freefloat.postcapture as pc
from freefloat import InputError, models
from freefloat.io import data
from freefloat.postcapture.simulation import _derivative

PLAIN = data.read_text("scenarios", "zhang2020_3d")
THRUST = data.read_text("scenarios", "zhang2020_3d_thrusters")


def test_savgol_derivative_is_exact_on_polynomials_and_has_the_least_squares_noise_gain():
    h = 0.01
    t = np.arange(400) * h
    x = np.stack([1 + 2 * t - 3 * t**2, 0.5 * t**3 - t], -1)
    d = _derivative({"accelerations": "savgol", "savgol_window": 21, "savgol_polyorder": 3}, len(t), "test")
    np.testing.assert_allclose(d(x, h), np.stack([2 - 6 * t, 1.5 * t**2 - 1], -1), rtol=0, atol=1e-9)
    # white noise σ = 1: a centred degree-2 fit over w = 2m + 1 samples has the slope of the degree-1 fit,
    # Σ k x_k / (h Σ k²), whose standard deviation is 1 / (h sqrt(Σ k²)), Σ k² = m (m + 1) (2m + 1) / 3
    rng = np.random.default_rng(3)
    noise = rng.normal(size=(200_000, 1))
    for w in (11, 21, 51):
        mm = (w - 1) // 2
        d = _derivative({"accelerations": "savgol", "savgol_window": w, "savgol_polyorder": 2}, len(noise), "test")
        got = d(noise, h)[w:-w].std()
        want = 1 / (h * np.sqrt(mm * (mm + 1) * (2 * mm + 1) / 3))
        assert got == pytest.approx(want, rel=0.02), (w, got, want)
    cd = _derivative({"accelerations": "central_difference"}, len(noise), "test")(noise, h)[1:-1].std()
    assert cd == pytest.approx(1 / (np.sqrt(2) * h), rel=0.02)


@pytest.mark.parametrize(
    "block, key, words",
    [
        ("measurement:\n  accelerations: savgol\n  savgol_window: 20\n", "measurement.savgol_window", "odd"),
        ("measurement:\n  accelerations: savgol\n  savgol_window: 1\n", "measurement.savgol_window", ">= 3"),
        (
            "measurement:\n  accelerations: savgol\n  savgol_window: 5\n  savgol_polyorder: 5\n",
            "measurement.savgol_polyorder",
            "below savgol_window = 5",
        ),
        ("measurement:\n  accelerations: savgol\n  savgol_polyorder: 0\n", "measurement.savgol_polyorder", ">= 1"),
        (
            "measurement:\n  accelerations: central_difference\n  savgol_window: 21\n",
            "measurement.savgol_window",
            "savgol only",
        ),
        ("measurement:\n  accelerations: savgole\n", "measurement.accelerations", "savgol"),
    ],
)
def test_bad_savgol_settings_name_the_key(tmp_path, block, key, words):
    p = tmp_path / "bad.yaml"
    p.write_text(PLAIN + block)
    with pytest.raises(InputError) as e:
        pc.load_scenario(p)
    msg = str(e.value)
    assert msg.startswith(str(p)) and key in msg and words in msg and "line " in msg, msg


def short(tmp_path, text: str, duration: float):
    t = re.sub(r"^duration: [\d.]+", f"duration: {duration}", text, count=1, flags=re.M)
    p = tmp_path / "short.yaml"
    p.write_text(t)
    return pc.load_scenario(p)


def test_window_longer_than_the_telemetry_is_refused(tmp_path):
    sc = short(tmp_path, THRUST, 1.0)  # 100 telemetry samples
    sc = dataclasses.replace(sc, measurement={"accelerations": "savgol", "savgol_window": 201})
    m = models.load(sc.model)
    with pytest.raises(InputError, match=r"measurement.savgol_window: 201 samples is longer than"):
        pc.measure(m, pc.simulate(sc, m), sc)


def test_savgol_takes_the_gyro_noise_out_of_the_base_angular_accelerations(tmp_path):
    """A MEMS-class gyro (1e-3 rad/s/√Hz at 100 Hz: σ = 0.01 rad/s per sample): central differences put
    σ/(√2 h) = 0.7 rad/s² of noise on the base's angular accelerations; a quadratic Savitzky-Golay fit over 51
    samples 1/(h sqrt(Σk²)) = 0.0095 of σ/h, so its error against the exact accelerations is far smaller (the
    base turns slowly, so the window's bias is small there)."""
    sc = short(tmp_path, THRUST, 10.0)
    sens = sc.sensors
    sens.sensors = [dict(s, noise_density=1e-3) if s["type"] == "gyro" else dict(s) for s in sens.sensors]
    m = models.load(sc.model)
    sim = pc.simulate(sc, m)
    exact = pc.measure(m, sim, dataclasses.replace(sc, measurement={"accelerations": "exact"}))

    def err(meas):
        r = pc.measure(m, sim, dataclasses.replace(sc, measurement=meas))
        i = np.searchsorted(exact.t, r.t)
        return np.sqrt(np.mean((r.ddq[:, 3:6] - exact.ddq[i, 3:6]) ** 2))

    e_cd = err({"accelerations": "central_difference"})
    e_sg = err({"accelerations": "savgol", "savgol_window": 51, "savgol_polyorder": 2})
    assert e_cd == pytest.approx(0.01 / (np.sqrt(2) * 0.01), rel=0.2)
    assert e_sg < e_cd / 20, (e_sg, e_cd)
