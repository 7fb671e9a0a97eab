#!/usr/bin/env python3
"""Cost of the orbital environment: the seed robots simulated with internal joint torques, without an
environment and with the gravity gradient (and with gravity gradient + J2) in a 500 km orbit, interleaved
repeats, medians and spread; the ratio to the same run without the environment is the figure of merit
(target: within 1.5x). The runs are pure engine runs (torque table, no Python callbacks).

    python benches/environment_bench.py            # full: 20 s simulated at dt = 1 ms, 7 repeats
    python benches/environment_bench.py --quick    # smoke: 1 s simulated, 2 repeats

Writes environment_bench.json and environment_bench.md into --out (default benches/results)."""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

import numpy as np

import freefloat as ff

MODELS = ["naveen_dual_arm", "valverde_ch9_two_arm", "zhang2020_3d"]


def _torques(m, t_final, dt):
    t = np.arange(0.0, t_final + dt, 0.01)
    tau = np.zeros((len(t), m.nv))
    k = np.arange(m.nv - 6)
    tau[:, 6:] = 0.5 * np.sin(np.outer(t, 0.5 + 0.1 * k) + k)
    return t, tau


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="1 s simulated, 2 repeats (CI smoke run)")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "results"), help="output folder")
    ap.add_argument("--repeats", type=int, default=None, help="interleaved repeats (default 7, quick 2)")
    args = ap.parse_args()
    t_final, dt = (1.0, 1e-3) if args.quick else (20.0, 1e-3)
    repeats = args.repeats or (2 if args.quick else 7)
    cases = {
        "none": None,
        "gravity_gradient": ff.Environment(altitude=500e3, inclination=0.9, gravity_gradient=True),
        "gravity_gradient_j2": ff.Environment(altitude=500e3, inclination=0.9, gravity_gradient=True, j2=True),
    }
    results, agreement = {}, {}
    load0 = [round(x, 2) for x in os.getloadavg()]
    print(f"{t_final} s at dt = {dt} s, {repeats} interleaved repeats, load average {load0} (1/5/15 min)")
    for name in MODELS:
        m = ff.models.load(name)
        tt, tau = _torques(m, t_final, dt)
        q0, v0 = m.neutral(), np.zeros(m.nv)

        def run(env, m=m, tt=tt, tau=tau, q0=q0, v0=v0):
            return ff.simulate(m, q0, v0, t_final, dt, torques=tau, torque_times=tt, record_every=100, environment=env)

        # an environment that is off is the environment-free run bit for bit
        a, b = run(None), run(ff.Environment())
        agreement[name] = {"off_bitwise_equal": bool(np.array_equal(a.q, b.q) and np.array_equal(a.v, b.v))}
        times = {c: [] for c in cases}
        order = list(cases)
        for r in range(repeats):
            # interleaved: each repeat runs every case once, the order rotated from repeat to repeat
            for c in order[r % len(order) :] + order[: r % len(order)]:
                t0 = time.perf_counter()
                run(cases[c])
                times[c].append(time.perf_counter() - t0)
        base = statistics.median(times["none"])
        results[name] = {}
        for c, v in times.items():
            ratios = [a / b for a, b in zip(v, times["none"])]  # per repeat, against that repeat's run without
            results[name][c] = {
                "median_s": statistics.median(v),
                "min_s": min(v),
                "max_s": max(v),
                "ratio_to_none": statistics.median(ratios),
                "ratio_min": min(ratios),
                "ratio_max": max(ratios),
            }
        print(
            f"{name:24s} none {base * 1e3:8.1f} ms   "
            + "   ".join(
                f"{c} x{results[name][c]['ratio_to_none']:.3f} "
                f"({results[name][c]['ratio_min']:.3f}..{results[name][c]['ratio_max']:.3f})"
                for c in cases
                if c != "none"
            ),
            flush=True,
        )
    load1 = [round(x, 2) for x in os.getloadavg()]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    doc = {
        "t_final": t_final,
        "dt": dt,
        "repeats": repeats,
        "quick": args.quick,
        "results": results,
        "agreement": agreement,
        "target_ratio": 1.5,
        "load_before": load0,
        "load_after": load1,
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
    }
    (out / "environment_bench.json").write_text(json.dumps(doc, indent=2))
    lines = [
        "# Orbital environment cost (ratio to the same run without it)",
        "",
        f"{doc['date_utc']} UTC, load average {load0} before, {load1} after (1/5/15 min).",
        f"{t_final} s simulated at dt = {dt} s (RK4), {repeats} interleaved repeats: median of the per-repeat ratio "
        "to the run without (its min..max), and the run's median time.",
        "",
        "| model | none (ms) | gravity gradient | gravity gradient + J2 |",
        "|---|---|---|---|",
    ]
    for name, r in results.items():
        cells = [
            f"x{r[c]['ratio_to_none']:.3f} ({r[c]['ratio_min']:.3f}..{r[c]['ratio_max']:.3f}), "
            f"{r[c]['median_s'] * 1e3:.0f} ms"
            for c in ("gravity_gradient", "gravity_gradient_j2")
        ]
        lines.append(f"| {name} | {r['none']['median_s'] * 1e3:.1f} | {cells[0]} | {cells[1]} |")
    (out / "environment_bench.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    if not all(a["off_bitwise_equal"] for a in agreement.values()):
        print("an environment that is off changed the run")
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
