"""Joint limits, input timing, reaction wheels, thrusters and tanks in the engine's simulator, each checked
against a closed form or a conservation law (never against the code's own numbers)."""

from __future__ import annotations

import numpy as np
import pytest

import freefloat as ff
from freefloat import InputError, ModelError

G0 = 9.80665


def hub_wheel_yaml(effort=None, velocity=None, hub_mass=10.0, hub_i=2.0, js=0.1, jt=0.06):
    lim = ""
    if effort is not None or velocity is not None:
        parts = [
            f"effort: {effort}" if effort is not None else "",
            f"velocity: {velocity}" if velocity is not None else "",
        ]
        lim = ", limits: {" + ", ".join(p for p in parts if p) + "}"
    return f"""name: hub_wheel
base: free
gravity: [0, 0, 0]
bodies:
  - name: hub
    inertial: {{mass: {hub_mass}, com: [0, 0, 0], inertia: [{hub_i}, {hub_i}, {hub_i}]}}
  - name: rotor
    parent: hub
    joint: {{name: rw, type: revolute, axis: [0, 0, 1]{lim}}}
    origin: {{xyz: [0, 0, 0], rpy: [0, 0, 0]}}
    inertial: {{mass: 1.0, com: [0, 0, 0], inertia: [{jt}, {jt}, {js}]}}
"""


def hub_wheel(**kw):
    return ff.Model.from_yaml_string(hub_wheel_yaml(**kw))


def const(m, k, value):
    tau = np.zeros((1, m.nv))
    tau[0, k] = value
    return dict(torques=tau, torque_times=np.array([0.0]))


# -- joint limits -------------------------------------------------------------------------------------------------
def test_wheel_limits_from_the_issue_are_enforced_and_momentum_stays_at_round_off():
    """The issue's case: limits {effort 0.05, velocity 1.0}, command 0.1 N m. The applied torque is 0.05 until
    the wheel reaches 1 rad/s, then zero (nothing else acts on the wheel): the rate stops within one step's
    acceleration of the limit and stays; momentum (internal torque) stays at round-off."""
    m = hub_wheel(effort=0.05, velocity=1.0)
    dt = 1e-3
    tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 5.0, dt, **const(m, 6, 0.1))
    assert np.abs(tr.tau[:, 6]).max() <= 0.05 + 1e-15
    w = tr.v[:, 6]
    # relative acceleration under 0.05 N m: 0.05 (1/Js + 1/I_hub,z) (hub inertia about z: 2.0 + rotor Jt-free)
    a = 0.05 * (1 / 0.1 + 1 / 2.0)
    assert w.max() <= 1.0 + a * dt + 1e-12
    assert w[-1] >= 1.0 - 1e-12
    # before the limit: the closed form Ω = a t
    early = tr.t < 0.9 / a
    np.testing.assert_allclose(w[early], a * tr.t[early], atol=1e-12)
    assert tr.momentum_drift()["angular_abs"] < 1e-13
    assert tr.momentum_drift()["angular_rel"] < 1e-10


def test_velocity_limit_lets_a_slowing_command_through():
    m = hub_wheel(velocity=1.0)
    v0 = np.zeros(m.nv)
    v0[6] = 2.0  # already past the limit: a slowing torque must act
    tr = ff.simulate(m, m.neutral(), v0, 1.0, 1e-3, **const(m, 6, -0.1))
    np.testing.assert_allclose(tr.tau[:, 6], -0.1)
    tr = ff.simulate(m, m.neutral(), v0, 1.0, 1e-3, **const(m, 6, 0.1))
    np.testing.assert_allclose(tr.tau[:, 6], 0.0)
    np.testing.assert_allclose(tr.v[:, 6], 2.0, atol=1e-14)


@pytest.mark.parametrize(
    "lim, key",
    [("effort: -0.05", "limits.effort"), ("velocity: -1", "limits.velocity"), ("lower: 1, upper: -1", "lower")],
)
def test_negative_or_inverted_limits_are_errors_naming_the_key(lim, key):
    text = hub_wheel_yaml().replace("axis: [0, 0, 1]}", "axis: [0, 0, 1], limits: {" + lim + "}}")
    with pytest.raises(ModelError, match=key):
        ff.Model.from_yaml_string(text)


# -- joint limits given by the simulation (actuators.limits), overriding the model's --------------------------------
def test_limit_from_the_actuators_clips_the_command_and_the_acceleration_is_the_closed_form():
    """A model without limits, `JointLimit(rw, effort=0.05)`, command 0.1 N m: the applied torque is 0.05 and the
    wheel's relative acceleration is the closed form τ (1/Js + 1/I_hub,z) for a free hub (τ/Js alone for a fixed
    hub, below), constant through the run."""
    m = hub_wheel()
    acts = ff.Actuators(limits=[ff.JointLimit("rw", effort=0.05)])
    tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 1.0, 1e-3, actuators=acts, **const(m, 6, 0.1))
    np.testing.assert_allclose(tr.tau[:, 6], 0.05, rtol=0, atol=1e-15)
    np.testing.assert_allclose(tr.ddq[:, 6], 0.05 * (1 / 0.1 + 1 / 2.0), rtol=1e-12)
    # without the limit the same command gives twice the acceleration
    tr0 = ff.simulate(m, m.neutral(), np.zeros(m.nv), 1.0, 1e-3, **const(m, 6, 0.1))
    np.testing.assert_allclose(tr0.ddq[:, 6], 0.1 * (1 / 0.1 + 1 / 2.0), rtol=1e-12)
    assert tr.momentum_drift()["angular_abs"] < 1e-13
    # a fixed hub: the closed form τ/Js
    fixed = ff.Model.from_yaml_string(hub_wheel_yaml().replace("base: free", "base: fixed"))
    trf = ff.simulate(fixed, fixed.neutral(), np.zeros(1), 1.0, 1e-3, actuators=acts, **const(fixed, 0, 0.1))
    np.testing.assert_allclose(trf.ddq[:, 0], 0.05 / 0.1, rtol=1e-12)
    np.testing.assert_allclose(trf.v[-1, 0], 0.5, rtol=1e-12)


def test_limit_from_the_actuators_overrides_the_model_value_per_quantity():
    """The model says effort 0.05, velocity 1.0. An override of the effort alone (0.08, above the model's: an
    override, not the smaller of the two) changes the torque and keeps the model's velocity limit; an override of
    the velocity alone (0.5) keeps the model's effort."""
    m = hub_wheel(effort=0.05, velocity=1.0)
    a = 0.08 * (1 / 0.1 + 1 / 2.0)
    dt = 1e-3
    acts = {"limits": [{"joint": "rw", "effort": 0.08}]}
    tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 3.0, dt, actuators=acts, **const(m, 6, 0.1))
    assert tr.tau[0, 6] == 0.08
    assert 1.0 <= tr.v[-1, 6] <= 1.0 + a * dt + 1e-12  # the model's velocity limit holds
    acts = ff.Actuators(limits=[ff.JointLimit("rw", velocity=0.5)])
    tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 3.0, dt, actuators=acts, **const(m, 6, 0.1))
    assert tr.tau[0, 6] == 0.05  # the model's effort
    a = 0.05 * (1 / 0.1 + 1 / 2.0)
    w = tr.v[:, 6]
    assert w.max() <= 0.5 + a * dt + 1e-12 and w[-1] >= 0.5 - 1e-12  # the new velocity limit holds
    assert tr.tau[-1, 6] == 0.0


@pytest.mark.parametrize(
    "limits, key, words",
    [
        ([{"joint": "nope", "effort": 1.0}], r"actuators.limits\[0\].joint", "no joint 'nope'"),
        ([{"joint": "rw", "effort": -0.05}], r"actuators.limits\[0\].effort", "positive"),
        ([{"joint": "rw", "effort": 0.0}], r"actuators.limits\[0\].effort", "positive"),
        ([{"joint": "rw", "velocity": float("nan")}], r"actuators.limits\[0\].velocity", "positive"),
        ([{"joint": "rw", "effort": 1.0}, {"joint": "rw", "velocity": 1.0}], r"actuators.limits\[1\].joint", "twice"),
        ([{"joint": "rw"}], r"actuators.limits\[0\]", "effort, a velocity limit or both"),
        ([{"joint": "rw", "efort": 1.0}], r"actuators.limits\[0\]", "efort"),
    ],
)
def test_bad_actuator_limits_name_the_entry(limits, key, words):
    m = hub_wheel()
    with pytest.raises(InputError, match=key) as e:
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.1, 1e-3, actuators={"limits": limits})
    assert words in str(e.value)


# -- input timing -------------------------------------------------------------------------------------------------
def point_body():
    return ff.Model.from_yaml_string(
        """name: point
base: free
gravity: [0, 0, 0]
bodies:
  - name: body
    inertial: {mass: 2.0, com: [0, 0, 0], inertia: {xx: 1, yy: 1, zz: 1, xy: 0, yz: 0, xz: 0}}
"""
    )


def test_zoh_table_switch_on_a_step_boundary_lands_exactly_there():
    """1 N along x for t < 0.5 s, then 0: the impulse is 0.5 N s. Held per step (default) it is exact; read at
    the RK4 stage times the last stage of the step ending at 0.5 s sees the new value and loses 1/6 of a step
    (the issue's report), 0.5 − dt/6."""
    m = point_body()
    tau = np.zeros((2, 6))
    tau[0, 0] = 1.0
    times = np.array([0.0, 0.5])
    dt = 0.01
    step = ff.simulate(m, m.neutral(), np.zeros(6), 1.0, dt, torques=tau, torque_times=times)
    assert abs(step.momentum[-1, 0] - 0.5) < 1e-14
    stage = ff.simulate(m, m.neutral(), np.zeros(6), 1.0, dt, torques=tau, torque_times=times, input_timing="stage")
    assert abs(stage.momentum[-1, 0] - (0.5 - dt / 6)) < 1e-14
    # rk45 lands on the table's switch times
    rk = ff.simulate(m, m.neutral(), np.zeros(6), 1.0, 0.3, torques=tau, torque_times=times, method="rk45")
    assert abs(rk.momentum[-1, 0] - 0.5) < 1e-12
    with pytest.raises(InputError, match="input_timing"):
        ff.simulate(m, m.neutral(), np.zeros(6), 1.0, dt, input_timing="sometimes")


def test_momentum_drift_is_relative_to_a_meaningful_scale_when_every_body_sits_at_the_centre_of_mass():
    """Hub and rotor both at the centre of mass (radius 0): the relative angular drift used to be 1.0."""
    m = hub_wheel()
    v0 = np.zeros(m.nv)
    v0[3:6] = [0.01, 0.02, 0.03]
    tr = ff.simulate(m, m.neutral(), v0, 2.0, 1e-3, **const(m, 6, 0.01))
    d = tr.momentum_drift()
    assert d["angular_abs"] < 1e-12
    assert d["angular_rel"] < 1e-9


# -- reaction wheels ---------------------------------------------------------------------------------------------
def test_wheel_viscous_friction_spin_down_follows_the_closed_form():
    """Hub + wheel spinning at 10 rad/s, viscous friction c only: the relative rate decays as
    exp(−c (1/Js + 1/I_h) t) (I_h: the hub's inertia about the axis, without the rotor's axial part)."""
    m = hub_wheel()
    v0 = np.zeros(m.nv)
    v0[6] = 10.0
    c = 0.01
    acts = ff.Actuators(wheels=[ff.Wheel("rw", viscous=c)])
    tr = ff.simulate(m, m.neutral(), v0, 5.0, 1e-3, actuators=acts)
    k = c * (1 / 0.1 + 1 / 2.0)
    np.testing.assert_allclose(tr.v[:, 6], 10.0 * np.exp(-k * tr.t), rtol=1e-10)
    assert tr.momentum_drift()["angular_abs"] < 1e-12
    np.testing.assert_allclose(tr.tau[:, 6], -c * tr.v[:, 6], rtol=1e-12)


def test_wheel_coulomb_friction_and_torque_saturation():
    """Command 1 N m saturated at 0.2, Coulomb friction 0.02 opposing the spin: the relative rate grows
    linearly at (0.2 − 0.02)(1/Js + 1/I_h); the applied (recorded) joint torque is 0.18."""
    m = hub_wheel()
    v0 = np.zeros(m.nv)
    v0[6] = 1.0
    acts = ff.Actuators(wheels=[ff.Wheel("rw", max_torque=0.2, coulomb=0.02)])
    tr = ff.simulate(m, m.neutral(), v0, 2.0, 1e-3, actuators=acts, **const(m, 6, 1.0))
    a = 0.18 * (1 / 0.1 + 1 / 2.0)
    np.testing.assert_allclose(tr.v[:, 6], 1.0 + a * tr.t, rtol=1e-12)
    np.testing.assert_allclose(tr.tau[:, 6], 0.18, rtol=1e-12)


def test_wheel_power_and_speed_saturation():
    m = hub_wheel()
    v0 = np.zeros(m.nv)
    v0[6] = 5.0
    acts = ff.Actuators(wheels=[ff.Wheel("rw", max_power=0.25, max_speed=6.0)])
    tr = ff.simulate(m, m.neutral(), v0, 3.0, 1e-3, actuators=acts, **const(m, 6, 0.1))
    w, u = tr.v[:, 6], tr.tau[:, 6]
    assert np.all(np.abs(u * w) <= 0.25 + 1e-12)  # power limited (0.1 × 5 = 0.5 W asked)
    assert w.max() <= 6.0 + 0.1 * (1 / 0.1 + 1 / 2.0) * 1e-3
    assert u[-1] == 0.0  # at the speed limit the motor stops pushing


def test_wheel_jitter_is_a_rotating_force_on_the_hub():
    """Static imbalance U_s at rate Ω (wheel at the hub origin = centre of mass): a force of magnitude U_s Ω² on
    the hub turning with the wheel angle. Its integral, the linear momentum, is U_s Ω (sin θ, 1 − cos θ): at most
    2 U_s Ω, back to zero after whole turns; the work of the force is in the energy balance."""
    m = hub_wheel()
    v0 = np.zeros(m.nv)
    dt = 1e-4
    t_final = 12566 * dt  # ten whole turns at about 50 rad/s, in whole steps
    om = 10 * 2 * np.pi / t_final
    v0[6] = om
    us = 1e-4
    acts = ff.Actuators(wheels=[ff.Wheel("rw", static_imbalance=us)])
    tr = ff.simulate(m, m.neutral(), v0, t_final, dt, actuators=acts)
    p = np.linalg.norm(tr.momentum[:, :2], axis=1)
    assert p.max() <= 2 * us * om * (1 + 1e-6)
    assert p.max() >= 1.9 * us * om
    assert abs(tr.momentum[-1, 0]) < 1e-3 * us * om  # whole turns: back to zero
    e = tr.energy_balance()
    assert e["rel"] < 1e-8


# -- thrusters and tanks -----------------------------------------------------------------------------------------
def test_thruster_through_the_centre_of_mass_gives_exactly_its_impulse():
    m = point_body()
    th = ff.Thruster(direction=(1, 0, 0), max_thrust=2.0, firings=[(0.2, 0.5)])
    tr = ff.simulate(m, m.neutral(), np.zeros(6), 1.0, 0.01, actuators=ff.Actuators(thrusters=[th]))
    np.testing.assert_allclose(tr.momentum[-1, :3], [1.0, 0, 0], atol=1e-13)
    assert np.abs(tr.momentum[:, 3:]).max() < 1e-13
    assert tr.energy_balance()["rel"] < 1e-12  # the work includes the thrust's power


def test_minimum_on_time_and_ramps():
    """A 10 ms request with a 100 ms minimum on-time delivers F × 0.1; linear ramps of 0.1 s on a 1 s firing
    lose 0.05 s of full thrust on the rise and gain it back on the fall: impulse F × 1.0."""
    m = point_body()
    th = ff.Thruster(direction=(1, 0, 0), max_thrust=1.0, min_on_time=0.1, firings=[(0.1, 0.01)])
    tr = ff.simulate(m, m.neutral(), np.zeros(6), 0.5, 0.001, actuators=ff.Actuators(thrusters=[th]))
    assert abs(tr.momentum[-1, 0] - 0.1) < 1e-12
    th = ff.Thruster(direction=(1, 0, 0), max_thrust=1.0, ramp_on=0.1, ramp_off=0.1, firings=[(0.1, 1.0)])
    tr = ff.simulate(m, m.neutral(), np.zeros(6), 1.5, 0.001, actuators=ff.Actuators(thrusters=[th]))
    assert abs(tr.momentum[-1, 0] - 1.0) < 1e-12


def test_tank_depletion_mass_equals_the_propellant_through_the_nozzle():
    """F = 2 N, Isp = 200 s for 3 s: ṁ = F / (Isp g0); the propellant left and the base mass drop by
    F T / (Isp g0); the base's centre of mass moves as the tank's point mass leaves (closed form); the momentum
    change equals the impulse plus the momentum the propellant carried away (∫ ṁ v dt)."""
    m = point_body()
    tank = ff.Tank("main", mass=0.5, position=(0.1, 0.0, 0.0))  # on the thrust line: no torque
    th = ff.Thruster(direction=(1, 0, 0), max_thrust=2.0, isp=200.0, tank="main", firings=[(0.5, 3.0)])
    tr = ff.simulate(m, m.neutral(), np.zeros(6), 4.0, 0.01, actuators=ff.Actuators(thrusters=[th], tanks=[tank]))
    used = 2.0 * 3.0 / (200.0 * G0)
    np.testing.assert_allclose(tr.propellant[-1, 0], 0.5 - used, rtol=1e-12)
    np.testing.assert_allclose(tr.base_parameters[-1, 0], 2.0 - used, rtol=1e-12)
    np.testing.assert_allclose(tr.base_parameters[0, 0], 2.0, rtol=1e-15)
    # the model's (wet) body has its centre of mass at the origin; m c_x then changes by 0.1 × propellant used
    np.testing.assert_allclose(tr.base_parameters[:, 1], 0.1 * (tr.propellant[:, 0] - 0.5), rtol=1e-12, atol=1e-15)
    # rocket: the body's velocity grows as ∫ F / m(t) dt: Δv = Isp g0 ln(m0 / m1) (Tsiolkovsky)
    m0, m1 = 2.0, 2.0 - used
    np.testing.assert_allclose(tr.v[-1, 0], 200.0 * G0 * np.log(m0 / m1), rtol=1e-10)
    assert np.abs(tr.v[:, 3:]).max() < 1e-14


def test_actuator_bad_input_names_the_key():
    m = point_body()
    with pytest.raises(InputError, match=r"thrusters\[0\].direction"):
        ff.simulate(
            m,
            m.neutral(),
            np.zeros(6),
            1.0,
            0.01,
            actuators=ff.Actuators(thrusters=[ff.Thruster(direction=(0, 0, 0), max_thrust=1.0)]),
        )
    with pytest.raises(InputError, match=r"thrusters\[0\].isp"):
        ff.simulate(
            m,
            m.neutral(),
            np.zeros(6),
            1.0,
            0.01,
            actuators=ff.Actuators(thrusters=[ff.Thruster(direction=(1, 0, 0), max_thrust=1.0, isp=0.0)]),
        )
    with pytest.raises(InputError, match=r"tanks\[0\].mass"):
        ff.simulate(m, m.neutral(), np.zeros(6), 1.0, 0.01, actuators=ff.Actuators(tanks=[ff.Tank("t", mass=3.0)]))
    with pytest.raises(InputError, match="unknown key"):
        ff.simulate(m, m.neutral(), np.zeros(6), 1.0, 0.01, actuators={"wheels": [{"joint": "x", "frition": 1}]})
    mw = hub_wheel()
    with pytest.raises(InputError, match=r"wheels\[0\].joint"):
        ff.simulate(mw, mw.neutral(), np.zeros(mw.nv), 1.0, 0.01, actuators=ff.Actuators(wheels=[ff.Wheel("nope")]))
    with pytest.raises(InputError, match=r"wheels\[0\].max_torque"):
        ff.simulate(
            mw,
            mw.neutral(),
            np.zeros(mw.nv),
            1.0,
            0.01,
            actuators=ff.Actuators(wheels=[ff.Wheel("rw", max_torque=-1.0)]),
        )


def test_actuators_from_a_yaml_block():
    import yaml

    d = yaml.safe_load(
        """
actuators:
  wheels:
    - {joint: rw, viscous: 0.01}
"""
    )
    m = hub_wheel()
    v0 = np.zeros(m.nv)
    v0[6] = 10.0
    tr = ff.simulate(m, m.neutral(), v0, 1.0, 1e-3, actuators=d["actuators"])
    np.testing.assert_allclose(tr.v[-1, 6], 10.0 * np.exp(-0.01 * (1 / 0.1 + 1 / 2.0)), rtol=1e-10)


def test_add_wheels_appends_rotor_bodies_to_the_base():
    import yaml

    from freefloat.actuators import add_wheels

    doc = yaml.safe_load(hub_wheel_yaml())
    doc["bodies"] = doc["bodies"][:1]
    m = ff.Model.from_yaml_string(yaml.safe_dump(add_wheels(doc, 3, inertia=(0.1, 0.06), mass=1.0)))
    assert m.nv == 9 and [j for j in m.joint_names if j.startswith("rw")] == ["rw1", "rw2", "rw3"]
    # locked inertia about the base origin: hub 2 + per axis one spin (0.1) and two transverse (0.06 + m r² 0.04)
    mb = ff.crba(m, m.neutral())[3:6, 3:6]
    np.testing.assert_allclose(np.diag(mb), 2.0 + 0.1 + 2 * (0.06 + 0.04), rtol=1e-12)


@pytest.mark.slow
def test_cli_simulate_reads_an_actuators_file(tmp_path):
    """`freefloat simulate MODEL --actuators FILE` reads the `actuators:` block; a bad key is a clear error."""
    import json
    import subprocess
    import sys

    model = tmp_path / "hub_wheel.yaml"
    model.write_text(hub_wheel_yaml())
    acts = tmp_path / "acts.yaml"
    acts.write_text("actuators:\n  wheels:\n    - {joint: rw, viscous: 0.01, max_torque: 0.1}\n")
    out = tmp_path / "run"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "freefloat.cli",
            "simulate",
            str(model),
            "--actuators",
            str(acts),
            "--t-final",
            "1",
            "--torques",
            "zero",
            "--v0",
            "0,0,0,0,0,0,10",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    res = json.loads((out / "results.json").read_text())
    assert res["model"] == "hub_wheel"
    acts.write_text("actuators:\n  wheels:\n    - {joint: rw, frition: 0.01}\n")
    r = subprocess.run(
        [sys.executable, "-m", "freefloat.cli", "simulate", str(model), "--actuators", str(acts), "--t-final", "1"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode != 0 and "frition" in r.stderr and "Traceback" not in r.stderr


def test_cli_simulate_applies_limits_from_an_actuators_file(tmp_path):
    """The same limit through the command line: `--actuators` with `limits: [{joint, effort, velocity}]` and a
    table of 0.1 N m: the recorded torque is the limit and the wheel stops accelerating at the velocity limit."""
    import subprocess
    import sys

    model = tmp_path / "hub_wheel.yaml"
    model.write_text(hub_wheel_yaml())
    acts = tmp_path / "acts.yaml"
    acts.write_text("actuators:\n  limits:\n    - {joint: rw, effort: 0.05, velocity: 1.0}\n")
    tau = tmp_path / "tau.npy"
    np.save(tau, np.array([[0, 0, 0, 0, 0, 0, 0.1]]))
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "freefloat.cli", "simulate", str(model), "--actuators", str(acts)]
    cmd += ["--t-final", "3", "--dt", "0.001", "--record-every", "1", "--torques", str(tau), "--out", str(out)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    tr = ff.Trajectory.from_parquet(out / "trajectory.parquet")
    a = 0.05 * (1 / 0.1 + 1 / 2.0)
    assert np.abs(tr.tau[:, 6]).max() == 0.05
    early = tr.t < 0.9 / a
    np.testing.assert_allclose(tr.v[early, 6], a * tr.t[early], atol=1e-12)
    assert tr.v[:, 6].max() <= 1.0 + a * 1e-3 + 1e-12 and tr.v[-1, 6] >= 1.0 - 1e-12
    acts.write_text("actuators:\n  limits:\n    - {joint: rw, effort: -1}\n")
    r = subprocess.run(cmd[:7] + ["--t-final", "0.1"], capture_output=True, text=True, timeout=300)
    assert r.returncode != 0 and "limits[0].effort" in r.stderr and "Traceback" not in r.stderr


def test_propellant_and_base_parameters_survive_the_trajectory_files(tmp_path):
    """A run with a draining tank keeps its propellant and base-parameter columns in Parquet and CSV."""
    m = point_body()
    tank = ff.Tank("main", mass=0.5, position=(0.1, 0.0, 0.0))
    th = ff.Thruster(direction=(1, 0, 0), max_thrust=2.0, isp=200.0, tank="main", firings=[(0.1, 0.5)])
    tr = ff.simulate(m, m.neutral(), np.zeros(6), 1.0, 0.01, actuators=ff.Actuators(thrusters=[th], tanks=[tank]))
    assert tr.propellant[-1, 0] < tr.propellant[0, 0]  # the tank really drained
    tr.to_parquet(tmp_path / "run.parquet")
    back = ff.Trajectory.from_parquet(tmp_path / "run.parquet")
    np.testing.assert_array_equal(back.propellant, tr.propellant)
    np.testing.assert_array_equal(back.base_parameters, tr.base_parameters)
    tr.to_csv(tmp_path / "run.csv")
    header = (tmp_path / "run.csv").read_text().splitlines()[1].split(",")
    assert "propellant.0" in header and "base_parameters.m" in header and "base_parameters.Izz" in header
    # a run without tanks writes none of these columns
    plain = ff.simulate(m, m.neutral(), np.zeros(6), 0.1, 0.01)
    plain.to_parquet(tmp_path / "plain.parquet")
    assert ff.Trajectory.from_parquet(tmp_path / "plain.parquet").propellant is None


def test_actuator_keys_and_wheel_defaults_have_one_source():
    """The engine (`Wheel::new`, the binding's key lists) is the one source: the Python classes and the scenario
    schema take their wheel defaults and keys from it, and all three agree."""
    from dataclasses import fields

    from freefloat import _core
    from freefloat.io import scenario_schemas as ss

    f = _core.actuator_fields()
    assert f["actuators"] == ["limits", "wheels", "thrusters", "tanks"]
    assert set(f["actuators"]) == {x.name for x in fields(ff.Actuators)} == set(ss.ActuatorsBlock.model_fields)
    for key, cls, block in [
        ("limits", ff.JointLimit, ss.ActLimit),
        ("wheels", ff.Wheel, ss.ActWheel),
        ("thrusters", ff.Thruster, ss.ActThruster),
        ("tanks", ff.Tank, ss.ActTank),
    ]:
        assert set(f[key]["keys"]) == {x.name for x in fields(cls)} == set(block.model_fields), key
    wd = f["wheels"]["defaults"]
    assert set(wd) == set(f["wheels"]["keys"]) - {"joint"}  # every setting has its engine default
    for k, v in wd.items():
        assert getattr(ff.Wheel("rw"), k) == v, k
        assert ss.ActWheel.model_fields[k].default == v, k
    # Basilisk's default limit-cycle speed (ReactionWheelStateEffector, 1e-4 rad/s), the documented value
    assert wd["limit_cycle_speed"] == 1e-4
    # a wheel given without a setting runs with the engine's default: the same run as with it written out
    m = hub_wheel()
    v0 = np.zeros(m.nv)
    v0[6] = 5e-5  # inside the limit-cycle band, where the default matters
    a = {"wheels": [{"joint": "rw", "coulomb": 1e-3}]}
    b = {"wheels": [{"joint": "rw", "coulomb": 1e-3, "limit_cycle_speed": wd["limit_cycle_speed"]}]}
    ta = ff.simulate(m, m.neutral(), v0, 0.01, 1e-3, actuators=a)
    tb = ff.simulate(m, m.neutral(), v0, 0.01, 1e-3, actuators=b)
    np.testing.assert_array_equal(ta.v, tb.v)
