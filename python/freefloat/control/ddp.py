"""DDP end-effector control of a free-floating robot (Valverde 2018, ch. 8), driven from Python.

The solver, the dynamics, the costs and their derivatives are in the engine (`freefloat._core.ddp_solve`); this
module builds problems (costs on frames, states and controls, for any model), reads the chapter 8 scenario files,
and turns a solution into the numbers of `results.json`.

    from freefloat.control import ddp
    prob = ddp.load_scenario("valverde_ch8_tracking", cost="log")
    sol = ddp.solve(prob, progress=print)
    res = ddp.results(prob, sol)

State x = [q; v] (q with base position and quaternion x, y, z, w), control u = generalized force (the base force
and torque in the base frame at its origin, then joint torques), semi-implicit Euler steps; costs are Σ w r²
per node without ½ or Δt, as the thesis writes them (eqs. 8.52, 8.56).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _core
from .._core import InputError
from ..io import scenario_files
from ..model import Model
from ..models import load as load_model

__all__ = [
    "Problem",
    "frame_cost",
    "state_cost",
    "control_cost",
    "screw_reference",
    "load_scenario",
    "solve",
    "results",
]


@dataclass
class Problem:
    """An optimal-control problem: robot, initial state, horizon, costs, initial guess and solver options."""

    model: Model
    x0: np.ndarray
    dt: float
    horizon: int
    running: list[dict]
    terminal: list[dict]
    us0: np.ndarray
    keep_out: list[dict] = field(default_factory=list)
    xs0: np.ndarray | None = None
    options: dict = field(default_factory=dict)
    frame: str = "ee"
    #: reference poses of the frame as thesis-layout dual quaternions (horizon + 1, 8), for results and plots
    reference_dq: np.ndarray | None = None
    name: str = ""
    cost_kind: str = "log"
    #: the model's last joints driven by their rates (the thesis' massless wrist, eq. 8.51): their controls are joint
    #: rates in rad/s, their bodies' inertia is ignored; empty: every joint torque-driven
    rate_joints: list[str] = field(default_factory=list)


def _weights(w, n: int, what: str) -> dict:
    """Constant (`[...]`) or scheduled (`{"start":..., "medium":..., "end":..., "breakpoints":...}`) weights."""
    if isinstance(w, dict):
        out = {f"weights_{k}": list(map(float, w[k])) for k in ("start", "medium", "end")}
        out["breakpoints"] = [int(b) for b in w["breakpoints"]]
        for k in ("start", "medium", "end"):
            if len(out[f"weights_{k}"]) != n:
                raise InputError(f"{what}: {k} weights need {n} entries, got {len(out[f'weights_{k}'])}")
        return out
    w = [float(x) for x in np.atleast_1d(w)]
    if len(w) != n:
        raise InputError(f"{what}: need {n} weights, got {len(w)}")
    return {"weights": w}


def frame_cost(name: str, frame: str, reference, weights, kind: str = "log", sign: str = "nearest") -> dict:
    """End-effector pose cost. `kind="log"`: residual log6(M_ref⁻¹ M) (6: translation then rotation), reference
    (M, 7) [p, quat xyzw]; `kind="dq"`: thesis component-wise dual-quaternion difference (8), reference (M, 8)
    [real w x y z, dual w x y z]. M = 1 or one per node. `sign` (dq only): 'nearest' compares with whichever of
    ±q_D is nearer to q_G (a pose metric), 'literal' is the thesis' q_G − q_D, which is largest at the exact pose
    on the quaternion's other sheet."""
    if kind not in ("log", "dq"):
        raise InputError(f"cost {name!r}: pose cost kind must be 'log' or 'dq', got {kind!r}")
    if sign not in DQ_SIGNS:
        raise InputError(f"cost {name!r}: sign must be one of {', '.join(DQ_SIGNS)}, got {sign!r}")
    n = 6 if kind == "log" else 8
    ref = np.atleast_2d(np.asarray(reference, dtype=float))
    d = {
        "name": name,
        "kind": "frame_placement" if kind == "log" else "frame_dq",
        "frame": frame,
        "reference": ref,
        **_weights(weights, n, f"cost {name!r}"),
    }
    if kind == "dq":
        d["sign"] = sign
    return d


def state_cost(name: str, model: Model, weights, reference=None) -> dict:
    """Residual x ⊖ x_ref (2 nv: configuration tangent, then velocities); default reference: neutral, at rest."""
    d = {"name": name, "kind": "state", **_weights(weights, 2 * model.nv, f"cost {name!r}")}
    if reference is not None:
        d["reference"] = np.atleast_2d(np.asarray(reference, dtype=float))
    return d


def control_cost(name: str, model: Model, weights, reference=None) -> dict:
    """Residual u − u_ref (nv); default reference zero."""
    d = {"name": name, "kind": "control", **_weights(weights, model.nv, f"cost {name!r}")}
    if reference is not None:
        d["reference"] = np.atleast_2d(np.asarray(reference, dtype=float))
    return d


def screw_reference(start_dq, axis, moment, angle, advance, t_hold, t_move, dt, n) -> np.ndarray:
    """Hold / screw / hold reference of §8.7 as dual quaternions (n + 1, 8) (engine: `ddp_screw_reference`)."""
    return _core.ddp_screw_reference(
        [float(x) for x in start_dq],
        list(map(float, axis)),
        list(map(float, moment)),
        angle,
        advance,
        t_hold,
        t_move,
        dt,
        n,
    )


# -- small dual-quaternion helpers for the user-facing reference description and the error metrics ---------


def _qmul(a, b):
    a0, av = a[..., 0], a[..., 1:]
    b0, bv = b[..., 0], b[..., 1:]
    w = a0 * b0 - np.sum(av * bv, axis=-1)
    v = a0[..., None] * bv + b0[..., None] * av + np.cross(av, bv)
    return np.concatenate([w[..., None], v], axis=-1)


def _qconj(a):
    return np.concatenate([a[..., :1], -a[..., 1:]], axis=-1)


def _axis_angle_quat(axis, angle):
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    return np.r_[math.cos(angle / 2), math.sin(angle / 2) * axis]


def _pose_dq(q_wxyz, p):
    """Translation-first pose dual quaternion (Valverde 2018, eq. 3.2): q + ε ½ p q."""
    q = np.asarray(q_wxyz, dtype=float)
    return np.r_[q, 0.5 * _qmul(np.r_[0.0, p], q)]


def dq_to_pose(dq: np.ndarray) -> np.ndarray:
    """(M, 8) thesis-layout dual quaternions → (M, 7) [p, quat xyzw] (r = 2 q_d q_r*)."""
    dq = np.atleast_2d(dq)
    p = 2 * _qmul(dq[:, 4:], _qconj(dq[:, :4]))[:, 1:]
    return np.c_[p, dq[:, 1:4], dq[:, 0]]


def pose_errors(g_dq: np.ndarray, d_dq: np.ndarray) -> dict:
    """Error dual quaternion q_{D/G} = q_G* q_D (eq. 8.55), its Euler angle 2 acos|sc| (eq. 8.65 with |·|,
    sign-safe) and the position error r^G = 2 q_d q_r* in G."""
    conj = np.c_[_qconj(g_dq[:, :4]), _qconj(g_dq[:, 4:])]
    er = _qmul(conj[:, :4], d_dq[:, :4])
    ed = _qmul(conj[:, 4:], d_dq[:, :4]) + _qmul(conj[:, :4], d_dq[:, 4:])
    angle = 2 * np.arccos(np.clip(np.abs(er[:, 0]), 0.0, 1.0))
    rg = 2 * _qmul(ed, _qconj(er))[:, 1:]
    return {"error_dq": np.c_[er, ed], "angle": angle, "position": rg}


# -- scenario files ------------------------------------------------------------------------------------------


def _key(d: dict, key: str, source: str, kind=None, default=...):
    if key not in d:
        if default is ...:
            raise InputError(f"{source}: missing key '{key}'")
        return default
    v = d[key]
    if kind is not None and not isinstance(v, kind):
        raise InputError(f"{source}: key '{key}': expected {getattr(kind, '__name__', kind)}, got {v!r}")
    return v


def _num_list(d: dict, key: str, source: str, n: int | None = None, default=...) -> list[float]:
    v = _key(d, key, source, default=default)
    try:
        out = [float(x) for x in np.atleast_1d(v)]
    except (TypeError, ValueError):
        raise InputError(f"{source}: key '{key}': expected numbers, got {v!r}") from None
    if n is not None and len(out) != n:
        raise InputError(f"{source}: key '{key}': expected {n} numbers, got {len(out)}")
    if not all(math.isfinite(x) for x in out):
        raise InputError(f"{source}: key '{key}': non-finite entries")
    return out


def _sched(d: dict, key: str, source: str, schedule, n_each: int = 3) -> list[float] | dict:
    """Weights given as [start, medium, end] (Table 8.2 columns) → scheduled or End-constant."""
    v = _num_list(d, key, source, n_each)
    if schedule is None:
        return [v[-1]]
    return {"start": [v[0]], "medium": [v[1]], "end": [v[2]], "breakpoints": list(schedule)}


def _expand(w, n: int):
    if isinstance(w, dict):
        return {k: (v * n if k != "breakpoints" else v) for k, v in w.items()}
    return w * n


def _concat(parts: list):
    """Concatenate weight blocks (each list or scheduled dict) into one weight spec."""
    if all(not isinstance(p, dict) for p in parts):
        return [x for p in parts for x in p]
    bps = next(p["breakpoints"] for p in parts if isinstance(p, dict))
    out = {"start": [], "medium": [], "end": [], "breakpoints": bps}
    for p in parts:
        for k in ("start", "medium", "end"):
            out[k] += p[k] if isinstance(p, dict) else p
    return out


#: how the dual-quaternion pose cost meets the reference's sign (`frame_cost`)
DQ_SIGNS = ("nearest", "literal")
#: how the scenario's wrist is driven: 'rate' = the thesis' massless wrist with Euler-angle-rate controls
#: (eq. 8.51); 'torque' = the model's wrist bodies with their inertia, driven by joint torques
WRIST_MODES = ("rate", "torque")

#: the `weights` keys of a control_ddp scenario, each [Start, Medium, End] (Valverde 2018, Tables 8.1-8.2)
_WEIGHT_KEYS = [
    "pose_terminal_real",
    "pose_terminal_dual",
    "base_velocity_terminal",
    "pose_running_real",
    "pose_running_dual",
    "base_velocity_running",
    "control_force",
    "control_torque",
    "control_joints",
    "control_wrist",
]
#: not in the thesis: a separate weight on the base's linear velocity (default: base_velocity_*)
_OPTIONAL_WEIGHT_KEYS = ["base_linear_velocity_running", "base_linear_velocity_terminal"]


def load_scenario(
    spec: str | Path,
    cost: str | None = None,
    max_iter: int | None = None,
    schedule: bool | None = None,
    keep_out: bool | None = None,
    initial_controls: str | None = None,
    wrist: str | None = None,
    dq_sign: str | None = None,
    robot: str | None = None,
) -> Problem:
    """Read a `control_ddp` scenario (built-in name or YAML path) and build its problem. The keyword arguments
    override the file: pose cost 'dq' or 'log', iteration count, weight schedule on/off (off: the End column),
    keep-out on/off, initial controls 'zero' or 'gaussian', wrist 'rate' or 'torque' (`WRIST_MODES`), the dq
    cost's sign 'nearest' or 'literal' (`DQ_SIGNS`), the robot (a built-in name or model file with the scenario's
    joint and frame names)."""
    d, source = scenario_files.read(spec, kind="control_ddp")
    model = load_model(robot or _key(d, "robot", source, str))
    frame = _key(d, "frame", source, str, "ee")
    dt = float(_key(d, "dt", source, (int, float)))
    n = _key(d, "horizon", source, int)
    if n < 1:
        raise InputError(f"{source}: key 'horizon': must be at least 1, got {n}")
    if not dt > 0:
        raise InputError(f"{source}: key 'dt': must be positive, got {dt}")
    # Initial state.
    init = _key(d, "initial_state", source, dict, {})
    q = np.array(model.neutral(), dtype=float)
    for j, deg in _key(init, "joints_deg", f"{source}: initial_state", dict, {}).items():
        if j not in model.joint_names:
            raise InputError(f"{source}: initial_state.joints_deg: no joint '{j}' in {model.name}")
        i = model.joint_names.index(j)
        q[model.idx_q[i]] = math.radians(float(deg))
    x0 = np.r_[q, np.zeros(model.nv)]
    # Reference as dual quaternions.
    ref = _key(d, "reference", source, dict)
    rsrc = f"{source}: reference"
    rtype = _key(ref, "type", rsrc, str)
    pos = _num_list(ref, "position", rsrc, 3)
    aa = _num_list(ref, "rotation_axis_angle_deg", rsrc, 4)
    start = _pose_dq(_axis_angle_quat(aa[:3], math.radians(aa[3])), pos)
    if rtype == "fixed":
        ref_dq = np.tile(start, (n + 1, 1))
    elif rtype == "screw":
        axis = np.array(_num_list(ref, "axis", rsrc, 3))
        point = np.array(_num_list(ref, "axis_point", rsrc, 3))
        ref_dq = screw_reference(
            start,
            axis,
            np.cross(point, axis),
            math.radians(float(_key(ref, "angle_deg", rsrc, (int, float)))),
            float(_key(ref, "advance", rsrc, (int, float))),
            float(_key(ref, "t_hold", rsrc, (int, float))),
            float(_key(ref, "t_move", rsrc, (int, float))),
            dt,
            n,
        )
    else:
        raise InputError(f"{rsrc}: key 'type': expected 'fixed' or 'screw', got {rtype!r}")
    # Weights (thesis tables: each entry [start, medium, end], or one number when constant).
    w = _key(d, "weights", source, dict)
    wsrc = f"{source}: weights"
    sched_bp = _key(d, "schedule", source, default=None)
    if schedule is False:
        sched_bp = None
    if sched_bp is not None:
        sched_bp = [int(x) for x in sched_bp]
        if len(sched_bp) != 4:
            raise InputError(f"{source}: key 'schedule': need 4 iteration breakpoints [i1, i2, i3, i4]")
    cost = cost or _key(d, "cost", source, str, "dq")
    if cost not in ("dq", "log"):
        raise InputError(f"--cost / key 'cost': expected 'dq' or 'log', got {cost!r}")
    dq_sign = dq_sign or _key(d, "dq_sign", source, str, "nearest")
    if dq_sign not in DQ_SIGNS:
        raise InputError(f"{source}: key 'dq_sign' / --dq-sign: expected one of {', '.join(DQ_SIGNS)}, got {dq_sign!r}")
    rate_joints = _rate_joints(d, source, model, wrist)

    def sched(key):
        return _sched(w, key, wsrc, sched_bp)

    def pose_weights(real, dual):
        if cost == "dq":
            return _concat([_expand(real, 4), _expand(dual, 4)])
        # log6 = [translation; rotation]: ‖δq‖² ≈ ¼‖(δp, δθ)‖² for small errors, so W/4 on each block.
        quarter = lambda b: (
            {k: ([x / 4 for x in v] if k != "breakpoints" else v) for k, v in b.items()}
            if isinstance(b, dict)
            else [x / 4 for x in b]
        )  # noqa: E731
        return _concat([_expand(quarter(dual), 3), _expand(quarter(real), 3)])

    pose_ref = ref_dq if cost == "dq" else dq_to_pose(ref_dq)
    nv = model.nv
    zeros = lambda k: [0.0] * k  # noqa: E731
    unknown = sorted(set(w) - set(_WEIGHT_KEYS) - set(_OPTIONAL_WEIGHT_KEYS))
    if unknown:
        raise InputError(
            f"{wsrc}: unknown key(s) {', '.join(map(repr, unknown))}; the weights are "
            + ", ".join(_WEIGHT_KEYS + _OPTIONAL_WEIGHT_KEYS)
        )

    def base_velocity(when):
        # the base twist (linear, angular): one weight for all six, or the linear three apart when
        # `base_linear_velocity_<when>` is given (a heavier hold on the base's drift than on its rotation)
        both = sched(f"base_velocity_{when}")
        lin = sched(f"base_linear_velocity_{when}") if f"base_linear_velocity_{when}" in w else both
        return _concat([zeros(nv), _expand(lin, 3), _expand(both, 3), zeros(nv - 6)])

    running = [
        frame_cost(
            "pose", frame, pose_ref, pose_weights(sched("pose_running_real"), sched("pose_running_dual")), cost, dq_sign
        ),
        state_cost("base_velocity", model, base_velocity("running")),
        control_cost(
            "control",
            model,
            _concat(
                [
                    _expand(sched("control_force"), 3),
                    _expand(sched("control_torque"), 3),
                    _expand(sched("control_joints"), 3),
                    _expand(sched("control_wrist"), nv - 9),
                ]
            ),
        ),
    ]
    terminal = [
        frame_cost(
            "pose",
            frame,
            pose_ref,
            pose_weights(sched("pose_terminal_real"), sched("pose_terminal_dual")),
            cost,
            dq_sign,
        ),
        state_cost("base_velocity", model, base_velocity("terminal")),
    ]
    # Keep-out.
    kos = []
    ko = _key(d, "keep_out", source, dict, None)
    if ko is not None and keep_out is not False:
        ksrc = f"{source}: keep_out"
        for j in _key(ko, "joints", ksrc, list):
            kos.append(
                {
                    "joint": str(j),
                    "center": math.radians(float(_key(ko, "center_deg", ksrc, (int, float)))),
                    "width": math.radians(float(_key(ko, "width_deg", ksrc, (int, float)))),
                    "height": float(_key(ko, "height", ksrc, (int, float))),
                }
            )
    # Initial controls.
    ic = initial_controls or _key(d, "initial_controls", source, str, "zero")
    if ic == "zero":
        us0 = np.zeros((n, nv))
    elif ic == "gaussian":
        g = _key(d, "gaussian", source, dict, {})
        std = np.array(_num_list(g, "std", f"{source}: gaussian", nv))
        rng = np.random.default_rng(int(g.get("seed", 0)))
        us0 = rng.standard_normal((n, nv)) * std
    else:
        raise InputError(f"{source}: key 'initial_controls': expected 'zero' or 'gaussian', got {ic!r}")
    # Solver options.
    s = dict(_key(d, "solver", source, dict, {}))
    if max_iter is not None:
        s["max_iter"] = int(max_iter)
    if s.get("alphas") == "backtracking":
        s["alphas"] = [0.5**k for k in range(10)]
    return Problem(
        model=model,
        x0=x0,
        dt=dt,
        horizon=n,
        running=running,
        terminal=terminal,
        us0=us0,
        keep_out=kos,
        options=s,
        frame=frame,
        reference_dq=ref_dq,
        name=Path(str(spec)).stem,
        cost_kind=cost,
        rate_joints=rate_joints,
    )


def _rate_joints(d: dict, source: str, model: Model, wrist: str | None) -> list[str]:
    """The scenario's `wrist` ('rate': the joints of `wrist_joints`, the model's last ones, are driven by their
    rates as the thesis' massless wrist is; 'torque': by torques, with the model's wrist inertia) → rate joints."""
    wrist = wrist or _key(d, "wrist", source, str, "torque")
    if wrist not in WRIST_MODES:
        raise InputError(f"{source}: key 'wrist' / --wrist: expected one of {', '.join(WRIST_MODES)}, got {wrist!r}")
    if wrist == "torque":
        return []
    names = _key(d, "wrist_joints", source, list, None)
    if names is None:
        raise InputError(
            f"{source}: key 'wrist_joints': 'wrist: rate' needs the wrist's joint names (the model's last joints)"
        )
    names = [str(j) for j in names]
    tail = list(model.joint_names[len(model.joint_names) - len(names) :])
    if not names or names != tail:
        raise InputError(
            f"{source}: key 'wrist_joints': {names} must be the last joints of {model.name}, in order ({tail})"
        )
    return names


def solve(problem: Problem, progress=None, **options) -> dict:
    """Solve `problem`; `options` override `problem.options` (variant, max_iter, alphas, ...). `progress(info)` is
    called after every iteration (return False to stop); Ctrl-C stops and keeps the best iterate. Returns the
    engine's solution dict plus `solve_time_s`."""
    import time

    opts = {**problem.options, **options}
    t0 = time.perf_counter()
    sol = _core.ddp_solve(
        problem.model._core,
        list(map(float, problem.x0)),
        problem.dt,
        problem.horizon,
        problem.running,
        problem.terminal,
        np.ascontiguousarray(problem.us0, dtype=float),
        keep_out=problem.keep_out,
        xs0=problem.xs0,
        options=opts,
        callback=progress,
        rate_joints=problem.rate_joints or None,
    )
    sol["solve_time_s"] = time.perf_counter() - t0
    return sol


def results(problem: Problem, sol: dict, final_hold_s: float | None = None) -> dict:
    """The numbers of results.json: iterations, final cost, timings, end-effector position and angle errors
    (over the final hold and overall), peak base force and torque, peak joint torque, and the quantities of the
    end-to-end criteria: peak base speed and rate over the whole run (base quiescence), the summed squared base
    force and torque (effort ordering), and for each keep-out joint the fraction of nodes within ±1° of the
    keep-out centre (dwell)."""
    m = problem.model
    xs, us = np.asarray(sol["xs"]), np.asarray(sol["us"])
    nq = m.nq
    g = _core.ddp_frame_dual_quats(m._core, np.ascontiguousarray(xs[:, :nq]), problem.frame)
    ref = problem.reference_dq if problem.reference_dq is not None else _reference_from_costs(problem)
    err = pose_errors(g, ref)
    t = np.arange(problem.horizon + 1) * problem.dt
    pos = np.linalg.norm(err["position"], axis=1)
    ang = np.degrees(err["angle"])
    t_end = t[-1]
    hold = final_hold_s if final_hold_s is not None else min(5.0, t_end)
    sel = t >= t_end - hold - 1e-9
    f, tau = us[:, :3], us[:, 3:6]
    nt = us.shape[1] - len(problem.rate_joints)  # torque-driven entries (rate-driven ones last)
    it = int(sol["iterations"])
    # base twist in base axes (linear, angular) is the first block of the velocities
    vb = xs[:, nq : nq + 6] if m.joint_types and m.joint_types[0] == "free" else np.zeros((len(xs), 6))
    dwell = {}
    for ko in problem.keep_out:
        i = m.joint_names.index(ko["joint"])
        theta = xs[:-1, m.idx_q[i]]
        # distance to the centre modulo whole turns (the keep-out term itself is not periodic, the joint is)
        off = np.angle(np.exp(1j * (theta - ko["center"])))
        dwell[ko["joint"]] = float(np.mean(np.abs(off) < math.radians(1.0)))
    return {
        "scenario": problem.name,
        "pose_cost": problem.cost_kind,
        "iterations": it,
        "stop": sol["stop"],
        "stop_message": sol["stop_message"],
        "initial_cost": float(sol["initial_cost"]),
        "final_cost": float(sol["cost"]),
        "solve_time_s": float(sol["solve_time_s"]),
        "time_per_iteration_s": float(sol["solve_time_s"]) / max(it, 1),
        "final_hold_s": hold,
        "ee_position_error_final_hold_max_m": float(pos[sel].max()),
        "ee_angle_error_final_hold_max_deg": float(ang[sel].max()),
        "ee_position_error_final_m": float(pos[-1]),
        "ee_angle_error_final_deg": float(ang[-1]),
        "ee_position_error_rms_m": float(np.sqrt(np.mean(pos**2))),
        "base_force_peak_N": float(np.linalg.norm(f, axis=1).max()),
        "base_torque_peak_Nm": float(np.linalg.norm(tau, axis=1).max()),
        "joint_torque_peak_Nm": float(np.abs(us[:, 6:nt]).max()) if nt > 6 else 0.0,
        "rate_joints": list(problem.rate_joints),
        "rate_control_peak_rad_s": float(np.abs(us[:, nt:]).max()) if nt < us.shape[1] else 0.0,
        "base_speed_peak_m_s": float(np.linalg.norm(vb[:, :3], axis=1).max()),
        "base_rate_peak_rad_s": float(np.linalg.norm(vb[:, 3:], axis=1).max()),
        "base_force_sum_sq": float(np.sum(f**2)),
        "base_torque_sum_sq": float(np.sum(tau**2)),
        "keep_out_dwell_within_1deg": dwell,
        "gap": float(sol["gap"]),
        "cost_history": [float(h["cost"]) for h in sol["history"]],
    }


def _reference_from_costs(problem: Problem) -> np.ndarray:
    """The reference poses of `problem.frame` as thesis-layout dual quaternions (horizon + 1, 8), read from its first
    pose cost on that frame (running, else terminal), for a problem built by hand without `reference_dq`."""
    for t in problem.running + problem.terminal:
        if t["kind"] in ("frame_placement", "frame_dq") and t["frame"] == problem.frame:
            r = np.atleast_2d(np.asarray(t["reference"], dtype=float))
            if t["kind"] == "frame_placement":  # [p, quat xyzw] -> [real w x y z, dual w x y z]
                r = np.array([_pose_dq(np.r_[row[6], row[3:6]] / np.linalg.norm(row[3:7]), row[:3]) for row in r])
            if len(r) == 1:
                return np.tile(r, (problem.horizon + 1, 1))
            if len(r) == problem.horizon + 1:
                return r
            return np.vstack([r, np.tile(r[-1], (problem.horizon + 1 - len(r), 1))])
    raise InputError(
        f"argument `problem`: no `reference_dq` and no pose cost on its frame {problem.frame!r} to read the reference"
        " from: set Problem.reference_dq ((horizon + 1, 8) dual quaternions) or add a frame cost"
    )


def unwind_joint_turns(model: Model, xs, us) -> tuple[np.ndarray, np.ndarray, list]:
    """Remove whole turns that a revolute joint makes within one step of a trajectory (xs (N + 1, nx), us (N, nu)).

    A light joint can spin by ~2π between two nodes at no visible cost in a pose cost that only sees the nodes (the
    converged log-SE(3) tracking solution does it with the wrist at t = 17 s); the pose is the same, but the chain
    quaternion ends on the opposite sign, where the thesis' component-wise dual-quaternion cost is maximal. Where one
    step changes a revolute angle by more than π, the whole turns are subtracted from the rest of the trajectory, the
    spike's velocity is replaced by the mean of its neighbours and the two impulse controls by their neighbours.
    Returns (xs, us, [(joint, node, turns), ...]); the result is a guess with a gap, for the feasibility-driven
    solver."""
    xs, us = np.array(xs, dtype=float), np.array(us, dtype=float)
    n, nq = len(us), model.nq
    done = []
    for i, jt in enumerate(model.joint_types):
        if jt != "revolute":
            continue
        iq, iv = model.idx_q[i], nq + model.idx_v[i]
        step = np.diff(xs[:, iq])
        for k in np.flatnonzero(np.abs(step) > math.pi):
            turns = float(np.round(step[k] / (2 * math.pi)))
            if turns == 0:
                continue
            xs[k + 1 :, iq] -= turns * 2 * math.pi
            xs[k + 1, iv] = 0.5 * (xs[k, iv] + xs[min(k + 2, n), iv])
            if k >= 1:
                us[k, model.idx_v[i]] = us[k - 1, model.idx_v[i]]
            if k + 2 < n:
                us[k + 1, model.idx_v[i]] = us[k + 2, model.idx_v[i]]
            done.append((model.joint_names[i], int(k), turns))
    return xs, us, done


def warm_started(
    problem: Problem, guide: Problem, max_iter: int = 100, progress=None, unwind: bool = True
) -> tuple[Problem, dict]:
    """`problem` with its initial guess (controls and, for the feasibility-driven variant, states) replaced by the
    solution of `guide`, an easier problem on the same robot, horizon and reference (e.g. the same scenario with
    the log-SE(3) pose cost, constant End weights and no keep-out, which converges in a few tens of iterations
    with a backtracking line search), with one-step whole joint turns removed (`unwind_joint_turns`) unless
    `unwind=False`. Returns (the warm-started problem, the guide's solution, with `unwound` listing the turns)."""
    if (guide.horizon, guide.model.nv, guide.model.nq) != (problem.horizon, problem.model.nv, problem.model.nq):
        raise InputError("argument `guide`: its horizon and robot sizes must equal the problem's")
    sol = solve(guide, progress=progress, max_iter=max_iter, alphas=[0.5**k for k in range(10)])
    xs, us = np.asarray(sol["xs"], float), np.asarray(sol["us"], float)
    sol["unwound"] = []
    if unwind:
        xs, us, sol["unwound"] = unwind_joint_turns(problem.model, xs, us)
    from dataclasses import replace

    return replace(problem, us0=us, xs0=xs), sol
