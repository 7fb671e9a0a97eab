#!/usr/bin/env python3
"""Reaction-wheel simulation speed: freefloat's engine wheel model against Basilisk's (2.12,
ReactionWheelStateEffector, BalancedWheels), and the cost of actuators and the environment on the seed robots.

Part 1: a 750 kg hub with three wheels, Coulomb and viscous friction, torque, power and speed saturation on,
30 s with RK4 at 0.01 s in both (tests/_basilisk_cases.py builds the same case in both), everything from Python:
model set-up, the run, the recorded result as arrays. freefloat records its whole state (and accelerations,
forces, momentum, energy) at every step; Basilisk records the two messages the comparison reads at every step
(spacecraft state, wheel speeds) and nothing else (its angular-momentum logger, a Python callback at every step, is
used for the agreement check only, not timed). Before timing, the two are checked to agree (abort above 1e-9 rad/s
on the body rates). Each repeat times freefloat and Basilisk back to back, in alternating order; the figure is the
median over the repeats of the per-repeat ratio Basilisk / freefloat, with its min..max (target >= 5).

Part 2: seed robots, 10 s with RK4 at 1 ms driven by a smooth torque table, recorded every 100 steps: without
anything, with actuators (wheel friction and saturation on three wheel joints, two thrusters on the base firing
pulses), and with the actuators and the gravity gradient of a 500 km orbit. `naveen_dual_arm` carries its own wheels
Wx, Wy, Wz; `zhang2020_3d` gets three rotors appended to its base (`freefloat.actuators.add_wheels`), in all three
runs. Interleaved repeats; median of the per-repeat ratio to the run without, with its min..max (target <= 1.5).

    python benches/basilisk_wheels.py [--quick] [--repeats R] [--out benches/results]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

from _basilisk_cases import basilisk_run, freefloat_run  # noqa: E402

import freefloat as ff  # noqa: E402
from freefloat.actuators import add_wheels  # noqa: E402

SEEDS = ("naveen_dual_arm", "zhang2020_3d")


def spread(xs):
    """(median, min, max) of a list."""
    xs = np.asarray(xs, float)
    return float(np.median(xs)), float(xs.min()), float(xs.max())


def load():
    """1-, 5- and 15-minute load averages of the machine (the runs share it with other jobs)."""
    return [round(x, 2) for x in os.getloadavg()]


def part1(repeats, t_final, dt):
    tr, _ = freefloat_run(t_final, dt)
    _, _, omega, speeds, _ = basilisk_run(t_final, dt)
    agree = float(np.abs(tr.v[:, 3:6] - omega).max())
    agree_w = float(np.abs(tr.v[:, 6:9] - speeds).max())
    if not (agree < 1e-9 and agree_w < 1e-7):
        raise SystemExit(f"freefloat and Basilisk disagree: body rates {agree:.3g}, wheel rates {agree_w:.3g}")
    basilisk_run(t_final, dt, log_momentum=False)  # warm-up of the timed configuration

    def ff_once():
        t0 = time.perf_counter()
        freefloat_run(t_final, dt)
        return time.perf_counter() - t0

    def bsk_once():
        t0 = time.perf_counter()
        basilisk_run(t_final, dt, log_momentum=False)
        return time.perf_counter() - t0

    tf, tb = [], []
    for r in range(repeats):
        if r % 2 == 0:
            tf.append(ff_once())
            tb.append(bsk_once())
        else:
            tb.append(bsk_once())
            tf.append(ff_once())
    return {
        "t_final": t_final,
        "dt": dt,
        "freefloat_s": spread(tf),
        "basilisk_s": spread(tb),
        "ratio": spread([b / f for b, f in zip(tb, tf)]),
        "speedup_median": float(np.median(tb) / np.median(tf)),
        "agreement_body_rate": agree,
        "agreement_wheel_rate": agree_w,
    }


def seed_model(name):
    """The seed robot and its wheel joints (three rotors appended to the base if it has none)."""
    m = ff.models.load(name)
    wheels = [j for j in m.joint_names if j in ("Wx", "Wy", "Wz")]
    if not wheels:
        m = ff.Model.from_yaml_string(yaml.safe_dump(add_wheels(yaml.safe_load(ff.models.source(name)), 3)))
        wheels = ["rw1", "rw2", "rw3"]
    return m, wheels


def seed_actuators(wheels):
    return ff.Actuators(
        wheels=[
            ff.Wheel(j, max_torque=5.0, max_speed=600.0, max_power=500.0, coulomb=1e-3, viscous=1e-5) for j in wheels
        ],
        thrusters=[
            ff.Thruster(direction=(1, 0, 0), position=(0, 1, 0), max_thrust=1.0, firings=[(1.0, 0.5), (5.0, 0.2)]),
            ff.Thruster(direction=(-1, 0, 0), position=(0, -1, 0), max_thrust=1.0, firings=[(1.0, 0.5), (5.0, 0.2)]),
        ],
    )


def part2(repeats, t_final, dt):
    out = {}
    for name in SEEDS:
        m, wheels = seed_model(name)
        acts = seed_actuators(wheels)
        env = ff.Environment(altitude=500e3, inclination=0.9, gravity_gradient=True)
        t = np.arange(0.0, t_final + dt / 2, dt)
        tau = np.zeros((len(t), m.nv))
        tau[:, 6:] = 0.5 * np.sin(np.outer(t, 1 + np.arange(m.nv - 6)))
        args = (m, m.neutral(), np.zeros(m.nv), t_final, dt)
        kw = dict(torques=tau, torque_times=t, record_every=100)
        cases = {
            "none": {},
            "actuators": {"actuators": acts},
            "actuators_gravity_gradient": {"actuators": acts, "environment": env},
        }
        for c in cases.values():
            ff.simulate(*args, **kw, **c)  # warm-up and check it runs
        times = {c: [] for c in cases}
        order = list(cases)
        for r in range(repeats):
            for c in order[r % len(order) :] + order[: r % len(order)]:  # interleaved, order rotated
                t0 = time.perf_counter()
                ff.simulate(*args, **kw, **cases[c])
                times[c].append(time.perf_counter() - t0)
        res = {"wheels": wheels, "thrusters": 2, "nbodies": m.nbodies, "nv": m.nv}
        for c, ts in times.items():
            res[c] = {"s": spread(ts)}
            if c != "none":
                res[c]["ratio"] = spread([a / b for a, b in zip(ts, times["none"])])
        out[name] = res
    return out


def git_rev():
    try:
        return subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=HERE, check=True
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main():
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        epilog=__doc__.split("\n\n", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ap.add_argument("--quick", action="store_true", help="short runs and 1 repeat (CI smoke)")
    ap.add_argument("--repeats", type=int, default=None, help="interleaved repeats (default 9, quick 1)")
    ap.add_argument("--out", default=str(HERE / "results"), help="folder for basilisk_wheels.json/.md")
    a = ap.parse_args()
    reps = a.repeats or (1 if a.quick else 9)
    load0 = load()
    print(f"part 1: hub + 3 wheels vs Basilisk, {reps} repeats (load {load0})", flush=True)
    p1 = part1(reps, 3.0 if a.quick else 30.0, 0.01)
    print("part 2: seed robots with and without actuators and gravity gradient", flush=True)
    p2 = part2(reps, 1.0 if a.quick else 10.0, 1e-3)
    load1 = load()
    res = {
        "hub_three_wheels": p1,
        "seed_robots": p2,
        "repeats": reps,
        "quick": a.quick,
        "load_before": load0,
        "load_after": load1,
        "git": git_rev(),
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
    }
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "basilisk_wheels.json").write_text(json.dumps(res, indent=2))
    f, b, r = p1["freefloat_s"], p1["basilisk_s"], p1["ratio"]
    lines = [
        "# freefloat vs Basilisk: hub + three reaction wheels (friction and saturation on)",
        "",
        f"{res['date_utc']} UTC, git `{res['git']}`, load average {load0} before, {load1} after (1/5/15 min).",
        f"{p1['t_final']:g} s, RK4 at {p1['dt']:g} s, {reps} interleaved repeats: medians (min..max).",
        "",
        "| | freefloat (s) | Basilisk (s) | Basilisk / freefloat, per repeat | target |",
        "|---|---|---|---|---|",
        f"| hub + 3 wheels | {f[0]:.4f} ({f[1]:.4f}..{f[2]:.4f}) | {b[0]:.4f} ({b[1]:.4f}..{b[2]:.4f}) | "
        f"**{r[0]:.1f}x** ({r[1]:.1f}..{r[2]:.1f}) | >= 5x |",
        "",
        f"Agreement: body rates {p1['agreement_body_rate']:.2g} rad/s, "
        f"wheel rates {p1['agreement_wheel_rate']:.2g} rad/s.",
        "",
        "## Seed robots: with actuators (and gravity gradient) / without",
        "",
        f"{1.0 if a.quick else 10.0:g} s, RK4 at 1 ms, recorded every 100 steps; per-repeat ratios, "
        "medians (min..max); target <= 1.5.",
        "",
        "| robot | without (s) | wheels + 2 thrusters | wheels + 2 thrusters + gravity gradient |",
        "|---|---|---|---|",
    ]
    for k, v in p2.items():
        cells = []
        for c in ("actuators", "actuators_gravity_gradient"):
            x = v[c]["ratio"]
            cells.append(f"**{x[0]:.2f}** ({x[1]:.2f}..{x[2]:.2f}), {v[c]['s'][0]:.4f} s")
        lines.append(f"| {k} ({v['nbodies']} bodies) | {v['none']['s'][0]:.4f} | {cells[0]} | {cells[1]} |")
    (out / "basilisk_wheels.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
