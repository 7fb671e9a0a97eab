"""What a post-capture run with thrusters, propellant tanks and sensors adds to the identification (issue 17):
the base's true parameters over time (they drift as propellant leaves), the propellant used, and the balance
checks of the run -- the base's mass change against the propellant that left through the nozzles, and the
momentum change against the integrated thrust plus the momentum the propellant carried away.

The balances are formed from the engine's records (the thruster wrench and flow of `_core.postcapture_thruster_wrench`,
the propellant and base parameters the stepper integrated, the momentum it recorded), integrated by Simpson's
rule at the step rate; they are independent of the stepper's own accounting, so a wrong depletion or thrust in
the engine shows up as a residual.
"""

from __future__ import annotations

import numpy as np

from .. import algorithms as alg
from ..algorithms import quat_to_matrix
from . import equations as eq
from .estimators import _physical
from .scenario import Scenario
from .simulation import simpson_cumulative, thruster_wrench


def truth_history(model, sim: dict, planar: bool, target: int) -> tuple[np.ndarray, np.ndarray] | None:
    """(t (T,), parameters (T, P)) the true values over time in `parameter_names` order: the base's from the
    recorded `base_parameters` (propellant depletion), the target's constant. None when nothing depletes."""
    bp = np.asarray(sim.get("base_parameters", np.zeros((0, 0))), float)
    if bp.size == 0:
        return None
    m1, b1, I1 = eq.from_standard(bp)
    mn, bn, In = eq.body_truth(model, target)
    n = len(bp)
    return np.asarray(sim["t"], float), _physical(
        planar, m1, b1, I1, np.full(n, mn), np.tile(bn, (n, 1)), np.tile(In, (n, 1, 1))
    )


def balances(model, sim: dict, sc: Scenario) -> dict:
    """Propellant used and the balance checks at the end of the run (see the module's docstring)."""
    t = np.asarray(sim["t"], float)
    mp = np.asarray(sim.get("propellant", np.zeros((len(t), 0))), float)
    out: dict = {}
    if mp.shape[1] == 0 or len(t) < 3:
        return out
    wrench, flow = thruster_wrench(model, sim, sc)
    n = len(t) - 1 if (len(t) - 1) % 2 == 0 else len(t) - 2  # Simpson needs an even number of steps
    end = np.array([n])
    h = sc.dt
    tanks = sc.actuators.get("tanks", [])
    used = mp[0] - mp[n]
    left_nozzles = -simpson_cumulative(flow[: n + 1], h, end)[0]
    bp = np.asarray(sim["base_parameters"], float)
    out["propellant"] = {
        "tanks": [tk.get("name", f"tank{k}") for k, tk in enumerate(tanks)],
        "initial_kg": mp[0].tolist(),
        "final_kg": mp[n].tolist(),
        "used_kg": used.tolist(),
        "t_end": float(t[n]),
    }
    dm_base = float(bp[n, 0] - bp[0, 0])
    out["mass_balance"] = {
        "what": "base mass change + propellant that left through the nozzles (−∫ Σ F/(Isp g0) dt, Simpson) = 0",
        "base_mass_change_kg": dm_base,
        "propellant_through_nozzles_kg": float(left_nozzles.sum()),
        "residual_kg": float(dm_base + left_nozzles.sum()),
    }
    # momentum: d[p; L]/dt = [F; x_F × F + M] + Σ_k ṁ_k [v_k; x_k × v_k + (2/5) r_k² ω]
    # (mass leaves with the velocity of its tank's material: its linear and angular momentum per kg)
    q, v = np.asarray(sim["q"], float), np.asarray(sim["v"], float)
    fk = np.asarray(alg.forward_kinematics(model, q))[:, 0]
    A, rb = quat_to_matrix(fk[:, 3:]), fk[:, :3]
    planar = model.joint_types[0] == "planar"
    if planar:
        return out  # the planar base's momentum rows differ; the 3D balance is the check
    F = eq.mv(A, wrench[:, :3])
    M = eq.mv(A, wrench[:, 3:]) + np.cross(rb, F)
    tau_b = np.asarray(sim["tau"], float)[:, :6]  # the paper's thrust law (eq. 40), if on
    F += eq.mv(A, tau_b[:, :3])
    M += eq.mv(A, tau_b[:, 3:]) + np.cross(rb, eq.mv(A, tau_b[:, :3]))
    w_i = eq.mv(A, v[:, 3:6])
    carried = np.zeros((len(t), 6))
    for k, tk in enumerate(tanks):
        p = np.asarray(tk.get("position", [0, 0, 0]), float)
        x = rb + eq.mv(A, np.broadcast_to(p, rb.shape))
        vel = eq.mv(A, v[:, 0:3] + np.cross(v[:, 3:6], p))
        rad = float(tk.get("radius", 0.0))
        carried[:, :3] += flow[:, k : k + 1] * vel
        carried[:, 3:] += flow[:, k : k + 1] * (np.cross(x, vel) + 0.4 * rad**2 * w_i)
    impulse = simpson_cumulative(np.concatenate([F, M], 1)[: n + 1], h, end)[0]
    away = simpson_cumulative(carried[: n + 1], h, end)[0]
    mom = np.asarray(sim["momentum"], float)
    dP = mom[n] - mom[0]
    resid = dP - impulse - away
    out["momentum_balance"] = {
        "what": "Δ[p; L] (recorded) = ∫[F; M] dt (thrust, Simpson) + ∫ ṁ [v; x × v + 0.4 r² ω] dt (carried away by "
        "the propellant); L about the inertial origin",
        "momentum_change": dP.tolist(),
        "integrated_thrust": impulse.tolist(),
        "carried_away_by_propellant": away.tolist(),
        "residual": resid.tolist(),
        "relative_residual": float(np.linalg.norm(resid) / max(np.linalg.norm(impulse), 1e-300)),
        "environment_on": sc.environment is not None,
    }
    return out


def tracking(res, sc: Scenario) -> dict:
    """How well each estimator follows the drifting base parameters: the final error against the final truth,
    the RMS relative error over the second half of the run, and what a forgetting factor λ predicts for the lag
    (an exponentially weighted least-squares fit of a constant to a parameter drifting at rate r lags by about
    r·T_mem, T_mem = sample_period/(1 − λ); with λ = 1 the estimate averages the whole run and lags by ~r·t/2)."""
    if res.truth_history is None:
        return {}
    th_t, th = res.truth_history
    lam = sc.forgetting
    t_mem = sc.sample_period / (1.0 - lam) if lam < 1 else None
    span = float(th_t[-1] - th_t[0])
    rate = (th[-1] - th[0]) / span if span > 0 else np.zeros(th.shape[1])
    out = {
        "forgetting": lam,
        "memory_s": t_mem,
        "drift_rate_per_s": {n: float(rate[j]) for j, n in enumerate(res.names) if _is_base(n)},
        "estimators": {},
    }
    base_cols = [j for j, n in enumerate(res.names) if _is_base(n)]
    for (method, solver), (t, h) in res.histories.items():
        tr = np.stack([np.interp(t, th_t, th[:, j]) for j in range(th.shape[1])], -1)
        half = t >= t[0] + 0.5 * (t[-1] - t[0])
        rel = np.abs(h - tr) / np.where(np.abs(tr) > 0, np.abs(tr), 1.0)
        rms = np.sqrt(np.mean(rel[half] ** 2, 0))
        lag_pred = {}
        for j in base_cols:
            n = res.names[j]
            if tr[-1, j] != 0 and rate[j] != 0:
                lag = abs(rate[j]) * (t_mem if t_mem is not None else 0.5 * (t[-1] - t[0]))
                lag_pred[n] = float(lag / abs(tr[-1, j]))
        out["estimators"][f"{method}/{solver}"] = {
            "rms_relative_error_second_half": {res.names[j]: float(rms[j]) for j in base_cols},
            "final_relative_error": {res.names[j]: float(rel[-1, j]) for j in base_cols},
            "predicted_lag_relative_error": lag_pred,
        }
    return out


def _is_base(name: str) -> bool:
    return len(name) > 1 and name[1] == "1"  # m1, b1x, I1xx, ... (the target's are mn, bnx, Inxx)
