"""Figures of the Valverde 2018 ch. 9 reproduction: Fig. 9.1 (singular values of Σ𝐑ᵀ𝐑), Figs. 9.2-9.4 (base and
link estimates against truth, the jump at T_th,2), Figs. 9.5-9.6 (accuracy and run time against N_s), and the
studies beyond the thesis (measurement noise, the momentum least squares side by side)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..dq.regressor import PARAM_NAMES
from ..viz import pyplot

__all__ = ["comparison_figure", "noise_figure", "ns_figures", "run_figures"]


def _vline(ax, res):
    s = res.settings
    ax.axvline(s["excitation"]["t_start"], color="0.6", lw=0.8, ls=":")
    if s["aggressive"]:
        ax.axvline(s["t_th2"], color="C3", lw=0.8, ls="--", label=f"T_th,2 = {s['t_th2']} s")


def run_figures(res, out: Path) -> list[Path]:
    """fig9_1_singular_values.png, fig9_2_base.png, fig9_3_arm1.png, fig9_4_arm2.png (bodies 2-6, 7-11)."""
    plt = pyplot()
    out = Path(out)
    paths = []
    fig, ax = plt.subplots(figsize=(8, 4.5))
    sv = np.where(res.singular_values > 0, res.singular_values, np.nan)
    ax.semilogy(res.t, sv, lw=0.7)
    _vline(ax, res)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("singular values of Σ R_kᵀ R_k")
    ax.set_title(f"Fig. 9.1: the {sv.shape[1]} singular values (N_s = {res.settings['ns']})")
    fig.tight_layout()
    paths.append(out / "fig9_1_singular_values.png")
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)
    names = res.scenario.model.body_names
    n = len(names)
    groups = [("fig9_2_base.png", "Fig. 9.2: base", [0])]
    if n == 11:
        groups += [
            ("fig9_3_arm1.png", "Fig. 9.3: arm 1 (bodies 2-6)", list(range(1, 6))),
            ("fig9_4_arm2.png", "Fig. 9.4: arm 2 (bodies 7-11)", list(range(6, 11))),
        ]
    else:
        groups += [("fig9_3_links.png", "links", list(range(1, n)))]
    for fname, title, bodies in groups:
        fig, axes = plt.subplots(len(bodies), 2, figsize=(10, 2.0 + 1.6 * len(bodies)), squeeze=False, sharex=True)
        for row, b in enumerate(bodies):
            est = res.estimates[:, 7 * b : 7 * b + 7]
            tru = res.truth[7 * b : 7 * b + 7]
            for j in range(6):
                axes[row, 0].plot(res.t, est[:, j], lw=0.9, label=PARAM_NAMES[j], color=f"C{j}")
                axes[row, 0].axhline(tru[j], color=f"C{j}", lw=0.5, ls=":")
            axes[row, 1].plot(res.t, est[:, 6], lw=0.9, color="k", label="m")
            axes[row, 1].axhline(tru[6], color="k", lw=0.5, ls=":")
            axes[row, 0].set_ylabel(f"{names[b]}\ninertia [kg m²]")
            axes[row, 1].set_ylabel("mass [kg]")
            for ax in axes[row]:
                _vline(ax, res)
        axes[0, 0].legend(ncol=6, fontsize=7, loc="upper left")
        axes[-1, 0].set_xlabel("t [s]")
        axes[-1, 1].set_xlabel("t [s]")
        fig.suptitle(f"{title}: estimates (solid) and truth (dotted)")
        fig.tight_layout()
        paths.append(out / fname)
        fig.savefig(paths[-1], dpi=100)
        plt.close(fig)
    return paths


def ns_figures(sweep: list[dict], out: Path) -> list[Path]:
    """fig9_5_accuracy_vs_ns.png and fig9_6_runtime_vs_ns.png from `concurrent_studies.ns_sweep`."""
    plt = pyplot()
    out = Path(out)
    ns = [r["ns"] for r in sweep]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogy(ns, [max(r["sup_error_9p7_to_10s"], 1e-17) for r in sweep], "o-")
    ax.axhline(0.01, color="C3", ls="--", lw=0.8, label="1 %")
    ax.set_xlabel("N_s")
    ax.set_ylabel("sup over 9.7-10 s of max relative error")
    ax.set_title("Fig. 9.5: accuracy against N_s")
    ax.legend()
    fig.tight_layout()
    p1 = out / "fig9_5_accuracy_vs_ns.png"
    fig.savefig(p1, dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6, 4))
    med = [r["run_time_s_median"] for r in sweep]
    lo = [r["run_time_s_min"] for r in sweep]
    hi = [r["run_time_s_max"] for r in sweep]
    ax.errorbar(ns, med, yerr=[np.subtract(med, lo), np.subtract(hi, med)], fmt="o-", capsize=3)
    ax.set_xlabel("N_s")
    ax.set_ylabel("run time of the 10 s simulation [s]")
    ax.set_title("Fig. 9.6: run time against N_s (median, min-max)")
    fig.tight_layout()
    p2 = out / "fig9_6_runtime_vs_ns.png"
    fig.savefig(p2, dpi=110)
    plt.close(fig)
    return [p1, p2]


def noise_figure(rows: list[dict], out: Path) -> Path:
    """noise_study.png: final error against noise level for the plain law, the thesis' SVD gain and the truncated
    gain."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    labels = {
        "thesis": ("o", "C0", "thesis SVD gain (9.27)"),
        "truncated": ("^", "C1", "truncated SVD gain (9.27')"),
        "plain": ("s", "C2", "plain law (9.15)"),
    }
    for ax, kind in zip(axes, ("wrench", "rate")):
        for g, (marker, color, label) in labels.items():
            sel = [
                r for r in rows if r["kind"] == kind and r.get("gain", "thesis" if r["aggressive"] else "plain") == g
            ]
            sel = [r for r in sel if r["level"] > 0]  # log axes
            if not sel:
                continue
            lv = [r["level"] for r in sel]
            ax.loglog(
                lv, [r["max_final_relative_error"] for r in sel], marker + "-", color=color, label=f"{label}: max"
            )
            ax.loglog(lv, [r["median_final_relative_error"] for r in sel], marker + ":", color=color, ms=4, lw=1,
                      label="median")  # fmt: skip
        ax.axhline(0.01, color="C3", ls=":", lw=0.8)
        ax.set_xlabel("joint F/T noise σ [N, N m]" if kind == "wrench" else "body-rate noise σ [rad/s, m/s (and /s)]")
        ax.set_title(f"{kind} noise")
    axes[0].set_ylabel("final relative error (77 parameters): max, median")
    axes[0].legend(fontsize=7, ncol=1)
    fig.suptitle("Remark 16: measured wrenches and rates")
    fig.tight_layout()
    p = Path(out) / "noise_study.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p


def comparison_figure(comp: dict, out: Path) -> Path:
    """cl_vs_ls.png: relative errors of the identifiable combinations, CL (mapped) and momentum least squares."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(10, 4))
    for label, key, style in (
        ("concurrent learning (mapped)", "cl_rel_errors", "o"),
        ("momentum LS", "ls_rel_errors", "x"),
    ):
        for lvl in comp["levels"]:
            e = np.maximum(np.abs(lvl[key]), 1e-17)
            ax.semilogy(np.arange(len(e)), e, style, ms=4, label=f"{label}, rate σ = {lvl['rate_noise']:g}")
    ax.set_xlabel("identifiable combination (index)")
    ax.set_ylabel("relative error")
    ax.set_title("Same motion: CL (77 parameters, needs joint wrenches) vs momentum LS (combinations, needs rates)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    p = Path(out) / "cl_vs_ls.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p
