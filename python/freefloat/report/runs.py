"""Reports of single-run `--out` folders: `freefloat demo`, `freefloat identify postcapture`,
`freefloat identify minimal`, `freefloat simulate` (recognised by the keys of their results.json)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .page import Page

#: Naveen, Shah, Misra Table 5, Case 1 (the full trajectory with noise) [%]
PAPER_TABLE5_CASE1 = {"median": 2.08, "max": 174.0}


def what(res: dict) -> str:
    """The kind of folder a results.json describes."""
    if "runs_total" in res:
        return "campaign"
    if "phases_done" in res and "mission" in res:
        return "mission"
    if "methods" in res and "scenario" in res:
        return "postcapture"
    if "identification" in res and "momentum_initial" in res:
        return "demo"
    if "names" in res and "estimate" in res:
        return "identify_minimal"
    if "momentum_initial" in res:
        return "simulation"
    return "unknown"


def _trajectory_files(out: Path) -> list[Path]:
    return sorted(p for p in out.glob("*.parquet") if p.name != "telemetry.parquet")


def simulation_sections(page: Page, out: Path, res: dict, title: str) -> None:
    """Conservation numbers, the trajectory's time plots and the 3D view (if a trajectory file is there)."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    page.section(title)
    keys = [
        ("simulated time [s]", "t_final"),
        ("samples", "samples"),
        ("wall time [s]", "wall_time_s"),
        ("integrator", "method"),
        ("momentum drift, linear [kg m/s]", "momentum_drift_linear_abs"),
        ("momentum drift, linear (relative)", "momentum_drift_linear_rel"),
        ("momentum drift, angular [kg m²/s]", "momentum_drift_angular_abs"),
        ("momentum drift, angular (relative)", "momentum_drift_angular_rel"),
        ("kinetic energy at start [J]", "kinetic_energy_initial"),
        ("kinetic energy at end [J]", "kinetic_energy_final"),
        ("|ΔE − work| [J]", "energy_minus_work_abs"),
        ("|ΔE − work| (relative)", "energy_minus_work_rel"),
    ]
    page.table(["quantity", "value"], [[n, res.get(k)] for n, k in keys if k in res])
    files = _trajectory_files(out)
    if not files:
        return
    from .. import models
    from ..simulation import Trajectory

    traj = Trajectory.from_parquet(files[0])
    t = np.asarray(traj.t)
    fig = make_subplots(
        rows=1,
        cols=3,
        subplot_titles=("momentum − initial", "kinetic energy and work [J]", "joint coordinates"),
    )
    h = np.asarray(traj.momentum) - np.asarray(traj.momentum)[0]
    for k, n in enumerate(("px", "py", "pz", "Lx", "Ly", "Lz")):
        fig.add_trace(go.Scatter(x=t, y=h[:, k], name=n, legendgroup="h"), row=1, col=1)
    fig.add_trace(go.Scatter(x=t, y=np.asarray(traj.kinetic_energy), name="kinetic energy"), row=1, col=2)
    fig.add_trace(
        go.Scatter(x=t, y=np.asarray(traj.kinetic_energy)[0] + np.asarray(traj.work), name="E(0) + work"),
        row=1,
        col=2,
    )
    labels = list(traj.q_labels)
    name = traj.model_name or res.get("model")
    m = None
    if name:
        try:
            m = models.load(name)
        except Exception:  # noqa: BLE001  (a model the report cannot load: no 3D view, said below)
            m = None
    first_joint = int(m.nqs[0]) if m is not None and m.joint_types[0] in ("free", "planar") else 0
    for j in range(first_joint, len(labels)):
        fig.add_trace(go.Scatter(x=t, y=np.asarray(traj.q)[:, j], name=labels[j], legendgroup="q"), row=1, col=3)
    fig.update_xaxes(title_text="t [s]")
    fig.update_layout(title=f"{files[0].name}: conservation and joint motion")
    page.figure(fig, height=420)
    if m is None:
        page.text(f"(no 3D view: the model '{name}' of the trajectory cannot be loaded here)")
        return
    from .robot3d import figure

    page.section("3D view of the motion")
    page.text("Bodies (orange), links to the parent body (grey) and body frames (x red, y green, z blue).")
    page.figure(figure(m, t, np.asarray(traj.q)), height=640)


def identification_sections(page: Page, d: dict, title: str) -> None:
    import plotly.graph_objects as go

    page.section(title)
    names, est, std = d["names"], np.asarray(d["estimate"]), np.asarray(d["std"])
    truth = np.asarray(d["truth"]) if "truth" in d else None
    if "median_rel_error_pct" in d:
        page.table(
            ["relative error (eqs. 38-39)", "ours [%]", "paper, Table 5 Case 1 [%]"],
            [
                ["median", d["median_rel_error_pct"], PAPER_TABLE5_CASE1["median"]],
                ["max", d["max_rel_error_pct"], PAPER_TABLE5_CASE1["max"]],
            ],
        )
    page.text(
        f"{len(names)} minimal parameters from {d.get('samples')} samples; condition number "
        f"{d.get('condition_number', float('nan')):.4g}; solver: {d.get('solver')}."
    )
    rows = []
    for k, n in enumerate(names):
        rel = None
        if truth is not None and truth[k] != 0:
            rel = abs(est[k] - truth[k]) / abs(truth[k]) * 100
        rows.append([k + 1, n, None if truth is None else truth[k], est[k], std[k], rel])
    page.table(["#", "parameter", "true", "estimate", "std", "rel. error [%]"], rows, left=2)
    if truth is not None:
        scale = np.where(truth != 0, np.abs(truth), 1.0)
        fig = go.Figure(
            go.Scatter(
                x=np.arange(1, len(names) + 1),
                y=(est - truth) / scale * 100,
                error_y=dict(array=std / scale * 100),
                mode="markers",
                text=names,
                name="estimate − truth (± 1 std)",
            )
        )
        fig.update_layout(
            title="identified minimal parameters: error in % of |truth|",
            xaxis_title="minimal parameter",
            yaxis_title="relative error [%]",
            yaxis_type="linear",
        )
        page.figure(fig, height=400)


def prediction_sections(page: Page, p: dict) -> None:
    page.section("Validation by prediction (Naveen, Shah, Misra Sec. VI.D, Table 6)")
    page.text(f"Identified robot: {p.get('identified_robot', '?')}; {p.get('duration', 0):.0f} s Fourier trajectory.")
    rows = [[k, v, p.get("paper_rms_twist", {}).get(k)] for k, v in p.get("rms_twist", {}).items()]
    rows += [[k, v, p.get("paper_rms_torque", {}).get(k)] for k, v in p.get("rms_torque", {}).items()]
    page.table(["RMS error of", "ours", "paper (Table 6)"], rows)


def demo(page: Page, out: Path, res: dict) -> None:
    page.title = "freefloat demo"
    page.subtitle = f"{res.get('model', '')}: simulation, identification, validation (Naveen, Shah, Misra)"
    simulation_sections(page, out, res, "Simulation: the arm manoeuvre")
    if "identification" in res:
        identification_sections(page, res["identification"], "Identification of the minimal parameters")
    if "prediction" in res:
        prediction_sections(page, res["prediction"])
    page.section("Settings")
    page.settings("results.json", res)


def simulation(page: Page, out: Path, res: dict) -> None:
    page.title = f"Simulation of {res.get('model', out.name)}"
    simulation_sections(page, out, res, "Simulation")
    page.section("Settings")
    page.settings("results.json", res)


def identify_minimal(page: Page, out: Path, res: dict) -> None:
    page.title = "Minimal-parameter identification"
    identification_sections(page, res, "Identified minimal parameters")
    if "prediction" in res:
        prediction_sections(page, res["prediction"])
    page.section("Settings")
    page.settings("results.json", res)


def postcapture(page: Page, out: Path, res: dict) -> None:
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    page.title = f"Post-capture identification: {res.get('scenario')}"
    page.subtitle = f"Zhang, Yue, Yuan 2020 — model {res.get('model')}, {res.get('duration')} s"
    methods = res.get("methods", {})
    for method, solvers in methods.items():
        page.section(f"{method}-based identification: final estimates beside the paper's")
        sol = list(solvers)
        names = list(solvers[sol[0]])
        rows = []
        for n in names:
            first = solvers[sol[0]][n]
            paper = first.get("paper")
            row = [n, first["truth"], None if not paper else paper[0]]
            for s in sol:
                e = solvers[s][n]
                row += [e["estimate"], e["error"], e["transit_time"]]
            rows.append(row)
        head = ["param", "truth", "paper"]
        for s in sol:
            head += [f"{s}: estimate", "error", "transit [s]"]
        page.table(head, rows)
        fig = make_subplots(rows=1, cols=1)
        for s in sol:
            fig.add_trace(
                go.Bar(x=names, y=[max(solvers[s][n]["error"] * 100, 1e-12) for n in names], name=s.replace("_", " "))
            )
        fig.update_layout(
            title=f"{method}-based: final error [%] (relative; absolute for a zero true value)",
            yaxis_type="log",
            barmode="group",
        )
        page.figure(fig, height=380)
    sw = res.get("velocity_sweep")
    if sw:
        page.section("Initial-velocity sweep (Figs. 6-9)")
        speed = np.linalg.norm(np.asarray(sw["velocities"], float), axis=1)
        fig = make_subplots(rows=2, cols=4, subplot_titles=sw["names"][:8])
        for key, errs in sw["errors"].items():
            e = np.asarray(errs) * 100
            for j in range(min(8, e.shape[1])):
                fig.add_trace(
                    go.Scatter(
                        x=speed,
                        y=np.maximum(e[:, j], 1e-12),
                        mode="markers",
                        name=key,
                        legendgroup=key,
                        showlegend=j == 0,
                    ),
                    row=j // 4 + 1,
                    col=j % 4 + 1,
                )
        fig.update_yaxes(type="log")
        fig.update_layout(title="relative error [%] vs |initial base velocity| [m/s]")
        page.figure(fig, height=560)
    page.section("Settings")
    page.settings("results.json (without the sweep)", {k: v for k, v in res.items() if k != "velocity_sweep"})


def mission(page: Page, out: Path, res: dict) -> None:
    """A capture mission (`freefloat mission --out`): the phase timeline, the handover, the berth comparison."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    page.title = f"Capture mission: {res.get('mission')}"
    page.subtitle = res.get("description", "")
    if res.get("interrupted"):
        page.text(f"Interrupted: {res['interrupted']}. The phases done are shown.")
    tl = res.get("timeline") or []
    if tl:
        page.section("Phase timeline (mission time since the grasp)")
        page.table(["phase", "start [s]", "end [s]"], [[p["phase"], p["start_s"], p["end_s"]] for p in tl])
    a = res.get("approach")
    if a:
        page.section("Approach: the servicer and the free target before the grasp")
        page.table(
            ["quantity", "value"],
            [
                ["duration [s]", a["duration_s"]],
                ["target to gripper at the start [m]", a["gap_at_start_m"]],
                ["momentum of the two kept to (relative)", a["momentum_drift_relative"]],
            ],
        )
    c = res.get("capture")
    if c:
        page.section("Capture: the grasp impact")
        page.table(
            ["quantity", "value"],
            [
                ["linear impulse [N s]", c["impulse_linear_Ns"]],
                ["angular impulse [N m s]", c["impulse_angular_Nms"]],
                ["momentum kept to (relative)", c["momentum_error_relative"]],
                ["kinetic energy before / after [J]", f"{c['energy_before_J']:.4g} / {c['energy_after_J']:.4g}"],
            ],
        )
    i = res.get("identify")
    if i:
        page.section("Detumble and online identification")
        page.table(
            ["quantity", "value"],
            [
                ["converged", i["converged"]],
                ["handover time [s]", i["handover_time_s"]],
                ["target mass estimate [kg]", i["target_mass_estimate_kg"]],
                ["target mass error", i["target_mass_error_relative"]],
                ["target CoM error [m]", i["target_com_error_m"]],
                ["target inertia error (largest diagonal, relative)", i["target_inertia_error_relative"]],
            ],
        )
    se = res.get("series") or {}
    if "identify" in se:
        fig = go.Figure()
        for n, y in se["identify"]["estimate_over_truth"].items():
            fig.add_trace(go.Scatter(x=se["identify"]["t"], y=y, name=n))
        fig.update_layout(title="target estimate / truth up to the handover", yaxis_range=[0.5, 1.5])
        page.figure(fig, height=360)
    b = res.get("berth")
    if b:
        page.section(f"Berth ({b.get('controller')}) with each model, on the true plant")
        keys = [
            ("final position error [m]", "position_error_final_m"),
            ("final angle error [deg]", "angle_error_final_deg"),
            ("settling time [s]", "settling_time_s"),
            ("thrust impulse [N s]", "thrust_impulse_Ns"),
            ("propellant [kg]", "propellant_kg"),
            ("peak base rate [rad/s]", "base_rate_peak_rad_s"),
            ("peak wheel momentum [N m s]", "wheel_momentum_peak_Nms"),
            ("peak joint torque [N m]", "joint_torque_peak_Nm"),
        ]
        models = [m for m in ("nominal", "identified", "truth", "adaptive") if m in b]
        page.table(["quantity"] + models, [[label] + [b[m].get(k) for m in models] for label, k in keys])
        if "berth" in se:
            fig = make_subplots(rows=2, cols=1, shared_xaxes=True)
            for name, tr in se["berth"].items():
                fig.add_trace(go.Scatter(x=tr["t"], y=tr["position_error_m"], name=f"{name} model"), row=1, col=1)
                fig.add_trace(
                    go.Scatter(x=tr["t"], y=tr["base_rate_rad_s"], name=f"{name}: base rate", showlegend=False),
                    row=2,
                    col=1,
                )
            fig.update_yaxes(type="log", title_text="target position error [m]", row=1, col=1)
            fig.update_yaxes(title_text="base rate [rad/s]", row=2, col=1)
            fig.update_layout(title="berth on the true plant")
            page.figure(fig, height=520)
    page.section("Settings")
    page.settings("results.json (without the series)", {k: v for k, v in res.items() if k != "series"})
