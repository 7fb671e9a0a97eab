#!/usr/bin/env python3
"""Smoke run of every benchmark for CI: each script with --quick into a temporary folder, then the agreement
numbers it recorded are checked. Exits non-zero if a script fails (each one aborts itself when freefloat and
its peer disagree) or a recorded number is out of bounds. Timings are not judged here (a loaded CI machine
says nothing about speed); the full runs and their tables are in benches/results/.

    python benches/smoke.py                 # all of them
    python benches/smoke.py identify dq     # a subset, by name

Pinocchio and Crocoddyl (the `[test]` extra) are needed for compare_pinocchio and excitation_bench; without them
those two are reported as skipped, not passed.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _check_mission(out: Path) -> list[str]:
    res = json.loads((out / "mission_bench.json").read_text())
    bad = []
    if set(res["phase_median_s"]) < {"capture", "detumble_simulation", "identification", "berth_closed_loop"}:
        bad.append(f"phases missing: {sorted(res['phase_median_s'])}")
    if not res["mission_time_s"] > res["handover_s"] > 0:
        bad.append(f"mission time {res['mission_time_s']} / handover {res['handover_s']}")
    return bad


def _check_compare_pinocchio(out: Path) -> list[str]:
    res = json.loads((out / "compare_pinocchio.json").read_text())
    bad = [f"agreement {k} = {v:.3g} > 1e-9" for k, v in res["agreement_max_rel_error"].items() if not v < 1e-9]
    if not (out / "compare_pinocchio.md").read_text().startswith("# freefloat vs Pinocchio"):
        bad.append("compare_pinocchio.md has no title")
    return bad


def _check_excitation(out: Path) -> list[str]:
    res = json.loads((out / "excitation_bench.json").read_text())
    agree, bad = res["agreement"], []
    if res["agreement_passed"] is not True:
        bad.append("agreement_passed is not true")
    bad += [
        f"{k} = {agree[k]:.3g} > 1e-6"
        for k in ("condition_number_rel", "mean_square_rel", "objective_rel")
        if not agree[k] <= 1e-6
    ]
    bad += [
        f"{k} = {agree[k]:.3g} > 1e-9"
        for k in ("regressor_max_rel", "batch_vs_sequential_max_rel")
        if not agree[k] <= 1e-9
    ]
    if res["problem"]["intervals"] != 256 or res["problem"]["regressor_shape"] != [7680, 52]:
        bad.append(f"unexpected problem size {res['problem']}")
    d = res["design"]
    if not (0 < d["kept_intervals"] <= 256 and d["condition_number"] >= 1.0):
        bad.append(f"design result out of range: {d}")
    return bad


def _check_identify(out: Path) -> list[str]:
    res = json.loads((out / "identify_vs_numpy.json").read_text())
    a, bad = res["agreement"], []
    if not a["estimate_max_rel"] < 1e-9:
        bad.append(f"estimate_max_rel = {a['estimate_max_rel']:.3g} >= 1e-9")
    if not a["regressor_max_rel"] < 1e-12:
        bad.append(f"regressor_max_rel = {a['regressor_max_rel']:.3g} >= 1e-12")
    return bad


def _check_ddp(out: Path) -> list[str]:
    res = json.loads((out / "ddp_vs_crocoddyl.json").read_text())
    a, bad = res["agreement"], []
    if not a["final_cost_rel"] <= 1e-6:
        bad.append(f"final_cost_rel = {a['final_cost_rel']:.3g} > 1e-6")
    if a["iterations_freefloat_le_crocoddyl"] is not True:
        bad.append("freefloat needed more iterations than Crocoddyl")
    return bad


def _check_mpc(out: Path) -> list[str]:
    res = json.loads((out / "mpc_bench.json").read_text())
    bad = []
    for name, c in res["cases"].items():
        if c["accuracy_same_in_every_repeat"] is not True:
            bad.append(f"{name}: the tracking accuracy changed between repeats")
        if not (c["replan_ms"]["count"] >= 1 and c["replan_ms"]["median_ms"] > 0):
            bad.append(f"{name}: no re-plan timed")
        if c["troubled_replans"]:
            bad.append(f"{name}: {c['troubled_replans']} troubled re-plans")
    return bad


def _check_dq(out: Path) -> list[str]:
    # the script aborts when dq_dynamics and aba disagree; check that it wrote its table
    return [] if (out / "dq_dynamics.md").is_file() else ["dq_dynamics.md not written"]


def _check_adaptive(out: Path) -> list[str]:
    res = json.loads((out / "adaptive_bench.json").read_text())
    a, bad = res["agreement"], []
    if not a["example_a_max_abs"] < 1e-6:
        bad.append(f"example A agreement {a['example_a_max_abs']:.3g} >= 1e-6")
    if not a["example_b_max_abs"] < 1e-9:
        bad.append(f"example B agreement {a['example_b_max_abs']:.3g} >= 1e-9")
    return bad


def _check_derivatives(out: Path) -> list[str]:
    res = json.loads((out / "derivatives_bench.json").read_text())
    bad = [f"agreement {k} = {v:.3g} > 1e-8" for k, v in res["agreement_max_rel_error"].items() if not v < 1e-8]
    if set(res["results"]) != {"ch8_spacecraft_wrist", "random_tree_26"}:
        bad.append(f"unexpected models {sorted(res['results'])}")
    return bad


def _check_campaign(out: Path) -> list[str]:
    # the script aborts when the campaign's rows and the direct runs disagree; check what it recorded
    res = json.loads((out / "campaign_bench.json").read_text())
    thr, bad = res["throughput_runs_per_s"], []
    if not all(v > 0 for v in thr.values()):
        bad.append(f"throughput not positive: {thr}")
    if not res["agreement_max_rel"] <= 1e-12:
        bad.append(f"agreement_max_rel = {res['agreement_max_rel']:.3g} > 1e-12")
    if not 0 <= res["overhead"]["per_run_overhead_ms"] < 10_000:
        bad.append(f"per-run overhead out of range: {res['overhead']}")
    return bad


def _check_cl(out: Path) -> list[str]:
    res = json.loads((out / "cl_vs_numpy.json").read_text())
    bad = []
    for ns, a in res["agreement"].items():
        if not (a["freefloat_max_rel_error"] < 0.01 and a["numpy_max_rel_error"] < 0.01):
            bad.append(f"N_s = {ns}: an estimator missed 1 % ({a})")
        if not a["engine_estimator_vs_run_max_rel_diff"] < 1e-6:
            bad.append(f"N_s = {ns}: engine estimator and whole run disagree ({a})")
    return bad


def _check_sensors(out: Path) -> list[str]:
    res = json.loads((out / "sensors_bench.json").read_text())
    bad = [] if res["agreement_passed"] is True else ["agreement_passed is not true"]
    bad += [f"{k}: std ratio {r['ratio']:.3f}" for k, r in res["agreement"].items() if not 0.5 < r["ratio"] < 2.0]
    return bad


def _check_rate_smoother(out: Path) -> list[str]:
    res = json.loads((out / "rate_smoother_bench.json").read_text())
    a = res["agreement"]
    bad = [] if res["agreement_passed"] is True else [f"agreement_passed is not true: {a}"]
    if not a["same_penalty_max_rel_diff"] < 1e-6:
        bad.append(f"same penalty: derivatives differ by {a['same_penalty_max_rel_diff']:.3g}")
    return bad


def _check_kernels(out: Path) -> list[str]:
    res = json.loads((out / "kernels_vs_pinocchio.json").read_text())
    bad = []
    for robot, r in res["results"].items():
        bad += [f"{robot}: agreement {k} = {v:.3g} > 1e-9" for k, v in r["agreement_max_rel"].items() if not v <= 1e-9]
        peer = r.get("cpp_peer_agreement_max_rel") or {}  # None when the C++ peer could not be built
        bad += [f"{robot}: C++ peer agreement {k} = {v:.3g} > 1e-9" for k, v in peer.items() if not v <= 1e-9]
    if len(res["results"]) != 3:
        bad.append(f"expected 3 robots, got {sorted(res['results'])}")
    return bad


def _check_sim_vs_mujoco(out: Path) -> list[str]:
    res = json.loads((out / "sim_vs_mujoco.json").read_text())
    a, bad = res["agreement"], []
    if not a["ff_vs_mujoco_max_abs"] < 1e-5:
        bad.append(f"freefloat vs MuJoCo trajectories differ by {a['ff_vs_mujoco_max_abs']:.3g}")
    if a["simulate_many"] != 0.0:
        bad.append(f"simulate_many differs from sequential simulate by {a['simulate_many']:.3g}")
    return bad


def _check_basilisk_wheels(out: Path) -> list[str]:
    res = json.loads((out / "basilisk_wheels.json").read_text())
    p1, bad = res["hub_three_wheels"], []
    if not p1["agreement_body_rate"] < 1e-9:
        bad.append(f"agreement_body_rate = {p1['agreement_body_rate']:.3g} >= 1e-9")
    if not res["seed_robots"]:
        bad.append("no seed robot was timed")
    return bad


def _check_environment(out: Path) -> list[str]:
    res = json.loads((out / "environment_bench.json").read_text())
    bad = [
        f"{k}: an environment that is off changed the run"
        for k, a in res["agreement"].items()
        if not a["off_bitwise_equal"]
    ]
    if set(res["results"]) != {"naveen_dual_arm", "valverde_ch9_two_arm", "zhang2020_3d"}:
        bad.append(f"unexpected models {sorted(res['results'])}")
    return bad


def _check_soak(out: Path) -> list[str]:
    s = json.loads((out / "soak.json").read_text())["summary"]
    bad = []
    if not (s["drift_linear_rel_max"] < 1e-12 and s["drift_angular_rel_max"] < 1e-12):
        bad.append(f"momentum drift above round-off: {s['drift_linear_rel_max']:.3g}, {s['drift_angular_rel_max']:.3g}")
    if not s["rss_growth_after_warmup_mb"] < 50:
        bad.append(f"resident memory grew by {s['rss_growth_after_warmup_mb']:.1f} MB")
    if not (s["chunks"] >= 1 and s["rls_samples"] >= 100):
        bad.append(f"too little work done: {s['chunks']} chunks, {s['rls_samples']} RLS samples")
    return bad


#: name -> (script, extra arguments, modules it needs, check of its output)
BENCHES = {
    "compare": ("compare_pinocchio.py", [], ("pinocchio", "crocoddyl"), _check_compare_pinocchio),
    "excitation": ("excitation_bench.py", [], ("pinocchio", "scipy"), _check_excitation),
    "identify": ("identify_vs_numpy.py", ["--repeats", "1"], (), _check_identify),
    "dq": ("dq_dynamics.py", [], (), _check_dq),
    "adaptive": ("adaptive_bench.py", [], ("scipy",), _check_adaptive),
    "derivatives": ("derivatives_bench.py", [], ("pinocchio", "crocoddyl"), _check_derivatives),
    "campaign": ("campaign_bench.py", [], ("distributed",), _check_campaign),
    "ddp": ("ddp_vs_crocoddyl.py", [], ("pinocchio", "crocoddyl"), _check_ddp),
    "mpc": ("mpc_bench.py", [], (), _check_mpc),
    "cl": ("cl_vs_numpy.py", [], (), _check_cl),
    "sensors": ("sensors_bench.py", [], ("scipy",), _check_sensors),
    "rate_smoother": ("rate_smoother_bench.py", [], ("scipy",), _check_rate_smoother),
    "kernels": ("kernels_vs_pinocchio.py", [], ("pinocchio",), _check_kernels),
    "mujoco": ("sim_vs_mujoco.py", [], ("mujoco",), _check_sim_vs_mujoco),
    "basilisk_wheels": ("basilisk_wheels.py", [], ("Basilisk",), _check_basilisk_wheels),
    "environment": ("environment_bench.py", [], (), _check_environment),
    "soak": ("soak.py", [], (), _check_soak),
    "mission": ("mission_bench.py", [], ("scipy",), _check_mission),
}


def main(argv: list[str]) -> int:
    names = argv or list(BENCHES)
    unknown = [n for n in names if n not in BENCHES]
    if unknown:
        print(f"unknown benchmark(s) {unknown}; choose from {list(BENCHES)}", file=sys.stderr)
        return 2
    failed = []
    for name in names:
        script, extra, needs, check = BENCHES[name]
        missing = [mod for mod in needs if importlib.util.find_spec(mod) is None]
        if missing:
            print(f"SKIP {script}: {', '.join(missing)} not installed")
            continue
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            r = subprocess.run(
                [sys.executable, str(HERE / script), "--quick", "--out", tmp, *extra], capture_output=True, text=True
            )
            wall = time.perf_counter() - t0
            problems = [f"exit code {r.returncode}: {r.stderr.strip()[-1500:]}"] if r.returncode else check(Path(tmp))
        if problems:
            failed.append(name)
            print(f"FAIL {script} ({wall:.0f} s):\n  " + "\n  ".join(problems))
        else:
            print(f"ok   {script} ({wall:.0f} s)")
    if failed:
        print(f"{len(failed)} benchmark smoke run(s) failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
