"""Gravity-gradient libration of a rigid body in a circular orbit, freefloat against Basilisk 2.12 (`bsk`,
`GravityGradientEffector` on a `spacecraft.Spacecraft` hub) in the same run.

Both integrate the same equations with fixed-step RK4 at the same step: Basilisk the hub's inertial position
(7e6 m) with point-mass gravity and its MRP attitude with the first-order gravity-gradient torque
3μ/r³ r̂ × (I r̂); freefloat the closed two-body orbit of its frame origin and the body's attitude on SO(3) with
the same torque (Valverde 2018, (2.63)/(2.67)). What is left between them is the difference of two RK4
discretisations of a motion whose fastest rate is the orbital rate n ≈ 1.1e-3 rad/s, (n h)^4 ≈ 1e-12 per orbit
at h = 1 s, and round-off: the tolerances below are set from that (body rates 1e-14 rad/s against rates of
1e-3 rad/s, attitude 1e-11 rad, Basilisk's RK4 orbit 1e-5 m from the closed form over three orbits; measured:
2.4e-16 rad/s, 2.8e-13 rad, 1.6e-6 m)."""

import numpy as np
import pytest

import freefloat as ff

bsk = pytest.importorskip("Basilisk", reason="Basilisk (PyPI `bsk`) is not installed")
from Basilisk.simulation import GravityGradientEffector, spacecraft  # noqa: E402
from Basilisk.utilities import RigidBodyKinematics as rbk  # noqa: E402
from Basilisk.utilities import SimulationBaseClass, macros, simIncludeGravBody  # noqa: E402

INERTIA = [10.0, 14.0, 18.0]
MASS = 100.0


def _basilisk(mu, r_n, v_n, sigma0, omega0, dt, t_final, every):
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("dynamics")
    proc.addTask(sim.CreateNewTask("task", macros.sec2nano(dt)))
    grav = simIncludeGravBody.gravBodyFactory()
    earth = grav.createEarth()
    earth.isCentralBody = True
    earth.mu = mu
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "rigid"
    sc.hub.mHub = MASS
    sc.hub.IHubPntBc_B = np.diag(INERTIA).tolist()
    sc.hub.r_CN_NInit = [[x] for x in r_n]
    sc.hub.v_CN_NInit = [[x] for x in v_n]
    sc.hub.sigma_BNInit = [[x] for x in sigma0]
    sc.hub.omega_BN_BInit = [[x] for x in omega0]
    sim.AddModelToTask("task", sc)
    grav.addBodiesTo(sc)
    gg = GravityGradientEffector.GravityGradientEffector()
    gg.ModelTag = "gravityGradient"
    gg.addPlanetName(earth.planetName)
    sc.addDynamicEffector(gg)
    sim.AddModelToTask("task", gg)
    rec = sc.scStateOutMsg.recorder(macros.sec2nano(dt * every))
    sim.AddModelToTask("task", rec)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(t_final))
    sim.ExecuteSimulation()
    return rec.times() * 1e-9, np.array(rec.sigma_BN), np.array(rec.omega_BN_B), np.array(rec.r_BN_N)


def _angle(ra, rb):
    """Rotation angle between two rotation matrices, from the skew part (arccos of the trace loses half the digits)."""
    e = ra.T @ rb
    w = np.array([e[2, 1] - e[1, 2], e[0, 2] - e[2, 0], e[1, 0] - e[0, 1]]) / 2
    return np.arcsin(min(np.linalg.norm(w), 1.0))


@pytest.mark.slow
def test_gravity_gradient_libration_matches_basilisk():
    """Three orbits of libration about a tilted, slowly tumbling start: body rates to 1e-14 rad/s and attitude to
    1e-11 rad over every recorded sample; the orbit positions agree to Basilisk's RK4 error (1e-5 m)."""
    mu, radius = 3.98600436e14, 6378136.6  # Basilisk's Earth, so both use one field
    env = ff.Environment(altitude=500e3, inclination=0.5, raan=0.3, mu=mu, radius=radius, gravity_gradient=True)
    r_n, v_n = env.orbit_state
    n = 2 * np.pi / env.period
    model = ff.Model.from_yaml_string(
        f"name: rigid\nbodies:\n  - name: base\n    inertial: {{mass: {MASS}, inertia: {INERTIA}}}\n"
    )
    axis = np.array([0.3, 0.5, 0.8]) / np.linalg.norm([0.3, 0.5, 0.8])
    angle = 0.05
    qv, qw = axis * np.sin(angle / 2), np.cos(angle / 2)
    omega0 = np.array([1e-4, -2e-4, n])
    q0 = np.r_[0.0, 0.0, 0.0, qv, qw]
    v0 = np.r_[0.0, 0.0, 0.0, omega0]
    sigma0 = qv / (1 + qw)  # MRP of the same attitude: [BN] = R(q)ᵀ
    assert np.abs(rbk.MRP2C(sigma0) - ff.quat_to_matrix(np.r_[qv, qw]).T).max() < 1e-15
    dt, every = 1.0, 10
    t_final = np.floor(3 * env.period / (dt * every)) * dt * every
    tb, sigma, omega, r_b = _basilisk(mu, r_n, v_n, sigma0, omega0, dt, t_final, every)
    tr = ff.simulate(model, q0, v0, t_final, dt, environment=env, record_every=every)
    assert len(tb) == len(tr.t) and np.abs(tb - tr.t).max() < 1e-9
    att = max(_angle(rbk.MRP2C(s).T, ff.quat_to_matrix(q)) for s, q in zip(sigma, tr.q[:, 3:7]))
    rate = np.abs(omega - tr.v[:, 3:6]).max()
    pos = np.abs(r_b - (tr.orbit[:, :3] + tr.q[:, :3])).max()
    # the libration is real: the rates move by far more than the tolerance
    assert np.abs(tr.v[:, 3:6] - omega0).max() > 1e-5
    print(f"attitude {att:.3g} rad, rates {rate:.3g} rad/s, position {pos:.3g} m")
    assert rate < 1e-14, rate
    assert att < 1e-11, att
    assert pos < 1e-5, pos
