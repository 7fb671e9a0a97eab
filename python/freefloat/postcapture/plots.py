"""Figures of the post-capture reproduction (Zhang, Yue, Yuan 2020): estimate histories (Figs. 4-5 style) and
the initial-velocity sweep (Figs. 6-9 style)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..viz import pyplot
from .estimators import METHODS, SOLVER_TITLES, SOLVERS, is_product

if TYPE_CHECKING:  # annotations only: results.py draws its figures with this module
    from .results import PostcaptureResult


def plot_histories(res: PostcaptureResult, out: Path) -> list[Path]:
    """Figs. 4-5 style: estimate / truth versus time, one figure per method (both solvers), with the scenario's
    tolerance band (e.g. ±0.1 %, shaded) and each solver's transit time (after which it stays in the band)
    marked by a dotted vertical line in the solver's colour."""
    plt = pyplot()
    tol = res.scenario.tolerance
    paths = []
    for method in METHODS:
        if (method, "modified_rls") not in res.histories:
            continue
        show = [j for j, n in enumerate(res.names) if not is_product(n)]
        ncol = 4
        nrow = int(np.ceil(len(show) / ncol))
        fig, axes = plt.subplots(nrow, ncol, figsize=(3.2 * ncol, 2.4 * nrow), constrained_layout=True, squeeze=False)
        transits = {s: res.transits(method, s) for s in SOLVERS}
        for ax, j in zip(axes.ravel(), show):
            tr = res.truth[j]
            if tr != 0:
                ax.axhspan(1 - tol, 1 + tol, color="0.8", alpha=0.6, lw=0, label=f"±{tol * 100:g} % band")
            for solver, style in zip(SOLVERS, ("-", "--")):
                t, h = res.histories[(method, solver)]
                y = h[:, j] / res.truth_at(t)[:, j] if tr != 0 else h[:, j]
                (line,) = ax.plot(t, y, style, label=SOLVER_TITLES[solver])
                stays = transits[solver][j][1]
                if stays is not None:
                    ax.axvline(
                        stays, color=line.get_color(), ls=":", lw=1.2, label=f"transit ({SOLVER_TITLES[solver]})"
                    )
            ax.set_title(res.names[j] + (" / truth" if res.truth[j] != 0 else " (truth 0)"))
            if res.truth[j] != 0:  # ±25 band widths: the band stays visible, the approach stays on the axes
                ax.set_ylim(1 - 25 * tol, 1 + 25 * tol)
            ax.grid(alpha=0.3)
        for ax in axes[-1]:
            ax.set_xlabel("t [s]")
        for ax in axes.ravel()[len(show) :]:
            ax.axis("off")
        axes[0, 0].legend(fontsize=7)
        fig.suptitle(f"{res.scenario.name}: {method}-based identification (estimate / truth)")
        p = out / f"{method}_estimates.png"
        fig.savefig(p, dpi=110)
        plt.close(fig)
        paths.append(p)
    return paths


def plot_sweep(sw: dict, out: Path, params=("In", "I1", "mn", "bnx")) -> Path:
    """Figs. 6-9 style: relative error vs |initial base velocity|, one panel per parameter."""
    plt = pyplot()
    names = sw["names"]
    speed = np.linalg.norm(np.asarray(sw["velocities"]), axis=1)
    order = np.argsort(speed, kind="stable")
    fig, axes = plt.subplots(1, len(params), figsize=(4 * len(params), 3.4), constrained_layout=True)
    for ax, p in zip(axes, params):
        j = names.index(p)
        for key, errs in sw["errors"].items():
            e = np.asarray(errs)[:, j] * 100
            ax.semilogy(speed[order], np.maximum(e[order], 1e-12), "o", label=key, ms=4, alpha=0.8)
        ax.set_xlabel("|v_base(0)| [m/s]")
        ax.set_ylabel("relative error [%]")
        ax.set_title(p)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    p = Path(out) / "velocity_sweep.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p


def plot_base_tracking(res: PostcaptureResult, out: Path) -> Path:
    """The base's true parameters over time (they drift as propellant leaves) against each estimator's
    estimate, one panel per base parameter (mass, centre of mass, principal inertias), and the propellant left."""
    plt = pyplot()
    th_t, th = res.truth_history
    show = [j for j, n in enumerate(res.names) if len(n) > 1 and n[1] == "1" and not is_product(n)]
    prop = res.extra.get("propellant_history")
    npan = len(show) + (1 if prop else 0)
    ncol = 4
    nrow = int(np.ceil(npan / ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.4 * ncol, 2.5 * nrow), constrained_layout=True, squeeze=False)
    styles = {"momentum": ":", "force": "-"}
    for ax, j in zip(axes.ravel(), show):
        ax.plot(th_t, th[:, j], "k", lw=2.2, alpha=0.35, label="truth")
        for (method, solver), (t, h) in res.histories.items():
            ax.plot(t, h[:, j], styles.get(method, "-"), lw=1, label=f"{method}/{SOLVER_TITLES[solver]}")
        lo, hi = th[:, j].min(), th[:, j].max()
        pad = max(hi - lo, 1e-3 * max(abs(hi), abs(lo), 1e-6)) * 3
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_title(res.names[j])
        ax.grid(alpha=0.3)
    k = len(show)
    if prop:
        ax = axes.ravel()[k]
        for name, y in zip(prop["tanks"], np.asarray(prop["kg"]).T):
            ax.plot(prop["t"], y, label=name)
        ax.set_title("propellant left [kg]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        k += 1
    for ax in axes.ravel()[k:]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=6)
    lam = res.scenario.forgetting
    fig.suptitle(f"{res.scenario.name}: the base's parameters as propellant leaves, truth and estimates (λ = {lam:g})")
    p = Path(out) / "base_parameters_tracking.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p
