"""Scenario files of kind `simulate` (`freefloat simulate SCENARIO.yaml`, `ff.run_simulation_scenario`) with the
spacecraft blocks, and the kinds that cannot apply them refusing them. Each block is checked by the change it
makes against a closed form: a limited wheel's acceleration τ(1/Js + 1/I_hub), a thruster's impulse F·t, the
gravity-gradient torque 3n²(Iz − Iy) sinθ cosθ, a gyro's bias."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest

import freefloat as ff
import freefloat.postcapture as pc
from freefloat import InputError, models
from freefloat import sensors as sn
from freefloat.io import data

MU = 3.986004418e14

HUB = """name: hub_wheel
base: free
gravity: [0, 0, 0]
bodies:
  - name: hub
    inertial: {mass: 10.0, com: [0, 0, 0], inertia: [2.0, 2.0, 2.0]}
  - name: rotor
    parent: hub
    joint: {name: rw, type: revolute, axis: [0, 0, 1]}
    origin: {xyz: [0, 0, 0], rpy: [0, 0, 0]}
    inertial: {mass: 1.0, com: [0, 0, 0], inertia: [0.06, 0.06, 0.1]}
"""

BOX = """name: box
base: free
gravity: [0, 0, 0]
bodies:
  - name: body
    inertial: {mass: 50.0, com: [0, 0, 0], inertia: [2.0, 3.0, 5.0]}
"""


def write(tmp_path, text: str, model: str = HUB, name: str = "sc.yaml"):
    (tmp_path / "robot.yaml").write_text(model)
    p = tmp_path / name
    p.write_text(text)
    return p


def test_limits_block_of_a_simulate_scenario_clips_the_wheel(tmp_path):
    """0.1 N m commanded, `limits: effort 0.05, velocity 1.0`: the wheel accelerates at the closed form
    0.05 (1/Js + 1/I_hub,z) until 1 rad/s and stays there; without the block, at twice that and past 1 rad/s."""
    text = "kind: simulate\nmodel: robot.yaml\nduration: 3.0\ndt: 0.001\ntorques: {constant: {rw: 0.1}}\n"
    block = "actuators:\n  limits:\n    - {joint: rw, effort: 0.05, velocity: 1.0}\n"
    tr = ff.run_simulation_scenario(write(tmp_path, text + block)).trajectory
    a = 0.05 * (1 / 0.1 + 1 / 2.0)
    early = tr.t < 0.9 / a
    np.testing.assert_allclose(tr.ddq[early, 6], a, rtol=1e-12)
    assert tr.v[:, 6].max() <= 1.0 + a * 1e-3 + 1e-12 and tr.v[-1, 6] >= 1.0 - 1e-12
    free = ff.run_simulation_scenario(write(tmp_path, text, name="free.yaml")).trajectory
    np.testing.assert_allclose(free.ddq[:, 6], 2 * a, rtol=1e-12)
    assert free.v[-1, 6] > 3.0


def test_thruster_block_of_a_simulate_scenario_gives_its_impulse(tmp_path):
    """A 2 N thruster through the centre of mass fired for 0.5 s changes the linear momentum by exactly 1 N s
    along its direction (no other force acts)."""
    text = (
        "kind: simulate\nmodel: robot.yaml\nduration: 1.0\ndt: 0.001\n"
        "actuators:\n  thrusters:\n    - {direction: [0, 1, 0], max_thrust: 2.0, firings: [[0.2, 0.5]]}\n"
    )
    tr = ff.run_simulation_scenario(write(tmp_path, text, BOX)).trajectory
    dP = tr.momentum[-1, :3] - tr.momentum[0, :3]
    np.testing.assert_allclose(dP, [0.0, 1.0, 0.0], rtol=0, atol=1e-12)


@pytest.mark.parametrize("theta", [0.3, -0.3])
def test_gravity_gradient_block_of_a_simulate_scenario_gives_the_closed_form_torque(tmp_path, theta):
    """A rigid body at rest (inertially) in a circular orbit, radial direction along inertial z, rolled by θ
    about x: the gravity-gradient torque about its centre of mass is 3n² (Iz − Iy) sinθ cosθ about x (n² = μ/r³),
    so its initial angular acceleration is that over Ix, with the sign of θ. Without the block: zero."""
    r = 6378137.0 + 500e3
    q = [0, 0, 0, math.sin(theta / 2), 0, 0, math.cos(theta / 2)]
    text = (
        f"kind: simulate\nmodel: robot.yaml\nduration: 1.0\ndt: 0.1\ninitial: {{q: {q}}}\n"
        f"environment:\n  orbit: {{position: [0, 0, {r}], velocity: [{math.sqrt(MU / r)}, 0, 0]}}\n"
        "  gravity_gradient: true\n"
    )
    tr = ff.run_simulation_scenario(write(tmp_path, text, BOX)).trajectory
    n2 = MU / r**3
    alpha = 3 * n2 * (5.0 - 3.0) * math.sin(theta) * math.cos(theta) / 2.0
    np.testing.assert_allclose(tr.ddq[0, 3:6], [alpha, 0.0, 0.0], rtol=1e-9, atol=1e-18)
    assert np.sign(tr.v[-1, 3]) == np.sign(theta)
    plain = text.split("environment:")[0]
    tr0 = ff.run_simulation_scenario(write(tmp_path, plain, BOX, "plain.yaml")).trajectory
    assert np.all(tr0.ddq == 0.0)


def test_sensors_block_of_a_simulate_scenario_measures_the_run(tmp_path):
    """A noiseless gyro with a constant bias reads the true base rate plus the bias, at its own rate."""
    text = (
        "kind: simulate\nmodel: robot.yaml\nduration: 1.0\ndt: 0.001\ntorques: {constant: {rw: 0.1}}\n"
        "sensors:\n  - {type: gyro, rate: 100, bias: [0.01, -0.02, 0.0]}\n"
    )
    run = ff.run_simulation_scenario(write(tmp_path, text))
    st = run.measurement.streams["gyro"]
    np.testing.assert_allclose(np.diff(st.t), 0.01, rtol=1e-12)
    idx = np.searchsorted(run.trajectory.t, st.t)
    bias = np.broadcast_to([0.01, -0.02, 0.0], st.values.shape)
    np.testing.assert_allclose(st.values - run.trajectory.v[idx, 3:6], bias, rtol=0, atol=1e-15)
    # the hub counter-rotates at the closed form −0.1/I_hub,z t
    np.testing.assert_allclose(st.values[:, 2], -0.1 / 2.0 * st.t, rtol=0, atol=1e-15)


def test_cli_runs_a_simulate_scenario_and_refuses_options_it_replaces(tmp_path):
    text = (
        "kind: simulate\nmodel: robot.yaml\nduration: 2.0\ndt: 0.001\ntorques: {constant: {rw: 0.1}}\n"
        "actuators:\n  limits:\n    - {joint: rw, effort: 0.05}\nsensors:\n  - {type: tachometer, rate: 50}\n"
    )
    p = write(tmp_path, text)
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "freefloat.cli", "simulate", str(p)]
    r = subprocess.run(cmd + ["--out", str(out)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    res = json.loads((out / "results.json").read_text())
    assert res["scenario"] == "sc" and res["t_final"] == 2.0
    tr = ff.Trajectory.from_parquet(out / "trajectory.parquet")
    assert np.abs(tr.tau[:, 6]).max() == 0.05
    assert (out / "telemetry" / "sensor_tachometer.csv").is_file()
    r = subprocess.run(cmd + ["--t-final", "5"], capture_output=True, text=True, timeout=300)
    assert r.returncode != 0 and "set 'duration' in the file" in r.stderr and "Traceback" not in r.stderr


def test_a_steps_schedule_switches_exactly_at_its_times(tmp_path):
    """`torques.steps`: 0 before 0.25 s, then 0.1 N m, then −0.05 N m from 0.5 s. The wheel's rate is the closed
    form τ (1/Js + 1/I_hub,z) integrated over the pieces, to round-off: every switch falls on a step boundary and
    acts from exactly there (the table is held per step)."""
    text = (
        "kind: simulate\nmodel: robot.yaml\nduration: 1.0\ndt: 0.001\n"
        "torques:\n  steps:\n    - {t: 0.25, rw: 0.1}\n    - {t: 0.5, rw: -0.05}\n"
    )
    tr = ff.run_simulation_scenario(write(tmp_path, text)).trajectory
    k = 1 / 0.1 + 1 / 2.0
    t = tr.t
    expected = k * (0.1 * np.clip(t - 0.25, 0, 0.25) - 0.05 * np.clip(t - 0.5, 0, None))
    np.testing.assert_allclose(tr.v[:, 6], expected, rtol=0, atol=1e-13)


def test_a_torque_table_replays_a_recorded_run(tmp_path):
    """A run's trajectory file is a torque table: `torques.table` pointing at it (CSV or Parquet; its q., v.,
    momentum... columns are ignored) reproduces the run's motion to round-off."""
    text = (
        "kind: simulate\nmodel: robot.yaml\nduration: 0.5\ndt: 0.001\n"
        "torques:\n  steps:\n    - {t: 0.0, rw: 0.2}\n    - {t: 0.1, rw: -0.1}\n    - {t: 0.3, rw: 0.05}\n"
    )
    ref = ff.run_simulation_scenario(write(tmp_path, text)).trajectory
    ref.to_parquet(tmp_path / "rec.parquet")
    ref.to_csv(tmp_path / "rec.csv")
    for f in ("rec.parquet", "rec.csv"):
        replay = f"kind: simulate\nmodel: robot.yaml\nduration: 0.5\ndt: 0.001\ntorques: {{table: {f}}}\n"
        tr = ff.run_simulation_scenario(write(tmp_path, replay, name=f"replay_{f}.yaml")).trajectory
        np.testing.assert_allclose(tr.v, ref.v, rtol=0, atol=1e-14)
        np.testing.assert_allclose(tr.q, ref.q, rtol=0, atol=1e-14)


@pytest.mark.parametrize(
    "torques, words",
    [
        ("{constant: {rw: 0.1}, table: x.csv}", "give one of constant, steps or table"),
        ("{steps: [{t: 0.5, rw: 0.1}, {t: 0.2, rw: 0.0}]}", "later than the previous entry"),
        ("{steps: [{rw: 0.1}]}", "needs its time t"),
        ("{steps: [{t: 0.0, rx: 0.1}]}", "no joint 'rx'"),
        ("{constant: {rw: 0.1}, hold: linear}", "applies to torques.table only"),
        ("{table: missing.csv}", "not found"),
    ],
)
def test_bad_torques_blocks_are_named(tmp_path, torques, words):
    text = f"kind: simulate\nmodel: robot.yaml\nduration: 1.0\ndt: 0.001\ntorques: {torques}\n"
    p = write(tmp_path, text)
    with pytest.raises(InputError) as e:
        ff.load_simulation_scenario(p)
    msg = str(e.value)
    assert msg.startswith(str(p)) and "torques" in msg and words in msg, msg


@pytest.mark.parametrize(
    "csv, words",
    [
        ("t,tau.rw\n0,0.1\n0.5,abc\n", "column 'tau.rw' row 1 (line 3): 'abc' is not a number"),
        ("t,rw\n0,0.1\n", "did you mean 'tau.rw'"),
        ("t,tau.rw\n0.1,0.1\n0.5,0\n", "must start at t = 0"),
        ("t,tau.rw\n-0.1,0.1\n0.5,0\n", "must start at t = 0"),
        ("t,tau.rw\n0,0.1\n0,0\n", "not strictly increasing at row 1, line 3"),
        ("t,q.x\n0,0.1\n", "no tau.<coordinate> column"),
        ("time,tau.rw\n0,0.1\n", "no column 't'"),
    ],
)
def test_bad_torque_tables_are_named(tmp_path, csv, words):
    (tmp_path / "tau.csv").write_text(csv)
    p = write(tmp_path, "kind: simulate\nmodel: robot.yaml\nduration: 1.0\ndt: 0.001\ntorques: {table: tau.csv}\n")
    with pytest.raises(InputError) as e:
        ff.load_simulation_scenario(p)
    msg = str(e.value)
    assert "tau.csv" in msg and words in msg, msg


@pytest.mark.parametrize(
    "block, key, words",
    [
        ("torques: {constant: {rx: 0.1}}\n", "torques.constant", "no joint 'rx'"),
        ("actuators:\n  limits:\n    - {joint: rw, velocity: 0}\n", "actuators.limits[0].velocity", "must be > 0"),
        ("actuators:\n  wheels:\n    - {joint: rw9}\n", "actuators.wheels[0].joint", "no joint 'rw9'"),
        ("environment:\n  gravity_gradient: true\n", "environment.gravity_gradient", "needs an orbit"),
        ("sensors:\n  - {type: gyro, rate: 2000}\n", "sensors[0].rate", "above the integration rate"),
        ("initial: {v: [0, 0]}\n", "initial.v", "expected 7 numbers"),
    ],
)
def test_bad_simulate_scenarios_name_file_and_key(tmp_path, block, key, words):
    text = "kind: simulate\nmodel: robot.yaml\nduration: 1.0\ndt: 0.001\n" + block
    p = write(tmp_path, text)
    with pytest.raises(InputError) as e:
        ff.load_simulation_scenario(p)
    msg = str(e.value)
    assert msg.startswith(str(p)) and key in msg and words in msg, msg


def test_postcapture_applies_the_limits_block(tmp_path):
    """The post-capture kind (its own runner) applies `actuators.limits` too: a limit of 0.5 N m on the arm's
    first joint bounds its torque, which without the block goes above it."""
    text = data.read_text("scenarios", "zhang2020_3d")
    text = re.sub(r"^duration: [\d.]+", "duration: 2.0", text, count=1, flags=re.M)
    p0 = tmp_path / "plain.yaml"
    p0.write_text(text)
    p1 = tmp_path / "limited.yaml"
    p1.write_text(text + "actuators:\n  limits:\n    - {joint: J1, effort: 0.5}\n")
    m = models.load(pc.load_scenario(p0).model)
    k = m.idx_v[m.joint_names.index("J1")]
    tau0 = pc.simulate(pc.load_scenario(p0), m)["tau"][:, k]
    tau1 = pc.simulate(pc.load_scenario(p1), m)["tau"][:, k]
    assert np.abs(tau0).max() > 0.5
    assert np.abs(tau1).max() <= 0.5


@pytest.mark.parametrize(
    "name, kind", [("valverde_ch4_example_a", "control_adaptive"), ("valverde_ch9_two_arm", "identify_cl")]
)
@pytest.mark.parametrize(
    "block",
    [
        "actuators:\n  wheels: []\n",
        "environment:\n  gravity_gradient: false\n",
        "sensors:\n  - {type: gyro}\n",
    ],
)
def test_kinds_that_cannot_apply_a_block_refuse_it(tmp_path, name, kind, block):
    from freefloat.io import scenario_files

    p = tmp_path / "x.yaml"
    p.write_text(data.read_text("scenarios", name) + block)
    with pytest.raises(InputError) as e:
        scenario_files.read(p, kind=kind)
    msg = str(e.value)
    key = block.split(":")[0]
    assert f"key '{key}': a {kind} scenario cannot apply it" in msg and "postcapture, simulate" in msg, msg
    assert "line " in msg


def test_ddp_scenarios_refuse_the_blocks(tmp_path):
    from freefloat.io import scenario_files

    p = tmp_path / "x.yaml"
    p.write_text(data.read_text("scenarios", "valverde_ch8_stabilisation") + "actuators:\n  wheels: []\n")
    with pytest.raises(InputError, match="a control_ddp scenario cannot apply it"):
        scenario_files.read(p, kind="control_ddp")


def test_the_built_in_simulate_scenario_runs_from_the_command_line(tmp_path):
    """`freefloat simulate valverde_ch5_leo`: the shoulder's drive limits hold (0.2 N m asked, 0.05 given; no push
    past 0.05 rad/s), the sensors' telemetry is written, and the orbit's torques are external (the angular
    momentum changes) while the tidal force on the system is second order (the linear momentum barely moves)."""
    out = tmp_path / "leo"
    r = subprocess.run(
        [sys.executable, "-m", "freefloat.cli", "simulate", "valverde_ch5_leo", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    tr = ff.Trajectory.from_parquet(out / "trajectory.parquet")
    m = models.load("valverde_ch5_single_arm")
    k = m.idx_v[m.joint_names.index("J0")]
    assert np.abs(tr.tau[:, k]).max() == 0.05
    assert tr.v[-1, k] == pytest.approx(0.05, abs=0.01)  # pushed up to the limit, then only passive motion
    assert (out / "telemetry" / "sensor_gyro.csv").is_file() and (out / "telemetry" / "sensor_encoder.csv").is_file()
    res = json.loads((out / "results.json").read_text())
    assert res["scenario"] == "valverde_ch5_leo" and "measurement" in res
    assert res["momentum_drift_angular_abs"] > 1e-6 and res["momentum_drift_linear_rel"] < 1e-6


# -- a sensors block that names a preset (freefloat.sensors.PRESETS) ---------------------------------------
PRESET_SCENARIO = "kind: simulate\nmodel: robot.yaml\nduration: 1.0\ndt: 0.001\ntorques: {constant: {rw: 0.1}}\n"


def test_a_scenario_sensors_block_may_name_a_preset(tmp_path):
    r = ff.run_simulation_scenario(write(tmp_path, PRESET_SCENARIO + "sensors: {preset: tactical}\n"))
    assert r.measurement.sensors.to_dict() == sn.tactical().to_dict()
    assert {k: len(s.t) for k, s in r.measurement.streams.items()} == {
        "base_velocity": 101,
        "gyro": 101,
        "tachometer": 101,
        "encoder": 101,
    }
    r = ff.run_simulation_scenario(
        write(tmp_path, PRESET_SCENARIO + "sensors:\n  preset: {name: navigation, rate: 50, force_torque: rw}\n")
    )
    assert r.measurement.sensors.to_dict() == sn.navigation(rate=50, force_torque="rw").to_dict()
    assert len(r.measurement.streams["force_torque"].t) == 51


@pytest.mark.parametrize(
    "block, words",
    [
        ("sensors: {preset: tactcal}\n", ["line 6", "unknown preset 'tactcal'", "naveen, mems, tactical, navigation"]),
        ("sensors: {preset: mems, sensors: []}\n", ["line 6", "{preset: NAME}", "preset, sensors"]),
        ("sensors: {preset: {name: mems, rte: 5}}\n", ["line 6", "preset.rte"]),
        ("sensors: {preset: {name: mems, rate: 5000}}\n", ["sensors[0].rate", "above the integration rate"]),
        ("sensors: {preset: {name: mems, force_torque: J9}}\n", ["sensors[4].joint", "no joint 'J9'"]),
    ],
)
def test_a_bad_preset_in_a_scenario_names_the_file_line_and_key(tmp_path, block, words):
    with pytest.raises(InputError) as e:
        ff.run_simulation_scenario(write(tmp_path, PRESET_SCENARIO + block))
    msg = str(e.value)
    assert "sc.yaml" in msg and all(w in msg for w in words), msg
