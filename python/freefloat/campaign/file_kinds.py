"""Campaign kinds for the scenario files that the chapter-4, chapter-8 and chapter-9 commands run
(`control_adaptive`, `control_ddp`, `identify_cl`).

Their scenarios are read and checked by each command's own `load_scenario`, which takes a built-in name or a YAML
file. A campaign run holds the scenario as a mapping (with the campaign's parameters set on it), so `run` writes
that mapping to a YAML file in a temporary folder and hands the file to the same reader: one reader, one set of
checks and messages, whichever way a scenario arrives. Model files named by a relative path are made absolute
when the scenario is loaded, so they still resolve from the temporary folder."""

from __future__ import annotations

import copy
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from .._core import InputError
from .kind import Kind, json_roundtrip, leaf_paths


def _load(ref, kind: str) -> dict:
    from ..io import scenario_files

    if isinstance(ref, dict):
        d = copy.deepcopy(ref)
        d.setdefault("kind", kind)
        d.setdefault("name", "inline")
        if d["kind"] != kind:
            raise InputError(f"scenario mapping: kind '{d['kind']}' given to a campaign of kind '{kind}'")
        return json_roundtrip(d)
    d, source = scenario_files.read(ref, kind=kind)
    src = Path(source)
    for key in ("model", "robot", "servicer"):
        p = d.get(key)
        if isinstance(p, str) and Path(p).suffix in (".yaml", ".yml", ".urdf", ".xml") and src.is_file():
            if not Path(p).is_absolute():
                d[key] = str((src.parent / p).resolve())
    return json_roundtrip(d)


def _normalize(d: dict) -> dict:
    d = json_roundtrip(d)
    d.pop("description", None)  # not an input of a run
    return d


def _as_file(scenario: dict, folder: str) -> Path:
    path = Path(folder) / f"{scenario.get('name', 'scenario')}.yaml"
    path.write_text(yaml.safe_dump(scenario, sort_keys=False), encoding="utf-8")
    return path


def _flat(d: dict, prefix: str = "") -> dict:
    """The numbers, flags and short strings of a results mapping, nested keys joined by dots (lists dropped, except
    short numeric ones, which become one entry per element)."""
    out = {}
    for k, v in d.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(_flat(v, name + "."))
        elif isinstance(v, bool) or v is None:
            out[name] = v
        elif isinstance(v, (int, float, np.floating, np.integer)):
            out[name] = float(v)
        elif isinstance(v, str) and len(v) <= 200:
            out[name] = v
        elif isinstance(v, (list, tuple)) and 0 < len(v) <= 12 and all(isinstance(x, (int, float)) for x in v):
            out.update({f"{name}.{j}": float(x) for j, x in enumerate(v)})
    return out


def run_identify_cl(scenario: dict, seed: int) -> dict:
    """One chapter-9 concurrent-learning run -> its results.json numbers (max and median final relative error,
    time within 1 %, rank, ...) and each parameter's final relative error. The campaign's `noise.wrench` and
    `noise.rate` set the joint force/torque and body-motion sensor noise, drawn with `seed`."""
    from ..identification import concurrent as cl

    t0 = time.perf_counter()
    scenario = dict(scenario)
    noise = scenario.pop("noise", None) or {}  # the campaign's own section: sensor noise levels of the run
    unknown = sorted(set(noise) - {"wrench", "rate"})
    if unknown:
        raise InputError(f"identify_cl campaign: noise.{unknown[0]} is not a noise level (noise.wrench, noise.rate)")
    with tempfile.TemporaryDirectory() as tmp:
        sc = cl.load_scenario(_as_file(scenario, tmp))
    res = cl.run(sc, wrench_noise=float(noise.get("wrench", 0.0)), rate_noise=float(noise.get("rate", 0.0)),
                 noise_seed=seed)  # fmt: skip
    d = res.to_dict()
    out = _flat({k: v for k, v in d.items() if k not in ("final_relative_error",)})
    names = [f"{b}.{p}" for b in d["bodies"] for p in d["parameter_order"]]
    out.update({f"final_relative_error.{n}": float(e) for n, e in zip(names, d["final_relative_error"])})
    out["median_final_relative_error"] = float(np.median(d["final_relative_error"]))
    out["wall_s"] = time.perf_counter() - t0
    return out


def run_control_adaptive(scenario: dict, seed: int) -> dict:
    """One chapter-4 adaptive pose-tracking scenario: every CL weight of the scenario and the baseline -> each run's
    summary (time within 1 %, final errors, tracking errors, ...) under `cl.` (the first CL weight), `baseline.`
    and `alpha=<value>.` for further weights. The scenario's own seed
    (`learning.seed`, the stack selection) is what a campaign varies; `seed` is not used."""
    from ..control import adaptive as ad

    del seed
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        sc = ad.load_scenario(_as_file(scenario, tmp))
    res = ad.run(sc)
    out = {}
    cl_runs = [label for label in res.runs if label != "baseline"]
    for label, r in res.runs.items():
        # the first CL run's columns keep one name whatever its alpha (a campaign over learning.alpha compares them)
        prefix = "cl" if cl_runs and label == cl_runs[0] else label
        out.update(_flat(r.summary(sc.truth), f"{prefix}."))
    out["wall_s"] = time.perf_counter() - t0
    return out


def run_control_ddp(scenario: dict, seed: int) -> dict:
    """One chapter-8 DDP solve -> its results.json numbers (iterations, final cost, end-effector errors over the
    final hold, peak base force and torque, solve time). Deterministic: `seed` is not used."""
    from ..control import ddp

    del seed
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        prob = ddp.load_scenario(_as_file(scenario, tmp))
    res = ddp.results(prob, ddp.solve(prob))
    res.pop("cost_history", None)
    out = _flat(res)
    out["wall_s"] = time.perf_counter() - t0
    return out


def run_mission(scenario: dict, seed: int) -> dict:
    """One capture mission (capture, detumble + online identification from the sensors drawn with `seed`, berth
    with the nominal, identified and true models) -> its results.json numbers, flattened."""
    from .. import mission as fm

    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        m = fm.load_mission(_as_file(scenario, tmp))
    res = fm.run(m, seed=seed)
    res.pop("traces", None)
    for key in ("v_post", "momentum_before", "momentum_after", "impulse_world"):
        res.get("capture", {}).pop(key, None)
    res.get("identify", {}).pop("sensors", None)
    out = _flat(res)
    out["wall_s"] = time.perf_counter() - t0
    return out


def kinds() -> list[Kind]:
    """The kinds of this module, in the order the registry lists them."""
    out = []

    def kind(name, description, run, headline, extra=(), campaign_keys=()):
        out.append(
            Kind(
                name=name,
                description=description,
                load=lambda ref, _k=name: _load(ref, _k),
                parameters=lambda base, _x=extra: (
                    [p for p in leaf_paths(base) if p not in ("kind", "name", "description")] + list(_x)
                ),
                run=run,
                normalize=_normalize,
                headline=headline,
                campaign_keys=campaign_keys,
            )
        )

    kind(
        "identify_cl",
        "Valverde 2018 ch. 9: concurrent-learning mass estimation of every body (scenario: a built-in name such as "
        "valverde_ch9_two_arm, a file, or a mapping)",
        run_identify_cl,
        ("max_final_relative_error", "median_final_relative_error", "time_within_1pct_s"),
        extra=("noise.wrench", "noise.rate"),  # sensor noise of the run (N, N m; m/s, rad/s), drawn with the seed
        campaign_keys=("noise",),
    )
    kind(
        "control_adaptive",
        "Valverde 2018 ch. 4: adaptive pose tracking with concurrent learning beside the baseline (scenario: "
        "valverde_ch4_example_a or _b, a file, or a mapping)",
        run_control_adaptive,
        ("cl.time_within_1pct_s", "baseline.time_within_1pct_s"),
    )
    kind(
        "control_ddp",
        "Valverde 2018 ch. 8: end-effector control by DDP (scenario: valverde_ch8_tracking or _stabilisation, a "
        "file, or a mapping)",
        run_control_ddp,
        ("final_cost", "ee_position_error_final_hold_max_m", "ee_angle_error_final_hold_max_deg", "iterations"),
    )
    kind(
        "mission",
        "Capture mission: grasp, detumble and identify online, berth with the nominal, identified and true models "
        "(scenario: zhang2020_3d_capture, a file, or a mapping)",
        run_mission,
        (
            "identify.handover_time_s",
            "identify.target_inertia_error_relative",
            "berth.nominal.position_error_final_m",
            "berth.identified.position_error_final_m",
        ),
    )
    return out
