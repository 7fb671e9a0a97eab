#!/usr/bin/env python3
"""The capture mission's wall time, phase by phase: is a 120 s mission with MPC in the loop faster than 10 s?

Problem: the built-in mission `zhang2020_3d_capture` (grasp, detumble + online identification from the sensors,
berth), with the berth lengthened so that grasp-to-berth-end is 120 s of mission time and the berth driven by
receding-horizon DDP (MPC: a 5 s window re-planned every 0.25 s, shrinking at the berth's end) on the true plant:
by default the adaptive berth (MPC from the identified model, re-planning on the estimate the berth's telemetry
refines every 1 s), `--berth frozen` the identified model kept.

There is no peer: no library runs this mission (Pinocchio, Crocoddyl, MuJoCo and Basilisk each do one part), so the
figure is the absolute wall time against the issue's target (10 s on this machine), with each phase's share. The
mission's own comparison runs (the berth with the nominal and the true models) are not part of "the mission" and
are timed apart. Repeats are medians; the spread is printed.

    python benches/mission_bench.py            # 3 repeats
    python benches/mission_bench.py --quick    # 1 repeat, 30 s mission, checks only
    python benches/mission_bench.py --berth frozen   # MPC on the identified model, no online updates
    python benches/mission_bench.py --out DIR  # write mission_bench.{json,md} there (default benches/results)
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from freefloat import mission as fm
from freefloat.mission import adaptive_berth, phases


def one_run(total_s: float, controller: str, adaptive: bool = True) -> dict:
    m = fm.load_mission("zhang2020_3d_capture")
    t = {}
    t0 = time.perf_counter()
    truth = phases.load_truth(m)
    cap = phases.capture(m, truth)
    t["capture"] = time.perf_counter() - t0
    sc = phases.detumble_scenario(m, cap["q"], cap["v_post"], truth)
    ident = phases.identify_online(m, truth, sc)
    t["detumble_simulation"] = ident["timings"]["simulation_s"]
    t["identification"] = ident["timings"]["identification_s"]
    berth = {**phases.DEFAULT_BERTH, **m.berth, "controller": controller}
    berth["duration"] = round((total_s - ident["handover_time"]) / berth["dt"]) * berth["dt"]
    q_h, v_h = ident["handover_state"]
    ref7 = phases.berth_reference(truth, q_h, berth)
    t0 = time.perf_counter()
    model = phases.identified_model(truth, ident)
    observer, spent = None, [0.0]
    if adaptive:
        est = adaptive_berth.BerthEstimator(truth, ident, {**adaptive_berth.DEFAULTS, **berth})

        def observer(k, seg):  # the estimator's own time, apart from the MPC's
            t1 = time.perf_counter()
            try:
                return est(k, seg)
            finally:
                spent[0] += time.perf_counter() - t1

    if adaptive:
        berth = {**adaptive_berth.DEFAULTS, **berth}
    r = phases.berth_run(model, truth, np.r_[q_h, v_h], ref7, berth, "identified", observer=observer)
    s = r["summary"]
    t["berth_plan"] = s["solve_s"]
    t["berth_closed_loop"] = s["closed_loop_s"] - spent[0]
    if adaptive:
        t["berth_online_estimator"] = spent[0]
    t["berth_total"] = time.perf_counter() - t0
    mission_wall = t["capture"] + t["detumble_simulation"] + t["identification"] + t["berth_total"]
    return {
        "timings": t,
        "mission_wall_s": mission_wall,
        "mission_time_s": ident["handover_time"] + berth["duration"],
        "handover_s": ident["handover_time"],
        "berth_s": berth["duration"],
        "detumble_simulated_s": sc.duration,
        "position_error_final_m": s["position_error_final_m"],
        "mpc": s.get("mpc"),
        "model_updates": (s.get("mpc") or {}).get("model_updates", 0),
        "momentum_error_relative": cap["momentum_error_relative"],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeats", type=int, default=None)
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "results"))
    ap.add_argument(
        "--berth",
        choices=("adaptive", "frozen"),
        default="adaptive",
        help="adaptive: MPC re-planning on the online estimate (default); frozen: MPC on the handover's estimate",
    )
    a = ap.parse_args()
    total = 30.0 if a.quick else 120.0
    reps = a.repeats or (1 if a.quick else 3)
    runs = [one_run(total, "mpc", a.berth == "adaptive") for _ in range(reps)]
    # checks: the grasp conserves momentum, the berth reaches its pose
    for r in runs:
        assert r["momentum_error_relative"] < 1e-12, r["momentum_error_relative"]
        assert r["position_error_final_m"] < 0.01, r["position_error_final_m"]
    walls = [r["mission_wall_s"] for r in runs]
    phases_med = {k: statistics.median(r["timings"][k] for r in runs) for k in runs[0]["timings"]}
    share = {k: v / statistics.median(walls) for k, v in phases_med.items() if k != "berth_total"}
    dominant = max(share, key=share.get)
    res = {
        "machine": {"cpu_count": __import__("os").cpu_count(), "python": platform.python_version()},
        "quick": a.quick,
        "repeats": reps,
        "mission_time_s": runs[0]["mission_time_s"],
        "handover_s": runs[0]["handover_s"],
        "mission_wall_s_median": statistics.median(walls),
        "mission_wall_s_min": min(walls),
        "mission_wall_s_max": max(walls),
        "target_s": 10.0,
        "met": statistics.median(walls) < 10.0,
        "phase_median_s": phases_med,
        "phase_share": share,
        "dominant_phase": dominant,
        "berth": a.berth,
        "model_updates": runs[0]["model_updates"],
        "mpc": runs[0]["mpc"],
        "detumble_simulated_s": runs[0]["detumble_simulated_s"],
    }
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "mission_bench.json").write_text(json.dumps(res, indent=1))
    lines = [
        f"# Capture mission wall time (zhang2020_3d_capture, MPC berth: {a.berth})",
        "",
        f"mission time {res['mission_time_s']:.1f} s (handover at {res['handover_s']:.1f} s); wall time median "
        f"{res['mission_wall_s_median']:.2f} s (min {res['mission_wall_s_min']:.2f}, "
        f"max {res['mission_wall_s_max']:.2f}, "
        f"{reps} repeats); target < 10 s: {'met' if res['met'] else 'NOT met'}",
        "",
        "| phase | median s | share |",
        "|---|---|---|",
    ]
    for k, v in phases_med.items():
        # berth_total sums the berth's phases above it: it has no share of its own
        lines.append(f"| {k} | {v:.3f} | {f'{share[k]:.0%}' if k in share else '(sum of the berth rows)'} |")
    lines += ["", f"dominant phase: {dominant}; model updates {res['model_updates']}; MPC: {res['mpc']}"]
    (out / "mission_bench.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
