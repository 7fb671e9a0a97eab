#!/usr/bin/env python3
"""Soak run: simulation plus online identification, over and over, for `--minutes`, watching the process's
memory (resident set size) and the momentum drift. A long job must not leak (RSS flat after the first
chunks) and must not let the integration error accumulate (momentum of a free-floating robot under internal
torques is conserved: its drift stays at round-off).

Each chunk simulates `--chunk` seconds of the 3D dual-arm robot (naveen_dual_arm, free base, RK4 at 1 ms) with
smooth internal joint torques, continuing from the previous chunk's final state (one long motion), then folds
every 10th sample into a recursive least-squares estimator of the momentum model K(q, v) φ = h (the online
identification of the mass properties, one sample at a time, as a flight computer would). Per chunk it records
the RSS, the largest momentum deviation from the run's initial momentum (relative to the momentum scale, as
`Trajectory.momentum_drift`), and the RLS prediction residual |K φ̂ − h| / |h| on the chunk's samples.

    python benches/soak.py --minutes 10 --out benches/results     # the documented run (docs/reliability.md)
    python benches/soak.py --quick --out /tmp/soak                 # a few seconds (benches/smoke.py)

Writes soak.json (per-chunk series and the summary) and soak.png (RSS and drift against time).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

import freefloat as ff
from freefloat.identification.online import RecursiveLS


def rss_mb() -> float:
    """Resident set size of this process, MB (Linux /proc; elsewhere the peak from getrusage)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--minutes", type=float, default=10.0, help="wall-clock length of the soak (default 10)")
    ap.add_argument("--chunk", type=float, default=2.0, help="simulated seconds per chunk (default 2)")
    ap.add_argument("--quick", action="store_true", help="a few seconds (CI smoke run)")
    ap.add_argument("--out", type=Path, default=Path("benches/results"), help="folder for soak.json / soak.png")
    a = ap.parse_args(argv)
    minutes = 0.08 if a.quick else a.minutes
    a.out.mkdir(parents=True, exist_ok=True)

    m = ff.models.load("naveen_dual_arm")
    nb = m.nvs[0]
    rng = np.random.default_rng(0)
    q = m.neutral()
    v = np.concatenate([rng.uniform(-0.05, 0.05, nb), rng.uniform(-0.2, 0.2, m.nv - nb)])
    freq = 0.2 + 0.05 * np.arange(m.nv - nb)
    phase = np.arange(m.nv - nb, dtype=float)
    t0_sim = 0.0

    def torques_at(offset):
        def torques(t, q_, v_):
            out = np.zeros(m.nv)
            out[nb:] = 2.0 * np.sin(2 * np.pi * freq * (t + offset) + phase)
            return out

        return torques

    phi_true = np.asarray(m.parameters(), float).ravel()
    n = phi_true.size
    # the initial guess: every parameter off by a random 30 % (the estimator only sees the momentum model)
    rls = RecursiveLS(phi_true * rng.uniform(0.7, 1.3, n), np.full(n, 1e2))
    h0 = np.asarray(ff.momentum(m, q, v), float)

    series = {"wall_s": [], "sim_s": [], "rss_mb": [], "drift_linear_rel": [], "drift_angular_rel": [], "residual": []}
    start = time.perf_counter()
    chunks = 0
    while time.perf_counter() - start < minutes * 60:
        tr = ff.simulate(m, q, v, a.chunk, 1e-3, torques=torques_at(t0_sim), record_every=10)
        q, v = tr.q[-1].copy(), tr.v[-1].copy()
        t0_sim += a.chunk
        # drift against the run's initial momentum, relative to the momentum scale of Trajectory.momentum_drift
        e = np.abs(tr.kinetic_energy).max()
        mass, radius = tr.stats["total_mass"], tr.stats["radius"]
        scale_p = max(np.linalg.norm(tr.momentum[:, :3], axis=1).max(), np.sqrt(2 * mass * e), 1e-300)
        scale_l = max(np.linalg.norm(tr.momentum[:, 3:], axis=1).max(), np.sqrt(2 * mass * radius**2 * e), 1e-300)
        dp = np.linalg.norm(tr.momentum[:, :3] - h0[:3], axis=1).max() / scale_p
        dl = np.linalg.norm(tr.momentum[:, 3:] - h0[3:], axis=1).max() / scale_l
        res = []
        for k in range(1, len(tr.t)):
            K = np.asarray(ff.momentum_regressor(m, tr.q[k], tr.v[k]))
            h = tr.momentum[k]
            rls.update(t0_sim - a.chunk + tr.t[k], K, h)
            res.append(np.linalg.norm(K @ rls.estimate - h) / max(np.linalg.norm(h), 1e-300))
        chunks += 1
        series["wall_s"].append(time.perf_counter() - start)
        series["sim_s"].append(t0_sim)
        series["rss_mb"].append(rss_mb())
        series["drift_linear_rel"].append(float(dp))
        series["drift_angular_rel"].append(float(dl))
        series["residual"].append(float(np.max(res)))
        if not a.quick and chunks % 20 == 0:
            print(
                f"  {series['wall_s'][-1] / 60:5.1f} min, {t0_sim:7.0f} s simulated, "
                f"RSS {series['rss_mb'][-1]:6.1f} MB, drift {dp:.1e} / {dl:.1e}, residual {series['residual'][-1]:.1e}",
                flush=True,
            )

    rss = np.array(series["rss_mb"])
    w = np.array(series["wall_s"]) / 60
    # growth after warm-up: RSS at the end minus RSS after the first 10 % of the chunks (allocator warm-up,
    # lazy imports), and the slope of a straight-line fit over the same span, MB per minute
    k0 = max(1, len(rss) // 10)
    slope = float(np.polyfit(w[k0:], rss[k0:], 1)[0]) if len(rss) - k0 >= 3 else 0.0
    summary = {
        "minutes": float(w[-1]),
        "chunks": chunks,
        "simulated_s": t0_sim,
        "rls_samples": int(rls.samples),
        "rss_start_mb": float(rss[0]),
        "rss_after_warmup_mb": float(rss[k0 - 1]),
        "rss_end_mb": float(rss[-1]),
        "rss_max_mb": float(rss.max()),
        "rss_growth_after_warmup_mb": float(rss[-1] - rss[k0 - 1]),
        "rss_slope_mb_per_min": slope,
        "drift_linear_rel_max": float(max(series["drift_linear_rel"])),
        "drift_angular_rel_max": float(max(series["drift_angular_rel"])),
        "rls_residual_last": float(series["residual"][-1]),
        "machine": {"cpus": os.cpu_count(), "nice": os.nice(0)},
        "command": "python benches/soak.py " + ("--quick" if a.quick else f"--minutes {a.minutes:g}"),
    }
    (a.out / "soak.json").write_text(json.dumps({"summary": summary, "series": series}, indent=1))
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
        ax1.plot(w, rss, ".-", ms=2)
        ax1.set_ylabel("resident memory [MB]")
        ax1.set_ylim(0, max(rss.max() * 1.2, 1))
        ax1.set_title(f"soak: {t0_sim:.0f} s of naveen_dual_arm simulated + {rls.samples} RLS updates")
        ax2.semilogy(w, np.maximum(series["drift_linear_rel"], 1e-18), ".", ms=3, label="linear momentum")
        ax2.semilogy(w, np.maximum(series["drift_angular_rel"], 1e-18), ".", ms=3, label="angular momentum")
        ax2.axhline(np.finfo(float).eps, color="gray", lw=0.8, ls="--", label="machine epsilon")
        ax2.set_ylabel("drift from t = 0 (relative)")
        ax2.set_xlabel("wall-clock time [min]")
        ax2.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.out / "soak.png", dpi=110)
        plt.close(fig)
    except ImportError:
        pass
    print(json.dumps(summary, indent=1))
    return summary


if __name__ == "__main__":
    main()
