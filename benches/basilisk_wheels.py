#!/usr/bin/env python3
"""Reaction-wheel simulation speed: freefloat's engine wheel model against Basilisk's (2.12,
ReactionWheelStateEffector, BalancedWheels), and the cost of actuators on the seed robots.

Part 1: a 750 kg hub with three wheels, Coulomb and viscous friction, torque, power and speed saturation on,
30 s with RK4 at 0.01 s in both (tests/_basilisk_cases.py builds the same case in both). Each repeat runs
freefloat then Basilisk (interleaved); medians over the repeats, spread min..max; ratio Basilisk / freefloat.
Before timing, the two are checked to agree (abort above 1e-9 rad/s on the body rates).

Part 2: the built-in seed robots that carry wheels, 10 s with RK4 at 1 ms driven by a smooth torque table,
with and without actuators (wheel friction and saturation on every wheel joint, two thrusters on the base
firing pulses); ratio with / without (target <= 1.5).

    python benches/basilisk_wheels.py [--quick] [--repeats R] [--out benches/results]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

from _basilisk_cases import basilisk_run, freefloat_run  # noqa: E402

import freefloat as ff  # noqa: E402


def med_spread(xs):
    xs = np.asarray(xs)
    return float(np.median(xs)), float(xs.min()), float(xs.max())


def part1(repeats, t_final, dt):
    tr, _ = freefloat_run(t_final, dt)
    t, _, omega, speeds, _ = basilisk_run(t_final, dt)
    agree = float(np.abs(tr.v[:, 3:6] - omega).max())
    agree_w = float(np.abs(tr.v[:, 6:9] - speeds).max())
    if not (agree < 1e-9 and agree_w < 1e-7):
        raise SystemExit(f"freefloat and Basilisk disagree: body rates {agree:.3g}, wheel rates {agree_w:.3g}")
    tf, tb = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        freefloat_run(t_final, dt)
        tf.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        basilisk_run(t_final, dt)
        tb.append(time.perf_counter() - t0)
    f, b = med_spread(tf), med_spread(tb)
    return {
        "t_final": t_final,
        "dt": dt,
        "freefloat_s": f,
        "basilisk_s": b,
        "speedup_median": b[0] / f[0],
        "agreement_body_rate": agree,
        "agreement_wheel_rate": agree_w,
    }


def seed_actuators(m):
    wheels = [j for j in m.joint_names if j.lower().startswith(("w", "rw"))]
    wheels = [j for j in wheels if j in ("Wx", "Wy", "Wz") or j.startswith("rw")]
    acts = ff.Actuators(
        wheels=[
            ff.Wheel(j, max_torque=5.0, max_speed=600.0, max_power=500.0, coulomb=1e-3, viscous=1e-5) for j in wheels
        ],
        thrusters=[
            ff.Thruster(direction=(1, 0, 0), position=(0, 1, 0), max_thrust=1.0, firings=[(1.0, 0.5), (5.0, 0.2)]),
            ff.Thruster(direction=(-1, 0, 0), position=(0, -1, 0), max_thrust=1.0, firings=[(1.0, 0.5), (5.0, 0.2)]),
        ],
    )
    return acts, wheels


def part2(repeats, t_final, dt):
    out = {}
    for name in ("naveen_dual_arm",):
        m = ff.models.load(name)
        acts, wheels = seed_actuators(m)
        t = np.arange(0.0, t_final + dt / 2, dt)
        tau = np.zeros((len(t), m.nv))
        tau[:, 6:] = 0.5 * np.sin(np.outer(t, 1 + np.arange(m.nv - 6)))
        args = (m, m.neutral(), np.zeros(m.nv), t_final, dt)
        kw = dict(torques=tau, torque_times=t, record_every=100)
        ff.simulate(*args, **kw, actuators=acts)  # warm-up and check it runs
        tw, to = [], []
        for _ in range(repeats):
            t0 = time.perf_counter()
            ff.simulate(*args, **kw)
            to.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            ff.simulate(*args, **kw, actuators=acts)
            tw.append(time.perf_counter() - t0)
        a, b = med_spread(to), med_spread(tw)
        out[name] = {"wheels": wheels, "thrusters": 2, "without_s": a, "with_s": b, "ratio_median": b[0] / a[0]}
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="short runs and 1 repeat (CI smoke)")
    ap.add_argument("--repeats", type=int, default=None, help="interleaved repeats (default 7, quick 1)")
    ap.add_argument("--out", default=str(HERE / "results"), help="folder for basilisk_wheels.json/.md")
    a = ap.parse_args()
    reps = a.repeats or (1 if a.quick else 7)
    p1 = part1(reps, 3.0 if a.quick else 30.0, 0.01)
    p2 = part2(reps, 1.0 if a.quick else 10.0, 1e-3)
    res = {"hub_three_wheels": p1, "seed_robots": p2, "repeats": reps, "quick": a.quick}
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "basilisk_wheels.json").write_text(json.dumps(res, indent=2))
    lines = [
        "# freefloat vs Basilisk: hub + three reaction wheels (friction and saturation on)",
        "",
        f"{p1['t_final']:g} s, RK4 at {p1['dt']:g} s, median of {reps} interleaved repeats (min..max)",
        "",
        "| | freefloat (s) | Basilisk (s) | Basilisk / freefloat |",
        "|---|---|---|---|",
        f"| hub + 3 wheels | {p1['freefloat_s'][0]:.4f} ({p1['freefloat_s'][1]:.4f}..{p1['freefloat_s'][2]:.4f}) | "
        f"{p1['basilisk_s'][0]:.4f} ({p1['basilisk_s'][1]:.4f}..{p1['basilisk_s'][2]:.4f}) | "
        f"{p1['speedup_median']:.1f}x |",
        "",
        f"Agreement: body rates {p1['agreement_body_rate']:.2g} rad/s, "
        f"wheel rates {p1['agreement_wheel_rate']:.2g} rad/s.",
        "",
        "## Seed robots with and without actuators",
        "",
        "| robot | without (s) | with wheels + 2 thrusters (s) | ratio |",
        "|---|---|---|---|",
    ]
    for k, v in p2.items():
        lines.append(f"| {k} | {v['without_s'][0]:.4f} | {v['with_s'][0]:.4f} | {v['ratio_median']:.2f} |")
    (out / "basilisk_wheels.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
