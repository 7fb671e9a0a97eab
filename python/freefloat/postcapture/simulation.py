"""Post-capture motion (Zhang, Yue, Yuan 2020, eqs. 39-40) simulated by the engine, and the measurements the
estimators see: samples of the state, accelerations, thrust and thrust impulses, optionally with noise."""

from __future__ import annotations

import numpy as np

from .. import _core, models
from .. import algorithms as alg
from .._core import InputError
from ..algorithms import quat_to_matrix
from ..simulation import memory_limit
from . import equations as eq
from .scenario import Scenario


def simulate(sc: Scenario, model=None) -> dict:
    """RK4 at sc.dt with the paper's controllers (eqs. 39-40), every step recorded."""
    m = model or models.load(sc.model)
    c, e = sc.control, sc.excitation
    return _core.postcapture_simulate(
        m._core,
        np.asarray(sc.q0, float),
        np.asarray(sc.v0, float),
        sc.duration,
        sc.dt,
        float(c["F_max"]),
        float(c["K_F"]),
        float(c["M_max"]),
        float(c["K_M"]),
        list(np.atleast_1d(np.asarray(c["K_D"], float))),
        list(np.atleast_1d(np.asarray(c["K_P"], float))),
        list(map(float, c.get("jet", [0, 0, 0]))),
        e["damping"],
        e["amp"],
        e["freq"],
        e["phase"],
        1,
        max_memory=memory_limit(),  # refused before any work, not an abort or a swapping machine
        actuators=sc.actuators,
        environment=sc.environment,
    )


def thruster_wrench(model, sim: dict, sc: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """The thrusters' base wrench (T, 6) [f; τ] (base frame, about the base origin) and each tank's propellant
    flow (T, tanks) [kg/s] at every recorded step, from the engine's thruster model (zeros without thrusters)."""
    t = sim["t"]
    if not sc.actuators or not sc.actuators.get("thrusters"):
        return np.zeros((len(t), 6)), np.zeros((len(t), 0))
    return _core.postcapture_thruster_wrench(model._core, sc.actuators, t, np.asarray(sim["propellant"], float))


def simpson_cumulative(f: np.ndarray, h: float, idx: np.ndarray) -> np.ndarray:
    """∫₀^{t_idx} f dt by Simpson's rule on the step-rate samples f (T, ...) of spacing h, at the (even) sample
    indices idx."""
    pair = h / 3.0 * (f[:-2:2] + 4 * f[1:-1:2] + f[2::2])
    cum = np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(pair, 0)])
    return cum[idx // 2]


def _telemetry_at_samples(model, sim: dict, sc: Scenario, idx: np.ndarray):
    """(q, v) at the sample instants t[idx] from the telemetry of the scenario's sensors (`freefloat measure` on
    the recorded run), and the sensors' summary. A sample instant the telemetry does not hold (its rate is not a
    multiple of 1/sample_period, or a latency delays the first frame past it) is an error naming the key."""
    from .. import sensors as sn

    run = {"t": sim["t"], "q": sim["q"], "v": sim["v"], "ddq": sim["ddq"], "momentum": sim["momentum"]}
    meas = sn.measure(model, run, sc.sensors, seed=sc.sensor_seed)
    tel = meas.require_telemetry()
    ts = sim["t"][idx]
    k = np.searchsorted(tel.t, ts - 1e-9 * sc.dt)
    ok = (k < len(tel.t)) & (np.abs(tel.t[np.minimum(k, len(tel.t) - 1)] - ts) <= 1e-6 * sc.dt)
    first = int(np.argmax(ok)) if ok.any() else len(ts)
    if not ok[first:].all() or first >= len(ts) - 2:
        raise InputError(
            f"{sc.source}: key 'sensors': the telemetry ({len(tel.t)} frames from t = {tel.t[0]:g} s) does not hold "
            f"every sample instant (every sample_period = {sc.sample_period:g} s): give the sensors feeding the "
            "velocities a rate that is a multiple of 1/sample_period (or set telemetry.rate to it)"
        )
    return first, k[first:], np.asarray(tel.t, float), np.asarray(tel.q, float), np.asarray(tel.v, float)


#: Savitzky-Golay defaults: a cubic over 21 samples (0.2 s of 100 Hz telemetry): see `_derivative`
SAVGOL_WINDOW = 21
SAVGOL_POLYORDER = 3


def _derivative(mode: dict, n: int, where: str):
    """d/dt along axis 0 of evenly spaced samples, as `mode` (the scenario's `measurement:`) asks:

    - `central_difference`: `np.gradient` (second-order central differences; one-sided at the ends). White noise σ
      on the rates becomes σ/(√2 h) on the accelerations: at h = 10 ms, 70 times σ.
    - `savgol`: the first derivative of a least-squares polynomial of degree `savgol_polyorder` fitted to
      `savgol_window` consecutive samples around each one (Savitzky & Golay 1964; scipy.signal.savgol_filter,
      deriv=1; at the ends the polynomial fitted to the first or last window). The window trades noise for lag
      and bandwidth: the derivative's white noise falls as window^(-3/2) (for a degree 1 or 2 fit it is
      σ √12 / (h w^(3/2)) for large w, against σ/(√2 h) for central differences: 20 times less at w = 21; a
      degree 3 or 4 fit has 2.5 times more than that), but the fit is centred, so an online estimator can use a
      sample only (w − 1)/2 samples later (its lag: 0.1 s for 21 samples at 100 Hz), and motion faster than
      about (polyorder + 1)/(3.2 w − 4.6) cycles per sample (Schafer 2011) is attenuated, which biases the
      accelerations of fast joints.
    - `rts`: the Rauch-Tung-Striebel smoother of the white-jerk rate model (state: rate and its derivative; the
      rate measured with white noise), each column with its own ratio of jerk to rate noise chosen by
      generalised cross-validation (the engine's `sensors::smooth_rates`; equal to the cubic smoothing spline of
      the rates with that ratio as its penalty). No window to choose: the bandwidth follows the noise the record
      shows. It is a whole-record (two-pass) smoother; online it would run as a fixed-lag smoother."""
    kind = mode.get("accelerations", "exact")
    if kind == "central_difference":
        return lambda x, h: np.gradient(x, h, axis=0)
    if kind == "rts":
        from ..sensors import smooth_rates

        return lambda x, h: smooth_rates(x, h)["accel"]
    w = int(mode.get("savgol_window", SAVGOL_WINDOW))
    p = int(mode.get("savgol_polyorder", SAVGOL_POLYORDER))
    if w < 3 or w % 2 == 0:
        raise InputError(f"measurement.savgol_window: must be an odd number of samples >= 3, got {w}")
    if not 1 <= p < w:
        raise InputError(
            f"measurement.savgol_polyorder: must be at least 1 (a derivative) and below savgol_window = {w}, got {p}"
        )
    if w > n:
        raise InputError(
            f"measurement.savgol_window: {w} samples is longer than the {n} samples of the {where}; shorten it"
        )
    from scipy.signal import savgol_filter

    return lambda x, h: savgol_filter(x, w, p, deriv=1, delta=h, axis=0, mode="interp")


def _central_difference(
    model, planar: bool, qs: np.ndarray, vs: np.ndarray, h: float, d=lambda x, h: np.gradient(x, h, axis=0)
) -> np.ndarray:
    """v̇ at evenly spaced samples (spacing h) of the (measured) q and v by the derivative `d` (central
    differences by default; `_derivative` gives the Savitzky-Golay one).
    The base's v holds body-frame components and ddq their time derivative, but differencing rotating-frame
    components over a whole sample period (0.1 s of a tumbling base) drops the ω×v term the frame's rotation
    adds. So the base velocities are differenced in the INERTIAL frame, where the derivative is the plain
    acceleration, and brought back: with v_b = Aᵀ v_I,  d(v_b)/dt = Aᵀ a_I − ω_b × v_b  and
    d(ω_b)/dt = Aᵀ d(ω_I)/dt. Joint rates are differenced as they are."""
    as_ = d(vs, h)
    if not planar:
        As = quat_to_matrix(np.asarray(alg.forward_kinematics(model, qs))[:, 0, 3:])  # measured attitude
        lin_i, ang_i = eq.mv(As, vs[:, 0:3]), eq.mv(As, vs[:, 3:6])
        a_lin = d(lin_i, h)
        a_ang = d(ang_i, h)
        At = np.swapaxes(As, -1, -2)
        as_[:, 0:3] = eq.mv(At, a_lin) - np.cross(vs[:, 3:6], vs[:, 0:3])
        as_[:, 3:6] = eq.mv(At, a_ang)
    else:  # planar: (vx, vy) body-frame in the plane, yaw rate r: d(v_b)/dt = R(ψ)ᵀ a_I − r × v_b
        psi = qs[:, 2]
        c, s_ = np.cos(psi), np.sin(psi)
        vi = np.stack([c * vs[:, 0] - s_ * vs[:, 1], s_ * vs[:, 0] + c * vs[:, 1]], -1)
        ai = d(vi, h)
        r = vs[:, 2]
        as_[:, 0] = c * ai[:, 0] + s_ * ai[:, 1] + r * vs[:, 1]
        as_[:, 1] = -s_ * ai[:, 0] + c * ai[:, 1] - r * vs[:, 0]
    return as_


def measure(model, sim: dict, sc: Scenario, rng: np.random.Generator | None = None) -> eq.Measurements:
    """Samples every `sample_period`: state, exact accelerations, thruster wrench, and the impulses
    ∫F and ∫M_B about the base point with the transport term ∫ v_B × P (measurement.momentum_point: base, the
    default), or ∫(M + x_F × F) about the inertial origin (momentum_point: origin, the paper's eqs. 9-10),
    integrated from the step-rate thrust by Simpson's rule. With `sc.noise`
    (and rng) white noise is added: `velocity` to v, `acceleration` to ddq at the samples, `force`
    (N, and N·m) to the thrust at the step rate before integration."""
    planar = model.joint_types[0] == "planar"
    nb = 3 if planar else 6
    step = int(round(sc.sample_period / sc.dt))
    if step % 2:
        raise InputError("sample_period / dt must be even (Simpson's rule between samples)")
    t, q, v, ddq = sim["t"], sim["q"], sim["v"].copy(), sim["ddq"].copy()
    wrench = sim["tau"][:, :nb].copy()
    thrust, _flow = thruster_wrench(model, sim, sc)
    wrench += thrust[:, [0, 1, 5]] if planar else thrust
    noise = sc.noise or {}
    if noise and rng is not None:
        wrench += rng.normal(0.0, float(noise.get("force", 0.0)), wrench.shape)
    # the attitude at the step rate for the inertial thrust: the true one (a flight computer's attitude
    # estimate between telemetry frames is not modelled)
    fk = np.asarray(alg.forward_kinematics(model, q))[:, 0]
    A, rb = quat_to_matrix(fk[:, 3:]), fk[:, :3]
    if planar:
        z = np.zeros(len(t))
        fb, tb = np.stack([wrench[:, 0], wrench[:, 1], z], -1), np.stack([z, z, wrench[:, 2]], -1)
    else:
        fb, tb = wrench[:, :3], wrench[:, 3:]
    F = eq.mv(A, fb)
    point = sc.measurement.get("momentum_point", "base")
    if point not in ("base", "origin"):
        raise InputError(f"measurement.momentum_point: expected 'base' or 'origin', got {point!r}")
    # tb holds M + r'_jet × f about the sensor (the base point B); about the inertial origin add r_b × F
    M = eq.mv(A, tb) if point == "base" else eq.mv(A, tb) + np.cross(rb, F)
    idx = np.arange(0, len(t), step)
    h = sc.dt

    def simpson(f):
        return simpson_cumulative(f, h, idx)

    def trapezoid(f):
        # only the sampled thrust (the alternative when the 1 kHz thrust is not recorded):
        # trapezoid between the 10 Hz samples
        fs = f[idx]
        return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(0.5 * (fs[1:] + fs[:-1]) * sc.sample_period, 0)])

    qs, tel = q[idx], None
    dense = (t, q, v, idx)  # the record between the samples (for the base point's transport term)
    if sc.sensors is not None and noise:
        raise InputError(
            f"{sc.source}: key 'noise': the scenario has sensors, whose errors are the measurement noise; give "
            "either sensors or noise (or run with --no-noise)"
        )
    if sc.sensors is not None:
        # the measured telemetry replaces the true samples of q and v (from the first complete frame on)
        first, rows, tel_t, tel_q, tel_v = _telemetry_at_samples(model, sim, sc, idx)
        idx = idx[first:]
        qs = tel_q[rows]
        v = v.copy()
        v[idx] = tel_v[rows]
        tel = (rows, tel_q, tel_v, float(tel_t[1] - tel_t[0]))
        dense = (tel_t, tel_q, tel_v, rows)
    mode = sc.measurement
    vs, as_ = v[idx], ddq[idx]
    if noise and rng is not None:
        vs = vs + rng.normal(0.0, float(noise.get("velocity", 0.0)), vs.shape)
        as_ = as_ + rng.normal(0.0, float(noise.get("acceleration", 0.0)), as_.shape)
    keep = slice(None)
    if mode.get("accelerations", "exact") in ("central_difference", "savgol", "rts"):
        # v̇ from the sampled (possibly noisy) velocities by central differences, a Savitzky-Golay derivative or
        # the RTS smoother (_derivative). The first and last samples are dropped (an online estimator runs one
        # sample behind with central differences; (savgol_window - 1)/2 telemetry samples behind with
        # Savitzky-Golay; a few of the smoother's bandwidths behind with a fixed-lag RTS smoother).
        if tel is None:
            d = _derivative(mode, len(vs), "samples (one every sample_period)")
            as_ = _central_difference(model, planar, qs, vs, sc.sample_period, d)
        else:
            # at the telemetry's own rate (the arm's joints move fast: differences over a whole sample period
            # would not follow them), then read at the sample instants
            d = _derivative(mode, len(tel[2]), "telemetry")
            as_ = _central_difference(model, planar, tel[1], tel[2], tel[3], d)[tel[0]]
        keep = slice(1, -1)
    elif mode.get("accelerations", "exact") != "exact":
        raise InputError(
            "measurement.accelerations: expected 'exact', 'central_difference', 'savgol' or 'rts', got "
            f"{mode['accelerations']!r}"
        )
    elif "savgol_window" in mode or "savgol_polyorder" in mode:
        raise InputError("measurement.savgol_window: applies to accelerations: savgol only")
    integ = {"simpson": simpson, "trapezoid": trapezoid}.get(mode.get("impulses", "simpson"))
    if integ is None:
        raise InputError(f"measurement.impulses: expected 'simpson' or 'trapezoid', got {mode['impulses']!r}")
    # about the base point: the transport term ∫ v_B × P dτ on the dense record (the telemetry frames with
    # sensors, else the simulator's steps)
    if point == "base" and noise and rng is not None and float(noise.get("velocity", 0.0)) > 0:
        # the `noise` block's velocity noise on the steps too, at the samples' noise density (σ per sample every
        # sample_period is σ √(sample_period/dt) per step), drawn after the samples' noise (whose streams stay
        # as they were); at the sample instants the record holds the noisy samples themselves
        dt_, q_, v_, at_ = dense
        vd = v_ + rng.normal(0.0, float(noise["velocity"]) * np.sqrt(sc.sample_period / sc.dt), v_.shape)
        vd[at_] = vs
        dense = (dt_, q_, vd, at_)
    transport = eq.momentum_transport(model, *dense) if point == "base" else None
    return eq.Measurements(
        t[idx][keep],
        qs[keep],
        vs[keep],
        as_[keep],
        wrench[idx][keep],
        integ(F)[keep],
        integ(M)[keep],
        None if transport is None else transport[keep],
    )
