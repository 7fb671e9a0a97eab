#!/usr/bin/env python3
"""Run every benchmark in benches/ and regenerate BENCHMARKS.md's tables and the README's speed table.

Each script is run once, in its full mode (or with --fast: its --quick mode, or fewer repeats, and the tables
say so), writing its results with --json FILE; the Rust estimator benchmark (cargo bench --bench rls_cpu) is
run several times. Every row of the summary gives freefloat's number, the peer's, their ratio (median of the
script's interleaved repeats) and the spread over repeats where the script records it; every section gives the
machine load (os.getloadavg() before and after the script) and the git hash the run was made on.

What is written:
  BENCHMARKS.md   the part between `<!-- run_all:begin -->` and `<!-- run_all:end -->` (added at the top if
                  absent): the summary table and each script's own markdown table; text outside is kept.
  README.md       the part between `<!-- speed:begin -->` and `<!-- speed:end -->`: a table quoting only
                  rows of this run (left alone if the markers are absent).
  benches/results/run_all/  every script's JSON and markdown.

    python benches/run_all.py                  # full runs (long: tens of minutes on 2 cores)
    python benches/run_all.py --fast           # quick modes / fewer repeats, about 10-15 minutes
    python benches/run_all.py --only identify rls   # a subset (names below), tables of the others dropped
    python benches/run_all.py --dry-run        # write to benches/results/run_all/ only, not BENCHMARKS/README

A script that fails or whose peer is not installed is reported in the table as failed/skipped; the others
still run. Ctrl-C stops the current script and writes nothing.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import re
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results" / "run_all"
BEGIN, END = "<!-- run_all:begin -->", "<!-- run_all:end -->"
SPEED_BEGIN, SPEED_END = "<!-- speed:begin -->", "<!-- speed:end -->"


@dataclass
class Row:
    """One comparison: > 1 means freefloat is faster (peer time / freefloat time) unless `lower_is_better`."""

    what: str
    peer: str
    ratio: float | None
    spread: str = ""
    freefloat: str = ""
    peer_value: str = ""
    target: str = ""
    note: str = ""


@dataclass
class Section:
    name: str
    command: str
    status: str = "ok"
    seconds: float = 0.0
    load_before: tuple = ()
    load_after: tuple = ()
    rows: list = field(default_factory=list)
    markdown: str = ""
    quick: bool = False  # run in its quick mode inside a full run (--quick-for)


def git_hash() -> str:
    try:
        h = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True)
        return h.strip() + ("+dirty" if dirty.stdout.strip() else "")
    except OSError:
        return "unknown"


def fmt_s(x: float) -> str:
    return f"{x * 1e6:.2f} µs" if x < 1e-3 else f"{x * 1e3:.2f} ms" if x < 1 else f"{x:.2f} s"


def _range(lo, hi) -> str:
    return f"{lo:.2f}-{hi:.2f}" if lo is not None and hi is not None else ""


# ------------------------------------------------------------------------------------------ row extractors
def rows_identify(res: dict) -> list[Row]:
    cores = res.get("cores")
    out = []
    for r in res["rows"]:
        out.append(
            Row(
                what=f"{r['what']}, {res['samples']:,} samples, {cores} core(s)",
                peer=r["peer"],
                ratio=r["ratio"],
                spread=_range(*r["ratio_range"])
                + (f"; CPU-time ratio {r['cpu_ratio']:.2f}" if "cpu_ratio" in r else ""),
                freefloat=fmt_s(r["freefloat_s"]),
                peer_value=fmt_s(r["peer_s"]),
                target=f"{r['target']} ({'met' if r['met'] else 'not met'})",
            )
        )
    return out


def rows_generic_ratios(res: dict, peer: str) -> list[Row]:
    """Scripts that record a `ratios` dict: {key: float} or {key: {median, min, max?, label?, target?}}."""
    out = []
    targets = res.get("targets", {}) if isinstance(res.get("targets"), dict) else {}
    met = res.get("targets_met", res.get("meets_targets", {})) or {}
    for key, v in (res.get("ratios") or {}).items():
        if isinstance(v, dict):
            med = v.get("median")
            spread = _range(v.get("min"), v.get("max")) if "max" in v else (f"min {v['min']:.2f}" if "min" in v else "")
            label = v.get("label", key)
        else:
            med, spread, label = v, "", key
        tgt = v.get("target", "") if isinstance(v, dict) else ""
        tgt = tgt or (str(targets.get(key, "")) if not isinstance(targets.get(key), dict) else "")
        if key in met:
            tgt = f"{tgt} ({met[key]})".strip()
        out.append(
            Row(what=label, peer=peer, ratio=med if isinstance(med, (int, float)) else None, spread=spread, target=tgt)
        )
    return out


def rows_adaptive(res: dict) -> list[Row]:
    out = []
    mm = res.get("min_max_s", {})
    for ex, key in (("example_a", "a"), ("example_b", "b")):
        ff_, np_ = res["median_s"][f"ff_{key}"], res["median_s"][f"np_{key}"]
        lo_hi = mm.get(f"np_{key}"), mm.get(f"ff_{key}")
        spread = ""
        if all(isinstance(x, (list, tuple)) and len(x) == 2 for x in lo_hi):
            spread = _range(lo_hi[0][0] / lo_hi[1][1], lo_hi[0][1] / lo_hi[1][0])
        out.append(
            Row(
                f"adaptive pose tracking (Valverde ch. 4), {ex}",
                "numpy/scipy closed loop",
                res["ratio_numpy_over_freefloat"][ex],
                spread,
                fmt_s(ff_),
                fmt_s(np_),
            )
        )
    return out


def rows_ddp(res: dict) -> list[Row]:
    f, c = res["freefloat"], res["crocoddyl"]
    spread = _range(c["solve_s_spread"][0] / f["solve_s_spread"][1], c["solve_s_spread"][1] / f["solve_s_spread"][0])
    return [
        Row(
            "DDP solve, valverde_ch8_tracking (same iterations)",
            "Crocoddyl 3.2.1",
            c["solve_s_median"] / f["solve_s_median"],
            spread,
            fmt_s(f["solve_s_median"]),
            fmt_s(c["solve_s_median"]),
        )
    ]


def rows_mpc(res: dict) -> list[Row]:
    rows = []
    cr = res.get("crocoddyl_replay")
    for name, c in res["cases"].items():
        s = c["replan_ms"]
        peer = cr is not None and cr["case"] == name
        rows.append(
            Row(
                f"MPC re-plan (H = 100, 5 it.), ch. 8 tracking, {name}: median / p95 / slowest",
                "Crocoddyl 3.2.1 FDDP, same re-plans" if peer else "targets (issue 36)",
                cr["replan_ms"]["median_ms"] / s["median_ms"] if peer else None,
                freefloat=f"{s['median_ms']:.1f} / {s['p95_ms']:.1f} / {s['max_ms']:.1f} ms"
                + (f" (CPU {c['replan_cpu_ms']['median_ms']:.1f} ms median)" if "replan_cpu_ms" in c else ""),
                peer_value=f"{cr['replan_ms']['median_ms']:.1f} ms median" if peer else "",
                target="median <= 25 ms, slowest <= 50 ms",
                note=f"final hold {c['accuracy']['final_hold_position_max_mm']:.1f} mm / "
                f"{c['accuracy']['final_hold_angle_max_deg']:.3f} deg",
            )
        )
    return rows


def rows_campaign(res: dict) -> list[Row]:
    return [
        Row("campaign throughput, 2 workers vs 1", "freefloat 1 worker", res["speedup_2_vs_1"], target=">= 1.8"),
        Row("campaign throughput, 2 workers vs direct loop", "direct Python loop", res["speedup_2_vs_peer"]),
    ]


def rows_derivatives(res: dict) -> list[Row]:
    out = []
    for name, r in res.get("results", {}).items():
        for key, v in r.get("ratios", {}).items():
            # these ratios are freefloat's time over the peer's: invert so that > 1 means freefloat is faster
            out.append(
                Row(
                    f"derivatives {name}: {key} (inverted)",
                    "Pinocchio 4.0.0 / Crocoddyl 3.2.1",
                    1.0 / v if v else None,
                    # issue 36: Pinocchio's ABA derivatives at most 0.6x; the DDP node block at most 0.5x Crocoddyl's
                    target="freefloat time <= 0.6x peer (ratio >= 1.67)"
                    if "pin" in key
                    else "freefloat time <= 0.5x peer (ratio >= 2)",
                )
            )
    return out


def rows_cl(res: dict) -> list[Row]:
    out = []
    for r in res.get("rows", []):
        ns = r.get("ns", "?")
        spread = _range(r["numpy_min"] / r["estimator_max"], r["numpy_max"] / r["estimator_min"])
        out.append(
            Row(
                f"concurrent learning (Valverde ch. 9), N_s = {ns}, estimator",
                "numpy (batched)",
                r["ratio_estimator"],
                spread,
                fmt_s(r["estimator_s"]),
                fmt_s(r["numpy_s"]),
                ">= 10",
                note=f"whole run {r['ratio_whole_run']:.2f}",
            )
        )
    return out


def rows_dq(res: dict) -> list[Row]:
    return [
        Row(
            f"dq_dynamics vs ABA + RNEA, {r['robot']}",
            "freefloat ABA + RNEA",
            r["aba_rnea_us"] / r["dq_us"],
            freefloat=f"{r['dq_us']:.2f} µs",
            peer_value=f"{r['aba_rnea_us']:.2f} µs",
        )
        for r in res.get("rows", [])
    ]


def rows_kernels(res: dict) -> list[Row]:
    targets = {"aba": "freefloat <= 0.5x (ratio >= 2)", "rnea": "<= 0.7x (ratio >= 1.43)", "crba": "<= 0.7x"}
    # row key -> (peer, words after the kernel's name); older JSON has no "peer" and only aba/rnea/crba (estimate)
    labels = {
        "pin abaInParallel": ("Pinocchio abaInParallel", ""),
        "pin rneaInParallel": ("Pinocchio rneaInParallel", ""),
        "pin crba (C++ estimate)": ("Pinocchio crba (C++ est.)", " (estimated peer)"),
    }
    out = []
    for robot, r in res["results"].items():
        for k, v in r["rows"].items():  # freefloat time / Pinocchio's: inverted so that > 1 means faster
            kernel = k.split("_")[0]
            default = {"aba": "pin abaInParallel", "rnea": "pin rneaInParallel"}.get(k, "pin crba (C++ estimate)")
            peer = v.get("peer", default)
            name, words = labels.get(peer, ("Pinocchio C++ loop (benches/pinocchio_peer.cpp)", " (vs C++ loop)"))
            if v.get("freefloat") == "ff loop":  # freefloat's own loop inside the engine: both sides loops, no binding
                words = " (engine loop vs C++ loop)"
            out.append(
                Row(
                    f"{kernel.upper()} per call{words}, core to core, {robot} (nv = {r['nv']})",
                    name,
                    1.0 / v["median"] if v.get("median") else None,
                    _range(1.0 / v["max"], 1.0 / v["min"]) if v.get("min", 0) > 0 and v.get("max", 0) > 0 else "",
                    target=targets.get(kernel, ""),
                    note=f"CPU-time ratio {1.0 / v['cpu_median']:.2f}" if v.get("cpu_median") else "",
                )
            )
    # one call from Python each (binding overhead): freefloat's time over Pinocchio's, inverted like the rows above
    for k, v in (res.get("single_rows") or {}).items():
        peer = {"momentum": "computeCentroidalMomentum"}.get(k, k)
        out.append(
            Row(
                f"single {k} call from Python, seed001_dual_arm_consistent",
                f"Pinocchio `{peer}` from Python",
                1.0 / v["median"] if v.get("median") else None,
                _range(1.0 / v["max"], 1.0 / v["min"]) if v.get("min", 0) > 0 and v.get("max", 0) > 0 else "",
                target="no slower than Pinocchio (ratio >= 1)",
                note=f"CPU-time ratio {1.0 / v['cpu_median']:.2f}" if v.get("cpu_median") else "",
            )
        )
    return out


def rows_inverted_ratios(res: dict, peer: str) -> list[Row]:
    """`ratios` whose values are freefloat's cost over a reference (lower is better): reported as they are."""
    out = rows_generic_ratios(res, peer)
    for r in out:
        r.note = "freefloat / reference (lower is better)"
    return out


def rows_sim_mujoco(res: dict) -> list[Row]:
    rows = []
    for key, v in (res.get("ratios") or {}).items():
        lower = "/ table" in key  # the Python-torque rows are a cost ratio, not a speed-up
        rows.append(
            Row(
                key,
                "MuJoCo 4 (same robot, RK4, 10 s at 1 kHz)" if not lower else "freefloat with table torques",
                v.get("median"),
                _range(v.get("min"), v.get("max")),
                target=v.get("target", ""),
                note=(f"CPU-time ratio {v['cpu_median']:.2f}" if "cpu_median" in v else "")
                + ("; freefloat / reference (lower is better)" if lower else ""),
            )
        )
    return rows


def rows_basilisk(res: dict) -> list[Row]:
    p = res["hub_three_wheels"]
    r_hub = p.get("ratio") or []
    out = [
        Row(
            f"hub + 3 reaction wheels, friction and saturation, {p['t_final']:g} s at {p['dt']:g} s",
            "Basilisk 2.12 wheel model",
            p["speedup_median"],
            _range(min(r_hub), max(r_hub)) if r_hub else "",
            freefloat=fmt_s(statistics.median(p["freefloat_s"])),
            peer_value=fmt_s(statistics.median(p["basilisk_s"])),
            target=">= 5",
            note=f"body rates agree to {p['agreement_body_rate']:.1e} rad/s",
        )
    ]
    cases = {
        "actuators": "wheel models and 2 thrusters",
        "actuators_gravity_gradient": "wheels, 2 thrusters, gravity gradient",
    }
    for name, r in res.get("seed_robots", {}).items():
        for key, label in cases.items():
            c = r.get(key)
            if not c or not c.get("ratio"):
                continue
            out.append(
                Row(
                    f"{name} with {label}",
                    "the same run without them",
                    statistics.median(c["ratio"]),
                    _range(min(c["ratio"]), max(c["ratio"])),
                    freefloat=fmt_s(statistics.median(c["s"])),
                    peer_value=fmt_s(statistics.median(r["none"]["s"])),
                    target="<= 1.5",
                    note="freefloat with / without (lower is better)",
                )
            )
    return out


def rows_environment(res: dict) -> list[Row]:
    out = []
    for robot, cases in res["results"].items():
        for c, v in cases.items():
            if c == "none":
                continue
            out.append(
                Row(
                    f"{robot} with {c}",
                    "the same run without an environment",
                    v["ratio_to_none"],
                    freefloat=fmt_s(v["median_s"]),
                    target=f"<= {res.get('target_ratio', 1.5)}",
                    note="with / without (lower is better)",
                )
            )
    return out


def rows_sensors(res: dict) -> list[Row]:
    lo_f, hi_f = res["spread_s"]["freefloat"]
    lo_n, hi_n = res["spread_s"]["numpy"]
    return [
        Row(
            f"measure: {res['problem']['samples']:,} samples of {res['problem']['model']}, full sensor set",
            "numpy/scipy, same error models",
            res["speedup_vs_numpy"],
            _range(lo_n / hi_f, hi_n / lo_f),
            fmt_s(res["median_s"]["freefloat"]),
            fmt_s(res["median_s"]["numpy"]),
            note="error statistics agree" if res.get("agreement_passed") else "error statistics DISAGREE",
        )
    ]


def rows_rate_smoother(res: dict) -> list[Row]:
    lo_f, hi_f = res["spread_s"]["freefloat"]
    lo_s, hi_s = res["spread_s"]["scipy"]
    p = res["problem"]
    return [
        Row(
            f"smooth_rates (RTS smoother, GCV): {p['samples']:,} samples × {p['channels']} channels",
            "scipy make_smoothing_spline (GCV)",
            res["speedup_vs_scipy"],
            _range(lo_s / hi_f, hi_s / lo_f),
            fmt_s(res["median_s"]["freefloat"]),
            fmt_s(res["median_s"]["scipy"]),
            note="same spline, GCV choices agree" if res.get("agreement_passed") else "DISAGREE",
        )
    ]


#: name -> (script, full args, fast args, modules needed, extractor[, the JSON file the script writes in --out
#: when it has no --json option])
BENCHES = {
    "identify": ("identify_vs_numpy.py", [], ["--quick"], (), rows_identify),
    "identify_1core": ("identify_vs_numpy.py", ["--cores", "1"], ["--quick", "--cores", "1"], (), rows_identify),
    "compare": (
        "compare_pinocchio.py",
        [],
        ["--quick"],
        ("pinocchio", "crocoddyl"),
        lambda r: rows_generic_ratios(r, "Pinocchio 4.0.0 / Crocoddyl 3.2.1"),
    ),
    "excitation": (
        "excitation_bench.py",
        [],
        ["--quick"],
        ("pinocchio", "scipy"),
        lambda r: rows_generic_ratios(r, "Pinocchio + numpy"),
    ),
    "adaptive": ("adaptive_bench.py", [], ["--quick"], ("scipy",), rows_adaptive),
    "cl": ("cl_vs_numpy.py", [], ["--quick"], (), rows_cl),
    "derivatives": ("derivatives_bench.py", [], ["--quick"], ("pinocchio", "crocoddyl"), rows_derivatives),
    "ddp": ("ddp_vs_crocoddyl.py", [], ["--quick"], ("pinocchio", "crocoddyl"), rows_ddp),
    "mpc": ("mpc_bench.py", [], ["--quick"], (), rows_mpc),
    "campaign": ("campaign_bench.py", [], ["--quick"], ("distributed",), rows_campaign),
    "dq": ("dq_dynamics.py", [], ["--quick"], (), rows_dq),
    "kernels": (
        "kernels_vs_pinocchio.py",
        [],
        ["--repeats", "3", "--batch", "2000", "--calls", "4000"],
        ("pinocchio",),
        rows_kernels,
        "kernels_vs_pinocchio.json",
    ),
    "mujoco": ("sim_vs_mujoco.py", [], ["--repeats", "3"], ("mujoco",), rows_sim_mujoco, "sim_vs_mujoco.json"),
    "basilisk": ("basilisk_wheels.py", [], ["--repeats", "3"], ("Basilisk",), rows_basilisk, "basilisk_wheels.json"),
    "environment": ("environment_bench.py", [], ["--repeats", "3"], (), rows_environment, "environment_bench.json"),
    "sensors": ("sensors_bench.py", [], ["--repeats", "5"], ("scipy",), rows_sensors, "sensors_bench.json"),
    "rate_smoother": (
        "rate_smoother_bench.py",
        [],
        ["--quick"],
        ("scipy",),
        rows_rate_smoother,
        "rate_smoother_bench.json",
    ),
}
RLS_LINE = re.compile(r"^(\S+)\s+wall\s+([\d.]+) ns/update .*?cpu\s+([\d.]+) ns/update")


def run_script(name: str, fast: bool) -> Section:
    script, full, quick, needs, extract, *own_json = BENCHES[name]
    args = quick if fast else full
    out = RESULTS / name
    out.mkdir(parents=True, exist_ok=True)
    jf = out / (own_json[0] if own_json else f"{name}.json")
    jf.unlink(missing_ok=True)
    cmd = [sys.executable, str(HERE / script), *args, "--out", str(out)] + ([] if own_json else ["--json", str(jf)])
    sec = Section(name, "python benches/" + " ".join([script, *args]), quick=fast)
    missing = [m for m in needs if importlib.util.find_spec(m) is None]
    if missing:
        sec.status = f"skipped ({', '.join(missing)} not installed)"
        return sec
    sec.load_before = os.getloadavg()
    t0 = time.perf_counter()
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    sec.seconds = time.perf_counter() - t0
    sec.load_after = os.getloadavg()
    if r.returncode != 0 or not jf.is_file():
        sec.status = f"failed (exit code {r.returncode}): {r.stderr.strip()[-600:]}"
        return sec
    res = json.loads(jf.read_text())
    try:
        sec.rows = extract(res)
    except (KeyError, TypeError, ValueError, ZeroDivisionError, IndexError) as e:
        sec.status = f"ran, but its JSON was not understood ({type(e).__name__}: {e}); see its table below"
    mds = sorted(out.glob("*.md"))
    sec.markdown = "\n".join(p.read_text().strip() for p in mds)
    return sec


def run_rls(fast: bool) -> Section:
    repeats = 3 if fast else 7
    sec = Section("rls", f"cargo bench -p freefloat-core --bench rls_cpu (x{repeats})")
    env = dict(os.environ)
    build = subprocess.run(
        ["cargo", "bench", "-p", "freefloat-core", "--bench", "rls_cpu", "--no-run"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=env,
    )
    if build.returncode != 0:
        sec.status = f"failed to build: {build.stderr.strip()[-600:]}"
        return sec
    sec.load_before = os.getloadavg()
    t0 = time.perf_counter()
    runs: dict[str, list[tuple[float, float]]] = {}
    for _ in range(repeats):
        r = subprocess.run(
            ["cargo", "bench", "-p", "freefloat-core", "--bench", "rls_cpu"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            env=env,
        )
        if r.returncode != 0:
            sec.status = f"failed: {r.stderr.strip()[-600:]}"
            return sec
        for line in r.stdout.splitlines():
            m = RLS_LINE.match(line.strip())
            if m:
                runs.setdefault(m[1], []).append((float(m[2]), float(m[3])))
    sec.seconds = time.perf_counter() - t0
    sec.load_after = os.getloadavg()
    md = [
        f"Median (min-max) of {repeats} runs of 2,000,000 updates each, single thread.",
        "",
        "| estimator | wall ns/update | wall M updates/s | CPU ns/update | CPU M updates/s | target |",
        "|---|---:|---:|---:|---:|---|",
    ]
    for name, vals in runs.items():
        wall = [v[0] for v in vals]
        cpu = [v[1] for v in vals]
        wm, cm = statistics.median(wall), statistics.median(cpu)
        tgt = ">= 1 M/s" if name == "modified_rls_3d" else "-"
        met = f"wall {'met' if wm <= 1000 else 'not met'}, CPU {'met' if cm <= 1000 else 'not met'}"
        md.append(
            f"| {name} | {wm:.0f} ({min(wall):.0f}-{max(wall):.0f}) | {1e3 / wm:.2f} | {cm:.0f} "
            f"({min(cpu):.0f}-{max(cpu):.0f}) | {1e3 / cm:.2f} | {tgt} ({met}) |"
        )
        sec.rows.append(
            Row(
                f"online estimator update {name} (wall / CPU time), M updates/s",
                "none (no library)",
                None,
                f"wall {1e3 / max(wall):.2f}-{1e3 / min(wall):.2f}, CPU {1e3 / max(cpu):.2f}-{1e3 / min(cpu):.2f}",
                f"{1e3 / wm:.2f} / {1e3 / cm:.2f} M/s",
                "",
                tgt if name == "modified_rls_3d" else "",
                note="absolute rate, no peer",
            )
        )
    sec.markdown = "\n".join(md)
    (RESULTS / "rls").mkdir(parents=True, exist_ok=True)
    (RESULTS / "rls" / "rls.json").write_text(json.dumps(runs, indent=1))
    return sec


# --------------------------------------------------------------------------------------------- rendering
def load_str(sec: Section) -> str:
    if not sec.load_before:
        return "-"
    return f"{sec.load_before[0]:.1f} → {sec.load_after[0]:.1f}"


def render(sections: list[Section], fast: bool, git: str, total: float) -> str:
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    mode = "**fast mode** (quick problem sizes / fewer repeats: indicative only)" if fast else "full mode"
    lines = [
        BEGIN,
        "<!-- generated by benches/run_all.py; edit the scripts, not this part -->",
        "## Summary of the last `benches/run_all.py` run",
        "",
        f"Run {when}, git `{git}`, {mode}, {os.cpu_count()} CPUs, total {total / 60:.1f} min. "
        "Ratio = peer time / freefloat time (> 1: freefloat faster), median of each script's interleaved "
        "repeats; spread = the ratio's range over repeats where the script records it; load = 1-minute load "
        "average before → after the script.",
        "",
        "| comparison | peer | freefloat | peer's | ratio | spread | target | load | git |",
        "|---|---|---:|---:|---:|---|---|---|---|",
    ]
    for s in sections:
        if s.status != "ok" and not s.rows:
            lines.append(f"| {s.name}: {s.status.splitlines()[0][:160]} | | | | | | | {load_str(s)} | `{git}` |")
        for r in s.rows:
            ratio = f"{r.ratio:.2f}" if isinstance(r.ratio, (int, float)) else (r.note or "-")
            what = r.what + (" *(quick mode)*" if s.quick and not fast else "")
            lines.append(
                f"| {what} | {r.peer} | {r.freefloat} | {r.peer_value} | {ratio} | {r.spread} | "
                f"{r.target} | {load_str(s)} | `{git}` |"
            )
    lines.append("")
    for s in sections:
        lines += [
            f"### {s.name}: `{s.command}`",
            "",
            f"Status: {s.status.splitlines()[0][:300]}; {s.seconds:.0f} s; load {load_str(s)}; git `{git}`.",
            "",
        ]
        if s.markdown:
            lines += [re.sub(r"^#+ ", "#### ", s.markdown, flags=re.M), ""]
    lines.append(END)
    return "\n".join(lines) + "\n"


def _faster(r: Row) -> str:
    """'1.9× faster than PEER' / '0.7× the speed of PEER' for a peer-time / freefloat-time ratio."""
    if r.ratio is None:
        return f"no result against {r.peer}"
    word = "faster than" if r.ratio >= 1 else "the speed of"
    return f"{r.ratio:.2f}× {word} {r.peer}"


def speed_paragraph(sections: list[Section], git: str, fast: bool) -> str:
    """The README's speed table: one row per capability, each number a row of this run's summary table (never a
    number from an older run), each with its target when the issue set one."""
    rows = {s.name: s.rows for s in sections}
    parts: list[tuple[str, str, str]] = []  # (what, result, target)

    def add(r: Row, label: str) -> None:
        if r.ratio is None:
            return
        if r.note.startswith("freefloat / reference") or "lower is better" in r.note:
            text = f"{r.ratio:.2f}× the time of {r.peer}"
        else:
            text = _faster(r)
        parts.append((label, text, r.target))

    seed = [r for r in rows.get("kernels", []) if "naveen" in r.what or "seed001" in r.what]
    # one row per kernel: the core-to-core loop against the C++ peer where it ran, else the batched call
    loops = [r for r in seed if "engine loop vs C++ loop" in r.what]
    for r in loops or [r for r in seed if "estimated peer" not in r.what and not r.what.startswith("single")]:
        add(r, r.what.split(",")[0].replace(" per call", "") + " on the Naveen robot")
    for r in seed:
        if r.what.startswith("single"):
            add(r, r.what.split(",")[0].replace("single", "a single"))
    # the strongest of MuJoCo's two loops (the Python mj_step loop, the C rollout) in this run: the smaller ratio
    sims = [r for r in rows.get("mujoco", []) if r.what.startswith("MuJoCo ") and r.ratio is not None]
    if sims:
        r = min(sims, key=lambda r: r.ratio)
        add(r, f"10 s 1 kHz RK4 simulation, against {r.what.split(' / ')[0]} (the faster of MuJoCo's two loops)")
    for r in rows.get("identify", []):
        add(r, "identification " + r.what.split(" (")[0])
    for r in rows.get("rls", []):
        if r.what.startswith("modified_rls_3d") or "modified" in r.what:
            parts.append(("online 3D post-capture estimator", f"{r.freefloat} in wall / CPU time", r.target))
    for r in rows.get("ddp", []):
        add(r, "DDP on the ch. 8 tracking problem")
    for r in rows.get("basilisk", [])[:1]:
        add(r, "hub with three reaction wheels")
    mode = " in fast mode (quick problem sizes, indicative only)" if fast else ""
    table = ["| what | freefloat against the peer | target |", "|---|---|---|"]
    table += [f"| {what} | {text} | {target or '—'} |" for what, text, target in parts] or ["| no rows | | |"]
    return (
        f"{SPEED_BEGIN}\nMeasured by `python benches/run_all.py`{mode} at git `{git}` against the strongest peer in "
        f"the same run; every number is a row of [BENCHMARKS.md](BENCHMARKS.md), with its spread and the machine "
        f"load there.\n\n" + "\n".join(table) + f"\n{SPEED_END}"
    )


def replace_between(text: str, begin: str, end: str, new: str, prepend_if_absent: bool) -> str | None:
    if begin in text and end in text:
        a, b = text.index(begin), text.index(end) + len(end)
        return text[:a] + new.rstrip("\n") + text[b:]
    if prepend_if_absent:
        first_nl = text.find("\n") + 1  # after the title line
        return text[:first_nl] + "\n" + new + "\n" + text[first_nl:]
    return None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__.split("\n\n", 1)[1] + "\nbenchmarks: " + ", ".join([*BENCHES, "rls"]),
    )
    ap.add_argument("--fast", action="store_true", help="quick modes and fewer repeats (aim: <= 15 min)")
    ap.add_argument("--only", nargs="+", default=None, help="run only these benchmarks")
    ap.add_argument(
        "--quick-for",
        nargs="+",
        default=[],
        metavar="NAME",
        help="in a full run, run these benchmarks in their quick mode (their rows say so)",
    )
    ap.add_argument("--dry-run", action="store_true", help="do not touch BENCHMARKS.md / README.md")
    ap.add_argument("--benchmarks-md", type=Path, default=ROOT / "BENCHMARKS.md")
    ap.add_argument("--readme", type=Path, default=ROOT / "README.md")
    a = ap.parse_args(argv)
    names = a.only or [*BENCHES, "rls"]
    bad = [n for n in [*names, *a.quick_for] if n not in BENCHES and n != "rls"]
    if bad:
        ap.error(f"unknown benchmark(s) {bad}; choose from {[*BENCHES, 'rls']}")
    git = git_hash()
    t0 = time.perf_counter()
    sections = []
    try:
        for i, n in enumerate(names, 1):
            print(f"[{i}/{len(names)}] {n} ... ", end="", flush=True)
            quick = a.fast or n in a.quick_for
            sec = run_rls(quick) if n == "rls" else run_script(n, quick)
            sections.append(sec)
            elapsed = (time.perf_counter() - t0) / 60
            print(f"{sec.status.splitlines()[0][:200]} ({sec.seconds:.0f} s, total {elapsed:.1f} min)", flush=True)
    except KeyboardInterrupt:
        print("\ninterrupted: nothing written", file=sys.stderr)
        return 130
    total = time.perf_counter() - t0
    text = render(sections, a.fast, git, total)
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "BENCHMARKS_generated.md").write_text(text)
    para = speed_paragraph(sections, git, a.fast)
    (RESULTS / "README_speed.md").write_text(para + "\n")
    if not a.dry_run:
        bm = a.benchmarks_md.read_text() if a.benchmarks_md.is_file() else "# Benchmarks\n"
        a.benchmarks_md.write_text(replace_between(bm, BEGIN, END, text, True))
        if a.readme.is_file():
            new = replace_between(a.readme.read_text(), SPEED_BEGIN, SPEED_END, para, False)
            if new is None:
                print(f"{a.readme}: no {SPEED_BEGIN} marker, speed paragraph not written", file=sys.stderr)
            else:
                a.readme.write_text(new)
    print(f"done in {total / 60:.1f} min; wrote {RESULTS}" + ("" if a.dry_run else f", {a.benchmarks_md.name}"))
    failed = [s.name for s in sections if s.status.startswith("failed")]
    if failed:
        print(f"failed: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
