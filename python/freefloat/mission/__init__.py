"""The capture mission end to end (`freefloat mission`): capture a drifting, tumbling target of unknown inertia,
identify the stack online from its telemetry while it is detumbled, and berth the target with the estimate,
compared on the true plant against the nominal model (target guessed) and the truth.

    from freefloat import mission
    res = mission.run("zhang2020_3d_capture", progress=print)
    print(res["berth"]["identified"]["position_error_final_m"])

The phases and their assumptions are in docs/mission.md; the physics (impact, simulation, rows, RLS, DDP) is the
engine's, this package wires the phases together and measures them.
"""

from __future__ import annotations

import time

import numpy as np

from .._core import Interrupted
from . import adaptive_berth, phases
from .spec import Mission, list_missions, load_mission

__all__ = ["Mission", "list_missions", "load_mission", "run", "write"]


def run(mission: Mission | str, seed: int = 0, controller: str | None = None, progress=None) -> dict:
    """Run every phase of `mission` (a built-in name, a file or a `Mission`). Returns a dict with the phases'
    numbers (`capture`, `identify`, `berth` per model, `timeline`, `timings`) and, under `traces`, the histories
    the figures are drawn from. Ctrl-C raises `freefloat.Interrupted` whose `partial` holds the phases done."""
    if not isinstance(mission, Mission):
        mission = load_mission(mission)
    say = progress or (lambda s: None)
    out: dict = {"mission": mission.name, "description": mission.description, "phases_done": []}
    traces: dict = {}
    out["traces"] = traces
    wall0 = time.perf_counter()
    try:
        truth = phases.load_truth(mission)
        # phase 1: the grasp
        cap = phases.capture(mission, truth)
        sc = phases.detumble_scenario(mission, cap["q"], cap["v_post"], truth)
        # refused before simulating: a berth point the arm cannot reach (the reach does not depend on the base pose)
        phases.check_reachable(truth, cap["q"], phases.berth_reference(truth, cap["q"], mission.berth), mission.source)
        out["capture"] = {
            "target_mass_kg": mission.target.mass,
            "impulse_linear_Ns": float(np.linalg.norm(cap["impulse_world"][:3])),
            "impulse_angular_Nms": float(np.linalg.norm(cap["impulse_world"][3:])),
            "impulse_world": cap["impulse_world"].tolist(),
            "momentum_before": cap["momentum_before"].tolist(),
            "momentum_after": cap["momentum_after"].tolist(),
            "momentum_error_relative": cap["momentum_error_relative"],
            "energy_before_J": float(cap["energy_before"]),
            "energy_after_J": float(cap["energy_after"]),
            "v_post": cap["v_post"].tolist(),
        }
        if mission.approach_s > 0:
            ap = phases.approach(mission, truth, cap, mission.approach_s)
            traces["approach"] = ap
            out["approach"] = {
                "duration_s": mission.approach_s,
                "gap_at_start_m": float(ap["gap"][0]),
                "gap_at_contact_m": float(ap["gap"][-1]),
                "momentum_drift_relative": ap["momentum_drift_relative"],
            }
        out["phases_done"].append("capture")
        say(
            f"capture: impulse {out['capture']['impulse_linear_Ns']:.2f} N s / "
            f"{out['capture']['impulse_angular_Nms']:.2f} N m s, momentum kept to {cap['momentum_error_relative']:.1e}"
        )
        # phase 2: detumble and identify online
        ident = phases.identify_online(mission, truth, sc, seed=seed, progress=say)
        tgt = slice(len(ident["names"]) // 2, len(ident["names"]))
        est = ident["estimates"][ident["handover_index"]]
        tru = ident["truth_physical"]
        rel = np.abs(est - tru) / phases.relative_scale(tru)
        names = ident["names"]
        sim = ident["sim"]
        ts = np.asarray(sim["t"])
        sel = ts <= ident["handover_time"] + 1e-9
        vb = np.asarray(sim["v"])[sel]
        tau = np.asarray(sim["tau"])[sel]
        dt = sc.dt
        out["identify"] = {
            "method": mission.method,
            "estimator": "standard-parameter RLS (base and target in one step)",
            "converged": ident["converged"],
            "handover_time_s": ident["handover_time"],
            "max_duration_s": mission.max_duration,
            "tolerance": mission.tolerance,
            "target_mass_estimate_kg": float(est[tgt][0]),
            "target_mass_error_relative": float(rel[tgt][0]),
            "target_com_error_m": float(np.linalg.norm(est[tgt][1:4] - tru[tgt][1:4])),
            "target_inertia_error_relative": float(
                np.max(np.abs(est[tgt][[4, 7, 9]] - tru[tgt][[4, 7, 9]]) / np.abs(tru[tgt][[4, 7, 9]]))
            ),
            "errors_relative": {n: float(e) for n, e in zip(names, rel)},
            "sigma_at_handover": {
                "mass_relative": float(ident["sigma_rel_mass"][ident["handover_index"]]),
                "com_m": float(ident["sigma_com_m"][ident["handover_index"]]),
                "inertia_relative": float(ident["sigma_rel_inertia"][ident["handover_index"]]),
            },
            "base_rate_peak_rad_s": float(np.linalg.norm(vb[:, 3:6], axis=1).max()),
            # the eq. 40 damping force on the base up to the handover (the scenario's thrusters, when it has them,
            # come on top: postcapture results report their propellant)
            "thrust_impulse_Ns": float(np.sum(np.linalg.norm(tau[:, :3], axis=1)) * dt),
            "sensors": None if sc.sensors is None else sc.sensors.to_dict(),
            "timings": ident["timings"],
        }
        traces["identify"] = ident
        out["phases_done"].append("identify")
        say(
            f"identify: {'converged' if ident['converged'] else 'NOT converged'} "
            f"at t = {ident['handover_time']:.1f} s; "
            f"target mass error {100 * out['identify']['target_mass_error_relative']:.2f} %"
        )
        # phase 3: berth with each model, on the true plant
        berth = dict(mission.berth)
        if controller:
            berth["controller"] = controller
        berth.setdefault("controller", "policy")
        for k, v in phases.DEFAULT_BERTH.items():
            berth.setdefault(k, v)
        q_h, v_h = ident["handover_state"]
        x0 = np.r_[q_h, v_h]
        ref7 = phases.berth_reference(truth, q_h, berth)
        models = {
            "nominal": phases.nominal_model(truth, mission),
            "identified": phases.identified_model(truth, ident),
            "truth": truth,
        }
        out["berth"] = {"controller": berth["controller"], "reference": ref7.tolist()}
        traces["berth"] = {}
        runs = [(name, model, berth, None) for name, model in models.items()]
        if berth.get("adaptive", True):
            # the adaptive row: MPC from the identified model, re-planning on the estimate the berth refines
            ab = {**adaptive_berth.DEFAULTS, **berth, "controller": "mpc"}
            observer = adaptive_berth.BerthEstimator(truth, ident, ab, seed=seed)
            observer.check_sensors(float(ab["dt"]) / phases.BERTH_SUBSTEPS)
            runs.append(("adaptive", models["identified"], ab, observer))
        for name, model, b, observer in runs:
            r = phases.berth_run(model, truth, x0, ref7, b, name, observer=observer)
            if observer is not None:
                r["summary"]["online"] = adaptive_berth.summary(observer, ident)
                traces["adaptive_estimate"] = {
                    "t": np.array([ident["handover_time"] + t for t, _ in observer.history]),
                    "estimates": np.array([e for _, e in observer.history]),
                }
            out["berth"][name] = r["summary"]
            s = r["summary"]
            for joint, ratio in s["planned_torque_over_limit"].items():
                say(f"warning: the berth planned on the {name} model needs {ratio:.2f} x joint {joint}'s effort limit")
            if "failed" in s:
                say(f"berth with the {name} model: {s['failed']}")
                continue
            traces["berth"][name] = r["trace"]
            for joint, ratio in s["joint_torque_over_limit"].items():
                say(f"warning: the berth with the {name} model needs {ratio:.2f} x the effort limit of joint {joint}")
            say(
                f"berth with the {name} model: final error {1e3 * s['position_error_final_m']:.1f} mm / "
                f"{s['angle_error_final_deg']:.2f} deg, "
                + ("never settled" if s["settling_time_s"] is None else f"settled at {s['settling_time_s']:.2f} s")
            )
        out["phases_done"].append("berth")
        t_c = ident["handover_time"]
        out["timeline"] = [
            {"phase": "approach (servicer and free target)", "start_s": -mission.approach_s, "end_s": 0.0}
        ]
        out["timeline"] = out["timeline"] if mission.approach_s > 0 else []
        out["timeline"] += [
            {"phase": "capture", "start_s": 0.0, "end_s": 0.0},
            {"phase": "detumble + identify", "start_s": 0.0, "end_s": t_c},
            {"phase": "berth", "start_s": t_c, "end_s": t_c + float(berth["duration"])},
        ]
    except (KeyboardInterrupt, Interrupted) as e:
        out["interrupted"] = f"stopped after {', '.join(out['phases_done']) or 'no phase'} ({e or 'Ctrl-C'})"
        out["wall_time_s"] = time.perf_counter() - wall0
        err = Interrupted(out["interrupted"])
        err.partial = out
        raise err from None
    out["wall_time_s"] = time.perf_counter() - wall0
    return out


def write(res: dict, out_dir) -> list:
    """results.json (every printed number), table.txt and the figures of a mission run into `out_dir`."""
    import json
    from pathlib import Path

    from ..io.results import json_default
    from . import plots

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    data = {k: v for k, v in res.items() if k != "traces"}
    complete = "berth" in res.get("phases_done", [])  # an interrupted run keeps its numbers, not half a figure
    if complete:
        data["series"] = series(res)
    (out / "results.json").write_text(json.dumps(data, indent=1, default=json_default), encoding="utf-8")
    (out / "table.txt").write_text(table(res), encoding="utf-8")
    files = [out / "results.json", out / "table.txt"]
    if complete:
        files.append(plots.timeline(res, out / "mission_timeline.png"))
    return files


def series(res: dict, step_s: float = 0.5) -> dict:
    """The histories behind the figure, every `step_s` seconds, for the HTML report (`freefloat report DIR`): the
    target's estimate over truth up to the handover, and each berth run's target position error and base rate."""
    ident = res["traces"]["identify"]
    t, est, tru, names = ident["rows_t"], ident["estimates"], ident["truth_physical"], ident["names"]
    keep = t <= ident["handover_time"] + 1e-9
    stride = max(1, int(round(step_s / max(float(np.median(np.diff(t))), 1e-9)))) if len(t) > 1 else 1
    h = len(names) // 2
    out = {
        "identify": {
            "t": t[keep][::stride].tolist(),
            "estimate_over_truth": {
                names[j]: (est[keep, j][::stride] / tru[j]).tolist() for j in (h, h + 4, h + 7, h + 9)
            },
        },
        "berth": {},
    }
    for name, tr in res["traces"]["berth"].items():
        bt = np.asarray(tr["t"])
        st = max(1, int(round(step_s / max(float(np.median(np.diff(bt))), 1e-9)))) if len(bt) > 1 else 1
        out["berth"][name] = {
            "t": (ident["handover_time"] + bt[::st]).tolist(),
            "position_error_m": np.asarray(tr["position_error"])[::st].tolist(),
            "base_rate_rad_s": np.asarray(tr["base_rate"])[::st].tolist(),
        }
    return out


def table(res: dict) -> str:
    """The comparison on the true plant, one row per model."""
    lines = [f"mission {res['mission']}"]
    if "approach" in res:
        a = res["approach"]
        lines.append(
            f"approach: {a['duration_s']:g} s, the target from {a['gap_at_start_m']:.3f} m to "
            f"{a['gap_at_contact_m']:.1e} m of the gripper; "
            f"momentum of the two kept to {a['momentum_drift_relative']:.1e}"
        )
    if "capture" in res:
        c = res["capture"]
        lines.append(
            f"capture: impulse {c['impulse_linear_Ns']:.3f} N s, {c['impulse_angular_Nms']:.3f} N m s; "
            f"momentum kept to {c['momentum_error_relative']:.1e}; "
            f"kinetic energy {c['energy_before_J']:.3f} -> {c['energy_after_J']:.3f} J"
        )
    if "identify" in res:
        i = res["identify"]
        lines.append(
            f"identify ({i['method']} form): {'converged' if i['converged'] else 'not converged'} at "
            f"{i['handover_time_s']:.1f} s; target mass {i['target_mass_estimate_kg']:.2f} kg "
            f"({100 * i['target_mass_error_relative']:.2f} %), CoM {1e3 * i['target_com_error_m']:.1f} mm, inertia "
            f"{100 * i['target_inertia_error_relative']:.2f} %"
        )
    if "berth" in res:
        lines.append(f"berth ({res['berth']['controller']}), on the true plant:")
        cols = [("model", 11), ("pos err mm", 11), ("ang err deg", 12), ("settle s", 10), ("thrust N s", 11)]
        cols += [("prop kg", 9), ("max rate", 10), ("wheel Nms", 10)]
        hdr = "".join(f"{c:<{w}}" if k == 0 else f"{c:>{w}}" for k, (c, w) in enumerate(cols))
        lines.append(hdr)
        for name in ("nominal", "identified", "truth", "adaptive"):
            s = res["berth"].get(name)
            if s is None:
                continue
            if name == "adaptive":
                on = s.get("online") or {}
                lines.append(
                    "adaptive: MPC from the identified model, re-planning on the estimate the berth's telemetry "
                    f"refines ({on.get('model_updates', 0)} model updates; target inertia error "
                    f"{100 * on['target_error_at_handover']['inertia_relative']:.2f} % -> "
                    f"{100 * on['target_error_at_end']['inertia_relative']:.2f} %)"
                    if on
                    else "adaptive: MPC re-planning on the online estimate"
                )
            if "failed" in s:
                lines.append(f"{name:<11}failed: {s['failed']}")
                continue
            st = "never" if s["settling_time_s"] is None else f"{s['settling_time_s']:.1f}"
            lines.append(
                f"{name:<11}{1e3 * s['position_error_final_m']:>11.2f}{s['angle_error_final_deg']:>12.3f}{st:>10}"
                f"{s['thrust_impulse_Ns']:>11.2f}{s['propellant_kg']:>9.4f}{s['base_rate_peak_rad_s']:>10.4f}"
                f"{s['wheel_momentum_peak_Nms']:>10.2f}"
            )
    if "wall_time_s" in res:
        lines.append(f"wall time {res['wall_time_s']:.1f} s")
    return "\n".join(lines) + "\n"
