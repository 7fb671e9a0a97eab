"""The three phases of a capture mission on one engine (docs/mission.md):

1. **capture**: the grasp as an inelastic impact (`_core.capture_impact`: momentum conserved, the grasp impulse);
2. **detumble and identify**: the post-capture controllers of Zhang, Yue, Yuan 2020 (eqs. 39-40) damp the stack's
   momentum while the joints excite it; the sensors of the detumble scenario measure the motion and the
   standard-parameter RLS identifies base and target online from that telemetry; a covariance test decides when
   the estimate is good enough and the model is handed over then;
3. **berth**: DDP (Valverde 2018, ch. 8) on a model of the stack brings the target to its berth pose, and the
   optimised policy (feed-forward plus Riccati gains) or a receding-horizon DDP drives the true plant. Run three
   times from the same state: with the nominal model (target guessed), the identified one and the truth.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from .. import _core, models
from .._core import InputError, NumericalError
from ..algorithms import quat_to_matrix
from ..control import ddp
from ..control import ddp_closed_loop as closed
from ..identification import online
from ..postcapture import equations as eq
from ..postcapture.estimators import identify_standard, initial_guesses, parameter_names, target_index
from ..postcapture.scenario import Scenario, load_scenario
from ..postcapture.simulation import measure, simulate
from .spec import Body, Mission

G0 = 9.80665


def target_parameters(b: Body) -> np.ndarray:
    """Engine-order standard parameters of a target body (inertia about the grasp frame origin)."""
    return np.asarray(eq.standard_vector(b.mass, b.com, b.inertia), float)


def model_with_target(servicer, target: int, b: Body, base=None):
    """The combined model with the target's (and optionally the base's) parameters replaced."""
    P = np.array(servicer.parameters(), float)
    P[target] = target_parameters(b)
    if base is not None:
        P[0] = base
    return servicer.with_parameters(P)


# -- phase 1: capture ---------------------------------------------------------------------------------------
def capture(mission: Mission, truth) -> dict:
    """The servicer at contact (base at the origin, attitude identity) and the target's twist before the grasp,
    through the impact. Refuses a grasp point the arm cannot be at (wrong joint count) before simulating."""
    target = target_index(truth)
    nj = truth.nv - 6
    if truth.joint_types[0] != "free":
        raise InputError(f"{mission.source}: key 'servicer': a capture mission needs a free-floating base")
    if len(mission.joints) != nj:
        raise InputError(
            f"{mission.source}: key 'capture.joints_deg': {truth.name} has {nj} joints, got {len(mission.joints)}"
        )
    q = np.concatenate([[0, 0, 0, 0, 0, 0, 1], mission.joints])
    v = np.concatenate([mission.base_velocity, mission.base_rate, np.zeros(nj)])  # base frame = inertial at contact
    from .. import algorithms as alg

    fk = np.asarray(alg.forward_kinematics(truth, q[None]))[0, target]
    R = quat_to_matrix(fk[3:])
    twist = np.concatenate([R.T @ mission.target_velocity, R.T @ mission.target_rate])
    r = dict(_core.capture_impact(truth._core, target, list(q), list(v), list(twist)))
    r.update(q=q, v_pre=v, grasp_pose=fk, target_twist_local=twist)
    scale = np.abs(r["momentum_before"]).max()
    r["momentum_error_relative"] = float(np.abs(r["momentum_after"] - r["momentum_before"]).max() / max(scale, 1e-300))
    return r


def free_target_model(b: Body):
    """The target before the grasp: a free rigid body of its own (one-body model, its frame at the grasp point)."""
    from ..model import Model

    I, c = np.asarray(b.inertia, float).tolist(), np.asarray(b.com, float).tolist()
    text = (
        "name: free_target\nbase: free\ngravity: [0, 0, 0]\nbodies:\n  - name: target\n    inertial: "
        f"{{mass: {float(b.mass)!r}, com: {c!r}, inertia: {{xx: {I[0][0]!r}, yy: {I[1][1]!r}, zz: {I[2][2]!r}, "
        f"xy: {I[0][1]!r}, xz: {I[0][2]!r}, yz: {I[1][2]!r}}}}}\n"
    )
    return Model.from_yaml_string(text)


def approach(mission: Mission, truth, cap: dict, duration: float, dt: float = 0.01) -> dict:
    """The last `duration` seconds before the grasp: the servicer (without the target) and the free target drift,
    each on its own, until the target's grasp frame meets the gripper. Both are torque-free and conservative, so
    their motion before the contact is their motion after it with the velocities reversed (time reversal of
    Lagrangian mechanics): each is simulated from the contact with negated velocities and read backwards. Returns
    the times (-duration .. 0), the distance from the gripper to the target's grasp point, and the total momentum
    of the two bodies along the way (a conservation check across the change of topology)."""
    from .. import algorithms as alg
    from ..simulation import simulate as sim_free

    target = target_index(truth)
    P = np.array(truth.parameters(), float)
    P[target] = 0.0
    servicer = truth.with_parameters(P)
    free = free_target_model(mission.target)
    ts = sim_free(servicer, cap["q"], -np.asarray(cap["v_pre"], float), duration, dt)
    qt0 = np.asarray(cap["grasp_pose"], float)
    tt = sim_free(free, qt0, -np.asarray(cap["target_twist_local"], float), duration, dt)
    qs, vs = np.asarray(ts.q)[::-1], -np.asarray(ts.v)[::-1]
    qt, vt = np.asarray(tt.q)[::-1], -np.asarray(tt.v)[::-1]
    t = -np.asarray(ts.t)[::-1]
    grip = np.asarray(alg.forward_kinematics(servicer, qs))[:, target, :3]
    gap = np.linalg.norm(grip - qt[:, :3], axis=1)
    h = np.asarray(alg.momentum(servicer, qs, vs)) + np.asarray(alg.momentum(free, qt, vt))
    ref = np.asarray(cap["momentum_before"], float)
    drift = float(np.abs(h - ref).max() / max(np.abs(ref).max(), 1e-300))
    return {"t": t, "gap": gap, "momentum_drift_relative": drift}


# -- phase 2: detumble and identify ---------------------------------------------------------------------------
def detumble_scenario(mission: Mission, q0, v0, truth=None) -> Scenario:
    """The detumble scenario from the post-impact state, with the mission's guess of the target and, when the
    mission has its own `sensors:` block, those sensors (checked against the robot like a scenario's). The
    momentum rows balance angular momentum about the moving base point whatever the named scenario says (the
    paper-reproduction scenarios keep the paper's inertial origin; a mission measures a drifting stack with
    sensors, where only the base point holds up: docs/postcapture.md), as the adaptive berth's rows do."""
    from ..io.scenario_blocks import scenario_blocks

    if isinstance(mission.detumble, dict):  # the post-capture blocks given inline, for this servicer
        from ..postcapture.scenario import parse_scenario

        b = mission.detumble
        nj = len(mission.joints)
        d = {
            "name": f"{mission.name} detumble",
            "model": mission.servicer,
            "duration": mission.max_duration,
            "dt": b.get("dt", 1e-3),
            "sample_period": b.get("sample_period", 0.1),
            "initial": {"joints_deg": [0.0] * nj, "base_velocity": [0.0] * 3, "base_rate": [0.0] * 3},
            "control": b["control"],
            "excitation": b["excitation"],
            "identification": b["identification"],
        }
        try:
            sc = parse_scenario(d, f"{mission.source}: key 'detumble'", model=truth)
        except KeyError as e:
            raise InputError(f"{mission.source}: key 'detumble': missing key {e}") from None
    else:
        sc = load_scenario(mission.detumble)
    g = mission.guess
    guess = dict(sc.guess)
    guess["target"] = {"mass": g.mass, "com": list(g.com), "inertia": g.inertia.tolist()}
    sc = dataclasses.replace(
        sc,
        q0=np.asarray(q0, float),
        v0=np.asarray(v0, float),
        duration=mission.max_duration,
        guess=guess,
        measurement={**sc.measurement, "momentum_point": "base"},
    )
    if mission.sensors is not None:
        _, _, sset = scenario_blocks(
            mission.sensors, mission.source, truth if truth is not None else models.load(sc.model)
        )
        sc = dataclasses.replace(sc, sensors=sset)
    return sc


def covariance_history(rows: eq.StandardRows, x_hist: np.ndarray, p0: float, block: slice) -> np.ndarray:
    """Standard deviations (N, len(block)) of the standard parameters in `block` after each sample: the RLS
    covariance s² (P₀⁻¹ 1 + Σ φφᵀ)⁻¹ with s² the residual variance of the rows so far at the current estimate
    (unbiased: SSE / (rows − parameters), the prior counted as no row)."""
    phi, y = np.asarray(rows.Phi, float), np.asarray(rows.y, float)
    n, r, p = phi.shape[0], phi.shape[1], phi.shape[2]
    G = np.cumsum(np.einsum("kri,krj->kij", phi, phi), 0)
    b = np.cumsum(np.einsum("kri,kr->ki", phi, y), 0)
    yy = np.cumsum(np.einsum("kr,kr->k", y, y), 0)
    out = np.full((n, block.stop - block.start), np.inf)
    eye = np.eye(p) / p0
    for k in range(n):
        dof = (k + 1) * r - p
        if dof <= 0:
            continue
        x = x_hist[k]
        sse = max(yy[k] - 2 * x @ b[k] + x @ G[k] @ x, 0.0)
        cov = np.linalg.inv(G[k] + eye) * (sse / dof)
        out[k] = np.sqrt(np.maximum(np.diag(cov)[block], 0.0))
    return out


def identify_online(mission: Mission, truth, sc: Scenario, seed: int = 0, progress=None) -> dict:
    """Simulate the detumble (the scenario's controllers), measure with its sensors, run the standard-parameter RLS
    over the telemetry and find the handover instant: the first sample after `min_duration` at which the target's
    mass, CoM and inertia standard deviations are within the mission's tolerances (relative for mass and inertia,
    metres for the CoM). Without convergence the handover is at `max_duration`, and said so."""
    planar = False
    base, target = 0, target_index(truth)
    t0 = time.perf_counter()
    sim = simulate(sc, truth)
    t_sim = time.perf_counter() - t0
    if progress:
        progress(f"detumble simulated ({sc.duration:g} s in {t_sim:.1f} s)")
    if sc.sensors is not None:
        sc = dataclasses.replace(sc, sensor_seed=int(seed))
    rng = np.random.default_rng(seed) if sc.noise else None
    t0 = time.perf_counter()
    meas = measure(truth, sim, sc, rng)
    rows = (eq.standard_momentum_rows if mission.method == "momentum" else eq.standard_force_rows)(
        truth, meas, base, target
    )
    L = eq.Layout(planar)
    x0 = np.concatenate([eq.standard_vector(*g)[L.std_cols] for g in initial_guesses(sc, planar)])
    x_hist = _rls(x0, sc).run(rows.t, rows.Phi, rows.y)
    phys = identify_standard(truth, rows, sc, planar)
    k = len(L.std_cols)
    sig = covariance_history(rows, x_hist, sc.P0, slice(k, 2 * k))
    t_id = time.perf_counter() - t0
    names = parameter_names(planar)
    half = len(names) // 2
    m_hat = phys[:, half]
    # the target block of the standard vector: [m, h (3), I_o (6: xx, xy, yy, xz, yz, zz)]
    rel_m = sig[:, 0] / np.abs(m_hat)
    com_sd = np.linalg.norm(sig[:, 1:4], axis=1) / np.abs(m_hat)
    x_t = x_hist[:, k : 2 * k]
    diag = [4, 6, 9]
    rel_i = (sig[:, diag] / np.maximum(np.abs(x_t[:, diag]), 1e-12)).max(1)
    tol = mission.tolerance
    # The RLS covariance alone is optimistic here: the momentum form's rows are cumulative (their errors are
    # correlated, not white), and at 5 s it claimed 0.2 % on the inertia against a true error of 4.9 % (the
    # built-in mission). So the test also asks that the estimate has stopped moving: over the trailing
    # `window` seconds no past estimate differs from the current one by more than the same tolerances.
    t_rows = np.asarray(rows.t, float)
    w = float(tol.get("window", 5.0))
    drift_m, drift_c, drift_i = (np.full(len(t_rows), np.inf) for _ in range(3))
    est_t = phys[:, half:]
    for j in range(len(t_rows)):
        i0 = int(np.searchsorted(t_rows, t_rows[j] - w))
        if t_rows[j] - t_rows[0] < w:
            continue
        seg, cur = est_t[i0 : j + 1], est_t[j]
        drift_m[j] = np.abs(seg[:, 0] - cur[0]).max() / abs(cur[0])
        drift_c[j] = np.linalg.norm(seg[:, 1:4] - cur[1:4], axis=1).max()
        drift_i[j] = (np.abs(seg[:, [4, 7, 9]] - cur[[4, 7, 9]]).max(0) / np.abs(cur[[4, 7, 9]])).max()
    ok = (rel_m <= tol["mass"]) & (com_sd <= tol["com"]) & (rel_i <= tol["inertia"]) & (t_rows >= mission.min_duration)
    ok &= (drift_m <= tol["mass"]) & (drift_c <= tol["com"]) & (drift_i <= tol["inertia"])
    converged = bool(ok.any())
    kc = int(np.argmax(ok)) if converged else len(rows.t) - 1
    t_c = float(rows.t[kc])
    # the state at the handover: the sample instant of the recorded run
    i_sim = int(np.argmin(np.abs(np.asarray(sim["t"]) - t_c)))
    truth_phys = np.concatenate(
        [
            np.r_[m, b, eq.inertia_sharp(I)[[0, 1, 2, 3, 4, 5]]]
            for m, b, I in (eq.body_truth(truth, 0), eq.body_truth(truth, target))
        ]
    )
    # the estimator as it stands at the handover, for the berth to go on with (the adaptive berth)
    rls = _rls(x0, sc)
    rls.run(rows.t[: kc + 1], rows.Phi[: kc + 1], rows.y[: kc + 1])
    return {
        "scenario": sc,
        "sim": sim,
        "rls": rls,
        "rows_t": np.asarray(rows.t, float),
        "estimates": phys,
        "names": names,
        "sigma_rel_mass": rel_m,
        "sigma_com_m": com_sd,
        "sigma_rel_inertia": rel_i,
        "converged": converged,
        "handover_index": kc,
        "handover_time": t_c,
        "handover_state": (np.asarray(sim["q"])[i_sim], np.asarray(sim["v"])[i_sim]),
        "standard_estimate": x_hist[kc],
        "truth_physical": truth_phys,
        "timings": {"simulation_s": t_sim, "identification_s": t_id},
        "std_cols": L.std_cols,
    }


def _rls(x0, sc: Scenario) -> online.RecursiveLS:
    return online.RecursiveLS(x0, np.full(len(x0), sc.P0), sc.forgetting)


def identified_model(truth, ident: dict):
    """The combined model with the base's and target's parameters as identified at the handover, projected onto
    physically consistent parameters (the nearest positive definite pseudo-inertia) so that DDP can run on it."""
    return model_from_estimate(truth, ident["standard_estimate"], ident["std_cols"])


def model_from_estimate(truth, x_std: np.ndarray, std_cols) -> object:
    """`truth` with its base's and target's parameters from the standard-parameter estimate `x_std` (base block,
    then target block), each projected onto the nearest physically consistent parameters."""
    target = target_index(truth)
    k = len(std_cols)
    P = np.array(truth.parameters(), float)
    for body, sl in ((0, slice(0, k)), (target, slice(k, 2 * k))):
        full = np.zeros(10)
        full[std_cols] = np.asarray(x_std, float)[sl]
        P[body] = eq.project_consistent(full[None])[0]
    return truth.with_parameters(P)


def relative_scale(tru: np.ndarray) -> np.ndarray:
    """What an error in each physical parameter [m, c (3), I (6: xx, xy, xz, yy, yz, zz)] of base and target is
    relative to: its own size; a product of inertia (true value often zero) its body's largest moment; a CoM
    coordinate at least 1 mm."""
    h = len(tru) // 2
    scale = np.abs(np.asarray(tru, float)).copy()
    for b0 in (0, h):
        scale[[b0 + 5, b0 + 6, b0 + 8]] = np.abs(scale[[b0 + 4, b0 + 7, b0 + 9]]).max()
        scale[b0 + 1 : b0 + 4] = np.maximum(scale[b0 + 1 : b0 + 4], 1e-3)
    return np.maximum(scale, 1e-300)


# -- phase 3: berth -------------------------------------------------------------------------------------------
#: RK4 steps of the true plant per control step in the berth
BERTH_SUBSTEPS = 5
DEFAULT_BERTH = {
    "duration": 20.0,
    "dt": 0.05,
    "position_tolerance": 0.01,
    "angle_tolerance_deg": 1.0,
    "max_iter": 100,
    "isp": 220.0,
}
DEFAULT_WEIGHTS = {
    "pose": [1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
    "terminal_pose": 1e4,
    "velocity": 1.0,
    "base_rate": 100.0,
    "terminal_velocity": 1e3,
    "control": 1e-6,
}


def berth_reference(truth, q_h, berth: dict) -> np.ndarray:
    """The berth pose of the target frame [p, quat xyzw] in the inertial frame: `position` and `rpy_deg` are given
    in the base frame at the handover."""
    from ..algorithms import matrix_to_quat

    fk = np.asarray(_fk(truth, q_h))[0]
    Rb = quat_to_matrix(fk[3:])
    p = fk[:3] + Rb @ np.asarray(berth["position"], float)
    r, pch, y = np.radians(berth.get("rpy_deg") or [0, 0, 0])
    Rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    Ry = np.array([[np.cos(pch), 0, np.sin(pch)], [0, 1, 0], [-np.sin(pch), 0, np.cos(pch)]])
    Rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    return np.r_[p, matrix_to_quat(Rb @ Rz @ Ry @ Rx)]


def _fk(model, q):
    from .. import algorithms as alg

    return np.asarray(alg.forward_kinematics(model, np.asarray(q, float)[None]))[0]


def check_reachable(truth, q_h, ref7, source: str) -> None:
    """Refuse a berth position farther from the arm's first joint than the arm reaches (the sum of the joint
    offsets along the chain to the grasp point): no controller can get the target there."""
    target = target_index(truth)
    chain, j = [], target
    while j is not None and j != 0:
        chain.append(j)
        j = truth.parents[j]
    fk = _fk(truth, q_h)
    reach = sum(np.linalg.norm(fk[c, :3] - fk[truth.parents[c], :3]) for c in chain[:-1])
    d = float(np.linalg.norm(ref7[:3] - fk[chain[-1], :3]))
    if d > reach:
        raise InputError(
            f"{source}: key 'berth.position': the berth point is {d:.3f} m from the arm's first joint, beyond its "
            f"reach of {reach:.3f} m (refused before simulating)"
        )


def berth_problem(model, x0, ref7, berth: dict, name: str) -> ddp.Problem:
    w = {**DEFAULT_WEIGHTS, **(berth.get("weights") or {})}
    n = int(round(berth["duration"] / berth["dt"]))
    nv = model.nv
    pose_w = list(np.broadcast_to(np.asarray(w["pose"], float), (6,)))
    vel = np.r_[np.zeros(nv), np.full(nv, float(w["velocity"]))]
    # the base's rotation rate apart: a servicer does not want its base (antennas, sensors) spun by the berth
    vel[nv + 3 : nv + 6] = float(w["base_rate"])
    tvel = np.r_[np.zeros(nv), np.full(nv, float(w["terminal_velocity"]))]
    xref = np.asarray(x0, float)[None]
    running = [
        ddp.frame_cost("berth", "target", ref7, pose_w, "log"),
        ddp.state_cost("still", model, list(vel), reference=xref),
        ddp.control_cost("effort", model, [float(w["control"])] * nv),
    ]
    terminal = [
        ddp.frame_cost("berth_final", "target", ref7, [float(w["terminal_pose"]) * x for x in pose_w], "log"),
        ddp.state_cost("at_rest", model, list(tvel), reference=xref),
    ]
    q7 = np.r_[ref7[6], ref7[3:6]]
    ref_dq = np.tile(ddp._pose_dq(q7, ref7[:3]), (n + 1, 1))
    return ddp.Problem(
        model=model,
        x0=np.asarray(x0, float),
        dt=float(berth["dt"]),
        horizon=n,
        running=running,
        terminal=terminal,
        us0=np.zeros((n, nv)),
        options={"variant": "fddp", "max_iter": int(berth["max_iter"]), "refresh_gains": True},
        frame="target",
        reference_dq=ref_dq,
        name=name,
        cost_kind="log",
    )


def berth_run(model, truth, x0, ref7, berth: dict, name: str, progress=None, observer=None) -> dict:
    """Optimise the berth on `model`, then drive the true plant with the policy (or MPC) from the same state.
    `observer` (MPC only; see `adaptive_berth.BerthEstimator`) follows the plant every `update_every_s` and may
    hand the controller new parameters."""
    # DDP's robot model takes moving joints only: the welded target is merged into the end effector (same dynamics)
    prob = berth_problem(model.with_fixed_leaves_merged(), x0, ref7, berth, name)
    mode = berth.get("controller", "policy")
    t0 = time.perf_counter()
    # the policy needs the whole-horizon plan; MPC plans its own windows (the first from zero controls), so a
    # whole-horizon solve would be spent on a warm start only (3.4 s of a 120 s mission's 10.3 s, mission_bench)
    sol = ddp.solve(prob) if mode == "policy" else None
    t_solve = time.perf_counter() - t0
    if sol is not None and sol["stop"] == "interrupted":  # the solver keeps its best iterate on Ctrl-C
        raise KeyboardInterrupt(f"in the berth plan on the {name} model")
    planned_over = {} if sol is None else _over_limit(truth, np.asarray(sol["us"], float))
    t0 = time.perf_counter()
    try:
        kw = {}
        if observer is not None:
            kw = {"observer": observer, "observe_every": max(1, int(round(berth["update_every_s"] / berth["dt"])))}
        # MPC windows shrink at the end: the berth is a deadline (windows that reach past it put the terminal
        # cost after the berth's end; the naveen_dual_arm_capture stack then ended 84 mm off even on the truth,
        # 2.9 mm with shrinking windows)
        out = closed.run(prob, mode, plant=truth, solution=sol, substeps=BERTH_SUBSTEPS, shrink=True, **kw)
    except NumericalError as e:
        # the plant left the solver's reach (e.g. torques clipped at the joints' effort limits and the stack no
        # longer held): a result of the mission, reported, not a crash of it
        failed = {
            "model": name,
            "failed": f"the closed loop on the true plant diverged: {e}",
            "iterations": None if sol is None else int(sol["iterations"]),
            "solve_s": t_solve,
            "planned_torque_over_limit": planned_over,
            "position_error_final_m": None,
            "angle_error_final_deg": None,
            "settling_time_s": None,
        }
        return {"summary": failed, "trace": None}
    t_run = time.perf_counter() - t0
    t, pos, ang, us, xs = out["t"], out["position_error"], out["angle_error_deg"], out["us"], out["xs"]
    inside = (pos <= berth["position_tolerance"]) & (ang <= berth["angle_tolerance_deg"])
    # settling: the first instant after which the target stays within both tolerances to the end
    outside = np.flatnonzero(~inside)
    settle = None if inside[-1] is np.False_ or not inside[-1] else float(t[outside[-1] + 1] if outside.size else t[0])
    dt = float(berth["dt"])
    f, tau = us[:, :3], us[:, 3:6]
    impulse = float(np.sum(np.linalg.norm(f, axis=1)) * dt)
    nq = truth.nq
    w_base = np.linalg.norm(xs[:, nq + 3 : nq + 6], axis=1)
    wheel = np.cumsum(tau, 0) * dt  # the angular momentum a wheel set providing the base torque would store
    res = {
        "model": name,
        "iterations": None if sol is None else int(sol["iterations"]),
        "cost": None if sol is None else float(sol["cost"]),
        "solve_s": t_solve,
        "closed_loop_s": t_run,
        "position_error_final_m": float(pos[-1]),
        "angle_error_final_deg": float(ang[-1]),
        "position_error_max_m": float(pos.max()),
        "settling_time_s": settle,
        "thrust_impulse_Ns": impulse,
        "propellant_kg": impulse / (float(berth["isp"]) * G0),
        "base_rate_peak_rad_s": float(w_base.max()),
        "wheel_momentum_peak_Nms": float(np.linalg.norm(wheel, axis=1).max()),
        "joint_torque_peak_Nm": float(np.abs(us[:, 6:]).max()),
        "joint_torque_over_limit": _over_limit(truth, us),
        "planned_torque_over_limit": planned_over,
        "stopped": bool(out["stopped"]),
    }
    if "mpc" in out:
        s = dict(out["mpc"])
        for k in ("replan_costs", "replan_times_s", "replan_iterations"):  # per-re-plan lists
            s.pop(k, None)
        res["mpc"] = s
    return {"summary": res, "trace": {"t": t, "position_error": pos, "angle_error_deg": ang, "base_rate": w_base}}


def _over_limit(truth, us) -> dict:
    """Joints whose peak berth torque exceeds the model's effort limit: {joint: peak / limit}. A target too heavy
    for the arm is run and reported, not refused (the berth does not enforce the limits)."""
    effort = np.asarray(truth._core.limits["effort"], float)
    out = {}
    for i, (name, nv) in enumerate(zip(truth.joint_names, truth.nvs)):
        if i == 0 or nv != 1 or not np.isfinite(effort[i]) or effort[i] <= 0:
            continue
        peak = float(np.abs(us[:, truth.idx_v[i]]).max())
        if peak > effort[i]:
            out[name] = peak / float(effort[i])
    return out


def nominal_model(truth, mission: Mission):
    """What is known before identification: the servicer as it is (its base and arm are known from ground tests)
    and the target as the mission guesses it."""
    return model_with_target(truth, target_index(truth), mission.guess)


def load_truth(mission: Mission):
    """The combined model: the servicer (a built-in robot or a YAML model file) with the true target welded on."""
    from pathlib import Path

    from ..model import Model

    spec = str(mission.servicer)
    if Path(spec).suffix in (".yaml", ".yml"):
        path = Path(spec)
        if not path.is_absolute() and mission.source and Path(mission.source).is_file():
            path = Path(mission.source).parent / path  # relative to the mission file, as model files elsewhere
        text = path.read_text(encoding="utf-8")
    else:
        text = models.source(spec)
    if mission.grasp is not None:
        text = _with_grasped_body(text, mission)
    servicer = Model.from_yaml_string(text)
    return model_with_target(servicer, target_index(servicer), mission.target)


def _with_grasped_body(text: str, mission: Mission) -> str:
    """The servicer's model file with a body `target` welded at `grasp` (its inertia is set from the mission
    afterwards): how a servicer that carries no target becomes the post-capture stack."""
    import yaml

    d = yaml.safe_load(text)
    where = f"{mission.source}: key 'grasp'"
    bodies = d.get("bodies") or []
    names = [b.get("name") for b in bodies]
    if any("target" in (b.get("tags") or []) for b in bodies):
        raise InputError(f"{where}: the servicer '{mission.servicer}' already carries a target; remove 'grasp'")
    g = mission.grasp
    if g["body"] not in names:
        raise InputError(f"{where}.body: the servicer has no body '{g['body']}' (bodies: {', '.join(map(str, names))})")
    rpy = np.asarray(g.get("rpy_deg") or [0, 0, 0], float)
    if d.get("angles", "rad") != "deg":
        rpy = np.radians(rpy)
    bodies.append(
        {
            "name": "target",
            "parent": g["body"],
            "joint": {"name": "grasp", "type": "fixed"},
            "origin": {"xyz": [float(x) for x in (g.get("xyz") or [0, 0, 0])], "rpy": rpy.tolist()},
            "inertial": {"mass": 1.0, "com": [0.0, 0.0, 0.0], "inertia": [1.0, 1.0, 1.0]},
            "tags": ["target"],
        }
    )
    d["bodies"] = bodies
    return yaml.safe_dump(d, sort_keys=False)
