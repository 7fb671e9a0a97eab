#!/usr/bin/env python3
"""Sensor models: freefloat's `measure` (engine) vs a vectorised numpy peer of the same error models.

Problem: naveen_dual_arm, a still-base run of T samples at 1 kHz (60,000 by default) with moving joints, sampled
at every step by a full sensor set: a gyro (angle random walk, Gauss-Markov bias instability, rate random walk,
constant bias), a star tracker (small random rotation), a base velocity sensor, encoders (4096 counts/rev, noise)
and tachometers (resolution, noise, bias) on all nine joints.

freefloat: `freefloat._core.measure` (the engine: one ChaCha8 stream per sensor, ziggurat normals, exact
  discretisations) — the streams only, no telemetry assembly (timed: the engine call).
numpy peer: the same models with numpy's PCG64 `standard_normal` on whole arrays, the Gauss-Markov recursion with
  `scipy.signal.lfilter` (a compiled first-order filter), the random walk with `cumsum`, quantisation with
  `np.round`, the star tracker's quaternion product vectorised.
The generators differ, so agreement is statistical: for every error term, the standard deviation of freefloat's
and numpy's errors must agree within 3 % (5 % with --quick) — checked before anything is timed.

    python benches/sensors_bench.py            # full run
    python benches/sensors_bench.py --quick    # 6,000 samples, 3 repeats
    python benches/sensors_bench.py --out DIR  # write sensors_bench.{json,md} there (default benches/results)
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path

import numpy as np
from scipy.signal import lfilter

from freefloat import _core, models
from freefloat import sensors as sn

GYRO = dict(noise_density=1e-4, bias=[1e-4, -2e-4, 5e-5], bias_instability=2e-5, bias_correlation_time=50.0,
            rate_random_walk=1e-6)  # fmt: skip
ST_SIGMA = [2e-5, 2e-5, 1.5e-4]
CPR, ENC_NOISE = 4096, 1e-4
TACHO = dict(resolution=1e-3, noise=5e-4, bias=1e-4)
VEL_NOISE = 5e-5


def run_arrays(m, n, dt):
    t = np.arange(n) * dt
    q = np.zeros((n, m.nq))
    q[:, 6] = 1.0
    v = np.zeros((n, m.nv))
    nj = m.nv - 6
    w = 0.3 + np.arange(nj)
    q[:, 7:] = 0.5 * np.sin(np.outer(t, w))
    v[:, 6:] = 0.5 * w * np.cos(np.outer(t, w))
    return t, q, v


def sensor_set():
    return sn.SensorSet(
        [
            sn.Gyro(**GYRO),
            sn.StarTracker(sigma=ST_SIGMA),
            sn.BaseVelocity(noise=VEL_NOISE),
            sn.Encoder(counts_per_rev=CPR, noise=ENC_NOISE),
            sn.Tachometer(**TACHO),
        ]
    )


def numpy_peer(t, q, v, dt, rng):
    """The same error models on whole arrays."""
    n = len(t)
    out = {}
    sb = GYRO["bias_instability"] * 0.6642824702679601 / 0.6173642830742981
    phi = np.exp(-dt / GYRO["bias_correlation_time"])
    w = rng.standard_normal((n, 3))
    gm0 = sb * rng.standard_normal(3)
    gm, _ = lfilter([sb * np.sqrt(1 - phi * phi)], [1.0, -phi], w, axis=0, zi=(phi * gm0)[None, :])
    gm = np.vstack([gm0, gm[:-1]])
    rw = np.vstack(
        [np.zeros(3), np.cumsum(GYRO["rate_random_walk"] * np.sqrt(dt) * rng.standard_normal((n - 1, 3)), 0)]
    )
    out["gyro"] = (
        v[:, 3:6]
        + np.asarray(GYRO["bias"])
        + gm
        + rw
        + GYRO["noise_density"] / np.sqrt(dt) * rng.standard_normal((n, 3))
    )
    d = rng.standard_normal((n, 3)) * ST_SIGMA
    th = np.linalg.norm(d, axis=1, keepdims=True)
    k = np.where(th < 1e-4, 0.5 - th * th / 48, np.sin(th / 2) / np.maximum(th, 1e-300))
    e = np.hstack([k * d, np.cos(th / 2)])
    a, b = q[:, 3:7], e
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b.T
    out["star_tracker"] = np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        -1,
    )
    out["base_velocity"] = v[:, 0:3] + VEL_NOISE * rng.standard_normal((n, 3))
    dq = 2 * np.pi / CPR
    out["encoder"] = dq * np.round((q[:, 7:] + ENC_NOISE * rng.standard_normal(q[:, 7:].shape)) / dq)
    res = TACHO["resolution"]
    out["tachometer"] = res * np.round(
        (v[:, 6:] + TACHO["bias"] + TACHO["noise"] * rng.standard_normal(v[:, 6:].shape)) / res
    )
    return out


def engine(m, text, t, q, v, seed):
    return {r["sensor"]: r["values"] for r in _core.measure(m._core, text, t, q, v, None, seed)}


def agreement(ours, theirs, t, q, v, tol):
    """Per error term: the standard deviation of freefloat's and numpy's errors, and their ratio."""
    rows = {}

    def comp(name, a, b):
        sa, sb = float(np.std(a)), float(np.std(b))
        rows[name] = {"freefloat_std": sa, "numpy_std": sb, "ratio": sa / sb}

    comp("gyro (all terms)", ours["gyro"] - v[:, 3:6], theirs["gyro"] - v[:, 3:6])
    comp("gyro first difference (white part)", np.diff(ours["gyro"], axis=0), np.diff(theirs["gyro"], axis=0))
    comp("star tracker qz error", ours["star_tracker"][:, 2], theirs["star_tracker"][:, 2])
    comp("base velocity", ours["base_velocity"] - v[:, :3], theirs["base_velocity"] - v[:, :3])
    comp("encoder", ours["encoder"] - q[:, 7:], theirs["encoder"] - q[:, 7:])
    comp("tachometer", ours["tachometer"] - v[:, 6:], theirs["tachometer"] - v[:, 6:])
    ok = all(abs(r["ratio"] - 1) < tol for k, r in rows.items() if k != "gyro (all terms)")
    # the slow bias terms of one short record vary a lot from draw to draw: only a loose check on the total
    ok = ok and 0.5 < rows["gyro (all terms)"]["ratio"] < 2.0
    return rows, ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="6,000 samples, 3 repeats")
    ap.add_argument("--samples", type=int, default=60_000)
    ap.add_argument("--repeats", type=int, default=9)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results"))
    a = ap.parse_args()
    n, repeats, tol = (6_000, 3, 0.05) if a.quick else (a.samples, a.repeats, 0.03)
    m = models.load("naveen_dual_arm")
    dt = 1e-3
    t, q, v = run_arrays(m, n, dt)
    text = sensor_set().to_json()
    ours = engine(m, text, t, q, v, 1)
    theirs = numpy_peer(t, q, v, dt, np.random.default_rng(1))
    rows, ok = agreement(ours, theirs, t, q, v, tol)
    if not ok:
        raise SystemExit(f"freefloat and numpy sensor errors disagree: {json.dumps(rows, indent=1)}")
    times = {"freefloat": [], "numpy": []}
    for r in range(repeats):  # interleaved
        t0 = time.perf_counter()
        engine(m, text, t, q, v, r)
        times["freefloat"].append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        numpy_peer(t, q, v, dt, np.random.default_rng(r))
        times["numpy"].append(time.perf_counter() - t0)
    med = {k: statistics.median(x) for k, x in times.items()}
    res = {
        "problem": {"model": m.name, "samples": n, "sensors": sensor_set().to_dicts()},
        "agreement": rows,
        "agreement_passed": ok,
        "median_s": med,
        "spread_s": {k: [min(x), max(x)] for k, x in times.items()},
        "speedup_vs_numpy": med["numpy"] / med["freefloat"],
        "samples_per_s_freefloat": n / med["freefloat"],
        "repeats": repeats,
        "machine": platform.platform(),
    }
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sensors_bench.json").write_text(json.dumps(res, indent=2))
    md = [
        "# Sensor models: freefloat measure vs numpy",
        "",
        f"{n} samples of naveen_dual_arm, full sensor set at every sample; median of {repeats} interleaved repeats.",
        "",
        "| | median [ms] | spread [ms] |",
        "|---|---|---|",
    ]
    for k in times:
        lo, hi = res["spread_s"][k]
        md.append(f"| {k} | {med[k] * 1e3:.2f} | {lo * 1e3:.2f} – {hi * 1e3:.2f} |")
    md += ["", f"freefloat / numpy speed ratio: {res['speedup_vs_numpy']:.2f}x", ""]
    (out / "sensors_bench.md").write_text("\n".join(md))
    print("\n".join(md))


if __name__ == "__main__":
    main()
