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
    )


def measure(model, sim: dict, sc: Scenario, rng: np.random.Generator | None = None) -> eq.Measurements:
    """Samples every `sample_period`: state, exact accelerations, thruster wrench, and the impulses
    ∫F and ∫(M + x_F × F) integrated from the step-rate thrust by Simpson's rule. With `sc.noise`
    (and rng) white noise is added: `velocity` to v, `acceleration` to ddq at the samples, `force`
    (N, and N·m) to the thrust at the step rate before integration."""
    planar = model.joint_types[0] == "planar"
    nb = 3 if planar else 6
    step = int(round(sc.sample_period / sc.dt))
    if step % 2:
        raise InputError("sample_period / dt must be even (Simpson's rule between samples)")
    t, q, v, ddq = sim["t"], sim["q"], sim["v"].copy(), sim["ddq"].copy()
    wrench = sim["tau"][:, :nb].copy()
    noise = sc.noise or {}
    if noise and rng is not None:
        wrench += rng.normal(0.0, float(noise.get("force", 0.0)), wrench.shape)
    fk = np.asarray(alg.forward_kinematics(model, q))[:, 0]
    A, rb = quat_to_matrix(fk[:, 3:]), fk[:, :3]
    if planar:
        z = np.zeros(len(t))
        fb, tb = np.stack([wrench[:, 0], wrench[:, 1], z], -1), np.stack([z, z, wrench[:, 2]], -1)
    else:
        fb, tb = wrench[:, :3], wrench[:, 3:]
    F = eq.mv(A, fb)
    M = eq.mv(A, tb) + np.cross(rb, F)  # tb holds M + r'_jet × f about the sensor; add r_b × F
    idx = np.arange(0, len(t), step)
    h = sc.dt

    def simpson(f):
        pair = h / 3.0 * (f[:-2:2] + 4 * f[1:-1:2] + f[2::2])
        cum = np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(pair, 0)])
        return cum[idx // 2]

    def trapezoid(f):
        # only the sampled thrust (the alternative when the 1 kHz thrust is not recorded):
        # trapezoid between the 10 Hz samples
        fs = f[idx]
        return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(0.5 * (fs[1:] + fs[:-1]) * sc.sample_period, 0)])

    mode = sc.measurement
    vs, as_ = v[idx], ddq[idx]
    if noise and rng is not None:
        vs = vs + rng.normal(0.0, float(noise.get("velocity", 0.0)), vs.shape)
        as_ = as_ + rng.normal(0.0, float(noise.get("acceleration", 0.0)), as_.shape)
    keep = slice(None)
    if mode.get("accelerations", "exact") == "central_difference":
        # v̇ from the sampled (possibly noisy) velocities by central differences. The base's v holds body-frame
        # components and ddq their time derivative, but differencing rotating-frame components over a whole
        # sample period (0.1 s of a tumbling base) drops the ω×v term the frame's rotation adds. So the base
        # velocities are differenced in the INERTIAL frame, where the derivative is the plain acceleration,
        # and brought back: with v_b = Aᵀ v_I,  d(v_b)/dt = Aᵀ a_I − ω_b × v_b  and  d(ω_b)/dt = Aᵀ d(ω_I)/dt.
        # Joint rates are differenced as they are. The first and last samples have no central difference and
        # are dropped (an online estimator runs one sample behind).
        as_ = np.gradient(vs, sc.sample_period, axis=0)
        if not planar:
            As = A[idx]
            lin_i, ang_i = eq.mv(As, vs[:, 0:3]), eq.mv(As, vs[:, 3:6])
            a_lin = np.gradient(lin_i, sc.sample_period, axis=0)
            a_ang = np.gradient(ang_i, sc.sample_period, axis=0)
            At = np.swapaxes(As, -1, -2)
            as_[:, 0:3] = eq.mv(At, a_lin) - np.cross(vs[:, 3:6], vs[:, 0:3])
            as_[:, 3:6] = eq.mv(At, a_ang)
        else:  # planar: (vx, vy) body-frame in the plane, yaw rate r: d(v_b)/dt = R(ψ)ᵀ a_I − r × v_b
            psi = q[idx][:, 2]
            c, s_ = np.cos(psi), np.sin(psi)
            vi = np.stack([c * vs[:, 0] - s_ * vs[:, 1], s_ * vs[:, 0] + c * vs[:, 1]], -1)
            ai = np.gradient(vi, sc.sample_period, axis=0)
            r = vs[:, 2]
            as_[:, 0] = c * ai[:, 0] + s_ * ai[:, 1] + r * vs[:, 1]
            as_[:, 1] = -s_ * ai[:, 0] + c * ai[:, 1] - r * vs[:, 0]
        keep = slice(1, -1)
    elif mode.get("accelerations", "exact") != "exact":
        raise InputError(
            f"measurement.accelerations: expected 'exact' or 'central_difference', got {mode['accelerations']!r}"
        )
    integ = {"simpson": simpson, "trapezoid": trapezoid}.get(mode.get("impulses", "simpson"))
    if integ is None:
        raise InputError(f"measurement.impulses: expected 'simpson' or 'trapezoid', got {mode['impulses']!r}")
    return eq.Measurements(
        t[idx][keep], q[idx][keep], vs[keep], as_[keep], wrench[idx][keep], integ(F)[keep], integ(M)[keep]
    )
