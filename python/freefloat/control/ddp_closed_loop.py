"""Closed-loop DDP (Valverde 2018, ch. 8, taken past the thesis' open-loop plots): the optimised policy
`u_k = ū_k + L_k (x ⊖ x̄_k)` (feed-forward plus Riccati gains on the tangent-space state error) or a receding-horizon
DDP (MPC, warm-started by the previous window shifted in time) drives freefloat's simulator (`simulate`, RK4 on the
configuration group, the true continuous dynamics) of a plant that differs from the model the controller was
optimised on (a mass error of one body, and the controller's own semi-implicit Euler discretisation). The policy,
the window solves and the warm starts are the engine's (`DdpPolicy`, `DdpMpc`); this module wires them to the
simulator and measures the end-effector errors."""

from __future__ import annotations

import time

import numpy as np

from .. import _core
from .._core import InputError
from ..model import Model
from .ddp import Problem, pose_errors

MODES = ("open_loop", "policy", "mpc")


def perturbed_model(model: Model, mass_error: float, body: str | None = None) -> Model:
    """The plant: `model` with the mass of `body` (default: the last body) scaled by 1 + mass_error and its inertia
    with it (first and second moments scaled alike, so the centre of mass and the shape stay: a heavier copy of the
    same body, e.g. an unmodelled grasped load)."""
    if not np.isfinite(mass_error) or mass_error <= -1.0:
        raise InputError(f"argument `mass_error`: must be a finite number > -1 (relative), got {mass_error!r}")
    names = list(model.body_names)
    if body is None:
        i = len(names) - 1
    elif body in names:
        i = names.index(body)
    else:
        raise InputError(f"argument `body`: no body {body!r} in {model.name} (bodies: {', '.join(names)})")
    p = np.array(model.parameters(), dtype=float)
    p[i] *= 1.0 + mass_error
    return model.with_parameters(p)


def run(
    problem: Problem,
    mode: str,
    plant: Model | None = None,
    *,
    solution: dict | None = None,
    substeps: int = 5,
    mpc_horizon: int = 100,
    replan: int = 5,
    mpc_options: dict | None = None,
    first_max_iter: int = 50,
    shrink: bool = False,
    progress=None,
    observer=None,
    observe_every: int | None = None,
) -> dict:
    """Simulate `plant` (default: the problem's own model) for the problem's N·dt seconds from its x0 under a
    controller sampled every dt (zero-order hold), RK4 at dt/substeps:

    - `open_loop`: the feed-forward ū_k of `solution` (what the thesis plots: the optimiser's own prediction);
    - `policy`: ū_k + L_k (x ⊖ x̄_k) with the gains of `solution` (solve with `refresh_gains=True` so they belong
      to the returned iterate);
    - `mpc`: `DdpMpc` re-solving a window of `mpc_horizon` nodes every `replan` nodes (warm start: the previous
      window shifted; the first window from `solution` if given, else zero controls), `mpc_options` per re-plan
      (default: feasibility-driven, backtracking line search, 5 iterations), `first_max_iter` for the first;
      `shrink`: no window reaches past the task's end (its terminal cost is the task's deadline).

    `progress(k, n)` is called at each control sample and may return False to stop (Ctrl-C stops too); a stopped
    run returns the samples so far with `stopped=True`.

    `observer` (MPC only) follows the plant as an estimator does: the run is simulated in segments of
    `observe_every` nodes (the same RK4 steps and zero-order hold as in one piece), and after each one
    `observer(k, seg)` gets the node reached and the segment's record at every RK4 step (`t`, `q`, `v`, and `u`,
    the control held over each step). If it returns parameters P (nbodies, 10) of the problem's model, the
    controller re-plans on them from its next re-plan on (`DdpMpc.set_parameters`); None keeps the model.

    Returns a dict: mode, t (T,), xs (T, nx), us (T-1, nu), the end-effector pose errors and their summary, and
    for MPC the controller's statistics."""
    if mode not in MODES:
        raise InputError(f"argument `mode`: expected one of {', '.join(MODES)}, got {mode!r}")
    if mode in ("open_loop", "policy") and solution is None:
        raise InputError(f"argument `solution`: mode {mode!r} needs a DDP solution (from `ddp.solve`)")
    if not isinstance(substeps, int) or substeps < 1:
        raise InputError(f"argument `substeps`: must be an integer >= 1, got {substeps!r}")
    if observer is not None and (mode != "mpc" or not isinstance(observe_every, int) or observe_every < 1):
        raise InputError("argument `observer`: needs mode 'mpc' and `observe_every` an integer >= 1 (nodes)")
    from ..simulation import simulate

    m = problem.model
    plant = plant or m
    if plant.nq != m.nq or plant.nv != m.nv:
        raise InputError("argument `plant`: its sizes (nq, nv) differ from the problem's model")
    n, dt, nq = problem.horizon, problem.dt, m.nq
    # A rate-driven tail (the thesis' massless wrist): the simulator integrates the leading bodies' dynamics, and the
    # tail's angles follow the held rate controls exactly, q_w(t_k+1) = q_w(t_k) + dt u_w,k.
    nr = len(problem.rate_joints)
    if nr and observer is not None:
        raise InputError("argument `observer`: not available with rate-driven joints (problem.rate_joints)")
    sim_plant = plant.leading_bodies(len(plant.body_names) - nr) if nr else plant
    nqd, nvd = sim_plant.nq, sim_plant.nv
    wq = np.zeros((n + 1, nr))
    wv = np.zeros((n + 1, nr))
    if nr:
        wq[0], wv[0] = problem.x0[nqd:nq], problem.x0[nq + nvd :]
    if mode == "mpc":
        opts = {"variant": "fddp", "max_iter": 5, "alphas": [0.5**k for k in range(10)], "reg_init": 1e-6}
        opts.update(mpc_options or {})
        guess = {}
        if solution is not None:
            guess = {"guess_xs": np.asarray(solution["xs"], float), "guess_us": np.asarray(solution["us"], float)}
        ctrl = _core.DdpMpc(
            m._core,
            problem.dt,
            n,
            problem.running,
            problem.terminal,
            int(mpc_horizon),
            int(replan),
            keep_out=problem.keep_out,
            options=opts,
            first_max_iter=int(first_max_iter),
            shrink=bool(shrink),
            rate_joints=problem.rate_joints or None,
            **guess,
        )

        def law(k, x):
            return ctrl.control(k, x)
    else:
        pol = _core.DdpPolicy(
            m._core,
            np.asarray(solution["xs"], float),
            np.asarray(solution["us"], float),
            np.asarray(solution["gains"], float),
        )
        feedback = mode == "policy"

        def law(k, x):
            return pol.control(k, x, feedback)

    applied = np.zeros((n, m.nv))
    stopped = [False]

    def controller(t, q, v):
        k = int(round(t / dt))
        if k >= n or stopped[0]:
            return np.zeros(nvd)
        if progress is not None and progress(k, n) is False:
            stopped[0] = True
            return np.zeros(nvd)
        u = law(k, np.r_[q, wq[k], v, wv[k]])
        applied[k] = u
        if nr:
            wq[k + 1] = wq[k] + dt * u[nvd:]
            wv[k + 1] = u[nvd:]
        return u[:nvd]

    x0 = np.asarray(problem.x0, float)
    t0 = time.perf_counter()
    if observer is None:
        tr = simulate(
            sim_plant,
            x0[:nqd],
            x0[nq : nq + nvd],
            n * dt,
            dt / substeps,
            method="rk4",
            record_every=substeps,
            controller=controller,
            controller_period=dt,
        )
        tq, tv, t = np.asarray(tr.q), np.asarray(tr.v), np.asarray(tr.t)
    else:
        tq, tv, t = _observed(plant, x0, n, dt, substeps, controller, applied, stopped, observer, observe_every, ctrl)
    wall = time.perf_counter() - t0
    kk = np.clip(np.rint(t / dt).astype(int), 0, n)
    if nr:
        tq, tv = np.c_[tq, wq[kk]], np.c_[tv, wv[kk]]
    xs = np.c_[tq, tv]
    g = _core.ddp_frame_dual_quats(m._core, np.ascontiguousarray(tq), problem.frame)
    err = pose_errors(g, problem.reference_dq[kk])
    out = {
        "mode": mode,
        "t": t,
        "xs": xs,
        "us": applied,
        "ee_dq": g,
        "position_error": np.linalg.norm(err["position"], axis=1),
        "angle_error_deg": np.degrees(err["angle"]),
        "wall_time_s": wall,
        "stopped": stopped[0],
    }
    if mode == "mpc":
        out["mpc"] = dict(ctrl.stats())
    return out


def _observed(plant, x0, n, dt, substeps, controller, applied, stopped, observer, every, ctrl):
    """The closed loop in segments of `every` nodes, each recorded at every RK4 step and shown to `observer`
    (see `run`); returns the records at the control samples (t, q, v), as one simulation would."""
    from ..simulation import simulate

    nq = plant.nq
    q, v = x0[:nq].copy(), x0[nq:].copy()
    ts, qs, vs = [np.zeros(1)], [q[None]], [v[None]]
    k0 = 0
    while k0 < n and not stopped[0]:
        k1 = min(k0 + every, n)
        t_start = k0 * dt

        def seg_law(t, q_, v_, _t0=t_start):
            return controller(t + _t0, q_, v_)

        tr = simulate(
            plant,
            q,
            v,
            (k1 - k0) * dt,
            dt / substeps,
            method="rk4",
            record_every=1,
            controller=seg_law,
            controller_period=dt,
        )
        sq, sv, st = np.asarray(tr.q), np.asarray(tr.v), np.asarray(tr.t) + t_start
        # the control held over each RK4 step (the last record ends the segment)
        step_node = np.minimum(np.floor((st[:-1] - t_start) / dt + 1e-9).astype(int) + k0, n - 1)
        seg = {"t": st, "q": sq, "v": sv, "u": applied[step_node]}
        ts.append(st[substeps::substeps])
        qs.append(sq[substeps::substeps])
        vs.append(sv[substeps::substeps])
        q, v = sq[-1].copy(), sv[-1].copy()
        k0 = k1
        P = observer(k1, seg)
        if P is not None:
            ctrl.set_parameters(np.asarray(P, float))
    return np.vstack(qs), np.vstack(vs), np.concatenate(ts)


def summary(run_out: dict, final_hold_s: float = 5.0) -> dict:
    """results.json numbers of one closed-loop run: end-effector position and angle errors over the final hold
    (max) and overall (RMS, max), peak base force/torque applied, wall time, MPC statistics."""
    t, pos, ang, us = run_out["t"], run_out["position_error"], run_out["angle_error_deg"], run_out["us"]
    sel = t >= t[-1] - final_hold_s - 1e-9
    d = {
        "ee_position_error_final_hold_max_m": float(pos[sel].max()),
        "ee_angle_error_final_hold_max_deg": float(ang[sel].max()),
        "ee_position_error_final_m": float(pos[-1]),
        "ee_angle_error_final_deg": float(ang[-1]),
        "ee_position_error_rms_m": float(np.sqrt(np.mean(pos**2))),
        "ee_position_error_max_m": float(pos.max()),
        "ee_angle_error_max_deg": float(ang.max()),
        "base_force_peak_N": float(np.linalg.norm(us[:, :3], axis=1).max()),
        "base_torque_peak_Nm": float(np.linalg.norm(us[:, 3:6], axis=1).max()),
        "wall_time_s": float(run_out["wall_time_s"]),
        "stopped": bool(run_out["stopped"]),
    }
    if "mpc" in run_out:
        s = dict(run_out["mpc"])
        s.pop("replan_costs", None)
        s.pop("replan_iterations", None)
        # the per-re-plan times as their median and 95th percentile, the first re-plan excluded as in
        # `max_replan_s` (it is warm-started from the offline plan with `first_max_iter` iterations)
        times = s.pop("replan_times_s", None)
        if times is not None and len(times) > 1:
            s["median_replan_s"] = float(np.median(times[1:]))
            s["p95_replan_s"] = float(np.percentile(times[1:], 95))
        d["mpc"] = s
    return d


def plot(runs: dict, problem: Problem, out, prefix: str = "closed_loop_") -> list:
    """Position and angle error of the end effector against time for each run (open loop, policy, MPC)."""
    from pathlib import Path

    from ..viz import pyplot

    plt = pyplot()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True)
    for name, r in runs.items():
        ax[0].semilogy(r["t"], np.maximum(r["position_error"], 1e-9), label=name)
        ax[1].semilogy(r["t"], np.maximum(r["angle_error_deg"], 1e-9), label=name)
    ax[0].set_ylabel("position error (m)")
    ax[1].set_ylabel("angle error (deg)")
    ax[1].set_xlabel("t (s)")
    ax[0].legend()
    ax[0].set_title(f"{problem.name}: end effector in closed loop (true dynamics, RK4)")
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
    p1 = out / f"{prefix}errors.png"
    fig.tight_layout()
    fig.savefig(p1, dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True)
    for name, r in runs.items():
        tu = r["t"][: len(r["us"])]
        ax[0].plot(tu, np.linalg.norm(r["us"][:, :3], axis=1), label=name)
        ax[1].plot(tu, np.linalg.norm(r["us"][:, 3:6], axis=1), label=name)
    ax[0].set_ylabel("|base force| (N)")
    ax[1].set_ylabel("|base torque| (N m)")
    ax[1].set_xlabel("t (s)")
    ax[0].legend()
    p2 = out / f"{prefix}base_wrench.png"
    fig.tight_layout()
    fig.savefig(p2, dpi=110)
    plt.close(fig)
    return [p1, p2]
