"""The `actuators:`, `environment:` and `sensors:` scenario blocks (issue 17) and the built-in scenario that uses
them, `zhang2020_3d_thrusters`: bad inputs refused with file, line and key; the blocks mapped onto the Python API
objects; the run's balances (mass, momentum) against closed forms; the identification error against gyro noise.

The runs here are a shortened copy of the built-in scenario (a few seconds instead of 100 s)."""

from __future__ import annotations

import copy
import dataclasses
import re

import numpy as np
import pytest

import freefloat as ff
import freefloat.postcapture as pc
from freefloat import InputError, models
from freefloat import sensors as sn
from freefloat.actuators import Actuators
from freefloat.io import data

BUILTIN = "zhang2020_3d_thrusters"
TEXT = data.read_text("scenarios", BUILTIN)
# the built-in scenario without its blocks (the base of the bad-input cases)
PLAIN = data.read_text("scenarios", "zhang2020_3d")
G0 = 9.80665


def short(tmp_path, duration: float, text: str = TEXT, name: str = "short.yaml") -> pc.Scenario:
    t = re.sub(r"^duration: [\d.]+", f"duration: {duration}", text, count=1, flags=re.M)
    p = tmp_path / name
    p.write_text(t)
    return pc.load_scenario(p)


def load_with(tmp_path, block: str, base: str = PLAIN):
    p = tmp_path / "bad.yaml"
    p.write_text(base + block)
    return pc.load_scenario(p), p


def line_of(text: str, needle: str) -> int:
    return next(i + 1 for i, s in enumerate(text.splitlines()) if needle in s)


# -- bad input: the list, each one line naming the file, line and key --------------------------------
BAD = [
    (  # a limit that is negative
        "actuators:\n  wheels:\n    - {joint: J1, max_torque: -0.1}\n",
        "actuators.wheels[0].max_torque",
        "must be > 0",
    ),
    (  # a joint limit that is negative
        "actuators:\n  limits:\n    - {joint: J1, effort: -1.0}\n",
        "actuators.limits[0].effort",
        "must be > 0",
    ),
    (  # a joint limited twice
        "actuators:\n  limits:\n    - {joint: J1, effort: 1.0}\n    - {velocity: 1.0, joint: J1}\n",
        "actuators.limits[1].joint",
        "limited twice",
    ),
    (  # a joint the robot does not have (the engine's check, on the robot)
        "actuators:\n  limits:\n    - {joint: J9, effort: 1.0}\n",
        "actuators.limits[0].joint",
        "no joint 'J9'",
    ),
    (  # limits inverted: static friction below Coulomb friction
        "actuators:\n  wheels:\n    - {joint: J1, coulomb: 0.01, static_friction: 0.005, stribeck_speed: 0.1}\n",
        "actuators.wheels[0].static_friction",
        "inverted",
    ),
    (  # firings inverted in time
        "actuators:\n  thrusters:\n    - {direction: [1, 0, 0], max_thrust: 1, firings: [[5, 1], [2, 1]]}\n",
        "actuators.thrusters[0].firings",
        "time order",
    ),
    (
        "actuators:\n  thrusters:\n    - {direction: [0, 0, 0], max_thrust: 1}\n",
        "actuators.thrusters[0].direction",
        "zero length",
    ),
    (
        "actuators:\n  tanks:\n    - {name: t, mass: 5}\n  thrusters:\n"
        "    - {direction: [0, 0, 1], max_thrust: 1, isp: 0, tank: t}\n",
        "actuators.thrusters[0].isp",
        "must be > 0",
    ),
    (  # the engine's check against the robot: the base is 500 kg
        "actuators:\n  tanks:\n    - {name: t, mass: 600}\n",
        "actuators.tanks[0].mass",
        "not lighter than its body",
    ),
    (
        "environment:\n  orbit: {semi_major_axis: 6.0e6}\n",
        "environment.orbit.semi_major_axis",
        "not above the central body's radius",
    ),
    (
        "environment:\n  orbit: {semi_major_axis: 7.0e6, eccentricity: 0.2}\n",
        "environment.orbit.semi_major_axis",
        "periapsis radius",
    ),
    ("environment:\n  orbit: {altitude: -1000.0}\n", "environment.orbit.altitude", "must be > 0"),
    (
        "environment:\n  orbit: {position: [6.0e6, 0, 0], velocity: [0, 7500, 0]}\n",
        "environment.orbit.position",
        "not above the central body's radius",
    ),
    (  # dt = 0.5 ms: 2000 Hz integration rate
        "sensors:\n  - {type: gyro, rate: 5000, noise_density: 1.0e-5}\n",
        "sensors[0].rate",
        "above the integration rate 2000 Hz",
    ),
    ("sensors:\n  - {type: tachometer, joints: [J9]}\n", "sensors", "J9"),
]


@pytest.mark.parametrize("block,key,words", BAD, ids=[b[1] + ":" + b[2] for b in BAD])
def test_bad_blocks_name_file_line_and_key(tmp_path, block, key, words):
    with pytest.raises(InputError) as e:
        load_with(tmp_path, block)
    msg = str(e.value)
    assert "\n" not in msg
    assert msg.startswith(str(tmp_path / "bad.yaml")), msg
    assert f"'{key}" in msg or f"`{key}" in msg or key in msg, msg
    assert words in msg, msg
    if key != "sensors":
        first = block.splitlines()[-1].strip()[:12]
        assert f"line {line_of(PLAIN + block, first)}:" in msg, msg


@pytest.mark.parametrize(
    "block,typo,suggestion",
    [
        (
            "actuators:\n  thrusters:\n    - {direction: [0, 0, 1], max_thrust: 1, isp: 70, ramp_onn: 0.1}\n",
            "ramp_onn",
            "ramp_on",
        ),
        ("actuators:\n  tankz: []\n", "tankz", "tanks"),
        ("environment:\n  orbit: {altitud: 5.0e5}\n", "altitud", "altitude"),
        ("environment:\n  gravity_gradiant: true\n", "gravity_gradiant", "gravity_gradient"),
        ("sensors:\n  - {type: gyro, noise_densty: 1.0e-5}\n", "noise_densty", "noise_density"),
        ("sensors:\n  - {type: star_tracker, sigmaa: 1.0e-5}\n", "sigmaa", "sigma"),
        ("telemetry:\n  pose: integrate\n", "pose", "poses"),
    ],
)
def test_unknown_keys_suggest_the_right_one(tmp_path, block, typo, suggestion):
    with pytest.raises(
        InputError, match=rf"line \d+: unknown key '[\w.\[\]]*{typo}' \(did you mean '{suggestion}'\?\)"
    ):
        load_with(tmp_path, block)


def test_blocks_are_the_python_api_objects(tmp_path):
    sc = pc.load_scenario(BUILTIN)
    import yaml

    d = yaml.safe_load(TEXT)
    assert sc.actuators == Actuators.from_dict(d["actuators"]).to_dict()
    assert isinstance(sc.sensors, sn.SensorSet)
    assert sc.sensors.to_dict() == sn.load({"sensors": d["sensors"], "telemetry": d["telemetry"]}).to_dict()
    sc2, _ = load_with(
        tmp_path, "environment:\n  orbit: {altitude: 5.0e5, inclination_deg: 51.6}\n  gravity_gradient: true\n"
    )
    assert isinstance(sc2.environment, ff.Environment)
    assert sc2.actuators is None and sc2.sensors is None


def test_the_built_in_scenario_is_listed():
    names = [n for n, _ in pc.list_scenarios()]
    assert BUILTIN in names


# -- the run: balances against closed forms ------------------------------------------------------------------
@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    sc = short(tmp_path_factory.mktemp("s"), 6.0)
    return sc, pc.run(sc)


def test_propellant_used_is_the_closed_form_of_the_firings(short_run):
    """Each complete firing (s, d) with equal on and off ramps delivers F·d of impulse, so it burns
    F·d/(Isp g0) kg: the sum over the firings done by the end of the run, against the recorded propellant."""
    sc, res = short_run
    d = res.to_dict()
    T = d["propellant"]["t_end"]
    expected = 0.0
    for th in sc.actuators["thrusters"]:
        assert th["ramp_on"] == th["ramp_off"]
        for s, dur in th["firings"]:
            if s + dur + th["ramp_off"] <= T:
                expected += th["max_thrust"] * dur / (th["isp"] * G0)
    assert expected > 0.1
    assert d["propellant"]["used_kg"][0] == pytest.approx(expected, rel=1e-9)
    # the base's mass fell by what left through the nozzles
    mb = d["mass_balance"]
    assert abs(mb["residual_kg"]) < 1e-9 * expected
    assert mb["base_mass_change_kg"] == pytest.approx(-expected, rel=1e-9)


def test_momentum_changes_by_the_thrust_plus_what_the_propellant_carried(short_run):
    sc, res = short_run
    mb = res.to_dict()["momentum_balance"]
    dP, thrust, away = (
        np.asarray(mb[k]) for k in ("momentum_change", "integrated_thrust", "carried_away_by_propellant")
    )
    # the thrust is a real fraction of the change (the check is not vacuous) and so is the carried momentum
    assert np.linalg.norm(thrust[:3]) > 10.0 and np.linalg.norm(away[:3]) > 1.0
    # the balance closes to the integration error of a 4th-order scheme at 0.5 ms (Simpson against RK4)
    assert mb["relative_residual"] < 1e-7, mb
    # dropping the carried-away term leaves a residual of its own size: the term is needed
    assert np.linalg.norm(dP[:3] - thrust[:3]) > 0.5 * np.linalg.norm(away[:3])


def test_results_have_the_base_truth_over_time_and_the_tracking(short_run, tmp_path):
    sc, res = short_run
    d = res.to_dict()
    hist = d["base_truth_history"]
    m1 = np.asarray(hist["values"])[:, hist["names"].index("m1")]
    assert m1[0] > m1[-1]  # the base gets lighter
    assert d["tracking"]["forgetting"] == sc.forgetting
    assert d["methods"]["force"]["standard_rls"]["m1"]["truth"] == pytest.approx(m1[-1], rel=1e-3)
    res.save(tmp_path)
    assert (tmp_path / "base_parameters_tracking.png").stat().st_size > 10_000


def test_environment_block_is_honoured(tmp_path):
    """A constant inertial disturbance force F on the base changes the linear momentum by exactly F·t (the
    paper's jets off, no thrusters): the block reaches the engine."""
    text = PLAIN.replace("K_F: -1.0", "K_F: 0.0").replace("K_M: -1.0", "K_M: 0.0")
    block = "environment:\n  disturbance: {force: [0.5, -0.2, 0.1], axes: inertial, body: 0}\n"
    sc = short(tmp_path, 1.0, text + block)
    m = models.load(sc.model)
    sim = pc.simulate(sc, m)
    dP = sim["momentum"][-1, :3] - sim["momentum"][0, :3]
    np.testing.assert_allclose(dP, np.array([0.5, -0.2, 0.1]) * sim["t"][-1], rtol=0, atol=1e-9)


def test_sensors_and_noise_block_together_are_refused(tmp_path):
    sc = short(tmp_path, 1.0)
    sc.noise = dict(pc.DEFAULT_NOISE)
    with pytest.raises(InputError, match="key 'noise'"):
        pc.run(sc)


# -- identification error against gyro noise ----------------------------------------------------------------
def test_identification_error_grows_with_gyro_noise(tmp_path):
    """One simulation, measured with the scenario's sensors at three gyro noise densities (×1, ×10, ×50 of
    the built-in 1e-6 rad/s/√Hz); the force-based standard RLS (the tracker) on each. Its error grows with the
    noise: the angular accelerations are differences of the gyro's rates, so their noise is σ/(√2 h) and
    enters the regressor (errors in variables: the error grows faster than σ once above the floor of the
    differencing error)."""
    sc = short(tmp_path, 10.0)
    m = models.load(sc.model)
    sim = pc.simulate(sc, m)
    cols = ["m1", "mn", "Inxx", "Inyy", "Inzz"]
    errs = []
    for scale in (1.0, 10.0, 50.0):
        sens = copy.deepcopy(sc.sensors)
        sens.sensors = [dict(s) for s in sens.sensors]
        for s in sens.sensors:
            if s["type"] == "gyro":
                s["noise_density"] = 1e-6 * scale
        s2 = dataclasses.replace(sc, sensors=sens)
        meas = pc.measure(m, sim, s2)
        res = pc.identify(m, meas, s2, methods=("force",))
        from freefloat.postcapture.spacecraft import truth_history

        res.truth_history = truth_history(m, sim, False, pc.estimators.target_index(m))
        e = res.rel_error("force", "standard_rls")
        errs.append(float(np.sqrt(np.mean([e[res.names.index(c)] ** 2 for c in cols]))))
    print("gyro noise x1, x10, x50: RMS relative error", errs)
    assert errs[0] < errs[1] < errs[2], errs
    assert errs[2] > 5 * errs[0], errs
