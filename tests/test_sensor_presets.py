"""Sensor presets by hardware class (`freefloat.sensors.mems`, `tactical`, `navigation`; docs/sensors.md, "Presets
by hardware class"): each loads by name, through a `preset:` mapping (with its options and more sensors) and in a
scenario's `sensors:` block, and the engine accepts it; on a simulated run its gyro's white noise per sample is
N/√P and its derived joint-rate noise is what it declares; the classes are ordered; the gyro's numbers are the SI
conversions of the cited datasheet figures, recomputed here from the datasheet's units; a bad preset name is an
InputError that lists the presets."""

from __future__ import annotations

import math

import numpy as np
import pytest

import freefloat as ff
from freefloat import models
from freefloat import sensors as sn
from freefloat._core import InputError

CLASSES = ("mems", "tactical", "navigation")

# The datasheet figures in the datasheet's units, converted here independently of the module:
#   1 °/√h = (π/180)/60 rad/s/√Hz, 1 °/s/√Hz = π/180 rad/s/√Hz, 1 °/h = (π/180)/3600 rad/s.
GYRO = {
    # Analog Devices ADIS16470: 0.008 °/s/√Hz rms rate noise density, 8 °/h in-run bias stability
    "mems": {"N": 0.008 * math.pi / 180.0, "B": 8.0 * math.pi / 180.0 / 3600.0, "Tc": 100.0},
    # KVH DSP-1750 / DSP-1760: angle random walk 0.012 °/√h, bias instability 0.05 °/h
    "tactical": {"N": 0.012 * math.pi / 180.0 / 60.0, "B": 0.05 * math.pi / 180.0 / 3600.0, "Tc": 1000.0},
    # Honeywell HG9900: angle random walk 0.002 °/√h, gyro bias 0.0035 °/h
    "navigation": {"N": 0.002 * math.pi / 180.0 / 60.0, "B": 0.0035 * math.pi / 180.0 / 3600.0, "Tc": 3600.0},
}
ENCODER = {
    # ams AS5048A: 14 bits, output noise 0.06 ° rms (maximum)
    "mems": {"counts": 2**14, "noise": 0.06 * math.pi / 180.0},
    # ROBOTIS DYNAMIXEL-P PH54-200-S500-R: 1,003,846 pulse/rev, no noise figure
    "tactical": {"counts": 1_003_846, "noise": 0.0},
    # Renishaw RESOLUTE: 32 bits/rev, jitter < 10 nm RMS on a Ø52 mm ring
    "navigation": {"counts": 2**32, "noise": 10e-9 / 26e-3},
}


def by_type(sset: sn.SensorSet) -> dict:
    return {s["type"] if isinstance(s, dict) else s.TYPE: s for s in sset.sensors}


@pytest.fixture(scope="module")
def run():
    """60 s of the dual-arm robot with every joint driven (sinusoidal torques), recorded every 5 ms."""
    m = models.load("naveen_dual_arm")
    k = np.arange(1, m.nv - 5)

    def tau(t, q, v):
        u = np.zeros(m.nv)
        u[6:] = 0.5 * np.sin(0.7 * k * t)
        return u

    traj = ff.simulate(m, m.neutral(), np.zeros(m.nv), 60.0, 0.005, torques=tau)
    assert np.abs(traj.v[:, 3:6]).max() > 1e-3  # the base does turn
    return m, traj


# ---------------------------------------------------------------------------------------------------------------
def test_unit_conversions_are_the_documented_ones():
    assert math.pi / 180.0 / 60.0 == pytest.approx(2.909e-4, rel=1e-3)  # 1 °/√h in rad/s/√Hz
    assert math.pi / 180.0 / 3600.0 == pytest.approx(4.848e-6, rel=1e-3)  # 1 °/h in rad/s
    assert sn.DEG_PER_SQRT_HOUR == pytest.approx(math.pi / 180.0 / 60.0, rel=1e-15)
    assert sn.DEG_PER_HOUR == pytest.approx(math.pi / 180.0 / 3600.0, rel=1e-15)


@pytest.mark.parametrize("cls", CLASSES)
def test_gyro_numbers_are_the_si_conversions_of_the_datasheet(cls):
    g = by_type(sn.PRESETS[cls]())["gyro"]
    want = GYRO[cls]
    assert g.noise_density == pytest.approx(want["N"], rel=1e-12)
    assert g.bias_instability == pytest.approx(want["B"], rel=1e-12)
    assert g.bias_correlation_time == want["Tc"]
    assert g.rate_random_walk == 0.0 and g.bias is None and g.noise_per_sample is None
    sheet = sn.HARDWARE[cls]["gyro"]
    assert sheet.noise_density == pytest.approx(want["N"], rel=1e-12)
    assert sheet.bias_instability == pytest.approx(want["B"], rel=1e-12)


@pytest.mark.parametrize("cls", CLASSES)
@pytest.mark.parametrize("rate", [100.0, 50.0])
def test_encoders_tachometers_and_base_velocity_follow_the_stated_rules(cls, rate):
    s = by_type(sn.PRESETS[cls](rate=rate))
    e, tach, bv = s["encoder"], s["tachometer"], s["base_velocity"]
    want = ENCODER[cls]
    assert e.counts_per_rev == want["counts"] and e.noise == pytest.approx(want["noise"], rel=1e-12)
    # joint rate = difference of two encoder readings over P: variance (2σ² + Δ²/12·2)/P²
    delta = 2 * math.pi / want["counts"]
    assert tach.noise == pytest.approx(math.sqrt(2 * want["noise"] ** 2 + delta**2 / 6) * rate, rel=1e-12)
    assert tach.resolution == 0.0 and tach.bias == 0.0
    # base velocity: the convention N·(1 m)/√P
    assert bv.noise == pytest.approx(GYRO[cls]["N"] * math.sqrt(rate), rel=1e-12)
    assert all(x.rate == rate for x in s.values())
    assert by_type(sn.PRESETS[cls](rate=rate, base_velocity_noise=2e-4))["base_velocity"].noise == 2e-4


def test_presets_are_ordered_navigation_tactical_mems():
    sets = {c: by_type(sn.PRESETS[c]()) for c in CLASSES}
    for key in ("noise_density", "bias_instability"):
        nav, tac, mem = (getattr(sets[c]["gyro"], key) for c in ("navigation", "tactical", "mems"))
        assert nav < tac < mem, key
    for typ in ("tachometer", "base_velocity"):
        nav, tac, mem = (sets[c][typ].noise for c in ("navigation", "tactical", "mems"))
        assert nav < tac < mem, typ
    cpr = [sets[c]["encoder"].counts_per_rev for c in ("navigation", "tactical", "mems")]
    assert cpr[0] > cpr[1] > cpr[2]


# ---------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("cls", CLASSES)
def test_every_preset_loads_by_name_and_by_mapping_and_the_engine_accepts_it(cls, run):
    m, _ = run
    by_name = sn.load(cls)
    assert by_name.to_dict() == sn.PRESETS[cls]().to_dict()
    assert by_name.poses == "integrate" and by_name.telemetry_rate is None
    assert by_name.names() == ["base_velocity", "gyro", "tachometer", "encoder"]
    more = sn.load(
        {
            "preset": {"name": cls, "rate": 50, "force_torque": m.joint_names[3]},
            "sensors": [{"type": "star_tracker", "rate": 10, "sigma": [2e-5, 2e-5, 1.5e-4]}],
            "telemetry": {"rate": 50},
        }
    )
    assert more.names() == ["base_velocity", "gyro", "tachometer", "encoder", "force_torque", "star_tracker"]
    assert more.telemetry_rate == 50 and all(s["rate"] == 50 for s in more.to_dicts()[:5])
    ft = by_type(more)["force_torque"]
    assert ft.joint == m.joint_names[3]
    assert (ft.force_noise, ft.torque_noise) == pytest.approx((0.25, 0.01), rel=1e-12)  # 0.05 % of 500 N, 20 N·m
    assert sn.load({"preset": cls}).to_dict() == by_name.to_dict()


def test_a_bad_preset_is_an_input_error_naming_the_presets():
    known = ("naveen", "mems", "tactical", "navigation")
    for spec in ("tactcal", {"preset": "tactcal"}, {"preset": {"name": "tactcal"}}):
        with pytest.raises(InputError) as e:
            sn.load(spec)
        assert "tactcal" in str(e.value) and all(k in str(e.value) for k in known), str(e.value)
    with pytest.raises(InputError, match=r"preset\.rte: not an option of preset 'mems' \(its options: rate, "):
        sn.load({"preset": {"name": "mems", "rte": 50}})
    with pytest.raises(InputError, match="needs `name:`"):
        sn.load({"preset": {"rate": 50}})
    for bad in (0, -1.0, float("nan"), "100", None):
        with pytest.raises(InputError, match="preset rate"):
            sn.tactical(rate=bad)
    with pytest.raises(InputError, match="preset force_torque"):
        sn.navigation(force_torque=3)
    # a path that does not exist is still a missing file
    with pytest.raises(FileNotFoundError, match="naveen, mems, tactical, navigation"):
        sn.load("no/such/sensors.yaml")


# ---------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("cls", CLASSES)
@pytest.mark.parametrize("rate", [100.0, 50.0])
def test_measured_gyro_white_noise_per_sample_is_N_over_sqrt_P(cls, rate, run):
    """The gyro error e = measured − true base rate at the sample instants is white noise of σ = N/√P plus the
    Gauss-Markov bias, whose change between samples (σ_b·√(2P/T_c) at most) is below 0.3 % of σ for every class:
    σ is estimated from the successive differences, std(Δe)/√2, over the three axes (about 9000 to 18000
    differences, a 1σ sampling error under 1 %). A gyro given N·√P, N·P or another class's N fails by far;
    a 5 % error in N fails too."""
    m, traj = run
    meas = sn.measure(m, traj, {"preset": {"name": cls, "rate": rate}}, seed=7)
    st = meas.streams["gyro"]
    dt = traj.t[1] - traj.t[0]
    idx = np.rint((st.t - traj.t[0]) / dt).astype(int)
    e = st.values - traj.v[idx, 3:6]
    sigma = np.std(np.diff(e, axis=0)) / math.sqrt(2.0)
    want = GYRO[cls]["N"] * math.sqrt(rate)
    assert sigma == pytest.approx(want, rel=0.03), (cls, rate, sigma, want)
    # the declared white noise (identification's errors-in-variables input) is the same number
    tel = meas.telemetry
    assert tel.rate_noise[3:6] == pytest.approx([want] * 3, rel=1e-12)
    # the joint rates: white noise of the derived σ_ω, as declared
    tach = meas.streams["tachometer"]
    et = tach.values - traj.v[idx, 6:]
    assert np.std(et) == pytest.approx(tel.rate_noise[6], rel=0.03)
    assert abs(np.corrcoef(et[1:].ravel(), et[:-1].ravel())[0, 1]) < 0.03
    # the poses are rebuilt from the rates, the encoders' stream is there beside them
    assert meas.streams["encoder"].values.shape == (len(st.t), m.nv - 6)


def test_presets_with_a_force_torque_sensor_measure_the_joint_wrench(run):
    """The preset's F/T sensor minus a noiseless one at the same joint: white noise of 0.25 N and 0.01 N·m."""
    m, traj = run
    joint = m.joint_names[2]
    meas = sn.measure(m, traj, sn.tactical(force_torque=joint), seed=1)
    ft = meas.streams["force_torque"]
    assert ft.columns[0] == "ft.force_torque.fx" and ft.values.shape[1] == 6
    clean = sn.measure(m, traj, [sn.ForceTorque(rate=100, joint=joint)], seed=1).streams["force_torque"]
    d = ft.values - clean.values
    assert np.std(d[:, :3]) == pytest.approx(0.25, rel=0.03) and np.std(d[:, 3:]) == pytest.approx(0.01, rel=0.03)


# ---------------------------------------------------------------------------------------------------------------
def test_cli_measure_takes_a_preset_and_its_help_lists_them(tmp_path):
    from click.testing import CliRunner

    from freefloat.cli import main

    r = CliRunner()
    res = r.invoke(main, ["measure", "--help"])
    assert res.exit_code == 0
    help_text = " ".join(res.output.split())
    for name in ("naveen", "mems", "tactical", "navigation", "docs/sensors.md"):
        assert name in help_text, name
    run_dir, tel_dir = tmp_path / "run", tmp_path / "tel"
    res = r.invoke(main, ["simulate", "naveen_dual_arm", "--t-final", "1", "--dt", "1e-3", "--out", str(run_dir)])
    assert res.exit_code == 0, res.output
    res = r.invoke(main, ["measure", str(run_dir), "--sensors", "tactical", "--out", str(tel_dir)])
    assert res.exit_code == 0, res.output
    assert "gyro" in res.output and (tel_dir / "sensor_encoder.csv").exists()
    res = r.invoke(main, ["measure", str(run_dir), "--sensors", "tactcal", "--out", str(tel_dir)])
    assert res.exit_code != 0 and "known: naveen, mems, tactical, navigation" in res.output
