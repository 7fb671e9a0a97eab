#!/usr/bin/env python3
"""freefloat's DDP against Crocoddyl 3.2.1 on the identical chapter 8 tracking problem (Valverde 2018, §8.7):
valverde_ch8_arm, log-SE(3) pose cost, constant Table 8.2 End weights, semi-implicit Euler, zero-control start,
backtracking line search. Both solvers run interleaved (repeats), single thread; reported: iterations, final cost
(agreement), total solve and per-iteration time (median, min-max), and the per-node cost of each block
(derivatives, backward pass, forward rollout). Aborts (exit 1) if the final costs differ by more than 1e-6
relative or freefloat needs more iterations.

    python benches/ddp_vs_crocoddyl.py --out benches/results          # full problem (N = 640), 3 repeats
    python benches/ddp_vs_crocoddyl.py --quick --out /tmp/x          # N = 80, 1 repeat (CI smoke)

freefloat's step Jacobians are still central finite differences (temporary, until the analytic ABA derivatives
land), so its derivative block is expected to be far slower than Crocoddyl's analytic one; the backward and forward
blocks are the solver's own.
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

from freefloat.control import ddp  # noqa: E402
from freefloat.control import ddp_crocoddyl as dc  # noqa: E402

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
    ap.add_argument("--quick", action="store_true", help="N = 80 and 1 repeat (smoke run)")
    ap.add_argument("--repeats", type=int, default=None)
    a = ap.parse_args(argv)
    reps = a.repeats or (1 if a.quick else 3)
    prob = ddp.load_scenario(
        "valverde_ch8_tracking", cost="log", schedule=False, keep_out=False, initial_controls="zero"
    )
    prob = truncate(prob, 80 if a.quick else prob.horizon)
    n = prob.horizon
    ff_t, cr_t, ff_it, cr_it, ff_cost, cr_cost, ff_blocks = [], [], [], [], [], [], []
    cr_solver = None
    for r in range(reps):
        sol = ddp.solve(prob, **OPTIONS)
        ff_t.append(sol["solve_time_s"])
        ff_it.append(sol["iterations"])
        ff_cost.append(sol["cost"])
        tm = sol["timings"]
        ff_blocks.append(
            {
                "calc_diff": 1e6 * tm["calc_diff_s"] / max(tm["calc_diff_calls"], 1) / n,
                "backward": 1e6 * tm["backward_s"] / max(tm["backward_calls"], 1) / n,
                "forward": 1e6 * tm["forward_s"] / max(tm["forward_calls"], 1) / n,
            }
        )
        shooting = dc.build_crocoddyl_problem(prob)
        t0 = time.perf_counter()
        cr_solver, it, c = dc.solve_crocoddyl(shooting, prob.us0, OPTIONS["max_iter"])
        cr_t.append(time.perf_counter() - t0)
        cr_it.append(it)
        cr_cost.append(c)
        print(
            f"repeat {r + 1}/{reps}: freefloat {ff_t[-1]:.2f} s ({ff_it[-1]} it, cost {ff_cost[-1]:.10g}); "
            f"crocoddyl {cr_t[-1]:.2f} s ({cr_it[-1]} it, cost {cr_cost[-1]:.10g})",
            flush=True,
        )
    cb = crocoddyl_blocks(cr_solver, n)
    med = statistics.median

    def spread(x):
        return [min(x), max(x)]

    rel = abs(ff_cost[-1] - cr_cost[-1]) / abs(cr_cost[-1])
    ffb = {k: med([b[k] for b in ff_blocks]) for k in ff_blocks[0]}
    res = {
        "problem": {
            "scenario": "valverde_ch8_tracking",
            "horizon": n,
            "dt": prob.dt,
            "pose_cost": "log",
            "weights": "Table 8.2 End (constant)",
            "start": "zero controls",
            "repeats": reps,
        },
        "freefloat": {
            "iterations": ff_it[-1],
            "final_cost": ff_cost[-1],
            "solve_s_median": med(ff_t),
            "solve_s_spread": spread(ff_t),
            "per_iteration_ms_median": 1e3 * med(ff_t) / ff_it[-1],
            "blocks_us_per_node": ffb,
        },
        "crocoddyl": {
            "iterations": cr_it[-1],
            "final_cost": cr_cost[-1],
            "solve_s_median": med(cr_t),
            "solve_s_spread": spread(cr_t),
            "per_iteration_ms_median": 1e3 * med(cr_t) / cr_it[-1],
            "blocks_us_per_node": cb,
        },
        "agreement": {"final_cost_rel": rel, "iterations_freefloat_le_crocoddyl": ff_it[-1] <= cr_it[-1]},
        "ratios_freefloat_over_crocoddyl": {
            "total": med(ff_t) / med(cr_t),
            "per_iteration": (med(ff_t) / ff_it[-1]) / (med(cr_t) / cr_it[-1]),
            **{f"block_{k}": ffb[k] / cb[k] for k in cb},
        },
    }
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "ddp_vs_crocoddyl.json").write_text(json.dumps(res, indent=2))
    ra = res["ratios_freefloat_over_crocoddyl"]
    md = [
        "# freefloat DDP vs Crocoddyl 3.2.1 (ch. 8 tracking, log-SE(3) cost, End weights, zero start)",
        "",
        f"N = {n}, dt = {prob.dt} s, {reps} interleaved repeats, single thread; times: median (min-max).",
        "",
        "| solver | iterations | final cost | solve [s] | per iteration [ms] "
        "| calcDiff / backward / forward [µs per node] |",
        "|---|---|---|---|---|---|",
    ]
    for name, key in (("freefloat (FD step Jacobians)", "freefloat"), ("Crocoddyl FDDP", "crocoddyl")):
        s = res[key]
        b = s["blocks_us_per_node"]
        md.append(
            f"| {name} | {s['iterations']} | {s['final_cost']:.10g} | {s['solve_s_median']:.3f} "
            f"({s['solve_s_spread'][0]:.3f}-{s['solve_s_spread'][1]:.3f}) | {s['per_iteration_ms_median']:.1f} | "
            f"{b['calc_diff']:.1f} / {b['backward']:.1f} / {b['forward']:.1f} |"
        )
    md += [
        "",
        f"Final-cost agreement {rel:.2e} relative. Ratios freefloat/Crocoddyl: total {ra['total']:.2f}, per "
        f"iteration {ra['per_iteration']:.2f}, calcDiff {ra['block_calc_diff']:.2f}, backward "
        f"{ra['block_backward']:.2f}, forward {ra['block_forward']:.2f}.",
    ]
    (out / "ddp_vs_crocoddyl.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))
    if not rel <= 1e-6 or ff_it[-1] > cr_it[-1]:
        print(f"DISAGREEMENT: cost rel {rel:.3g}, iterations {ff_it[-1]} vs {cr_it[-1]}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
