"""The mission's figure: the phase timeline with what each phase shows."""

from __future__ import annotations

import numpy as np


def timeline(res: dict, path):
    """Three panels on one time axis: the base rate through detumble and berth, the target's estimate over truth
    during identification (with the handover), and the target's pose error in the berth for each model."""
    from ..viz import pyplot

    plt = pyplot()
    ident = res["traces"]["identify"]
    t_c = ident["handover_time"]
    fig, ax = plt.subplots(3, 1, figsize=(8, 8.5), sharex=True)
    sim = ident["sim"]
    ts = np.asarray(sim["t"])
    sel = ts <= t_c + 1e-9
    ax[0].plot(ts[sel], np.linalg.norm(np.asarray(sim["v"])[sel, 3:6], axis=1), color="k", label="detumble")
    for name, tr in res["traces"]["berth"].items():
        ax[0].plot(t_c + tr["t"], tr["base_rate"], label=_label(name))
    ax[0].set_ylabel("|base rate| (rad/s)")
    ax[0].legend(fontsize=8)
    names, est, tru = ident["names"], ident["estimates"], ident["truth_physical"]
    rt = ident["rows_t"]
    upto = rt <= t_c + 1e-9  # what the estimator had seen by the handover
    h = len(names) // 2
    ad = res["traces"].get("adaptive_estimate")
    for j in (h, h + 4, h + 7, h + 9):
        (line,) = ax[1].plot(rt[upto], est[upto, j] / tru[j], label=names[j])
        if ad is not None:  # the adaptive berth's estimator goes on with the berth's telemetry
            ax[1].plot(ad["t"], ad["estimates"][:, j] / tru[j], color=line.get_color(), ls="--")
    ax[1].axvline(t_c, color="k", ls="--", lw=1)
    ax[1].set_ylim(0.5, 1.5)
    ax[1].set_ylabel("target estimate / truth")
    ax[1].legend(fontsize=8, ncol=4)
    ap = res["traces"].get("approach")
    if ap is not None:
        ax[2].semilogy(ap["t"], np.maximum(ap["gap"], 1e-6), color="k", label="approach: target to gripper")
        ax[0].plot(ap["t"], np.zeros_like(ap["t"]), color="k", lw=0.8)
    for name, tr in res["traces"]["berth"].items():
        ax[2].semilogy(t_c + tr["t"], np.maximum(tr["position_error"], 1e-6), label=_label(name))
    ax[2].set_ylabel("distance (m)")
    ax[2].set_xlabel("mission time (s; the grasp at 0)")
    ax[2].legend(fontsize=8)
    for a in ax:
        a.axvspan(0, t_c, color="0.92", zorder=0)
        a.grid(True, which="both", alpha=0.3)
    ax[0].set_title(
        f"{res['mission']}: grasp at 0 s, detumble + identify (grey), handover {t_c:.1f} s, berth", fontsize=10
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _label(name: str) -> str:
    return "berth, adaptive (MPC on the online estimate)" if name == "adaptive" else f"berth, {name} model"
