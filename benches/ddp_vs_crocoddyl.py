#!/usr/bin/env python3
"""freefloat's DDP against Crocoddyl 3.2.1 on the identical chapter 8 tracking problem (Valverde 2018, §8.7):
valverde_ch8_arm, log-SE(3) pose cost, constant Table 8.2 End weights, semi-implicit Euler, zero-control start,
backtracking line search. freefloat and Crocoddyl's SolverFDDP and SolverDDP run interleaved (repeats), single
thread; reported: iterations, final cost (agreement), total solve and per-iteration time (median, min-max, wall and
CPU), and the per-node cost of each block (derivatives, backward pass, forward rollout). The peer is run as
Crocoddyl's own examples run it: C++ action models and no Python callback in the timed solve (the iterations are
counted in a separate untimed run, and each timed run must end after as many iterations at the same cost); the
faster of its two solvers per iteration is the reference of the ratios. Aborts (exit 1) if the final costs differ
by more than 1e-6 relative or freefloat needs more iterations.

    python benches/ddp_vs_crocoddyl.py --out benches/results          # full problem (N = 640), 3 repeats
    python benches/ddp_vs_crocoddyl.py --quick --out /tmp/x          # N = 80, 1 repeat (CI smoke)

Both use analytic derivatives: freefloat's step Jacobians come from its forward-dynamics derivatives
(`dynamics::derivatives`), Crocoddyl's from Pinocchio's ABA derivatives.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from freefloat.control import ddp  # noqa: E402

# -- the identical problem in Pinocchio + Crocoddyl (independent oracle; also used by tests/test_ddp.py) --
# The robot is built here by hand from its description (not from freefloat's model file); Crocoddyl's cost is
# dt·Σ½ w r² (running) + ½ w r² (terminal), so weights are scaled by 2/dt and 2 to equal freefloat's Σ w r².


def build_pinocchio_model():
    """valverde_ch8_arm in Pinocchio: free-flyer base 50 kg / 10 I, RRR arm (waist z, shoulder and elbow about the
    local z of frames rotated +90° about x), 5 kg / I links, a Z-Y-X wrist of 0.1 kg / 0.01 I bodies, frame `ee`."""
    import pinocchio as pin

    m = pin.Model()
    m.gravity = pin.Motion.Zero()
    eye = np.eye(3)

    def body(jid, mass, com, inertia):
        m.appendBodyToJoint(jid, pin.Inertia(mass, np.asarray(com, float), inertia * eye), pin.SE3.Identity())

    rx90 = pin.utils.rotate("x", np.pi / 2)
    base = m.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
    body(base, 50.0, [0, 0, 0], 10.0)
    waist = m.addJoint(base, pin.JointModelRZ(), pin.SE3(eye, np.array([0.0, 0, 1])), "waist")
    body(waist, 5.0, [0, 0, 1], 1.0)
    shoulder = m.addJoint(waist, pin.JointModelRZ(), pin.SE3(rx90, np.array([0.75, 0, 4])), "shoulder")
    body(shoulder, 5.0, [1.5, 0, 0], 1.0)
    elbow = m.addJoint(shoulder, pin.JointModelRZ(), pin.SE3(eye, np.array([3.0, 0, 0])), "elbow")
    body(elbow, 5.0, [1.5, 0, 0], 1.0)
    wz = m.addJoint(elbow, pin.JointModelRZ(), pin.SE3(eye, np.array([3.0, 0, 0])), "wrist_z")
    body(wz, 0.1, [0, 0, 0], 0.01)
    wy = m.addJoint(wz, pin.JointModelRY(), pin.SE3.Identity(), "wrist_y")
    body(wy, 0.1, [0, 0, 0], 0.01)
    wx = m.addJoint(wy, pin.JointModelRX(), pin.SE3.Identity(), "wrist_x")
    body(wx, 0.1, [0, 0, 0], 0.01)
    m.addFrame(pin.Frame("ee", wx, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return m


def _se3(pose7):
    import pinocchio as pin

    p = np.asarray(pose7, float)
    quat = pin.Quaternion(p[6], p[3], p[4], p[5])  # (w, x, y, z)
    quat.normalize()
    return pin.SE3(quat.matrix(), p[:3].copy())


def build_crocoddyl_problem(problem):
    """Crocoddyl's ShootingProblem for a freefloat `Problem` whose costs are frame_placement (log), state and
    control terms with constant weights (e.g. `load_scenario(..., cost="log", schedule=False, keep_out=False)`)."""
    import crocoddyl

    if problem.keep_out:
        raise ValueError("Crocoddyl has no keep-out activation: build the problem with keep_out=False")
    if problem.model.name != "valverde_ch8_arm" or problem.rate_joints:
        raise ValueError(
            "the Pinocchio model is valverde_ch8_arm with a torque-driven wrist: load the scenario with "
            "robot='valverde_ch8_arm', wrist='torque'"
        )
    model = build_pinocchio_model()
    state = crocoddyl.StateMultibody(model)
    act = crocoddyl.ActuationModelFull(state)
    nu = act.nu
    fid = model.getFrameId(problem.frame)
    dt, n = problem.dt, problem.horizon

    def costs_for(terms, k, scale):
        cs = crocoddyl.CostModelSum(state, nu)
        for t in terms:
            if "weights" not in t:
                raise ValueError(f"cost {t['name']!r}: scheduled weights cannot be mirrored in Crocoddyl")
            w = np.asarray(t["weights"], float) * scale
            act_w = crocoddyl.ActivationModelWeightedQuad(w)
            ref = t.get("reference")
            if t["kind"] == "frame_placement":
                r = ref[min(k, len(ref) - 1)]
                res = crocoddyl.ResidualModelFramePlacement(state, fid, _se3(r), nu)
            elif t["kind"] == "state":
                xr = state.zero() if ref is None else np.asarray(ref[min(k, len(ref) - 1)], float)
                res = crocoddyl.ResidualModelState(state, xr, nu)
            elif t["kind"] == "control":
                res = crocoddyl.ResidualModelControl(state, nu)
            else:
                raise ValueError(f"cost kind {t['kind']!r} has no Crocoddyl counterpart here")
            cs.addCost(t["name"], crocoddyl.CostModelResidual(state, act_w, res), 1.0)
        return cs

    running = []
    for k in range(n):
        dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(state, act, costs_for(problem.running, k, 2.0 / dt))
        running.append(crocoddyl.IntegratedActionModelEuler(dam, dt))
    dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(state, act, costs_for(problem.terminal, n, 2.0))
    terminal = crocoddyl.IntegratedActionModelEuler(dam, 0.0)
    x0 = np.asarray(problem.x0, float)
    shooting = crocoddyl.ShootingProblem(x0, running, terminal)
    try:
        shooting.nthreads = 1
    except AttributeError:
        pass
    return shooting


def solve_crocoddyl(shooting, us0, max_iter: int = 150, solver: str = "fddp"):
    """Solve with Crocoddyl's FDDP (or DDP) from the rollout of `us0`, counting iterations with a Python callback
    (untimed use only). Returns (solver, iterations, cost), iterations being the solver's loop iterations (one
    callback each, rejected steps included), as freefloat's `iterations` are."""
    s, c = count_crocoddyl(shooting, us0, max_iter, solver)
    return s, c["iterations"], c["cost"]


def count_crocoddyl(shooting, us0, max_iter: int = 150, solver: str = "fddp"):
    """The untimed counting run: loop iterations (callbacks), derivative evaluations (Crocoddyl recomputes the
    derivatives on its first iteration and after every accepted step: an iteration whose cost differs from the
    previous one's), the final cost and `solver.iter` (to check that the timed runs, which have no callback,
    followed the same path). Returns (solver, that dict)."""
    import crocoddyl

    s = crocoddyl.SolverFDDP(shooting) if solver == "fddp" else crocoddyl.SolverDDP(shooting)
    costs = []

    class _Count(crocoddyl.CallbackAbstract):
        def __init__(self):
            crocoddyl.CallbackAbstract.__init__(self)

        def __call__(self, solver):
            costs.append(float(solver.cost))

    s.setCallbacks([_Count()])
    us = [np.asarray(u, float) for u in us0]
    xs = shooting.rollout(us)
    c0 = float(shooting.calc(xs, us))
    s.solve(xs, us, max_iter, True)
    # iteration i accepted its step iff the cost moved; iteration i + 1 then recomputes the derivatives
    accepted = [c != p for p, c in zip([c0] + costs[:-1], costs)]
    diffs = 1 + sum(accepted[:-1])
    return s, {"iterations": len(costs), "calc_diff_calls": diffs, "cost": float(s.cost), "solver_iter": int(s.iter)}


def time_crocoddyl(shooting, us0, max_iter: int = 150, solver: str = "fddp"):
    """One timed solve as Crocoddyl's own C++ examples run it: C++ action models, no callback (no Python in the
    solve), single thread (`shooting.nthreads = 1`), the initial rollout outside the timed region. Returns
    (solver, wall s, CPU s)."""
    import crocoddyl

    s = crocoddyl.SolverFDDP(shooting) if solver == "fddp" else crocoddyl.SolverDDP(shooting)
    s.setCallbacks([])
    us = [np.asarray(u, float) for u in us0]
    xs = shooting.rollout(us)
    t0, c0 = time.perf_counter(), time.process_time()
    s.solve(xs, us, max_iter, True)
    return s, time.perf_counter() - t0, time.process_time() - c0


#: Crocoddyl's solvers timed as the peer; the faster per iteration that reaches the same cost is the reference
PEERS = ("fddp", "ddp")

OPTIONS = dict(
    variant="fddp",
    alphas=[0.5**k for k in range(10)],  # Crocoddyl's line search: 1, 1/2, ..., 1/512
    accept_ratio=0.1,  # Crocoddyl's th_acceptStep
    reg_init=1e-9,
    reg_min=1e-9,
    tol_expected=1e-9,  # Crocoddyl's th_stop on the expected improvement
    max_iter=150,
)


def truncate(p: ddp.Problem, n: int) -> ddp.Problem:
    """The first n steps of a problem (references cut to n + 1 nodes)."""
    if n >= p.horizon:
        return p

    def cut(terms):
        out = []
        for t in terms:
            t = dict(t)
            if "reference" in t and len(t["reference"]) > 1:
                t["reference"] = t["reference"][: n + 1]
            out.append(t)
        return out

    return replace(
        p,
        horizon=n,
        running=cut(p.running),
        terminal=cut(p.terminal),
        us0=p.us0[:n],
        reference_dq=p.reference_dq[: n + 1],
    )


def crocoddyl_blocks(solver, n: int, reps: int = 10) -> dict:
    """Per-node µs of Crocoddyl's calcDiff, backwardPass and forwardPass(1) at its solution (median of reps)."""
    out = {}
    for name, f in (
        ("calc_diff", lambda: solver.calcDiff()),
        ("backward", lambda: solver.backwardPass()),
        ("forward", lambda: solver.forwardPass(1.0)),
    ):
        ts = []
        for _ in range(reps):
            t0 = time.perf_counter()
            f()
            ts.append(time.perf_counter() - t0)
        out[name] = 1e6 * statistics.median(ts) / n
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="Directory for ddp_vs_crocoddyl.json and .md")
    ap.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    ap.add_argument("--quick", action="store_true", help="N = 80 and 1 repeat (smoke run)")
    ap.add_argument("--repeats", type=int, default=None)
    a = ap.parse_args(argv)
    reps = a.repeats or (1 if a.quick else 3)
    # the problem Crocoddyl's baseline solves: the 50 kg base of valverde_ch8_arm, torque-driven wrist
    prob = ddp.load_scenario(
        "valverde_ch8_tracking",
        cost="log",
        schedule=False,
        keep_out=False,
        initial_controls="zero",
        robot="valverde_ch8_arm",
        wrist="torque",
    )
    prob = truncate(prob, 80 if a.quick else prob.horizon)
    n = prob.horizon
    med = statistics.median

    def spread(x):
        return [min(x), max(x)]

    # Crocoddyl's two solvers; each is counted once, untimed (a Python callback per iteration), then timed
    # without any callback: the timed runs must end at the counted run's cost after as many iterations.
    shooting = {v: build_crocoddyl_problem(prob) for v in PEERS}
    counts = {}
    for v in PEERS:
        _, counts[v] = count_crocoddyl(shooting[v], prob.us0, OPTIONS["max_iter"], v)
    ff_t, ff_cpu, ff_it, ff_diffs, ff_cost, ff_blocks = [], [], [], [], [], []
    cr_t = {v: [] for v in PEERS}
    cr_cpu = {v: [] for v in PEERS}
    cr_solver = {}
    for r in range(reps):
        c0 = time.process_time()
        sol = ddp.solve(prob, **OPTIONS)
        ff_cpu.append(time.process_time() - c0)
        ff_t.append(sol["solve_time_s"])
        ff_it.append(sol["iterations"])
        ff_cost.append(sol["cost"])
        tm = sol["timings"]
        ff_diffs.append(tm["calc_diff_calls"])
        ff_blocks.append(
            {
                "calc_diff": 1e6 * tm["calc_diff_s"] / max(tm["calc_diff_calls"], 1) / n,
                "backward": 1e6 * tm["backward_s"] / max(tm["backward_calls"], 1) / n,
                "forward": 1e6 * tm["forward_s"] / max(tm["forward_calls"], 1) / n,
            }
        )
        line = f"repeat {r + 1}/{reps}: freefloat {ff_t[-1]:.3f} s ({ff_it[-1]} it, cost {ff_cost[-1]:.10g})"
        for v in PEERS:
            s, wall, cpu = time_crocoddyl(shooting[v], prob.us0, OPTIONS["max_iter"], v)
            if s.iter != counts[v]["solver_iter"] or float(s.cost) != counts[v]["cost"]:
                print(
                    f"Crocoddyl {v}: the timed run (iter {s.iter}, cost {s.cost!r}) differs from the counted one "
                    f"({counts[v]})",
                    file=sys.stderr,
                )
                return 1
            cr_t[v].append(wall)
            cr_cpu[v].append(cpu)
            cr_solver[v] = s
            line += f"; crocoddyl {v} {wall:.3f} s"
        print(line, flush=True)
    ffb = {k: med([b[k] for b in ff_blocks]) for k in ff_blocks[0]}
    ff_iter_ms = 1e3 * med(ff_t) / ff_it[-1]
    peers = {}
    for v in PEERS:
        c = counts[v]
        peers[v] = {
            "solver": "SolverFDDP" if v == "fddp" else "SolverDDP",
            "iterations": c["iterations"],
            "calc_diff_calls": c["calc_diff_calls"],
            "solver_iter": c["solver_iter"],
            "final_cost": c["cost"],
            "solve_s_median": med(cr_t[v]),
            "solve_s_spread": spread(cr_t[v]),
            "solve_cpu_s_median": med(cr_cpu[v]),
            "solve_cpu_s_spread": spread(cr_cpu[v]),
            "per_iteration_ms_median": 1e3 * med(cr_t[v]) / c["iterations"],
            "per_iteration_cpu_ms_median": 1e3 * med(cr_cpu[v]) / c["iterations"],
            "blocks_us_per_node": crocoddyl_blocks(cr_solver[v], n),
            "final_cost_rel": abs(ff_cost[-1] - c["cost"]) / abs(c["cost"]),
        }
    # the peer: the faster of Crocoddyl's solvers per iteration (CPU time), among those that reach freefloat's cost
    agreeing = [v for v in PEERS if peers[v]["final_cost_rel"] <= 1e-6] or list(PEERS)
    best = min(agreeing, key=lambda v: peers[v]["per_iteration_cpu_ms_median"])
    cr = peers[best]
    cb = cr["blocks_us_per_node"]
    rel = cr["final_cost_rel"]
    res = {
        "problem": {
            "scenario": "valverde_ch8_tracking",
            "robot": "valverde_ch8_arm",
            "wrist": "torque",
            "horizon": n,
            "dt": prob.dt,
            "pose_cost": "log",
            "weights": "Table 8.2 End (constant)",
            "start": "zero controls",
            "repeats": reps,
            "options": OPTIONS,
        },
        "freefloat": {
            "iterations": ff_it[-1],
            "calc_diff_calls": ff_diffs[-1],
            "final_cost": ff_cost[-1],
            "solve_s_median": med(ff_t),
            "solve_s_spread": spread(ff_t),
            "solve_cpu_s_median": med(ff_cpu),
            "solve_cpu_s_spread": spread(ff_cpu),
            "per_iteration_ms_median": ff_iter_ms,
            "per_iteration_cpu_ms_median": 1e3 * med(ff_cpu) / ff_it[-1],
            "blocks_us_per_node": ffb,
        },
        "crocoddyl": {**cr, "peer": best},
        "crocoddyl_solvers": peers,
        "agreement": {"final_cost_rel": rel, "iterations_freefloat_le_crocoddyl": ff_it[-1] <= cr["iterations"]},
        "ratios_freefloat_over_crocoddyl": {
            "total": med(ff_t) / cr["solve_s_median"],
            "total_cpu": med(ff_cpu) / cr["solve_cpu_s_median"],
            "per_repeat_wall": [f / c for f, c in zip(ff_t, cr_t[best])],
            "per_iteration": ff_iter_ms / cr["per_iteration_ms_median"],
            "per_iteration_cpu": (1e3 * med(ff_cpu) / ff_it[-1]) / cr["per_iteration_cpu_ms_median"],
            "per_calc_diff_call": (med(ff_t) / ff_diffs[-1]) / (cr["solve_s_median"] / cr["calc_diff_calls"]),
            **{f"block_{k}": ffb[k] / cb[k] for k in cb},
        },
        "load_average": list(os.getloadavg()),
    }
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "ddp_vs_crocoddyl.json").write_text(json.dumps(res, indent=2))
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1, default=str))
    ra = res["ratios_freefloat_over_crocoddyl"]
    md = [
        "# freefloat DDP vs Crocoddyl 3.2.1 (ch. 8 tracking, log-SE(3) cost, End weights, zero start)",
        "",
        f"N = {n}, dt = {prob.dt} s, {reps} interleaved repeats, single thread; times: median (min-max). "
        "Crocoddyl: C++ action models, no callback in the timed solves (iterations counted in a separate untimed "
        "run), `nthreads = 1`; iterations = solver loop iterations on both sides (derivative evaluations in "
        "brackets).",
        "",
        "| solver | iterations | final cost | solve [s] | solve CPU [s] | per iteration [ms] "
        "| calcDiff / backward / forward [µs per node] |",
        "|---|---|---|---|---|---|---|",
    ]
    rows = [("freefloat DDP", res["freefloat"])] + [
        (f"Crocoddyl {peers[v]['solver']}" + (" (peer)" if v == best else ""), peers[v]) for v in PEERS
    ]
    for name, s in rows:
        b = s["blocks_us_per_node"]
        md.append(
            f"| {name} | {s['iterations']} ({s['calc_diff_calls']}) | {s['final_cost']:.10g} | "
            f"{s['solve_s_median']:.3f} ({s['solve_s_spread'][0]:.3f}-{s['solve_s_spread'][1]:.3f}) | "
            f"{s['solve_cpu_s_median']:.3f} ({s['solve_cpu_s_spread'][0]:.3f}-{s['solve_cpu_s_spread'][1]:.3f}) | "
            f"{s['per_iteration_ms_median']:.1f} | "
            f"{b['calc_diff']:.1f} / {b['backward']:.1f} / {b['forward']:.1f} |"
        )
    md += [
        "",
        f"Final-cost agreement {rel:.2e} relative. Ratios freefloat/Crocoddyl {cr['solver']}: total {ra['total']:.2f} "
        f"(CPU time {ra['total_cpu']:.2f}; per repeat {min(ra['per_repeat_wall']):.2f}-"
        f"{max(ra['per_repeat_wall']):.2f}), per iteration {ra['per_iteration']:.2f} (CPU time "
        f"{ra['per_iteration_cpu']:.2f}), calcDiff {ra['block_calc_diff']:.2f}, backward "
        f"{ra['block_backward']:.2f}, forward {ra['block_forward']:.2f}. Load average at the end: "
        + ", ".join(f"{x:.2f}" for x in res["load_average"])
        + ".",
    ]
    (out / "ddp_vs_crocoddyl.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))
    if not rel <= 1e-6 or ff_it[-1] > cr["iterations"]:
        print(f"DISAGREEMENT: cost rel {rel:.3g}, iterations {ff_it[-1]} vs {cr['iterations']}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
