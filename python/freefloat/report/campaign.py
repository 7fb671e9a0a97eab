"""The report of a campaign folder (`freefloat campaign --out DIR`): counts, failures, the kind's figures beside the
paper's values, the table of runs, the settings; PNG versions of the papers' figures in DIR/figures/."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .page import Page

PAPER_NAVEEN_CASE1 = {"median": 2.08, "max": 174.0}  # Naveen, Shah, Misra Table 5, Case 1 (with noise) [%]


def _col(t, name, default=np.nan):
    if name not in t.column_names:
        return np.full(t.num_rows, default, dtype=float)
    vals = t.column(name).to_pylist()
    try:
        return np.array([np.nan if v is None else v for v in vals], dtype=float)
    except (TypeError, ValueError):
        return np.array(vals, dtype=object)


def build(out: Path, page: Page) -> list[Path]:
    """Fill `page` with the campaign in `out`; returns the PNG files written."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # medians of all-missing columns (no transit) are NaN
        return _build(out, page)


def _build(out: Path, page: Page) -> list[Path]:
    from ..campaign import dataset

    res = json.loads((out / "results.json").read_text())
    meta = json.loads((out / "campaign.json").read_text()) if (out / "campaign.json").is_file() else {}
    page.title = f"Campaign {res.get('campaign', out.name)}"
    page.subtitle = f"{res.get('kind', '?')} — {res.get('description', '')}"
    page.section("Summary")
    page.table(
        ["runs", "total", "done", "failed", "remaining", "run by the last invocation", "on", "its wall time [s]"],
        [
            [
                "count",
                res.get("runs_total"),
                res.get("runs_done"),
                res.get("runs_failed"),
                res.get("runs_remaining"),
                res.get("runs_new"),
                res.get("scheduler") or "–",
                res.get("wall_s"),
            ]
        ],
    )
    page.text(f"Dataset: {res.get('dataset')} (Parquet, partitioned by status; one row per run).")
    t = dataset.read(out / "runs", status=None)
    done = t.filter(np.array(t.column("status").to_pylist()) == "done") if t.num_rows else t
    failed_rows = [r for r in t.to_pylist() if r.get("status") == "failed"]
    pngs: list[Path] = []
    kind = res.get("kind")
    grid = list((meta.get("spec") or {}).get("grid") or {})
    paper = (meta.get("spec") or {}).get("paper") or {}
    if done.num_rows:
        if kind == "postcapture":
            pngs += _postcapture(out, page, done, grid, paper)
        elif kind == "identify_minimal":
            pngs += _minimal(out, page, done, grid, paper)
        elif kind == "sensor_classes":
            _sensor_classes(page, done)
        else:
            _generic(page, done, grid)
    else:
        page.text("No finished runs yet.")
    if failed_rows:
        page.section(f"Failed runs ({len(failed_rows)})")
        page.table(
            ["run", "key", "error"],
            [[r.get("run_index"), r.get("run_key"), (r.get("error") or "")[:400]] for r in failed_rows[:100]],
            left=3,
            bad_rows=set(range(len(failed_rows))),
        )
    page.section("Runs")
    params = [c for c in t.column_names if c.startswith("param.")]
    rows = sorted(t.to_pylist(), key=lambda r: r.get("run_index") or 0)
    head = ["run", "status", "seed", *[p[6:] for p in params], "wall [s]"]
    page.table(
        head,
        [
            [r.get("run_index"), r.get("status"), r.get("seed"), *[r.get(p) for p in params], r.get("run_wall_s")]
            for r in rows[:200]
        ],
        left=2,
        bad_rows={k for k, r in enumerate(rows[:200]) if r.get("status") == "failed"},
    )
    if len(rows) > 200:
        page.text(f"(first 200 of {len(rows)} rows; the dataset has them all)")
    page.section("Settings")
    page.settings("campaign spec", meta.get("spec") or {})
    page.settings("base scenario", meta.get("base_scenario") or {})
    page.settings("results.json", res)
    return pngs


# -- post-capture (Zhang, Yue, Yuan 2020) --------------------------------------------------------------------
def _postcapture(out, page, t, grid, paper) -> list[Path]:
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    names = [c.split(".")[-1] for c in t.column_names if c.startswith("error.momentum.modified_rls.")]
    combos = [
        (m, s)
        for m in ("momentum", "force")
        for s in ("modified_rls", "standard_rls")
        if f"error.{m}.{s}.{names[0] if names else ''}" in t.column_names
    ]
    vx, vy = "param.initial.base_velocity.0", "param.initial.base_velocity.1"
    pngs = []
    if vx in t.column_names and vy in t.column_names:
        X, Y = _col(t, vx), _col(t, vy)
        xs, ys = np.unique(X), np.unique(Y)
        page.section("Initial-velocity sweep (Zhang, Yue, Yuan 2020, Figs. 6-9)")
        page.text(
            "Relative error of every parameter at the end of the run over the grid of initial base velocities "
            "(Vx, Vy); colour: log10 of the error in percent. One figure per identification form and solver."
        )
        for m, s in combos:
            fig = make_subplots(rows=2, cols=4, subplot_titles=names[:8], horizontal_spacing=0.06)
            for k, n in enumerate(names[:8]):
                Z = np.full((len(ys), len(xs)), np.nan)
                e = _col(t, f"error.{m}.{s}.{n}") * 100
                for x, y, v in zip(X, Y, e):
                    Z[np.searchsorted(ys, y), np.searchsorted(xs, x)] = v
                fig.add_trace(
                    go.Heatmap(
                        x=xs,
                        y=ys,
                        z=np.log10(np.maximum(Z, 1e-12)),
                        customdata=Z,
                        coloraxis="coloraxis",
                        hovertemplate="Vx %{x} m/s, Vy %{y} m/s<br>error %{customdata:.3g} %<extra>" + n + "</extra>",
                    ),
                    row=k // 4 + 1,
                    col=k % 4 + 1,
                )
            fig.update_layout(
                title=f"{m}-based, {s.replace('_', ' ')}: relative error [%] vs initial base velocity",
                coloraxis=dict(colorscale="Viridis", colorbar=dict(title="log10 %")),
            )
            fig.update_xaxes(title_text="Vx [m/s]", row=2)
            fig.update_yaxes(title_text="Vy [m/s]", col=1)
            page.figure(fig, height=560)
        pngs.append(_png_sweep(out, t, names, combos, X, Y, xs, ys))
        _paper_sweep_table(page, t, X, Y, paper)
    else:
        xname = f"param.{grid[0]}" if grid and f"param.{grid[0]}" in t.column_names else "run_index"
        x = _col(t, xname)
        page.section("Final relative error of every parameter over the runs")
        page.text(
            f"One point per run against {xname.replace('param.', '')}; each identification form and solver in "
            "its own colour (relative error, absolute for a zero true value)."
        )
        fig = make_subplots(rows=2, cols=4, subplot_titles=names[:8])
        for c, (m, s) in enumerate(combos):
            for k, n in enumerate(names[:8]):
                fig.add_trace(
                    go.Box(
                        x=x,
                        y=np.maximum(_col(t, f"error.{m}.{s}.{n}") * 100, 1e-12),
                        name=f"{m} / {s.replace('_', ' ')}",
                        legendgroup=f"{m}/{s}",
                        showlegend=k == 0,
                        boxpoints="all",
                        marker_color=("#1f77b4", "#aec7e8", "#d62728", "#ff9896")[c % 4],
                    ),
                    row=k // 4 + 1,
                    col=k % 4 + 1,
                )
        fig.update_yaxes(type="log")
        fig.update_yaxes(title_text="error [%]", col=1)
        fig.update_xaxes(title_text=xname.replace("param.", ""), row=2)
        fig.update_layout(boxmode="group", title="final relative error [%]")
        page.figure(fig, height=620)
    # final estimates beside the truth, over the runs
    page.section("Final estimates over the runs (median, min, max) beside the truth")
    rows = []
    for m, s in combos:
        for n in names:
            e = _col(t, f"estimate.{m}.{s}.{n}")
            tr = _col(t, f"truth.{n}")
            rows.append([f"{m}/{s}", n, np.nanmedian(tr), np.nanmedian(e), np.nanmin(e), np.nanmax(e)])
    page.table(["method/solver", "param", "truth", "median", "min", "max"], rows, left=2)
    return pngs


def _paper_sweep_table(page, t, X, Y, paper):
    pts = (paper or {}).get("momentum_In") or []
    if not pts:
        return
    rows = []
    e = _col(t, "error.momentum.modified_rls.In") * 100
    for p in pts:
        v = np.asarray(p["velocity"], float)
        d = np.hypot(X - v[0], Y - v[1])
        k = int(np.argmin(d))
        rows.append([f"{p['velocity']}", p["error_percent"], f"[{X[k]:g}, {Y[k]:g}]", e[k]])
    page.text("The paper's printed values (text of Sec. V-A-3) beside ours at the nearest grid point:")
    page.table(["velocity [m/s]", "paper: momentum I'n error [%]", "our grid point", "ours [%]"], rows, left=1)
    if paper.get("force_In"):
        page.text(f"Force-based, the paper: {paper['force_In']}.")


def _png_sweep(out, t, names, combos, X, Y, xs, ys) -> Path:
    """The papers' format for print: rows = form/solver, columns = the eight parameters, one colour scale (log10
    of the error in percent) shared by all panels (no constrained layout: 32 panels would make it slow)."""
    from ..viz import pyplot

    plt = pyplot()
    grids = {}
    for m, s in combos:
        for n in names[:8]:
            Z = np.full((len(ys), len(xs)), np.nan)
            for x, y, v in zip(X, Y, _col(t, f"error.{m}.{s}.{n}") * 100):
                Z[np.searchsorted(ys, y), np.searchsorted(xs, x)] = v
            grids[(m, s, n)] = np.log10(np.maximum(Z, 1e-12))
    vals = np.concatenate([g[np.isfinite(g)] for g in grids.values()]) if grids else np.zeros(1)
    lo, hi = (float(np.min(vals)), float(np.max(vals))) if vals.size else (0.0, 1.0)
    fig, axes = plt.subplots(len(combos), 8, figsize=(20, 2.4 * len(combos) + 0.8), squeeze=False)
    fig.subplots_adjust(left=0.05, right=0.92, bottom=0.08, top=0.9, wspace=0.3, hspace=0.45)
    im = None
    for r, (m, s) in enumerate(combos):
        for k, n in enumerate(names[:8]):
            ax = axes[r, k]
            im = ax.pcolormesh(xs, ys, grids[(m, s, n)], shading="nearest", cmap="viridis", vmin=lo, vmax=hi)
            ax.set_title(f"{n} ({m}, {s.split('_')[0]})", fontsize=8)
            ax.tick_params(labelsize=7)
            if k == 0:
                ax.set_ylabel("Vy [m/s]", fontsize=8)
            if r == len(combos) - 1:
                ax.set_xlabel("Vx [m/s]", fontsize=8)
    if im is not None:
        fig.colorbar(im, cax=fig.add_axes([0.94, 0.1, 0.012, 0.78]), label="log10 relative error [%]")
    fig.suptitle("Relative error at the end of the run vs initial base velocity (Zhang, Yue, Yuan 2020, Figs. 6-9)")
    (out / "figures").mkdir(exist_ok=True)
    p = out / "figures" / "velocity_sweep.png"
    fig.savefig(p, dpi=90)
    plt.close(fig)
    return p


# -- minimal parameters (Naveen, Shah, Misra) -------------------------------------------------------------
def _minimal(out, page, t, grid, paper) -> list[Path]:
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    gp = [f"param.{g}" for g in grid if f"param.{g}" in t.column_names]
    labels = (
        [", ".join(f"{g[6:]}={r[g]}" for g in gp) for r in t.select(gp).to_pylist()] if gp else ["all"] * t.num_rows
    )
    groups = list(dict.fromkeys(labels))
    page.section("Errors over the noise draws (Naveen, Shah, Misra eqs. 38-39)")
    page.text(
        "Median and maximum relative error of the minimal parameters, one point per noise draw: plain least "
        "squares beside least squares with the errors-in-variables bias removed. Boxes: quartiles; whiskers: "
        "1.5 IQR; the paper's Case 1 (Table 5: median 2.08 %, max 174 %) as dashed lines."
    )
    fig = make_subplots(rows=1, cols=2, subplot_titles=("median relative error [%]", "max relative error [%]"))
    lab = np.array(labels, dtype=object)
    for c, stat in enumerate(("median", "max")):
        for est, name, colour in (
            ("ls", "least squares", "#d62728"),
            ("eiv", "errors-in-variables removed", "#1f77b4"),
        ):
            y = _col(t, f"{est}.{stat}_rel_error_pct")
            fig.add_trace(
                go.Box(
                    x=lab,
                    y=y,
                    name=name,
                    marker_color=colour,
                    boxpoints="all",
                    jitter=0.4,
                    showlegend=c == 0,
                    legendgroup=est,
                ),
                row=1,
                col=c + 1,
            )
        fig.add_hline(y=PAPER_NAVEEN_CASE1[stat], line_dash="dash", line_color="grey", row=1, col=c + 1)
    fig.update_layout(boxmode="group", title="Minimal-parameter errors over noise seeds")
    fig.update_yaxes(type="log")
    page.figure(fig, height=480)
    rows = []
    for g in groups:
        sel = lab == g
        for est in ("ls", "eiv"):
            med = _col(t, f"{est}.median_rel_error_pct")[sel]
            mx = _col(t, f"{est}.max_rel_error_pct")[sel]
            rows.append(
                [
                    g,
                    "least squares" if est == "ls" else "EIV removed",
                    int(sel.sum()),
                    np.median(med),
                    np.percentile(med, 25),
                    np.percentile(med, 75),
                    np.median(mx),
                    np.min(mx),
                    np.max(mx),
                ]
            )
    page.table(
        ["group", "estimator", "draws", "median of medians", "q25", "q75", "median of max", "min of max", "max of max"],
        rows,
        left=2,
    )
    page.text("Paper (Table 5, Case 1, one noise draw): median 2.08 %, max 174 %.")
    # per-parameter spread
    pcols = sorted(c for c in t.column_names if c.startswith("eiv.rel_error_pct."))
    if pcols:
        fig = go.Figure()
        for est, name, colour in (("ls", "least squares", "#d62728"), ("eiv", "EIV removed", "#1f77b4")):
            ks = [c.split(".")[-1] for c in pcols]
            arr = np.stack([_col(t, f"{est}.rel_error_pct.{k}") for k in ks], axis=1)
            fig.add_trace(
                go.Box(
                    y=np.abs(arr).ravel(),
                    x=np.repeat([[int(k) for k in ks]], len(arr), 0).ravel(),
                    name=name,
                    marker_color=colour,
                    boxpoints=False,
                )
            )
        fig.update_layout(
            boxmode="group",
            title="|relative error| of each minimal parameter over the draws [%]",
            xaxis_title="minimal parameter (Naveen, Shah, Misra Table 4 order)",
            yaxis_type="log",
        )
        page.figure(fig, height=420)
    return [_png_minimal(out, t, lab, groups)]


def _png_minimal(out, t, lab, groups) -> Path:
    from ..viz import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    for ax, stat in zip(axes, ("median", "max")):
        data, ticks = [], []
        for g in groups:
            for est in ("ls", "eiv"):
                data.append(_col(t, f"{est}.{stat}_rel_error_pct")[lab == g])
                ticks.append(f"{'LS' if est == 'ls' else 'EIV'}\n{g}")
        ax.boxplot(data)
        ax.set_xticks(range(1, len(ticks) + 1), ticks, fontsize=7)
        ax.axhline(PAPER_NAVEEN_CASE1[stat], ls="--", color="grey", label="paper, Case 1")
        ax.set_yscale("log")
        ax.set_ylabel(f"{stat} relative error [%]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Naveen, Shah, Misra: minimal-parameter errors over noise seeds")
    (out / "figures").mkdir(exist_ok=True)
    p = out / "figures" / "noise_monte_carlo.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p


# -- identification error by sensor class ---------------------------------------------------------------------
def _sensor_classes(page, t):
    from ..identification import sensor_classes as scl

    rows = t.to_pylist()
    horizons = scl.horizons_of(rows)
    page.section("Identification error by sensor class (median / 95th percentile over the seeds)")
    page.text(
        "Relative error ‖θ̂ − θ‖/‖θ‖ of each parameter group (mass; centre of mass or first moments; inertia), the "
        "worst body where there are several; — where the estimator gives none (ch. 9 knows the centres of mass)."
    )
    head = ["estimator", "class", "quantity", *[f"{h:g} s" for h in horizons], "runs"]
    page.table(head, scl.table_rows(rows, horizons), left=3)
    if not horizons:
        return
    import plotly.graph_objects as go

    # one chart per quantity: the median at the last horizon, estimator by sensor class, log scale (errors span
    # 1e-5 to 1e4), the 95th percentile as the error bar's top
    last = horizons[-1]
    summary = [x for x in scl.summary(rows, horizons) if x["horizon_s"] == last and x["finite"]]
    for q in scl.QUANTITIES:
        fig = go.Figure()
        for cls in scl.CLASSES:
            mine = [x for x in summary if x["quantity"] == q and x["sensor_class"] == cls]
            if not mine:
                continue
            med = [x["median"] for x in mine]
            fig.add_trace(
                go.Bar(
                    x=[x["estimator"] for x in mine],
                    y=med,
                    name=cls,
                    error_y={"type": "data", "symmetric": False, "array": [x["p95"] - m for x, m in zip(mine, med)]},
                )
            )
        if fig.data:
            fig.update_layout(
                title=f"{q} error after {last:g} s (median; bar to the 95th percentile)",
                yaxis={"type": "log", "title": "relative error"},
                barmode="group",
            )
            page.figure(fig, height=360)


# -- any kind ---------------------------------------------------------------------------------------------
def _generic(page, t, grid, prefer=()):
    import plotly.graph_objects as go

    numeric = [
        c
        for c in t.column_names
        if not c.startswith("param.")
        and c not in ("run_index", "seed", "attempts", "status")
        and _col(t, c).dtype == float
    ]
    show = [c for c in prefer if c in numeric][:6] or numeric[:6]
    if not show:
        return
    page.section("Summary numbers over the runs")
    xname = f"param.{grid[0]}" if grid and f"param.{grid[0]}" in t.column_names else "run_index"
    x = _col(t, xname)
    for c in show:
        fig = go.Figure(go.Scatter(x=x, y=_col(t, c), mode="markers", name=c))
        fig.update_layout(title=c, xaxis_title=xname.replace("param.", ""), yaxis_title=c)
        page.figure(fig, height=340)
    page.table(
        ["summary", "median", "min", "max"],
        [[c, np.nanmedian(_col(t, c)), np.nanmin(_col(t, c)), np.nanmax(_col(t, c))] for c in numeric[:40]],
    )
