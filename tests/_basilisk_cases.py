"""The hub-plus-three-wheels case built identically in Basilisk and in freefloat (shared by
tests/test_basilisk_actuators.py and benches/basilisk_wheels.py)."""

from __future__ import annotations

import numpy as np

RPM = 2 * np.pi / 60
# Basilisk's hub carries the whole locked spacecraft (BalancedWheels adds only the spin dynamics);
# in freefloat each rotor is a body, so the hub there is the Basilisk hub minus the rotors.
M_HUB, I_HUB = 750.0, np.diag([900.0, 800.0, 600.0])
OMEGA0 = np.array([0.08, 0.01, 0.0])  # rad/s, body frame
M_W, JS, JT = 1.0, 0.1, 0.06  # rotor mass, spin and transverse inertia
AXES = np.eye(3)
WHEEL_RPM0 = np.array([100.0, 200.0, -150.0])
CMD = np.array([0.3, 0.1, -0.5])  # N m, constant
U_MAX, OMEGA_MAX_RPM = 0.2, 400.0
P_MAX = [None, 1.5, None]  # W: only the second wheel is power-limited
F_COULOMB, C_VISCOUS = 0.005, 1e-4


def freefloat_model():
    import freefloat as ff

    i_rot = sum(JS * np.outer(a, a) + JT * (np.eye(3) - np.outer(a, a)) for a in AXES)
    ih = (I_HUB - i_rot).tolist()
    lines = [
        "name: bsk_hub_three_wheels",
        "base: free",
        "gravity: [0, 0, 0]",
        "bodies:",
        "  - name: hub",
        f"    inertial: {{mass: {M_HUB - 3 * M_W!r}, com: [0, 0, 0], inertia: {{xx: {ih[0][0]!r}, yy: {ih[1][1]!r}, "
        f"zz: {ih[2][2]!r}, xy: 0, yz: 0, xz: 0}}}}",
    ]
    for k, a in enumerate(AXES):
        d = (JT * np.ones(3) + (JS - JT) * a).tolist()
        a = a.tolist()
        lines += [
            f"  - name: rotor{k + 1}",
            "    parent: hub",
            f"    joint: {{name: rw{k + 1}, type: revolute, axis: [{a[0]!r}, {a[1]!r}, {a[2]!r}]}}",
            "    origin: {xyz: [0, 0, 0], rpy: [0, 0, 0]}",
            f"    inertial: {{mass: {M_W!r}, com: [0, 0, 0], inertia: [{d[0]!r}, {d[1]!r}, {d[2]!r}]}}",
        ]
    return ff.Model.from_yaml_string("\n".join(lines) + "\n")


def freefloat_actuators(friction=True, limits=True):
    import freefloat as ff

    wheels = [
        ff.Wheel(
            f"rw{k + 1}",
            max_torque=U_MAX if limits else None,
            max_speed=OMEGA_MAX_RPM * RPM if limits else None,
            max_power=P_MAX[k] if limits else None,
            coulomb=F_COULOMB if friction else 0.0,
            viscous=C_VISCOUS if friction else 0.0,
        )
        for k in range(3)
    ]
    return ff.Actuators(wheels=wheels)


def freefloat_run(t_final, dt, friction=True, limits=True, record_every=1):
    import freefloat as ff

    m = freefloat_model()
    q0 = m.neutral()
    v0 = np.zeros(m.nv)
    v0[3:6] = OMEGA0
    v0[6:9] = WHEEL_RPM0 * RPM
    n = int(round(t_final / dt)) + 1
    tau = np.zeros((1, m.nv))
    tau[0, 6:9] = CMD
    return ff.simulate(
        m,
        q0,
        v0,
        t_final,
        dt,
        torques=np.repeat(tau, 1, axis=0),
        torque_times=np.array([0.0]),
        actuators=freefloat_actuators(friction, limits),
        record_every=record_every,
    ), n


def basilisk_run(t_final, dt, friction=True, limits=True, log_momentum=True):
    """Basilisk 2.12: Spacecraft hub + ReactionWheelStateEffector (BalancedWheels), RK4 at the task rate,
    constant motor-torque message. Returns (t, sigma_BN, omega_BN_B, wheel speeds, H about C in N); H is None
    with `log_momentum=False` (its logger is a Python callback at every step, which a timing run leaves out)."""
    from Basilisk.architecture import messaging
    from Basilisk.simulation import reactionWheelStateEffector, spacecraft
    from Basilisk.utilities import SimulationBaseClass, macros, simIncludeRW

    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("proc")
    proc.addTask(sim.CreateNewTask("task", macros.sec2nano(dt)))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "hub"
    fac = simIncludeRW.rwFactory()
    for k, a in enumerate(AXES):
        kw = dict(
            Js=JS,
            Omega=float(WHEEL_RPM0[k]),
            rWB_B=[0.0, 0.0, 0.0],
            RWModel=messaging.BalancedWheels,
            useRWfriction=friction,
            useMaxTorque=limits,
        )
        if limits:
            kw.update(u_max=U_MAX, Omega_max=OMEGA_MAX_RPM)
            if P_MAX[k] is not None:
                kw.update(P_max=P_MAX[k])
        if friction:
            kw.update(fCoulomb=F_COULOMB, cViscous=C_VISCOUS)
        rw = fac.create("custom", [float(x) for x in a], **kw)
        rw.mass = M_W
        if not limits:
            rw.Omega_max = -1.0
    rwe = reactionWheelStateEffector.ReactionWheelStateEffector()
    rwe.ModelTag = "rw"
    fac.addToSpacecraft("rw", rwe, sc)
    cmd = messaging.ArrayMotorTorqueMsgPayload()
    cmd.motorTorque = [float(x) for x in CMD]
    msg = messaging.ArrayMotorTorqueMsg().write(cmd)
    rwe.rwMotorCmdInMsg.subscribeTo(msg)
    sim.AddModelToTask("task", rwe)
    sim.AddModelToTask("task", sc)
    sc.hub.mHub = M_HUB
    sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    sc.hub.IHubPntBc_B = I_HUB.tolist()
    sc.hub.omega_BN_BInit = [[x] for x in OMEGA0]
    sc.hub.sigma_BNInit = [[0.0], [0.0], [0.0]]
    sc.hub.r_CN_NInit = [[0.0], [0.0], [0.0]]
    sc.hub.v_CN_NInit = [[0.0], [0.0], [0.0]]
    log = sc.scStateOutMsg.recorder()
    speeds = rwe.rwSpeedOutMsg.recorder()
    hlog = sc.logger(["totRotAngMomPntC_N"]) if log_momentum else None
    for r in (log, speeds, hlog) if log_momentum else (log, speeds):
        sim.AddModelToTask("task", r)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(t_final))
    sim.ExecuteSimulation()
    t = log.times() * 1e-9
    return (
        t,
        np.array(log.sigma_BN),
        np.array(log.omega_BN_B),
        np.array(speeds.wheelSpeeds)[:, :3],
        np.array(hlog.totRotAngMomPntC_N) if log_momentum else None,
    )


def mrp_to_dcm_nb(s):
    """Rotation matrix of the body in the inertial frame (B axes in N) from the MRP sigma_BN."""
    s = np.asarray(s, float)
    s2 = s @ s
    sx = np.array([[0, -s[2], s[1]], [s[2], 0, -s[0]], [-s[1], s[0], 0]])
    c_bn = np.eye(3) + (8 * sx @ sx - 4 * (1 - s2) * sx) / (1 + s2) ** 2
    return c_bn.T


# -- thruster firing sequence -------------------------------------------------------------------------------------
TH_HUB_M, TH_HUB_I = 750.0, np.diag([900.0, 800.0, 600.0])
TH_PROP, TH_TANK_R = 40.0, 46.0 / 2.0 / 3.2808399 / 12.0  # kg, m (Basilisk's integrated thruster test tank)
TH_POS, TH_DIR, TH_F, TH_ISP = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.9, 227.5  # MOOG Monarc-1
TH_FIRINGS = [(1.0, 2.0), (5.0, 0.5), (8.0, 3.0)]  # (start, duration) s


def freefloat_thruster_run(t_final, dt, delay=0.0):
    """The hub carries the tank at its origin: the model's (wet) inertia is hub + full propellant sphere. `delay`
    shifts every firing (Basilisk reads a command written at t at its next task update, t + dt)."""
    import freefloat as ff

    i_wet = TH_HUB_I + 0.4 * TH_PROP * TH_TANK_R**2 * np.eye(3)
    text = "\n".join(
        [
            "name: bsk_hub_thruster",
            "base: free",
            "gravity: [0, 0, 0]",
            "bodies:",
            "  - name: hub",
            f"    inertial: {{mass: {TH_HUB_M + TH_PROP!r}, com: [0, 0, 0], inertia: [{float(i_wet[0, 0])!r}, "
            f"{float(i_wet[1, 1])!r}, {float(i_wet[2, 2])!r}]}}",
        ]
    )
    m = ff.Model.from_yaml_string(text + "\n")
    acts = ff.Actuators(
        thrusters=[
            ff.Thruster(
                position=TH_POS,
                direction=TH_DIR,
                max_thrust=TH_F,
                isp=TH_ISP,
                tank="main",
                min_on_time=0.02,
                firings=[(s + delay, d) for s, d in TH_FIRINGS],
            )
        ],
        tanks=[ff.Tank("main", mass=TH_PROP, radius=TH_TANK_R)],
    )
    return ff.simulate(m, m.neutral(), np.zeros(6), t_final, dt, actuators=acts)


def basilisk_thruster_run(t_final, dt):
    """Basilisk 2.12: hub + ThrusterDynamicEffector (Monarc-1 preset) fed by a FuelTank (constant-volume sphere),
    on-time commands written at each firing start. Returns (t, r_BN_N, sigma_BN, omega_BN_B, fuel mass)."""
    from Basilisk.architecture import messaging
    from Basilisk.simulation import fuelTank, spacecraft, thrusterDynamicEffector
    from Basilisk.utilities import SimulationBaseClass, macros, simIncludeThruster

    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("proc")
    proc.addTask(sim.CreateNewTask("task", macros.sec2nano(dt)))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "hub"
    fac = simIncludeThruster.thrusterFactory()
    fac.create("MOOG_Monarc_1", TH_POS, TH_DIR)
    the = thrusterDynamicEffector.ThrusterDynamicEffector()
    fac.addToSpacecraft("thr", the, sc)
    tank = fuelTank.FuelTank()
    model = fuelTank.FuelTankModelConstantVolume()
    tank.setTankModel(model)
    model.propMassInit = TH_PROP
    model.r_TcT_TInit = [[0.0], [0.0], [0.0]]
    model.radiusTankInit = TH_TANK_R
    tank.setR_TB_B([[0.0], [0.0], [0.0]])
    tank.addThrusterSet(the)
    sc.addStateEffector(tank)
    fuel = tank.fuelTankOutMsg.recorder()
    cmd = messaging.THRArrayOnTimeCmdMsgPayload()
    cmd.OnTimeRequest = [0.0]
    msg = messaging.THRArrayOnTimeCmdMsg().write(cmd)
    the.cmdsInMsg.subscribeTo(msg)
    sim.AddModelToTask("task", tank)
    sim.AddModelToTask("task", the)
    sim.AddModelToTask("task", sc)
    sc.hub.mHub = TH_HUB_M
    sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    sc.hub.IHubPntBc_B = TH_HUB_I.tolist()
    sc.hub.omega_BN_BInit = [[0.0], [0.0], [0.0]]
    sc.hub.sigma_BNInit = [[0.0], [0.0], [0.0]]
    sc.hub.r_CN_NInit = [[0.0], [0.0], [0.0]]
    sc.hub.v_CN_NInit = [[0.0], [0.0], [0.0]]
    log = sc.scStateOutMsg.recorder()
    thr = the.thrusterOutMsgs[0].recorder()
    for r in (log, fuel, thr):
        sim.AddModelToTask("task", r)
    sim.InitializeSimulation()
    for start, dur in TH_FIRINGS:
        sim.ConfigureStopTime(macros.sec2nano(start))
        sim.ExecuteSimulation()
        cmd.OnTimeRequest = [float(dur)]
        msg.write(cmd, macros.sec2nano(start))
    sim.ConfigureStopTime(macros.sec2nano(t_final))
    sim.ExecuteSimulation()
    t = log.times() * 1e-9
    return (
        t,
        np.array(log.r_BN_N),
        np.array(log.sigma_BN),
        np.array(log.omega_BN_B),
        np.array(fuel.fuelMass),
        thr.times() * 1e-9,
        np.array(thr.thrustForce),
    )
