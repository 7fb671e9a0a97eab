#!/usr/bin/env python3
"""Campaign throughput on Dask (issue 15): 2 workers against 1, and the per-run overhead of the campaign layer.

Problem: the medium post-capture scenario of Zhang, Yue, Yuan 2020 (zhang2020_2d_medium) with measurement noise,
shortened so one run takes about a second (simulation, measurements, four estimators), N runs over noise seeds.

Measured, in the same process, interleaved (1 worker, 2 workers, 1 worker, ...; median of the repeats):
  peer      : the same N runs called directly in a loop in this process (no Dask, no dataset): the strongest
              single-core peer (it pays nothing for scheduling, pickling or writing);
  1 worker  : `run_campaign` on a LocalCluster of 1 worker process (single-threaded);
  2 workers : the same on 2 worker processes.
  Throughput = runs / span, span = from the first run's start to the last run's end on the workers (the
  cluster's start-up, ~2-5 s, is reported apart: it is paid once per campaign, not per run).
Per-run overhead: a 1-worker campaign of very short runs (0.3 s of simulated time, a few tens of ms each):
  (span - sum of the runs' own wall times) / runs = what scheduling, transfer, bookkeeping and the streamed
  Parquet writes add to each run.
Agreement: every campaign row's final estimates equal the direct peer's for the same run (same seeds) to 1e-12
before anything is reported.

    python benches/campaign_bench.py            # 16 runs of ~1 s (20 s simulated), 3 repeats; 200 short runs
    python benches/campaign_bench.py --quick    # 4 runs of ~0.3 s, 1 repeat; 40 short runs (CI smoke)
    python benches/campaign_bench.py --out DIR  # write campaign_bench.{json,md} there (default benches/results)
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

from freefloat import campaign as cp


def spec(runs: int, duration: float, name: str):
    return cp.spec.parse(
        {
            "name": name,
            "kind": "postcapture",
            "scenario": "zhang2020_2d_medium",
            "set": {"duration": duration, "noise": {"velocity": 1e-4, "acceleration": 1e-4, "force": 0.01}},
            "monte_carlo": {"runs": runs, "seed": 11},
        },
        "campaign_bench",
    )


def campaign_once(s, workers: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = cp.run_campaign(s, Path(tmp) / "c", workers=workers, progress=False)
        wall = time.perf_counter() - t0
        rows = cp.read_dataset(Path(tmp) / "c").to_pylist()
    assert res["runs_done"] == len(rows) == s.runs_total, res
    span = max(r["finished_at"] for r in rows) - min(r["started_at"] for r in rows)
    busy = sum(r["run_wall_s"] for r in rows)
    return {"wall_s": wall, "span_s": span, "busy_s": busy, "rows": rows, "startup_s": wall - span}


def direct(s) -> tuple[float, dict]:
    kind = cp.registry.KINDS[s.kind]
    t0 = time.perf_counter()
    out = {r.key: kind.run(r.scenario, r.seed) for r in s.runs()}
    return time.perf_counter() - t0, out


def check_agreement(rows, ref) -> float:
    worst = 0.0
    for r in rows:
        d = ref[r["run_key"]]
        for k, v in d.items():
            if k.startswith("estimate."):
                worst = max(worst, abs(r[k] - v) / max(abs(v), 1e-300))
    return worst


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="small problem, one repeat (CI smoke run)")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "results"))
    ap.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    ap.add_argument("--runs", type=int, help="runs per campaign (default 16; quick 4)")
    ap.add_argument("--duration", type=float, help="simulated seconds per run (default 20: ~1 s of work)")
    ap.add_argument("--repeats", type=int, help="interleaved repeats (default 3; quick 1)")
    a = ap.parse_args(argv)
    runs = a.runs or (4 if a.quick else 16)
    duration = a.duration or (2.0 if a.quick else 20.0)
    repeats = a.repeats or (1 if a.quick else 3)
    short_runs = 40 if a.quick else 200
    s = spec(runs, duration, "bench_throughput")

    t_peer, ref = direct(s)
    print(f"peer (direct loop, this process): {runs} runs in {t_peer:.2f} s ({t_peer / runs:.3f} s per run)")
    one, two, peers = [], [], [t_peer]
    worst = 0.0
    for k in range(repeats):
        for w, acc in ((1, one), (2, two)):
            r = campaign_once(s, w)
            agree = check_agreement(r["rows"], ref)
            worst = max(worst, agree)
            if not agree <= 1e-12:
                print(f"FAIL: campaign rows differ from the direct runs by {agree:.3g}", file=sys.stderr)
                return 1
            r.pop("rows")
            acc.append(r)
            print(
                f"repeat {k + 1}: {w} worker(s): span {r['span_s']:.2f} s ({runs / r['span_s']:.2f} runs/s), "
                f"wall {r['wall_s']:.2f} s incl. cluster start/stop {r['startup_s']:.2f} s"
            )
        if k + 1 < repeats:
            peers.append(direct(s)[0])

    def med(xs, key):
        return statistics.median(x[key] for x in xs)

    thr1, thr2 = runs / med(one, "span_s"), runs / med(two, "span_s")
    thr_peer = runs / statistics.median(peers)
    s_short = spec(short_runs, 0.3, "bench_overhead")
    o = campaign_once(s_short, 1)
    o.pop("rows")
    overhead = (o["span_s"] - o["busy_s"]) / short_runs
    res = {
        "problem": {"scenario": "zhang2020_2d_medium", "duration_s": duration, "runs": runs, "repeats": repeats},
        "run_s_median": statistics.median(peers) / runs,
        "throughput_runs_per_s": {"peer_direct": thr_peer, "workers_1": thr1, "workers_2": thr2},
        "speedup_2_vs_1": thr2 / thr1,
        "speedup_2_vs_peer": thr2 / thr_peer,
        "spread": {
            "span_1_s": [x["span_s"] for x in one],
            "span_2_s": [x["span_s"] for x in two],
            "peer_s": peers,
        },
        "startup_s_median": {"workers_1": med(one, "startup_s"), "workers_2": med(two, "startup_s")},
        "overhead": {
            "runs": short_runs,
            "run_s_mean": o["busy_s"] / short_runs,
            "per_run_overhead_ms": overhead * 1e3,
            "span_s": o["span_s"],
        },
        "agreement_max_rel": worst,
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version(), "load": os.getloadavg()},
        "quick": a.quick,
    }
    print(
        f"throughput: peer {thr_peer:.2f}, 1 worker {thr1:.2f}, 2 workers {thr2:.2f} runs/s -> 2 vs 1: "
        f"{res['speedup_2_vs_1']:.2f}x (target >= 1.8x for runs of a second or more), 2 vs direct peer "
        f"{res['speedup_2_vs_peer']:.2f}x"
    )
    print(
        f"per-run overhead of the campaign layer: {overhead * 1e3:.1f} ms (target < 50 ms), {short_runs} runs of "
        f"{o['busy_s'] / short_runs * 1e3:.0f} ms"
    )
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "campaign_bench.json").write_text(json.dumps(res, indent=1))
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1, default=str))
    md = [
        "# Campaign throughput on Dask (LocalCluster)",
        "",
        f"{runs} post-capture runs (zhang2020_2d_medium, {duration:g} s simulated, noise), median of {repeats} "
        f"interleaved repeats; machine: {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}.",
        "",
        "| | runs/s | vs 1 worker |",
        "|---|---|---|",
        f"| direct loop in one process (peer) | {thr_peer:.3f} | {thr_peer / thr1:.2f}x |",
        f"| campaign, 1 worker | {thr1:.3f} | 1.00x |",
        f"| campaign, 2 workers | {thr2:.3f} | {thr2 / thr1:.2f}x |",
        "",
        f"Per-run overhead of the campaign layer: {overhead * 1e3:.1f} ms ({short_runs} runs of "
        f"{o['busy_s'] / short_runs * 1e3:.0f} ms on 1 worker). Cluster start-up and shut-down (once per campaign): "
        f"{med(one, 'startup_s'):.1f} s (1 worker), {med(two, 'startup_s'):.1f} s (2 workers).",
        "",
    ]
    (out / "campaign_bench.md").write_text("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
