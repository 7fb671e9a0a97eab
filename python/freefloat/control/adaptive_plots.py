"""Figures of the ch. 4 reproductions (Valverde 2018, Figs. 4.1-4.7): tracking errors, the seven estimates
against the truth, the singular values of the concurrent-learning matrix, the control effort; each with every
run of the scenario (the CL runs beside the baseline)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..viz import pyplot

NAMES = ["I11", "I12", "I13", "I22", "I23", "I33", "m"]


def _style(k: int):
    return ("-", "--", ":", "-.")[k % 4]


def plot_all(res, out: Path) -> list[Path]:
    """Write tracking_errors.png, estimates.png, singular_values.png and control_effort.png into `out`."""
    plt = pyplot()
    name = res.scenario.name
    paths = []

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True, constrained_layout=True)
    for k, (lab, r) in enumerate(res.runs.items()):
        axes[0].semilogy(r.t, np.maximum(np.degrees(r.attitude_error), 1e-12), _style(k), label=lab)
        axes[1].semilogy(r.t, np.maximum(np.linalg.norm(r.position_error, axis=1), 1e-12), _style(k), label=lab)
    axes[0].set_ylabel("attitude error [deg]")
    axes[1].set_ylabel("|r_B/D| [m]")
    axes[1].set_xlabel("t [s]")
    for a in axes:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle(f"{name}: pose tracking error (Figs. 4.1 / 4.5)")
    paths.append(_save(plt, fig, out / "tracking_errors.png"))

    fig, axes = plt.subplots(2, 4, figsize=(14, 6), sharex=True, constrained_layout=True)
    for j, ax in enumerate(axes.ravel()[:7]):
        for k, (lab, r) in enumerate(res.runs.items()):
            ax.plot(r.t, r.estimate[:, j], _style(k), label=lab)
        ax.axhline(res.scenario.truth[j], color="k", lw=0.8, alpha=0.6, label="truth")
        ax.set_title(NAMES[j] + (" [kg]" if j == 6 else " [kg m²]"))
        ax.grid(alpha=0.3)
    axes.ravel()[7].axis("off")
    axes[0, 0].legend(fontsize=7)
    for a in axes[-1]:
        a.set_xlabel("t [s]")
    fig.suptitle(f"{name}: estimated dual-inertia parameters (Figs. 4.2 / 4.6)")
    paths.append(_save(plt, fig, out / "estimates.png"))

    cl = [(lab, r) for lab, r in res.runs.items() if r.alpha != 0] or list(res.runs.items())
    fig, axes = plt.subplots(1, len(cl), figsize=(6 * len(cl), 4), squeeze=False, constrained_layout=True)
    for ax, (lab, r) in zip(axes[0], cl):
        ax.semilogy(r.t, np.maximum(r.singular_values, 1e-16))
        ax.axhline(0.1, color="k", lw=0.6, ls=":")
        ax.set_title(f"{lab}: singular values of {'P' if res.scenario.mode == 'continuous' else 'Σ R_kᵀR_k'}")
        ax.set_xlabel("t [s]")
        ax.grid(alpha=0.3)
    which = "Fig. 4.3" if res.scenario.mode == "continuous" else "not plotted in the thesis for the discrete case"
    fig.suptitle(f"{name}: singular values ({which})")
    paths.append(_save(plt, fig, out / "singular_values.png"))

    fig, axes = plt.subplots(2, 3, figsize=(13, 6), sharex=True, constrained_layout=True)
    comp = [(1, "f_x [N]"), (2, "f_y [N]"), (3, "f_z [N]"), (5, "τ_x [N m]"), (6, "τ_y [N m]"), (7, "τ_z [N m]")]
    for ax, (i, lab_) in zip(axes.ravel(), comp):
        for k, (lab, r) in enumerate(res.runs.items()):
            ax.plot(r.t, r.force[:, i], _style(k), label=lab)
        ax.set_title(lab_)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7)
    for a in axes[-1]:
        a.set_xlabel("t [s]")
    fig.suptitle(f"{name}: control effort (Figs. 4.4 / 4.7)")
    paths.append(_save(plt, fig, out / "control_effort.png"))
    return paths


def _save(plt, fig, p: Path) -> Path:
    fig.savefig(p, dpi=100)
    plt.close(fig)
    return p
