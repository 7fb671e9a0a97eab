"""The orbital environment (`ff.Environment`): off changes nothing; the orbit against the closed two-body
solution and J2 against an independent high-order integration; gravity-gradient libration against its
linearised closed form; momentum changes by exactly the integrated external wrench; bad input names its key;
the `environment:` block of a file and `freefloat simulate --environment`."""

import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import freefloat as ff
from freefloat.environment import environment_from_dict

MU = 3.986004418e14
RE = 6378137.0
RIGID = "name: rigid\nbodies:\n  - name: base\n    inertial: {mass: 100, com: [%s], inertia: [10, 14, 18]}\n"


def rigid(com=(0.0, 0.0, 0.0)):
    return ff.Model.from_yaml_string(RIGID % ", ".join(str(c) for c in com))


def kepler_position(a, e, i, raan, argp, nu0, t, mu=MU):
    """Two-body position from classical elements, written independently of the engine: mean anomaly, Kepler's
    equation E − e sin E = M by Newton, perifocal coordinates, then the 3-1-3 rotation."""
    n = np.sqrt(mu / a**3)
    e0 = 2 * np.arctan(np.sqrt((1 - e) / (1 + e)) * np.tan(nu0 / 2))
    m = e0 - e * np.sin(e0) + n * np.asarray(t)
    ecc = m.copy()
    for _ in range(30):
        ecc = ecc - (ecc - e * np.sin(ecc) - m) / (1 - e * np.cos(ecc))
    x = a * (np.cos(ecc) - e)
    y = a * np.sqrt(1 - e * e) * np.sin(ecc)

    def rz(q):
        return np.array([[np.cos(q), -np.sin(q), 0], [np.sin(q), np.cos(q), 0], [0, 0, 1]])

    rx = np.array([[1, 0, 0], [0, np.cos(i), -np.sin(i)], [0, np.sin(i), np.cos(i)]])
    rot = rz(raan) @ rx @ rz(argp)
    return (rot @ np.vstack([x, y, np.zeros_like(x)])).T


def test_an_environment_that_is_off_changes_nothing_bit_for_bit():
    """`Environment()` (everything off) gives the very same trajectory as no environment."""
    m = ff.models.load("naveen_dual_arm")
    rng = np.random.default_rng(1)
    tau = np.zeros((50, m.nv))
    tau[:, 6:] = rng.normal(size=(50, m.nv - 6))
    args = (m, m.neutral(), np.zeros(m.nv), 0.5, 0.01)
    a = ff.simulate(*args, torques=tau)
    b = ff.simulate(*args, torques=tau, environment=ff.Environment())
    for k in ("q", "v", "ddq", "tau", "momentum", "kinetic_energy", "work"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert b.orbit is None


def test_centre_of_mass_orbit_is_the_two_body_solution_over_one_orbit():
    """Point-mass gravity with the gravity gradient on, a rigid body whose CoM is off the base origin and drifts:
    the CoM's inertial position (frame origin + local CoM) follows Kepler's closed form to round-off over one
    eccentric, inclined orbit."""
    el = dict(a=7.2e6, e=0.05, i=0.9, raan=0.4, argp=1.1, nu0=0.3)
    env = ff.Environment(
        semi_major_axis=el["a"],
        eccentricity=el["e"],
        inclination=el["i"],
        raan=el["raan"],
        arg_periapsis=el["argp"],
        true_anomaly=el["nu0"],
        gravity_gradient=True,
    )
    m = rigid((0.2, -0.1, 0.05))
    q0 = np.r_[0.3, 0.0, -0.2, 0.1, 0.2, 0.0, np.sqrt(0.95)]
    v0 = np.r_[0.01, -0.02, 0.005, 0.01, 0.0, 0.02]
    tr = ff.simulate(m, q0, v0, env.period, env.period / 6000, record_every=20, environment=env)
    com = np.array([ff.center_of_mass(m, q) for q in tr.q])
    ref = kepler_position(**el, t=tr.t)
    assert tr.t[-1] == pytest.approx(env.period)
    # the reference point (frame origin + the CoM's free-floating path c0 + ċ0 t) is the closed form to round-off
    cdot = ff.momentum(m, q0, v0)[:3] / m.total_mass
    path = com[0] + np.outer(tr.t, cdot)
    err = np.abs(tr.orbit[:, :3] + path - ref).max()
    assert err < 1e-7, err  # 7.5e6 m radius: ~1e-14 relative (measured 1.8e-8 m)
    # the CoM itself: that plus the multibody RK4 error of the tumbling body's local CoM (dt ≈ 1 s, 4th order)
    err_com = np.abs(tr.orbit[:, :3] + com - ref).max()
    assert err_com < 2e-5, err_com  # measured 1.1e-5 m at dt = T/6000, 7e-7 m at T/12000
    # the local positions stay small (metres, not 7e6 m)
    assert np.abs(tr.q[:, :3]).max() < 1e3


def test_j2_orbit_matches_an_independent_high_order_integration():
    """With J2 the frame origin's orbit (RK4 on the engine's fine grid) matches scipy's DOP853 at rtol 1e-13 over
    one orbit to a millimetre; the J2 effect itself is kilometres."""
    env = ff.Environment(altitude=400e3, eccentricity=0.01, inclination=0.9, j2=True)
    m = rigid()
    t = np.linspace(0, env.period, 41)
    orb = env.reference_orbit(m, m.neutral(), np.zeros(6), t)
    j2 = 1.0826267e-3

    def f(_, y):
        r = y[:3]
        rn = np.linalg.norm(r)
        z2 = (r[2] / rn) ** 2
        k = -1.5 * MU * j2 * RE**2 / rn**4
        a = -MU * r / rn**3 + k * np.array([(1 - 5 * z2) * r[0], (1 - 5 * z2) * r[1], (3 - 5 * z2) * r[2]]) / rn
        return np.r_[y[3:], a]

    r0, v0 = env.orbit_state
    sol = solve_ivp(f, (0, t[-1]), np.r_[r0, v0], method="DOP853", rtol=1e-13, atol=1e-9, t_eval=t)
    assert np.abs(sol.y[:3].T - orb[:, :3]).max() < 1e-3
    kep = ff.Environment(altitude=400e3, eccentricity=0.01, inclination=0.9).reference_orbit(
        m, m.neutral(), np.zeros(6), t
    )
    assert np.abs(kep[:, :3] - orb[:, :3]).max() > 1e3


def test_gravity_gradient_pitch_libration_matches_the_linearised_closed_form():
    """A rigid body in a circular orbit, aligned with the orbit frame and turned by a small pitch θ0 about the
    orbit normal: θ(t) = θ0 cos(ω t) with ω = n √(3 (Iy − Ix)/Iz) (first-order gravity gradient, small angles)."""
    env = ff.Environment(altitude=500e3, gravity_gradient=True)
    n = 2 * np.pi / env.period
    ix, iy, iz = 10.0, 14.0, 18.0
    w = n * np.sqrt(3 * (iy - ix) / iz)
    th0 = 1e-3
    q0 = np.r_[0, 0, 0, 0, 0, np.sin(th0 / 2), np.cos(th0 / 2)]
    v0 = np.r_[0, 0, 0, 0, 0, n]
    # three orbits, rounded to whole 1 s steps
    tr = ff.simulate(rigid(), q0, v0, float(round(3 * env.period)), 1.0, record_every=10, environment=env)
    yaw = 2 * np.arctan2(tr.q[:, 5], tr.q[:, 6])
    theta = (yaw - n * tr.t + np.pi) % (2 * np.pi) - np.pi
    err = np.abs(theta - th0 * np.cos(w * tr.t)).max()
    assert np.abs(theta).max() == pytest.approx(th0, rel=1e-3)
    assert err < 2e-5 * th0, err  # the neglected sin θ cos θ − θ term: ~θ0² relative


def _integrate(t, y):
    """Composite Simpson over the recorded samples (an even number of intervals)."""
    h = t[1] - t[0]
    return h / 3 * (y[0] + 4 * y[1:-1:2].sum(axis=0) + 2 * y[2:-1:2].sum(axis=0) + y[-1])


def test_angular_momentum_about_the_com_changes_by_the_integrated_gravity_gradient_torque():
    """A two-arm robot tumbling with joint motion in orbit: the angular momentum about its CoM changes by the
    integral of the environment's moment about the CoM (gravity-gradient torques and tidal forces), and the linear
    momentum by the integrated tidal force, both to the integration error (the momentum drift of the same run
    without the environment); the change itself is far larger."""
    m = ff.models.load("naveen_dual_arm")
    env = ff.Environment(altitude=400e3, inclination=0.7, gravity_gradient=True)
    v0 = np.zeros(m.nv)
    v0[3:6] = [0.02, -0.01, 0.03]
    v0[6:] = 0.05
    q0 = m.neutral()
    tr = ff.simulate(m, q0, v0, 100.0, 0.025, environment=env)
    # the integration error of this motion: the momentum drift of the same run without the environment
    free = ff.simulate(m, q0, v0, 100.0, 0.025)
    drift = np.abs(free.momentum[-1] - free.momentum[0]).max()
    w = env.external_wrenches(m, q0, v0, tr.t, tr.q)
    com = np.array([ff.center_of_mass(m, q) for q in tr.q])
    p, lo = tr.momentum[:, :3], tr.momentum[:, 3:]
    l_com = lo - np.cross(com, p)
    m_com = w[:, 3:] - np.cross(com, w[:, :3])
    dl = l_com[-1] - l_com[0]
    il = _integrate(tr.t, m_com)
    dp = p[-1] - p[0]
    ip = _integrate(tr.t, w[:, :3])
    assert np.linalg.norm(dl) > 1e-4
    # measured at dt = 0.025 s: mismatch 1.8e-10 against a drift of 2.6e-10 (both scale as dt⁴)
    assert np.linalg.norm(dl - il) < 3 * drift, (dl - il, drift)
    assert np.linalg.norm(dl - il) < 1e-7 * np.linalg.norm(dl)
    assert np.linalg.norm(dp - ip) < 3 * drift + 1e-15, (dp - ip, drift)
    assert tr.integration_warning() is None  # external forces: the conservation warning does not apply


def test_a_constant_inertial_disturbance_changes_momentum_by_force_times_time():
    m = ff.models.load("valverde_ch5_single_arm")
    f, tq = np.array([0.1, -0.2, 0.05]), np.array([0.01, 0.0, -0.02])
    env = ff.Environment(disturbance_force=f, disturbance_torque=tq)
    tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 2.0, 0.01, environment=env)
    assert np.abs(tr.momentum[-1, :3] - f * 2.0).max() < 1e-12
    w = env.external_wrenches(m, m.neutral(), np.zeros(m.nv), tr.t, tr.q)
    dl = tr.momentum[-1, 3:] - tr.momentum[0, 3:]
    assert np.abs(dl - _integrate(tr.t, w[:, 3:])).max() < 1e-10
    # body-axes disturbance on a spinning base points elsewhere: different motion
    body = ff.simulate(
        m,
        m.neutral(),
        np.r_[0, 0, 0, 0, 0, 1.0, np.zeros(m.nv - 6)],
        2.0,
        0.01,
        environment=ff.Environment(disturbance_force=f, disturbance_axes="body"),
    )
    assert np.abs(body.momentum[-1, :3] - f * 2.0).max() > 1e-3


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(altitude=-10e3), ["altitude", "above"]),
        (dict(semi_major_axis=6.0e6), ["semi_major_axis", "radius"]),
        (dict(altitude=500e3, mu=-1.0), ["mu", "positive"]),
        (dict(altitude=500e3, mu=0.0), ["mu", "positive"]),
        (dict(altitude=500e3, eccentricity=1.2), ["eccentricity"]),
        (dict(disturbance_force=[0.0, np.nan, 0.0]), ["disturbance_force", "finite"]),
        (dict(disturbance_torque=[np.inf, 0.0, 0.0]), ["disturbance_torque", "finite"]),
        (dict(gravity_gradient=True), ["gravity_gradient", "orbit"]),
        (dict(altitude=500e3, disturbance_axes="lvlh"), ["disturbance_axes"]),
        (dict(position=[7e6, 0, 0]), ["position", "velocity"]),
        (dict(position=[6e6, 0, 0], velocity=[0, 7e3, 0]), ["periapsis", "radius"]),
    ],
)
def test_bad_environment_arguments_are_named(kwargs, words):
    with pytest.raises(ff.InputError) as e:
        ff.Environment(**kwargs)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_environment_errors_against_the_model():
    m = ff.models.load("valverde_ch5_single_arm")
    with pytest.raises(ff.InputError, match="disturbance.body"):
        ff.simulate(
            m,
            m.neutral(),
            np.zeros(m.nv),
            0.1,
            0.01,
            environment=ff.Environment(disturbance_force=[1, 0, 0], disturbance_body=99),
        )


@pytest.mark.parametrize(
    "block, key",
    [
        ({"orbit": {"altitude": -5.0}}, "environment.orbit.altitude"),
        ({"orbit": {"altitude": 5e5}, "central_body": {"mu": -3.0}}, "environment.central_body.mu"),
        ({"orbit": {"altitude": 5e5, "inclination_deg": "high"}}, "environment.orbit.inclination_deg"),
        ({"orbit": {"altitude": 5e5, "color": 1}}, "environment.orbit"),
        ({"gravity_gradient": "yes"}, "environment.gravity_gradient"),
        ({"disturbance": {"force": [0, ".nan", 0]}}, "environment.disturbance.force"),
        ({"disturbance": {"torque": [0, float("nan"), 0]}}, "environment.disturbance.torque"),
        ({"orbits": {}}, "environment"),
        ({"orbit": {"semi_major_axis": 6e6}}, "semi_major_axis"),
    ],
)
def test_bad_environment_blocks_name_the_key(block, key):
    with pytest.raises(ff.InputError) as e:
        environment_from_dict(block)
    assert key in str(e.value), str(e.value)


@pytest.mark.slow
def test_environment_block_and_cli(tmp_path):
    from click.testing import CliRunner

    from freefloat.cli import main

    block = {
        "orbit": {"altitude": 450e3, "eccentricity": 0.001, "inclination_deg": 51.6},
        "gravity_gradient": True,
        "j2": True,
        "disturbance": {"torque": [1e-5, 0, 0], "axes": "body"},
    }
    env = environment_from_dict(block)
    assert env.gravity_gradient and env.j2
    assert env.period == pytest.approx(2 * np.pi * np.sqrt((RE + 450e3) ** 3 / (1 - 0.001) ** 3 / MU))
    path = tmp_path / "scenario.yaml"
    path.write_text(
        "environment:\n  orbit: {altitude: 450000.0, inclination_deg: 51.6}\n  gravity_gradient: true\n  j2: true\n"
    )
    out = tmp_path / "run"
    res = CliRunner().invoke(
        main,
        [
            "simulate",
            "valverde_ch5_single_arm",
            "--t-final",
            "0.5",
            "--dt",
            "0.01",
            "--environment",
            str(path),
            "--out",
            str(out),
        ],
    )
    assert res.exit_code == 0, res.output
    assert json.loads((out / "results.json").read_text())
    bad = tmp_path / "bad.yaml"
    bad.write_text("environment:\n  orbit: {altitude: -1.0}\n")
    res = CliRunner().invoke(
        main, ["simulate", "valverde_ch5_single_arm", "--t-final", "0.1", "--environment", str(bad)]
    )
    assert res.exit_code != 0
    assert "environment.orbit.altitude" in res.output
