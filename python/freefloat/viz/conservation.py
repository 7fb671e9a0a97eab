"""Conservation figure of a simulated trajectory: momentum drift, energy balance, joint angles and forces."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._backend import pyplot


def conservation(traj, path, title: str | None = None) -> Path:
    """Four panels: momentum drift, energy balance, joint angles, joint forces. Returns the path."""
    plt = pyplot()
    t = traj.t
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), constrained_layout=True)
    dp = np.linalg.norm(traj.momentum[:, :3] - traj.momentum[0, :3], axis=1)
    dl = np.linalg.norm(traj.momentum[:, 3:] - traj.momentum[0, 3:], axis=1)
    floor = 1e-18  # below double-precision round-off of any real momentum; keeps the log axis readable
    ax[0, 0].semilogy(t, np.maximum(dp, floor), label="|p(t) − p(0)|  [kg m/s]")
    ax[0, 0].semilogy(t, np.maximum(dl, floor), label="|L(t) − L(0)|  [kg m²/s]")
    ax[0, 0].set_title("momentum drift (should stay at round-off)")
    ax[0, 0].legend()
    ax[0, 1].plot(t, traj.kinetic_energy - traj.kinetic_energy[0], label="ΔE kinetic")
    ax[0, 1].plot(t, traj.work, "--", label="work of joint forces")
    ax[0, 1].set_title("energy balance [J]")
    ax[0, 1].legend()
    # Joint columns are those not belonging to the base (labels without the base's "name." prefix).
    base = traj.q_labels[0].split(".")[0] + "." if traj.q_labels else None
    qj = [k for k, n in enumerate(traj.q_labels) if not (base and n.startswith(base))]
    vj = [k for k, n in enumerate(traj.v_labels) if not (base and n.startswith(base))]
    for k in qj:
        ax[1, 0].plot(t, traj.q[:, k], label=traj.q_labels[k])
    for k in vj:
        ax[1, 1].plot(t, traj.tau[:, k], label=traj.v_labels[k])
    ax[1, 0].set_title("joint coordinates [rad or m]")
    ax[1, 1].set_title("joint forces [N m or N]")
    if 0 < len(qj) <= 12:
        ax[1, 0].legend(fontsize=7, ncol=2)
        ax[1, 1].legend(fontsize=7, ncol=2)
    for a in ax.flat:
        a.set_xlabel("t [s]")
        a.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
