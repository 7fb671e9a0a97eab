#!/usr/bin/env python3
"""Receding-horizon DDP (MPC) on the chapter 8 tracking task (Valverde 2018, §8.7): how long does a re-plan take,
and does the controller still track? The documented command (docs/ddp.md §1)

    freefloat control ddp valverde_ch8_tracking --cost log --no-schedule --line-search backtracking \\
        --closed-loop --mpc --horizon 100 --replan 5 --model-error 0.1

runs, through the same Python calls as the CLI (offline solve with refreshed gains, then `ddp_closed_loop.run` in
mode 'mpc' on a plant with the last massive body 10 % heavier, RK4 at dt/5), on:

- `default`: the default scenario (1500 kg servicer, rate-driven wrist, keep-out on);
- `light_torque`: the issue's problem, the 50 kg base with the torque-driven wrist (`--robot valverde_ch8_arm
  --wrist torque`);
- `light_torque_no_keep_out`: the same without the keep-out term (`--no-keep-out`), the problem Crocoddyl can
  state; its re-plans are replayed by Crocoddyl 3.2.1's FDDP as the peer: the same windows (H = 100 nodes from the
  same task node), started from the same measured states, warm-started the same way (the first window from the
  offline solution with up to 50 iterations, then its own previous window shifted by K, the last node repeated),
  the same iteration budget (5) and initial regularisation (1e-6), single thread, no callback, followed by one
  `computeDirection` at the returned iterate (freefloat's re-plans refresh the gains there too).

Every re-plan's wall time comes from the engine (`DdpMpc.stats()['replan_times_s']`), its thread CPU time from
around the controller call that re-planned (a loaded machine inflates the wall time, not the CPU time); reported
over all re-plans of all repeats (the first re-plan of each run apart: it runs up to 50 iterations from the offline
plan and happens before the task starts): median, 95th percentile, slowest; and the tracking accuracy (end-effector
position and angle errors over the final 5 s hold, RMS over the run), which must not change from repeat to repeat.
Targets (issue 36): median re-plan <= 25 ms, slowest <= 50 ms (10x real time for the 0.25 s re-plan period).

    python benches/mpc_bench.py --out benches/results      # 3 interleaved repeats
    python benches/mpc_bench.py --quick --out /tmp/x       # 1 repeat, 160-node task (smoke)
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from freefloat.control import ddp  # noqa: E402
from freefloat.control import ddp_closed_loop as cl  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ddp_vs_crocoddyl import build_pinocchio_model, truncate  # noqa: E402

H, K, MPC_ITER, FIRST_ITER, MODEL_ERROR, SUBSTEPS = 100, 5, 5, 50, 0.1, 5
TARGET_MEDIAN_S, TARGET_MAX_S = 0.025, 0.050

#: name -> load_scenario keywords (the documented command's --cost log --no-schedule, plus the case's own flags)
CASES = {
    "default": dict(cost="log", schedule=False),
    "light_torque": dict(cost="log", schedule=False, robot="valverde_ch8_arm", wrist="torque"),
    "light_torque_no_keep_out": dict(
        cost="log", schedule=False, keep_out=False, robot="valverde_ch8_arm", wrist="torque"
    ),
}
PEER_CASE = "light_torque_no_keep_out"
BACKTRACKING = [0.5**k for k in range(10)]


def setup(name: str, nodes: int | None) -> dict:
    """The problem, the CLI's offline solve (backtracking, gains refreshed at the returned iterate) and the plant."""
    prob = ddp.load_scenario("valverde_ch8_tracking", **CASES[name])
    if nodes:
        prob = truncate(prob, nodes)
    sol = ddp.solve(prob, alphas=BACKTRACKING, refresh_gains=True)
    body = prob.model.body_names[-1 - len(prob.rate_joints)]  # the CLI's default error body
    plant = cl.perturbed_model(prob.model, MODEL_ERROR, body)
    return {"problem": prob, "solution": sol, "plant": plant, "error_body": body}


class _CpuTimedMpc:
    """`DdpMpc` with the thread CPU time of each re-plan (the calls at nodes 0, K, 2K, ...): unlike the engine's wall
    times it is not inflated when other processes share the cores."""

    def __init__(self, *args, **kw):
        from freefloat import _core

        self._mpc = _core.DdpMpc(*args, **kw)
        self.cpu = []

    def control(self, k, x):
        if k % K:
            return self._mpc.control(k, x)
        c0 = time.thread_time()
        u = self._mpc.control(k, x)
        self.cpu.append(time.thread_time() - c0)
        return u

    def __getattr__(self, name):
        return getattr(self._mpc, name)


def run_mpc(case: dict) -> dict:
    """One closed-loop MPC run as the CLI makes it; per-re-plan times and the tracking summary."""
    import types

    from freefloat import _core

    made = []

    def factory(*args, **kw):
        made.append(_CpuTimedMpc(*args, **kw))
        return made[-1]

    names = {n: getattr(_core, n) for n in dir(_core) if not n.startswith("__")}
    cl._core = types.SimpleNamespace(**{**names, "DdpMpc": factory})
    try:
        c0 = time.process_time()
        r = cl.run(
            case["problem"],
            "mpc",
            case["plant"],
            solution=case["solution"],
            substeps=SUBSTEPS,
            mpc_horizon=H,
            replan=K,
            mpc_options={"max_iter": MPC_ITER},
        )
        cpu = time.process_time() - c0
    finally:
        cl._core = _core
    s = cl.summary(r)
    st = r["mpc"]
    if len(made[0].cpu) != st["replans"]:
        raise RuntimeError(f"{len(made[0].cpu)} CPU-timed calls for {st['replans']} re-plans")
    return {
        "times": list(st["replan_times_s"]),
        "cpu_times": made[0].cpu,
        "iterations": list(st["replan_iterations"]),
        "replans": st["replans"],
        "troubled": st["troubled_replans"],
        "accuracy": {
            "final_hold_position_max_mm": 1e3 * s["ee_position_error_final_hold_max_m"],
            "final_hold_angle_max_deg": s["ee_angle_error_final_hold_max_deg"],
            "position_rms_mm": 1e3 * s["ee_position_error_rms_m"],
        },
        "closed_loop_wall_s": r["wall_time_s"],
        "closed_loop_cpu_s": cpu,
        "replan_nodes": [K * i for i in range(st["replans"])],
        "xs": r["xs"],
    }


# -- the Crocoddyl peer: the same re-plans, replayed -------------------------------------------------------------


class CrocoddylReplay:
    """Crocoddyl FDDP over the same windows as `DdpMpc` (node i of the window at task node k reads reference k + i,
    the last one holding; the terminal node reads k + H with the terminal weights), built from the hand-made
    Pinocchio model of ddp_vs_crocoddyl.py."""

    def __init__(self, prob):
        import crocoddyl

        self.prob = prob
        model = build_pinocchio_model()
        self.state = crocoddyl.StateMultibody(model)
        self.act = crocoddyl.ActuationModelFull(self.state)
        self.fid = model.getFrameId(prob.frame)
        self._running, self._terminal = {}, {}

    def _costs(self, terms, j, scale):
        import crocoddyl
        from ddp_vs_crocoddyl import _se3

        cs = crocoddyl.CostModelSum(self.state, self.act.nu)
        for t in terms:
            w = np.asarray(t["weights"], float) * scale
            act_w = crocoddyl.ActivationModelWeightedQuad(w)
            ref = t.get("reference")
            if t["kind"] == "frame_placement":
                res = crocoddyl.ResidualModelFramePlacement(
                    self.state, self.fid, _se3(ref[min(j, len(ref) - 1)]), self.act.nu
                )
            elif t["kind"] == "state":
                xr = self.state.zero() if ref is None else np.asarray(ref[min(j, len(ref) - 1)], float)
                res = crocoddyl.ResidualModelState(self.state, xr, self.act.nu)
            elif t["kind"] == "control":
                res = crocoddyl.ResidualModelControl(self.state, self.act.nu)
            else:
                raise ValueError(t["kind"])
            cs.addCost(t["name"], crocoddyl.CostModelResidual(self.state, act_w, res), 1.0)
        return cs

    def running(self, j):
        import crocoddyl

        if j not in self._running:
            dt = self.prob.dt
            dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(
                self.state, self.act, self._costs(self.prob.running, j, 2.0 / dt)
            )
            self._running[j] = crocoddyl.IntegratedActionModelEuler(dam, dt)
        return self._running[j]

    def terminal(self, j):
        import crocoddyl

        if j not in self._terminal:
            dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(
                self.state, self.act, self._costs(self.prob.terminal, j, 2.0)
            )
            self._terminal[j] = crocoddyl.IntegratedActionModelEuler(dam, 0.0)
        return self._terminal[j]

    def replay(self, nodes, states, guess_xs, guess_us) -> dict:
        """Solve the window at each task node of `nodes` from the matching state; returns the wall times."""
        import crocoddyl

        times, cpu, iters, prev = [], [], [], None
        for k, x in zip(nodes, states):
            shooting = crocoddyl.ShootingProblem(
                np.asarray(x, float), [self.running(k + j) for j in range(H)], self.terminal(k + H)
            )
            shooting.nthreads = 1
            if prev is None:  # the first window: the offline solution from node k
                xs = [np.asarray(guess_xs[min(k + j, len(guess_xs) - 1)], float) for j in range(H + 1)]
                us = [np.asarray(guess_us[min(k + j, len(guess_us) - 1)], float) for j in range(H)]
                budget = FIRST_ITER
            else:  # the previous window shifted by the nodes elapsed, the last node repeated
                d = k - prev[0]
                xs = [prev[1][min(j + d, H)] for j in range(H + 1)]
                us = [prev[2][min(j + d, H - 1)] for j in range(H)]
                budget = MPC_ITER
            xs[0] = np.asarray(x, float).copy()
            s = crocoddyl.SolverFDDP(shooting)
            s.setCallbacks([])
            t0, c0 = time.perf_counter(), time.thread_time()
            s.solve(xs, us, budget, False, 1e-6)
            s.computeDirection(True)  # gains at the returned iterate, as DdpMpc's re-plans refresh them
            times.append(time.perf_counter() - t0)
            cpu.append(time.thread_time() - c0)
            iters.append(int(s.iter))
            prev = (k, [np.array(v) for v in s.xs], [np.array(v) for v in s.us])
        return {"times": times, "cpu_times": cpu, "solver_iter": iters}


def stats(times: list) -> dict:
    t = np.asarray(times, float)
    return {
        "count": int(t.size),
        "median_ms": 1e3 * float(np.median(t)),
        "p95_ms": 1e3 * float(np.percentile(t, 95)),
        "max_ms": 1e3 * float(t.max()),
        "min_ms": 1e3 * float(t.min()),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="Directory for mpc_bench.json and .md")
    ap.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    ap.add_argument("--quick", action="store_true", help="1 repeat, the first 160 nodes of the task (smoke run)")
    ap.add_argument("--repeats", type=int, default=None)
    ap.add_argument("--no-peer", action="store_true", help="skip the Crocoddyl replay")
    a = ap.parse_args(argv)
    reps = a.repeats or (1 if a.quick else 3)
    nodes = 160 if a.quick else None
    try:
        import crocoddyl  # noqa: F401

        peer = not a.no_peer
    except ImportError:
        peer = False
    cases = {name: setup(name, nodes) for name in CASES}
    runs = {name: [] for name in CASES}
    peer_runs = []
    replay = CrocoddylReplay(cases[PEER_CASE]["problem"]) if peer else None
    for r in range(reps):
        line = f"repeat {r + 1}/{reps}:"
        for name, case in cases.items():
            out = run_mpc(case)
            runs[name].append(out)
            line += f" {name} median {1e3 * statistics.median(out['times'][1:]):.1f} ms"
            if peer and name == PEER_CASE:
                sol = case["solution"]
                states = [out["xs"][k] for k in out["replan_nodes"]]
                pr = replay.replay(out["replan_nodes"], states, sol["xs"], sol["us"])
                peer_runs.append(pr)
                line += f" (Crocoddyl {1e3 * statistics.median(pr['times'][1:]):.1f} ms)"
        print(line, flush=True)
    res = {
        "problem": {
            "scenario": "valverde_ch8_tracking",
            "command": "freefloat control ddp valverde_ch8_tracking --cost log --no-schedule --line-search "
            "backtracking --closed-loop --mpc --horizon 100 --replan 5 --model-error 0.1",
            "task_nodes": cases["default"]["problem"].horizon,
            "dt": cases["default"]["problem"].dt,
            "mpc_horizon": H,
            "replan_every": K,
            "iterations_per_replan": MPC_ITER,
            "first_replan_iterations": FIRST_ITER,
            "model_error": MODEL_ERROR,
            "repeats": reps,
            "targets_ms": {"median": 1e3 * TARGET_MEDIAN_S, "max": 1e3 * TARGET_MAX_S},
        },
        "cases": {},
        "load_average": list(os.getloadavg()),
    }
    ok = True
    for name, rs in runs.items():
        later = [t for o in rs for t in o["times"][1:]]
        later_cpu = [t for o in rs for t in o["cpu_times"][1:]]
        first = [o["times"][0] for o in rs]
        acc = [o["accuracy"] for o in rs]
        same = all(x == acc[0] for x in acc)
        ok &= same
        st = stats(later)
        res["cases"][name] = {
            "load_scenario": CASES[name],
            "robot": cases[name]["problem"].model.name,
            "rate_joints": list(cases[name]["problem"].rate_joints),
            "error_body": cases[name]["error_body"],
            "offline_iterations": int(cases[name]["solution"]["iterations"]),
            "replans_per_run": rs[0]["replans"],
            "iterations_per_run": sum(rs[0]["iterations"]),
            "troubled_replans": rs[0]["troubled"],
            "replan_ms": st,
            "replan_cpu_ms": stats(later_cpu),
            "replan_median_ms_per_repeat": [1e3 * statistics.median(o["times"][1:]) for o in rs],
            "replan_max_ms_per_repeat": [1e3 * max(o["times"][1:]) for o in rs],
            "first_replan_ms": [1e3 * t for t in first],
            "solve_s_per_run": [sum(o["times"]) for o in rs],
            "closed_loop_wall_s": [o["closed_loop_wall_s"] for o in rs],
            "closed_loop_cpu_s": [o["closed_loop_cpu_s"] for o in rs],
            "accuracy": acc[0],
            "accuracy_same_in_every_repeat": same,
            "targets_met": {
                "median": st["median_ms"] <= 1e3 * TARGET_MEDIAN_S,
                "max": st["max_ms"] <= 1e3 * TARGET_MAX_S,
            },
        }
    if peer_runs:
        later = [t for p in peer_runs for t in p["times"][1:]]
        res["crocoddyl_replay"] = {
            "case": PEER_CASE,
            "solver": "crocoddyl.SolverFDDP 3.2.1, nthreads 1, no callback, init_reg 1e-6, + computeDirection",
            "replan_ms": stats(later),
            "replan_cpu_ms": stats([t for p in peer_runs for t in p["cpu_times"][1:]]),
            "first_replan_ms": [1e3 * p["times"][0] for p in peer_runs],
            "solver_iter_per_run": sum(peer_runs[0]["solver_iter"]),
        }
        ff = res["cases"][PEER_CASE]["replan_ms"]
        res["crocoddyl_replay"]["ratio_median_freefloat_over_crocoddyl"] = (
            ff["median_ms"] / res["crocoddyl_replay"]["replan_ms"]["median_ms"]
        )
        ffc, crc = res["cases"][PEER_CASE]["replan_cpu_ms"], res["crocoddyl_replay"]["replan_cpu_ms"]
        res["crocoddyl_replay"]["ratio_median_cpu_freefloat_over_crocoddyl"] = ffc["median_ms"] / crc["median_ms"]
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "mpc_bench.json").write_text(json.dumps(res, indent=2))
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1, default=str))
    p = res["problem"]
    md = [
        "# MPC on the ch. 8 tracking task: re-plan times and tracking (docs/ddp.md §1)",
        "",
        f"`{p['command']}`; task N = {p['task_nodes']}, window H = {H}, re-plan every {K} nodes "
        f"({K * p['dt']:.2f} s), {MPC_ITER} iterations per re-plan, plant +{100 * MODEL_ERROR:g} % mass on the "
        f"error body, RK4 at dt/{SUBSTEPS}; {reps} interleaved repeats. Re-plan times over all re-plans of all "
        "repeats, the first of each run apart (up to 50 iterations from the offline plan, before the task starts). "
        f"Targets: median <= {1e3 * TARGET_MEDIAN_S:g} ms, slowest <= {1e3 * TARGET_MAX_S:g} ms.",
        "",
        "| case | re-plans x repeats | iterations / run | re-plan median / p95 / slowest [ms] | CPU time: median / "
        "p95 / slowest [ms] | first re-plan [ms] | final hold: position / angle (max) | position RMS | targets |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, c in res["cases"].items():
        s, sc, acc = c["replan_ms"], c["replan_cpu_ms"], c["accuracy"]
        md.append(
            f"| {name} ({c['robot']}{', rate wrist' if c['rate_joints'] else ', torque wrist'}) | "
            f"{c['replans_per_run']} x {reps} | {c['iterations_per_run']} | "
            f"{s['median_ms']:.1f} / {s['p95_ms']:.1f} / {s['max_ms']:.1f} | "
            f"{sc['median_ms']:.1f} / {sc['p95_ms']:.1f} / {sc['max_ms']:.1f} | "
            f"{statistics.median(c['first_replan_ms']):.0f} | "
            f"{acc['final_hold_position_max_mm']:.1f} mm / {acc['final_hold_angle_max_deg']:.3f}° | "
            f"{acc['position_rms_mm']:.1f} mm | "
            f"{'met' if all(c['targets_met'].values()) else 'MISSED'} |"
        )
    if "crocoddyl_replay" in res:
        cr = res["crocoddyl_replay"]
        s = cr["replan_ms"]
        md += [
            "",
            f"Peer, {cr['case']}: Crocoddyl 3.2.1 FDDP replaying the same re-plans (same windows, start states, "
            f"warm start, iteration budget; gains recomputed at the returned iterate): median / p95 / slowest "
            f"{s['median_ms']:.1f} / {s['p95_ms']:.1f} / {s['max_ms']:.1f} ms (CPU time "
            f"{cr['replan_cpu_ms']['median_ms']:.1f} / {cr['replan_cpu_ms']['p95_ms']:.1f} / "
            f"{cr['replan_cpu_ms']['max_ms']:.1f} ms), first {statistics.median(cr['first_replan_ms']):.0f} ms; "
            f"freefloat/Crocoddyl median {cr['ratio_median_freefloat_over_crocoddyl']:.2f} (CPU time "
            f"{cr['ratio_median_cpu_freefloat_over_crocoddyl']:.2f}).",
        ]
    md += ["", "Load average at the end: " + ", ".join(f"{x:.2f}" for x in res["load_average"]) + "."]
    (out / "mpc_bench.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))
    if not ok:
        print("the tracking accuracy changed between repeats", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
