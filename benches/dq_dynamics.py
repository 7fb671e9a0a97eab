#!/usr/bin/env python3
"""Cost per evaluation of the dual-quaternion formulation (`ff.dq_dynamics`, Valverde 2018 ch. 6) against the
engine's ABA, and ABA + one RNEA pass (what the recursive engine needs to give the same joint wrenches).

Each call is timed on a stacked batch of N random states (one Rust loop, GIL released), divided by N, so
Python overhead is amortised; median of R interleaved repeats. Robots: the built-in thesis chapter 5 single
arm (4 bodies) and chapter 7 two-arm spacecraft (11 bodies), and free-base random revolute trees of 5-60
bodies (each body hangs from a random earlier one among the last three, so the trees branch).
Before timing, dq_dynamics is checked against ABA (abort above 1e-9 relative).

    python benches/dq_dynamics.py [--quick] [--out benches/results]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import freefloat as ff


def random_tree_yaml(n: int, seed: int) -> str:
    rng = np.random.default_rng(seed)
    lines = [
        f"name: bench_tree_{n}",
        "base: free",
        "gravity: [0, 0, 0]",
        "bodies:",
        "  - name: b0",
        "    inertial: {mass: 50, com: [0.1, 0, 0], inertia: [10, 12, 9]}",
    ]
    for i in range(1, n):
        parent = int(rng.integers(max(0, i - 3), i))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        xyz = rng.uniform(-1, 1, size=3)
        lines += [
            f"  - name: b{i}",
            f"    parent: b{parent}",
            "    joint: {type: revolute, axis: [" + ", ".join(f"{a:.6f}" for a in axis) + "]}",
            "    origin: {xyz: [" + ", ".join(f"{a:.6f}" for a in xyz) + "], rpy: [0, 0, 0]}",
            "    inertial: {mass: 2, com: [0.2, 0.05, 0], inertia: [0.3, 0.4, 0.5]}",
        ]
    return "\n".join(lines) + "\n"


def states(m, n, rng):
    Q = np.stack([m.random_configuration(rng) for _ in range(n)])
    V = rng.normal(size=(n, m.nv))
    T = rng.normal(size=(n, m.nv))
    return Q, V, T


def timed(f, reps):
    out = []
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        out.append(time.perf_counter() - t0)
    return out


def bench(m, n, reps, rng):
    Q, V, T = states(m, n, rng)
    a, W = ff.dq_dynamics(m, Q, V, T)
    ref = ff.aba(m, Q, V, T)
    err = np.linalg.norm(a - ref) / np.linalg.norm(ref)
    if err > 1e-9:
        raise SystemExit(f"{m.name}: dq_dynamics differs from aba by {err:e}")
    fns = {
        "dq": lambda: ff.dq_dynamics(m, Q, V, T),
        "decoupled": lambda: ff.dq_dynamics(m, Q, V, T, formulation="decoupled"),
        "aba": lambda: ff.aba(m, Q, V, T),
        "aba+rnea": lambda: ff.rnea(m, Q, V, ff.aba(m, Q, V, T)),
    }
    res = {k: [] for k in fns}
    for _ in range(reps):  # interleaved
        for k, f in fns.items():
            res[k] += timed(f, 1)
    return {k: 1e6 * float(np.median(v)) / n for k, v in res.items()}, err


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results"))
    ap.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    args = ap.parse_args()
    n, reps = (200, 3) if args.quick else (2000, 7)
    rng = np.random.default_rng(1)
    rows = []
    robots = [ff.models.load("valverde_ch5_single_arm"), ff.models.load("valverde_ch7_two_arm")]
    robots += [ff.Model.from_yaml_string(random_tree_yaml(k, k)) for k in (5, 10, 20, 40, 60)]
    for m in robots:
        t, err = bench(m, n, reps, rng)
        rows.append((m.name, m.nbodies, m.nv, t["dq"], t["decoupled"], t["aba"], t["aba+rnea"], err))
        print(
            f"{m.name:28s} bodies {m.nbodies:3d}  dq {t['dq']:8.2f} us  decoupled {t['decoupled']:8.2f} us  "
            f"aba {t['aba']:7.2f} us  aba+rnea {t['aba+rnea']:7.2f} us  err {err:.1e}"
        )
    md = [
        "| robot | bodies | nv | dq_dynamics [µs] | decoupled (dense) [µs] | ABA [µs] | ABA + RNEA [µs] "
        "| dq / (ABA+RNEA) | dq / decoupled | dq vs ABA rel. diff |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        md.append(
            f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:.2f} | {r[4]:.2f} | {r[5]:.2f} | {r[6]:.2f} | "
            f"{r[3] / r[6]:.2f} | {r[3] / r[4]:.2f} | {r[7]:.1e} |"
        )
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "dq_dynamics.md").write_text(
        f"Per-evaluation cost, batch of {n} states, median of {reps} interleaved repeats "
        f"({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}).\n\n" + "\n".join(md) + "\n"
    )
    if args.json:
        keys = ["robot", "bodies", "nv", "dq_us", "decoupled_us", "aba_us", "aba_rnea_us", "rel_diff"]
        Path(args.json).write_text(json.dumps({"rows": [dict(zip(keys, r)) for r in rows], "repeats": reps}, indent=1))
    print("\n".join(md))


if __name__ == "__main__":
    main()
